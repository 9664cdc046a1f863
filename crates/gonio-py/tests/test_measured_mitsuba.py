"""The RGL `measured` BSDF (Dupuy & Jakob 2018) against Mitsuba 3's `measured` plugin (scalar_rgb).

Conventions as in test_mitsuba.py: Mitsuba's `si.wi` is gonio's `wo`, and
`mitsuba.eval(si.wi=a, wo=b) == gonio f(a, b) * cos θ(b)`. gonio clamps negative RGB channels of the
tables (Mitsuba returns them), so values are compared where Mitsuba's exceed 1e-4; the pdf is compared
where it exceeds 1e-4.

Bad files (truncated, foreign, missing field, NaN) must raise gonio.SpecError naming the file and problem.
"""

import os
import struct

import numpy as np
import pytest

import gonio

mi = pytest.importorskip("mitsuba", reason="mitsuba is not installed (pip install -r requirements-dev.txt)")
mi.set_variant("scalar_rgb")

DATA = "/work/shared/data/rgl"
FILES = sorted(f for f in os.listdir(DATA) if f.endswith(".bsdf")) if os.path.isdir(DATA) else []
N = 1200          # direction pairs per file
RTOL = 1e-3       # the bound; measured errors are reported by -s (see the module doc of measured.rs)
FLOOR = 1e-4      # compare values above this


def upper(r, n):
    """n directions uniform on the upper hemisphere, float32."""
    w = r.normal(size=(n, 3))
    w[:, 2] = np.abs(w[:, 2])
    return (w / np.linalg.norm(w, axis=1, keepdims=True)).astype(np.float32)


def pairs(r, n):
    """A mix of random pairs and pairs near the specular configuration, where the lobes are."""
    wo = upper(r, n)
    wi = upper(r, n)
    k = n // 2
    # Mirror direction of wo, jittered: wi = reflect(wo) + noise.
    mirror = wo[:k] * np.array([-1, -1, 1], dtype=np.float32)
    jitter = mirror + 0.15 * r.normal(size=(k, 3)).astype(np.float32)
    jitter[:, 2] = np.abs(jitter[:, 2])
    wi[:k] = (jitter / np.linalg.norm(jitter, axis=1, keepdims=True)).astype(np.float32)
    return wo, wi


def mi_eval_pdf(m, wo, wi):
    ctx = mi.BSDFContext()
    vals, pdfs = np.zeros((len(wo), 3)), np.zeros(len(wo))
    si = mi.SurfaceInteraction3f()
    for i, (a, b) in enumerate(zip(wo, wi)):
        si.wi = mi.Vector3f(*map(float, a))
        d = mi.Vector3f(*map(float, b))
        vals[i] = np.array(m.eval(ctx, si, d))
        pdfs[i] = float(m.pdf(ctx, si, d))
    return vals, pdfs


def rel_err(a, b, floor):
    mask = b > floor
    return (np.abs(a - b)[mask] / b[mask]), mask


@pytest.mark.parametrize("name", FILES)
def test_eval_and_pdf_match_mitsuba(name):
    path = os.path.join(DATA, name)
    g = gonio.load_bsdf({"type": "measured", "filename": path})
    m = mi.load_dict({"type": "measured", "filename": path})
    r = np.random.default_rng(sum(map(ord, name)))
    wo, wi = pairs(r, N)
    mi_val, mi_pdf = mi_eval_pdf(m, wo, wi)
    g_val = g.f(wo, wi).astype(np.float64) * wi[:, 2:3].astype(np.float64)
    g_pdf = g.pdf(wo, wi).astype(np.float64)

    err, mask = rel_err(g_val, mi_val, FLOOR)
    assert mask.sum() > 0.5 * mask.size, "most channels of most pairs should be above the floor"
    perr, pmask = rel_err(g_pdf, mi_pdf, FLOOR)
    assert pmask.sum() > 0.5 * N
    print(f"\n{name}: f·cos max rel err {err.max():.3e} over {mask.sum()} values; "
          f"pdf max rel err {perr.max():.3e} over {pmask.sum()} pairs")
    assert err.max() < RTOL, f"worst f·cos at pair {np.argwhere(mask)[np.argmax(err)]}"
    assert perr.max() < RTOL, f"worst pdf at pair {np.argwhere(pmask)[np.argmax(perr)]}"
    # Near the pole of the half vector (θm = 1.9e-3 here) a float32 √(1 − z²) for sin θm would be 1.6 %
    # off; gonio's |(x, y)| agrees with Mitsuba 3.9.1.
    # Where Mitsuba's value is negative (an RGB channel below 0), gonio returns 0; elsewhere both are ≥ 0.
    assert np.all(g_val >= 0)
    assert np.all(g_val[mi_val <= 0] == 0)
    # Below the floor the values agree in absolute terms.
    small = (mi_val > 0) & (mi_val <= FLOOR)
    assert np.all(np.abs(g_val[small] - mi_val[small]) <= RTOL * FLOOR)


