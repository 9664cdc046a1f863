"""The bad-input catalogue of docs/errors.md through the Python API.

Each row of the catalogue's table is fed to the Python function that does what the CLI command of the
row does (``load_scene``, ``load_bsdf``, ``write_image``, ``Scene.render``); the exception must be the
type the row's "Python" column names and its message the row's exact text (the CLI's words, with the
scratch directory written ``DIR``), read from docs/errors.md itself so that the two cannot drift apart.
A Rust panic must never surface: ``pyo3_runtime.PanicException`` derives from ``BaseException``, so every
call is made through ``expect_error``, which fails the test on it (and on any exception chained to the
one raised, i.e. a traceback from inside the bindings).
"""

import os
import pathlib
import re

import numpy as np
import pytest

import gonio

ROOT = pathlib.Path(__file__).resolve().parents[3]
DATA = pathlib.Path(os.environ.get("GONIO_DATA", ROOT.parent / "shared" / "data"))
if not DATA.is_dir():
    DATA = pathlib.Path("/work/shared/data")

# The scene the CLI's tests vary (crates/gonio-cli/tests/data/sphere_sky.xml, the CLI tests' `SCENE`): line
# numbers in the messages refer to it.
SCENE = (ROOT / "crates" / "gonio-cli" / "tests" / "data" / "sphere_sky.xml").read_text()
SPHERE = '<shape type="sphere"/>'
CONSTANT = '<emitter type="constant"/>'


def catalogue():
    """The rows of docs/errors.md's table: {input: (exact text, python column)}."""
    rows = {}
    for line in (ROOT / "docs" / "errors.md").read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        if len(cells) != 5 or cells[0] in ("input", "---") or set(cells[0]) <= {"-"}:
            continue
        text = cells[1].split(" — ")[0].strip()
        if text.startswith("`") and text.endswith("`"):
            text = text[1:-1]
        rows[cells[0]] = (text, cells[4])
    return rows


ROWS = catalogue()


def expect_error(kind, call, *args, **kwargs):
    """Call and return the exception, which must be a `kind`: never a panic, never a chained traceback."""
    try:
        call(*args, **kwargs)
    except BaseException as e:  # noqa: BLE001 - a PanicException is a BaseException
        name = f"{type(e).__module__}.{type(e).__qualname__}"
        assert "Panic" not in name, f"a Rust panic reached Python: {name}: {e}"
        assert isinstance(e, kind), f"expected {kind.__name__}, got {name}: {e}"
        assert e.__cause__ is None and e.__context__ is None, f"chained exception behind {name}: {e!r}"
        return e
    pytest.fail(f"{call.__name__} raised nothing")


def message(e, tmp_path):
    """The exception's text as the CLI prints it: OSErrors as `FILE: STRERROR`, DIR for the scratch dir."""
    if isinstance(e, OSError) and e.filename is not None:
        text = f"{e.filename}: {e.strerror}"
    else:
        text = str(e)
    return text.replace(str(tmp_path), "DIR")


def assert_row(row, e, tmp_path):
    """The exception matches the catalogue's row: the type its Python column names, the exact text."""
    text, python = ROWS[row]
    # The Python column: "`Type`", or "`Type`: `` Python's own text ``" where the words differ.
    kind, _, own = python.partition(": ")
    kind = kind.strip("`")
    assert kind in (type(e).__qualname__, f"gonio.{type(e).__qualname__}"), (
        f"{row}: docs/errors.md says {kind}, Python raised {type(e).__qualname__}"
    )
    if own:
        assert own.startswith("`` ") and own.endswith(" ``"), own
        text = own[3:-3]
    got = message(e, tmp_path)
    if text.endswith("…"):
        assert got.startswith(text[:-1]), f"{row}:\n  got      {got}\n  expected {text}"
    else:
        assert got == text, f"{row}:\n  got      {got}\n  expected {text}"


def scene_with(tmp_path, name, old, new):
    assert old in SCENE
    path = tmp_path / name
    path.write_text(SCENE.replace(old, new), encoding="utf-8")
    return path


def shared(tmp_path, source, n, name):
    """The first `n` bytes of a shared data file as tmp_path/name (skipped when the data is missing)."""
    path = DATA / source
    if not path.exists():
        pytest.skip(f"{path} is missing")
    out = tmp_path / name
    out.write_bytes(path.read_bytes()[:n])
    return out


# --- rows that load a scene: SceneError (a ValueError) or an OSError, with the CLI's text -----------

