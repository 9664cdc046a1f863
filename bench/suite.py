#!/usr/bin/env python3
"""The benchmark suite: gonio against Mitsuba 3 `llvm_ad_rgb` on every scene of bench/scenes/.

A benchmark, never a test: it prints numbers and exits 0 whatever they are (it exits non-zero only when it
cannot run at all: no gonio binary, no Mitsuba). Issue 27, "The benchmark suite".

For each scene (bench/scenes/*.xml, plus Mitsuba's own unmodified files listed in `EXTERNAL`):
- **gonio**: the whole `gonio render` process (start-up, scene load, BVH, render, writing the EXR), wall
  time, `--threads N`.
- **Mitsuba 3** (`llvm_ad_rgb`; `scalar_rgb` with a loud note when libLLVM 19 is missing): `mi.load_file`
  + `mi.render` + `dr.eval` + the copy to NumPy, wall time, in one long-lived worker process with
  `dr.set_thread_count(N)`; before the timed renders of a scene the worker renders it once untimed, so
  the JIT kernels are compiled (and in Dr.Jit's cache) and the timed renders are warm.
- Equal spp (`--spp`, default 32) and equal thread count (`--threads`, default all cores) on both sides.
  `--repeats` rounds (default 3), each with one render of each renderer (gonio, `--baseline` builds,
  Mitsuba), the order alternating from round to round, so that a change in the machine's load falls on
  all of them alike; the fastest wall time of each is kept (the median goes to `--json`).
- Image error: each image's MSE against a reference rendered once by Mitsuba at `--ref-spp` (default
  1024, in passes of 64 spp with their own seeds) and cached in bench/.cache/, keyed by a hash of the
  scene file, every file it references (includes, meshes, textures, envmaps), the `-D` values, the spp
  and the variant. MSE ratio = gonio's MSE / Mitsuba's at equal spp (both include the reference's own
  noise, 1/32 of a 32-spp image's variance at the defaults).
- Image means: gonio's mean over the image / the reference's, and Mitsuba's own (at equal spp) for
  scale. A gonio mean more than 1 % from the reference's is flagged `!`: a scene where the two
  renderers disagree is a correctness finding (unless Mitsuba's own low-spp mean is as far off: noise).

`--mode spectral` renders gonio with `--mode spectral` against Mitsuba's `llvm_ad_spectral` (and references of
that variant); `--baseline BIN --baseline-mode rgb` then times the same binary's RGB mode in the same rounds,
the issue-30 ratio spectral / RGB.

Printed: a table (scene, gonio s, Mitsuba s, time ratio gonio/Mitsuba, MSE ratio, mean ratios), then the
geometric mean of the time ratios and the worst scene. A renderer that fails on a scene is reported with
its error and the suite goes on with the others; failed scenes are left out of the geometric mean (and
said so).

Usage: python bench/suite.py [--gonio PATH] [--spp 32] [--ref-spp 1024] [--repeats 3] [--threads N]
                             [--scenes GLOB ...] [--baseline OTHER_GONIO] [--json OUT] [--list]
(GONIO_BIN or --gonio: the gonio binary, target/release/gonio by default.)
"""

from __future__ import annotations

import argparse
import fnmatch
import gc
import hashlib
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from render_vs_mitsuba import CACHE, ROOT, children_cpu, llvm_library, load_note, mse, read_exr, write_sphere_ply  # noqa: E402

SCENES = ROOT / "bench" / "scenes"
SHARED = ROOT.parent / "shared"
REF_SEED = 7
REF_PASS_SPP = 64
MEAN_TOLERANCE = 0.01

# Mitsuba's own scene files, unmodified, in the suite as they are (with -D values both renderers accept).
# name -> (path, defines, why gonio fails to load it, if it does at the time of writing)
EXTERNAL = {
    "mitsuba-matpreview": (
        SHARED / "data/mitsuba/scenes/matpreview/matpreview.xml",
        {"width": "256", "height": "192"},
        "gonio refuses `focus_distance` on `perspective` (bench/scenes/matpreview.xml is the adapted copy)",
    ),
    "mitsuba-cbox-rgb": (
        SHARED / "data/mitsuba/scenes/cbox/cbox-rgb.xml",
        {"res": "192"},
        "gonio resolves paths in an <include>d file against the fragment's folder, Mitsuba against the main "
        "file's; and it refuses `focus_distance`",
    ),
}