@pytest.mark.parametrize("name", FILES[:3])
def test_samples_match_mitsuba(name):
    """Same (wo, u) → the same sampled direction and pdf (gonio's f and pdf of a sample come from the
    inverse warp, Mitsuba's from the forward one: equal to float32 round-off)."""
    path = os.path.join(DATA, name)
    g = gonio.load_bsdf({"type": "measured", "filename": path})
    m = mi.load_dict({"type": "measured", "filename": path})
    r = np.random.default_rng(7)
    n = 300
    wo = upper(r, n)
    u = r.random((n, 2), dtype=np.float32)
    s = g.sample(wo, np.full(n, 0.5, dtype=np.float32), u)
    ctx = mi.BSDFContext()
    si = mi.SurfaceInteraction3f()
    wi_m, pdf_m = np.zeros((n, 3)), np.zeros(n)
    for i in range(n):
        si.wi = mi.Vector3f(*map(float, wo[i]))
        bs, _ = m.sample(ctx, si, 0.5, mi.Point2f(float(u[i, 0]), float(u[i, 1])))
        wi_m[i] = np.array(bs.wo)
        pdf_m[i] = float(bs.pdf)
    both = s.valid & (wi_m[:, 2] > 0)
    assert both.sum() > 0.9 * n
    np.testing.assert_allclose(s.wi[both], wi_m[both], atol=1e-4)
    big = both & (pdf_m > FLOOR)
    np.testing.assert_allclose(s.pdf[big], pdf_m[big], rtol=RTOL)


# --- bad files ------------------------------------------------------------------------------------------

def tensor_file(fields):
    """Encode {name: numpy array} in the tensor_file format (data 8-byte aligned)."""
    codes = {np.uint8: 1, np.int8: 2, np.uint16: 3, np.int16: 4, np.uint32: 5, np.int32: 6, np.uint64: 7,
             np.int64: 8, np.float16: 9, np.float32: 10, np.float64: 11}
    header = 18 + sum(2 + len(k) + 2 + 1 + 8 + 8 * v.ndim for k, v in fields.items())
    offsets, off = [], (header + 7) // 8 * 8
    for v in fields.values():
        offsets.append(off)
        off = (off + v.nbytes + 7) // 8 * 8
    buf = bytearray(b"tensor_file\0" + struct.pack("<BBI", 1, 0, len(fields)))
    for (k, v), off in zip(fields.items(), offsets):
        buf += struct.pack("<H", len(k)) + k.encode() + struct.pack("<HBQ", v.ndim, codes[v.dtype.type], off)
        buf += b"".join(struct.pack("<Q", n) for n in v.shape)
    for v, off in zip(fields.values(), offsets):
        buf += b"\0" * (off - len(buf)) + np.ascontiguousarray(v).tobytes()
    return bytes(buf)


