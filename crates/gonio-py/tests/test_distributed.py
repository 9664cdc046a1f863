"""gonio.distributed on a local Ray cluster (127.0.0.1 only): a head without CPUs and two worker nodes of
one CPU each, started once for the module (start-up takes seconds). Renders split over the workers equal
the single-machine render to the last bit of float32 (bit for bit when one task renders everything); a
worker killed mid-task loses nothing; fits and checks equal their local runs; a failing task is reported
with its material while the others complete."""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np
import pytest

# Ray on this machine only: every node and the driver use 127.0.0.1 (Ray's switch for single-machine
# clusters; read when Ray is imported, and inherited by the processes the test cluster starts).
os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
import ray  # noqa: E402
from ray.cluster_utils import Cluster  # noqa: E402

import gonio  # noqa: E402
from gonio import distributed  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[3]
CLI = ROOT / "target" / "release" / "gonio"
SCENE = ROOT / "bench" / "scenes" / "mask-measured-rectlight.xml"  # measured files and a PNG: assets to ship
RGL = pathlib.Path("/work/shared/data/rgl") if pathlib.Path("/work/shared/data/rgl").is_dir() else ROOT.parent / "shared" / "data" / "rgl"
SMALL = {"width": 48, "height": 36}
STORE = 80 * 1024 * 1024  # per node


@pytest.fixture(scope="module")
def cluster():
    # Ray's files (sessions, logs, sockets, the address file `ray.init()` looks for) in a folder of this
    # test's own, short enough for Unix socket paths, so nothing else on the machine finds this cluster.
    # The workers' temporary files (the scenes they unpack) go there too (TMPDIR): a worker Ray stops
    # with a signal does not remove its own.
    temp = tempfile.mkdtemp(prefix="gonio-ray-test-")
    saved = {k: os.environ.get(k) for k in ("RAY_TMPDIR", "TMPDIR")}
    os.environ["RAY_TMPDIR"] = os.environ["TMPDIR"] = temp
    c = Cluster(
        initialize_head=True,
        head_node_args={"num_cpus": 0, "object_store_memory": STORE, "include_dashboard": False, "node_ip_address": "127.0.0.1"},
    )
    for _ in range(2):
        c.add_node(num_cpus=1, object_store_memory=STORE, node_ip_address="127.0.0.1")
    c.wait_for_nodes()
    ray.init(address=c.address, log_to_driver=False)
    yield c
    ray.shutdown()
    c.shutdown()
    for k, v in saved.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v
    shutil.rmtree(temp, ignore_errors=True)


def ulps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    assert (a >= 0).all() and (b >= 0).all()
    return np.abs(a.view(np.int32).astype(np.int64) - b.view(np.int32).astype(np.int64))


def gaussian_dict() -> dict:
    """A scene dictionary with Mitsuba's default (Gaussian) filter: parts carry summed weights."""
    return {
        "type": "scene",
        "sensor": {"type": "perspective", "fov": 40, "to_world": gonio.look_at([0, 1, 4], [0, 0, 0]),
                   "film": {"type": "hdrfilm", "width": 40, "height": 30}},
        "ball": {"type": "sphere", "bsdf": {"type": "roughconductor", "material": "Au", "alpha": 0.2}},
        "floor": {"type": "rectangle", "to_world": [[3, 0, 0, 0], [0, 0, 3, -1], [0, -3, 0, 0], [0, 0, 0, 1]],
                  "bsdf": {"type": "diffuse"}},
        "sky": {"type": "constant"},
        "sun": {"type": "directional", "direction": [-1, -1, -0.5], "irradiance": 3},
    }


def test_render_matches_the_single_machine(cluster):
    single = gonio.load_scene(str(SCENE), **SMALL).render(spp=24, seed=5, progress=False)
    r = distributed.render(SCENE, spp=24, seed=5, chunk_spp=5, progress=False, defines=SMALL)
    assert (r.spp, r.spp_requested, r.cancelled, len(r.tasks)) == (24, 24, False, 5)
    assert sorted((t[0], t[1]) for t in r.tasks) == [(0, 5), (5, 5), (10, 5), (15, 5), (20, 4)]
    assert (single > 0).mean() > 0.5  # not a black image
    d = ulps(r.image, single)
    assert d.max() <= 1, f"{d.max()} ulps"
    assert (d > 0).mean() < 0.01
    # One task: the single machine's very sums, bit for bit.
    whole = distributed.render(SCENE, spp=24, seed=5, chunk_spp=24, progress=False, defines=SMALL)
    assert np.array_equal(whole.image, single)


