#!/usr/bin/env python3
"""The variance suite: gonio's image error against Mitsuba 3 `llvm_ad_rgb`'s at equal samples, for every BSDF
model the two share × every light type (issue 28).

A benchmark, never a test (`make test` runs a small subset as a statistical test: crates/gonio/tests/variance.rs
with references kept in crates/gonio/tests/data/variance/, made by `--write-test-data`).

The scenes are generated (one per light, written to bench/.cache/variance/): a 4 × 4 grid of unit spheres,
one BSDF each ([`BSDFS`]: every model shared with Mitsuba, with its defaults and rough / anisotropic settings),
in front of a diffuse wall, seen by an orthographic camera, lit by one light type ([`LIGHTS`]: envmap, constant,
point, spot, directional, area on a sphere, a disk, a rectangle and a mesh, and several lights of very
different power together); path tracer, max_depth 8. A cell of the table is one sphere's pixels in one scene.

For each scene: a reference by Mitsuba at `--ref-spp` (default 4096, cached in bench/.cache/ as the benchmark
suite caches its own), then `--seeds` renders of each renderer at `--spp` (default 64) with different seeds
(default 32: with 8, a cell whose error is one rare caustic sample read anything from 0.9 to 3.3 by the
seeds alone, 2026-12-06; docs/performance.md).
Cell value: gonio's MSE / Mitsuba's, each the mean over its renders of the mean squared error of the sphere's
pixels against the reference (and a second table with medians over the renders: see `print_table`).
Printed: the tables, their worst cells and geometric means, and per scene the
fireflies of each renderer (pixels brighter than 20× the reference, summed over the renders) and the image
means against the reference (a correctness check: an unbiased renderer's mean is the reference's within noise).

Targets (issue 28): every cell ≤ 1.3, geometric mean ≤ 1.0, no scene with more fireflies than Mitsuba's.

Usage: python bench/variance.py [--gonio PATH] [--spp 64] [--ref-spp 4096] [--seeds 32] [--lights GLOB ...]
                                [--json OUT] [--write-test-data]
"""

from __future__ import annotations

import argparse
import fnmatch
import json
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from render_vs_mitsuba import CACHE, ROOT, load_note, read_exr  # noqa: E402
from suite import SHARED, Scene, run_gonio, scene_key, start_mitsuba  # noqa: E402

OUT = CACHE / "variance"
TEST_DATA = ROOT / "crates" / "gonio" / "tests" / "data" / "variance"
ENVMAP = SHARED / "data" / "envmaps" / "venice_sunset_1k.hdr"
MESH = SHARED / "data" / "mitsuba-scenes" / "mitsuba-renderer__mitsuba-tutorials" / "scenes" / "meshes" / "sphere.obj"

# A firefly: a pixel (mean of its channels) brighter than this many times the reference's.
FIREFLY = 20.0

# The grid: GRID × GRID unit spheres, SPACING apart, centred on the origin in the plane z = 0; the
# orthographic view covers [-HALF, HALF]² of it.
GRID = 4
SPACING = 2.5
RADIUS = 1.0
HALF = 5.0

