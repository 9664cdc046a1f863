"""gonio.verify: result types and shapes, verdicts on honest and broken models, agreement with `gonio check`."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import gonio
from gonio import verify

DIFFUSE = '{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}'
# Unnormalised Phong: diffuse 0.5 plus an unnormalised cosine lobe 0.5 reflects more than it receives.
PHONG_GAIN = '{"type":"phong","normalization":"none","diffuse_reflectance":0.5,"specular_reflectance":0.5,"exponent":1}'
WO = [0.6, 0.0, 0.8]
CLI = pathlib.Path(os.environ.get("GONIO_CLI", pathlib.Path(__file__).resolve().parents[3] / "target" / "release" / "gonio"))


@pytest.fixture(scope="module")
def diffuse():
    return gonio.load_bsdf(DIFFUSE)


def test_module_is_exported():
    assert gonio.verify is verify
    for name in verify.__all__:
        assert getattr(verify, name).__doc__, f"gonio.verify.{name} has no docstring"
    assert "Šidák" in verify.chi2.__doc__ and "Veach 1997" in verify.reciprocity.__doc__


# --- chi2 --------------------------------------------------------------------------------------------


def test_chi2_diffuse_passes_with_histograms(diffuse):
    n = 200_000
    r = verify.chi2(diffuse, WO, samples=n, seed=3)
    assert isinstance(r, verify.Chi2Result)
    assert r.passed and bool(r) and r.message == "", r
    assert 0 < r.alpha < 0.01 + 1e-12 and r.alpha <= r.p_value <= 1
    assert isinstance(r.dof, int) and r.dof > 100 and r.statistic > 0
    for h in (r.observed, r.expected):
        assert h.dtype == np.float64 and h.shape == (40, 80)
    # Every sample lands in a cell; the cosine lobe integrates to 1 over the upper hemisphere (Gauss–Legendre
    # is exact for a density linear in cos θ; what remains is the float32 rounding of pdf(), ~4e-8 here),
    # and nothing below the horizon.
    assert r.observed.sum() == n and r.no_sample_observed == 0
    assert r.expected.sum() == pytest.approx(n, rel=1e-6)
    assert r.expected[:20].sum() == 0 and r.observed[:20].sum() == 0
    assert r.delta_bins == [] and r.pdf_mismatches == 0
    assert "cos θ" in r.domain
    assert "passed" in repr(r) and "dof" in str(r)


def test_chi2_grid_and_seed(diffuse):
    a = verify.chi2(diffuse, np.array(WO, dtype=np.float32), samples=50_000, theta_res=10, phi_res=6, seed=1)
    b = verify.chi2(diffuse, WO, samples=50_000, theta_res=10, phi_res=6, seed=1)
    c = verify.chi2(diffuse, WO, samples=50_000, theta_res=10, phi_res=6, seed=2)
    assert a.observed.shape == (10, 6)
    np.testing.assert_array_equal(a.observed, b.observed)
    np.testing.assert_array_equal(a.expected, c.expected)
    assert not np.array_equal(a.observed, c.observed)


def test_chi2_sidak_family(diffuse):
    one = verify.chi2(diffuse, WO, samples=10_000)
    eight = verify.chi2(diffuse, WO, samples=10_000, tests=8, significance=0.05)
    assert one.alpha == pytest.approx(0.01)
    assert eight.alpha == pytest.approx(1 - 0.95 ** (1 / 8), rel=1e-12)


def test_chi2_delta_lobe_has_its_own_bin():
    mirror = gonio.load_bsdf({"type": "conductor", "material": "none"})
    n = 10_000
    r = verify.chi2(mirror, WO, samples=n)
    assert r.passed, r
    assert len(r.delta_bins) == 1
    wi, observed, expected = r.delta_bins[0]
    assert wi.shape == (3,) and wi.dtype == np.float64
    np.testing.assert_allclose(wi, [-0.6, 0.0, 0.8], atol=1e-6)
    assert observed == n and expected == pytest.approx(n, rel=1e-6)
    assert r.observed.sum() == 0


def test_chi2_from_below_a_one_sided_model(diffuse):
    r = verify.chi2(diffuse, [0.0, 0.0, -1.0], samples=1000)
    assert r.passed and "no scattering" in r.message
    assert r.no_sample_observed == 1000


# --- reciprocity, energy, sweep ----------------------------------------------------------------------


def test_reciprocity(diffuse):
    r = verify.reciprocity(diffuse, pairs=20_000, seed=4)
    assert isinstance(r, verify.ReciprocityResult)
    assert r.max_rel_error < 1e-5
    # About a quarter of uniform pairs have both directions above the surface.
    assert 4_000 < r.compared < 6_000
    assert r.worst is None or (r.worst[0].shape == (3,) and r.worst[1].shape == (3,))
    assert "ReciprocityResult" in repr(r)


def test_reciprocity_of_an_exactly_symmetric_model_has_no_worst_pair():
    # f(wo, wi) and f(wi, wo) of roughconductor are computed by the same float operations: not one ulp apart.
    b = gonio.load_bsdf({"type": "roughconductor", "alpha_u": 0.1, "alpha_v": 0.4, "material": "none"})
    r = verify.reciprocity(b, pairs=5_000)
    assert r.compared > 0 and r.max_rel_error == 0 and r.worst is None


def test_energy_above_and_below(diffuse):
    e = verify.energy(diffuse, angles=8, samples=1024)
    assert isinstance(e, verify.EnergyResult) and e.side == "above"
    np.testing.assert_allclose(e.cos_theta_o, (np.arange(8) + 0.5) / 8, rtol=1e-6)
    assert e.albedo.shape == (8, 3) and e.albedo.dtype == np.float64
    assert e.white_furnace.shape == (3,)
    # White-weighted Lambertian: constant sample weights give the exact albedo at every θo.
    np.testing.assert_allclose(e.albedo, np.tile([0.2, 0.5, 0.8], (8, 1)), rtol=1e-6)
    np.testing.assert_allclose(e.white_furnace, [0.2, 0.5, 0.8], rtol=1e-5)
    assert e.max_albedo == pytest.approx(0.8, rel=1e-6)
    below = verify.energy(diffuse, angles=4, samples=64, side="below")
    assert below.side == "below" and (below.cos_theta_o < 0).all()
    assert (below.albedo == 0).all() and (below.white_furnace == 0).all()
    assert not verify.scatters_from_below(diffuse)
    assert verify.scatters_from_below(gonio.load_bsdf({"type": "dielectric"}))
    assert verify.scatters_from_below(gonio.load_bsdf({"type": "twosided", "a": json.loads(DIFFUSE)}))
    assert "white furnace" in repr(e)


def test_energy_of_a_violation():
    e = verify.energy(gonio.load_bsdf(PHONG_GAIN), angles=8, samples=4096)
    assert e.max_albedo > 1.001 and (e.white_furnace > 1.001).all()


def test_the_harness_per_wavelength():
    # A model at one wavelength is any model to the harness (issue 30): `at_wavelength`, and `check`'s
    # `wavelengths=` (one report each, as `gonio check --wavelengths`).
    table = '<bsdf type="diffuse"><spectrum name="reflectance" value="400:0.2, 700:0.9"/></bsdf>'
    paper = gonio.load_bsdf(table)
    for nm, rho in [(400.0, 0.2), (550.0, 0.55), (650.0, 0.2 + 0.7 * 250 / 300)]:
        at = paper.at_wavelength(nm)
        assert at.spec.endswith(f"@ {nm:g} nm")
        e = verify.energy(at, angles=4, samples=256)
        np.testing.assert_allclose(e.albedo, rho, rtol=1e-5)  # the table's value, not its colour's spectrum
        assert at.f([0, 0, 1], [0, 0, 1])[0] == paper.f([0, 0, 1], [0, 0, 1], wavelengths=nm)
    # The same table in Mitsuba's dictionary form.
    as_dict = gonio.load_bsdf({"type": "diffuse", "reflectance": {"type": "spectrum", "value": [(400, 0.2), (700, 0.9)]}})
    assert as_dict.at_wavelength(650).f([0, 0, 1], [0, 0, 1])[0] == paper.at_wavelength(650).f([0, 0, 1], [0, 0, 1])[0]
    sf11 = gonio.load_bsdf({"type": "roughdielectric", "int_ior": "sf11", "alpha": 0.3, "distribution": "ggx"})
    reports = verify.check(sf11, samples=100_000, sweep=10_000, wavelengths=[400, 650])
    assert [r.name.endswith(f"@ {nm} nm") for r, nm in zip(reports, (400, 650))] == [True, True]
    assert all(reports), [str(r) for r in reports]
    assert isinstance(verify.check(sf11, samples=10_000, sweep=1_000), verify.Report)
    with pytest.raises(gonio.SpecError, match="at_wavelength: .*`diffuse_reflectance` of `phong`"):
        gonio.load_bsdf({"type": "phong", "diffuse_reflectance": [0.8, 0.2, 0.1]}).at_wavelength(550)
    with pytest.raises(gonio.SpecError, match="already at 550 nm"):
        paper.at_wavelength(550).at_wavelength(600)
    with pytest.raises(ValueError, match=r"at_wavelength\(900.*\[360, 830\] nm"):
        paper.at_wavelength(900)


def test_sweep(diffuse):
    s = verify.sweep(diffuse, queries=20_000, seed=5)
    assert isinstance(s, verify.SweepResult)
    # At least the queries asked for, in whole chunks of 16384 (each chunk its own random stream).
    assert s.queries == 2 * 16_384 and s.bad == 0 and s.first_bad is None
    assert "0 of 32768" in repr(s)


# --- check -------------------------------------------------------------------------------------------


def test_check_report(diffuse):
    r = verify.check(diffuse, samples=100_000, sweep=10_000)
    assert isinstance(r, verify.Report)
    assert r.passed and bool(r) and r.name == DIFFUSE
    checks = [row.check for row in r.rows]
    assert checks[:4] == ["chi2 cosθo=+0.98", "chi2 cosθo=+0.70", "chi2 cosθo=+0.30", "chi2 cosθo=+0.05"]
    assert {"sample weight/pdf", "reciprocity", "albedo max (above)", "white furnace (above)"} <= set(checks)
    assert checks[-1] == "NaN/Inf sweep (16384 queries)"
    row = r.rows[0]
    assert isinstance(row, verify.CheckRow) and isinstance(row.measured, float) and row.limit.startswith("p > ")
    d = r.to_dict()
    assert d["name"] == DIFFUSE and d["passed"] is True and len(d["checks"]) == len(r.rows)
    assert d["checks"][0] == row.to_dict() == {"check": row.check, "measured": row.measured, "limit": row.limit,
                                               "passed": row.passed, "detail": row.detail}
    table = str(r)
    assert table.splitlines()[0] == DIFFUSE and "measured" in table and "FAIL" not in table
    assert table.count("pass") == len(r.rows)
    assert "passed" in repr(r)


def test_check_fails_energy_of_a_phong_violation():
    r = verify.check(gonio.load_bsdf(PHONG_GAIN), samples=100_000, sweep=10_000)
    assert not r.passed
    failed = {row.check: row for row in r.rows if not row.passed}
    assert "albedo max (above)" in failed and "white furnace (above)" in failed, str(r)
    assert failed["albedo max (above)"].measured > 1.001
    assert "FAIL" in str(r) and "albedo max (above)" in repr(r)


@pytest.mark.parametrize("spec", [DIFFUSE, PHONG_GAIN, '{"type": "dielectric", "int_ior": 1.5}'])
def test_check_matches_the_cli(spec):
    """The same spec and seed give the same report as `gonio check --json`, figure for figure, and the same
    table as `gonio check`."""
    if not CLI.exists():
        pytest.skip(f"{CLI} not built (cargo build --release -p gonio-cli, or set GONIO_CLI)")
    seed = 11
    args = [str(CLI), "check", spec, "--json", "--samples", "100000", "--sweep", "20000", "--seed", str(seed),
            "--histograms", os.devnull]
    out = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert out.returncode in (0, 1), out.stderr
    cli = json.loads(out.stdout)
    report = verify.check(gonio.load_bsdf(spec), samples=100_000, sweep=20_000, seed=seed)
    assert report.to_dict() == cli
    # And str(report) is the table the CLI prints without --json.
    table = subprocess.run([a for a in args if a != "--json"], capture_output=True, text=True, timeout=600)
    assert table.stdout.startswith(str(report)) and table.stdout[len(str(report)):].endswith("BSDFs passed every check\n")


# --- bad arguments -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda b: verify.chi2(b, [0.0, 0.0, 2.0]), "not a unit vector"),
        (lambda b: verify.chi2(b, [[0.0, 0.0, 1.0]]), "one direction of shape"),
        (lambda b: verify.chi2(b, [0.0, 1.0]), "shape"),
        (lambda b: verify.chi2(b, [np.nan, 0.0, 1.0]), "not finite"),
        (lambda b: verify.chi2(b, WO, samples=0), "samples"),
        (lambda b: verify.chi2(b, WO, theta_res=7), "theta_res"),
        (lambda b: verify.chi2(b, WO, phi_res=0), "phi_res"),
        (lambda b: verify.chi2(b, WO, significance=0.0), "significance"),
        (lambda b: verify.chi2(b, WO, significance=1.5), "significance"),
        (lambda b: verify.chi2(b, WO, tests=0), "tests"),
        (lambda b: verify.reciprocity(b, pairs=0), "pairs"),
        (lambda b: verify.energy(b, angles=0), "angles"),
        (lambda b: verify.energy(b, samples=0), "samples"),
        (lambda b: verify.energy(b, side="left"), "side"),
        (lambda b: verify.sweep(b, queries=0), "queries"),
        (lambda b: verify.check(b, samples=0), "samples"),
        (lambda b: verify.check(b, sweep=0), "sweep"),
    ],
)
def test_bad_arguments_raise_value_error(diffuse, call, message):
    with pytest.raises(ValueError, match=message):
        call(diffuse)


def test_negative_counts_and_non_models_are_rejected(diffuse):
    with pytest.raises(ValueError, match="queries"):
        verify.sweep(diffuse, queries=-1)
    with pytest.raises(ValueError, match="seed"):
        verify.reciprocity(diffuse, seed=-1)
    with pytest.raises(TypeError):
        verify.check(DIFFUSE)


def test_the_gil_is_released(diffuse):
    """Another Python thread keeps running while a check computes."""
    import threading
    import time

    done = threading.Event()
    worker = threading.Thread(target=lambda: (verify.chi2(diffuse, WO, samples=2_000_000), done.set()))
    ticks = 0
    worker.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert ticks >= 10
