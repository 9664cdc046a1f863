#!/usr/bin/env python3
"""gonio against Mitsuba 3 on the same scene files, and how gonio's cost grows with work.

Run by `make bench` (never by `make test`): a benchmark, not a test. It prints three tables.

1. **gonio vs Mitsuba 3.** Renders ../shared/scenes/cornell-box.xml and material-spheres.xml with gonio
   (the release CLI) and with Mitsuba 3 (variants `scalar_rgb` and `llvm_ad_rgb`), at the same spp and
   resolution, and prints wall and CPU time (user + system, all threads), the ratios gonio / Mitsuba, and
   each image's mean squared error against a high-spp reference. The reference is rendered once by
   Mitsuba (`llvm_ad_rgb` if it runs here, else `scalar_rgb`) and cached in bench/.cache/. `llvm_ad_rgb`
   needs libLLVM 19: the script looks for it with `ldconfig -p` (or takes DRJIT_LIBLLVM_PATH as given)
   and skips the variant with a message when it is missing. Every render is repeated (`--repeats`) and
   the fastest kept; the repeats go in rounds of one render of each renderer (gonio, `--baseline` builds,
   Mitsuba's variants), so that a change in the machine's load falls on all of them alike. Mitsuba's LLVM
   kernels are compiled in the first repeat.
2. **Cost against pixels × spp** for the Cornell box (should be linear: constant ns per sample).
3. **Cost against triangle count**, 10³ … 10⁶ (a tessellated sphere written as binary PLY): BVH build
   time (should grow as n log n) and render time at fixed pixels × spp (should grow as log n).

What is timed, the same way on both sides:
- **wall**: the render alone. gonio: the render loop, as the CLI reports it (not the scene load, BVH build
  or image writing). Mitsuba: `mi.render` + `dr.eval` + the copy to NumPy, after `mi.load_file`; the JIT
  kernels come from Dr.Jit's on-disk cache once the first repeat (or any earlier run) has compiled them,
  and the fastest repeat is kept, so this is Mitsuba's warm-cache time.
- **cpu**: scene load + render, user + system time of all threads. gonio: its whole process (start-up,
  load, BVH, render, writing the EXR). Mitsuba: `mi.load_file` through the copy to NumPy (not the Python
  start-up, imports and `set_variant`). Loading counts on both sides because both build tables then
  (gonio's `roughplastic` coating tables for material-spheres.xml took ≈ 0.3 s of CPU until 2026-12-02,
  ≈ 0.02 s since).

On a shared machine wall time depends on the other processes: the CPU-time ratio is the fairer one
there, wall time on an idle machine. The load average is printed with each table.

Usage: python bench/render_vs_mitsuba.py [--spp 64] [--ref-spp 2048] [--repeats 2] [--skip-compare] [--skip-scaling]
                                        [--baseline OTHER_GONIO ...]
(GONIO_BIN overrides the gonio binary, target/release/gonio by default; --baseline adds rows for another
gonio build, e.g. one from before a change, timed in the same run.)
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT.parent / "shared" / "scenes"
CACHE = ROOT / "bench" / ".cache"
GONIO = Path(os.environ.get("GONIO_BIN", ROOT / "target" / "release" / "gonio"))
VARIANTS = ["scalar_rgb", "llvm_ad_rgb"]
REF_SEED = 7


# ---------------------------------------------------------------------------------------------------------
# Workers: one Mitsuba render per process (so that variants and their thread pools do not interfere).


def mitsuba_worker(variant: str, scene: str, spp: int, out: str, defines: dict[str, str], seed: int) -> None:
    import mitsuba as mi

    mi.set_variant(variant)
    import drjit as dr

    load_cpu0 = time.process_time()
    s = mi.load_file(scene, **defines)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    img = mi.render(s, spp=spp, seed=seed)
    dr.eval(img)
    arr = np.array(img, dtype=np.float32)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    np.save(out, arr[..., :3])
    # cpu counts the scene load as well, as gonio's (its whole process) does: both renderers build tables
    # at load time (e.g. roughplastic's), which a render-only CPU time would count for gonio alone.
    print(json.dumps({"wall": wall, "cpu": cpu0 - load_cpu0 + cpu, "cpu_render": cpu}))


def llvm_library() -> str | None:
    """libLLVM 19 for Dr.Jit's LLVM backend (LLVM 15 crashes it), from DRJIT_LIBLLVM_PATH or ldconfig."""
    given = os.environ.get("DRJIT_LIBLLVM_PATH")
    if given:
        return given if Path(given).exists() else None
    try:
        listing = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True, check=False).stdout
    except OSError:
        return None
    for line in listing.splitlines():
        m = re.search(r"(libLLVM(?:-19)?\.so\.19[.\d]*|libLLVM-19\.so[.\d]*)\s.*=>\s*(\S+)", line)
        if m:
            return m.group(2)
    return None


