"""gonio — a physically based reflectance toolkit.

Reflection models (BSDFs) with ``f``, ``sample`` and ``pdf``, described with Mitsuba 3's plugin names and
parameters, evaluated in Rust over numpy arrays; Mitsuba 3 scenes (XML files or scene dictionaries)
rendered to numpy arrays; lit-sphere previews and parameter sweeps of a material (``preview``); images read
and written as EXR, PNG or HDR.

Conventions
-----------
- ``wo`` (towards the viewer) and ``wi`` (towards the light) point *away* from the surface, are unit length
  and are given in the local shading frame, normal = +z.
- ``f(wo, wi)`` excludes the cosine. Mitsuba's ``eval`` includes it:
  ``mitsuba.eval(si.wi=a, wo=b) == gonio f(a, b) * |cos θ(b)|``.
- ``sample`` returns ``weight = f * |cos θi| / pdf``; for delta lobes ``pdf`` is the probability of having
  chosen the lobe.

Example
-------
>>> import gonio
>>> gold = gonio.load_bsdf({"type": "conductor", "material": "none"})
>>> s = gold.sample([0.6, 0.0, 0.8], 0.5, [0.5, 0.5])
>>> s.wi.tolist()
[-0.6000000238418579, 0.0, 0.800000011920929]
>>> gonio.load_bsdf({"type": "diffuse", "reflectance": 0.5}).albedo([0, 0, 1], samples=1000).round(3).tolist()
[0.5, 0.5, 0.5]
"""

from __future__ import annotations

# The helpers below are imported under private names: ``import gonio`` leaves only gonio's API in the
# package's namespace (``dir(gonio)``), not ``enum``, ``json`` or typing's names.
import enum as _enum
import json as _json
from typing import Any as _Any, Mapping as _Mapping, Optional as _Optional, Sequence as _Sequence, Union as _Union

from . import _gonio, verify
from .explorer import explore
from ._preview import PreviewResult, preview
from ._gonio import (
    AlbedoData,
    Bsdf,
    BsdfSample,
    LobeData,
    Scene,
    SceneError,
    SliceData,
    SpecError,
    develop,
    examples,
    fit_models,
    load_dict,
    load_scene,
    look_at,
    plugins,
    read_image,
    scene_files,
    write_image,
)

__version__: str = _gonio.__version__

__all__ = [
    "AlbedoData",
    "Bsdf",
    "BsdfFlags",
    "BsdfSample",
    "LobeData",
    "PreviewResult",
    "Scene",
    "SceneError",
    "SliceData",
    "SpecError",
    "__version__",
    "albedo_data",
    "develop",
    "examples",
    "explore",
    "fit",
    "fit_models",
    "load_bsdf",
    "load_dict",
    "load_scene",
    "lobe_data",
    "look_at",
    "plot",
    "plugins",
    "preview",
    "read_image",
    "scene_files",
    "slice_data",
    "verify",
    "write_image",
]


class BsdfFlags(_enum.IntFlag):
    """The lobes of a model (``Bsdf.flags``) or of one sample (``BsdfSample.flags``)."""

    NONE = 0
    REFLECTION = _gonio.FLAG_REFLECTION
    TRANSMISSION = _gonio.FLAG_TRANSMISSION
    DIFFUSE = _gonio.FLAG_DIFFUSE
    GLOSSY = _gonio.FLAG_GLOSSY
    DELTA = _gonio.FLAG_DELTA


Spec = _Union[str, bytes, _Mapping[str, _Any]]


