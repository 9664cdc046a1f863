"""gonio — a physically based reflectance toolkit.

Reflection models (BSDFs) with ``f``, ``sample`` and ``pdf``, described with Mitsuba 3's plugin names and
parameters, evaluated in Rust over numpy arrays; Mitsuba 3 scenes (XML files or scene dictionaries)
rendered to numpy arrays; images read and written as EXR, PNG or HDR.

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

import enum
import json
from typing import Any, Mapping, Union

from . import _gonio, verify
from ._gonio import (
    Bsdf,
    BsdfSample,
    Scene,
    SceneError,
    SpecError,
    examples,
    load_dict,
    load_scene,
    look_at,
    plugins,
    read_image,
    write_image,
)

__version__: str = _gonio.__version__

__all__ = [
    "Bsdf",
    "BsdfFlags",
    "BsdfSample",
    "Scene",
    "SceneError",
    "SpecError",
    "__version__",
    "examples",
    "load_bsdf",
    "load_dict",
    "load_scene",
    "look_at",
    "plugins",
    "read_image",
    "verify",
    "write_image",
]


class BsdfFlags(enum.IntFlag):
    """The lobes of a model (``Bsdf.flags``) or of one sample (``BsdfSample.flags``)."""

    NONE = 0
    REFLECTION = _gonio.FLAG_REFLECTION
    TRANSMISSION = _gonio.FLAG_TRANSMISSION
    DIFFUSE = _gonio.FLAG_DIFFUSE
    GLOSSY = _gonio.FLAG_GLOSSY
    DELTA = _gonio.FLAG_DELTA


Spec = Union[str, bytes, Mapping[str, Any]]


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
    if isinstance(spec, Mapping):
        try:
            text = json.dumps(spec, default=_to_json)
        except (TypeError, ValueError) as e:
            raise SpecError(f"$: the description cannot be written as JSON: {e}") from None
        return _gonio.from_json(text)
    if isinstance(spec, str):
        if spec.lstrip().startswith("<"):
            return _gonio.from_xml(spec, source)
        return _gonio.from_json(spec)
    raise TypeError(f"load_bsdf expects a dict, a JSON string or an XML string, got {type(spec).__name__}")


def _to_json(value: Any) -> Any:
    """Let numpy values and tuples inside a dict spec be written as JSON numbers and lists."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (tuple, set)):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not a number, string, list or dict")