# (name, <bsdf> element): every model shared with Mitsuba 3, defaults and rough / anisotropic settings.
BSDFS: list[tuple[str, str]] = [
    ("diffuse", '<bsdf type="diffuse"/>'),
    ("roughconductor", '<bsdf type="roughconductor"/>'),
    ("roughconductor-ggx-cu", '<bsdf type="roughconductor"><string name="distribution" value="ggx"/>'
     '<float name="alpha" value="0.3"/><string name="material" value="Cu"/></bsdf>'),
    ("roughconductor-aniso", '<bsdf type="roughconductor"><float name="alpha_u" value="0.05"/>'
     '<float name="alpha_v" value="0.4"/></bsdf>'),
    ("roughconductor-ggx-aniso", '<bsdf type="roughconductor"><string name="distribution" value="ggx"/>'
     '<float name="alpha_u" value="0.4"/><float name="alpha_v" value="0.05"/><string name="material" value="Au"/></bsdf>'),
    ("conductor", '<bsdf type="conductor"><string name="material" value="Au"/></bsdf>'),
    ("dielectric", '<bsdf type="dielectric"/>'),
    ("thindielectric", '<bsdf type="thindielectric"><float name="int_ior" value="1.6"/></bsdf>'),
    ("roughdielectric", '<bsdf type="roughdielectric"/>'),
    ("roughdielectric-ggx", '<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>'
     '<float name="alpha" value="0.2"/><float name="int_ior" value="1.33"/></bsdf>'),
    ("plastic", '<bsdf type="plastic"/>'),
    ("plastic-nonlinear", '<bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.7, 0.15, 0.1"/>'
     '<boolean name="nonlinear" value="true"/></bsdf>'),
    ("roughplastic", '<bsdf type="roughplastic"/>'),
    ("roughplastic-ggx", '<bsdf type="roughplastic"><string name="distribution" value="ggx"/>'
     '<float name="alpha" value="0.3"/><rgb name="diffuse_reflectance" value="0.2, 0.5, 0.3"/>'
     '<boolean name="nonlinear" value="true"/></bsdf>'),
    ("blendbsdf", '<bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.5, 0.3"/></bsdf>'
     '<bsdf type="roughconductor"><string name="material" value="Cu"/><float name="alpha" value="0.15"/></bsdf></bsdf>'),
    ("twosided", '<bsdf type="twosided"><bsdf type="roughconductor"><string name="material" value="Al"/>'
     '<float name="alpha" value="0.15"/></bsdf></bsdf>'),
]


def _disk(x: float, y: float, z: float, radius: float, radiance: float) -> str:
    """A disk light at (x, y, z) of `radius`, facing the grid's centre (Mitsuba's disk emits along +z)."""
    return (f'<shape type="disk"><transform name="to_world"><scale value="{radius}"/>'
            f'<lookat origin="{x}, {y}, {z}" target="0, 0, 0" up="0, 1, 0"/></transform>'
            f'<emitter type="area"><rgb name="radiance" value="{radiance}"/></emitter></shape>')  # fmt: skip


# (name, emitter elements): one light type per scene, and several lights of very different power.
LIGHTS: list[tuple[str, str]] = [
    ("envmap", f'<emitter type="envmap"><string name="filename" value="{ENVMAP}"/></emitter>'),
    ("constant", '<emitter type="constant"><rgb name="radiance" value="1"/></emitter>'),
    ("point", '<emitter type="point"><point name="position" x="-4" y="5" z="6"/><rgb name="intensity" value="60"/></emitter>'),
    ("spot", '<emitter type="spot"><transform name="to_world"><lookat origin="4, 5, 8" target="0, 0, 0" up="0, 1, 0"/>'
     '</transform><rgb name="intensity" value="150"/><float name="cutoff_angle" value="35"/></emitter>'),
    ("directional", '<emitter type="directional"><vector name="direction" x="0.4" y="-0.5" z="-1"/>'
     '<rgb name="irradiance" value="2"/></emitter>'),
    ("sphere", '<shape type="sphere"><point name="center" x="-3" y="4" z="5"/><float name="radius" value="0.5"/>'
     '<emitter type="area"><rgb name="radiance" value="12"/></emitter></shape>'),
    ("disk", _disk(3, 4, 5, 0.5, 12)),
    ("rectangle", '<shape type="rectangle"><transform name="to_world"><scale value="0.7"/>'
     '<lookat origin="0, 6, 4" target="0, 0, 0" up="0, 1, 0"/></transform>'
     '<emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>'),
    ("mesh", f'<shape type="obj"><string name="filename" value="{MESH}"/><transform name="to_world">'
     '<scale value="0.5"/><translate x="-2" y="5" z="6"/></transform>'
     '<emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>'),
    ("several", f'<emitter type="envmap"><string name="filename" value="{ENVMAP}"/><float name="scale" value="0.05"/></emitter>'
     '<emitter type="point"><point name="position" x="-4" y="5" z="6"/><rgb name="intensity" value="200"/></emitter>'
     + _disk(3, 4, 5, 0.15, 300) +
     '<emitter type="directional"><vector name="direction" x="-0.3" y="-0.4" z="-1"/><rgb name="irradiance" value="0.05"/></emitter>'),
]


