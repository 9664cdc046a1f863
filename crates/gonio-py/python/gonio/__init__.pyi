"""Type stub of the public API of gonio (the compiled part lives in gonio._gonio)."""

import enum
from typing import Any, Mapping, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import verify as verify

__version__: str

ArrayLike = npt.ArrayLike
Spec = Union[str, bytes, Mapping[str, Any]]

class SpecError(ValueError):
    """A plugin description gonio cannot build; the message starts with where the problem is."""

class BsdfFlags(enum.IntFlag):
    NONE = 0
    REFLECTION = 1
    TRANSMISSION = 2
    DIFFUSE = 4
    GLOSSY = 8
    DELTA = 16

class BsdfSample:
    """Arrays with one row per sample; squeezed (shape (3,) / numpy scalars) for a single `wo`."""

    @property
    def wi(self) -> npt.NDArray[np.float32]: ...
    @property
    def f(self) -> npt.NDArray[np.float32]: ...
    @property
    def pdf(self) -> npt.NDArray[np.float32]: ...
    @property
    def weight(self) -> npt.NDArray[np.float32]: ...
    @property
    def flags(self) -> npt.NDArray[np.uint32]: ...
    @property
    def eta(self) -> npt.NDArray[np.float32]: ...
    @property
    def valid(self) -> npt.NDArray[np.bool_]: ...
    def __len__(self) -> int: ...

class Bsdf:
    """A reflection model; build one with `load_bsdf`."""

    @property
    def flags(self) -> int: ...
    @property
    def plugin(self) -> str: ...
    @property
    def spec(self) -> str: ...
    def f(self, wo: ArrayLike, wi: ArrayLike, *, normalize: bool = False) -> npt.NDArray[np.float32]:
        """f(wo, wi) in 1/sr without the cosine: shape (N, 3), or (3,) for two (3,) directions."""
    def pdf(self, wo: ArrayLike, wi: ArrayLike, *, normalize: bool = False) -> npt.NDArray[np.float32]:
        """Solid-angle pdf of `sample` (smooth lobes): shape (N,), or a scalar for two (3,) directions."""
    def sample(self, wo: ArrayLike, uc: ArrayLike, u: ArrayLike, *, normalize: bool = False) -> BsdfSample:
        """Sample wi given wo ((3,) or (N, 3)), uc (scalar or (N,)) and u ((2,) or (N, 2)) in [0, 1]."""
    def albedo(self, wo: ArrayLike, *, samples: int = 100_000, seed: int = 0, normalize: bool = False) -> npt.NDArray[np.float32]:
        """Directional albedo by Monte Carlo: shape (N, 3), or (3,) for a single wo."""
    def __eq__(self, other: object) -> bool: ...

def load_bsdf(spec: Spec, *, source: str = "<string>") -> Bsdf:
    """Build a model from a Mitsuba-style dict, a JSON string or an XML string (starting with '<')."""

def plugins() -> Tuple[str, ...]:
    """The plugin names gonio understands."""

def examples() -> Tuple[str, ...]:
    """Example JSON specs per plugin, as used by `gonio check --all`."""
