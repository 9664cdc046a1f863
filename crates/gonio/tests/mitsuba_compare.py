#!/usr/bin/env python3
"""Render one scene with Mitsuba 3 and with gonio, and compare: time and mean absolute difference.

    python crates/gonio/tests/mitsuba_compare.py SCENE.xml [--spp N] [--variant llvm_ad_rgb] [--gonio target/release/gonio]

Needs the `mitsuba` and `numpy` Python packages (installed in the project's .venv by `make build`).
Mitsuba's timing includes its JIT compilation on the first render of an LLVM variant; the script renders
twice and reports the second run.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import mitsuba as mi
import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, default=None)
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--gonio", default="target/release/gonio")
    ap.add_argument("-D", action="append", default=[], help="NAME=VALUE passed to both renderers")
    args = ap.parse_args()

    mi.set_variant(args.variant)
    params = dict(d.split("=", 1) for d in args.D)
    scene = mi.load_file(args.scene, **params)
    spp = args.spp or scene.sensors()[0].sampler().sample_count()
    times = []
    for _ in range(2):
        t0 = time.perf_counter()
        ref = np.array(mi.render(scene, spp=spp))
        times.append(time.perf_counter() - t0)
    ref = ref[..., :3]

    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "gonio.exr")
        cmd = [args.gonio, "render", args.scene, "-o", out, "--spp", str(spp), "--quiet"] + sum((["-D", d] for d in args.D), [])
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True)
        gonio_time = time.perf_counter() - t0
        img = np.array(mi.Bitmap(out))[..., :3]

    diff = np.abs(img - ref)
    print(f"scene {args.scene}: {ref.shape[1]}x{ref.shape[0]}, {spp} spp")
    print(f"  mitsuba {args.variant}: {times[1]:.3f} s (first run {times[0]:.3f} s)")
    print(f"  gonio (incl. loading): {gonio_time:.3f} s  → ratio mitsuba/gonio = {times[1] / gonio_time:.2f}")
    print(f"  mean: mitsuba {ref.mean(axis=(0, 1))}  gonio {img.mean(axis=(0, 1))}")
    print(f"  mean |difference| {diff.mean():.5f}  (relative to mean {diff.mean() / max(ref.mean(), 1e-12):.4f})")


if __name__ == "__main__":
    sys.exit(main())
