"""Type stub of the public API of gonio (the compiled part lives in gonio._gonio)."""

import enum
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import verify as verify

__version__: str

ArrayLike = npt.ArrayLike
Spec = Union[str, bytes, Mapping[str, Any]]

class SpecError(ValueError):
    """A plugin description gonio cannot build; the message starts with where the problem is."""

class SceneError(ValueError):
    """A scene gonio cannot load (XML or dictionary that does not parse, an unknown or unsupported plugin
    or parameter, a value out of range, a malformed mesh or image it refers to). The message starts with
    where the problem is: `file:line:col`, or a dictionary path such as `$.ball.bsdf.alpha`."""

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
    def f(self, wo: ArrayLike, wi: ArrayLike, *, normalize: bool = False, wavelengths: Optional[ArrayLike] = None) -> npt.NDArray[np.float32]:
        """f(wo, wi) in 1/sr without the cosine: shape (N, 3), or (3,) for two (3,) directions. With
        `wavelengths` (nm, scalar or (N,)): the value at each row's wavelength as spectral mode renders
        the model, shape (N,)."""
    def pdf(self, wo: ArrayLike, wi: ArrayLike, *, normalize: bool = False, wavelengths: Optional[ArrayLike] = None) -> npt.NDArray[np.float32]:
        """Solid-angle pdf of `sample` (smooth lobes): shape (N,), or a scalar for two (3,) directions;
        with `wavelengths`, the model's at each row's wavelength."""
    def sample(self, wo: ArrayLike, uc: ArrayLike, u: ArrayLike, *, normalize: bool = False, wavelengths: Optional[ArrayLike] = None) -> BsdfSample:
        """Sample wi given wo ((3,) or (N, 3)), uc (scalar or (N,)) and u ((2,) or (N, 2)) in [0, 1]; with
        `wavelengths`, each row at its wavelength (f and weight then one number per row)."""
    def at_wavelength(self, nm: float) -> "Bsdf":
        """The model at one wavelength (nm, in [360, 830]) as spectral mode renders it there (all three
        channels at it), for `gonio.verify`; SpecError where spectral mode refuses the model."""
    def albedo(self, wo: ArrayLike, *, samples: int = 100_000, seed: int = 0, normalize: bool = False) -> npt.NDArray[np.float32]:
        """Directional albedo by Monte Carlo: shape (N, 3), or (3,) for a single wo."""
    def __eq__(self, other: object) -> bool: ...

def load_bsdf(spec: Spec, *, source: str = "<string>") -> Bsdf:
    """Build a model from a Mitsuba-style dict, a JSON string or an XML string (starting with '<')."""

def plugins() -> Tuple[str, ...]:
    """The plugin names gonio understands."""

def examples() -> Tuple[str, ...]:
    """Example JSON specs per plugin, as used by `gonio check --all`."""

PathLike = Union[str, "os.PathLike[str]"]

class Scene:
    """A renderable scene; build one with `load_scene` or `load_dict`."""

    @property
    def channels(self) -> List[str]:
        """Names of the channels `render` returns: R, G, B, then an `aov` integrator's (`image.R`, …, `nn.X`, …)."""
    @property
    def mode(self) -> str:
        """"rgb" or "spectral": how the scene was loaded (`load_scene(..., mode=...)`)."""
    @property
    def width(self) -> int:
        """Image width in pixels (the film's `width`)."""
    @property
    def height(self) -> int:
        """Image height in pixels (the film's `height`)."""
    @property
    def spp(self) -> int:
        """Samples per pixel `render` takes by default (the sampler's `sample_count`)."""
    @property
    def seed(self) -> int:
        """The seed `render` takes by default (the sampler's `seed`)."""
    @property
    def shape_count(self) -> int: ...
    @property
    def light_count(self) -> int: ...
    @property
    def primitive_count(self) -> int: ...
    @property
    def source(self) -> str:
        """The file name, or "<dict>"."""
    @property
    def warnings(self) -> List[str]:
        """What the loader accepted but approximates (also issued as UserWarnings at load time)."""
    def render(
        self, spp: Optional[int] = None, seed: Optional[int] = None, threads: Optional[int] = None, progress: bool = True
    ) -> npt.NDArray[np.float32]:
        """Render to linear RGB of shape (height, width, 3), float32, top row first; with an `aov` integrator
        (height, width, C), its further channels after the RGB, named by `channels` (Mitsuba's film order).

        `spp`/`seed` default to the scene's sampler; the image depends on the seed only (not on `threads`)
        and equals `gonio render --seed` bit for bit. `threads` defaults to all cores. A progress bar goes to
        stderr when it is a terminal (tqdm's widget in Jupyter). The GIL is released; Ctrl-C stops the
        render promptly and raises KeyboardInterrupt.
        """
    def render_samples(
        self, first: int, count: int, seed: Optional[int] = None, threads: Optional[int] = None, progress: bool = False
    ) -> Dict[str, Any]:
        """The unnormalised sums of the samples first … first + count − 1 of every pixel: `sum` (H, W, C)
        float64 (C as in `render`), `weight` (H, W) float64 or None (box filter), `first`, `spp`, `nonfinite`, `seconds`.
        Parts of disjoint ranges add up; `develop(sum, weight, spp)` makes the image (docs/distributed.md)."""

