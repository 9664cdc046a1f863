"""gonio.verify — proofs of a model's physics that anyone can run on any ``Bsdf``.

The same harness backs ``cargo test``, the ``gonio check`` command and this module:

============  ====================================================================  =========================
check         what it proves                                                        limit (``gonio check``)
============  ====================================================================  =========================
chi2          ``sample`` draws directions with the density ``pdf`` claims            p > α (Šidák, α = 0.01)
consistency   ``weight == f·cos/pdf``, and ``f``, ``pdf`` agree with sampled values  1e-4 relative
reciprocity   f(ωo, ωi) = f(ωi, ωo) (η-scaled across an interface)                   1e-5 relative
energy        directional albedo ≤ 1 at every θo; the white furnace ≤ 1             1 + 1e-3
sweep         no NaN, Inf or negative value for random and degenerate inputs        0 bad queries
============  ====================================================================  =========================

Every function releases the GIL while it computes and returns a result object with the measured figures.

Example
-------
>>> import gonio
>>> bsdf = gonio.load_bsdf({"type": "diffuse"})
>>> r = gonio.verify.chi2(bsdf, [0.6, 0.0, 0.8], samples=100_000)
>>> r.passed, r.observed.shape
(True, (40, 80))
>>> bool(gonio.verify.check(bsdf, samples=100_000, sweep=10_000))
True
"""

from __future__ import annotations

from ._gonio import verify as _verify

Chi2Result = _verify.Chi2Result
ReciprocityResult = _verify.ReciprocityResult
EnergyResult = _verify.EnergyResult
SweepResult = _verify.SweepResult
CheckRow = _verify.CheckRow
Report = _verify.Report

chi2 = _verify.chi2
reciprocity = _verify.reciprocity
energy = _verify.energy
scatters_from_below = _verify.scatters_from_below
sweep = _verify.sweep


def check(bsdf, samples=1_000_000, sweep=1_000_000, seed=0, family=None, wavelengths=None):
    """Run every check of ``gonio check`` on ``bsdf`` (see ``_gonio.verify.check``) and return its
    ``Report``; with ``wavelengths`` (nm), run them on the model at each wavelength as spectral mode renders
    it (``bsdf.at_wavelength(nm)``, as ``gonio check --wavelengths``) and return one ``Report`` per
    wavelength, in order."""
    if wavelengths is None:
        return _verify.check(bsdf, samples, sweep, seed, family)
    return [_verify.check(bsdf.at_wavelength(float(nm)), samples, sweep, seed, family) for nm in wavelengths]

chi2_tests = _verify.chi2_tests
expect_violation = _verify.expect_violation
violations = _verify.violations

__all__ = [
    "CheckRow",
    "Chi2Result",
    "EnergyResult",
    "ReciprocityResult",
    "Report",
    "SweepResult",
    "check",
    "chi2",
    "chi2_tests",
    "energy",
    "expect_violation",
    "reciprocity",
    "scatters_from_below",
    "sweep",
    "violations",
]