def run_mitsuba(variant: str, scene: Path, spp: int, defines: dict[str, str], llvm: str | None, seed: int = 0) -> tuple[dict, np.ndarray]:
    env = dict(os.environ)
    if variant.startswith("llvm"):
        env["DRJIT_LIBLLVM_PATH"] = llvm or ""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "img.npy"
        cmd = [sys.executable, __file__, "--worker", variant, str(scene), str(spp), str(out), json.dumps(defines), str(seed)]
        p = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
        if p.returncode != 0:
            raise RuntimeError(f"mitsuba {variant} failed on {scene.name}:\n{p.stderr[-2000:]}")
        times = json.loads(p.stdout.strip().splitlines()[-1])
        return times, np.load(out)


def read_exr(path: Path) -> np.ndarray:
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(str(path)), dtype=np.float32)[..., :3]


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_gonio(scene: Path, spp: int, defines: dict[str, str], out: Path, extra: list[str] | None = None, binary: Path | None = None) -> dict:
    """Render with the CLI (`binary`, GONIO by default); returns wall (the render loop, as gonio reports
    it), cpu (the whole process, scene loading included), load and bvh (seconds)."""
    cmd = [str(binary or GONIO), "render", str(scene), "-o", str(out), "--spp", str(spp)]
    for k, v in defines.items():
        cmd += ["-D", f"{k}={v}"]
    cmd += extra or []
    cpu0 = children_cpu()
    p = subprocess.run(cmd, capture_output=True, text=True, check=False)
    cpu = children_cpu() - cpu0
    if p.returncode != 0:
        raise RuntimeError(f"gonio failed on {scene.name}:\n{p.stderr[-2000:]}")
    m = re.search(r"loaded in ([\d.]+) s(?:, BVH built in ([\d.]+) s)?, rendered in ([\d.]+) s", p.stderr)
    if not m:
        raise RuntimeError(f"unexpected gonio output: {p.stderr}")
    return {"wall": float(m.group(3)), "cpu": cpu, "load": float(m.group(1)), "bvh": float(m.group(2) or "nan")}


def best_of(repeats: int, f):
    return fastest([f() for _ in range(repeats)])


def fastest(runs: list):
    """The run with the fastest wall time, given the least CPU time of all the runs (a run is a dict of
    times, or a tuple whose first item is one)."""
    best = min(runs, key=lambda r: r[0]["wall"] if isinstance(r, tuple) else r["wall"])
    if isinstance(best, tuple):
        best[0]["cpu"] = min(r[0]["cpu"] for r in runs)
    else:
        best["cpu"] = min(r["cpu"] for r in runs)
    return best


def interleaved(repeats: int, runners: list) -> list:
    """Each of `runners` ((label, render) pairs; a render returns (times, image)) `repeats` times, in rounds
    of one render of each, so that a change in the machine's load falls on all of them alike rather than
    on whichever ran during it. Per runner: (label, (times, image), error), times with the fastest wall
    time and the least CPU time of its renders; error is the message of a failed render (None if all ran)."""
    runs: dict[str, list] = {label: [] for label, _ in runners}
    errors: dict[str, str] = {}
    for _ in range(repeats):
        for label, render in runners:
            if label in errors:
                continue
            try:
                runs[label].append(render())
            except RuntimeError as e:
                errors[label] = str(e)
    out = []
    for label, _ in runners:
        if label in errors:
            out.append((label, (None, None), errors[label]))
            continue
        out.append((label, fastest(runs[label]), None))
    return out


def mse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))