def develop(sum: npt.NDArray[np.float64], weight: Optional[npt.NDArray[np.float64]], spp: int) -> npt.NDArray[np.float32]:
    """The image of summed samples holding `spp` samples per pixel (the development `Scene.render` uses)."""

def scene_files(path: PathLike, **defines: Any) -> List[str]:
    """The files a Mitsuba 3 XML scene is read from: the file, its includes, then every asset it names."""

def fit(target: Any, models: Sequence[str], strata: int = 12) -> List[Dict[str, Any]]:
    """Fit each model (`fit_models()`) to `target` (a Bsdf, a measured file's path, or a spec), as `gonio fit`:
    per model a dict with `model`, `values`, `spec`, `error`, `relative_error`, `per_angle`, `seconds`, `xml`."""

def fit_models() -> List[Tuple[str, str]]:
    """(name, description) of every model `fit` knows, as `gonio fit --list`."""

def load_scene(path: PathLike, *, mode: str = "rgb", **defines: Any) -> Scene:
    """Load a Mitsuba 3 XML scene; `defines` override `<default>` parameters like `-D name=value`.
    `mode` is "rgb" or "spectral" (three sampled wavelengths per path), as `gonio render --mode`.

    Raises FileNotFoundError for a missing file, SceneError for anything wrong inside it."""

def load_dict(scene: Mapping[str, Any], *, mode: str = "rgb") -> Scene:
    """Build a scene from Mitsuba 3's scene dictionary ({"type": "scene", ...}, as `mitsuba.load_dict`).

    Plugins are dicts with a "type"; top-level keys are ids for {"type": "ref", "id": ...}; `to_world` is a
    4×4 matrix (nested list, numpy array, or an object with `.matrix` such as mitsuba.ScalarTransform4f).
    Raises SceneError naming the dictionary path of the problem (`$.ball.bsdf.alpha`)."""

def look_at(origin: ArrayLike, target: ArrayLike, up: ArrayLike = (0.0, 1.0, 0.0)) -> npt.NDArray[np.float64]:
    """The 4×4 camera-to-world matrix of Mitsuba's `<lookat>` (the one gonio's XML loader builds)."""

def read_image(path: PathLike) -> npt.NDArray[np.float32]:
    """Read EXR, HDR, PNG or JPEG as linear RGB of shape (height, width, 3), float32 (PNG/JPEG sRGB-decoded).

    Raises FileNotFoundError (or another OSError) when unreadable, ValueError when not a valid image."""

def write_image(path: PathLike, array: npt.ArrayLike) -> None:
    """Write linear RGB atomically: .exr float32, .png 8-bit sRGB (clamped), .hdr RGBE.

    `array`: float32/float64 of shape (height, width, 3) or (height, width). Raises ValueError for another
    shape, dtype or extension, FileNotFoundError when the directory does not exist."""

# Plot data: the numbers `gonio plot` draws. Value arrays are float32 with a last axis of 4 channels
# (r, g, b, Rec. 709 luminance); angles are float64 degrees.

ModelLike = Union[Bsdf, str, bytes, Mapping[str, Any]]

class LobeData:
    """f·|cos θi| (sr⁻¹) of a model seen from θo; see `lobe_data`."""

    @property
    def theta_o(self) -> float: ...
    @property
    def angles(self) -> npt.NDArray[np.float64]:
        """(samples,): the angle a of both planes, degrees, evenly over [−180°, 180°]."""
    @property
    def incidence(self) -> npt.NDArray[np.float32]:
        """(samples, 4): in the plane of incidence, ωi = (sin a, 0, cos a)."""
    @property
    def perpendicular(self) -> npt.NDArray[np.float32]:
        """(samples, 4): in the perpendicular plane, ωi = cos a·ωr + sin a·ŷ."""
    @property
    def grid_theta(self) -> npt.NDArray[np.float64]: ...
    @property
    def grid_phi(self) -> npt.NDArray[np.float64]: ...
    @property
    def grid(self) -> npt.NDArray[np.float32]:
        """(grid_theta, grid_phi, 4): over ωi = (sin θ cos φ, sin θ sin φ, cos θ)."""

