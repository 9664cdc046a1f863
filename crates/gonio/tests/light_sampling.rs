//! Light sampling for low variance (issue 28): each test here failed before its fix.
//!
//! - The environment map draws the point inside a cell by the bilinear interpolant of the corner texels'
//!   luminance (as Mitsuba's `Hierarchical2D` warp does), so that luminance over density is the same across a
//!   cell; uniform points in a cell with one bright corner spread it over a factor of up to 4.
//! - The bilinear warp that does it is a triplet (sample, pdf, invert) held together here.
//! - Next-event estimation chooses a light by its estimated irradiance at the shading point, mixed with the
//!   uniform choice (Mitsuba's); the render-level guard of it is `variance.rs`.

use gonio::image::Image;
use gonio::light::EnvMap;
use gonio::math::{Transform, Vec2, Vec3};
use gonio::sampling::warp::{bilinear_pdf, invert_bilinear_sample, linear_pdf, sample_bilinear, sample_linear};
use gonio::sampling::Pcg32;
use gonio::spectrum::Rgb;

#[test]
fn bilinear_warp_round_trips_and_its_density_integrates_to_one() {
    let corners = [[1.0f32, 0.0, 0.0, 0.0], [0.2, 5.0, 1.0, 0.0], [3.0, 3.0, 3.0, 3.0], [0.0, 0.0, 2.0, 7.0]];
    let mut rng = Pcg32::new(3, 9);
    for w in corners {
        for _ in 0..2000 {
            let u = rng.next_vec2();
            let p = sample_bilinear(u, w);
            assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y), "{w:?}: {u} → {p}");
            let back = invert_bilinear_sample(p, w);
            assert!((back - u).abs().max_element() < 2e-4, "{w:?}: {u} → {p} → {back}");
        }
        // Midpoint rule over a fine grid: the density integrates to 1.
        let n = 400;
        let total: f64 = (0..n * n)
            .map(|i| f64::from(bilinear_pdf(Vec2::new(((i % n) as f32 + 0.5) / n as f32, ((i / n) as f32 + 0.5) / n as f32), w)))
            .sum::<f64>()
            / (n * n) as f64;
        assert!((total - 1.0).abs() < 1e-4, "{w:?}: ∫ pdf = {total}");
    }
    // The 1-D linear warp: its density by a histogram of samples.
    let (a, b) = (0.3f32, 2.0f32);
    let mut counts = [0u32; 10];
    let m = 200_000;
    for _ in 0..m {
        counts[((sample_linear(rng.next_f32(), a, b) * 10.0) as usize).min(9)] += 1;
    }
    for (k, c) in counts.iter().enumerate() {
        let expect = linear_pdf((k as f32 + 0.5) / 10.0, a, b) / 10.0;
        assert!((*c as f32 / m as f32 - expect).abs() < 4e-3, "bin {k}: {} vs {expect}", *c as f32 / m as f32);
    }
}

/// A 16 × 9 map, dark except one bright texel (a sun): the cells around it have one bright corner.
fn sun_map() -> EnvMap {
    let mut img = Image::new(16, 9);
    for y in 0..9 {
        for x in 0..16 {
            img.set(x, y, Rgb::splat(0.05));
        }
    }
    img.set(6, 4, Rgb::new(400.0, 380.0, 300.0));
    EnvMap::new(&img, 1.0, Transform::IDENTITY, "test").unwrap()
}

#[test]
fn envmap_luminance_over_density_is_flat_inside_a_cell() {
    let env = sun_map();
    let mut rng = Pcg32::new(17, 2);
    let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
    let mut near_sun = 0;
    for _ in 0..200_000 {
        let Some(s) = env.sample_li(Vec3::ZERO, Vec3::ZERO, rng.next_f32(), rng.next_vec2()) else { continue };
        // θ of the sample: the cells around the sun texel (row 4 of 9, on the equator) span θ ∈ [3π/8, 5π/8].
        let sin_theta = (s.wi.x * s.wi.x + s.wi.z * s.wi.z).sqrt();
        if s.li.luminance() < 1.0 {
            continue;
        }
        near_sun += 1;
        // L / pdf_solid = L · 2π² sin θ / pdf_uv: constant over a cell where pdf_uv ∝ L (up to sin θ, which
        // varies by at most cos(π/8)⁻¹ = 1.08 across these cells; divided out here).
        let ratio = s.li.luminance() / (s.pdf * sin_theta);
        lo = lo.min(ratio);
        hi = hi.max(ratio);
    }
    assert!(near_sun > 1000, "{near_sun} samples near the sun");
    // Uniform points in the cells spread the ratio over a factor of up to 4 (seen: 1.3e4 for this map).
    assert!(hi / lo < 1.01, "luminance / density from {lo} to {hi} near the sun");
}

/// The light choice follows the lights' estimated irradiance, keeps a uniform share for every light, and
/// `sample` chooses with the probabilities `pmf` gives (which sum to 1).
#[test]
fn light_selection_follows_importance_and_agrees_with_its_pmf() {
    use gonio::light::{selection::UNIFORM_SHARE, ConstantLight, Light, LightSelection, PointLight};
    let lights = vec![
        Light::Point(PointLight { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(100.0) }),
        Light::Constant(ConstantLight { radiance: Rgb::splat(0.01) }),
        Light::Point(PointLight { position: Vec3::new(0.0, 20.0, 0.0), intensity: Rgb::splat(1.0) }),
    ];
    let selection = LightSelection::new(&lights, &[]);
    let x = Vec3::ZERO;
    let pmf: Vec<f32> = (0..3).map(|i| selection.pmf(&lights, x, i)).collect();
    assert!((pmf.iter().sum::<f32>() - 1.0).abs() < 1e-6, "{pmf:?}");
    // Importances 100/4 = 25, 0.01π, 1/400: the near point light takes nearly all of the non-uniform share.
    assert!(pmf[0] > 0.85 && pmf.iter().all(|p| *p >= UNIFORM_SHARE / 3.0 - 1e-6), "{pmf:?}");
    let mut rng = Pcg32::new(5, 5);
    let mut counts = [0u32; 3];
    let n = 300_000;
    for _ in 0..n {
        let (i, p) = selection.sample(&lights, x, rng.next_f32());
        assert_eq!(p, pmf[i]);
        counts[i] += 1;
    }
    for (c, p) in counts.iter().zip(&pmf) {
        assert!((*c as f32 / n as f32 - p).abs() < 3e-3, "{counts:?} vs {pmf:?}");
    }
    // One light, or more than MAX_LIGHTS: uniform (Mitsuba's choice).
    let one = LightSelection::new(&lights[..1], &[]);
    assert!(one.is_uniform() && one.pmf(&lights[..1], x, 0) == 1.0);
}
