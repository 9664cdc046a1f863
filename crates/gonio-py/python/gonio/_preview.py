"""Lit-sphere previews: ``gonio.preview`` and what ``gonio.distributed.preview`` shares with it.

A sweep is expanded, checked, labelled and rendered by the core (``gonio::preview::Sweep``, the code behind
``gonio preview --grid``); this module only turns Python values into its input, renders point after point
and collects the images. ``gonio.distributed.preview`` renders the same points, one Ray task each, through
the same ``_gonio._render_preview``: the same images, bit for bit.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
from pathlib import Path
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _gonio

Grid = Optional[Mapping[str, Sequence[Any]]]


@dataclasses.dataclass
class PreviewResult:
    """The spheres of a preview, one per grid point in row-major order (the last parameter varies
    fastest): ``images`` (size, size, 3) float32 linear RGB; ``points`` each image's parameter values
    (taken from ``grid``); ``labels`` (``"alpha=0.05, material=Au"``); ``columns`` of the contact sheet
    (the last parameter's values); non-finite samples dropped; ``seconds`` in all."""

    images: List[np.ndarray]
    points: List[Dict[str, Any]]
    labels: List[str]
    columns: int
    nonfinite: int = 0
    seconds: float = 0.0

    def sheet(self, exposure: float = 0.0) -> np.ndarray:
        """The contact sheet: rows of ``columns`` spheres scaled by 2^``exposure`` with thin dark gaps, the
        image ``gonio preview`` writes."""
        return _gonio._contact_sheet(self.images, self.columns, exposure)

    def write(self, output: Optional[Union[str, os.PathLike]] = None, output_dir: Optional[Union[str, os.PathLike]] = None,
              exposure: float = 0.0, ext: str = "exr") -> List[Path]:
        """Write the contact sheet to ``output`` and/or each sphere to ``output_dir`` as
        ``<index>_<label>.<ext>`` (e.g. ``001_alpha=0.05_material=Cu.exr``), scaled by 2^``exposure``,
        atomically. Returns the files written."""
        written = []
        if output is not None:
            _gonio.write_image(str(output), self.sheet(exposure))
            written.append(Path(output))
        if output_dir is not None:
            folder = Path(output_dir)
            folder.mkdir(parents=True, exist_ok=True)
            for i, (image, label) in enumerate(zip(self.images, self.labels)):
                name = "_".join([f"{i:03d}"] + ([label.replace(", ", "_").replace(os.sep, "-")] if label else []))
                path = folder / f"{name}.{ext.lstrip('.')}"
                _gonio.write_image(str(path), _gonio._contact_sheet([image], 1, exposure))
                written.append(path)
        return written


def _to_json(value: Any) -> Any:
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, (tuple, set)):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not a number, string, list or dict")


@dataclasses.dataclass
class Sweep:
    """A checked sweep as the core takes it (spec and grid as text) and what it reported."""

    spec: str
    source: str
    grid: str
    labels: List[str]
    points: List[Dict[str, Any]]
    columns: int

    @staticmethod
    def of(spec: Any, grid: Grid, source: str = "<string>") -> "Sweep":
        """Check `spec` (a dict, JSON or XML text, or a ``Bsdf``) swept over `grid` (parameter → values);
        every point's material is built, so a bad value raises ``SpecError`` naming it before any render."""
        if isinstance(spec, bytes):
            spec = spec.decode("utf-8")
        if isinstance(spec, _gonio.Bsdf):
            spec = spec.spec
        elif isinstance(spec, Mapping):
            try:
                spec = json.dumps(spec, default=_to_json)
            except (TypeError, ValueError) as e:
                raise _gonio.SpecError(f"$: the description cannot be written as JSON: {e}") from None
        elif not isinstance(spec, str):
            raise TypeError(f"preview expects a dict, a JSON or XML string or a gonio.Bsdf, got {type(spec).__name__}")
        if grid is None:
            grid = {}
        if not isinstance(grid, Mapping):
            raise TypeError(
                f"`grid` must be a dict of parameter name → list of values, e.g. {{\"alpha\": [0.05, 0.1]}}, got {type(grid).__name__}")
        axes = []
        for name, values in grid.items():
            if not isinstance(name, str):
                raise TypeError(f"`grid` keys must be parameter names (strings), got {name!r}")
            try:
                axes.append([name, json.loads(json.dumps(values, default=_to_json))])
            except (TypeError, ValueError) as e:
                raise _gonio.SpecError(f"grid: parameter `{name}`: the values cannot be written as JSON: {e}") from None
        text = json.dumps(axes)
        labels, indices, columns = _gonio._preview_sweep(spec, text, source)
        given = {name: list(grid[name]) for name, _ in axes}  # the caller's own objects (numpy scalars, tuples, …)
        points = [{name: given[name][j] for name, j in zip(given, idx)} for idx in indices]
        return Sweep(spec, source, text, labels, points, columns)

    def render(self, point: int, lighting: Any, settings: "Settings", threads: Optional[int] = None, mode: str = "rgb") -> Tuple[np.ndarray, int]:
        return _gonio._render_preview(self.spec, self.grid, point, lighting, settings.size, settings.spp, settings.seed,
                                      threads=threads, source=self.source, mode=mode)


