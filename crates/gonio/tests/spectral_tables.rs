//! Colours and indices given as tables (`<spectrum name=… value="λ:v, …"/>` or an `.spd` file) inside a
//! `<bsdf>` (issue 30): RGB mode reduces a table as Mitsuba 3's RGB variants do (the colour under D65);
//! spectral mode renders the table itself, where it used to render the upsampled spectrum of that
//! reduction — a metamer, which under a light of narrow lines can look nothing like the surface. Checked
//! against Mitsuba 3.9.1 and, for a diffuse surface, against the closed form.

mod common;

use common::{mean_and_se, xyz_of};
use gonio::bsdf::Bsdf;
use gonio::measured::tensor_file::{encode, f32_bytes, DType, TensorFile};
use gonio::props::Props;
use gonio::render::{render, RenderOutput};
use gonio::scene::spectral::{given_spectra, reflectances_at};
use gonio::scene::{mitsuba_xml, Mode, Scene};
use gonio::spectrum::named::xyz_to_linear_srgb;
use gonio::spectrum::piecewise::PiecewiseLinear;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// A light of three lines (triangles 40 nm wide at 450, 550 and 610 nm), and a reflectance that dips to
/// 0.05 exactly there: its RGB reduction is a bright colour, its product with the light is dark.
const LINES: &str = "360:0, 430:0, 450:4, 470:0, 530:0, 550:4, 570:0, 590:0, 610:4, 630:0, 830:0";
const DIPS: &str = "360:0.8, 450:0.05, 500:0.8, 550:0.05, 580:0.8, 610:0.05, 660:0.8, 830:0.8";

fn ior_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/ior")
}

