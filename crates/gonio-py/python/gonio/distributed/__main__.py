"""``python -m gonio.distributed``: the command line behind ``gonio render|fit|check --ray ADDRESS``.

    python -m gonio.distributed render SCENE.xml -o out.exr --spp 256 --address auto
    python -m gonio.distributed fit a.bsdf b.bsdf --model ggx --model roughplastic -o fits/ --address auto
    python -m gonio.distributed check --all --address auto
    python -m gonio.distributed preview '{"type": "roughconductor"}' --grid alpha=0.05,0.3 --grid material=Au,Cu -o s.png

Exit codes as ``gonio``'s: 0 success, 1 a check or fit failed, 2 bad input, 130 interrupted.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

from . import check, check_all, fit, fit_table, preview, render, TaskError
from .. import SceneError, SpecError, _gonio, write_image


def _defines(pairs: List[str]) -> dict:
    out = {}
    for d in pairs:
        k, sep, v = d.partition("=")
        if not sep or not k:
            raise ValueError(f"-D expects NAME=VALUE, got `{d}`")
        out[k] = v
    return out


def _render(a: argparse.Namespace) -> int:
    output = Path(a.output) if a.output else Path(a.scene).with_suffix(".exr")
    r = render(a.scene, spp=a.spp, seed=a.seed, address=a.address, chunk_spp=a.chunk_spp, num_cpus=a.cpus_per_task,
               progress=not a.quiet, defines=_defines(a.define), mode=a.mode)
    if r.nonfinite:
        print(f"gonio: warning: {r.nonfinite} non-finite samples dropped (counted as black)", file=sys.stderr)
    if r.image is None:
        print("gonio: interrupted before the first part was merged: nothing written", file=sys.stderr)
        return 130
    write_image(str(output), r.image)
    if not a.quiet:
        nodes = len({t[3] for t in r.tasks})
        print(f"gonio: {r.image.shape[1]}×{r.image.shape[0]}, {r.spp} spp in {len(r.tasks)} Ray tasks on {nodes} node(s), "
              f"{r.seconds:.3f} s → {output}", file=sys.stderr)
    if r.cancelled:
        print(f"gonio: interrupted: wrote {r.spp} of {r.spp_requested} spp to {output}", file=sys.stderr)
        return 130
    return 0


def _fit(a: argparse.Namespace) -> int:
    rows = fit(a.files, a.models, strata=a.strata, address=a.address, output_dir=a.output, progress=not a.quiet)
    print(fit_table(rows))
    if a.output:
        print(f"wrote the best fit of each file to {a.output}/<file stem>.xml")
    return 1 if any(r.failure for r in rows) else 0


def _check(a: argparse.Namespace) -> int:
    if a.all:
        rows, bad = check_all(a.samples, a.sweep, a.seed, a.address, a.cpus_per_task, progress=not a.quiet)
    else:
        rows, bad = check(a.specs, a.samples, a.sweep, a.seed, address=a.address, num_cpus=a.cpus_per_task,
                          progress=not a.quiet), []
    failed = [r for r in rows if not r.get("passed")]
    missed = [r for r in bad if "error" in r or r["missed"] is not None]
    if a.json:
        def obj(r: dict) -> dict:
            if "error" in r:
                return {"name": r["spec"], "passed": False, "error": r["error"]}
            o = r["report"]
            if "violation" in r:
                o = {**o, "expected_violation": r["violation"], "detected": r["missed"] is None}
            return o
        value = {"examples": [obj(r) for r in rows], "violations": [obj(r) for r in bad]} if a.all else [obj(r) for r in rows]
        print(json.dumps(value, indent=2, default=lambda v: None))
    else:
        for r in rows:
            print(r["table"] if "error" not in r else f"{r['spec']}: FAILED to run: {r['error']}", end="" if "error" not in r else "\n")
        if bad:
            print("\nexpected violations (non-physical models kept for teaching)")
        for r in bad:
            if "error" in r:
                print(f"{r['spec']}: FAILED to run: {r['error']}")
                continue
            print(r["table"], end="")
            kind = r["violation"]
            print(f"  `{kind}`: violation detected" if r["missed"] is None else f"  `{kind}`: NOT DETECTED ({r['missed'].splitlines()[0]})")
        print(f"{len(rows) - len(failed)} of {len(rows)} BSDFs passed every check")
        if bad:
            print(f"{len(bad) - len(missed)} of {len(bad)} expected violations detected")
    return 0 if not failed and not missed else 1


def _spec_arg(arg: str) -> Tuple[Any, str]:
    """A BSDF argument as ``gonio preview`` takes it: JSON or XML text, or a file (JSON, XML, or measured
    data, read where the spec names it: on every node), and the name of its source."""
    if arg.lstrip().startswith(("{", "<")):
        return arg, "<argument>"
    plugin = _gonio.measured_plugin(arg)
    if plugin:
        return {"type": plugin, "filename": arg}, arg
    return Path(arg).read_text(), arg


def _preview(a: argparse.Namespace) -> int:
    grid: Dict[str, Any] = {}
    for g in a.grid:
        name, values = json.loads(_gonio._parse_grid_option(g))
        if name in grid:
            raise ValueError(f"--grid {name} is given twice")
        grid[name] = values
    light = None
    if a.light is not None:
        try:
            light = tuple(float(v) for v in a.light.split(","))
        except ValueError:
            raise ValueError(f"--light expects a direction X,Y,Z of three numbers, got `{a.light}`") from None
    spec, source = _spec_arg(a.bsdf)
    r = preview(spec, grid, env=a.env, light=light, size=a.size, spp=a.spp, seed=a.seed, output=a.output,
                exposure=a.exposure, source=source, address=a.address, num_cpus=a.cpus_per_task, progress=not a.quiet,
                mode=a.mode)
    if r.nonfinite:
        print(f"gonio: warning: dropped {r.nonfinite} non-finite samples (counted as black)", file=sys.stderr)
    if not a.quiet:
        print(f"gonio: {len(r.images)} sphere(s), {a.size}×{a.size} px, {a.spp} spp in {len(r.images)} Ray tasks, "
              f"{r.seconds:.2f} s → {a.output}", file=sys.stderr)
    return 0


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="python -m gonio.distributed", description="gonio's renders, fits and checks on a Ray cluster")
    p.add_argument("--address", default=None, help="`auto` (an existing cluster), `local` (start one here) or a cluster address")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="render a Mitsuba 3 XML scene, its samples split over the cluster")
    r.add_argument("scene")
    r.add_argument("-o", "--output")
    r.add_argument("--spp", type=int)
    r.add_argument("--seed", type=int)
    r.add_argument("-D", dest="define", action="append", default=[], metavar="NAME=VALUE")
    r.add_argument("--chunk-spp", type=int, help="samples per pixel in each task (default: ~4 tasks per CPU)")
    r.add_argument("--cpus-per-task", type=int, default=1, help="CPUs (render threads) per task")
    r.add_argument("--mode", choices=["rgb", "spectral"], default="rgb", help="how light is carried (as gonio render --mode)")
    r.add_argument("-q", "--quiet", action="store_true")
    f = sub.add_parser("fit", help="fit models to measured files, one task per file and model")
    f.add_argument("files", nargs="+")
    f.add_argument("--model", dest="models", action="append", required=True)
    f.add_argument("-o", "--output", help="folder for the best fit of each file, <stem>.xml")
    f.add_argument("--strata", type=int, default=12)
    f.add_argument("-q", "--quiet", action="store_true")
    c = sub.add_parser("check", help="the verification harness, one task per model")
    c.add_argument("specs", nargs="*")
    c.add_argument("--all", action="store_true")
    c.add_argument("--json", action="store_true")
    c.add_argument("--samples", type=int, default=1_000_000)
    c.add_argument("--sweep", type=int, default=1_000_000)
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--cpus-per-task", type=int, default=1)
    c.add_argument("-q", "--quiet", action="store_true")
    v = sub.add_parser("preview", help="lit spheres of one BSDF swept over a grid, one task per sphere")
    v.add_argument("bsdf")
    v.add_argument("-o", "--output", required=True)
    v.add_argument("--grid", action="append", default=[], metavar="NAME=V1,V2,...")
    v.add_argument("--env", help="gradient, constant or an environment image (read here)")
    v.add_argument("--light", metavar="X,Y,Z")
    v.add_argument("--spp", type=int, default=64)
    v.add_argument("--size", type=int, default=256)
    v.add_argument("--seed", type=int, default=0)
    v.add_argument("--exposure", type=float, default=0.0)
    v.add_argument("--cpus-per-task", type=int, default=1)
    v.add_argument("--mode", choices=["rgb", "spectral"], default="rgb", help="how light is carried (as gonio preview --mode)")
    v.add_argument("-q", "--quiet", action="store_true")
    for s in (r, f, c, v):
        s.add_argument("--address", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.command == "check" and bool(a.all) == bool(a.specs):
        p.error("check takes either --all or specs")
    try:
        return {"render": _render, "fit": _fit, "check": _check, "preview": _preview}[a.command](a)
    except KeyboardInterrupt:
        print("gonio: interrupted", file=sys.stderr)
        return 130
    except TaskError as e:
        print(f"gonio: error: {e}", file=sys.stderr)
        return 1
    except (SceneError, SpecError, ValueError, OSError) as e:
        print(f"gonio: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