def load_bsdf(spec: Spec, *, source: str = "<string>") -> Bsdf:
    """Build a reflection model from a plugin description.

    ``spec`` is one of

    - a dict in Mitsuba's dictionary form, e.g. ``{"type": "conductor", "material": "Au"}``; colours may
      be lists (``[0.2, 0.5, 0.8]``) or ``{"type": "rgb", "value": [...]}``, nested BSDFs are nested dicts;
    - the same as a JSON string;
    - an XML string (starting with ``<``) holding one ``<bsdf type="...">`` element, as in a Mitsuba scene.
      ``source`` names it in error messages.

    Raises ``gonio.SpecError`` (a ``ValueError``) with gonio's message, which starts with where the
    problem is (``$.alpha: parameter ...``), for unknown types or parameters, out-of-range values and text
    that does not parse.
    """
    if isinstance(spec, bytes):
        spec = spec.decode("utf-8")
    if isinstance(spec, _Mapping):
        try:
            text = _json.dumps(spec, default=_to_json)
        except (TypeError, ValueError) as e:
            raise SpecError(f"$: the description cannot be written as JSON: {e}") from None
        return _gonio.from_json(text)
    if isinstance(spec, str):
        if spec.lstrip().startswith("<"):
            return _gonio.from_xml(spec, source)
        return _gonio.from_json(spec)
    raise TypeError(f"load_bsdf expects a dict, a JSON string or an XML string, got {type(spec).__name__}")


