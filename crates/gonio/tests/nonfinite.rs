//! The integrator never writes a NaN or Inf pixel: every scene of `scenes/` and `../shared/scenes/` renders
//! with zero non-finite samples (Mitsuba's nine `bsdf_spheres` scenes are held to the same in
//! `mitsuba_regression.rs`, at 2·10⁶ samples each, where they are loaded anyway), and a scene that does produce them (radiance at the edge of the f32 range, which
//! overflows in the estimator) has them counted and dropped (as black) instead of poisoning the pixel.

use gonio::render::{render, RenderOutput};
use gonio::scene::{mitsuba_xml, Scene};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Every scene file of the repository's `scenes/` and of `../shared/scenes/`.
fn scene_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    for dir in [root.join("scenes"), PathBuf::from("/work/shared/scenes")] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            assert!(
                std::env::var_os("GONIO_SKIP_MISSING_DATA").is_some(),
                "{} is missing (set GONIO_SKIP_MISSING_DATA to skip)",
                dir.display()
            );
            continue;
        };
        let mut xml: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "xml")).collect();
        xml.sort();
        files.extend(xml);
    }
    files
}

/// Render at most 64 pixels wide (the aspect kept: the camera maps the unit square to the film) with `spp`.
fn render_small(scene: &mut Scene, spp: u32) -> RenderOutput {
    let (w, h) = (scene.film.width, scene.film.height);
    if w > 64 {
        scene.film.width = 64;
        scene.film.height = (h * 64 / w).max(1);
    }
    render(scene, spp, 1, &AtomicBool::new(false), &|_| {})
}

#[test]
fn every_scene_renders_without_non_finite_samples() {
    let files = scene_files();
    let mut report = Vec::new();
    for file in &files {
        let mut scene = Scene::load(file, &[]).unwrap_or_else(|e| panic!("{e}"));
        let out = render_small(&mut scene, 4);
        let samples = u64::from(out.width) * u64::from(out.height) * u64::from(out.spp_done);
        report.push(format!("{}: {samples} samples, {} non-finite", file.display(), out.nonfinite));
        assert_eq!(out.nonfinite, 0, "{}", report.last().unwrap());
        assert!(out.data.iter().all(|v| v.is_finite() && *v >= 0.0), "{}: a non-finite or negative pixel", file.display());
    }
    println!("{}", report.join("\n"));
    if std::env::var_os("GONIO_SKIP_MISSING_DATA").is_none() {
        assert!(files.len() >= 3, "expected demo.xml and the two shared scenes, found {files:?}");
    }
}

/// A white diffuse sphere under a constant environment of radiance `l`, seen from outside.
fn sphere_under_sky(l: f32) -> Scene {
    let xml = format!(
        r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="3"/></integrator>
        <sensor type="perspective"><float name="fov" value="30"/>
            <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/></film></sensor>
        <emitter type="constant"><rgb name="radiance" value="{l:e}"/></emitter>
        <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf></shape></scene>"#
    );
    Scene::build(mitsuba_xml::load_str(&xml, "sky.xml", Path::new("."), &[]).unwrap()).unwrap()
}

/// Radiance is linear in the emitter's: at L = 3·10³⁸ (just below f32::MAX) the estimator overflows to Inf
/// on some paths. Those samples are dropped and counted, every pixel stays finite, and what remains is
/// exactly L times the L = 1 image with the dropped samples counted as black.
#[test]
fn overflowing_samples_are_dropped_and_counted() {
    let (big, spp) = (3e38f32, 8);
    let one = render(&sphere_under_sky(1.0), spp, 5, &AtomicBool::new(false), &|_| {});
    let huge = render(&sphere_under_sky(big), spp, 5, &AtomicBool::new(false), &|_| {});
    assert_eq!(one.nonfinite, 0);
    let total = u64::from(huge.width * huge.height * spp);
    assert!(huge.nonfinite > 0 && huge.nonfinite < total, "{} of {total} samples non-finite", huge.nonfinite);
    assert!(huge.data.iter().all(|v| v.is_finite() && *v >= 0.0), "a dropped sample poisoned a pixel");
    // Per pixel: huge/L ≤ one (dropped samples only remove energy); equal where nothing was dropped (the
    // sky seen directly), and below where something was.
    let (mut equal, mut below) = (0, 0);
    for (h, o) in huge.data.iter().zip(&one.data) {
        let scaled = f64::from(*h) / f64::from(big);
        let o = f64::from(*o);
        // 1e-5 relative: f32 rounding of the products along a path at two magnitudes (2026-11).
        assert!(scaled <= o * (1.0 + 1e-5) + 1e-30, "pixel gained energy: {scaled} > {o}");
        if (scaled - o).abs() <= 1e-5 * o {
            equal += 1;
        } else {
            below += 1;
        }
    }
    println!("{} non-finite samples of {total}; channels equal {equal}, lower {below}", huge.nonfinite);
    assert!(equal > 0 && below > 0);
}
