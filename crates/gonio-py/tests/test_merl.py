"""MERL tables through the plugin registry: files written here with numpy, independently of gonio's writer."""

import numpy as np
import pytest

import gonio

SCALE = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
CELLS = 90 * 90 * 180


def write_merl(path, blocks, dims=(90, 90, 180)):
    """Three int32 dimensions, then the red, green and blue blocks of float64."""
    with open(path, "wb") as f:
        f.write(np.asarray(dims, dtype="<i4").tobytes())
        f.write(np.asarray(blocks, dtype="<f8").tobytes())
    return str(path)


def test_a_constant_table_is_lambertian(tmp_path):
    rho = np.array([0.5, 0.25, 0.125])
    # Entry = f / scale with f = ρ/π; θh ≥ 45 (index) left "not measured" (−1) and filled by the reader.
    blocks = np.repeat((rho / np.pi / SCALE)[:, None], CELLS, axis=1)
    blocks[:, 45 * 90 * 180:] = -1.0
    path = write_merl(tmp_path / "lambert.binary", blocks)
    for interp in ["trilinear", "nearest"]:
        b = gonio.load_bsdf({"type": "merl", "filename": path, "interpolation": interp})
        assert b.plugin == "merl"
        rng = np.random.default_rng(1)
        wo = rng.normal(size=(1000, 3))
        wi = rng.normal(size=(1000, 3))
        wo[:, 2] = np.abs(wo[:, 2]) + 0.05
        wi[:, 2] = np.abs(wi[:, 2]) + 0.05
        f = b.f(wo, wi, normalize=True)
        np.testing.assert_allclose(f, np.broadcast_to(rho / np.pi, f.shape), rtol=1e-5)
    # Sampling and the white furnace: the albedo of a Lambertian table is ρ.
    np.testing.assert_allclose(b.albedo([0.0, 0.6, 0.8], samples=200_000), rho, rtol=0.01)


def test_bad_files_name_the_file_and_the_problem(tmp_path):
    bad_dims = write_merl(tmp_path / "dims.binary", np.ones((3, CELLS)), dims=(180, 90, 90))
    all_negative = write_merl(tmp_path / "neg.binary", -np.ones((3, CELLS)))
    truncated = write_merl(tmp_path / "short.binary", np.ones(3 * CELLS - 5))
    for path, expect in [(bad_dims, "dimensions"), (all_negative, "negative"), (truncated, "truncated")]:
        with pytest.raises(ValueError) as e:
            gonio.load_bsdf({"type": "merl", "filename": path})
        assert path in str(e.value) and expect in str(e.value)