/// A plane filling the view of a camera looking straight at it, under a constant sky of [`LINES`]; one
/// bounce, so a pixel is the surface's reflectance of the sky.
fn render_plane(bsdf: &str, mode: Mode, spp: u32) -> RenderOutput {
    render_plane_under(&format!(r#"<emitter type="constant"><spectrum name="radiance" value="{LINES}"/></emitter>"#), bsdf, mode, spp)
}

/// [`render_plane`] under the constant emitter `sky`.
fn render_plane_under(sky: &str, bsdf: &str, mode: Mode, spp: u32) -> RenderOutput {
    let xml = format!(
        r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="2"/></integrator>
        <sensor type="perspective"><float name="fov" value="4"/>
        <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/><rfilter type="box"/></film></sensor>
        {sky}
        <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>{bsdf}</shape></scene>"#
    );
    let scene = Scene::build_in(mitsuba_xml::load_str(&xml, "test.xml", &ior_dir(), &[]).unwrap(), mode).unwrap();
    render(&scene, scene.sampler.sample_count, scene.sampler.seed, &AtomicBool::new(false), &|_| {})
}

fn table(pairs: &str) -> PiecewiseLinear {
    let (w, v): (Vec<f64>, Vec<f64>) = pairs
        .split(',')
        .map(|p| {
            let (l, v) = p.split_once(':').unwrap();
            (l.trim().parse::<f64>().unwrap(), v.trim().parse::<f64>().unwrap())
        })
        .unzip();
    PiecewiseLinear::new(w, v).unwrap()
}

/// Mitsuba 3.9.1 renders of the same files (65 536 spp on 4 × 4 pixels, 2026-12-06), `scalar_spectral` and
/// `scalar_rgb`: a `diffuse` of [`DIPS`], a `conductor` whose `eta` and `k` are copper's `.spd` files, and a
/// `twosided` gold `conductor` whose `specular_reflectance` is [`DIPS`]. Spectral mode agrees within 5
/// standard errors and 0.5 %; before, it rendered a smooth spectrum upsampled from the table's colour, near
/// 0.8 at the lines where the table is 0.05 (RGB mode's 0.62, twice the 0.33 of the table). RGB mode agrees
/// within 0.3 %; before, the reduction of a table by the response to the equal-energy white made the
/// diffuse plane 4.7 % too bright in red (0.6536) and copper 2.1 % too dark in red (1.705).
#[test]
fn tables_in_a_bsdf_render_as_in_mitsuba() {
    #[rustfmt::skip]
    let cases: [(String, [f64; 3], [f64; 3]); 3] = [
        (format!(r#"<bsdf type="diffuse"><spectrum name="reflectance" value="{DIPS}"/></bsdf>"#),
            [0.333_594, 0.181_480, 0.141_585], [0.624_127, 0.409_110, 0.294_230]),
        (r#"<bsdf type="conductor"><spectrum name="eta" filename="Cu.eta.spd"/><spectrum name="k" filename="Cu.k.spd"/></bsdf>"#.to_string(),
            [1.581_569, 0.607_434, 0.646_450], [1.742_216, 0.592_489, 0.652_362]),
        (format!(r#"<bsdf type="twosided"><bsdf type="conductor"><string name="material" value="Au"/>
            <spectrum name="specular_reflectance" value="{DIPS}"/></bsdf></bsdf>"#),
            [0.303_865, 0.159_891, 0.040_747], [0.603_162, 0.328_126, 0.095_343]),
    ];
    for (bsdf, spectral_mitsuba, rgb_mitsuba) in cases {
        let spectral = mean_and_se(&render_plane(&bsdf, Mode::Spectral, 16384));
        let rgb = mean_and_se(&render_plane(&bsdf, Mode::Rgb, 1024));
        for c in 0..3 {
            let ((s, s_se), (r, r_se)) = (spectral[c], rgb[c]);
            eprintln!(
                "{bsdf}\n  channel {c}: spectral {s:.5} ± {s_se:.5} (Mitsuba {:.5}), RGB {r:.5} ± {r_se:.5} (Mitsuba {:.5})",
                spectral_mitsuba[c], rgb_mitsuba[c]
            );
            let m = spectral_mitsuba[c];
            assert!((s - m).abs() < 5.0 * s_se + 5e-3 * m, "{bsdf}: spectral channel {c}: {s} ± {s_se}, Mitsuba {m}");
            let m = rgb_mitsuba[c];
            assert!((r - m).abs() < 5.0 * r_se + 3e-3 * m, "{bsdf}: RGB channel {c}: {r} ± {r_se}, Mitsuba {m}");
        }
    }
}

/// The closed form of the diffuse plane: with the sky the same in every direction, a pixel is the sRGB of
/// ∫ ρ(λ) L(λ) (x̄, ȳ, z̄)(λ) dλ, ρ and L the two tables — the table rendered as given.
#[test]
fn a_diffuse_table_under_lines_is_the_product_of_the_spectra() {
    let (rho, light) = (table(DIPS), table(LINES));
    let expected = xyz_to_linear_srgb(xyz_of(|l| rho.eval(l) * light.eval(l)));
    let img = mean_and_se(&render_plane(
        &format!(r#"<bsdf type="diffuse"><spectrum name="reflectance" value="{DIPS}"/></bsdf>"#),
        Mode::Spectral,
        16384,
    ));
    for c in 0..3 {
        let (mean, se) = img[c];
        eprintln!("channel {c}: {mean:.5} ± {se:.5}, closed form {:.5}", expected[c]);
        assert!((mean - expected[c]).abs() < 5.0 * se + 2e-3 * expected[c], "channel {c}: {mean} ± {se}, expected {}", expected[c]);
    }
}

/// A model given a table, as `gonio check --wavelengths` and Python's `wavelengths=` see it: at λ the
/// colour is the table's value (clamped to [0, 1] as a texture's), a conductor's η and k are their tables',
/// a dielectric's index is its table's (RGB mode: at 587.56 nm).
#[test]
fn a_model_at_one_wavelength_reads_its_tables() {
    let props = |xml: &str| Props::from_xml_bsdf(xml, "test.xml").unwrap();
    let at = |p: &Props, nm: f32| {
        let mut b = Bsdf::from_props(p).unwrap();
        reflectances_at(&mut b, [nm; 3], &given_spectra(p));
        b
    };

    let p = props(&format!(r#"<bsdf type="diffuse"><spectrum name="reflectance" value="{DIPS}"/></bsdf>"#));
    for nm in [450.0, 500.0, 525.0, 610.0] {
        let Bsdf::Diffuse(d) = at(&p, nm) else { panic!("a diffuse") };
        assert!((f64::from(d.reflectance.g()) - table(DIPS).eval(f64::from(nm))).abs() < 1e-6, "{nm} nm: {:?}", d.reflectance);
    }

    let dir = ior_dir().display().to_string();
    let p = props(&format!(
        r#"<bsdf type="conductor"><spectrum name="eta" filename="{dir}/Cu.eta.spd"/><spectrum name="k" filename="{dir}/Cu.k.spd"/></bsdf>"#
    ));
    let named = props(r#"<bsdf type="conductor"><string name="material" value="Cu"/></bsdf>"#);
    for nm in [400.0, 550.0, 700.0] {
        // The same data as the named metal's: the same index at every wavelength.
        let (Bsdf::Conductor(a), Bsdf::Conductor(b)) = (at(&p, nm), at(&named, nm)) else { panic!("conductors") };
        assert_eq!(a.eta_k, b.eta_k, "{nm} nm");
    }

    let p = props(
        r#"<bsdf type="dielectric"><spectrum name="int_ior" value="400:1.60, 500:1.55, 700:1.50"/><float name="ext_ior" value="1"/></bsdf>"#,
    );
    let eta = |b: &mut Bsdf| *b.dispersion_mut().expect("dispersive").1;
    let mut rgb = Bsdf::from_props(&p).unwrap();
    assert!(rgb.is_dispersive());
    let n_d = 1.55 - 0.05 * (587.56 - 500.0) / 200.0;
    assert!((f64::from(eta(&mut rgb)) - n_d).abs() < 1e-6, "RGB mode at n_d: {}", eta(&mut rgb));
    assert!((eta(&mut at(&p, 450.0)) - 1.575).abs() < 1e-6);
    assert!((eta(&mut at(&p, 300.0)) - 1.60).abs() < 1e-6, "its end value outside the table");
    // A flat table is a constant index: no dispersion.
    let flat = props(r#"<bsdf type="dielectric"><spectrum name="int_ior" value="400:1.6, 700:1.6"/></bsdf>"#);
    assert!(!Bsdf::from_props(&flat).unwrap().is_dispersive());
    // An index out of range at some wavelength is refused, naming it.
    let e = Bsdf::from_props(&props(r#"<bsdf type="dielectric"><spectrum name="int_ior" value="400:1.5, 700:40"/></bsdf>"#))
        .unwrap_err()
        .to_string();
    assert!(e.contains("int_ior / ext_ior at") && e.contains("must lie in"), "{e}");
}

/// What a table cannot be, refused naming the parameter; and a valid reflectance whose colour leaves the
/// sRGB gamut, which Mitsuba clamps, clamped.
#[test]
fn tables_are_checked() {
    let load = |xml: &str| Props::from_xml_bsdf(xml, "test.xml").and_then(|p| Bsdf::from_props(&p));
    let e = load(r#"<bsdf type="plastic"><spectrum name="int_ior" value="400:1.6, 700:1.5"/></bsdf>"#).unwrap_err().to_string();
    assert!(e.contains("int_ior") && e.contains("varies with wavelength"), "{e}");
    // A flat table is a number.
    load(r#"<bsdf type="plastic"><spectrum name="int_ior" value="400:1.6, 700:1.6"/></bsdf>"#).unwrap();
    let e = load(r#"<bsdf type="conductor"><spectrum name="eta" value="400:-1, 700:1"/><float name="k" value="1"/></bsdf>"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("`eta`") && e.contains("< 0"), "{e}");
    let e = load(r#"<bsdf type="conductor"><spectrum name="eta" value="400:1, 500:0, 700:1"/><spectrum name="k" value="400:1, 500:0, 700:1"/></bsdf>"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("eta + k > 0") && e.contains("500 nm"), "{e}");
    let e = load(r#"<bsdf type="diffuse"><spectrum name="reflectance" value="400:2, 700:2"/></bsdf>"#).unwrap_err().to_string();
    assert!(e.contains("reflectance") && e.contains("[0, 1]"), "{e}");
    // Green beyond sRGB's primaries: (1.09, 0.91, −0.11) before clamping; Mitsuba 3.9.1 gives (1, 0.9008, 0).
    let Bsdf::Diffuse(d) =
        load(r#"<bsdf type="diffuse"><spectrum name="reflectance" value="360:0, 500:0, 520:1, 830:1"/></bsdf>"#).unwrap()
    else {
        panic!("a diffuse")
    };
    assert!(d.reflectance.r() == 1.0 && (d.reflectance.g() - 0.9008).abs() < 1e-3 && d.reflectance.b() == 0.0, "{:?}", d.reflectance);
}

/// A measured RGL file in its spectral form (`spectra` at `wavelengths`): Mitsuba 3's spectral variants
/// read it, its RGB variants refuse it (and spectral variants refuse RGB files). The file is made here
/// from `cc_ibiza_sunset_rgb`: each cell's spectrum at 360, 370, …, 830 nm is the RGB file's r at λ ≥ 580
/// nm, g at 500–570 nm, b at λ ≤ 490 nm and 0 between, copied exactly, so that the file Mitsuba rendered
/// (written by a script with the same rule) and this one are the same bytes of data. Mitsuba
/// 3.9.1 `scalar_spectral`, 2²⁰ spp on 4 × 4 pixels (2026-12-07), under the sky of three lines: (0.461258,
/// 0.096889, 0.219852), and under a white sky (`<rgb value="1, 1, 1">`, D65 in a spectral variant):
/// (0.291797, 0.121250, 0.177636). Spectral mode renders both; RGB mode, which reduces each cell's
/// spectrum under D65, renders the white sky alike (one bounce, so the reduction is exact there).
#[test]
fn a_spectral_measured_file_renders_as_in_mitsuba() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/rgl");
    let file =
        TensorFile::open(&data.join("cc_ibiza_sunset_rgb.bsdf")).unwrap_or_else(|e| panic!("the shared RGL data must be present: {e}"));
    let rgb = file.f32_field("rgb", 5).unwrap();
    let shape = &rgb.shape;
    let cells = shape[3] * shape[4];
    let lambda: Vec<f32> = (0..48).map(|k| 360.0 + 10.0 * k as f32).collect();
    let mut spectra = Vec::with_capacity(shape[0] * shape[1] * lambda.len() * cells);
    for slice in 0..shape[0] * shape[1] {
        let channel = |c: usize| &rgb.data[(slice * 3 + c) * cells..(slice * 3 + c + 1) * cells];
        for &l in &lambda {
            let c = if l >= 580.0 {
                Some(0)
            } else if (500.0..=570.0).contains(&l) {
                Some(1)
            } else if l <= 490.0 {
                Some(2)
            } else {
                None
            };
            spectra.extend(c.map_or_else(|| vec![0.0; cells], |c| channel(c).to_vec()));
        }
    }
    let spectra_shape = [shape[0], shape[1], lambda.len(), shape[3], shape[4]];
    let (lambda_bytes, spectra_bytes) = (f32_bytes(&lambda), f32_bytes(&spectra));
    let mut fields: Vec<(&str, DType, &[usize], &[u8])> = file
        .fields()
        .iter()
        .filter(|f| f.name != "rgb")
        .map(|f| (f.name.as_str(), f.dtype, f.shape.as_slice(), file.field_bytes(&f.name).unwrap()))
        .collect();
    let lambda_shape = [lambda.len()];
    fields.push(("wavelengths", DType::F32, &lambda_shape, &lambda_bytes));
    fields.push(("spectra", DType::F32, &spectra_shape, &spectra_bytes));
    let path = std::env::temp_dir().join(format!("gonio-spectral-tables-{}-ibiza_spectral.bsdf", std::process::id()));
    std::fs::write(&path, encode(&fields)).unwrap();

    let bsdf = format!(r#"<bsdf type="measured"><string name="filename" value="{}"/></bsdf>"#, path.display());
    let white = r#"<emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>"#;
    let renders = [
        ("spectral, lines", render_plane(&bsdf, Mode::Spectral, 16384), [0.461_258, 0.096_889, 0.219_852]),
        ("spectral, white", render_plane_under(white, &bsdf, Mode::Spectral, 16384), [0.291_797, 0.121_250, 0.177_636]),
        ("RGB, white", render_plane_under(white, &bsdf, Mode::Rgb, 1024), [0.291_797, 0.121_250, 0.177_636]),
    ];
    let _ = std::fs::remove_file(&path);
    for (what, img, mitsuba) in renders {
        let img = mean_and_se(&img);
        for c in 0..3 {
            let ((mean, se), m) = (img[c], mitsuba[c]);
            eprintln!("{what}: channel {c}: {mean:.5} ± {se:.5}, Mitsuba {m:.5}");
            assert!((mean - m).abs() < 5.0 * se + 5e-3 * m, "{what}: channel {c}: {mean} ± {se}, Mitsuba {m}");
        }
    }

    // The RGB file in spectral mode is refused, naming the plugin and what it lacks.
    let rgb_bsdf =
        format!(r#"<bsdf type="measured"><string name="filename" value="{}"/></bsdf>"#, data.join("cc_ibiza_sunset_rgb.bsdf").display());
    let xml = format!(r#"<scene version="3.0.0"><shape type="rectangle">{rgb_bsdf}</shape></scene>"#);
    let e = Scene::build_in(mitsuba_xml::load_str(&xml, "rgb.xml", &ior_dir(), &[]).unwrap(), Mode::Spectral).unwrap_err().to_string();
    assert!(e.contains("rgb.xml") && e.contains("`measured`") && e.contains("RGB data only"), "{e}");
}
