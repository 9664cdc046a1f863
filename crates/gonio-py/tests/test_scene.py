"""Scenes from Python: load_scene, load_dict, Scene.render (against the CLI bit for bit), progress,
Ctrl-C and errors."""

import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import gonio
from gonio import _progress

ROOT = pathlib.Path(__file__).resolve().parents[3]
CLI = ROOT / "target" / "release" / "gonio"

# A small scene touching every part of the loader: defaults, lookat, a referenced BSDF, a plastic
# sphere, an area light on a rectangle, an environment, the path integrator.
SCENE_XML = """<scene version="3.0.0">
    <default name="spp" value="4"/>
    <default name="width" value="32"/>
    <default name="height" value="24"/>
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 1, 4" target="0, 0.3, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="$width"/><integer name="height" value="$height"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>
    <bsdf type="roughconductor" id="gold"><string name="material" value="Au"/><float name="alpha" value="0.25"/></bsdf>
    <shape type="sphere"><point name="center" x="-0.6" y="0.5" z="0"/><float name="radius" value="0.5"/><ref id="gold"/></shape>
    <shape type="sphere">
        <point name="center" x="0.6" y="0.5" z="0"/><float name="radius" value="0.5"/>
        <bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2, 0.4, 0.7"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.5, 0.5"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.5"/></transform>
        <emitter type="area"><rgb name="radiance" value="8, 8, 8"/></emitter>
    </shape>
    <emitter type="constant"><rgb name="radiance" value="0.2, 0.25, 0.3"/></emitter>
</scene>
"""


def rotate_x(degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def translate_y(y):
    m = np.eye(4)
    m[1, 3] = y
    return m


def scene_dict(width=32, height=24, spp=4):
    """The dictionary form of SCENE_XML."""
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 4},
        "sensor": {
            "type": "perspective",
            "fov": 45,
            "to_world": gonio.look_at([0, 1, 4], [0, 0.3, 0], [0, 1, 0]),
            "film": {"type": "hdrfilm", "width": width, "height": height},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "gold": {"type": "roughconductor", "material": "Au", "alpha": 0.25},
        "left": {"type": "sphere", "center": [-0.6, 0.5, 0], "radius": 0.5, "bsdf": {"type": "ref", "id": "gold"}},
        "right": {
            "type": "sphere",
            "center": np.array([0.6, 0.5, 0.0]),
            "radius": 0.5,
            "bsdf": {"type": "plastic", "diffuse_reflectance": {"type": "rgb", "value": [0.2, 0.4, 0.7]}},
        },
        # <scale value="3"/><rotate x="1" angle="-90"/>: the rotation applies after the scale.
        "floor": {
            "type": "rectangle",
            "to_world": rotate_x(-90) @ np.diag([3, 3, 3, 1.0]),
            "bsdf": {"type": "diffuse", "reflectance": [0.5, 0.5, 0.5]},
        },
        "lamp": {
            "type": "rectangle",
            "to_world": translate_y(2.5) @ rotate_x(90) @ np.diag([0.5, 0.5, 0.5, 1.0]),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [8, 8, 8]}},
        },
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.2, 0.25, 0.3]}},
    }


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "small.xml"
    path.write_text(SCENE_XML)
    return path


def test_load_scene_properties_and_defines(scene_file):
    s = gonio.load_scene(scene_file)
    assert (s.width, s.height, s.spp, s.seed) == (32, 24, 4, 0)
    assert (s.shape_count, s.light_count) == (4, 2)
    assert s.primitive_count >= 4 and s.warnings == [] and s.source == str(scene_file)
    assert repr(s).startswith("<gonio.Scene ") and "32×24" in repr(s) and "4 spp" in repr(s) and "path" in repr(s)
    # Keyword defines override <default>s like -D; values go through str().
    t = gonio.load_scene(str(scene_file), width=20, height="10", spp=3)
    assert (t.width, t.height, t.spp) == (20, 10, 3)


