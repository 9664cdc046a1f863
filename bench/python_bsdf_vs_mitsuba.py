"""Benchmark (not a test): gonio's batched `f`, `pdf` and `sample` from Python against Mitsuba 3's
`llvm_ad_rgb` `bsdf.eval` / `bsdf.pdf` / `bsdf.sample` on the same 10⁶ direction pairs, in one run, for
every model the two share (`MODELS`: Mitsuba's defaults, and GGX and anisotropic settings).

    .venv/bin/python bench/python_bsdf_vs_mitsuba.py [--n 1000000] [--repeat 7] [--rounds 3] [--one-process]

Inputs are float32 arrays of shape (N, 3) (gonio reads them in place); Mitsuba gets the same numbers as
`mi.Vector3f` built from the (contiguous) columns, outside the timing. Every figure is the median of
`--repeat` runs after one warm-up (which also compiles Mitsuba's kernels). The issue's target: gonio at
least as fast as Mitsuba's LLVM variant (whose `f`-equivalent is `eval`, which includes the cosine).

Each library is timed alone, in a child process of its own that draws the same arrays from the same seed,
the two alternating for `--rounds` rounds; each figure printed is the median over the rounds. Why: both
libraries keep a pool of worker threads, one per core, and on two cores the one timed right after the
other's kernel shares the CPU with the other's still-active workers (2026-12-01: gonio's roughconductor
`f` took 1.4 ms per million alone and 3.6–5.7 ms right after a Mitsuba kernel in the same process, where
the order of the script always put it). `--one-process` times both in this process (all of gonio's calls,
then all of Mitsuba's), for comparison.

What each side's timed call does, so that like is compared with like:
- `f`: gonio checks every direction (finite, unit length within 10⁻³) and returns f as an (N, 3) float32
  array; Mitsuba evaluates `eval` (no input checks) and its result is converted to numpy (`np.array`), as
  a user would do.
- `sample`: gonio checks `wo`, `uc` and `u` and returns seven arrays (wi, f, pdf, weight, flags, eta,
  valid). Mitsuba's `sample` returns a BSDFSample3f (wo, pdf, eta, sampled_type, sampled_component) and
  the weight: all six are evaluated in one kernel (`dr.eval`) and each is converted to numpy. (Until
  2026-11 only wo, weight and pdf were converted, each `np.array` launching a kernel of its own; the one
  fused kernel is Mitsuba's efficient idiom and made its time shorter, not longer.)
- Memory: gonio's large result arrays come from a pool of reused blocks (freed results return to it); the
  arrays Mitsuba converts to are numpy's own, and Dr.Jit keeps its kernels' outputs in its own cache.
Both libraries use both cores. The load average is printed before and after: the machine may be shared.

Mitsuba's LLVM variant needs libLLVM ≥ 16 (19 here): set DRJIT_LIBLLVM_PATH, or it is looked up with
`ldconfig -p`. Without Mitsuba (or LLVM) only gonio is timed.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import gonio

def _rgb(*v):
    return {"type": "rgb", "value": list(v)}


# Every model gonio shares with Mitsuba 3: with Mitsuba's defaults (Beckmann for the rough ones), and the
# rough ones also with GGX and anisotropy. The same dictionary loads in both libraries.
MODELS = {
    "diffuse": {"type": "diffuse", "reflectance": _rgb(0.2, 0.5, 0.8)},
    "conductor": {"type": "conductor"},
    "conductor (Au)": {"type": "conductor", "material": "Au"},
    "roughconductor": {"type": "roughconductor"},
    "roughconductor (GGX)": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Au"},
    "roughconductor (aniso)": {"type": "roughconductor", "alpha_u": 0.05, "alpha_v": 0.4},
    "dielectric": {"type": "dielectric"},
    "thindielectric": {"type": "thindielectric"},
    "roughdielectric": {"type": "roughdielectric"},
    "roughdielectric (GGX)": {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.2, "int_ior": 1.33},
    "plastic": {"type": "plastic"},
    "roughplastic": {"type": "roughplastic"},
    "roughplastic (GGX)": {"type": "roughplastic", "distribution": "ggx", "alpha": 0.3,
                           "diffuse_reflectance": _rgb(0.2, 0.5, 0.8)},
    "blendbsdf": {"type": "blendbsdf", "weight": 0.3, "a": {"type": "diffuse"},
                  "b": {"type": "roughconductor", "material": "Cu"}},
    "twosided": {"type": "twosided", "bsdf": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2}},
    "mask": {"type": "mask", "opacity": 0.4, "bsdf": {"type": "diffuse"}},
}

# The three timed calls, in the order of each model's tuple.
CALLS = ("f", "pdf", "sample")


def find_llvm() -> str | None:
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    try:
        out = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    for line in out.splitlines():
        if "libLLVM" in line and ("-19" in line or ".so.19" in line):
            return line.split("=>")[-1].strip()
    return None


def median_ms(fn, repeat: int) -> float:
    fn()  # warm-up (and Mitsuba's kernel compilation)
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return 1e3 * statistics.median(times)


def directions(rng, n):
    w = rng.normal(size=(n, 3))
    w[:, 2] = np.abs(w[:, 2])
    return (w / np.linalg.norm(w, axis=1, keepdims=True)).astype(np.float32)


MODEL_NAMES = list(MODELS)


def time_gonio(wo, wi, uc, u, repeat: int) -> dict:
    """ms per call of gonio's `f`, `pdf` and `sample` for each model."""
    out = {}
    for name, spec in MODELS.items():
        g = gonio.load_bsdf(spec)
        out[name] = (
            median_ms(lambda: g.f(wo, wi), repeat),
            median_ms(lambda: g.pdf(wo, wi), repeat),
            median_ms(lambda: g.sample(wo, uc, u), repeat),
        )
    return out


