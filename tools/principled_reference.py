#!/usr/bin/env python3
"""Reference values of Mitsuba 3's `principled` for gonio's `bsdf::principled::tests::matches_mitsuba`.

    .venv/bin/python tools/principled_reference.py > crates/gonio/tests/data/principled_mitsuba.json

For each parameter set, 80 pairs (wo, wi) in gonio's naming (Mitsuba's si.wi = wo, its bs.wo = wi): half
with wi drawn by Mitsuba's own `sample` (so that most land in the lobes, transmitted ones included), half
uniform on the sphere; wo uniform over the sphere (or the upper hemisphere where nothing transmits).
Each row is wo, wi, Mitsuba's eval (= gonio f·|cos θi|) per channel and pdf, in float32 (9 significant
digits: exact for float32).
Mitsuba 3.9.1, variant scalar_rgb. Rows where Mitsuba's scalar variant and gonio differ by design (module
doc of principled.rs: pdf from below when nothing transmits) are not written.
"""
import json
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

SETS = [
    {"type": "principled"},
    {"type": "principled", "base_color": [0.9, 0.6, 0.2], "metallic": 0.8, "roughness": 0.3, "anisotropic": 0.7},
    {"type": "principled", "base_color": [0.8, 0.9, 1.0], "spec_trans": 0.9, "roughness": 0.2, "eta": 1.5},
    {"type": "principled", "base_color": [0.2, 0.4, 0.6], "clearcoat": 1.0, "clearcoat_gloss": 0.9, "sheen": 1.0,
     "sheen_tint": 0.5, "spec_tint": 0.5, "roughness": 0.6},
    {"type": "principled", "roughness": 0.05, "spec_trans": 0.5, "metallic": 0.3, "clearcoat": 0.5, "flatness": 0.5,
     "eta": 1.33, "main_specular_sampling_rate": 0.5, "clearcoat_sampling_rate": 2.0,
     "diffuse_reflectance_sampling_rate": 0.25},
    {"type": "principled", "base_color": 0.7, "roughness": 1.0, "spec_trans": 0.8, "eta": 0.75, "anisotropic": 1.0},
    {"type": "principled", "base_color": [0.95, 0.64, 0.54], "roughness": 0.1, "metallic": 1.0, "clearcoat": 1.0,
     "clearcoat_gloss": 0.5},
    {"type": "principled", "base_color": [0.2, 0.8, 0.1], "roughness": 0.15, "anisotropic": 0.8, "metallic": 0.1,
     "clearcoat": 0.9, "sheen": 0.9, "specular": 0.7},
    {"type": "principled", "base_color": [0.8, 0.8, 0.8], "specular": 0.5, "spec_tint": 0.0, "spec_trans": 0.0,
     "metallic": 0.0, "anisotropic": 0.0, "roughness": 0.4, "sheen": 0.0, "sheen_tint": 0.5, "clearcoat": 0.0,
     "clearcoat_gloss": 0.173205},
    {"type": "principled", "base_color": [0.3, 0.5, 0.9], "spec_tint": 1.0, "sheen": 0.5, "sheen_tint": 1.0,
     "flatness": 1.0, "roughness": 0.8, "specular": 0.2},
    {"type": "principled", "base_color": [0.6, 0.6, 0.3], "spec_trans": 0.4, "spec_tint": 0.6, "specular": 0.9,
     "roughness": 0.5, "anisotropic": 0.4, "sheen": 0.3, "clearcoat": 0.3, "clearcoat_gloss": 0.2},
    {"type": "principled", "base_color": [0.5, 0.2, 0.7], "spec_trans": 1.0, "roughness": 0.35, "eta": 1.8,
     "metallic": 0.2},
    {"type": "principled", "base_color": [0.1, 0.1, 0.1], "eta": 0.8, "roughness": 0.3, "metallic": 0.5,
     "spec_tint": 0.3},
    {"type": "principled", "base_color": [0.7, 0.3, 0.2], "roughness": 0.25, "spec_trans": 0.6, "eta": 1.1,
     "main_specular_sampling_rate": 2.0, "diffuse_reflectance_sampling_rate": 0.5},
]
PAIRS = 80


def short(x):
    """A float32 value as the shortest decimal of 9 significant digits (every float32 is exact at that length)."""
    return float("%.9g" % x)


def to_mitsuba(spec):
    out = {}
    for key, value in spec.items():
        if isinstance(value, list):
            out[key] = {"type": "rgb", "value": value}
        else:
            out[key] = value
    return out


def unit(v):
    v = np.asarray(v, dtype=np.float32)
    return (v / np.linalg.norm(v)).astype(np.float32)


def sphere(rng):
    return unit(rng.normal(size=3))


def main():
    rng = np.random.default_rng(2026)
    ctx = mi.BSDFContext()
    out = []
    for spec in SETS:
        bsdf = mi.load_dict(to_mitsuba(spec))
        transmissive = spec.get("spec_trans", 0) != 0
        weight_transmit = (1 - spec.get("metallic", 0)) * spec.get("spec_trans", 0)
        rows = []
        while len(rows) < PAIRS:
            wo = sphere(rng)
            if not transmissive and wo[2] < 0:
                wo[2] = -wo[2]
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*map(float, wo))
            if len(rows) % 2 == 0:
                bs, _ = bsdf.sample(ctx, si, float(rng.random()), mi.Point2f(float(rng.random()), float(rng.random())))
                if not bs.pdf > 0:
                    continue
                wi = unit(np.array(bs.wo))
            else:
                wi = sphere(rng)
            if wo[2] < 0 and weight_transmit == 0:
                continue
            value = np.array(bsdf.eval(ctx, si, mi.Vector3f(*map(float, wi))), dtype=np.float32)
            pdf = np.float32(bsdf.pdf(ctx, si, mi.Vector3f(*map(float, wi))))
            rows.append([short(x) for x in [*wo, *wi, *value, pdf]])
        values = np.array([r[6:] for r in rows])
        out.append({"spec": spec, "scale": float(np.abs(values).max()), "rows": rows})
    sys.stdout.write(json.dumps(out, separators=(",", ":")) + "\n")


if __name__ == "__main__":
    main()
