"""gonio.distributed — renders, fits and checks on a Ray cluster (docs/distributed.md).

- ``render(scene, spp=..., seed=...)``: the samples of every pixel split into ranges, one Ray task per
  range; the scene (an XML file with every file it reads, or a scene dictionary) is put in the object
  store once. The merged image is the single-machine image for the same seed and spp to the last bit of
  float32 (bit for bit when one task renders everything; see ``docs/distributed.md``).
- ``fit(files, models=[...])``: one task per measured file × model; a table, and the best fit of each file
  as a Mitsuba ``<bsdf>`` file.
- ``check(specs)`` / ``check_all()``: the verification harness of ``gonio check``, one task per model.
- ``preview(spec, grid={...})``: a parameter sweep of lit spheres, one task per grid point; the images
  equal ``gonio.preview``'s bit for bit.

``address`` chooses the cluster: ``None`` (the one this process is connected to, else ``ray.init()``'s
autodetection, else a new local instance), ``"auto"`` (an existing cluster, e.g. one ``ray start --head``
started), ``"local"`` (a new instance on this machine) or a cluster's address (``"10.0.0.1:6379"``,
``"ray://host:10001"``). Every node needs gonio installed; a task is retried by Ray when its worker dies,
and gives the same result (sample ranges and fits are deterministic).

Needs Ray: ``pip install "gonio[ray]"``.
"""

from __future__ import annotations

try:
    import ray
    import ray.exceptions
except ImportError as _e:  # pragma: no cover - exercised by a test in a subprocess
    raise ImportError(
        f"gonio.distributed runs on Ray, which could not be imported ({_e}); install it with "
        "`pip install \"gonio[ray]\"` (or `pip install ray`)"
    ) from _e

import atexit
import dataclasses
import json
import math
import os
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .. import _gonio, _progress, load_bsdf, load_dict, load_scene, write_image
from .._preview import Grid, PreviewResult, Settings, Sweep

__all__ = [
    "FitRow",
    "PreviewResult",
    "RenderResult",
    "TaskError",
    "check",
    "check_all",
    "connect",
    "fit",
    "fit_table",
    "preview",
    "render",
]

#: Object store of a local instance this module starts (bytes): results pass through it once each.
LOCAL_OBJECT_STORE = 200 * 1024 * 1024


class TaskError(RuntimeError):
    """A task failed: ``what`` names the scene and sample range, or the material and model."""

    def __init__(self, what: str, error: BaseException) -> None:
        super().__init__(f"{what}: {error}")
        self.what = what
        self.error = error


# ---------------------------------------------------------------------------------------------------------
# The cluster


def connect(address: Optional[str] = None) -> None:
    """Connect this process to Ray (see the module docs for ``address``); nothing when already connected."""
    if ray.is_initialized():
        return
    if address == "local" or address is None:
        if address is None:
            try:
                ray.init(address="auto", log_to_driver=False)
                return
            except ConnectionError:
                pass
        # On 127.0.0.1: a local instance serves this machine only.
        ray.init(
            address="local",
            object_store_memory=LOCAL_OBJECT_STORE,
            include_dashboard=False,
            log_to_driver=False,
            _node_ip_address="127.0.0.1",
        )
        return
    ray.init(address=address, log_to_driver=False)


def _cluster_cpus() -> int:
    return max(1, int(ray.cluster_resources().get("CPU", 1)))


def _threads() -> int:
    """Inside a task: the CPUs Ray gave it (its render threads)."""
    cpus = ray.get_runtime_context().get_assigned_resources().get("CPU", 1.0)
    return max(1, int(cpus))


def _as_completed(refs: Sequence[Any], poll: float = 0.1) -> Iterator[Optional[int]]:
    """Indices of `refs` as their tasks finish (``ray.wait``); ``None`` every `poll` seconds without one,
    for the caller's progress bar."""
    index = {ref: i for i, ref in enumerate(refs)}
    pending = list(refs)
    while pending:
        ready, pending = ray.wait(pending, num_returns=1, timeout=poll)
        if not ready:
            yield None
        for ref in ready:
            yield index[ref]


