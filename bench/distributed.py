"""Scaling of gonio.distributed on a local Ray cluster (issue 32): one worker node of one CPU, then two.

    .venv/bin/python bench/distributed.py [--spp 256] [--scene bench/scenes/cbox-obj-meshlight.xml]
        [--models ggx+diffuse ...] [--strata 12] [--json out.json]

- render: the scene at --spp, distributed (default chunking: about four tasks per CPU), on one worker node
  and on two; efficiency = T(1 node) / (2 · T(2 nodes)) (issue 32 asks ≥ 0.85);
- fit: the seven RGL materials × --models, one task per material × model; efficiency as above (≥ 0.8);
- overhead per task: (nodes · wall − Σ seconds inside the tasks) / tasks, for each run, and for a run of
  many tiny tasks (1 spp of a 16 × 16 image each).

Each configuration runs untimed first until every node has run its tasks (worker processes start, gonio
is imported, the scene is loaded and cached per worker), then timed: a persistent cluster's steady state.
The cluster listens on 127.0.0.1 only. On a machine shared with other work the numbers are those of the
machine: the report prints the load average before and after.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import shutil
import sys
import tempfile
import time

# Ray on this machine only (127.0.0.1 for every node and the driver; read when Ray is imported).
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
import ray  # noqa: E402
from ray.cluster_utils import Cluster  # noqa: E402

from gonio import distributed  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
RGL = ROOT.parent / "shared" / "data" / "rgl"
STORE = 100 * 1024 * 1024


def overhead(nodes: int, wall: float, seconds: list) -> float:
    return (nodes * wall - sum(seconds)) / len(seconds)


def warm_render(scene, nodes: int) -> None:
    """Untimed renders of 1-spp tasks until every node has run one: its worker started, gonio imported,
    the scene loaded and cached. (A node that joined last starts its worker while the first node's warm
    worker already finishes the tasks, so one render does not warm it.)"""
    seen: set = set()
    for _ in range(50):
        r = distributed.render(scene, spp=4 * nodes, seed=1, chunk_spp=1, progress=False)
        seen |= {node for _, _, _, node in r.tasks}
        if len(seen) >= nodes:
            return
    raise SystemExit(f"warm-up: tasks ran on {len(seen)} of {nodes} nodes after 50 renders")


def run_render(scene: str, spp: int, nodes: int) -> dict:
    warm_render(scene, nodes)
    t = time.perf_counter()
    r = distributed.render(scene, spp=spp, seed=1, progress=False)
    wall = time.perf_counter() - t
    secs = [s for _, _, s, _ in r.tasks]
    return {"wall": wall, "tasks": len(secs), "task_seconds": sum(secs), "overhead": overhead(nodes, wall, secs)}


def run_fit(files: list, models: list, strata: int, nodes: int) -> dict:
    distributed.fit(files, models, strata=strata, progress=False)  # warm-up: the fit's workers on every node
    t = time.perf_counter()
    rows = distributed.fit(files, models, strata=strata, progress=False)
    wall = time.perf_counter() - t
    failed = [r.failure for r in rows if r.failure]
    if failed:
        raise SystemExit(f"fits failed: {failed}")
    secs = [r.seconds for r in rows]
    return {"wall": wall, "tasks": len(secs), "task_seconds": sum(secs), "overhead": overhead(nodes, wall, secs)}


def run_tiny(nodes: int, tasks: int = 40) -> dict:
    scene = {"type": "scene", "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 16, "height": 16, "rfilter": {"type": "box"}}},
             "ball": {"type": "sphere"}, "sky": {"type": "constant"}}
    warm_render(scene, nodes)
    t = time.perf_counter()
    r = distributed.render(scene, spp=tasks, chunk_spp=1, progress=False)
    wall = time.perf_counter() - t
    return {"wall": wall, "tasks": tasks, "overhead": overhead(nodes, wall, [s for _, _, s, _ in r.tasks])}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--scene", default=str(ROOT / "bench" / "scenes" / "cbox-obj-meshlight.xml"))
    p.add_argument("--models", nargs="+", default=["ggx+diffuse", "beckmann+diffuse"])
    p.add_argument("--strata", type=int, default=12)
    p.add_argument("--json")
    a = p.parse_args()
    files = sorted(RGL.glob("*.bsdf"))
    if len(files) != 7:
        print(f"bench/distributed.py: expected the seven RGL materials in {RGL}, found {len(files)}", file=sys.stderr)
        return 2
    load = os.getloadavg()[0]
    # Ray's files in a folder of this run's own (nothing else on the machine finds this cluster).
    temp = tempfile.mkdtemp(prefix="gonio-ray-bench-")
    os.environ["RAY_TMPDIR"] = os.environ["TMPDIR"] = temp
    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 0, "object_store_memory": STORE, "include_dashboard": False,
                                                      "node_ip_address": "127.0.0.1"})
    c.add_node(num_cpus=1, object_store_memory=STORE, node_ip_address="127.0.0.1")
    c.wait_for_nodes()
    ray.init(address=c.address, log_to_driver=False)
    results = {}
    try:
        for nodes in (1, 2):
            if nodes == 2:
                c.add_node(num_cpus=1, object_store_memory=STORE, node_ip_address="127.0.0.1")
                c.wait_for_nodes()
                while ray.cluster_resources().get("CPU", 0) < 2:
                    time.sleep(0.1)
            results[nodes] = {
                "render": run_render(a.scene, a.spp, nodes),
                "fit": run_fit(files, a.models, a.strata, nodes),
                "tiny": run_tiny(nodes),
            }
            print(f"{nodes} node(s): {json.dumps(results[nodes])}", flush=True)
    finally:
        ray.shutdown()
        c.shutdown()
        shutil.rmtree(temp, ignore_errors=True)
    eff = {k: results[1][k]["wall"] / (2 * results[2][k]["wall"]) for k in ("render", "fit")}
    name = pathlib.Path(a.scene).name
    print(f"\nload average (1 min) before {load:.2f}, after {os.getloadavg()[0]:.2f}; {os.cpu_count()} CPUs")
    print(f"{'':<44} {'1 node':>9} {'2 nodes':>9} {'efficiency':>10} {'target':>7}")
    print(f"{f'render {name}, {a.spp} spp':<44} {results[1]['render']['wall']:>8.2f}s {results[2]['render']['wall']:>8.2f}s "
          f"{eff['render']:>10.3f} {'0.85':>7}")
    fit_name = f"fit 7 RGL × {'+'.join(a.models) if len(a.models) == 1 else f'{len(a.models)} models'}, strata {a.strata}"
    print(f"{fit_name:<44} {results[1]['fit']['wall']:>8.2f}s {results[2]['fit']['wall']:>8.2f}s {eff['fit']:>10.3f} {'0.8':>7}")
    for nodes in (1, 2):
        r = results[nodes]
        print(f"overhead per task, {nodes} node(s): render {1000 * r['render']['overhead']:.0f} ms ({r['render']['tasks']} tasks), "
              f"fit {1000 * r['fit']['overhead']:.0f} ms ({r['fit']['tasks']} tasks), tiny renders {1000 * r['tiny']['overhead']:.0f} ms "
              f"({r['tiny']['tasks']} tasks)")
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps({"results": results, "efficiency": eff}, indent=2))
    return 0 if eff["render"] >= 0.85 and eff["fit"] >= 0.8 else 1


if __name__ == "__main__":
    sys.exit(main())