class SliceData:
    """f (sr⁻¹) on MERL's θh × θd grid at one φd; see `slice_data`."""

    @property
    def phi_d(self) -> float: ...
    @property
    def theta_h(self) -> npt.NDArray[np.float64]:
        """(n_h,): 90°·((i + ½)/n_h)², square-root spacing."""
    @property
    def theta_d(self) -> npt.NDArray[np.float64]:
        """(n_d,): 90°·(j + ½)/n_d."""
    @property
    def values(self) -> npt.NDArray[np.float32]:
        """(n_d, n_h, 4); NaN where ωo or ωi is below the horizon."""

class AlbedoData:
    """The directional albedo against θo; see `albedo_data`."""

    @property
    def theta_o(self) -> npt.NDArray[np.float64]:
        """(angles,): 90°·(k + ½)/angles."""
    @property
    def albedo(self) -> npt.NDArray[np.float32]:
        """(angles, 4): ∫ f |cos θi| dωi."""

def lobe_data(bsdf: ModelLike, theta_o: float, *, samples: int = 721, grid_theta: int = 31, grid_phi: int = 72) -> LobeData:
    """The lobe f·|cos θi| seen from θo (degrees, in [0, 90)), ωo = (sin θo, 0, cos θo): in the plane of
    incidence (mirror direction at a = −θo), in the perpendicular plane through the mirror direction, and
    on a θ × φ grid (0 for either count: no grid). Raises ValueError for bad arguments."""

def slice_data(bsdf: ModelLike, phi_d: float = 90.0, *, theta_h: int = 90, theta_d: int = 90) -> SliceData:
    """f on MERL's θh × θd grid at φd (degrees, in [0, 360)); at 90 × 90 the cell centres of a MERL table."""

def albedo_data(bsdf: ModelLike, *, angles: int = 30, samples: int = 16_384, seed: int = 0) -> AlbedoData:
    """The directional albedo at θo = 90°·(k + ½)/angles, by gonio's energy check (seed + k per angle)."""

def plot(
    bsdfs: Union[ModelLike, Sequence[ModelLike]],
    kind: str = "polar",
    theta_o: Optional[float] = None,
    *,
    log: bool = False,
    channel: str = "lum",
    labels: Optional[Sequence[str]] = None,
    phi_d: float = 90.0,
    angles: int = 30,
    samples: int = 16_384,
) -> Any:
    """Draw models with matplotlib (kind: "polar", "3d", "slice" or "albedo"), from the same numbers as
    `gonio plot`; returns the matplotlib Figure. Raises ImportError naming matplotlib when it is missing."""

def explore(*models: Any, data: Optional[PathLike] = None, environment: Optional[PathLike] = None, threads: int = 2) -> Any:
    """The explorer as a Jupyter widget (anywidget); ``widget.bsdf`` is the selected model as edited."""
    ...

# Lit-sphere previews (`gonio preview`): one sphere per point of a parameter grid.

class PreviewResult:
    """The spheres of a preview, one per grid point in row-major order (the last parameter varies fastest)."""

    images: List[npt.NDArray[np.float32]]
    """(size, size, 3) float32 linear RGB per grid point."""
    points: List[Dict[str, Any]]
    """Each image's parameter values, as given in `grid`."""
    labels: List[str]
    """`"alpha=0.05, material=Au"` per image ("" without a grid)."""
    columns: int
    """Columns of the contact sheet: the number of values of the last parameter (1 without a grid)."""
    nonfinite: int
    seconds: float
    def sheet(self, exposure: float = 0.0) -> npt.NDArray[np.float32]:
        """The contact sheet (rows of `columns` spheres scaled by 2^exposure, thin dark gaps), as `gonio preview` writes."""
    def write(
        self, output: Optional[PathLike] = None, output_dir: Optional[PathLike] = None, exposure: float = 0.0, ext: str = "exr"
    ) -> List["os.PathLike[str]"]:
        """Write the contact sheet to `output` and/or each sphere to `output_dir/<index>_<label>.<ext>`."""

def preview(
    spec: Union[Bsdf, Spec],
    grid: Optional[Mapping[str, Sequence[Any]]] = None,
    *,
    env: Union[None, PathLike, npt.NDArray[np.float32]] = None,
    light: Optional[Sequence[float]] = None,
    size: int = 128,
    spp: int = 64,
    seed: int = 0,
    threads: Optional[int] = None,
    output: Optional[PathLike] = None,
    output_dir: Optional[PathLike] = None,
    exposure: float = 0.0,
    source: str = "<string>",
    mode: str = "rgb",
) -> PreviewResult:
    """Lit spheres of a material, one per point of `grid` (e.g. `{"alpha": [0.05, 0.3], "material": ["Au", "Cu"]}`:
    the product, row-major). `env`: None/"gradient" (the built-in sky), "constant", an image file or array;
    or `light`, a direction towards a directional light. Raises SpecError/TypeError naming a bad grid
    parameter before any render. `gonio.distributed.preview` gives the same images on a Ray cluster."""