def reference(scene: Path, ref_spp: int, llvm: str | None) -> tuple[np.ndarray, str]:
    variant = "llvm_ad_rgb" if llvm else "scalar_rgb"
    # Its own seed, so that its samples are independent of the timed renders' (seed 0).
    key = hashlib.sha256(scene.read_bytes() + f"{ref_spp} seed {REF_SEED}".encode()).hexdigest()[:16]
    CACHE.mkdir(parents=True, exist_ok=True)
    path = CACHE / f"{scene.stem}-{ref_spp}spp-{key}.npy"
    label = f"Mitsuba {variant} at {ref_spp} spp"
    if path.exists():
        return np.load(path), label + " (cached)"
    print(f"rendering the reference of {scene.name}: {label} (once; cached in {path.relative_to(ROOT)}) …", flush=True)
    try:
        _, img = run_mitsuba(variant, scene, ref_spp, {}, llvm, REF_SEED)
    except RuntimeError:
        if variant == "scalar_rgb":
            raise
        variant = "scalar_rgb"
        label = f"Mitsuba {variant} at {ref_spp} spp"
        _, img = run_mitsuba(variant, scene, ref_spp, {}, llvm, REF_SEED)
    np.save(path, img)
    return img, label


def load_note() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.1f} / {five:.1f} on {os.cpu_count()} cores"


# ---------------------------------------------------------------------------------------------------------
# 1. gonio vs Mitsuba


def compare(spp: int, ref_spp: int, repeats: int, tmp: Path, baseline: list[Path] | None = None) -> None:
    llvm = llvm_library()
    variants = list(VARIANTS)
    if llvm is None:
        print("llvm_ad_rgb skipped: libLLVM 19 not found by `ldconfig -p` (Debian: apt-get install libllvm19), "
              "and DRJIT_LIBLLVM_PATH is not set")
        variants.remove("llvm_ad_rgb")
    print(f"\n== gonio vs Mitsuba 3, {spp} spp, best of {repeats} in alternation ({load_note()})")
    header = f"{'scene':<18} {'renderer':<20} {'wall s':>8} {'cpu s':>8} {'MSE':>11}   {'gonio/this wall':>15} {'cpu':>6} {'MSE':>6}"
    print(header)
    print("-" * len(header))
    for name in ["cornell-box", "material-spheres"]:
        scene = SCENES / f"{name}.xml"
        ref, label = reference(scene, ref_spp, llvm)

        def gonio(binary: Path | None, out: Path):
            return lambda: (run_gonio(scene, spp, {}, out, binary=binary), out)

        # (label, render): gonio, other gonio builds (e.g. before a change), Mitsuba's variants.
        runners = [("gonio", gonio(None, tmp / f"{name}.exr"))]
        for k, other in enumerate(baseline or []):
            runners.append((f"gonio baseline {k + 1}" if len(baseline) > 1 else "gonio baseline", gonio(other, tmp / f"{name}-baseline{k}.exr")))
        runners += [(f"mitsuba {v}", lambda v=v: run_mitsuba(v, scene, spp, {}, llvm)) for v in variants]
        rows = []
        for label_r, (t, img), error in interleaved(repeats, runners):
            if error is not None and label_r == "gonio":
                raise RuntimeError(error)
            if error is not None:
                print(f"{name:<18} {label_r:<20} failed: {error.splitlines()[-1]}")
                continue
            rows.append((label_r, t, mse(read_exr(img) if isinstance(img, Path) else img, ref)))
        gt, ge = rows[0][1], rows[0][2]
        for label_r, t, e in rows:
            ratio = f"{gt['wall'] / t['wall']:>15.2f} {gt['cpu'] / t['cpu']:>6.2f} {ge / e:>6.2f}" if label_r != "gonio" else ""
            print(f"{name:<18} {label_r:<20} {t['wall']:>8.3f} {t['cpu']:>8.3f} {e:>11.4e}   {ratio}")
        print(f"{'':<18} (reference: {label})")


# ---------------------------------------------------------------------------------------------------------
# 2. pixels × spp


def scaling_work(repeats: int, tmp: Path) -> None:
    print(f"\n== gonio: Cornell box, render time against pixels × spp ({load_note()})")
    print(f"{'res':>5} {'spp':>5} {'pixels×spp':>12} {'wall s':>8} {'cpu s':>8} {'ns/sample (cpu)':>16}")
    scene = SCENES / "cornell-box.xml"
    for res, spp in [(64, 16), (128, 16), (128, 64), (256, 16), (256, 64), (512, 64)]:
        g = best_of(repeats, lambda res=res, spp=spp: run_gonio(scene, spp, {"res": str(res)}, tmp / "work.exr"))
        n = res * res * spp
        print(f"{res:>5} {spp:>5} {n:>12} {g['wall']:>8.3f} {g['cpu']:>8.3f} {1e9 * g['cpu'] / n:>16.1f}")


