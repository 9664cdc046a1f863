#!/usr/bin/env python3
"""gonio against Mitsuba 3 on real scene files nobody here wrote: speed outside the suite.

A benchmark, never a test (run by `make bench` after the suite; by hand for a before/after with
`--baseline`). Issue 27: gonio is judged on scenes it was not tuned for, and bench/scenes/ are scenes
written here. This script takes the scenes of ../shared/data/mitsuba-scenes (public repositories' Mitsuba 3
files, `results.tsv` giving each one's spp and `-D` values) whose renders take long enough to time: the
Mitsuba documentation scenes (`d_*`, 960×720 and the like), Mitsuba's `scenes/` (`s_*`), the tutorials'
(`tu_*`), the Blender exporter's (`bl_*`) and the path-guiding lab's (`tk_*`), `yz_*` — not the 48×48 test
scenes (`t_*`), whose time is start-up.

For each scene both renderers render at `--mult` × the spp of `results.tsv` (default 4) with all cores;
gonio's CPU time is its whole `gonio render` process, Mitsuba 3's (`llvm_ad_rgb`) is `mi.load_file` +
render + the copy to NumPy in a fresh worker process, warm in Dr.Jit's kernel cache after the first repeat
(bench/render_vs_mitsuba.py's workers). The least CPU time of `--repeats` rounds is kept, each round one
render by each, so that a change in the machine's load falls on both. CPU time (user + system, all
threads) rather than wall time, because the machine is shared. The image means are compared too: a mean
more than 2 % from Mitsuba's is flagged `!` (the spp are low; `tests/mitsuba_scenes.rs` is the accuracy
check).

Printed: a table, the geometric mean of the CPU-time ratios gonio / Mitsuba and the worst scene, and for
each scene gonio cannot load, its error. Usage:
  python bench/real_scenes.py [--gonio PATH] [--baseline OTHER_GONIO] [--mult 4] [--repeats 2]
                              [--scenes ID,ID,...]
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import render_vs_mitsuba as rv  # noqa: E402  (its workers and timers)

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT.parent / "shared" / "data" / "mitsuba-scenes"
PREFIXES = ("d_", "s_", "tu_", "bl_", "tk_", "yz_")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--gonio", default=os.environ.get("GONIO_BIN", str(ROOT / "target" / "release" / "gonio")))
    ap.add_argument("--baseline", help="another gonio binary, timed in the same rounds")
    ap.add_argument("--mult", type=int, default=4, help="spp = this × the spp of results.tsv")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--scenes", help="comma-separated scene ids (results.tsv's `id`)")
    args = ap.parse_args()
    table = SCENES / "results.tsv"
    if not table.exists():
        print(f"no {table}: nothing to run", file=sys.stderr)
        return 1
    llvm = rv.llvm_library()
    if llvm is None:
        print("libLLVM 19 not found: Mitsuba's llvm_ad_rgb cannot run (apt-get install libllvm19)", file=sys.stderr)
        return 1
    wanted = set(args.scenes.split(",")) if args.scenes else None
    rows = [r for r in csv.DictReader(table.open(), delimiter="\t") if r["id"].startswith(PREFIXES)]
    rows = [r for r in rows if wanted is None or r["id"] in wanted]
    binaries = [("gonio", Path(args.gonio))] + ([("baseline", Path(args.baseline))] if args.baseline else [])
    results, failed = [], []
    print(f"== gonio vs Mitsuba 3 llvm_ad_rgb on {len(rows)} real scenes, {args.mult}× their spp, CPU time, least of {args.repeats}")
    with tempfile.TemporaryDirectory() as tmp:
        for r in rows:
            scene = SCENES / r["repo"].replace("/", "__") / r["path"]
            defines = dict(kv.split("=", 1) for kv in r["defines"].split())
            spp = int(r["spp"]) * args.mult
            cpu = {name: math.inf for name, _ in binaries} | {"mitsuba": math.inf}
            means = {}
            try:
                for _ in range(args.repeats):
                    for name, binary in binaries:
                        out = Path(tmp) / f"{name}.exr"
                        cpu[name] = min(cpu[name], rv.run_gonio(scene, spp, defines, out, binary=binary)["cpu"])
                        means[name] = float(rv.read_exr(out).mean())
                    times, img = rv.run_mitsuba("llvm_ad_rgb", scene, spp, defines, llvm)
                    cpu["mitsuba"] = min(cpu["mitsuba"], times["cpu"])
                    means["mitsuba"] = float(np.mean(img))
            except RuntimeError as e:
                failed.append((r["id"], str(e).strip().splitlines()[-1][:160]))
                print(f"  {r['id']}: {failed[-1][1]}", flush=True)
                continue
            results.append((r["id"], spp, cpu, means))
            extra = f", baseline {cpu['baseline']:.2f} s" if args.baseline else ""
            print(f"  {r['id']}: gonio {cpu['gonio']:.2f} s{extra}, mitsuba {cpu['mitsuba']:.2f} s", flush=True)
    if not results:
        print("no scene rendered in both", file=sys.stderr)
        return 1
    head = f"{'scene':22s} {'spp':>5s} {'gonio s':>8s} {'mitsuba s':>9s} {'cpu g/m':>8s} {'mean g/m':>9s}"
    head += f" {'base s':>7s} {'g/base':>7s}" if args.baseline else ""
    print("\n" + head + "\n" + "-" * len(head))
    for sid, spp, cpu, means in results:
        ratio = means["gonio"] / means["mitsuba"] if means["mitsuba"] else math.nan
        flag = "!" if abs(ratio - 1.0) > 0.02 else " "
        line = f"{sid:22s} {spp:5d} {cpu['gonio']:8.2f} {cpu['mitsuba']:9.2f} {cpu['gonio'] / cpu['mitsuba']:8.2f} {ratio:8.4f}{flag}"
        if args.baseline:
            line += f" {cpu['baseline']:7.2f} {cpu['gonio'] / cpu['baseline']:7.2f}"
        print(line)
    ratios = [cpu["gonio"] / cpu["mitsuba"] for _, _, cpu, _ in results]
    worst = max(range(len(ratios)), key=ratios.__getitem__)
    print(f"\ngeometric mean of the CPU-time ratios gonio/Mitsuba: {math.exp(np.mean(np.log(ratios))):.3f}   over {len(ratios)} scenes")
    print(f"worst scene: {results[worst][0]}  {ratios[worst]:.2f}x")
    if args.baseline:
        gb = [cpu["gonio"] / cpu["baseline"] for _, _, cpu, _ in results]
        print(f"gonio / baseline: geometric mean {math.exp(np.mean(np.log(gb))):.3f}")
    for sid, err in failed:
        print(f"not rendered: {sid}: {err}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
