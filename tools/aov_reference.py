#!/usr/bin/env python3
"""Mitsuba 3's channel means of the real `aov` scene, for gonio's test `tests/aov.rs`.

    .venv/bin/python tools/aov_reference.py > crates/gonio/tests/data/aov_mitsuba.json

The scene is mitsuba-data's `docs/scenes/integrator_aov.xml` (with its `include/integrator_scene.xml`) from
`../shared/data/mitsuba-scenes/` (results.tsv's `d_aov`), unmodified but for the film, scaled as the
compatibility test scales it: 960 × 720 → 80 × 60 (at most 4800 pixels, the aspect kept). Its two files are
copied to a temporary folder with those sizes and with `<path>` pointing at the data's `common` folder.
Mitsuba 3.9.1, variant llvm_ad_rgb, renders it twice, SPP samples per pixel each with seeds 0 and 1. For
every channel of the film's bitmap (`film().bitmap()`: Mitsuba's names and order) the file holds the mean
of the two renders and its standard error, sd(8 × 8-block means of A − B) / (2 √blocks), as the
compatibility test estimates gonio's.
"""
import json
import re
import sys
import tempfile
from pathlib import Path

import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_rgb")

DATA = Path("/work/shared/data/mitsuba-scenes/mitsuba-renderer__mitsuba-data")
SCENE = DATA / "docs/scenes/integrator_aov.xml"
INCLUDE = DATA / "docs/scenes/include/integrator_scene.xml"
SIZE = (80, 60)
SPP = 256
BLOCK = 8


def copy(src, dst):
    text = src.read_text()
    text = text.replace('<path value="../../common"/>', f'<path value="{DATA / "common"}"/>')
    text = re.sub(r'name="width" value="960"', f'name="width" value="{SIZE[0]}"', text)
    text = re.sub(r'name="height" value="720"', f'name="height" value="{SIZE[1]}"', text)
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_text(text)


def render(path, seed):
    scene = mi.load_file(str(path), spp=SPP)
    mi.render(scene, seed=seed)
    bitmap = scene.sensors()[0].film().bitmap()
    names = [bitmap.struct_()[i].name for i in range(bitmap.channel_count())]
    return names, np.array(bitmap, dtype=np.float64)


with tempfile.TemporaryDirectory() as tmp:
    scene = Path(tmp) / "integrator_aov.xml"
    copy(SCENE, scene)
    copy(INCLUDE, Path(tmp) / "include/integrator_scene.xml")
    names, a = render(scene, 0)
    _, b = render(scene, 1)

h, w, _ = a.shape
assert (w, h) == SIZE, (w, h)
means = 0.5 * (a.mean(axis=(0, 1)) + b.mean(axis=(0, 1)))
d = a - b
blocks = np.array([d[y:y + BLOCK, x:x + BLOCK].mean(axis=(0, 1)) for y in range(0, h, BLOCK) for x in range(0, w, BLOCK)])
errors = blocks.std(axis=0, ddof=1) / (2.0 * np.sqrt(len(blocks)))
json.dump(
    {
        "source": "tools/aov_reference.py: Mitsuba " + mi.MI_VERSION + " llvm_ad_rgb, mitsuba-data docs/scenes/integrator_aov.xml at "
        f"{SIZE[0]}x{SIZE[1]}, two renders of {SPP} spp (seeds 0, 1)",
        "size": list(SIZE),
        "spp": 2 * SPP,
        "channels": names,
        "means": [float("%.7g" % m) for m in means],
        "standard_errors": [float("%.3g" % e) for e in errors],
    },
    sys.stdout,
    indent=1,
)
sys.stdout.write("\n")