def _cause(e: BaseException) -> BaseException:
    """The exception a task raised, out of Ray's wrapper."""
    return getattr(e, "cause", None) or e


# ---------------------------------------------------------------------------------------------------------
# Worker side: files shipped through the object store, unpacked once per worker process

_UNPACKED: Dict[str, Path] = {}
_SCENES: Dict[str, Any] = {}


def _cleanup() -> None:
    for d in _UNPACKED.values():
        shutil.rmtree(d, ignore_errors=True)


atexit.register(_cleanup)


def _unpack(key: str, files: Callable[[], Mapping[str, bytes]]) -> Path:
    """Write `files()` (relative path → bytes) under a fresh folder, once per `key` in this process."""
    if key not in _UNPACKED:
        root = Path(tempfile.mkdtemp(prefix="gonio-ray-"))
        for rel, data in files().items():
            path = root / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        _UNPACKED[key] = root
    return _UNPACKED[key]


def _scene(boxed: List[Any]) -> Any:
    """The scene of a bundle (its object reference boxed in a list), loaded once per worker process."""
    ref = boxed[0]
    key = ref.hex()
    if key not in _SCENES:
        bundle = ray.get(ref)
        mode = bundle["mode"]
        if bundle["kind"] == "dict":
            _SCENES[key] = load_dict(bundle["scene"], mode=mode)
        else:
            root = _unpack(key, lambda: bundle["files"])
            _SCENES[key] = load_scene(str(root / bundle["scene"]), mode=mode, **bundle["defines"])
    return _SCENES[key]


@ray.remote(max_retries=3, retry_exceptions=False)
def _render_part(boxed: List[Any], first: int, count: int, seed: int) -> Dict[str, Any]:
    part = _scene(boxed).render_samples(first, count, seed=seed, threads=_threads(), progress=False)
    part["node"] = ray.get_runtime_context().get_node_id()
    return part


# ---------------------------------------------------------------------------------------------------------
# Render


@dataclasses.dataclass
class RenderResult:
    """What ``render`` produced: ``image`` (H, W, 3) float32 linear RGB holding ``spp`` samples per pixel
    (H, W, C with an ``aov`` integrator's further channels after the RGB, as ``Scene.render`` returns them)
    (fewer than ``spp_requested`` when ``cancelled``; ``None`` if nothing was merged), and per task
    (first sample, samples, seconds in the task, node id)."""

    image: Optional[np.ndarray]
    spp: int
    spp_requested: int
    seed: int
    cancelled: bool
    nonfinite: int
    seconds: float
    tasks: List[Tuple[int, int, float, str]]


def _bundle(scene: Any, defines: Mapping[str, Any]) -> Tuple[Dict[str, Any], str]:
    """The scene as it travels (a dict scene as it is; a file with every file it reads, relative to
    their common folder), and a name for messages."""
    if isinstance(scene, Mapping):
        return {"kind": "dict", "scene": dict(scene)}, "<dict>"
    if isinstance(scene, (str, os.PathLike)):
        path = Path(scene)
        # Absolute but not resolved: a worker finds each file at the path the scene's references spell
        # out from the scene's own folder, e.g. `../../../shared/data/x` through a symlinked `shared`
        # (`resolve()` would pack the link's target and the reference would miss it).
        files = [Path(os.path.abspath(f)) for f in _gonio.scene_files(str(path), **defines)]
        root = Path(os.path.commonpath([f.parent for f in files]))
        data = {str(f.relative_to(root)): f.read_bytes() for f in files}
        return {"kind": "file", "scene": str(files[0].relative_to(root)), "files": data, "defines": dict(defines)}, str(path)
    raise TypeError(
        f"render expects a scene file's path or a scene dictionary, got {type(scene).__name__} "
        "(a loaded gonio.Scene cannot be sent to other machines: pass what it was loaded from)"
    )


def _chunks(spp: int, chunk_spp: int) -> List[Tuple[int, int]]:
    return [(first, min(chunk_spp, spp - first)) for first in range(0, spp, chunk_spp)]