def centres() -> list[tuple[float, float]]:
    """World (x, y) of each sphere, row by row from the top left, in the order of [`BSDFS`]."""
    off = (GRID - 1) / 2
    return [((c - off) * SPACING, (off - r) * SPACING) for r in range(GRID) for c in range(GRID)]


def scene_xml(light: str, size: int, folder: Path | None = None) -> str:
    """The scene lit by `light` at `size`² pixels; with `folder`, the files it names relative to that folder
    (for scenes kept in the repository), else absolute."""
    emitters = dict(LIGHTS)[light]
    if folder is not None:
        for f in (ENVMAP, MESH):
            emitters = emitters.replace(str(f), os.path.relpath(f, folder))
    spheres = "\n".join(
        f'    <shape type="sphere"><point name="center" x="{x}" y="{y}" z="0"/><float name="radius" value="{RADIUS}"/>{bsdf}</shape>'
        for (x, y), (_, bsdf) in zip(centres(), BSDFS)
    )
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- gonio variance suite (bench/variance.py, generated): {GRID}x{GRID} spheres, one BSDF each, lit by `{light}`. -->
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <default name="size" value="{size}"/>
    <integrator type="path"><integer name="max_depth" value="8"/></integrator>
    <sensor type="orthographic">
        <transform name="to_world"><scale x="{HALF}" y="{HALF}"/><lookat origin="0, 0, 10" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="$size"/><integer name="height" value="$size"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="8"/><translate z="-2"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
{spheres}
    {emitters}
</scene>
"""


def masks(size: int) -> np.ndarray:
    """(len(BSDFS), size, size) booleans: the pixels whose centre sees each sphere (the orthographic film spans
    [-HALF, HALF]², its left edge at world −x and its top at +y)."""
    c = (np.arange(size) + 0.5) / size * 2 * HALF - HALF
    x, y = c[None, :], -c[:, None]
    return np.stack([(x - cx) ** 2 + (y - cy) ** 2 < RADIUS**2 for cx, cy in centres()])


def fireflies(img: np.ndarray, ref: np.ndarray) -> int:
    """Pixels brighter than FIREFLY × the reference (channel means; the reference floored at 1e-3)."""
    return int(np.count_nonzero(img.mean(axis=2) > FIREFLY * np.maximum(ref.mean(axis=2), 1e-3)))


def cell_errors(img: np.ndarray, ref: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The mean squared error of each sphere's pixels."""
    err = ((img.astype(np.float64) - ref.astype(np.float64)) ** 2).mean(axis=2)
    return np.array([err[k].mean() for k in m])


def write_scenes(lights: list[str], size: int, folder: Path) -> list[Scene]:
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for light in lights:
        path = folder / f"variance-{light}.xml"
        text = scene_xml(light, size)
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        out.append(Scene(light, path, {}))
    return out


# The subset `make test` guards (crates/gonio/tests/variance.rs): scene, film size, spp of the test's renders.
TEST_SCENES = ["several", "envmap", "sphere"]
TEST_SIZE = 64
TEST_SPP = 64
TEST_REF_SPP = 16384
TEST_MITSUBA_SEEDS = 16