def _to_json(value: _Any) -> _Any:
    """Let numpy values and tuples inside a dict spec be written as JSON numbers and lists."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (tuple, set)):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not a number, string, list or dict")


def fit(target: _Any, models: _Sequence[str], strata: int = 12) -> _Any:
    """Fit each of ``models`` (names from ``fit_models()``) to ``target`` — a ``Bsdf``, a measured file's path
    (MERL ``.binary``, RGL ``.bsdf``) or anything ``load_bsdf`` takes — as ``gonio fit`` does (the metric of
    Ngan et al. 2005, Levenberg–Marquardt from several starts). Returns per model a dict: ``model``,
    ``values``, ``spec`` (JSON text), ``error``, ``relative_error``, ``per_angle``, ``seconds``, and ``xml``,
    the file ``gonio fit -o`` writes. ``gonio.distributed.fit`` runs many on a Ray cluster."""
    source = "<bsdf>"
    if isinstance(target, str) and _gonio.measured_plugin(target):
        source, target = target, {"type": _gonio.measured_plugin(target), "filename": target}
    return _gonio.fit(_as_bsdf(target), list(models), strata=strata, source=source)


# ---------------------------------------------------------------------------------------------------------
# Plot data (gonio::plot, the numbers `gonio plot` draws) and gonio.plot (matplotlib, optional).

ModelLike = _Union[Bsdf, str, bytes, _Mapping[str, _Any]]


def _as_bsdf(model: ModelLike) -> Bsdf:
    return model if isinstance(model, Bsdf) else load_bsdf(model)


def lobe_data(bsdf: ModelLike, theta_o: float, *, samples: int = 721, grid_theta: int = 31, grid_phi: int = 72) -> LobeData:
    """The lobe of a model seen from θo (degrees, in [0, 90)): f·|cos θi| in sr⁻¹.

    ωo = (sin θo, 0, cos θo) lies in the xz-plane. ``angles`` (``samples`` values, degrees, evenly over
    [−180°, 180°]) parameterise two planes:

    - ``incidence``: the plane of incidence, ωi = (sin a, 0, cos a); a is the signed polar angle of ωi,
      the mirror direction ωr is at a = −θo, |a| > 90° is below the surface;
    - ``perpendicular``: the plane through ωr perpendicular to it, ωi = cos a·ωr + sin a·ŷ (a is the
      angle from ωr; there cos θi = cos a·cos θo).

    ``grid`` (shape ``(grid_theta, grid_phi, 4)``) covers ωi = (sin θ cos φ, sin θ sin φ, cos θ) with θ in
    ``grid_theta`` (0°…90°, or 0°…180° for models that transmit) and φ in ``grid_phi`` ([0°, 360°)); 0 for
    either count skips the grid. Value arrays are float32 with a last axis of four channels: r, g, b and
    the Rec. 709 luminance. A Lambertian surface of albedo ρ gives ρ/π·cos a in the plane of incidence.
    ``bsdf`` is a ``Bsdf`` or anything ``load_bsdf`` accepts. Bad arguments raise ``ValueError``.
    """
    return _gonio.lobe_data(_as_bsdf(bsdf), theta_o, samples=samples, grid_theta=grid_theta, grid_phi=grid_phi)


def slice_data(bsdf: ModelLike, phi_d: float = 90.0, *, theta_h: int = 90, theta_d: int = 90) -> SliceData:
    """f (sr⁻¹) on MERL's θh × θd grid at one φd (degrees, in [0, 360)): the image slices of the MERL
    papers and of Disney's BRDF Explorer, in Rusinkiewicz's half/difference angles.

    Column i has θh = 90°·((i + ½)/theta_h)² (square-root spacing), row j has θd = 90°·(j + ½)/theta_d;
    at 90 × 90 these are the centres of a MERL table's cells, and the directions are built exactly as
    ``gonio measure`` builds them, so the slice of a MERL table at φd = k + ½ reads its entries.
    ``values`` has shape ``(theta_d, theta_h, 4)`` (channels r, g, b, lum), NaN where ωo or ωi would be
    below the horizon.
    """
    return _gonio.slice_data(_as_bsdf(bsdf), phi_d, theta_h=theta_h, theta_d=theta_d)


def albedo_data(bsdf: ModelLike, *, angles: int = 30, samples: int = 16_384, seed: int = 0) -> AlbedoData:
    """The directional albedo ∫ f |cos θi| dωi against θo, by gonio's energy check (the model's own
    sampling, stratified; transmitted energy counted).

    ``theta_o`` holds ``angles`` midpoints 90°·(k + ½)/angles (degrees), ``albedo`` has shape
    ``(angles, 4)`` (channels r, g, b, lum); the k-th angle uses ``samples`` samples and seed ``seed + k``,
    so the result equals ``gonio plot --kind albedo -o data.csv`` for the same numbers.
    """
    return _gonio.albedo_data(_as_bsdf(bsdf), angles=angles, samples=samples, seed=seed)


def plot(bsdfs: _Any, kind: str = "polar", theta_o: _Optional[float] = None, *, log: bool = False, channel: str = "lum",
         labels: _Optional[_Sequence[str]] = None, phi_d: float = 90.0, angles: int = 30, samples: int = 16_384) -> _Any:
    """Draw one or more models with matplotlib, from the same numbers as ``gonio plot``; returns the figure.

    ``bsdfs`` is one model or a list (``Bsdf`` objects or anything ``load_bsdf`` accepts); ``kind`` is

    - ``"polar"``: f·cos θi in the plane of incidence and the perpendicular plane (``theta_o`` required);
    - ``"3d"``: the lobe f·cos θi over all incident directions (``theta_o`` required);
    - ``"slice"``: f on the θh × θd grid at ``phi_d``, one panel per model;
    - ``"albedo"``: the directional albedo against θo (``angles``, ``samples``; ``theta_o`` is marked).

    ``log`` uses a logarithmic scale (four decades, like the CLI); ``channel`` is ``"r"``, ``"g"``, ``"b"``
    or ``"lum"``; ``labels`` name the models in the legend (default: their plugin names).
    Needs matplotlib (``pip install matplotlib``); without it this raises ``ImportError`` saying so.
    """
    try:
        from . import _plot
    except ImportError as e:  # matplotlib (or one of its parts) is missing
        raise ImportError(f"gonio.plot needs matplotlib, which could not be imported ({e}); install it with `pip install matplotlib`") from e
    return _plot.plot(bsdfs, kind, theta_o, log=log, channel=channel, labels=labels, phi_d=phi_d, angles=angles, samples=samples)


# `from __future__ import annotations` binds the name `annotations` here; it is not part of gonio's API.
del annotations