def test_render_of_a_dict_with_a_gaussian_filter(cluster):
    scene = gaussian_dict()
    single = gonio.load_dict(scene).render(spp=16, seed=2, progress=False)
    r = distributed.render(scene, spp=16, seed=2, chunk_spp=3, progress=False)
    assert r.spp == 16 and len(r.tasks) == 6
    assert ulps(r.image, single).max() <= 1
    # The same split merged twice: the same image bit for bit (parts are merged in sample order).
    again = distributed.render(scene, spp=16, seed=2, chunk_spp=3, progress=False)
    assert np.array_equal(again.image, r.image)


def test_spectral_render_equals_the_single_machine(cluster, tmp_path):
    # Every task renders in the mode asked for (issue 30): a spectral dict render and a spectral file
    # render (with `<spectrum>` tables, which must reach the workers) equal the local spectral renders as
    # RGB renders equal theirs, and differ from RGB mode.
    scene = gaussian_dict()
    single = gonio.load_dict(scene, mode="spectral").render(spp=8, seed=2, progress=False)
    r = distributed.render(scene, spp=8, seed=2, chunk_spp=3, progress=False, mode="spectral")
    assert ulps(r.image, single).max() <= 1
    rgb = gonio.load_dict(scene).render(spp=8, seed=2, progress=False)
    assert not np.allclose(rgb, single, rtol=1e-3)
    xml = tmp_path / "lines.xml"
    xml.write_text("""<scene version="3.0.0"><sensor type="perspective"><float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/></film></sensor>
        <emitter type="constant"><spectrum name="radiance" value="400:0, 450:3, 500:0, 600:0, 650:3, 700:0"/></emitter>
        <shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" value="400:0.9, 550:0.1, 700:0.9"/></bsdf></shape>
        </scene>""")
    single = gonio.load_scene(str(xml), mode="spectral").render(spp=6, seed=1, progress=False)
    whole = distributed.render(xml, spp=6, seed=1, chunk_spp=6, progress=False, mode="spectral")
    assert np.array_equal(whole.image, single)
    with pytest.raises(Exception, match="spectral"):
        distributed.render(scene, spp=1, progress=False, mode="spectrum")


def _render_workers() -> list:
    """Worker processes running a render task (Ray titles a worker `ray::<task>` while it runs one)."""
    pids = []
    for p in pathlib.Path("/proc").iterdir():
        if p.name.isdigit():
            try:
                if (p / "cmdline").read_bytes().startswith(b"ray::_render_part"):
                    pids.append(int(p.name))
            except OSError:
                pass
    return pids


def test_a_killed_worker_loses_nothing(cluster):
    defines = {"width": 96, "height": 72}
    reference = distributed.render(SCENE, spp=32, seed=9, chunk_spp=8, progress=False, defines=defines)
    killed = []

    def kill_one():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not killed:
            pids = _render_workers()
            if pids:
                time.sleep(0.05)  # let it get into its render
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])
            time.sleep(0.01)

    t = threading.Thread(target=kill_one)
    t.start()
    r = distributed.render(SCENE, spp=32, seed=9, chunk_spp=8, progress=False, defines=defines)
    t.join()
    assert killed, "no render task was seen running"
    assert (r.spp, r.cancelled) == (32, False)
    assert np.array_equal(r.image, reference.image)


def test_fit_equals_local_fits_and_reports_a_bad_file(cluster, tmp_path):
    files = [RGL / "paper_white_rgb.bsdf", RGL / "cc_ibiza_sunset_rgb.bsdf"]
    bad = tmp_path / "broken_rgb.bsdf"
    bad.write_bytes(b"not a tensor file")
    out = tmp_path / "fits"
    rows = distributed.fit(files + [bad], ["ggx+diffuse"], strata=3, output_dir=out, progress=False)
    assert [(pathlib.Path(r.file).name, r.model) for r in rows] == [
        ("paper_white_rgb.bsdf", "ggx+diffuse"), ("cc_ibiza_sunset_rgb.bsdf", "ggx+diffuse"), ("broken_rgb.bsdf", "ggx+diffuse")]
    for f, row in zip(files, rows):
        (local,) = gonio._gonio.fit(gonio.load_bsdf({"type": "measured", "filename": str(f)}), ["ggx+diffuse"], strata=3, source=str(f))
        assert row.failure is None
        assert (row.relative_error, row.values, row.xml) == (local["relative_error"], local["values"], local["xml"])
        text = (out / (f.stem + ".xml")).read_text()
        assert text == local["xml"]
        gonio.load_bsdf(text.split("\n", 1)[1])  # the written <bsdf> loads
    assert rows[2].failure is not None and "broken_rgb.bsdf" in rows[2].failure and "ggx+diffuse" in rows[2].failure
    assert not (out / "broken_rgb.xml").exists()
    assert "FAILED" in distributed.fit_table(rows)


