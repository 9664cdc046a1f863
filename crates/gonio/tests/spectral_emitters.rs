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
    render_sky_at(radiance, mode, 1024, "")
}

/// [`render_sky`] at `spp` samples per pixel, with the film's `rfilter` (XML; "" for the default).
fn render_sky_at(radiance: &str, mode: Mode, spp: u32, rfilter: &str) -> RenderOutput {
    let xml = format!(
        r#"<scene version="3.0.0"><integrator type="path"/><sensor type="perspective">
        <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>{rfilter}</film></sensor>
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

/// A pixel's wavelengths are spread over the spectrum across its samples (`integrator::wavelength_stratum`),
/// so that a spectral pixel's colour has almost no noise of its own: a sky of one colour, seen directly at
/// 32 spp through a box filter (each pixel its own samples' mean), gives every pixel within 1 % of the
/// colour's maximum of the image's mean. With one independent number per
/// path, as before 2026-12-07, the pixels spread a hundred times as far (the blue channel of the first sky:
/// 0.0004 RMS now, 0.04 before; Mitsuba 3's four wavelengths per path 0.08) and this fails. Through the
/// default Gaussian filter a pixel's value weighs its neighbours' samples unequally and keeps more of the
/// wavelengths' noise (0.03 RMS there; Mitsuba 0.047).
#[test]
fn a_pixels_wavelengths_spread_over_the_spectrum() {
    for rgb in ["0.2, 0.5, 0.8", "0.9, 0.3, 0.05", "1, 1, 1"] {
        let img = render_sky_at(&format!(r#"<rgb name="radiance" value="{rgb}"/>"#), Mode::Spectral, 32, r#"<rfilter type="box"/>"#);
        let mean = mean_and_se(&img).map(|(m, _)| m);
        let scale = mean.iter().copied().fold(0.0, f64::max);
        let worst = img.data.chunks(3).flat_map(|p| (0..3).map(move |c| (f64::from(p[c]) - mean[c]).abs())).fold(0.0, f64::max);
        eprintln!("sky {rgb}: mean {mean:?}, the farthest pixel-channel {worst:.2e} from it");
        assert!(worst < 1e-2 * scale, "sky {rgb}: a pixel-channel {worst} from the mean {mean:?}");
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