# ---------------------------------------------------------------------------------------------------------
# 3. triangle count


def write_sphere_ply(path: Path, n_theta: int, n_phi: int) -> int:
    """A unit UV sphere: n_theta rings × n_phi segments, 2 n_phi (n_theta − 1) triangles (binary PLY)."""
    theta = np.linspace(0.0, np.pi, n_theta + 1)[1:-1]
    phi = np.linspace(0.0, 2 * np.pi, n_phi, endpoint=False)
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring = np.stack([st * np.cos(phi), st * np.sin(phi), np.broadcast_to(ct, st.shape * np.array([1, n_phi]))], -1).reshape(-1, 3)
    verts = np.concatenate([[[0, 0, 1]], ring, [[0, 0, -1]]]).astype("<f4")
    rings = n_theta - 1
    idx = lambda r, k: 1 + r * n_phi + (k % n_phi)  # noqa: E731
    k = np.arange(n_phi)
    faces = [np.stack([np.zeros(n_phi, int), idx(0, k), idx(0, k + 1)], -1)]
    for r in range(rings - 1):
        faces.append(np.stack([idx(r, k), idx(r + 1, k), idx(r + 1, k + 1)], -1))
        faces.append(np.stack([idx(r, k), idx(r + 1, k + 1), idx(r, k + 1)], -1))
    south = len(verts) - 1
    faces.append(np.stack([np.full(n_phi, south), idx(rings - 1, k + 1), idx(rings - 1, k)], -1))
    faces = np.concatenate(faces).astype("<i4")
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    body = np.empty(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    body["n"], body["i"] = 3, faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(verts.tobytes())
        f.write(body.tobytes())
    return len(faces)


SPHERE_SCENE = """<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 4.5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="128"/><integer name="height" value="128"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
    <shape type="ply">
        <string name="filename" value="{ply}"/>
        <boolean name="face_normals" value="true"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.5, 0.5"/></bsdf>
    </shape>
</scene>
"""


def scaling_triangles(repeats: int, tmp: Path) -> None:
    print(f"\n== gonio: tessellated sphere, BVH build and render (128×128, 8 spp) against triangles ({load_note()})")
    print(f"{'triangles':>10} {'BVH build s':>12} {'build/(n log2 n) ns':>20} {'render s':>9} {'render/log2 n':>14}")
    base = None
    for n_theta, n_phi in [(23, 23), (71, 71), (224, 224), (708, 708)]:
        ply = tmp / f"sphere-{n_theta}.ply"
        n = write_sphere_ply(ply, n_theta, n_phi)
        xml = tmp / f"sphere-{n_theta}.xml"
        xml.write_text(SPHERE_SCENE.format(ply=ply))
        g = best_of(repeats, lambda xml=xml: run_gonio(xml, 8, {}, tmp / "tri.exr"))
        lg = np.log2(n)
        base = base or g["wall"] / lg
        print(f"{n:>10} {g['bvh']:>12.4f} {1e9 * g['bvh'] / (n * lg):>20.1f} {g['wall']:>9.3f} {g['wall'] / lg / base:>14.2f}")
    print("(render time of the render loop, wall; render/log2 n relative to the smallest mesh: constant when it grows as log n)")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        variant, scene, spp, out, defines = sys.argv[2:7]
        seed = int(sys.argv[7]) if len(sys.argv) > 7 else 0
        mitsuba_worker(variant, scene, int(spp), out, json.loads(defines), seed)
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--skip-compare", action="store_true")
    ap.add_argument("--skip-scaling", action="store_true")
    ap.add_argument(
        "--baseline", type=Path, action="append", help="another gonio binary to time in the same run (e.g. a build before a change; repeatable)"
    )
    args = ap.parse_args()
    if not GONIO.exists():
        sys.exit(f"{GONIO} not found: run `cargo build --release -p gonio-cli` (or `make cli`) first")
    try:
        import mitsuba  # noqa: F401
    except ImportError:
        sys.exit("mitsuba is not installed in this Python: `make venv` installs it into .venv (requirements-dev.txt)")
    tmp = Path(tempfile.mkdtemp(prefix="gonio-bench-"))
    try:
        if not args.skip_compare:
            compare(args.spp, args.ref_spp, args.repeats, tmp, args.baseline)
        if not args.skip_scaling:
            scaling_work(args.repeats, tmp)
            scaling_triangles(args.repeats, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
