"""Concurrent calls from Python threads give the results of sequential calls; the batched loops
release the GIL; `import gonio` is quick."""

import subprocess
import sys
import threading
import time

import numpy as np

import gonio

RNG = np.random.default_rng(11)


def unit(n):
    w = RNG.normal(size=(n, 3))
    w[:, 2] = np.abs(w[:, 2])
    return w / np.linalg.norm(w, axis=1, keepdims=True)


SCENE = {
    "type": "scene",
    "sensor": {
        "type": "perspective",
        "to_world": gonio.look_at([0, 0, 4], [0, 0, 0]),
        "film": {"type": "hdrfilm", "width": 24, "height": 16},
        "sampler": {"type": "independent", "sample_count": 2},
    },
    "ball": {"type": "sphere", "bsdf": {"type": "roughconductor", "material": "Cu", "alpha": 0.3}},
    "sky": {"type": "constant"},
}


def run_concurrently(jobs):
    """Run every job on its own thread, all released at once; return their results in order."""
    results = [None] * len(jobs)
    errors = []
    barrier = threading.Barrier(len(jobs))

    def worker(i, job):
        try:
            barrier.wait()
            results[i] = job()
        except BaseException as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=worker, args=(i, job)) for i, job in enumerate(jobs)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    return results


def test_concurrent_calls_equal_sequential_calls():
    n = 50_000  # several parallel chunks per call
    wo, wi = unit(n), unit(n)
    uc, u = RNG.random(n), RNG.random((n, 2))
    bsdfs = [gonio.load_bsdf(s) for s in ({"type": "diffuse"}, {"type": "roughconductor", "alpha": 0.3}, {"type": "dielectric"})]
    scene = gonio.load_dict(SCENE)

    def jobs():
        out = []
        for b in bsdfs:
            out.append(lambda b=b: ("f", b.f(wo, wi)))
            out.append(lambda b=b: ("pdf", b.pdf(wo, wi)))
            out.append(lambda b=b: ("sample", b.sample(wo, uc, u)))
        out.append(lambda: ("render", scene.render(seed=5, threads=2, progress=False)))
        return out

    sequential = [job() for job in jobs()]
    # Four threads each running every job, twice over, all at once.
    concurrent = run_concurrently([lambda: [job() for job in jobs()] for _ in range(4)])
    for results in concurrent:
        for (kind, got), (_, want) in zip(results, sequential):
            if kind == "sample":
                for field in ("wi", "f", "pdf", "weight", "flags", "eta", "valid"):
                    assert np.array_equal(getattr(got, field), getattr(want, field)), field
            else:
                assert np.array_equal(got, want), kind


def test_batched_calls_release_the_gil():
    # While long f() calls run on this thread, another thread keeps running Python code. With the GIL held
    # for each whole call the spinner could tick at most about once per call (between calls), so it must
    # tick several times per call. Calls repeat for half a second, whatever the speed of one call.
    b = gonio.load_bsdf({"type": "roughconductor", "alpha": 0.3})
    wo, wi = unit(2_000_000), unit(2_000_000)
    ticks = []
    done = threading.Event()

    def spin():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=spin)
    t.start()
    start = time.perf_counter()
    calls = 0
    while time.perf_counter() - start < 0.5:
        b.f(wo, wi)
        calls += 1
    elapsed = time.perf_counter() - start
    done.set()
    t.join()
    during = [x for x in ticks if start <= x <= start + elapsed]
    assert len(during) > max(10, 3 * calls), (len(during), calls, elapsed)


def test_import_brings_in_no_notebook_or_plotting_stack():
    # ``import gonio`` loads the extension and gonio's own modules; the explorer's anywidget (with ipywidgets
    # and IPython: 0.15 s) and matplotlib are imported when they are first used, not before. (How long the
    # import takes is a benchmark's business, not a test's.)
    code = "import sys, gonio; print(' '.join(sorted(m for m in ('anywidget', 'ipywidgets', 'IPython', 'traitlets', 'matplotlib') if m in sys.modules)))"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert loaded == [], loaded
    code = "import sys, gonio; gonio.explore; print('anywidget' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip() == "False"
