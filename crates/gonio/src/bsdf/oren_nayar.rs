//! `oren_nayar` — rough diffuse reflection with retro-reflection: a surface of V-shaped Lambertian
//! facets whose slope angles are Gaussian with standard deviation σ (Oren & Nayar 1994, "Generalization of
//! Lambert's Reflectance Model", SIGGRAPH, §4). With α = max(θi, θo), β = min(θi, θo), Δφ = φi − φo:
//!
//! - qualitative model (eq. 30): f = ρ/π [A + B max(0, cos Δφ) sin α tan β],
//!   A = 1 − 0.5 σ²/(σ² + 0.33), B = 0.45 σ²/(σ² + 0.09);
//! - full model (eqs. 24–29, `full = true`): f = ρ/π [C₁ + cos Δφ C₂ tan β + (1 − |cos Δφ|) C₃ tan((α+β)/2)] +
//!   0.17 ρ²/π σ²/(σ² + 0.13) [1 − cos Δφ (2β/π)²], with C₁ = A, C₂ = B sin α when cos Δφ ≥ 0 and
//!   B (sin α − (2β/π)³) otherwise, C₃ = 0.125 σ²/(σ² + 0.09) (4αβ/π²)²; the last term is the light
//!   inter-reflected between facets (eq. 29).
//!
//! | parameter     | type           | default | meaning                                                        |
//! |---------------|----------------|---------|----------------------------------------------------------------|
//! | `reflectance` | rgb [0,1]      | 0.5     | ρ, the albedo of the facets                                    |
//! | `sigma`       | float [0, 90]  | 20      | σ in **degrees** (as pbrt): standard deviation of the facet slope angle |
//! | `full`        | bool           | false   | the full model with C₁–C₃ and inter-reflection instead of eq. 30 |
//!
//! σ = 0 is exactly Lambert (A = C₁ = 1, every other term 0). One-sided like `diffuse`; sampled by
//! Malley's method (cosine-weighted hemisphere). Both models are reciprocal (every term is symmetric in
//! θi, θo and Δφ).
//!
//! # Energy, and two guards
//! The qualitative model conserves energy for ρ ≤ 1: by quadrature its albedo at ρ = 1 is 0.87 (σ = 20°,
//! normal incidence) rising to 0.99 at grazing view, and lower for rougher surfaces. The full model does
//! not: its inter-reflection term is an approximation, and at ρ = 1, σ = 20° the albedo reaches 1.04 at
//! grazing view (the example in its `VIOLATIONS`, see [`crate::bsdf::Examples`]). Its direct term also goes *negative* for
//! rough surfaces (σ ≳ 45°) when both directions are near grazing with opposite azimuths (C₂'s
//! −(2β/π)³ correction is smaller than the growth of tan β); f is clamped at 0 there. Both tan β and
//! tan((α+β)/2) diverge as both directions reach the horizon (f·cos θi stays bounded); their cosines are
//! clamped at 10⁻⁶.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let rough = Bsdf::from_json(r#"{"type": "oren_nayar", "reflectance": 0.8, "sigma": 30}"#).unwrap();
//! // Retro-reflection: at grazing view the surface is brighter back towards the light than at the mirror.
//! let wo = Vec3::new(0.94, 0.0, 0.342);
//! assert!(rough.f(wo, wo).r() > rough.f(wo, Vec3::new(-0.94, 0.0, 0.342)).r());
//! ```

