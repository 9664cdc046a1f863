#!/usr/bin/env python3
"""Reference values of Mitsuba 3's `normalmap` and `bumpmap` frame for gonio's
`bsdf::normal_map::tests::matches_mitsuba`.

    .venv/bin/python tools/normalmap_reference.py > crates/gonio/tests/data/normalmap_mitsuba.json

For each case (a constant normal-map colour, a nested model, the two flags), 64 pairs (wo, wi) in gonio's
naming (Mitsuba's si.wi = wo, its eval's direction = wi) in the shading frame z = n: wo over the upper
hemisphere, wi over the whole sphere. Each row is wo, wi, Mitsuba's eval (= gonio f·|cos θi|) per channel
and pdf. Mitsuba 3.9.1, variant scalar_rgb. Not a case: the colour (½, ½, ½), a zero normal, where
Mitsuba's value is 0 everywhere and gonio keeps the shading normal (normal_map.rs's module docs).
"""
import json

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

NESTED = {
    "diffuse": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.5, 0.8]}},
    "aniso": {"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.1, "alpha_v": 0.4, "material": "Au"},
    "ggx": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Cu"},
}
CASES = [
    ([0.8, 0.5, 0.9], "diffuse", True, True),
    ([0.3, 0.65, 0.8], "diffuse", True, True),
    ([0.3, 0.65, 0.8], "diffuse", False, True),
    ([0.3, 0.65, 0.8], "diffuse", True, False),
    ([0.95, 0.2, 0.6], "aniso", True, True),
    ([0.6, 0.7, 0.85], "ggx", True, True),
    ([0.5, 0.5, 0.0], "diffuse", True, True),
]
PAIRS = 64


def short(x):
    return float("%.9g" % x)


def unit(rng, upper):
    while True:
        v = rng.normal(size=3)
        n = np.linalg.norm(v)
        if n > 1e-3 and (not upper or v[2] > 0.05 * n):
            return v / n


def main():
    rng = np.random.default_rng(5)
    cases = []
    for colour, nested, flip, shadow in CASES:
        bsdf = mi.load_dict({
            "type": "normalmap",
            "normalmap": {"type": "rgb", "value": colour},
            "flip_invalid_normals": flip,
            "use_shadowing_function": shadow,
            "nested": NESTED[nested],
        })
        rows = []
        for _ in range(PAIRS):
            wo, wi = unit(rng, True), unit(rng, False)
            si = mi.SurfaceInteraction3f()
            si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
            si.n = mi.Normal3f(0, 0, 1)
            si.wi = mi.Vector3f(*wo)
            ctx = mi.BSDFContext()
            value = bsdf.eval(ctx, si, mi.Vector3f(*wi))
            pdf = bsdf.pdf(ctx, si, mi.Vector3f(*wi))
            rows.append([short(x) for x in [*wo, *wi, value[0], value[1], value[2], pdf]])
        cases.append({"normalmap": colour, "nested": nested, "flip_invalid_normals": flip,
                      "use_shadowing_function": shadow, "rows": rows})
    print(json.dumps({"source": "Mitsuba 3.9.1 scalar_rgb, tools/normalmap_reference.py", "nested": NESTED,
                      "cases": cases}))


main()