def render(
    scene: Union[str, os.PathLike, Mapping[str, Any]],
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    address: Optional[str] = None,
    chunk_spp: Optional[int] = None,
    num_cpus: int = 1,
    progress: bool = True,
    defines: Optional[Mapping[str, Any]] = None,
    mode: str = "rgb",
) -> RenderResult:
    """Render `scene` (a Mitsuba 3 XML file or a scene dictionary) on a Ray cluster.

    Each task renders ``chunk_spp`` consecutive sample indices of every pixel (default: about four
    tasks per CPU of the cluster) with ``num_cpus`` threads; parts are merged in sample order as they
    finish (``ray.wait``), so the image does not depend on which tasks finished first or were retried.
    ``spp`` and ``seed`` default to the scene's sampler; ``defines`` are the scene's ``<default>``
    overrides (as ``load_scene``'s keywords); ``mode`` is ``"rgb"`` or ``"spectral"`` (as ``load_scene``'s
    and ``gonio render --mode``: every task renders in it). Ctrl-C cancels the tasks still running and returns what was
    merged (``cancelled=True``). A task that fails raises ``TaskError`` naming the scene and its samples.
    """
    defines = dict(defines or {})
    # Loaded here too: errors show before anything is sent, and the defaults come from the scene.
    local = (
        load_dict(dict(scene), mode=mode)
        if isinstance(scene, Mapping)
        else load_scene(str(scene), mode=mode, **defines) if isinstance(scene, (str, os.PathLike)) else None
    )
    bundle, name = _bundle(scene, defines)
    bundle["mode"] = mode
    spp = local.spp if spp is None else int(spp)
    seed = local.seed if seed is None else int(seed)
    if spp < 1:
        raise ValueError(f"`spp` must be at least 1, got {spp}")
    if num_cpus < 1:
        raise ValueError(f"`num_cpus` must be at least 1, got {num_cpus}")
    connect(address)
    if chunk_spp is None:
        chunk_spp = max(1, math.ceil(spp / (4 * max(1, _cluster_cpus() // num_cpus))))
    if chunk_spp < 1:
        raise ValueError(f"`chunk_spp` must be at least 1, got {chunk_spp}")
    start = time.perf_counter()
    ref = ray.put(bundle)
    chunks = _chunks(spp, chunk_spp)
    refs = [_render_part.options(**_spread(num_cpus)).remote([ref], first, count, seed) for first, count in chunks]
    pixels = local.width * local.height
    bar = _progress.bar(spp * pixels, f"gonio render (Ray, {len(chunks)} tasks)") if progress else None

    total: Optional[Dict[str, Any]] = None
    done = [False] * len(refs)
    merged = 0  # chunks merged: always a prefix 0 .. merged − 1
    spp_done = nonfinite = 0
    tasks: List[Tuple[int, int, float, str]] = []

    def merge(i: int) -> None:
        nonlocal total, spp_done, nonfinite
        try:
            part = ray.get(refs[i])
        except ray.exceptions.RayError as e:
            first, count = chunks[i]
            raise TaskError(f"{name}: samples {first}..{first + count - 1}", _cause(e)) from None
        if total is None:
            total = {"sum": part["sum"].copy(), "weight": None if part["weight"] is None else part["weight"].copy()}
        else:
            # Float64 `+`, as the film adds tiles (gonio::film::Film::add_tile).
            total["sum"] += part["sum"]
            if total["weight"] is not None:
                total["weight"] += part["weight"]
        spp_done += part["spp"]
        nonfinite += part["nonfinite"]
        tasks.append((part["first"], part["spp"], part["seconds"], part["node"]))

    cancelled = False
    try:
        for i in _as_completed(refs):
            if i is not None:
                done[i] = True
                while merged < len(refs) and done[merged]:
                    merge(merged)
                    merged += 1
            if bar is not None:
                bar.update(sum(c for (_, c), d in zip(chunks, done) if d) * pixels)
    except KeyboardInterrupt:
        cancelled = True
        for i, r in enumerate(refs):
            if not done[i]:
                ray.cancel(r, force=True)
        # Keep every part that had finished, in sample order.
        for i in range(merged, len(refs)):
            if done[i]:
                merge(i)
    except BaseException:
        for i, r in enumerate(refs):
            if not done[i]:
                ray.cancel(r, force=True)
        raise
    finally:
        if bar is not None:
            bar.close(spp_done * pixels)
    image = None if total is None else _gonio.develop(total["sum"], total["weight"], spp_done)
    return RenderResult(image, spp_done, spp, seed, cancelled, nonfinite, time.perf_counter() - start, tasks)


# ---------------------------------------------------------------------------------------------------------
# Batches: fits and checks


def _run_batch(labels: Sequence[str], refs: Sequence[Any], desc: str, progress: bool) -> List[Any]:
    """Wait for every task (in completion order, with a progress bar); each result, or the ``TaskError``
    of a task that raised (the others still complete). Ctrl-C cancels the tasks still running."""
    out: List[Any] = [None] * len(refs)
    bar = _progress.bar(len(refs), desc) if progress else None
    finished = 0
    try:
        for i in _as_completed(refs):
            if i is None:
                continue
            try:
                out[i] = ray.get(refs[i])
            except ray.exceptions.RayError as e:
                out[i] = TaskError(labels[i], _cause(e))
            finished += 1
            if bar is not None:
                bar.update(finished)
    except BaseException:
        for i, r in enumerate(refs):
            if out[i] is None:
                ray.cancel(r, force=True)
        raise
    finally:
        if bar is not None:
            bar.close(finished)
    return out


def _spread(num_cpus: int) -> Dict[str, Any]:
    """Options of every task here: its CPUs, and Ray's SPREAD placement. The tasks are independent and
    CPU-bound; under the default (hybrid) placement a node's next task often waited ~0.1 s for a new
    worker lease after its last one ended, where spread tasks follow each other within a few ms
    (bench/distributed.py, 2 one-CPU nodes, 0.7 s tasks: scaling 0.78 → 0.87)."""
    return {"num_cpus": num_cpus, "scheduling_strategy": "SPREAD"}


def _rayon(num_cpus: int) -> Dict[str, Any]:
    """Task options that also cap gonio's thread pool to the task's CPUs."""
    return {**_spread(num_cpus), "runtime_env": {"env_vars": {"RAYON_NUM_THREADS": str(num_cpus)}}}


@ray.remote(max_retries=3, retry_exceptions=False)
def _fit_task(boxed: List[Any], name: str, model: str, strata: int) -> Dict[str, Any]:
    ref = boxed[0]
    base = Path(name).name
    path = _unpack(ref.hex(), lambda: {base: ray.get(ref)}) / base
    plugin = _gonio.measured_plugin(str(path))
    spec = {"type": plugin, "filename": str(path)} if plugin else path.read_text()
    bsdf = load_bsdf(spec, source=name)
    (row,) = _gonio.fit(bsdf, [model], strata=strata, source=name)
    return row


@dataclasses.dataclass
class FitRow:
    """One fit: the ``file`` and ``model``, and either the fit (``relative_error``, ``error``, ``values``,
    ``spec`` as JSON text, ``xml``, ``seconds`` in the task) or ``failure``, what went wrong."""

    file: str
    model: str
    relative_error: float = math.nan
    error: float = math.nan
    values: Dict[str, float] = dataclasses.field(default_factory=dict)
    spec: str = ""
    xml: str = ""
    seconds: float = 0.0
    failure: Optional[str] = None


def fit(
    files: Sequence[Union[str, os.PathLike]],
    models: Sequence[str],
    strata: int = 12,
    address: Optional[str] = None,
    output_dir: Optional[Union[str, os.PathLike]] = None,
    progress: bool = True,
) -> List[FitRow]:
    """Fit every model of `models` (``gonio fit --list``) to every measured file (MERL ``.binary``, RGL
    ``.bsdf``, or a JSON/XML model file): one Ray task per file × model, each file sent once. Returns a
    row per file × model, in that order; a fit that failed has ``failure`` set (naming the file, model and
    error) and the others complete. With ``output_dir`` the best fit of each file is written there as
    ``<file stem>.xml`` (atomically), the file ``gonio fit -o`` writes."""
    names = [str(f) for f in files]
    known = {m for m, _ in _gonio.fit_models()}
    for m in models:
        if m not in known:
            raise ValueError(f"unknown model `{m}`; expected one of: {', '.join(sorted(known))}")
    data = []
    for n in names:
        try:
            data.append(Path(n).read_bytes())
        except OSError as e:
            raise type(e)(e.errno, f"cannot read the measured file: {e.strerror}", n) from None
    connect(address)
    file_refs = [ray.put(d) for d in data]
    jobs = [(n, r, m) for n, r in zip(names, file_refs) for m in models]
    refs = [_fit_task.options(**_rayon(1)).remote([r], n, m, strata) for n, r, m in jobs]
    results = _run_batch([f"{n}, model {m}" for n, _, m in jobs], refs, f"gonio fit (Ray, {len(refs)} tasks)", progress)
    rows = []
    for (n, _, m), res in zip(jobs, results):
        if isinstance(res, TaskError):
            rows.append(FitRow(n, m, failure=str(res)))
        else:
            rows.append(
                FitRow(n, m, res["relative_error"], res["error"], dict(res["values"]), res["spec"], res["xml"], res["seconds"])
            )
    if output_dir is not None:
        out = Path(output_dir)
        out.mkdir(parents=True, exist_ok=True)
        for n in names:
            good = [r for r in rows if r.file == n and r.failure is None]
            if good:
                best = min(good, key=lambda r: r.error)
                _write_text(out / (Path(n).stem + ".xml"), best.xml)
    return rows


def _write_text(path: Path, text: str) -> None:
    """Write atomically: a temporary file in the same folder, renamed over `path`."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def fit_table(rows: Sequence[FitRow]) -> str:
    """The rows as a text table: file, model, relative error, seconds, parameters (or the failure)."""
    lines = [f"{'file':<36} {'model':<22} {'rel. error':>10} {'s':>6}  parameters"]
    for r in rows:
        if r.failure is not None:
            lines.append(f"{Path(r.file).name:<36} {r.model:<22} {'FAILED':>10} {'':>6}  {r.failure}")
        else:
            params = ", ".join(f"{k} {v:.4g}" for k, v in r.values.items())
            lines.append(f"{Path(r.file).name:<36} {r.model:<22} {r.relative_error:>10.4f} {r.seconds:>6.1f}  {params}")
    return "\n".join(lines)


@ray.remote(max_retries=3, retry_exceptions=False)
def _check_task(spec: str, samples: int, sweep: int, seed: int, family: Optional[int], violation: Optional[str]) -> Dict[str, Any]:
    from .. import verify

    report = verify.check(load_bsdf(spec), samples=samples, sweep=sweep, seed=seed, family=family)
    out = {"name": report.name, "passed": report.passed, "table": str(report), "report": report.to_dict()}
    if violation is not None:
        out["violation"] = violation
        out["missed"] = verify.expect_violation(report, violation)
    return out


def check(
    specs: Sequence[Union[str, Mapping[str, Any]]],
    samples: int = 1_000_000,
    sweep: int = 1_000_000,
    seed: int = 0,
    family: Optional[int] = None,
    violations: Optional[Sequence[Optional[str]]] = None,
    address: Optional[str] = None,
    num_cpus: int = 1,
    progress: bool = True,
) -> List[Dict[str, Any]]:
    """Run ``gonio.verify.check`` on every spec (anything ``load_bsdf`` takes), one Ray task each, with
    ``num_cpus`` threads. Returns per spec ``{"name", "passed", "table", "report"}`` (``table``: what
    ``gonio check`` prints; ``report``: its ``--json`` object), or ``{"spec", "error"}`` for a spec whose
    task failed (the others complete). ``violations[i]``, when given, is the check row spec i must fail
    (a non-physical model kept for teaching): then ``"missed"`` is ``None`` when it does, else why not.
    ``family`` as for ``gonio.verify.check``."""
    texts = [s if isinstance(s, str) else json.dumps(s) for s in specs]
    for t in texts:
        load_bsdf(t)  # every spec parses before anything is sent
    kinds = list(violations) if violations is not None else [None] * len(texts)
    connect(address)
    refs = [_check_task.options(**_rayon(num_cpus)).remote(t, samples, sweep, seed, family, k) for t, k in zip(texts, kinds)]
    results = _run_batch(texts, refs, f"gonio check (Ray, {len(refs)} tasks)", progress)
    return [{"spec": t, "error": str(r)} if isinstance(r, TaskError) else r for t, r in zip(texts, results)]


def check_all(samples: int = 1_000_000, sweep: int = 1_000_000, seed: int = 0, address: Optional[str] = None,
              num_cpus: int = 1, progress: bool = True) -> Tuple[List[Dict[str, Any]], List[Dict[str, Any]]]:
    """``gonio check --all`` on the cluster: every example model (``gonio.examples()``), then the
    non-physical ones with the violation each must show; one Šidák family over all, as the CLI.
    Returns (examples, violations)."""
    from .. import examples, verify

    specs = list(examples())
    bad = list(verify.violations())
    family = sum(verify.chi2_tests(load_bsdf(s)) for s in specs + [s for s, _ in bad])
    rows = check(specs + [s for s, _ in bad], samples, sweep, seed, family, [None] * len(specs) + [k for _, k in bad],
                 address, num_cpus, progress)
    return rows[: len(specs)], rows[len(specs):]


# ---------------------------------------------------------------------------------------------------------
# Previews: a parameter sweep of lit spheres


@ray.remote(max_retries=3, retry_exceptions=False)
def _preview_task(boxed: List[Any], point: int) -> Dict[str, Any]:
    sweep, lighting, settings, mode = ray.get(boxed[0])
    start = time.perf_counter()
    image, nonfinite = sweep.render(point, lighting, settings, threads=_threads(), mode=mode)
    return {"image": image, "nonfinite": nonfinite, "seconds": time.perf_counter() - start,
            "node": ray.get_runtime_context().get_node_id()}


def preview(
    spec: Any,
    grid: Grid = None,
    *,
    env: Any = None,
    light: Optional[Sequence[float]] = None,
    size: int = 128,
    spp: int = 64,
    seed: int = 0,
    output: Optional[Union[str, os.PathLike]] = None,
    output_dir: Optional[Union[str, os.PathLike]] = None,
    exposure: float = 0.0,
    source: str = "<string>",
    address: Optional[str] = None,
    num_cpus: int = 1,
    progress: bool = True,
    mode: str = "rgb",
) -> PreviewResult:
    """``gonio.preview`` on a Ray cluster: one task per grid point (sphere), with ``num_cpus`` threads
    each; the arguments (``mode`` too) and the result are ``gonio.preview``'s, and so are the images, bit
    for bit.

    The spec, grid and lighting are checked here (every point's material is built: a bad grid raises
    ``SpecError`` or ``TypeError`` naming the parameter before anything is sent) and put in the object
    store once; an environment file is read here and sent as its image. A task that fails raises
    ``TaskError`` naming its grid point; Ctrl-C cancels the tasks still running.
    """
    start = time.perf_counter()
    settings = Settings(size, spp, seed, exposure)
    sweep = Sweep.of(spec, grid, source)
    lighting = _gonio.PreviewLighting(env, None if light is None else tuple(light))
    if num_cpus < 1:
        raise ValueError(f"`num_cpus` must be at least 1, got {num_cpus}")
    if mode not in ("rgb", "spectral"):
        raise ValueError(f"`mode` must be \"rgb\" or \"spectral\", got {mode!r}")
    connect(address)
    ref = ray.put((sweep, lighting, settings, mode))
    refs = [_preview_task.options(**_spread(num_cpus)).remote([ref], i) for i in range(len(sweep.labels))]
    labels = [f"{source}, grid point {label}" if label else source for label in sweep.labels]
    results = _run_batch(labels, refs, f"gonio preview (Ray, {len(refs)} tasks)", progress)
    for r in results:
        if isinstance(r, TaskError):
            raise r
    result = PreviewResult([r["image"] for r in results], sweep.points, sweep.labels, sweep.columns,
                           sum(r["nonfinite"] for r in results), time.perf_counter() - start)
    result.write(output, output_dir, exposure)
    return result
