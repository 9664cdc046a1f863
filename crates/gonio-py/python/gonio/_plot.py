"""gonio.plot: matplotlib figures drawn from gonio's plot data (``gonio.lobe_data``, ``slice_data``,
``albedo_data``) — the same numbers as ``gonio plot`` on the command line. Imported by ``gonio.plot`` only
when called, so that gonio itself does not need matplotlib."""

from __future__ import annotations

from typing import Any, List, Optional, Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm, Normalize
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from . import Bsdf, albedo_data, load_bsdf, lobe_data, slice_data

CHANNELS = ("r", "g", "b", "lum")
CHANNEL_NAMES = {"r": "red channel", "g": "green channel", "b": "blue channel", "lum": "luminance"}
# Decades shown below the top of a logarithmic scale, as in the CLI.
LOG_DECADES = 4


def _models(bsdfs: Any) -> List[Bsdf]:
    if isinstance(bsdfs, (Bsdf, str, bytes, dict)):
        bsdfs = [bsdfs]
    models = [b if isinstance(b, Bsdf) else load_bsdf(b) for b in bsdfs]
    if not models:
        raise ValueError("gonio.plot needs at least one model")
    return models


def _labels(models: List[Bsdf], labels: Optional[Sequence[str]]) -> List[str]:
    if labels is not None:
        labels = list(labels)
        if len(labels) != len(models):
            raise ValueError(f"{len(labels)} labels for {len(models)} models: give one per model, or none")
        return labels
    names: List[str] = []
    for k, m in enumerate(models):
        seen = sum(1 for other in models[:k] if other.plugin == m.plugin)
        names.append(m.plugin if seen == 0 else f"{m.plugin} #{seen + 1}")
    return names


def _log_radius(values: np.ndarray, top: float) -> np.ndarray:
    """Radius in decades above top·10⁻⁴ (0 below it), the CLI's logarithmic radial scale."""
    hi = np.ceil(np.log10(top))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.log10(np.where(values > 0, values, np.nan)) - (hi - LOG_DECADES)
    return np.clip(np.nan_to_num(r, nan=0.0), 0.0, LOG_DECADES)


def _theta_required(kind: str, theta_o: Optional[float]) -> float:
    if theta_o is None:
        raise ValueError(f"kind={kind!r} needs theta_o, the viewing angle in degrees, in [0, 90)")
    return float(theta_o)


def plot(bsdfs: Any, kind: str, theta_o: Optional[float], *, log: bool, channel: str, labels: Optional[Sequence[str]],
         phi_d: float, angles: int, samples: int) -> Any:
    if channel not in CHANNELS:
        raise ValueError(f"unknown channel {channel!r}; expected one of {', '.join(CHANNELS)}")
    c = CHANNELS.index(channel)
    models = _models(bsdfs)
    names = _labels(models, labels)
    suffix = f", {CHANNEL_NAMES[channel]}" + (", log scale" if log else "")
    if kind == "polar":
        return _polar(models, names, _theta_required(kind, theta_o), c, log, suffix)
    if kind == "3d":
        return _lobe3d(models, names, _theta_required(kind, theta_o), c, log, suffix)
    if kind == "slice":
        return _slice(models, names, phi_d, c, log, suffix)
    if kind == "albedo":
        return _albedo(models, names, theta_o, c, log, suffix, angles, samples)
    raise ValueError(f"unknown kind {kind!r}; expected polar, 3d, slice or albedo")


def _polar(models, names, theta_o, c, log, suffix):
    lobes = [lobe_data(m, theta_o, grid_theta=0, grid_phi=0) for m in models]
    full = any(m.flags & 2 for m in models)  # BsdfFlags.TRANSMISSION: show the lower half too
    inside = np.ones_like(lobes[0].angles, dtype=bool) if full else np.abs(lobes[0].angles) <= 90
    top = max(float(np.nanmax(np.r_[l.incidence[inside, c], l.perpendicular[inside, c], 0.0])) for l in lobes)
    fig = plt.figure(figsize=(12, 5.5 if not full else 7))
    fig.suptitle(f"f·cos θi at θo = {theta_o:g}°{suffix}")
    for p, (title, key) in enumerate([("plane of incidence (angle = θi, signed)", "incidence"),
                                      ("perpendicular plane (angle from ωr)", "perpendicular")]):
        ax = fig.add_subplot(1, 2, p + 1, projection="polar")
        ax.set_theta_zero_location("N")
        ax.set_theta_direction(-1)
        if not full:
            ax.set_thetamin(-90)
            ax.set_thetamax(90)
        for k, (lobe, name) in enumerate(zip(lobes, names)):
            v = getattr(lobe, key)[:, c].astype(np.float64)
            r = _log_radius(v, top) if (log and top > 0) else v
            a = np.where(inside, np.radians(lobe.angles), np.nan)
            ax.plot(a, r, color=f"C{k}", lw=2, label=name)
        if log and top > 0:
            ticks = np.arange(LOG_DECADES + 1)
            hi = int(np.ceil(np.log10(top)))
            ax.set_rticks(ticks)
            ax.set_yticklabels([f"1e{hi - LOG_DECADES + t}" for t in ticks])
            ax.set_rlim(0, LOG_DECADES)
        else:
            ax.yaxis.set_major_locator(MaxNLocator(4))
        ax.tick_params(axis="y", labelsize=8)
        if key == "incidence":
            ax.plot([np.radians(theta_o)] * 2, [0, ax.get_rmax()], "k--", lw=1)
            ax.annotate("ωo", (np.radians(theta_o), ax.get_rmax()))
        ax.set_title(title, fontsize=11)
    handles, texts = fig.axes[0].get_legend_handles_labels()
    fig.legend(handles, texts, loc="lower center", ncol=min(len(texts), 4))
    return fig