# -D values per scene (glob on the scene's name): Mitsuba's matpreview keeps its own 683x512 defaults.
DEFINES = {"matpreview*": {"width": "256", "height": "192"}}


# ---------------------------------------------------------------------------------------------------------
# Generated assets (bench/.cache, not committed)


def generated_assets() -> None:
    """Write the meshes scenes refer to in bench/.cache (idempotent)."""
    CACHE.mkdir(parents=True, exist_ok=True)
    ply = CACHE / "sphere-1m.ply"
    if not ply.exists():
        tmp = ply.with_suffix(".tmp")
        n = write_sphere_ply(tmp, 708, 708)  # 1,001,112 triangles
        tmp.rename(ply)
        print(f"wrote {ply.relative_to(ROOT)} ({n} triangles)")


# ---------------------------------------------------------------------------------------------------------
# Scenes


class Scene:
    def __init__(self, name: str, path: Path, defines: dict[str, str], expected_failure: str | None = None):
        self.name, self.path, self.defines, self.expected_failure = name, path, defines, expected_failure


def all_scenes() -> list[Scene]:
    out = []
    for p in sorted(SCENES.glob("*.xml")):
        defines = {}
        for pattern, d in DEFINES.items():
            if fnmatch.fnmatch(p.stem, pattern):
                defines.update(d)
        out.append(Scene(p.stem, p, defines))
    for name, (path, defines, why) in EXTERNAL.items():
        out.append(Scene(name, path, defines, why))
    return out


def referenced_files(scene: Path, seen: set[Path] | None = None) -> list[Path]:
    """The scene file and every file it names (`filename` of includes, meshes, bitmaps, envmaps, measured
    data), recursively through includes; relative names resolved against the including file's folder and
    the main file's (Mitsuba's rule), whichever exists."""
    seen = set() if seen is None else seen
    scene = scene.resolve()
    if scene in seen:
        return []
    seen.add(scene)
    files = [scene]
    try:
        root = ET.parse(scene).getroot()
    except (ET.ParseError, OSError):
        return files
    for el in root.iter():
        name = el.get("filename") if el.tag == "include" else (el.get("value") if el.get("name") == "filename" else None)
        if not name or "$" in name:
            continue
        for base in (scene.parent, *(p.parent for p in list(seen))):
            p = (base / name).resolve()
            if p.exists():
                files += referenced_files(p, seen) if p.suffix == ".xml" else ([p] if p not in seen else [])
                seen.add(p)
                break
    return files


def scene_key(scene: Scene, ref_spp: int, variant: str) -> str:
    h = hashlib.sha256()
    for f in referenced_files(scene.path):
        h.update(str(f.name).encode())
        h.update(f.read_bytes())
    h.update(json.dumps([sorted(scene.defines.items()), ref_spp, REF_PASS_SPP, REF_SEED, variant]).encode())
    return h.hexdigest()[:16]


# ---------------------------------------------------------------------------------------------------------
# Mitsuba: one long-lived worker process (`--mitsuba-server VARIANT THREADS`), one JSON request a line.

RESULT = "@@suite-result "