SCENE_ROWS = [
    ("not XML", "hello.xml", None, "hello"),
    ("unknown plugin", "blob.xml", SPHERE, '<shape type="blob"/>'),
    ("unknown parameter", "typo.xml", SPHERE, '<shape type="sphere"><float name="radiuss" value="1"/></shape>'),
    ("wrong type", "type.xml", SPHERE, '<shape type="sphere"><string name="radius" value="big"/></shape>'),
    ("NaN where a number is required", "nan.xml", SPHERE, '<shape type="sphere"><float name="radius" value="nan"/></shape>'),
    ("negative value", "negative.xml", SPHERE, '<shape type="sphere"><float name="radius" value="-1"/></shape>'),
    ("infinite radiance", "inf.xml", CONSTANT, '<emitter type="constant"><rgb name="radiance" value="inf"/></emitter>'),
    ("missing mesh", "mesh.xml", SPHERE, '<shape type="ply"><string name="filename" value="missing.ply"/></shape>'),
    (
        "missing texture",
        "texture.xml",
        SPHERE,
        '<shape type="sphere"><bsdf type="diffuse"><texture name="reflectance" type="bitmap">'
        '<string name="filename" value="missing.png"/></texture></bsdf></shape>',
    ),
    (
        "missing envmap (absolute path)",
        "envmap.xml",
        CONSTANT,
        '<emitter type="envmap"><string name="filename" value="/no/such/sky.exr"/></emitter>',
    ),
    ("zero-area sphere", "sphere.xml", SPHERE, '<shape type="sphere"><float name="radius" value="0"/></shape>'),
    (
        "zero scale",
        "scale.xml",
        SPHERE,
        '<shape type="rectangle"><transform name="to_world"><scale x="0" y="1" z="1"/></transform></shape>',
    ),
    (
        "`sample_count` 0",
        "zero.xml",
        "</sensor>",
        '<sampler type="independent"><integer name="sample_count" value="0"/></sampler></sensor>',
    ),
]


@pytest.mark.parametrize("row, name, old, new", SCENE_ROWS, ids=[r[0] for r in SCENE_ROWS])
def test_bad_scenes(tmp_path, row, name, old, new):
    if old is None:
        path = tmp_path / name
        path.write_text(new, encoding="utf-8")
    else:
        path = scene_with(tmp_path, name, old, new)
    e = expect_error(gonio.SceneError, gonio.load_scene, str(path))
    assert isinstance(e, ValueError)
    assert_row(row, e, tmp_path)


def test_missing_scene_file(tmp_path):
    e = expect_error(FileNotFoundError, gonio.load_scene, str(tmp_path / "nope.xml"))
    assert_row("missing scene file", e, tmp_path)


def test_unreadable_scene_file(tmp_path):
    path = scene_with(tmp_path, "locked.xml", "", "")
    path.chmod(0)
    try:
        if os.access(path, os.R_OK):
            pytest.skip("running as root: chmod 000 does not make the file unreadable")
        e = expect_error(PermissionError, gonio.load_scene, str(path))
        assert_row("unreadable scene file (chmod 000)", e, tmp_path)
    finally:
        path.chmod(0o644)


@pytest.mark.parametrize(
    "row, res",
    [("resolution 0×0", 0), ("resolution 10⁶×10⁶", 1_000_000), ("resolution 65536×65536 (each side allowed, too many pixels)", 65536)],
)
def test_absurd_resolutions(tmp_path, row, res):
    path = scene_with(tmp_path, "ok.xml", "", "")
    e = expect_error(gonio.SceneError, gonio.load_scene, str(path), res=res)
    assert_row(row, e, tmp_path)


# --- truncated binary files: through a scene, or as a measured BSDF --------------------------------

TRUNCATED = [
    (
        "truncated PLY",
        ("mitsuba/common/meshes/sphere.ply", 5000, "t.ply"),
        ("ply.xml", SPHERE, '<shape type="ply"><string name="filename" value="t.ply"/></shape>'),
    ),
    (
        "truncated `.serialized`",
        ("mitsuba/common/meshes/matpreview.serialized", 400_000, "t.serialized"),
        ("serialized.xml", SPHERE, '<shape type="serialized"><string name="filename" value="t.serialized"/></shape>'),
    ),
    (
        "truncated EXR",
        ("envmaps/museum.exr", 20_000, "t.exr"),
        ("exr.xml", CONSTANT, '<emitter type="envmap"><string name="filename" value="t.exr"/></emitter>'),
    ),
]


@pytest.mark.parametrize("row, file, scene", TRUNCATED, ids=[r[0] for r in TRUNCATED])
def test_truncated_files_in_scenes(tmp_path, row, file, scene):
    shared(tmp_path, *file)
    path = scene_with(tmp_path, *scene)
    e = expect_error(gonio.SceneError, gonio.load_scene, str(path))
    assert_row(row, e, tmp_path)


def test_truncated_measured_files(tmp_path):
    # RGL: the CLI's `gonio check FILE.bsdf` is `load_bsdf({"type": "measured", "filename": FILE})`.
    bsdf = shared(tmp_path, "rgl/paper_white_rgb.bsdf", 300_000, "t.bsdf")
    e = expect_error(gonio.SpecError, gonio.load_bsdf, {"type": "measured", "filename": str(bsdf)})
    assert_row("truncated RGL `.bsdf`", e, tmp_path)
    # MERL: a header (90 × 90 × 180) and 1000 of the 34,992,000 bytes of data.
    merl = tmp_path / "t.binary"
    merl.write_bytes(np.array([90, 90, 180], dtype="<i4").tobytes() + bytes(1000))
    e = expect_error(gonio.SpecError, gonio.load_bsdf, {"type": "merl", "filename": str(merl)})
    assert_row("truncated MERL `.binary`", e, tmp_path)


