"""gonio.read_image / gonio.write_image: round trips per format, dtypes, shapes and errors."""

import numpy as np
import pytest

import gonio

RNG = np.random.default_rng(3)


def pattern(h=5, w=7, dtype=np.float32):
    img = RNG.uniform(0, 1, size=(h, w, 3)).astype(dtype)
    img[0, 0] = [0.0, 1.0, 0.5]
    return img


def srgb(v):
    v = np.clip(v, 0, 1)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def test_exr_round_trip_is_exact(tmp_path):
    img = pattern()
    img[1, 2] = [1e-7, 12345.678, -3.0]  # EXR keeps float32 exactly, negatives included
    gonio.write_image(tmp_path / "a.exr", img)
    back = gonio.read_image(tmp_path / "a.exr")
    assert back.dtype == np.float32 and back.shape == img.shape
    assert np.array_equal(back, img)
    # str paths, float64 input (rounded to float32), and nothing left behind by the atomic write.
    gonio.write_image(str(tmp_path / "b.exr"), img.astype(np.float64))
    assert np.array_equal(gonio.read_image(str(tmp_path / "b.exr")), img)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "b.exr"]


def test_grey_images_become_rgb(tmp_path):
    grey = RNG.uniform(0, 1, size=(4, 6)).astype(np.float32)
    gonio.write_image(tmp_path / "g.exr", grey)
    back = gonio.read_image(tmp_path / "g.exr")
    assert back.shape == (4, 6, 3)
    for c in range(3):
        assert np.array_equal(back[:, :, c], grey)


def test_png_round_trip_within_one_step(tmp_path):
    img = pattern()
    img[2, 3] = [2.0, -1.0, np.nan]  # clamped; NaN written as 0
    gonio.write_image(tmp_path / "a.png", img)
    back = gonio.read_image(tmp_path / "a.png")
    assert back.shape == img.shape and back.dtype == np.float32
    expected = np.nan_to_num(img, nan=0.0)
    assert np.abs(srgb(back) - srgb(expected)).max() <= 0.5 / 255 + 1e-6


def test_hdr_round_trip_within_rgbe_precision(tmp_path):
    img = pattern() * 100
    gonio.write_image(tmp_path / "a.hdr", img)
    back = gonio.read_image(tmp_path / "a.hdr")
    assert back.shape == img.shape
    # RGBE keeps 8 bits per channel relative to the pixel's largest channel.
    assert (np.abs(back - img) <= img.max(axis=2, keepdims=True) / 128).all()


def test_render_output_can_be_written_and_read(tmp_path):
    img = np.zeros((3, 4, 3), np.float32)
    img[..., 0] = np.arange(12, dtype=np.float32).reshape(3, 4)
    gonio.write_image(tmp_path / "r.exr", img)
    back = gonio.read_image(tmp_path / "r.exr")
    # Row 0 is the top row, column x the x-th pixel.
    assert back[0, 3, 0] == 3 and back[2, 0, 0] == 8


def test_write_errors(tmp_path):
    for bad in [np.zeros((4, 4, 4), np.float32), np.zeros(3, np.float32), np.zeros((2, 2, 2, 3), np.float32)]:
        with pytest.raises(ValueError, match="shape"):
            gonio.write_image(tmp_path / "x.exr", bad)
    with pytest.raises(ValueError, match="no pixels"):
        gonio.write_image(tmp_path / "x.exr", np.zeros((0, 4, 3), np.float32))
    for bad in [np.zeros((2, 2, 3), np.uint8), np.zeros((2, 2, 3), bool), [[0.5, 0.5, 0.5]]]:
        with pytest.raises(ValueError, match="float32 or float64"):
            gonio.write_image(tmp_path / "x.exr", bad)
    with pytest.raises(ValueError, match=r"x\.bmp.*accepted: \.exr, \.png, \.hdr"):
        gonio.write_image(tmp_path / "x.bmp", pattern())
    with pytest.raises(FileNotFoundError):
        gonio.write_image(tmp_path / "no" / "such" / "dir.exr", pattern())
    assert list(tmp_path.iterdir()) == []


def test_read_errors(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        gonio.read_image(tmp_path / "missing.exr")
    assert e.value.filename.endswith("missing.exr")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(ValueError, match=r"notes\.txt.*not a recognised image"):
        gonio.read_image(tmp_path / "notes.txt")
    gonio.write_image(tmp_path / "t.png", pattern(40, 40))
    data = (tmp_path / "t.png").read_bytes()
    (tmp_path / "t.png").write_bytes(data[:100])
    with pytest.raises(ValueError, match=r"t\.png"):
        gonio.read_image(tmp_path / "t.png")
    with pytest.raises(IsADirectoryError):
        gonio.read_image(tmp_path)