def _lobe3d(models, names, theta_o, c, log, suffix):
    lobes = [lobe_data(m, theta_o, samples=2) for m in models]
    top = max(float(np.nanmax(np.r_[l.grid[..., c].ravel(), 0.0])) for l in lobes)
    fig = plt.figure(figsize=(8, 7))
    ax = fig.add_subplot(projection="3d")
    ax.set_title(f"f·cos θi at θo = {theta_o:g}°{suffix}: the lobe in 3-D")
    for k, (lobe, name) in enumerate(zip(lobes, names)):
        v = lobe.grid[..., c].astype(np.float64)
        r = _log_radius(v, top) / LOG_DECADES if (log and top > 0) else v / (top if top > 0 else 1.0)
        t = np.radians(lobe.grid_theta)[:, None]
        p = np.radians(np.r_[lobe.grid_phi, 360.0])[None, :]
        r = np.concatenate([r, r[:, :1]], axis=1)  # close the surface in φ
        ax.plot_surface(r * np.sin(t) * np.cos(p), r * np.sin(t) * np.sin(p), r * np.cos(t), color=f"C{k}",
                        alpha=0.6 if len(models) > 1 else 0.9, linewidth=0.2, edgecolor=f"C{k}")
    to = np.radians(theta_o)
    ax.plot([0, 1.1 * np.sin(to)], [0, 0], [0, 1.1 * np.cos(to)], "k--", lw=1)
    ax.text(1.15 * np.sin(to), 0, 1.15 * np.cos(to), "ωo")
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_zlim(-1 if any(m.flags & 2 for m in models) else 0, 1)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    # Surfaces have no legend handle of their own in every matplotlib version: patches stand in.
    ax.legend(handles=[Patch(color=f"C{k}", label=name) for k, name in enumerate(names)], loc="upper left")
    return fig


def _slice(models, names, phi_d, c, log, suffix):
    slices = [slice_data(m, phi_d) for m in models]
    # The colour scale tops out at the 99.5th percentile of f, as in the CLI: f grows without bound
    # towards grazing angles, and a few such cells would otherwise leave the image black.
    v = np.sort(np.concatenate([s.values[..., c].ravel() for s in slices]).astype(np.float64))
    v = v[np.isfinite(v) & (v > 0)]
    top = float(v[int(round((len(v) - 1) * 0.995))]) if len(v) else 1.0
    norm = LogNorm(vmin=10 ** (np.ceil(np.log10(top)) - LOG_DECADES), vmax=10 ** np.ceil(np.log10(top)), clip=True) if log \
        else Normalize(vmin=0.0, vmax=top)
    cmap = plt.get_cmap("inferno").with_extremes(bad="#d9d9d9")  # grey: below the horizon (NaN)
    fig, axes = plt.subplots(1, len(slices), figsize=(4.2 * len(slices) + 1.2, 4.6), squeeze=False)
    fig.suptitle(f"f (sr⁻¹) at φd = {phi_d:g}°{suffix}")
    for ax, s, name in zip(axes[0], slices, names):
        # Columns are evenly spaced in √θh (MERL's axis): draw against x = √(θh/90°).
        image = ax.imshow(np.ma.masked_invalid(s.values[..., c]), origin="lower", extent=(0, 1, 0, 90), aspect=1 / 90,
                          cmap=cmap, norm=norm, interpolation="nearest")
        ticks = np.array([0, 2, 10, 20, 45, 90])
        ax.set_xticks(np.sqrt(ticks / 90))
        ax.set_xticklabels([f"{t}°" for t in ticks])
        ax.set_yticks(np.arange(0, 91, 15))
        ax.set_xlabel("θh (square-root axis)")
        ax.set_ylabel("θd (degrees)")
        ax.set_title(name)
    fig.colorbar(image, ax=list(axes[0]), label="f (sr⁻¹)")
    return fig


def _albedo(models, names, theta_o, c, log, suffix, angles, samples):
    fig, ax = plt.subplots(figsize=(9, 5.5))
    for k, (m, name) in enumerate(zip(models, names)):
        d = albedo_data(m, angles=angles, samples=samples)
        ax.plot(d.theta_o, d.albedo[:, c], "o-", color=f"C{k}", ms=3, lw=2, label=name)
    ax.axhline(1.0, color="k", ls="--", lw=1)
    if theta_o is not None:
        ax.axvline(theta_o, color="k", ls=":", lw=1)
    ax.set_xlim(0, 90)
    ax.set_xticks(np.arange(0, 91, 15))
    if log:
        ax.set_yscale("log")
    else:
        ax.set_ylim(0, None)
    ax.set_xlabel("θo (viewing angle from the normal, degrees)")
    ax.set_ylabel("albedo")
    ax.set_title(f"directional albedo ∫ f cos θi dωi against θo{suffix}")
    ax.grid(alpha=0.3)
    ax.legend()
    return fig