def read_fields(path):
    """Decode a tensor file into {name: numpy array} (to rewrite the real files in tests)."""
    b = open(path, "rb").read()
    n = struct.unpack_from("<I", b, 14)[0]
    pos, out = 18, {}
    types = {1: np.uint8, 5: np.uint32, 10: np.float32}
    for _ in range(n):
        (ln,) = struct.unpack_from("<H", b, pos)
        name = b[pos + 2:pos + 2 + ln].decode()
        pos += 2 + ln
        nd, dt, off = struct.unpack_from("<HBQ", b, pos)
        pos += 11
        shape = struct.unpack_from("<%dQ" % nd, b, pos)
        pos += 8 * nd
        out[name] = np.frombuffer(b, types[dt], int(np.prod(shape)), off).reshape(shape).copy()
    return out


@pytest.fixture(scope="module")
def paper():
    return read_fields(os.path.join(DATA, "paper_white_rgb.bsdf"))


def load_bytes(tmp_path, data, name="bad.bsdf"):
    p = tmp_path / name
    p.write_bytes(data)
    return gonio.load_bsdf({"type": "measured", "filename": str(p)}), str(p)


@pytest.mark.skipif(not FILES, reason="no RGL data")
def test_own_encoder_round_trips(tmp_path, paper):
    g, _ = load_bytes(tmp_path, tensor_file(paper), "copy.bsdf")
    ref = gonio.load_bsdf({"type": "measured", "filename": os.path.join(DATA, "paper_white_rgb.bsdf")})
    r = np.random.default_rng(3)
    wo, wi = pairs(r, 200)
    np.testing.assert_array_equal(g.f(wo, wi), ref.f(wo, wi))


