"""Type stub of gonio.verify: chi-square, reciprocity, energy, NaN/Inf sweep and the `gonio check` report."""

from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, overload

import numpy as np
import numpy.typing as npt

from . import Bsdf

ArrayLike = npt.ArrayLike

class Chi2Result:
    """The outcome of a chi-square test, with both histograms (counts per cell, rows = cos θi bins)."""

    @property
    def statistic(self) -> float: ...
    @property
    def dof(self) -> int: ...
    @property
    def p_value(self) -> float: ...
    @property
    def alpha(self) -> float: ...
    @property
    def passed(self) -> bool: ...
    @property
    def message(self) -> str: ...
    @property
    def observed(self) -> npt.NDArray[np.float64]:
        """Shape (theta_res, phi_res)."""
    @property
    def expected(self) -> npt.NDArray[np.float64]:
        """Shape (theta_res, phi_res)."""
    @property
    def delta_bins(self) -> List[Tuple[npt.NDArray[np.float64], float, float]]:
        """(wi, observed, expected) per delta lobe direction."""
    @property
    def no_sample_observed(self) -> float: ...
    @property
    def no_sample_expected(self) -> float: ...
    @property
    def pdf_mismatches(self) -> int: ...
    @property
    def domain(self) -> str: ...
    def __bool__(self) -> bool: ...

class ReciprocityResult:
    @property
    def max_rel_error(self) -> float: ...
    @property
    def worst(self) -> Optional[Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """(wo, wi) of the largest error, or None."""
    @property
    def compared(self) -> int: ...

class EnergyResult:
    @property
    def side(self) -> Literal["above", "below"]: ...
    @property
    def cos_theta_o(self) -> npt.NDArray[np.float64]:
        """Shape (angles,), signed (negative below)."""
    @property
    def albedo(self) -> npt.NDArray[np.float64]:
        """Shape (angles, 3)."""
    @property
    def white_furnace(self) -> npt.NDArray[np.float64]:
        """Shape (3,)."""
    @property
    def max_albedo(self) -> float: ...
    @property
    def max_albedo_cos_theta_o(self) -> float: ...

class SweepResult:
    @property
    def queries(self) -> int:
        """Queries run: at least those asked for, in whole chunks of 16384."""
    @property
    def bad(self) -> int: ...
    @property
    def first_bad(self) -> Optional[str]: ...

class CheckRow:
    @property
    def check(self) -> str: ...
    @property
    def measured(self) -> float: ...
    @property
    def limit(self) -> str: ...
    @property
    def passed(self) -> bool: ...
    @property
    def detail(self) -> str: ...
    def to_dict(self) -> Dict[str, Any]: ...

class Report:
    """`str(report)` is the table `gonio check` prints; `to_dict()` the object of `gonio check --json`."""

    @property
    def name(self) -> str: ...
    @property
    def passed(self) -> bool: ...
    @property
    def rows(self) -> List[CheckRow]: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def __bool__(self) -> bool: ...

def chi2(
    bsdf: Bsdf,
    wo: ArrayLike,
    samples: int = 1_000_000,
    theta_res: int = 40,
    phi_res: int = 80,
    significance: float = 0.01,
    tests: int = 1,
    seed: int = 0,
) -> Chi2Result:
    """Chi-square test of `bsdf.sample(wo, ·, ·)` against `bsdf.pdf(wo, ·)` over the sphere of wi (Šidák-corrected)."""

def reciprocity(bsdf: Bsdf, pairs: int = 100_000, seed: int = 0) -> ReciprocityResult:
    """Compare f(wo, wi) with f(wi, wo) (η-scaled across an interface) at random direction pairs."""

def energy(
    bsdf: Bsdf, angles: int = 32, samples: int = 65_536, seed: int = 0, side: Literal["above", "below"] = "above"
) -> EnergyResult:
    """Directional albedo at `angles` values of cos θo on one side, and the white furnace."""

def scatters_from_below(bsdf: Bsdf) -> bool:
    """Whether the model scatters light arriving from below (the sides `check` measures)."""

def sweep(bsdf: Bsdf, queries: int = 1_000_000, seed: int = 0) -> SweepResult:
    """Query f, pdf and sample with random and degenerate inputs; count non-finite or negative outputs."""

@overload
def check(bsdf: Bsdf, samples: int = 1_000_000, sweep: int = 1_000_000, seed: int = 0, family: Optional[int] = None, wavelengths: None = None) -> Report: ...
@overload
def check(bsdf: Bsdf, samples: int = 1_000_000, sweep: int = 1_000_000, seed: int = 0, family: Optional[int] = None, *, wavelengths: Sequence[float]) -> List[Report]:
    """Every check of `gonio check`, with the same figures for the same seed; `family`: the chi-square
    tests sharing the significance (Šidák; default: this model's, `chi2_tests(bsdf)`). With `wavelengths`
    (nm), one report per wavelength, on `bsdf.at_wavelength(nm)` (as `gonio check --wavelengths`)."""

def chi2_tests(bsdf: Bsdf) -> int:
    """How many chi-square tests `check` runs on `bsdf`."""

def expect_violation(report: Report, row: str) -> Optional[str]:
    """None when `report` shows the violation `row` (and nothing else fails), else what went wrong."""

def violations() -> List[Tuple[str, str]]:
    """The non-physical example specs `gonio check --all` runs, each with the row it must fail."""