def test_load_scene_errors(scene_file, tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        gonio.load_scene(tmp_path / "missing.xml")
    assert "missing.xml" in str(e.value)
    bad = tmp_path / "bad.xml"
    bad.write_text(SCENE_XML.replace('name="alpha" value="0.25"', 'name="alpah" value="0.25"'))
    with pytest.raises(gonio.SceneError, match=r"bad\.xml:\d+:\d+: unknown parameter `alpah`"):
        gonio.load_scene(bad)
    assert issubclass(gonio.SceneError, ValueError)
    with pytest.raises(gonio.SceneError, match="not valid XML"):
        bad.write_text("<scene version='3.0.0'>")
        gonio.load_scene(bad)
    with pytest.raises(gonio.SceneError, match="not defined"):
        bad.write_text(SCENE_XML.replace('<default name="spp" value="4"/>', ""))
        gonio.load_scene(bad)


def test_render_shape_determinism_and_arguments(scene_file):
    s = gonio.load_scene(scene_file)
    a = s.render(seed=3, progress=False)
    assert a.shape == (24, 32, 3) and a.dtype == np.float32 and a.flags.c_contiguous
    assert np.isfinite(a).all() and a.mean() > 0.05
    # The same seed gives the same bits whatever the number of threads; another seed another image.
    assert np.array_equal(a, s.render(seed=3, threads=1, progress=False))
    assert np.array_equal(a, s.render(spp=4, seed=3, threads=2, progress=False))
    assert not np.array_equal(a, s.render(seed=4, progress=False))
    # The default seed is the sampler's (0), as for `gonio render`.
    assert np.array_equal(s.render(progress=False), s.render(seed=0, progress=False))
    for kwargs, message in [({"spp": 0}, "spp"), ({"threads": 0}, "threads"), ({"seed": -1}, "seed")]:
        with pytest.raises(ValueError, match=message):
            s.render(progress=False, **kwargs)


def cli_render(scene_file, out, *args):
    """`gonio render SCENE -o OUT --threads 2 -q ARGS…` with the CLI binary; returns the image it wrote."""
    subprocess.run([str(CLI), "render", str(scene_file), "-o", str(out), "--threads", "2", "-q", *args], check=True, timeout=120)
    return gonio.read_image(out)


@pytest.mark.skipif(not CLI.exists(), reason="target/release/gonio not built (make build builds it)")
def test_render_equals_cli_exr_bit_for_bit(scene_file, tmp_path):
    cli = cli_render(scene_file, tmp_path / "cli.exr", "--spp", "3", "--seed", "11", "-D", "width=24")
    py = gonio.load_scene(scene_file, width=24).render(spp=3, seed=11, threads=2, progress=False)
    assert cli.shape == py.shape == (24, 24, 3)
    assert np.array_equal(cli, py)


@pytest.mark.skipif(not CLI.exists(), reason="target/release/gonio not built (make build builds it)")
def test_spectral_mode_equals_cli_and_differs_from_rgb(scene_file, tmp_path):
    # `mode="spectral"` is `gonio render --mode spectral` bit for bit; its image is another estimate of the
    # scene (gold and a blue plastic: colours whose spectra differ from their RGB), not the RGB one.
    cli = cli_render(scene_file, tmp_path / "cli.exr", "--spp", "3", "--seed", "5", "--mode", "spectral")
    spectral = gonio.load_scene(scene_file, mode="spectral")
    assert (spectral.mode, gonio.load_scene(scene_file).mode) == ("spectral", "rgb")
    py = spectral.render(spp=3, seed=5, threads=2, progress=False)
    assert np.array_equal(cli, py)
    # Each path draws its wavelengths from its own stream: the image does not depend on the thread count.
    assert np.array_equal(py, spectral.render(spp=3, seed=5, threads=1, progress=False))
    rgb = gonio.load_scene(scene_file).render(spp=3, seed=5, threads=2, progress=False)
    assert np.isfinite(py).all() and not np.array_equal(py, rgb)
    # A scene parameter called `mode` is still a define: `mode` itself is keyword-only and checked.
    with pytest.raises(gonio.SceneError, match="unknown mode `hyperspectral`; expected `rgb` or `spectral`"):
        gonio.load_scene(scene_file, mode="hyperspectral")


def test_dispersive_glass_from_a_dictionary():
    # A dispersive index (issue 30) from Python: RGB mode renders it at n_d, spectral mode spreads it; a law
    # where it is not taken names the parameter.
    scene = {
        "type": "scene",
        "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 8, "height": 8}},
        "light": {"type": "constant"},
        "ball": {"type": "sphere", "bsdf": {"type": "dielectric", "int_ior": "sellmeier(1.03961212, 0.231792344, 1.01046945, 0.00600069867, 0.0200179144, 103.560653)"}},
    }
    rgb = gonio.load_dict(scene).render(spp=4, seed=3, progress=False)
    spectral = gonio.load_dict(scene, mode="spectral").render(spp=4, seed=3, progress=False)
    assert np.isfinite(spectral).all() and not np.array_equal(rgb, spectral)
    plastic = dict(scene, ball={"type": "sphere", "bsdf": {"type": "plastic", "int_ior": "sf11"}})
    with pytest.raises(gonio.SceneError, match=r"\$\.ball\.bsdf.*int_ior.*taken by `dielectric`, `roughdielectric` and `thindielectric` only"):
        gonio.load_dict(plastic)


def test_spectral_mode_refuses_what_it_does_not_take_yet(tmp_path):
    # A colour spectral mode cannot take to its spectrum yet is an error naming it and where it is.
    base = {
        "type": "scene",
        "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 8, "height": 8}},
        "light": {"type": "constant"},
    }
    ok = dict(base, ball={"type": "sphere", "bsdf": {"type": "conductor", "material": "Au"}})
    assert gonio.load_dict(ok, mode="spectral").render(spp=2, progress=False).shape == (8, 8, 3)
    index = dict(base, ball={"type": "sphere", "bsdf": {"type": "conductor", "eta": [0.2, 0.4, 1.4], "k": [3.0, 2.4, 1.8]}})
    assert np.isfinite(gonio.load_dict(index, mode="spectral").render(spp=2, progress=False)).all()
    # Phong derives its lobe choice from its colours when built: it is refused, not rendered with a stale one.
    bad = dict(base, ball={"type": "sphere", "bsdf": {"type": "phong", "diffuse_reflectance": [0.8, 0.2, 0.1]}})
    gonio.load_dict(bad)  # RGB mode takes it
    with pytest.raises(gonio.SceneError, match=r"\$\.ball\.bsdf.*spectral mode does not take this colour \(parameter `diffuse_reflectance` of `phong`\)"):
        gonio.load_dict(bad, mode="spectral")
    with pytest.raises(gonio.SceneError, match="unknown mode"):
        gonio.load_dict(ok, mode="RGB")


def test_aov_channels_follow_the_rgb(scene_file, tmp_path):
    # Mitsuba's `aov` integrator: its channels after the RGB, named as Mitsuba names them; the RGB (and the
    # nested image's channels) are the nested path integrator's image; parts of a render carry every channel.
    aov = (
        '<integrator type="aov"><string name="aovs" value="dd.y:depth, nn:sh_normal"/>'
        '<integrator type="path" name="image"><integer name="max_depth" value="4"/></integrator></integrator>'
    )
    path = tmp_path / "aov.xml"
    path.write_text(scene_file.read_text().replace('<integrator type="path"><integer name="max_depth" value="4"/></integrator>', aov))
    s = gonio.load_scene(path)
    assert s.channels == ["R", "G", "B", "image.R", "image.G", "image.B", "image.A", "dd.y.T", "nn.X", "nn.Y", "nn.Z"]
    assert gonio.load_scene(scene_file).channels == ["R", "G", "B"]
    img = s.render(seed=3, progress=False)
    assert img.shape == (24, 32, 11) and img.dtype == np.float32
    plain = gonio.load_scene(scene_file).render(seed=3, progress=False)
    assert np.array_equal(img[..., :3], plain) and np.array_equal(img[..., 3:6], plain)
    # The environment is seen where nothing is hit: the nested path's samples are all valid (A = 1).
    assert np.all(img[..., 6] == 1.0)
    depth = img[..., 7]
    assert depth.min() == 0.0 and 3.0 < depth.max() < 7.7  # the far corner of the 6 × 6 floor: 7.7 away
    part = s.render_samples(0, 4, seed=3)
    assert part["sum"].shape == (24, 32, 11)
    assert np.array_equal(gonio.develop(part["sum"], part["weight"], 4), img)


def test_load_dict_agrees_with_load_scene(tmp_path):
    # Transforms given as matrices in both forms, so that both hold the same numbers.
    def xml_matrix(m):
        return '<transform name="to_world"><matrix value="' + " ".join(repr(float(v)) for v in np.asarray(m).ravel()) + '"/></transform>'

    d = scene_dict()
    xml = SCENE_XML
    xml = xml.replace(
        '<transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>', xml_matrix(d["floor"]["to_world"])
    )
    xml = xml.replace(
        '<transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="2.5"/></transform>',
        xml_matrix(d["lamp"]["to_world"]),
    )
    path = tmp_path / "matrices.xml"
    path.write_text(xml)
    from_xml = gonio.load_scene(path)
    from_dict = gonio.load_dict(d)
    assert from_dict.source == "<dict>" and (from_dict.width, from_dict.height, from_dict.spp) == (32, 24, 4)
    assert (from_dict.shape_count, from_dict.light_count) == (from_xml.shape_count, from_xml.light_count)
    a = from_xml.render(seed=1, progress=False)
    assert np.array_equal(a, from_dict.render(seed=1, progress=False))
    # The dictionary is not consumed or modified.
    assert np.array_equal(gonio.load_dict(d).render(seed=1, progress=False), a)


def test_load_dict_accepts_mitsuba_transforms():
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_rgb")
    d = scene_dict(width=16, height=12)
    ref = gonio.load_dict(d).render(seed=2, progress=False)
    d["sensor"]["to_world"] = mi.ScalarTransform4f().look_at(origin=[0, 1, 4], target=[0, 0.3, 0], up=[0, 1, 0])
    d["left"]["center"] = mi.ScalarPoint3f(-0.6, 0.5, 0)
    img = gonio.load_dict(d).render(seed=2, progress=False)
    # Mitsuba's look_at rounds differently in the last bit; the images agree to rounding.
    assert np.abs(img - ref).mean() < 1e-3 * ref.mean()
    np.testing.assert_allclose(np.array(d["sensor"]["to_world"].matrix), gonio.look_at([0, 1, 4], [0, 0.3, 0]), atol=1e-6)


def test_load_dict_errors():
    d = scene_dict()
    d["gold"]["alpha"] = -1
    with pytest.raises(gonio.SceneError, match=r"\$\.gold\.alpha"):
        gonio.load_dict(d)
    d = scene_dict()
    d["left"]["bsdf"] = {"type": "ref", "id": "silver"}
    with pytest.raises(gonio.SceneError, match='unknown id "silver"'):
        gonio.load_dict(d)
    d = scene_dict()
    d["floor"]["to_world"] = np.zeros((3, 3))
    with pytest.raises(gonio.SceneError, match=r"\$\.floor\.to_world: a matrix must be 4 rows of 4"):
        gonio.load_dict(d)
    d = scene_dict()
    d["gold"]["alpha"] = float("nan")
    with pytest.raises(gonio.SceneError, match=r"\$\.gold\.alpha: NaN is not a finite number"):
        gonio.load_dict(d)
    d = scene_dict()
    d["gold"]["alpha"] = object()
    with pytest.raises(gonio.SceneError, match=r"\$\.gold\.alpha: a value of type `object`"):
        gonio.load_dict(d)
    with pytest.raises(gonio.SceneError, match="teapot"):
        gonio.load_dict({"type": "scene", "s": {"type": "perspective"}, "t": {"type": "teapot"}})
    with pytest.raises(gonio.SceneError, match='"type": "scene"'):
        gonio.load_dict({"type": "sphere"})
    with pytest.raises(TypeError, match="expects a dict"):
        gonio.load_dict('{"type": "scene"}')
    with pytest.raises(ValueError, match="look_at"):
        gonio.look_at([0, 0, 0], [0, 0, 0])


def test_look_at_is_the_xml_lookat():
    m = gonio.look_at([0, 0, 5], [0, 0, 0])
    assert m.shape == (4, 4) and m.dtype == np.float64
    # Looking down −z with +y up: the camera's +z is world −z, its origin (0, 0, 5).
    np.testing.assert_allclose(m @ [0, 0, 1, 0], [0, 0, -1, 0], atol=1e-7)
    np.testing.assert_allclose(m @ [0, 0, 0, 1], [0, 0, 5, 1])


class FakeTerminal:
    def __init__(self):
        self.text = ""

    def write(self, s):
        self.text += s

    def flush(self):
        pass

    def isatty(self):
        return True


def test_progress_bar_only_in_terminals(scene_file, capfd, monkeypatch):
    s = gonio.load_scene(scene_file)
    s.render(progress=True)
    assert capfd.readouterr().err == ""  # stderr is not a terminal under pytest
    fake = FakeTerminal()
    monkeypatch.setattr(sys, "stderr", fake)
    s.render(progress=True)
    assert fake.text.startswith("\r") and "100%|" in fake.text and fake.text.endswith("\n")
    assert f"{32 * 24 * 4 / 1000:.1f}k/{32 * 24 * 4 / 1000:.1f}k samples" in fake.text
    fake.text = ""
    s.render(progress=False)
    assert fake.text == ""


def test_text_bar_layout():
    fake = FakeTerminal()
    bar = _progress.bar(1_000_000, "demo", stream=fake)
    bar.close(250_000)
    line = fake.text.strip().split("\r")[-1]
    assert line.startswith("demo  25%|███████▌") and "250.0k/1.0M samples" in line
    assert _progress.bar(10, "x", stream=open(os.devnull, "w")) is None


def test_ctrl_c_interrupts_promptly_and_leaves_the_process_usable(scene_file):
    big = gonio.load_scene(scene_file, width=320, height=240)
    # Python keeps SIGINT ignored when it starts with it ignored (a background job of a shell without job
    # control); the test then sends a signal nothing receives and the render runs for hours. So it
    # installs Python's own handler for the signal it sends, as an interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            big.render(spp=100_000, progress=False)
        elapsed = time.monotonic() - start
    finally:
        timer.join()
        signal.signal(signal.SIGINT, previous)
    # 100 000 spp would take hours; the render stops within a tile of the signal.
    assert elapsed < 5.0, elapsed
    small = gonio.load_scene(scene_file)
    assert np.array_equal(small.render(seed=3, progress=False), small.render(seed=3, progress=False))


def test_an_error_in_the_progress_bar_cancels_the_render(scene_file, monkeypatch):
    # Ctrl-C may surface inside the bar's Python code rather than in check_signals; the render must
    # stop either way, and the bar still be closed.
    calls = []

    class Interrupting:
        def update(self, done):
            calls.append("update")
            raise KeyboardInterrupt

        def close(self, done):
            calls.append("close")

    monkeypatch.setattr(_progress, "bar", lambda total, desc: Interrupting())
    big = gonio.load_scene(scene_file, width=320, height=240)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        big.render(spp=100_000, progress=True)
    assert time.monotonic() - start < 5.0
    assert calls == ["update", "close"]


def test_preview_in_spectral_mode():
    # `gonio.preview(..., mode="spectral")` is `gonio preview --mode spectral`: a dispersive sphere in the
    # white furnace stays white; a colour spectral mode cannot take yet, and an unknown mode, are errors.
    spec = {"type": "thindielectric", "int_ior": "cauchy(1.5, 0.02)"}
    img = gonio.preview(spec, env="constant", size=32, spp=128, mode="spectral").images[0]
    assert np.allclose(img[8:24, 8:24].reshape(-1, 3).mean(axis=0), 1.0, atol=0.03)
    with pytest.raises(gonio.SpecError, match="`diffuse_reflectance` of `phong`"):
        gonio.preview({"type": "phong", "diffuse_reflectance": [0.8, 0.2, 0.1]}, size=8, spp=1, mode="spectral")
    with pytest.raises(gonio.SpecError, match="unknown mode `hyper`"):
        gonio.preview({"type": "diffuse"}, size=8, spp=1, mode="hyper")