def test_check_equals_local_checks(cluster):
    specs = [{"type": "diffuse"}, {"type": "roughconductor", "alpha": 0.3}]
    rows = distributed.check(specs, samples=100_000, sweep=10_000, seed=3, progress=False)
    for spec, row in zip(specs, rows):
        local = gonio.verify.check(gonio.load_bsdf(spec), samples=100_000, sweep=10_000, seed=3)
        assert row["report"] == local.to_dict()
        assert row["table"] == str(local) and row["passed"]
    spec, kind = gonio.verify.violations()[0]
    (row,) = distributed.check([spec], samples=100_000, sweep=10_000, violations=[kind], progress=False)
    assert row["missed"] is None, row["missed"]


def test_without_ray_it_says_how_to_install():
    code = "import sys; sys.modules['ray'] = None; import gonio.distributed"
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode != 0
    assert 'pip install "gonio[ray]"' in p.stderr, p.stderr


@pytest.mark.skipif(not CLI.exists(), reason="target/release/gonio not built (make build builds it)")
def test_cli_render_on_ray(cluster, tmp_path):
    out = tmp_path / "r.exr"
    env = {**os.environ, "GONIO_PYTHON": sys.executable}
    p = subprocess.run([str(CLI), "render", str(SCENE), "--ray", cluster.address, "-o", str(out), "--spp", "8", "--seed", "4",
                        "-D", "width=48", "-D", "height=36", "--chunk-spp", "3", "-q"], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    single = gonio.load_scene(str(SCENE), **SMALL).render(spp=8, seed=4, progress=False)
    assert ulps(gonio.read_image(str(out)), single).max() <= 1
    # --mode spectral reaches the tasks (a scene spectral mode takes: no measured RGB data).
    scene = ROOT / "bench" / "scenes" / "plastics-point-spot.xml"
    p = subprocess.run([str(CLI), "render", str(scene), "--ray", cluster.address, "-o", str(out), "--spp", "4", "--seed", "4",
                        "-D", "width=40", "-D", "height=30", "--chunk-spp", "4", "--mode", "spectral", "-q"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    single = gonio.load_scene(str(scene), mode="spectral", width=40, height=30).render(spp=4, seed=4, progress=False)
    assert np.array_equal(gonio.read_image(str(out)), single)
    # Without a Python that has gonio and Ray: one clear error, exit code 2.
    bad = {**os.environ, "GONIO_PYTHON": str(tmp_path / "no-python")}
    p = subprocess.run([str(CLI), "render", str(SCENE), "--ray", "auto"], capture_output=True, text=True, env=bad)
    assert p.returncode == 2 and "GONIO_PYTHON" in p.stderr and "cannot be started" in p.stderr, p.stderr


# Previews: one task per grid point; the images are gonio.preview's, bit for bit.
CONDUCTOR = {"type": "roughconductor", "alpha": 0.2}
GRID = {"alpha": [0.05, 0.3], "material": ["Au", "Cu"]}
SPHERE = {"size": 24, "spp": 4, "seed": 3}


def test_preview_sweep_equals_the_local_preview(cluster, tmp_path):
    local = gonio.preview(CONDUCTOR, GRID, light=(1, 1, 1), **SPHERE)
    r = distributed.preview(CONDUCTOR, GRID, light=(1, 1, 1), **SPHERE, output=tmp_path / "sheet.exr",
                            output_dir=tmp_path / "spheres", progress=False)
    assert r.labels == local.labels == ["alpha=0.05, material=Au", "alpha=0.05, material=Cu",
                                        "alpha=0.3, material=Au", "alpha=0.3, material=Cu"]
    assert r.points == local.points and r.points[1] == {"alpha": 0.05, "material": "Cu"}
    assert r.columns == local.columns == 2
    for a, b in zip(r.images, local.images):
        assert a.shape == (24, 24, 3) and np.array_equal(a, b)
    # The grid reaches the model: no two spheres are alike, and each is the sphere of its own spec.
    assert all(not np.array_equal(r.images[i], r.images[j]) for i in range(4) for j in range(i))
    alone = gonio.preview({"type": "roughconductor", "alpha": 0.3, "material": "Cu"}, light=(1, 1, 1), **SPHERE)
    assert alone.labels == [""] and np.array_equal(alone.images[0], r.images[3])
    # The contact sheet: 2 × 2 spheres with a one-pixel gap; one file per sphere.
    sheet = gonio.read_image(str(tmp_path / "sheet.exr"))
    assert sheet.shape == (49, 49, 3) and np.array_equal(sheet, local.sheet())
    assert np.array_equal(sheet[25:, 25:], r.images[3]) and np.array_equal(sheet[:24, 25:], r.images[1])
    files = sorted(p.name for p in (tmp_path / "spheres").iterdir())
    assert files == ["000_alpha=0.05_material=Au.exr", "001_alpha=0.05_material=Cu.exr",
                     "002_alpha=0.3_material=Au.exr", "003_alpha=0.3_material=Cu.exr"]
    assert np.array_equal(gonio.read_image(str(tmp_path / "spheres" / files[2])), r.images[2])


def test_spectral_preview_equals_the_local_preview(cluster):
    local = gonio.preview(CONDUCTOR, {"material": ["Au", "Cu"]}, light=(1, 1, 1), mode="spectral", **SPHERE)
    r = distributed.preview(CONDUCTOR, {"material": ["Au", "Cu"]}, light=(1, 1, 1), mode="spectral", **SPHERE, progress=False)
    assert all(np.array_equal(a, b) for a, b in zip(r.images, local.images))
    rgb = gonio.preview(CONDUCTOR, {"material": ["Au"]}, light=(1, 1, 1), **SPHERE)
    assert not np.array_equal(rgb.images[0], r.images[0])
    with pytest.raises(ValueError, match="`mode` must be"):
        distributed.preview(CONDUCTOR, mode="spectrum", progress=False)


def test_preview_with_an_environment_file(cluster, tmp_path):
    # The file is read on the driver and sent as its image; locally it is read from the file.
    sky = np.random.default_rng(1).uniform(0, 2, (16, 32, 3)).astype(np.float32)
    gonio.write_image(str(tmp_path / "sky.exr"), sky)
    xml = '<bsdf type="roughplastic"><float name="alpha" value="0.1"/></bsdf>'
    local = gonio.preview(xml, {"alpha": [0.1, 0.4]}, env=tmp_path / "sky.exr", size=16, spp=2)
    r = distributed.preview(xml, {"alpha": [0.1, 0.4]}, env=str(tmp_path / "sky.exr"), size=16, spp=2, progress=False)
    assert all(np.array_equal(a, b) for a, b in zip(r.images, local.images))
    assert np.array_equal(gonio.preview(xml, {"alpha": [0.4]}, env=sky, size=16, spp=2).images[0], r.images[1])


def test_preview_bad_grid_names_the_parameter(cluster):
    def error(grid, kind=gonio.SpecError, spec=CONDUCTOR):
        with pytest.raises(kind) as e:
            distributed.preview(spec, grid, size=8, spp=1, progress=False)
        return str(e.value)

    assert "parameter `alpha`: expected a list of values (one sphere each), got a number 0.1" in error({"alpha": 0.1})
    assert "parameter `material`: expected a list of values" in error({"material": "Au"})
    assert "parameter `alpha`: expected at least one value" in error({"alpha": []})
    e = error({"alpha": [0.1, -1]})
    assert e.startswith("grid alpha=-1: ") and "alpha" in e, e
    e = error({"alhpa": [0.1]})
    assert "grid alhpa=0.1: unknown parameter `alhpa` for `roughconductor`" in e and "alpha" in e, e
    e = error({"material": ["Au", "Xx"]})
    assert e.startswith("grid point material=Xx: ") and "unknown conductor material `Xx`" in e, e
    assert "`type` is not a parameter a grid can vary" in error({"type": ["diffuse"]})
    assert "dict of parameter name" in error([("alpha", [0.1])], TypeError)
    with pytest.raises(ValueError, match=r"`size` must be an integer in \[1, 4096\], got 0"):
        distributed.preview(CONDUCTOR, GRID, size=0, progress=False)


@pytest.mark.skipif(not CLI.exists(), reason="target/release/gonio not built (make build builds it)")
def test_cli_preview_on_ray(cluster, tmp_path):
    env = {**os.environ, "GONIO_PYTHON": sys.executable}
    args = [str(CLI), "preview", json.dumps(CONDUCTOR), "--grid", "alpha=0.05,0.3", "--grid", "material=Au,Cu", "--light", "1,1,1",
            "--size", "24", "--spp", "4", "--seed", "3", "--exposure", "-1", "-q"]
    p = subprocess.run(args + ["-o", str(tmp_path / "here.exr")], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    p = subprocess.run(args + ["-o", str(tmp_path / "ray.exr"), "--ray", cluster.address], capture_output=True, text=True, env=env,
                       timeout=120)
    assert p.returncode == 0, p.stderr
    here, there = gonio.read_image(str(tmp_path / "here.exr")), gonio.read_image(str(tmp_path / "ray.exr"))
    assert np.array_equal(here, there)
    assert np.array_equal(here, gonio.preview(CONDUCTOR, GRID, light=(1, 1, 1), **SPHERE).sheet(exposure=-1))
    p = subprocess.run(args[:3] + ["--grid", "alpha=0.1,-1", "-o", str(tmp_path / "bad.exr"), "--ray", cluster.address],
                       capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 2 and "grid alpha=-1" in p.stderr, p.stderr