# --- BSDF descriptions ------------------------------------------------------------------------------


def test_unknown_bsdf(tmp_path):
    for spec in ({"type": "glass"}, '{"type": "glass"}'):
        e = expect_error(gonio.SpecError, gonio.load_bsdf, spec)
        assert_row("unknown BSDF (`gonio check`)", e, tmp_path)


# --- rendering and writing -------------------------------------------------------------------------


def test_zero_spp(tmp_path):
    scene = gonio.load_scene(str(scene_with(tmp_path, "ok.xml", "", "")))
    e = expect_error(ValueError, scene.render, spp=0, progress=False)
    assert_row("`--spp 0`", e, tmp_path)


def test_degenerate_mesh_and_camera_inside_render(tmp_path):
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    flat = scene_with(
        tmp_path,
        "mesh.xml",
        SPHERE,
        '<shape type="obj"><string name="filename" value="flat.obj"/><emitter type="area"/></shape><shape type="sphere"/>',
    )
    image = gonio.load_scene(str(flat)).render(spp=16, progress=False)
    assert np.isfinite(image).all()
    means = []
    for name, bsdf in [("one", '<bsdf type="diffuse"/>'), ("two", '<bsdf type="twosided"><bsdf type="diffuse"/></bsdf>')]:
        inside = scene_with(
            tmp_path,
            f"{name}.xml",
            SPHERE,
            f'<shape type="sphere"><float name="radius" value="10"/>{bsdf}</shape>'
            '<emitter type="point"><point name="position" x="0" y="0" z="3"/><rgb name="intensity" value="100"/></emitter>',
        )
        image = gonio.load_scene(str(inside)).render(spp=4, progress=False)
        assert np.isfinite(image).all()
        means.append(float(image.mean()))
    assert means[0] == 0.0 and means[1] > 0.0, means


IMAGE = np.full((2, 3, 3), 0.5, dtype=np.float32)

OUTPUTS = [
    ("output directory missing", "no/such/dir/out.exr", FileNotFoundError),
    ("output under a regular file", "ok.xml/out.exr", NotADirectoryError),
    ("output extension gonio cannot write", "out.tiff", ValueError),
]


@pytest.mark.parametrize("row, name, kind", OUTPUTS, ids=[r[0] for r in OUTPUTS])
def test_unwritable_outputs(tmp_path, row, name, kind):
    (tmp_path / "ok.xml").write_text(SCENE, encoding="utf-8")
    e = expect_error(kind, gonio.write_image, str(tmp_path / name), IMAGE)
    assert_row(row, e, tmp_path)
    assert not (tmp_path / name).exists()


def test_read_only_output_directory_keeps_the_old_image(tmp_path):
    target = tmp_path / "keep.exr"
    gonio.write_image(str(target), IMAGE)
    good = target.read_bytes()
    tmp_path.chmod(0o555)
    try:
        if os.access(tmp_path, os.W_OK):
            pytest.skip("running as root: a read-only directory stays writable")
        e = expect_error(PermissionError, gonio.write_image, str(target), IMAGE * 2)
        assert_row("output directory read-only", e, tmp_path)
    finally:
        tmp_path.chmod(0o755)
    assert target.read_bytes() == good
    assert not [p for p in tmp_path.iterdir() if ".tmp-" in p.name]


def test_every_row_is_covered_or_marked_without_python_equivalent():
    """Each row of the catalogue either names a Python exception (tested above) or says `—`."""
    tested = (
        {r[0] for r in SCENE_ROWS}
        | {r[0] for r in TRUNCATED}
        | {r[0] for r in OUTPUTS}
        | {
            "missing scene file",
            "unreadable scene file (chmod 000)",
            "resolution 0×0",
            "resolution 10⁶×10⁶",
            "resolution 65536×65536 (each side allowed, too many pixels)",
            "truncated RGL `.bsdf`",
            "truncated MERL `.binary`",
            "unknown BSDF (`gonio check`)",
            "`--spp 0`",
            "output directory read-only",
        }
    )
    renders = {"mesh of degenerate triangles (also as an area light)", "camera inside geometry"}
    assert len(ROWS) >= 30, sorted(ROWS)
    for row, (_, python) in ROWS.items():
        if row in tested:
            assert python not in ("", "—"), f"{row}: tested from Python, but docs/errors.md says {python!r}"
        elif row in renders:
            assert python.startswith("renders"), f"{row}: {python!r}"
        else:
            assert python == "—", f"{row}: docs/errors.md names {python!r} but no test feeds it from Python"
    assert re.search(r"-D", " ".join(r for r in ROWS if ROWS[r][1] == "—")), "the `-D` row has no Python equivalent"