use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::Result;
use crate::math::{frame, Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::Rgb;
use std::f32::consts::{FRAC_1_PI, FRAC_2_PI};

/// Oren–Nayar rough diffuse reflection.
#[derive(Clone, Debug, PartialEq)]
pub struct OrenNayar {
    pub reflectance: Rgb,
    /// σ in radians.
    pub sigma: f32,
    /// The full model (eqs. 24–29) instead of the qualitative one (eq. 30).
    pub full: bool,
}

/// Cosines below this are clamped where a tangent divides by them (2026-11: tan β and tan((α+β)/2)
/// diverge as both directions reach the horizon; f·cos θi stays bounded, f must stay finite).
const MIN_COS: f32 = 1e-6;

/// The angles of a pair of directions that the model depends on.
struct Geometry {
    /// α = max(θi, θo), β = min(θi, θo), in radians.
    alpha: f32,
    beta: f32,
    sin_alpha: f32,
    /// tan β, with its cosine clamped at [`MIN_COS`].
    tan_beta: f32,
    /// cos(φi − φo); 0 when either direction is on the pole (then β = 0 and every term using it vanishes).
    cos_dphi: f32,
}

impl Geometry {
    fn new(wo: Vec3, wi: Vec3) -> Self {
        let (cos_o, cos_i) = (wo.z.clamp(0.0, 1.0), wi.z.clamp(0.0, 1.0));
        let (sin_o, sin_i) = (frame::sin_theta(wo), frame::sin_theta(wi));
        let sin_product = sin_o * sin_i;
        let cos_dphi = if sin_product > 0.0 { ((wo.x * wi.x + wo.y * wi.y) / sin_product).clamp(-1.0, 1.0) } else { 0.0 };
        // α is the angle of the direction nearer the horizon (the smaller cosine).
        let ((cos_a, sin_a), (cos_b, sin_b)) =
            if cos_o < cos_i { ((cos_o, sin_o), (cos_i, sin_i)) } else { ((cos_i, sin_i), (cos_o, sin_o)) };
        Geometry { alpha: cos_a.acos(), beta: cos_b.acos(), sin_alpha: sin_a, tan_beta: sin_b / cos_b.max(MIN_COS), cos_dphi }
    }
}

impl OrenNayar {
    /// The model with albedo `reflectance` and slope-angle deviation `sigma` in radians.
    #[must_use]
    pub fn new(reflectance: Rgb, sigma: f32, full: bool) -> Self {
        debug_assert!((0.0..=std::f32::consts::FRAC_PI_2).contains(&sigma), "σ must be in [0, π/2] rad, got {sigma}");
        OrenNayar { reflectance, sigma, full }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let reflectance = p.reflectance("reflectance", Rgb::splat(0.5))?;
        let sigma = p.float_in("sigma", 20.0, 0.0, 90.0)?.to_radians();
        Ok(OrenNayar::new(reflectance, sigma, p.bool("full", false)?))
    }

    /// The qualitative model's bracket A + B max(0, cos Δφ) sin α tan β (eq. 30).
    fn qualitative(&self, g: &Geometry) -> f32 {
        let s2 = self.sigma * self.sigma;
        let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
        let b = 0.45 * s2 / (s2 + 0.09);
        a + b * g.cos_dphi.max(0.0) * g.sin_alpha * g.tan_beta
    }

    /// The full model for one channel of ρ: direct term (eqs. 24–28) plus inter-reflection (eq. 29).
    fn full_model(&self, g: &Geometry, rho: f32) -> f32 {
        let s2 = self.sigma * self.sigma;
        let c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
        let b = 0.45 * s2 / (s2 + 0.09);
        let two_beta_over_pi = FRAC_2_PI * g.beta;
        let c2 = if g.cos_dphi >= 0.0 { b * g.sin_alpha } else { b * (g.sin_alpha - two_beta_over_pi.powi(3)) };
        let c3 = 0.125 * s2 / (s2 + 0.09) * (4.0 * FRAC_1_PI * FRAC_1_PI * g.alpha * g.beta).powi(2);
        let half = 0.5 * (g.alpha + g.beta);
        let tan_half = half.sin() / half.cos().max(MIN_COS);
        let direct = c1 + g.cos_dphi * c2 * g.tan_beta + (1.0 - g.cos_dphi.abs()) * c3 * tan_half;
        let inter = 0.17 * rho * s2 / (s2 + 0.13) * (1.0 - g.cos_dphi * two_beta_over_pi * two_beta_over_pi);
        // The direct term's approximation goes negative for rough, grazing, opposite-azimuth pairs
        // (2026-11: measured −0.27 at σ = 89°); a BRDF cannot, so clamp the sum at 0.
        (rho * FRAC_1_PI * (direct + inter)).max(0.0)
    }
}

impl crate::bsdf::Examples for OrenNayar {
    /// Specs that `gonio check --all` must pass.
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "oren_nayar"}"#,
        r#"{"type": "oren_nayar", "reflectance": 1.0, "sigma": 0}"#,
        r#"{"type": "oren_nayar", "reflectance": [1.0, 0.5, 0.1], "sigma": 90}"#,
        r#"{"type": "oren_nayar", "reflectance": 0.8, "sigma": 30, "full": true}"#,
        r#"{"type": "oren_nayar", "reflectance": 0.05, "sigma": 80, "full": true}"#,
    ];

    /// Specs that break physics, with the check row that must catch them: the full model's
    /// inter-reflection approximation gains energy at grazing view for ρ = 1.
    const VIOLATIONS: &'static [(&'static str, &'static str)] =
        &[(r#"{"type": "oren_nayar", "reflectance": 1.0, "sigma": 20, "full": true}"#, "albedo max")];
}

impl BsdfModel for OrenNayar {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let g = Geometry::new(wo, wi);
        if self.full {
            self.reflectance.map(|rho| self.full_model(&g, rho))
        } else {
            self.reflectance * (FRAC_1_PI * self.qualitative(&g))
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        BsdfSample::smooth(wi, self.f(wo, wi), cosine_hemisphere_pdf(wi), BsdfFlags::DIFFUSE_REFLECTION, 1.0)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }
}

#[cfg(test)]
mod tests {
    use super::super::glossy_mix::testing::hemisphere_integral;
    use super::*;
    use crate::bsdf::Diffuse;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::sampling::warp::sample_uniform_hemisphere;
    use crate::verify::energy::direction;
    use crate::verify::reciprocity::reciprocity;

    #[test]
    fn sigma_zero_is_lambert() {
        let rho = Rgb::new(0.2, 0.5, 0.9);
        let lambert = Diffuse::new(rho);
        for full in [false, true] {
            let on = OrenNayar::new(rho, 0.0, full);
            for k in 0..1000 {
                let u = |a: u32| Vec2::new(((k * 37 + a) % 1000) as f32 / 1000.0, ((k * 91 + 3 * a) % 997) as f32 / 997.0);
                let (wo, wi) = (sample_uniform_hemisphere(u(1)), sample_uniform_hemisphere(u(2)));
                assert_eq!(on.f(wo, wi), lambert.f(wo, wi), "full={full} wo={wo} wi={wi}");
            }
        }
    }

    #[test]
    fn retro_reflection_at_grazing_view() {
        for full in [false, true] {
            for sigma_deg in [20.0f32, 40.0, 60.0] {
                let on = OrenNayar::new(Rgb::splat(0.8), sigma_deg.to_radians(), full);
                let wo = direction(0.1, 0.0);
                let mirror = Vec3::new(-wo.x, -wo.y, wo.z);
                let (back, forward) = (on.f(wo, wo).r(), on.f(wo, mirror).r());
                assert!(back > 1.5 * forward, "σ={sigma_deg} full={full}: back {back} forward {forward}");
            }
        }
    }

    /// A full moon looks flat: lit and seen from the same direction, the radiance f·cos θ of a sphere
    /// falls off towards the limb much more slowly than Lambert's cos θ.
    #[test]
    fn full_moon_is_flatter_than_lambert() {
        let on = OrenNayar::new(Rgb::splat(0.8), 30f32.to_radians(), false);
        let lambert = Diffuse::new(Rgb::splat(0.8));
        // Radiance towards the viewer at a point whose normal makes angle θ with the view = light direction.
        let radiance = |b: &dyn BsdfModel, cos_theta: f32| {
            let w = direction(cos_theta, 0.7);
            b.f(w, w).r() * cos_theta
        };
        let limb = 80f32.to_radians().cos();
        let ratio_on = radiance(&on, limb) / radiance(&on, 1.0);
        let ratio_lambert = radiance(&lambert, limb) / radiance(&lambert, 1.0);
        println!("limb/centre at 80°: Oren–Nayar σ=30° {ratio_on:.3}, Lambert {ratio_lambert:.3}");
        assert!((ratio_lambert - limb).abs() < 1e-5);
        assert!(ratio_on > 2.0 * ratio_lambert, "{ratio_on} vs {ratio_lambert}");
    }

    #[test]
    fn reciprocal_and_energy_as_documented() {
        for full in [false, true] {
            let on = OrenNayar::new(Rgb::ONE, 20f32.to_radians(), full);
            assert_eq!(reciprocity(&on, 100_000, 9).max_rel_error, 0.0, "full={full}");
        }
        let albedo = |full: bool, mu: f32| {
            let on = OrenNayar::new(Rgb::ONE, 20f32.to_radians(), full);
            let wo = direction(mu, 0.0);
            hemisphere_integral(300, |wi| on.f(wo, wi).r() as f64 * wi.z as f64)
        };
        let (q1, q0, f0) = (albedo(false, 1.0), albedo(false, 0.016), albedo(true, 0.016));
        println!("ρ=1, σ=20°: qualitative albedo {q1:.3} (normal), {q0:.3} (grazing); full {f0:.3} (grazing)");
        assert!((q1 - 0.865).abs() < 5e-3 && q0 < 1.0 && f0 > 1.02, "{q1} {q0} {f0}");
    }

    #[test]
    fn full_model_is_clamped_at_zero() {
        let on = OrenNayar::new(Rgb::splat(0.05), 89f32.to_radians(), true);
        let wo = direction(1e-3, 0.0);
        let wi = direction(1e-3, std::f32::consts::PI);
        let f = on.f(wo, wi);
        assert!(f.min_component() >= 0.0 && f.is_finite(), "{f}");
    }
}