@dataclasses.dataclass
class Settings:
    """A preview's image size, samples per pixel, seed and exposure, checked."""

    size: int
    spp: int
    seed: int
    exposure: float

    def __post_init__(self) -> None:
        for name, lo, hi in (("size", 1, 4096), ("spp", 1, 2**32 - 1), ("seed", 0, 2**64 - 1)):
            v = getattr(self, name)
            if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or not lo <= v <= hi:
                raise ValueError(f"`{name}` must be an integer in [{lo}, {hi}], got {v!r}")
        if not (isinstance(self.exposure, (int, float, np.floating)) and math.isfinite(self.exposure) and abs(self.exposure) <= 30):
            raise ValueError(f"`exposure` must be a number in [-30, 30], got {self.exposure!r}")


def preview(
    spec: Any,
    grid: Grid = None,
    *,
    env: Any = None,
    light: Optional[Sequence[float]] = None,
    size: int = 128,
    spp: int = 64,
    seed: int = 0,
    threads: Optional[int] = None,
    output: Optional[Union[str, os.PathLike]] = None,
    output_dir: Optional[Union[str, os.PathLike]] = None,
    exposure: float = 0.0,
    source: str = "<string>",
    mode: str = "rgb",
) -> PreviewResult:
    """Render lit spheres of a material (``gonio preview``): one per point of ``grid``, the product of the
    values of its parameters in row-major order, e.g. ``grid={"alpha": [0.05, 0.1, 0.3], "material":
    ["Au", "Cu"]}`` gives six spheres, a row per ``alpha`` and a column per ``material``.

    ``spec`` is a dict, JSON or XML text (textures allowed; ``source`` names XML in errors) or a ``Bsdf``;
    a grid value replaces the spec's parameter of that name (top-level parameters only). Lighting: ``env``
    — ``None`` or ``"gradient"`` (the built-in sky), ``"constant"`` (uniform radiance 1: the white
    furnace), a lat-long image file's path or an (H, W, 3) float32 array — or ``light``, a direction
    (x, y, z) towards a directional light of irradiance π (+x right, +y up, +z towards the viewer) with a
    dim ambient. Each sphere is ``size`` × ``size`` pixels at ``spp`` samples per pixel with seed ``seed``,
    rendered with ``threads`` threads (default: all cores), in ``mode`` ``"rgb"`` or ``"spectral"`` (three
    sampled wavelengths per path, as ``gonio render --mode spectral``; docs/spectral.md).

    Returns a ``PreviewResult`` (images, their grid points and labels, ``sheet()`` the contact sheet).
    ``output`` writes the contact sheet, ``output_dir`` each sphere (both scaled by 2^``exposure``).
    Every point's material is built before the first render: a bad grid raises ``SpecError`` (or
    ``TypeError``) naming the parameter and what was expected. ``gonio.distributed.preview`` renders the
    same spheres on a Ray cluster, one task each, to the same images bit for bit.
    """
    start = time.perf_counter()
    settings = Settings(size, spp, seed, exposure)
    sweep = Sweep.of(spec, grid, source)
    lighting = _gonio.PreviewLighting(env, None if light is None else tuple(light))
    images, nonfinite = [], 0
    for i in range(len(sweep.labels)):
        image, dropped = sweep.render(i, lighting, settings, threads, mode)
        images.append(image)
        nonfinite += dropped
    result = PreviewResult(images, sweep.points, sweep.labels, sweep.columns, nonfinite, time.perf_counter() - start)
    result.write(output, output_dir, exposure)
    return result
