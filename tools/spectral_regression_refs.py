#!/usr/bin/env python3
"""Mitsuba 3's spectral references for the nine render regression scenes, for gonio's spectral z-tests
(`crates/gonio/tests/mitsuba_regression.rs`, `spectral_*`).

    .venv/bin/python tools/spectral_regression_refs.py crates/gonio/tests/data/spectral_refs

Each scene of `../shared/data/mitsuba/tests/scenes/bsdf_spheres/` (48 × 48) is rendered by Mitsuba's
`llvm_ad_spectral` variant RUNS times at SPP samples per pixel with seeds 0 … RUNS − 1. The reference is the
mean of the runs (RUNS · SPP samples per pixel) and the variance image is the variance of one sample,
estimated as SPP times the variance of the runs' images — the two images Mitsuba's own regression test
reads (`{name}_ref_spectral.exr`, `{name}_ref_spectral_var.exr`, linear sRGB, float32).
"""
import sys
from pathlib import Path

import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_spectral")

SCENES = Path("/work/shared/data/mitsuba/tests/scenes/bsdf_spheres")
NAMES = ["arealight", "constant", "envmap", "pointlight", "roughdielectric", "roughplastic_linear",
         "roughplastic_nonlinear", "textured_diffuse", "textured_roughconductor"]
RUNS, SPP = 64, 256

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
for name in NAMES:
    scene = mi.load_file(str(SCENES / f"test_{name}_path.xml"))
    images = np.stack([np.array(mi.render(scene, spp=SPP, seed=run), dtype=np.float64)[..., :3] for run in range(RUNS)])
    mean, var = images.mean(axis=0), images.var(axis=0, ddof=1) * SPP
    for suffix, image in [("", mean), ("_var", var)]:
        mi.Bitmap(image.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(out / f"test_{name}_ref_spectral{suffix}.exr"))
    print(name, mean.reshape(-1, 3).mean(axis=0), flush=True)
