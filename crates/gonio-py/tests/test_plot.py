"""gonio.lobe_data / slice_data / albedo_data (the numbers of `gonio plot`) and gonio.plot (matplotlib)."""

import csv
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gonio

CLI = Path(__file__).resolve().parents[3] / "target" / "release" / "gonio"
DIFFUSE = {"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}
GGX = {"type": "roughconductor", "distribution": "ggx", "alpha": 0.05}


def test_lambertian_lobe_is_rho_over_pi_cos():
    lobe = gonio.lobe_data(DIFFUSE, 40.0, samples=361, grid_theta=7, grid_phi=8)
    assert lobe.angles.shape == (361,) and lobe.angles.dtype == np.float64
    assert lobe.incidence.shape == (361, 4) and lobe.incidence.dtype == np.float32
    assert lobe.grid.shape == (7, 8, 4)
    cos = np.cos(np.radians(lobe.angles))
    expect = np.where(cos > 0, cos, 0.0)[:, None] * np.array([0.2, 0.5, 0.8]) / np.pi
    np.testing.assert_allclose(lobe.incidence[:, :3], expect, atol=1e-6, rtol=0)
    # Luminance column: Rec. 709 weights of the RGB columns.
    np.testing.assert_allclose(lobe.incidence[:, 3], lobe.incidence[:, :3] @ [0.212671, 0.715160, 0.072169], atol=1e-7)
    # Perpendicular plane: cos θi = cos a · cos θo.
    np.testing.assert_allclose(lobe.perpendicular[180, 1], 0.5 / np.pi * np.cos(np.radians(40)), atol=1e-6)


def test_mirror_like_ggx_peaks_at_the_specular_direction():
    lobe = gonio.lobe_data(GGX, 50.0, samples=721, grid_theta=0, grid_phi=0)
    assert lobe.grid.shape == (0, 0, 4)
    assert lobe.angles[np.argmax(lobe.incidence[:, 3])] == pytest.approx(-50.0, abs=0.5)
    assert lobe.angles[np.argmax(lobe.perpendicular[:, 3])] == pytest.approx(0.0, abs=0.5)


def test_albedo_of_diffuse_is_flat_at_rho():
    a = gonio.albedo_data(DIFFUSE, angles=12, samples=256)
    np.testing.assert_allclose(a.theta_o, 90 * (np.arange(12) + 0.5) / 12)
    np.testing.assert_allclose(a.albedo[:, :3], np.tile([0.2, 0.5, 0.8], (12, 1)), atol=1e-5)


def test_slice_of_diffuse_and_horizon():
    s = gonio.slice_data(DIFFUSE, 0.0, theta_h=30, theta_d=20)  # φd = 0: below the horizon when θh + θd > 90°
    assert s.values.shape == (20, 30, 4)
    np.testing.assert_allclose(s.theta_h, 90 * ((np.arange(30) + 0.5) / 30) ** 2)
    finite = np.isfinite(s.values[..., 0])
    assert 0 < (~finite).sum() < 300
    np.testing.assert_allclose(s.values[finite][:, 1], 0.5 / np.pi, rtol=1e-6)


def test_bad_arguments_raise_value_error():
    with pytest.raises(ValueError, match="theta_o"):
        gonio.lobe_data(DIFFUSE, 90.0)
    with pytest.raises(ValueError, match="samples"):
        gonio.lobe_data(DIFFUSE, 10.0, samples=-1)
    with pytest.raises(ValueError, match="phi_d"):
        gonio.slice_data(DIFFUSE, 361.0)
    with pytest.raises(ValueError, match="angles"):
        gonio.albedo_data(DIFFUSE, angles=0)


def cli_csv(tmp_path, *args):
    out = tmp_path / "data.csv"
    subprocess.run([str(CLI), "plot", *args, "-o", str(out)], check=True, timeout=120, capture_output=True)
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=np.float64)


@pytest.mark.skipif(not CLI.exists(), reason="target/release/gonio not built (make build builds it)")
def test_data_equals_the_cli_bit_for_bit(tmp_path):
    import json

    models = [json.dumps(DIFFUSE), json.dumps(GGX)]
    for channel, c in [("lum", 3), ("r", 0)]:
        header, table = cli_csv(tmp_path, *models, "--theta-o", "35", "--channel", channel)
        assert header[0] == "angle_deg"
        for k, m in enumerate(models):
            lobe = gonio.lobe_data(m, 35.0)
            assert np.array_equal(table[:, 0], lobe.angles)
            assert np.array_equal(table[:, 1 + 2 * k].astype(np.float32), lobe.incidence[:, c])
            assert np.array_equal(table[:, 2 + 2 * k].astype(np.float32), lobe.perpendicular[:, c])
    header, table = cli_csv(tmp_path, models[1], "--kind", "albedo", "--samples", "512", "--angles", "9")
    a = gonio.albedo_data(GGX, angles=9, samples=512)
    assert np.array_equal(table[:, 0], a.theta_o) and np.array_equal(table[:, 1].astype(np.float32), a.albedo[:, 3])
    header, table = cli_csv(tmp_path, models[1], "--kind", "slice", "--phi-d", "60", "--channel", "g")
    s = gonio.slice_data(GGX, 60.0)
    got = table[:, 2].astype(np.float32).reshape(90, 90)
    assert np.array_equal(got, s.values[..., 1], equal_nan=True)
    header, table = cli_csv(tmp_path, models[1], "--kind", "3d", "--theta-o", "20")
    lobe = gonio.lobe_data(GGX, 20.0)
    assert np.array_equal(table[:, 2].astype(np.float32), lobe.grid[..., 3].ravel())


def test_plot_draws_every_kind(tmp_path):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paint, gold = gonio.load_bsdf(DIFFUSE), gonio.load_bsdf(GGX)
    for kind in ["polar", "3d", "slice", "albedo"]:
        fig = gonio.plot([paint, gold], kind, theta_o=30, labels=["paint", "gold"], log=(kind == "slice"), samples=256)
        fig.savefig(tmp_path / f"{kind}.png", dpi=50)
        assert (tmp_path / f"{kind}.png").stat().st_size > 3000
        legends = [ax.get_legend() for ax in fig.axes] + list(fig.legends)
        texts = [t.get_text() for lg in legends if lg is not None for t in lg.get_texts()]
        titles = [ax.get_title() for ax in fig.axes]
        if kind == "slice":
            assert "paint" in titles and "gold" in titles
        else:
            assert texts == ["paint", "gold"], (kind, texts)
        plt.close(fig)
    # The same model twice gets numbered default labels.
    fig = gonio.plot([DIFFUSE, DIFFUSE], "albedo", samples=64)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["diffuse", "diffuse #2"]
    plt.close(fig)
    with pytest.raises(ValueError, match="theta_o"):
        gonio.plot(paint, "polar")
    with pytest.raises(ValueError, match="kind"):
        gonio.plot(paint, "pie", theta_o=10)


def test_plot_without_matplotlib_says_so():
    code = (
        "import sys; sys.modules['matplotlib'] = None\n"
        "import gonio\n"
        "try:\n    gonio.plot({'type': 'diffuse'}, 'polar', theta_o=0)\n"
        "except ImportError as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "gonio.plot needs matplotlib" in out and "pip install matplotlib" in out