@pytest.mark.skipif(not FILES, reason="no RGL data")
@pytest.mark.parametrize("case, pattern", [
    ("truncated", r"truncated"),
    ("header only", r"truncated"),
    ("empty", r"not a tensor file"),
    ("wrong magic", r"not a tensor file"),
    ("missing field", r"field `vndf`: missing"),
    ("nan", r"field `rgb`: element \[0, 3, 1, 7, 9\] is NaN"),
    ("inf sigma", r"field `sigma`: element .* is inf"),
    ("wrong shape", r"field `luminance`: expected shape \[1, 8, ≥2, ≥2\]"),
    ("wrong dtype", r"field `theta_i`: expected a 1-dimensional f32 array, found a 1-dimensional f64"),
    ("all zero", r"field `rgb`: has no positive value"),
    ("spectral without wavelengths", r"field `wavelengths`: missing"),
])
def test_bad_files_are_named_errors(tmp_path, paper, case, pattern):
    fields = {k: v.copy() for k, v in paper.items()}
    data = None
    full = tensor_file(fields)
    if case == "truncated":
        data = full[: len(full) // 2]
    elif case == "header only":
        data = full[:100]
    elif case == "empty":
        data = b""
    elif case == "wrong magic":
        data = b"tensor_fila\0" + full[12:]
    elif case == "missing field":
        del fields["vndf"]
    elif case == "nan":
        fields["rgb"][0, 3, 1, 7, 9] = np.nan
    elif case == "inf sigma":
        fields["sigma"][1, 5] = np.inf
    elif case == "wrong shape":
        fields["luminance"] = fields["luminance"][:, :, :1, :]
    elif case == "wrong dtype":
        fields["theta_i"] = fields["theta_i"].astype(np.float64)
    elif case == "all zero":
        fields["rgb"][:] = 0
    elif case == "spectral without wavelengths":
        fields["spectra"] = fields.pop("rgb")
    if data is None:
        data = tensor_file(fields)
    with pytest.raises(gonio.SpecError, match=pattern) as e:
        load_bytes(tmp_path, data)
    assert "bad.bsdf" in str(e.value)


def test_missing_file_and_parameter():
    with pytest.raises(gonio.SpecError, match="no_such_material.bsdf"):
        gonio.load_bsdf({"type": "measured", "filename": "/nonexistent/no_such_material.bsdf"})
    with pytest.raises(gonio.SpecError, match="needs a `filename`"):
        gonio.load_bsdf({"type": "measured"})


# --- anisotropic files ------------------------------------------------------------------------------------

def refine4(a):
    """Insert three points in every interval of the last two axes: bilinear interpolation on the fine grid
    is the same function as on the coarse one."""
    m = a.shape[-1]
    x = np.arange(4 * (m - 1) + 1) / 4.0
    i0 = np.minimum(np.floor(x).astype(int), m - 2)
    t = (x - i0).astype(np.float32)
    a = a[..., i0, :] * (1 - t)[:, None] + a[..., i0 + 1, :] * t[:, None]
    return a[..., i0] * (1 - t) + a[..., i0 + 1] * t


def anisotropic(phis, gains):
    """The anisotropic twin of an isotropic material, as in crates/gonio/src/bsdf/measured.rs
    (`isotropic_and_anisotropic`): the VNDF averaged over the half-vector azimuth, the reflectance and
    luminance squares made periodic, refined ×4 and turned by φₖ/2π for the incident azimuth φₖ, the
    reflectance at φₖ scaled by gains[k]."""
    f = read_fields(os.path.join(DATA, "cc_ibiza_sunset_rgb.bsdf"))
    f.pop("valid")
    f["vndf"] = np.broadcast_to(f["vndf"].mean(axis=2, keepdims=True), f["vndf"].shape)
    out = {}
    for name in ("luminance", "rgb"):
        a = f[name].copy()
        a[..., -1, :] = a[..., 0, :]
        fine = refine4(a)
        n = fine.shape[-1]
        turned = []
        for phi, g in zip(phis, gains):
            shift = (n - 1) * phi / (2 * np.pi)
            assert abs(shift - round(shift)) < 1e-6
            body = np.roll(fine[0, ..., : n - 1, :], round(shift), axis=-2)
            turned.append(np.concatenate([body, body[..., :1, :]], axis=-2) * (g if name == "rgb" else 1.0))
        out[name] = np.ascontiguousarray(np.stack(turned), dtype=np.float32)
    k = len(phis)
    f["phi_i"] = np.array(phis, dtype=np.float32)
    f["vndf"] = np.ascontiguousarray(np.repeat(f["vndf"], k, axis=0), dtype=np.float32)
    f.update(out)
    return f


@pytest.mark.skipif(not FILES, reason="no RGL data")
def test_spectral_file_matches_mitsuba_spectral(tmp_path):
    """A spectral RGL file (`spectra` at `wavelengths`) at given wavelengths, as spectral mode renders it
    (issue 30), against Mitsuba 3's `scalar_spectral`, which evaluates it at the four wavelengths of
    `si.wavelengths`. The file is made from cc_ibiza_sunset: each cell's spectrum is its RGB times three
    smooth bumps, at 13 irregular wavelengths over 380–760 nm, so that most wavelengths asked for fall
    between two of the file's and some outside its range (both renderers then take the nearer end's
    value). Mitsuba's spectral variants refuse RGB files, and gonio's `wavelengths=` refuses them too."""
    f = read_fields(os.path.join(DATA, "cc_ibiza_sunset_rgb.bsdf"))
    rgb = f.pop("rgb")
    lam = np.array([380, 400, 425, 450, 480, 510, 540, 575, 600, 630, 660, 700, 760], dtype=np.float32)
    bump = lambda centre, width: np.exp(-0.5 * ((lam - centre) / width) ** 2)
    basis = np.stack([bump(620, 60), bump(540, 40), bump(450, 35)])
    f["wavelengths"] = lam
    f["spectra"] = np.ascontiguousarray(np.einsum("pqcij,cl->pqlij", rgb, basis).astype(np.float32))
    path = tmp_path / "ibiza_spectral.bsdf"
    path.write_bytes(tensor_file(f))
    g = gonio.load_bsdf({"type": "measured", "filename": str(path)})

    r = np.random.default_rng(30)
    n = 400
    wo, wi = pairs(r, n)
    waves = r.uniform(360, 830, size=(n, 4))
    waves[:, 0] = np.where(np.arange(n) % 5 == 0, lam[r.integers(0, len(lam), n)], waves[:, 0])  # some on the nodes
    mi.set_variant("scalar_spectral")
    try:
        m = mi.load_dict({"type": "measured", "filename": str(path)})
        ctx, si = mi.BSDFContext(), mi.SurfaceInteraction3f()
        mi_val = np.zeros((n, 4))
        for i in range(n):
            si.wi = mi.Vector3f(*map(float, wo[i]))
            si.wavelengths = mi.Spectrum(*map(float, waves[i]))
            mi_val[i] = np.array(m.eval(ctx, si, mi.Vector3f(*map(float, wi[i]))))
        with pytest.raises(Exception, match="RGB variant"):
            mi.load_dict({"type": "measured", "filename": os.path.join(DATA, "cc_ibiza_sunset_rgb.bsdf")})
    finally:
        mi.set_variant("scalar_rgb")
    g_val = np.stack([g.f(wo, wi, wavelengths=waves[:, k]) for k in range(4)], axis=1).astype(np.float64) * wi[:, 2:3]
    err, mask = rel_err(g_val, mi_val, FLOOR)
    print(f"spectral file: {mask.sum()} values compared, worst relative error {err.max():.2e}")
    assert mask.sum() > 0.5 * mask.size
    assert err.max() < RTOL
    # Where Mitsuba's is below the floor (or negative: the RGB tables hold small negative entries, which
    # gonio clamps), gonio's is too.
    assert np.all(g_val[~mask] <= FLOOR + 1e-6)
    rgb_only = gonio.load_bsdf({"type": "measured", "filename": os.path.join(DATA, "cc_ibiza_sunset_rgb.bsdf")})
    with pytest.raises(gonio.SpecError, match="RGB data only"):
        rgb_only.f(wo[:2], wi[:2], wavelengths=550.0)


@pytest.mark.skipif(not FILES, reason="no RGL data")
@pytest.mark.parametrize("label, phis, gains", [
    ("full turn", [-np.pi, -np.pi / 2, 0.0, np.pi / 2, np.pi], [1.0] * 5),
    ("half turn", [-np.pi, -np.pi / 2, 0.0], [1.0] * 3),
    ("known φ-dependence", [-np.pi, -np.pi / 2, 0.0, np.pi / 2, np.pi], [0.6, 0.9, 1.2, 1.5, 0.6]),
])
def test_anisotropic_files_match_mitsuba(tmp_path, label, phis, gains):
    """gonio against Mitsuba 3 on anisotropic files (nφ > 2) at random viewer azimuths, i.e. mostly
    between the tabulated ones, where both interpolate the tables of neighbouring azimuths; the half-turn
    file is folded by its 2-fold symmetry. (At the tabulated azimuths, crates/gonio/src/bsdf/measured.rs
    checks that such a file equals the isotropic material it was made from.)"""
    p = tmp_path / "aniso.bsdf"
    p.write_bytes(tensor_file(anisotropic(phis, gains)))
    g = gonio.load_bsdf({"type": "measured", "filename": str(p)})
    m = mi.load_dict({"type": "measured", "filename": str(p)})
    r = np.random.default_rng(31)
    wo, wi = pairs(r, N)
    mi_val, mi_pdf = mi_eval_pdf(m, wo, wi)
    g_val = g.f(wo, wi).astype(np.float64) * wi[:, 2:3].astype(np.float64)
    g_pdf = g.pdf(wo, wi).astype(np.float64)
    err, mask = rel_err(g_val, mi_val, FLOOR)
    perr, pmask = rel_err(g_pdf, mi_pdf, FLOOR)
    assert mask.sum() > 0.5 * mask.size and pmask.sum() > 0.5 * N
    print(f"\n{label}: f·cos max rel err {err.max():.3e} over {mask.sum()} values; "
          f"pdf max rel err {perr.max():.3e} over {pmask.sum()} pairs")
    assert err.max() < RTOL, f"worst f·cos at pair {np.argwhere(mask)[np.argmax(err)]}"
    assert perr.max() < RTOL, f"worst pdf at pair {np.argwhere(pmask)[np.argmax(perr)]}"
