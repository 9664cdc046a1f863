#!/usr/bin/env python3
"""Mitsuba 3's spectral image means of the real scenes, for gonio's test
`spectral_means_match_mitsuba` (crates/gonio/tests/mitsuba_scenes.rs).

    .venv/bin/python tools/spectral_reference.py > crates/gonio/tests/data/mitsuba_spectral_means.tsv

Every scene of `../shared/data/mitsuba-scenes/results.tsv` that Mitsuba renders there is rendered again,
unmodified, with the same `-D` defines, film and samples per pixel, by Mitsuba's `llvm_ad_spectral` variant
(seed 0), and its image mean per channel (linear sRGB, as the film writes it) is printed beside its id.
A scene Mitsuba's spectral variant does not render is printed with its error in place of the mean.
"""
import csv
import sys
from pathlib import Path

import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_spectral")

DATA = Path("/work/shared/data/mitsuba-scenes")

rows = list(csv.DictReader(open(DATA / "results.tsv"), delimiter="\t"))
print(f"# tools/spectral_reference.py: Mitsuba {mi.MI_VERSION} llvm_ad_spectral, seed 0, each scene of "
      "../shared/data/mitsuba-scenes/results.tsv at its defines, film size and spp")
print("id\tspp\tsize\tmi_spectral_mean")
for row in rows:
    if row["mi_renders"] != "y":
        continue
    path = DATA / row["repo"].replace("/", "__") / row["path"]
    defines = dict(d.split("=", 1) for d in row["defines"].split())
    try:
        scene = mi.load_file(str(path), **defines)
        # A scene without an integrator renders with gonio's default, Mitsuba's `path` (as results.tsv's).
        integrator = None if scene.integrator() is not None else mi.load_dict({"type": "path"})
        image = np.array(mi.render(scene, spp=int(row["spp"]), seed=0, integrator=integrator), dtype=np.float64)[..., :3]
        mean = ",".join("%.7g" % m for m in image.reshape(-1, 3).mean(axis=0))
    except Exception as e:  # the refusal is the datum
        mean = "error: " + str(e).splitlines()[0][:200]
    print(f"{row['id']}\t{row['spp']}\t{row['size']}\t{mean}", flush=True)