def write_test_data(mitsuba) -> None:
    """The guard's data (crates/gonio/tests/data/variance/): each scene of TEST_SCENES at TEST_SIZE² px, Mitsuba's
    reference at TEST_REF_SPP (EXR) and Mitsuba's error at TEST_SPP, the mean over TEST_MITSUBA_SEEDS renders
    (mitsuba.json: per sphere and for the whole image, with the fireflies per render)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    TEST_DATA.mkdir(parents=True, exist_ok=True)
    m = masks(TEST_SIZE)
    out = {"how": "python bench/variance.py --write-test-data (Mitsuba 3 %s %s)" % (mi.__version__, mitsuba.variant),
           "spp": TEST_SPP, "ref_spp": TEST_REF_SPP, "seeds": TEST_MITSUBA_SEEDS, "firefly_factor": FIREFLY,
           "bsdfs": [b for b, _ in BSDFS], "scenes": {}}  # fmt: skip
    for light in TEST_SCENES:
        path = TEST_DATA / f"{light}.xml"
        path.write_text(scene_xml(light, TEST_SIZE, TEST_DATA))
        scene = Scene(light, path, {})
        print(f"  [{light}: reference at {TEST_REF_SPP} spp]", flush=True)
        mitsuba.reference(scene, TEST_REF_SPP, TEST_DATA / f"{light}-ref.npy")
        ref = np.load(TEST_DATA / f"{light}-ref.npy")
        (TEST_DATA / f"{light}-ref.npy").unlink()
        mi.Bitmap(ref.astype(np.float32)).write(str(TEST_DATA / f"{light}-ref.exr"))
        cells, image, ff = [], [], []
        for seed in range(TEST_MITSUBA_SEEDS):
            mitsuba.render(scene, TEST_SPP, TEST_DATA / "m.npy", seed=seed + 1)
            img = np.load(TEST_DATA / "m.npy")
            cells.append(cell_errors(img, ref, m))
            image.append(float(((img.astype(np.float64) - ref) ** 2).mean()))
            ff.append(fireflies(img, ref))
        (TEST_DATA / "m.npy").unlink()
        out["scenes"][light] = {"mse_cells": np.mean(cells, axis=0).tolist(), "mse_image": float(np.mean(image)),
                                "mse_image_per_seed": image, "fireflies_per_seed": ff}  # fmt: skip
        print(f"    Mitsuba image MSE {np.mean(image):.4g} (per seed {min(image):.3g}..{max(image):.3g}), fireflies {ff}", flush=True)
    (TEST_DATA / "mitsuba.json").write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {TEST_DATA.relative_to(ROOT)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gonio", type=Path, default=Path(os.environ.get("GONIO_BIN", ROOT / "target" / "release" / "gonio")))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--seeds", type=int, default=32, help="renders per renderer and scene, with different seeds")
    ap.add_argument("--size", type=int, default=160, help="film width and height in pixels")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--lights", action="append", metavar="GLOB", help="only these light scenes (repeatable)")
    ap.add_argument("--json", type=Path, metavar="OUT")
    ap.add_argument("--write-test-data", action="store_true", help="write the guard's data (crates/gonio/tests/data/variance/) and exit")
    args = ap.parse_args()
    if args.write_test_data:
        mitsuba, fallback = start_mitsuba(args.threads)
        try:
            write_test_data(mitsuba)
        finally:
            mitsuba.close()
        return
    lights = [name for name, _ in LIGHTS if not args.lights or any(fnmatch.fnmatch(name, g) for g in args.lights)]
    if not args.gonio.exists():
        sys.exit(f"{args.gonio} not found: build it (`cargo build --release -p gonio-cli`) or pass --gonio / GONIO_BIN")
    scenes = write_scenes(lights, args.size, OUT)
    mitsuba, fallback = start_mitsuba(args.threads)
    if fallback:
        print(f"!! Mitsuba llvm_ad_rgb unavailable ({fallback}): comparing against {mitsuba.variant}", flush=True)
    print(f"== variance suite: gonio ({args.gonio}) vs Mitsuba 3 {mitsuba.variant}, {args.size}² px, {args.spp} spp, "
          f"{args.seeds} seeds each; reference Mitsuba at {args.ref_spp} spp ({load_note()})", flush=True)  # fmt: skip
    m = masks(args.size)
    tmp = Path(tempfile.mkdtemp(prefix="gonio-variance-"))
    rows = {}
    try:
        for scene in scenes:
            key = scene_key(scene, args.ref_spp, mitsuba.variant)
            ref_path = CACHE / f"ref-variance-{scene.name}-{args.ref_spp}spp-{mitsuba.variant}-{key}.npy"
            if not ref_path.exists():
                print(f"  [{scene.name}: reference at {args.ref_spp} spp, once]", flush=True)
                mitsuba.reference(scene, args.ref_spp, ref_path.with_suffix(".tmp.npy"))
                ref_path.with_suffix(".tmp.npy").rename(ref_path)
            ref = np.load(ref_path)
            row = {"gonio": [], "mitsuba": [], "ff_gonio": 0, "ff_mitsuba": 0, "mean_gonio": [], "mean_mitsuba": []}
            for seed in range(args.seeds):
                out = tmp / f"{scene.name}-{seed}.exr"
                run_gonio(args.gonio, scene, args.spp, args.threads, out, seed=seed + 1)
                g = read_exr(out)
                mitsuba.render(scene, args.spp, tmp / "m.npy", seed=seed + 1)
                mi = np.load(tmp / "m.npy")
                for label, img in (("gonio", g), ("mitsuba", mi)):
                    row[label].append(cell_errors(img, ref, m).tolist())
                    row[f"ff_{label}"] += fireflies(img, ref)
                    row[f"mean_{label}"].append(float(img.mean() / ref.mean()))
            rows[scene.name] = row
            ratio = np.mean(row["gonio"], axis=0) / np.mean(row["mitsuba"], axis=0)
            print(f"  {scene.name:<12} worst {BSDFS[int(np.argmax(ratio))][0]} {ratio.max():.2f}x, fireflies gonio "
                  f"{row['ff_gonio']} / Mitsuba {row['ff_mitsuba']}", flush=True)  # fmt: skip
    finally:
        mitsuba.close()
    summary = print_table(rows)
    if args.json:
        args.json.write_text(json.dumps({"spp": args.spp, "ref_spp": args.ref_spp, "seeds": args.seeds, "size": args.size,
                                         "variant": mitsuba.variant, "rows": rows, "summary": summary}, indent=1))  # fmt: skip
        print(f"wrote {args.json}")


def print_table(rows: dict) -> dict:
    """Two tables: the issue's statistic (gonio's MSE over Mitsuba's, each the mean over its renders) and the
    same with medians over the renders. One render's error in a cell is heavy-tailed — a caustic path that
    finds the sun or a small bright light through a chain of mirrors adds hundreds of times a pixel's value
    once in many renders, in either renderer — so the mean's ratio can be 20 or 0.02 by chance where the
    medians agree within a few percent; a cell whose median ratio is high too is a systematic difference."""
    names = list(rows)
    summary: dict = {}
    for label, stat in (("mean", np.mean), ("median", np.median)):
        ratios = {n: stat(rows[n]["gonio"], axis=0) / stat(rows[n]["mitsuba"], axis=0) for n in names}
        print(f"\nMSE gonio / Mitsuba at equal spp, {label} over the renders (cells over 1.3 marked *)")
        print(f"{'bsdf':<26}" + "".join(f"{n[:10]:>11}" for n in names))
        for b, (bsdf, _) in enumerate(BSDFS):
            print(f"{bsdf:<26}" + "".join(f"{ratios[n][b]:>10.2f}{'*' if ratios[n][b] > 1.3 else ' '}" for n in names))
        cells = [(float(ratios[n][b]), BSDFS[b][0], n) for n in names for b in range(len(BSDFS)) if math.isfinite(ratios[n][b]) and ratios[n][b] > 0]
        worst = max(cells)
        geo = math.exp(sum(math.log(r) for r, _, _ in cells) / len(cells))
        over = sum(r > 1.3 for r, _, _ in cells)
        print(f"{label}: worst cell {worst[1]} × {worst[2]} {worst[0]:.2f}x;  geometric mean {geo:.3f} over {len(cells)} cells;  cells over 1.3: {over}")
        summary[label] = {"worst": [worst[1], worst[2], worst[0]], "geomean": geo, "over_1.3": over, "ratios": {n: ratios[n].tolist() for n in names}}
    print()
    print(f"{'fireflies gonio/Mitsuba':<26}" + "".join(f"{rows[n]['ff_gonio']:>5}/{rows[n]['ff_mitsuba']:<5}" for n in names))
    print(f"{'mean gonio/ref':<26}" + "".join(f"{np.mean(rows[n]['mean_gonio']):>11.4f}" for n in names))
    print(f"{'mean Mitsuba/ref':<26}" + "".join(f"{np.mean(rows[n]['mean_mitsuba']):>11.4f}" for n in names))
    more = [n for n in names if rows[n]["ff_gonio"] > rows[n]["ff_mitsuba"]]
    print(f"scenes with more fireflies than Mitsuba (pixels over {FIREFLY:g}x the reference, all renders): {', '.join(more) or 'none'}")
    summary["more_fireflies"] = more
    return summary


if __name__ == "__main__":
    main()
