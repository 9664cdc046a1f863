//! The variance guard (issue 28): a small subset of the variance suite (`bench/variance.py`, in `make bench`)
//! as a statistical test. Each scene of `tests/data/variance/` (a 4 × 4 grid of spheres, one BSDF model each,
//! under one kind of lighting) is rendered at Mitsuba's sample count with four seeds, and
//!
//! - in the scenes of [`MSE_BOUNDS`] (several lights of very different power: where gonio's light choice
//!   differs from Mitsuba's uniform one), its image error against Mitsuba's 16384-spp reference, the median
//!   over the four renders of each one's MSE, must not exceed the bound × Mitsuba 3's at equal samples (the
//!   median over 16 renders, in `mitsuba.json`; how the data were made is written there and in
//!   `bench/variance.py --write-test-data`), and no render may have more fireflies (pixels brighter than 20×
//!   the reference) than Mitsuba's renders have at most. The median: one render's MSE is heavy-tailed (a
//!   firefly can double it; Mitsuba's own 16 renders of the mixed-light scene spread over 0.04–0.14), the
//!   median of four is steady. In the single-light scenes gonio's estimator is Mitsuba's and the ratio at
//!   this budget scatters by ±30 % around 1 (a light's silhouette pixels and caustics dominate the error;
//!   measured over 12 seeds: 1.10 for `sphere`), too much for a bound to test anything but noise: the suite
//!   measures them (`make bench`), this test holds them to the reference's mean;
//! - each sphere's mean (over the four renders) must agree with the reference's: z = mean(img − ref) /
//!   √(mean((img − ref)²)/n) over the sphere's n pixels (the pixels' errors are independent, each of variance about its squared error) within
//!   [`Z_LIMIT`] (Šidák-corrected 10⁻³ over the 3 scenes × 16 spheres × 3 channels tested).

use gonio::image::read_image;
use gonio::render::render;
use gonio::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Per scene, the most gonio's image MSE may be of Mitsuba's at equal spp (medians over renders, see the module
/// docs). `several`: uniform light selection (Mitsuba's, and gonio's before issue 28) gave 0.78 (the median of
/// four renders; 1.0 in expectation), selection by estimated irradiance 0.47 (0.34–0.53 per render).
const MSE_BOUNDS: &[(&str, f64)] = &[("several", 0.6)];

/// The median of `v` (the mean of the middle two for an even count).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    0.5 * (v[(n - 1) / 2] + v[n / 2])
}

/// The |z| limit of a sphere's mean: the two-sided normal quantile at Šidák's (1 − 10⁻³)^(1/144), 4.495.
const Z_LIMIT: f64 = 4.5;

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/variance")
}

/// The pixels (row-major) inside sphere k of the grid, as `bench/variance.py`'s `masks`: a 4 × 4 grid of unit
/// spheres 2.5 apart, an orthographic film over [−5, 5]², left edge at −x, top at +y.
fn sphere_pixels(size: usize, k: usize) -> Vec<usize> {
    let (cx, cy) = ((k % 4) as f64 * 2.5 - 3.75, 3.75 - (k / 4) as f64 * 2.5);
    (0..size * size)
        .filter(|i| {
            let x = ((i % size) as f64 + 0.5) / size as f64 * 10.0 - 5.0;
            let y = 5.0 - ((i / size) as f64 + 0.5) / size as f64 * 10.0;
            (x - cx).powi(2) + (y - cy).powi(2) < 1.0
        })
        .collect()
}

#[test]
fn gonio_error_is_at_most_mitsubas_and_unbiased() {
    let meta: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(data().join("mitsuba.json")).unwrap()).unwrap();
    let spp = meta["spp"].as_u64().unwrap() as u32;
    let factor = meta["firefly_factor"].as_f64().unwrap();
    let bsdfs: Vec<&str> = meta["bsdfs"].as_array().unwrap().iter().map(|b| b.as_str().unwrap()).collect();
    let mut failures = Vec::new();
    for (name, m) in meta["scenes"].as_object().unwrap() {
        let path = data().join(format!("{name}.xml"));
        let scene = match Scene::load(&path, &[]) {
            Ok(s) => s,
            Err(e) if std::env::var_os("GONIO_SKIP_MISSING_DATA").is_some() => {
                eprintln!("{name}: skipped ({e})");
                continue;
            }
            Err(e) => panic!("{name}: {e} (set GONIO_SKIP_MISSING_DATA to skip scenes whose data is missing)"),
        };
        let reference = read_image(&data().join(format!("{name}-ref.exr"))).unwrap();
        let size = reference.width;
        let ref_px: Vec<[f64; 3]> = (0..size * size).map(|i| reference.get(i % size, i / size).0.map(f64::from)).collect();
        let (mut mses, mut fireflies_max) = (Vec::new(), 0usize);
        let mut sums = vec![[0.0f64; 3]; size * size];
        let seeds = [1u64, 2, 3, 4];
        for seed in seeds {
            let out = render(&scene, spp, seed, &AtomicBool::new(false), &|_| {});
            let px = |i: usize| [0, 1, 2].map(|c| f64::from(out.data[3 * i + c]));
            let (mut ff, mut mse) = (0, 0.0f64);
            for (i, r) in ref_px.iter().enumerate() {
                let p = px(i);
                mse += (0..3).map(|c| (p[c] - r[c]).powi(2)).sum::<f64>() / 3.0;
                let (lum, ref_lum) = (p.iter().sum::<f64>() / 3.0, r.iter().sum::<f64>() / 3.0);
                ff += usize::from(lum > factor * ref_lum.max(1e-3));
                for (s, v) in sums[i].iter_mut().zip(p) {
                    *s += v;
                }
            }
            fireflies_max = fireflies_max.max(ff);
            mses.push(mse / (size * size) as f64);
        }
        let mse = median(mses);
        let mitsuba = median(m["mse_image_per_seed"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect());
        let mitsuba_ff = m["fireflies_per_seed"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).max().unwrap();
        eprintln!(
            "{name}: median MSE {mse:.4e}, Mitsuba's {mitsuba:.4e} (ratio {:.3}); fireflies {fireflies_max} (Mitsuba ≤ {mitsuba_ff})",
            mse / mitsuba
        );
        let bound = MSE_BOUNDS.iter().find(|(n, _)| n == name).map(|(_, b)| *b);
        if let Some(b) = bound.filter(|b| mse > b * mitsuba) {
            failures.push(format!("{name}: MSE {mse:.4e} is {:.2}× Mitsuba's {mitsuba:.4e} (at most {b}×)", mse / mitsuba));
        }
        if bound.is_some() && fireflies_max > mitsuba_ff {
            failures.push(format!("{name}: {fireflies_max} fireflies in a render, Mitsuba's renders have at most {mitsuba_ff}"));
        }
        // The spheres' means, on the two renders' average.
        for (k, bsdf) in bsdfs.iter().enumerate() {
            let pixels = sphere_pixels(size, k);
            for c in 0..3 {
                let errs: Vec<f64> = pixels.iter().map(|&i| sums[i][c] / seeds.len() as f64 - ref_px[i][c]).collect();
                let n = errs.len() as f64;
                let mean = errs.iter().sum::<f64>() / n;
                let sigma = (errs.iter().map(|e| e * e).sum::<f64>() / n / n).sqrt();
                if sigma > 0.0 && (mean / sigma).abs() > Z_LIMIT {
                    failures.push(format!(
                        "{name}, sphere {k} ({bsdf}), channel {c}: mean off the reference by {mean:.3e} (z = {:.1})",
                        mean / sigma
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