def mitsuba_server(variant: str, threads: int) -> None:
    import mitsuba as mi

    mi.set_variant(variant)
    import drjit as dr

    dr.set_thread_count(threads)
    # Kernel history: a timed render reports the kernels it had to compile (cache misses), which a warm
    # render should not have.
    dr.set_flag(dr.JitFlag.KernelHistory, True)

    def compiled() -> tuple[int, float]:
        jit = [k for k in dr.kernel_history() if k.get("type") == dr.KernelType.JIT and not k.get("cache_hit")]
        return len(jit), sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0) for k in jit) / 1000

    print(RESULT + json.dumps({"ready": variant, "threads": dr.thread_count()}), flush=True)
    for line in sys.stdin:
        req = json.loads(line)
        try:
            if req["op"] == "render":
                compiled()  # clears the history
                wall0, cpu0 = time.perf_counter(), time.process_time()
                scene = mi.load_file(req["scene"], **req["defines"])
                img = mi.render(scene, spp=req["spp"], seed=req["seed"])
                dr.eval(img)
                arr = np.array(img, dtype=np.float32)[..., :3]
                wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
                np.save(req["out"], arr)
                misses, compile_s = compiled()
                reply = {"wall": wall, "cpu": cpu, "kernels_compiled": misses, "compile_s": compile_s}
            elif req["op"] == "reference":
                scene = mi.load_file(req["scene"], **req["defines"])
                acc = None
                for k in range(req["passes"]):
                    img = mi.render(scene, spp=req["pass_spp"], seed=req["seed"] + k)
                    a = np.array(img, dtype=np.float64)[..., :3]
                    acc = a if acc is None else acc + a
                np.save(req["out"], (acc / req["passes"]).astype(np.float32))
                reply = {}
            else:
                reply = {"error": f"unknown op {req['op']}"}
        except Exception as e:  # a scene Mitsuba refuses: report and serve the next request
            reply = {"error": f"{type(e).__name__}: {e}"}
        # Free the scene before the next request: Dr.Jit bakes the registry ids of a scene's objects into
        # its kernels, and a scene loaded while the previous one lives gets other ids, so other kernels
        # (compiled again, in a timed render). Loaded after the previous one is freed, it gets the same ids
        # and the warm-up's kernels.
        scene = img = None
        gc.collect()
        print(RESULT + json.dumps(reply), flush=True)


