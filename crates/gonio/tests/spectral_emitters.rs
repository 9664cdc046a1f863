//! Emission given as a spectrum (issue 30): `<spectrum value=…>`, tabulated pairs, `.spd` files and the
//! `d65` and `blackbody` spectrum plugins, in both modes. RGB mode reduces each to linear sRGB as Mitsuba
//! 3's RGB variants do; spectral mode renders the spectrum itself, whose film colour is then the same
//! integral sampled at the paths' wavelengths. Both are checked against Mitsuba 3.9.1.

mod common;

use common::mean_and_se;
use gonio::render::{render, RenderOutput};
use gonio::scene::{mitsuba_xml, Mode, Scene};
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn render_sky(radiance: &str, mode: Mode) -> RenderOutput {
    let xml = format!(
        r#"<scene version="3.0.0"><integrator type="path"/><sensor type="perspective">
        <sampler type="independent"><integer name="sample_count" value="1024"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film></sensor>
        <emitter type="constant">{radiance}</emitter></scene>"#
    );
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/ior");
    let scene = Scene::build_in(mitsuba_xml::load_str(&xml, "test.xml", &dir, &[]).unwrap(), mode).unwrap();
    render(&scene, scene.sampler.sample_count, scene.sampler.seed, &AtomicBool::new(false), &|_| {})
}

/// A constant sky of each spectrum: in RGB mode every pixel is the spectrum's reduction, within 0.3 % of
/// Mitsuba 3.9.1 `scalar_spectral`'s render of the same file (65 536 spp on 4 × 4 pixels, 2026-12-06;
/// its own noise is about 0.1 %); in spectral mode the image's mean is that reduction within 5 standard
/// errors and 0.1 %. Before 2026-12-06 gonio read a uniform `<spectrum value="1"/>` emitter as white
/// (1, 1, 1), where Mitsuba reads the equal-energy spectrum (1.206, 0.949, 0.909), and spectral mode rendered
/// every emission spectrum through its RGB reduction: the gold `.spd` was 1.7 % less red than Mitsuba's.
#[test]
fn emission_spectra_render_as_in_mitsuba() {
    #[rustfmt::skip]
    let cases: [(&str, [f64; 3]); 5] = [
        (r#"<spectrum name="radiance" value="1"/>"#, [1.206_162, 0.949_138, 0.909_191]),
        (r#"<spectrum name="radiance" value="400:1, 700:1"/>"#, [1.201_017, 0.950_405, 0.903_498]),
        (r#"<spectrum name="radiance" type="d65"><float name="scale" value="2"/></spectrum>"#, [2.000_164, 1.999_672, 1.997_576]),
        (r#"<spectrum name="radiance" type="blackbody"><float name="temperature" value="5000"/></spectrum>"#, [15_280.09, 12_092.99, 9_592.133]),
        (r#"<spectrum name="radiance" filename="Au.eta.spd"/>"#, [0.142_965, 0.375_837, 1.441_876]),
    ];
    for (spectrum, mitsuba) in cases {
        let rgb = mean_and_se(&render_sky(spectrum, Mode::Rgb));
        let spectral = mean_and_se(&render_sky(spectrum, Mode::Spectral));
        for c in 0..3 {
            let ((reduced, _), (mean, se)) = (rgb[c], spectral[c]);
            eprintln!("{spectrum}: channel {c}: RGB {reduced:.6}, spectral {mean:.6} ± {se:.6}, Mitsuba {:.6}", mitsuba[c]);
            assert!((reduced / mitsuba[c] - 1.0).abs() < 3e-3, "{spectrum}: RGB mode channel {c}: {reduced}, Mitsuba {}", mitsuba[c]);
            assert!(
                (mean - reduced).abs() < 5.0 * se + 1e-3 * reduced,
                "{spectrum}: spectral channel {c}: {mean} ± {se}, expected {reduced}"
            );
        }
    }
}

/// Malformed spectrum plugins are refused, naming the place and what was expected.
#[test]
fn spectrum_plugins_are_checked() {
    for (spectrum, expect) in [
        (r#"<spectrum name="radiance" type="blackbody"/>"#, "needs a `temperature` (K)"),
        (r#"<spectrum name="radiance" type="blackbody"><float name="temperature" value="-3"/></spectrum>"#, "temperature > 0 K"),
        (
            r#"<spectrum name="radiance" type="d65"><float name="temperature" value="3"/></spectrum>"#,
            "takes <float name=…> once each of: scale",
        ),
        (r#"<spectrum name="radiance" type="srgb"/>"#, "gonio reads the spectrum types d65, blackbody and uniform"),
        (r#"<spectrum name="radiance" type="uniform"><float name="value" value="x"/></spectrum>"#, "expected a number"),
    ] {
        let xml = format!(
            r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/>
            <integer name="height" value="4"/></film></sensor><emitter type="constant">{spectrum}</emitter></scene>"#
        );
        let e = mitsuba_xml::load_str(&xml, "test.xml", Path::new("."), &[])
            .and_then(Scene::build)
            .map(|_| ())
            .expect_err(spectrum)
            .to_string();
        assert!(e.contains(expect) && e.contains("test.xml:"), "{spectrum}: {e}");
    }
    // A blackbody is emission, not a reflectance.
    let xml = r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm"/></sensor><shape type="sphere"><bsdf type="diffuse">
        <spectrum name="reflectance" type="blackbody"><float name="temperature" value="3000"/></spectrum></bsdf></shape></scene>"#;
    let e =
        mitsuba_xml::load_str(xml, "test.xml", Path::new("."), &[]).and_then(Scene::build).map(|_| ()).expect_err("blackbody reflectance");
    assert!(e.to_string().contains("an emitter's spectrum"), "{e}");
}
