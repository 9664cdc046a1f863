//! Light sampling for low variance (issue 28).
//!
//! - Next-event estimation chooses a light by its estimated irradiance at the shading point, mixed with the
//!   uniform choice (Mitsuba's); the render-level guard of it is `variance.rs`.

use gonio::math::Vec3;
use gonio::sampling::Pcg32;
use gonio::spectrum::Rgb;

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
        let (i, p, _) = selection.sample(&lights, x, rng.next_f32());
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