class Mitsuba:
    """The client side of the worker: restarted if it dies (a crash on one scene does not end the suite)."""

    def __init__(self, variant: str, threads: int, llvm: str | None):
        self.variant, self.threads, self.llvm, self.proc = variant, threads, llvm, None
        self.log: list[str] = []

    def start(self) -> dict:
        env = dict(os.environ)
        if self.variant.startswith("llvm"):
            env["DRJIT_LIBLLVM_PATH"] = self.llvm or ""
        self.proc = subprocess.Popen(
            [sys.executable, __file__, "--mitsuba-server", self.variant, str(self.threads)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
        )  # fmt: skip
        return self._reply()

    def _reply(self) -> dict:
        self.log = []
        for line in self.proc.stdout:
            if line.startswith(RESULT):
                return json.loads(line[len(RESULT):])
            self.log.append(line.rstrip())  # Mitsuba's own log lines (warnings)
        code = self.proc.wait()
        self.proc = None
        tail = "\n".join(self.log[-15:])
        raise RuntimeError(f"Mitsuba worker exited with status {code}:\n{tail}")

    def request(self, **req) -> dict:
        if self.proc is None:
            self.start()
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        reply = self._reply()
        if "error" in reply:
            raise RuntimeError(reply["error"])
        return reply

    def render(self, scene: Scene, spp: int, out: Path, seed: int = 0) -> tuple[dict, Path]:
        t = self.request(op="render", scene=str(scene.path), defines=scene.defines, spp=spp, seed=seed, out=str(out))
        return t, out

    def reference(self, scene: Scene, spp: int, out: Path) -> None:
        passes = max(1, math.ceil(spp / REF_PASS_SPP))
        self.request(op="reference", scene=str(scene.path), defines=scene.defines, passes=passes, pass_spp=REF_PASS_SPP, seed=REF_SEED * 1000, out=str(out))

    def close(self) -> None:
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.wait()
            self.proc = None


def start_mitsuba(threads: int, mode: str = "rgb") -> tuple[Mitsuba, str | None]:
    """The llvm_ad_rgb worker (llvm_ad_spectral for `mode` "spectral"), or scalar_rgb (scalar_spectral) with a
    loud note (returned) when it cannot start."""
    llvm = llvm_library()
    why = None
    if llvm is None:
        given = os.environ.get("DRJIT_LIBLLVM_PATH")
        why = (f"DRJIT_LIBLLVM_PATH={given} does not exist" if given else
               "libLLVM 19 not found by `ldconfig -p` (Debian: apt-get install libllvm19) and DRJIT_LIBLLVM_PATH not set")  # fmt: skip
    else:
        m = Mitsuba(f"llvm_ad_{mode}", threads, llvm)
        try:
            m.start()
            return m, None
        except RuntimeError as e:
            why = f"the llvm_ad_{mode} worker did not start ({llvm}): {e}"
    m = Mitsuba(f"scalar_{mode}", threads, None)
    m.start()
    return m, why


# ---------------------------------------------------------------------------------------------------------
# gonio


def run_gonio(
    binary: Path, scene: Scene, spp: int, threads: int, out: Path, seed: int | None = None, mode: str = "rgb"
) -> tuple[dict, Path]:
    """The whole `gonio render` process: wall and CPU time (all threads); the render loop's own time as
    gonio reports it goes along as `render` (not used in the table). `seed`: `--seed` (else the scene's);
    `mode`: `--mode`."""
    cmd = [str(binary), "render", str(scene.path), "-o", str(out), "--spp", str(spp), "--threads", str(threads)]
    if mode != "rgb":
        cmd += ["--mode", mode]
    if seed is not None:
        cmd += ["--seed", str(seed)]
    for k, v in scene.defines.items():
        cmd += ["-D", f"{k}={v}"]
    cpu0, wall0 = children_cpu(), time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall, cpu = time.perf_counter() - wall0, children_cpu() - cpu0
    if p.returncode != 0:
        lines = [line for line in p.stderr.splitlines() if line.strip()]
        raise RuntimeError(lines[-1] if lines else f"exit status {p.returncode}")
    m = re.search(r"rendered in ([\d.]+) s", p.stderr)
    warnings = sorted({line.strip() for line in p.stderr.splitlines() if "warning" in line.lower()})
    return {"wall": wall, "cpu": cpu, "render": float(m.group(1)) if m else None, "warnings": warnings}, out


# ---------------------------------------------------------------------------------------------------------
# The suite


def run_scene(scene: Scene, args, mitsuba: Mitsuba, tmp: Path) -> dict:
    row: dict = {"scene": scene.name, "file": str(scene.path), "defines": scene.defines, "errors": {}}
    if scene.expected_failure:
        row["expected_failure"] = scene.expected_failure
    renderers = [("gonio", lambda out: run_gonio(args.gonio, scene, args.spp, args.threads, out, mode=args.mode))]
    if args.baseline:
        baseline_mode = args.baseline_mode or args.mode
        renderers.append(("baseline", lambda out: run_gonio(args.baseline, scene, args.spp, args.threads, out, mode=baseline_mode)))
    renderers.append(("mitsuba", lambda out: mitsuba.render(scene, args.spp, out)))
    # Warm Mitsuba up: the JIT kernels of this scene compiled and cached, untimed.
    try:
        mitsuba.render(scene, args.spp, tmp / "warm.npy")
    except RuntimeError as e:
        row["errors"]["mitsuba"] = str(e)
    runs: dict[str, list] = {label: [] for label, _ in renderers}
    images: dict[str, Path] = {}
    for r in range(args.repeats):
        order = renderers if r % 2 == 0 else renderers[::-1]
        for label, render in order:
            if label in row["errors"]:
                continue
            out = tmp / (f"{scene.name}-{label}.exr" if label != "mitsuba" else f"{scene.name}-{label}.npy")
            try:
                t, img = render(out)
            except RuntimeError as e:
                row["errors"][label] = str(e)
                continue
            runs[label].append(t)
            images[label] = img
    for label, ts in runs.items():
        if ts and label not in row["errors"]:
            row[label] = {
                "wall": min(t["wall"] for t in ts),
                "wall_median": statistics.median(t["wall"] for t in ts),
                "cpu": min(t["cpu"] for t in ts),
                "walls": [t["wall"] for t in ts],
            }
            best = min(ts, key=lambda t: t["wall"])
            if "kernels_compiled" in best:
                row[label]["kernels_compiled"] = best["kernels_compiled"]
                row[label]["compile_s"] = best["compile_s"]
            if ts[0].get("render") is not None:
                row[label]["render_loop"] = min(t["render"] for t in ts)
            if ts[0].get("warnings"):
                row[label]["warnings"] = ts[0]["warnings"]
    if "gonio" not in row or "mitsuba" not in row:
        return row  # no comparison: no reference needed
    # The reference (cached), errors and means.
    key = scene_key(scene, args.ref_spp, mitsuba.variant)
    ref_path = CACHE / f"ref-{scene.name}-{args.ref_spp}spp-{mitsuba.variant}-{key}.npy"
    if not ref_path.exists():
        print(f"  [{scene.name}: rendering the reference, Mitsuba {mitsuba.variant} at {args.ref_spp} spp, once; "
              f"cached in {ref_path.relative_to(ROOT)}]", flush=True)  # fmt: skip
        t0 = time.perf_counter()
        try:
            mitsuba.reference(scene, args.ref_spp, ref_path.with_suffix(".tmp.npy"))
            ref_path.with_suffix(".tmp.npy").rename(ref_path)
        except RuntimeError as e:
            row["errors"]["reference"] = str(e)
            return row
        print(f"  [reference done in {time.perf_counter() - t0:.0f} s]", flush=True)
    ref = np.load(ref_path)
    ref_mean = float(ref.mean())
    row["reference"] = {"file": str(ref_path.relative_to(ROOT)), "spp": args.ref_spp, "variant": mitsuba.variant, "mean": ref_mean}
    for label in [label for label, _ in renderers]:
        if label not in row:
            continue
        img = images[label]
        arr = np.load(img) if img.suffix == ".npy" else read_exr(img)
        if arr.shape != ref.shape:
            row["errors"][label] = f"image of shape {arr.shape}, the reference's is {ref.shape}"
            del row[label]
            continue
        row[label]["mse"] = mse(arr, ref)
        row[label]["mean"] = float(arr.mean())
        row[label]["mean_ratio"] = float(arr.mean()) / ref_mean if ref_mean > 0 else float("nan")
        row[label]["nonfinite"] = int(np.count_nonzero(~np.isfinite(arr)))
    return row


def fmt(x: float | None, spec: str) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return format("—", ">" + re.match(r"\d*", spec).group(0))
    return format(x, spec)


def print_table(rows: list[dict], baseline: bool) -> dict:
    head = f"{'scene':<32} {'gonio s':>8} {'mitsuba s':>9} {'time g/m':>8} {'cpu g/m':>7} {'MSE g/m':>8} {'mean g/ref':>10} {'mean m/ref':>10}"
    if baseline:
        head += f" {'base s':>8} {'g/base':>7}"
    print(head)
    print("-" * len(head))
    ratios, findings, failures = {}, [], []
    for row in rows:
        g, m, b = row.get("gonio"), row.get("mitsuba"), row.get("baseline")
        tr = g["wall"] / m["wall"] if g and m else None
        mr = g["mse"] / m["mse"] if g and m and "mse" in g and m["mse"] > 0 else None
        flag = ""
        if g and "mean_ratio" in g and abs(g["mean_ratio"] - 1) > MEAN_TOLERANCE:
            flag = "!"
            noise = m and "mean_ratio" in m and abs(m["mean_ratio"] - 1) > MEAN_TOLERANCE
            findings.append(
                f"{row['scene']}: gonio's image mean is {100 * (g['mean_ratio'] - 1):+.1f} % from the reference's"
                + (f" (Mitsuba's own {args_spp} spp image is {100 * (m['mean_ratio'] - 1):+.1f} % off too: maybe noise)" if noise else "")
            )
        if g and g.get("nonfinite"):
            findings.append(f"{row['scene']}: gonio's image has {g['nonfinite']} non-finite values")
        line = (
            f"{row['scene']:<32} {fmt(g and g['wall'], '8.3f')} {fmt(m and m['wall'], '9.3f')} {fmt(tr, '8.2f')} "
            f"{fmt(g['cpu'] / m['cpu'] if g and m else None, '7.2f')} "
            f"{fmt(mr, '8.2f')} {fmt(g and g.get('mean_ratio'), '10.4f')}{flag or ' '}{fmt(m and m.get('mean_ratio'), '9.4f')}"
        )
        if baseline:
            line += f" {fmt(b and b['wall'], '8.3f')} {fmt(g['wall'] / b['wall'] if g and b else None, '7.2f')}"
        print(line)
        for label, err in row["errors"].items():
            expected = f" (expected: {row['expected_failure']})" if label == "gonio" and row.get("expected_failure") else ""
            first = err.strip().splitlines()[0] if err.strip() else err
            print(f"{'':<4}{label} FAILED{expected}: {first[:300]}")
            failures.append(row["scene"])
        if m and m.get("kernels_compiled"):
            print(f"{'':<4}note: Mitsuba's kept render compiled {m['kernels_compiled']} kernels ({m['compile_s']:.2f} s): not warm")
        if g and g.get("warnings"):
            for w in g["warnings"]:
                print(f"{'':<4}gonio: {w[:200]}")
        if tr is not None:
            ratios[row["scene"]] = (tr, mr)
    print()
    summary: dict = {}
    if ratios:
        gm = math.exp(sum(math.log(t) for t, _ in ratios.values()) / len(ratios))
        worst = max(ratios, key=lambda k: ratios[k][0])
        mses = [m for _, m in ratios.values() if m is not None and m > 0]
        gm_mse = math.exp(sum(math.log(m) for m in mses) / len(mses)) if mses else float("nan")
        worst_mse = max((k for k in ratios if ratios[k][1] is not None), key=lambda k: ratios[k][1], default=None)
        print(f"geometric mean of the time ratios gonio/Mitsuba: {gm:.3f}   over {len(ratios)} scenes"
              + (f" (left out, a renderer failed: {', '.join(sorted(set(failures)))})" if failures else ""))  # fmt: skip
        print(f"worst scene (time): {worst}  {ratios[worst][0]:.2f}x")
        if worst_mse:
            print(f"MSE ratios: geometric mean {gm_mse:.3f}, worst {worst_mse} {ratios[worst_mse][1]:.2f}x")
        summary = {"geomean_time_ratio": gm, "worst_scene": worst, "worst_time_ratio": ratios[worst][0], "geomean_mse_ratio": gm_mse,
                   "worst_mse_scene": worst_mse, "scenes_compared": len(ratios), "failed": sorted(set(failures))}  # fmt: skip
    else:
        print("no scene ran in both renderers")
    if findings:
        print("\nCORRECTNESS FINDINGS (image means disagree by more than 1 %):")
        for f in findings:
            print("  " + f)
        summary["findings"] = findings
    return summary


args_spp = 32  # for the findings' wording


def main() -> None:
    global args_spp
    if len(sys.argv) > 1 and sys.argv[1] == "--mitsuba-server":
        mitsuba_server(sys.argv[2], int(sys.argv[3]))
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gonio", type=Path, default=Path(os.environ.get("GONIO_BIN", ROOT / "target" / "release" / "gonio")),
                    help="the gonio binary (default: $GONIO_BIN, else target/release/gonio)")  # fmt: skip
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=os.cpu_count(), help="worker threads on both sides (default: all cores)")
    ap.add_argument("--scenes", action="append", metavar="GLOB", help="only scenes whose name matches (repeatable)")
    ap.add_argument("--baseline", type=Path, help="another gonio binary timed in the same rounds (e.g. a build before a change)")
    ap.add_argument("--mode", choices=["rgb", "spectral"], default="rgb",
                    help="gonio's --mode, against Mitsuba's llvm_ad_rgb or llvm_ad_spectral (and references of that variant)")
    ap.add_argument("--baseline-mode", choices=["rgb", "spectral"],
                    help="the baseline's --mode (default: --mode); `--mode spectral --baseline BIN --baseline-mode rgb` times "
                         "spectral against RGB mode in the same rounds")  # fmt: skip
    ap.add_argument("--json", type=Path, metavar="OUT", help="write every number to OUT")
    ap.add_argument("--list", action="store_true", help="list the scenes and exit")
    ap.add_argument("--table", type=Path, metavar="JSON", help="print the table of an earlier run's --json output and exit")
    args = ap.parse_args()
    args_spp = args.spp
    if args.table:
        run = json.loads(args.table.read_text())
        args_spp = run["spp"]
        print(f"== {run['gonio']} vs Mitsuba 3 {run['variant']}, {run['spp']} spp, {run['threads']} threads, fastest of {run['repeats']}; "
              f"reference {run['ref_spp']} spp ({run['load']} at the end)")  # fmt: skip
        print_table(run["scenes"], run["baseline"] is not None)
        return
    scenes = all_scenes()
    if args.scenes:
        scenes = [s for s in scenes if any(fnmatch.fnmatch(s.name, g) for g in args.scenes)]
    if args.list:
        for s in scenes:
            print(f"{s.name:<32} {s.path}" + (f"   (expected to fail in gonio: {s.expected_failure})" if s.expected_failure else ""))
        return
    if not scenes:
        sys.exit("no scene matches --scenes")
    for b in [args.gonio] + ([args.baseline] if args.baseline else []):
        if not b.exists():
            sys.exit(f"{b} not found: build it (`cargo build --release -p gonio-cli`, or the dist profile) or pass --gonio / GONIO_BIN")
    try:
        import mitsuba  # noqa: F401
    except ImportError:
        sys.exit("mitsuba is not installed in this Python: `make venv` installs it into .venv (requirements-dev.txt)")
    generated_assets()
    mitsuba, fallback = start_mitsuba(args.threads, args.mode)
    if fallback:
        banner = "!" * 100
        print(f"{banner}\n!! Mitsuba llvm_ad_{args.mode} UNAVAILABLE — timing against scalar_{args.mode} instead, which is NOT the suite's baseline.\n"
              f"!! {fallback}\n{banner}", flush=True)  # fmt: skip
    print(f"== gonio ({args.gonio}) vs Mitsuba 3 {mitsuba.variant}: {len(scenes)} scenes, {args.spp} spp, {args.threads} threads each, "
          f"fastest of {args.repeats} in alternating rounds; MSE against Mitsuba at {args.ref_spp} spp ({load_note()})", flush=True)  # fmt: skip
    tmp = Path(tempfile.mkdtemp(prefix="gonio-suite-"))
    rows = []
    t0 = time.perf_counter()
    try:
        for scene in scenes:
            print(f"  {scene.name} …", flush=True)
            row = run_scene(scene, args, mitsuba, tmp)
            rows.append(row)
            done = [f"{label} {row[label]['wall']:.2f} s" for label in ("gonio", "baseline", "mitsuba") if label in row]
            failed = [f"{label} FAILED" for label in row["errors"]]
            print(f"    {', '.join(done + failed)}", flush=True)
    finally:
        mitsuba.close()
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"\n== results ({time.perf_counter() - t0:.0f} s; Mitsuba {mitsuba.variant}; {load_note()} at the end)")
    summary = print_table(rows, args.baseline is not None)
    print("(time: wall seconds, the fastest round; gonio's whole process against Mitsuba's load + render in a warm process. "
          "cpu g/m: the same with CPU time (user + system, all threads; the least of the rounds), fairer on a loaded machine. "
          "MSE g/m: gonio's MSE / Mitsuba's, against the reference. mean x/ref: the image mean / the reference's; ! = gonio off by > 1 %)")  # fmt: skip
    if args.json:
        out = {"gonio": str(args.gonio), "baseline": str(args.baseline) if args.baseline else None, "variant": mitsuba.variant,
               "fallback": fallback, "spp": args.spp, "ref_spp": args.ref_spp, "repeats": args.repeats, "threads": args.threads,
               "load": load_note(), "scenes": rows, "summary": summary}  # fmt: skip
        args.json.write_text(json.dumps(out, indent=1))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