def load_mitsuba():
    """(mi, dr) with the `llvm_ad_rgb` variant set, or None (with the reason printed)."""
    llvm = find_llvm()
    if not llvm:
        print("libLLVM-19 not found; timing gonio only")
        return None
    os.environ["DRJIT_LIBLLVM_PATH"] = llvm
    try:
        import drjit as dr
        import mitsuba as mi

        mi.set_variant("llvm_ad_rgb")
    except (ImportError, AttributeError, RuntimeError) as e:
        print(f"Mitsuba llvm_ad_rgb unavailable ({e}); timing gonio only")
        return None
    return mi, dr


def time_mitsuba(mi, dr, wo, wi, uc, u, repeat: int) -> dict:
    """ms per call of Mitsuba's `eval`, `pdf` and `sample` (with the copies to NumPy) for each model."""
    n = len(wo)
    mi_wo = mi.Vector3f(*(np.ascontiguousarray(wo[:, k]) for k in range(3)))
    mi_wi = mi.Vector3f(*(np.ascontiguousarray(wi[:, k]) for k in range(3)))
    mi_uc = mi.Float(uc)
    mi_u = mi.Point2f(np.ascontiguousarray(u[:, 0]), np.ascontiguousarray(u[:, 1]))
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi_wo
    ctx = mi.BSDFContext()
    out = {}
    for name, spec in MODELS.items():
        m = mi.load_dict(spec)

        def mi_eval():
            v = m.eval(ctx, si, mi_wi)
            return np.array(v)

        def mi_pdf():
            return np.array(m.pdf(ctx, si, mi_wi))

        def mi_sample():
            bs, weight = m.sample(ctx, si, mi_uc, mi_u)
            dr.eval(bs, weight)
            fields = (bs.wo, bs.pdf, bs.eta, bs.sampled_type, bs.sampled_component, weight)
            return [np.array(v) for v in fields]

        out[name] = (median_ms(mi_eval, repeat), median_ms(mi_pdf, repeat), median_ms(mi_sample, repeat))
    return out


def inputs(n: int):
    rng = np.random.default_rng(1)
    wo, wi = directions(rng, n), directions(rng, n)
    uc = rng.random(n, dtype=np.float32)
    u = rng.random((n, 2), dtype=np.float32)
    return wo, wi, uc, u


def child(side: str, n: int, repeat: int) -> None:
    """One side's timings as JSON on stdout (`--side`)."""
    wo, wi, uc, u = inputs(n)
    if side == "gonio":
        result = time_gonio(wo, wi, uc, u, repeat)
    else:
        loaded = load_mitsuba()
        result = None if loaded is None else time_mitsuba(*loaded, wo, wi, uc, u, repeat)
    print(json.dumps(result))


def run_child(side: str, args) -> dict | None:
    cmd = [sys.executable, __file__, "--side", side, "--n", str(args.n), "--repeat", str(args.repeat)]
    p = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if p.returncode != 0:
        raise SystemExit(f"the {side} child failed (exit {p.returncode}):\n{p.stderr}")
    lines = [line for line in p.stdout.splitlines() if line.strip()]
    for line in lines[:-1]:
        print(line)  # a child's messages (e.g. why Mitsuba is not timed)
    return json.loads(lines[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--rounds", type=int, default=3, help="alternating child processes per library")
    parser.add_argument("--one-process", action="store_true", help="time both libraries in this process (gonio, then Mitsuba)")
    parser.add_argument("--side", choices=["gonio", "mitsuba"], help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.side:
        child(args.side, args.n, args.repeat)
        return
    n = args.n
    print(f"load average {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    if args.one_process:
        wo, wi, uc, u = inputs(n)
        g = time_gonio(wo, wi, uc, u, args.repeat)
        loaded = load_mitsuba()
        m = None if loaded is None else time_mitsuba(*loaded, wo, wi, uc, u, args.repeat)
        how = "both in one process"
    else:
        rounds_g, rounds_m = [], []
        for _ in range(args.rounds):
            rounds_g.append(run_child("gonio", args))
            rounds_m.append(run_child("mitsuba", args))
        med = lambda rounds, k: tuple(statistics.median(r[k][j] for r in rounds) for j in range(len(CALLS)))  # noqa: E731
        g = {k: med(rounds_g, k) for k in MODEL_NAMES}
        m = None if rounds_m[0] is None else {k: med(rounds_m, k) for k in MODEL_NAMES}
        how = f"each alone in its own process, median of {args.rounds} alternating rounds"
    print(f"{n:,} direction pairs, float32 (N, 3) inputs, median of {args.repeat} calls; {how}; ms per million pairs")
    header = f"{'model':<24}" + "".join(f" {'gonio ' + c:>12} {'mitsuba':>9} {'ratio':>6}" for c in CALLS)
    print(header)
    print("-" * len(header))
    per_million = 1e6 / n
    ratios = []
    for name in MODEL_NAMES:
        row = f"{name:<24}"
        for j in range(len(CALLS)):
            gv = g[name][j] * per_million
            if m is None:
                row += f" {gv:12.2f} {'—':>9} {'':>6}"
                continue
            mv = m[name][j] * per_million
            ratios.append((gv / mv, f"{name} {CALLS[j]}"))
            row += f" {gv:12.2f} {mv:9.2f} {gv / mv:5.2f}×"
        print(row)
    if ratios:
        geo = float(np.exp(np.mean([np.log(r) for r, _ in ratios])))
        worst = max(ratios)
        print(f"ratio = gonio time / Mitsuba time (< 1: gonio is faster); geometric mean {geo:.2f}×, "
              f"worst {worst[0]:.2f}× ({worst[1]}); target: every ratio ≤ 1.0×")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
