//! `blinn_phong` — Blinn's half-vector lobe: f = k_d/π + k_s·S(ωo, ωi), S = (n·h)ᵉ with
//! h = (ωo + ωi)/|ωo + ωi| (Blinn 1977, "Models of Light Reflection for Computer Synthesized Pictures",
//! SIGGRAPH, eq. for the "Phong" distribution D₁ = (N·H)^c₁).
//!
//! | parameter              | type              | default   | meaning                                          |
//! |------------------------|-------------------|-----------|--------------------------------------------------|
//! | `diffuse_reflectance`  | rgb [0,1]         | 0.5       | k_d, weight of the Lambertian lobe k_d/π         |
//! | `specular_reflectance` | rgb [0,1]         | 0.2       | k_s, weight of the specular lobe                 |
//! | `exponent`             | float [0, 10⁵]    | 30        | e, the Blinn exponent (larger: sharper)          |
//! | `normalization`        | `none` \| `energy` | `energy` | `none`: S = cosᵉθh; `energy`: S = (e+8)/(8π) cosᵉθh |
//!
//! # Where it breaks physics
//! The lobe is reciprocal (h is symmetric in ωo and ωi; measured reciprocity error 0).
//! - **Unnormalised** (`none`): ∫ cosᵉθh cos θi dωi at normal incidence is 2.86 for e = 1 and π for
//!   e = 0: the example `k_d = k_s = 0.5, e = 1` measures a maximal albedo of 1.92 (at cos θo = 0.984, the
//!   harness's angle nearest normal incidence) and a white furnace of 1.76.
//! - **Energy** (`energy`, the default): the factor (e+8)/(8π) of Akenine-Möller, Haines & Hoffman,
//!   *Real-Time Rendering*, 3rd ed. (2008), §7.6, is an approximation of the exact normal-incidence factor
//!   (e+2)(e+4)/(8π(2^(−e/2) + e)) (Giesen 2009, "Derivation of Phong and Blinn-Phong BRDF normalization
//!   factors"). It overshoots: by quadrature the lobe's albedo at normal incidence is 1.024 (e = 1),
//!   1.075 (e = 8, the worst), 1.048 (e = 30), 1.002 (e = 1000); the example `k_s = 1, e = 8` measures
//!   a maximal albedo of 1.051 at cos θo = 0.984 (white furnace 0.67: it is lost at grazing angles, where
//!   the lobe falls below the surface). With k_d + 1.075·k_s ≤ 1 the model conserves energy.
//!
//! Sampling mixes cosine-weighted hemisphere sampling (k_d) with half vectors drawn from D(h) cos θh,
//! D = (e+2)/(2π) cosᵉθh, i.e. the power-cosine warp with exponent e+1, cos θh = u^(1/(e+2)), reflected
//! about h with the Jacobian dωh/dωi = 1/(4 |ωo·h|) (Torrance & Sparrow 1967, "Theory for Off-Specular
//! Reflection from Roughened Surfaces", JOSA 57(9)), in
//! proportion to the luminances of k_d and k_s (see [`glossy_mix`](super::glossy_mix)).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let b = Bsdf::from_json(r#"{"type": "blinn_phong", "diffuse_reflectance": 0, "specular_reflectance": 1,
//!     "exponent": 8, "normalization": "none"}"#).unwrap();
//! // Mirror configuration: h = n and S = 1.
//! let wo = Vec3::new(0.6, 0.0, 0.8);
//! assert!((b.f(wo, Vec3::new(-0.6, 0.0, 0.8)).r() - 1.0).abs() < 1e-5);
//! ```

use super::glossy_mix::{DiffuseGlossy, GlossyLobe, Normalization};
use crate::error::Result;
use crate::fresnel::reflect;
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{power_cosine_hemisphere_pdf, sample_power_cosine_hemisphere};
use crate::spectrum::Rgb;
use std::f32::consts::PI;

/// The Blinn lobe around the normal, in the half vector.
#[derive(Clone, Debug, PartialEq)]
pub struct BlinnPhongLobe {
    /// e ≥ 0.
    pub exponent: f32,
    pub normalization: Normalization,
}

/// Smallest ωo·h in the Jacobian of the reflection map (see [`BlinnPhongLobe::pdf`]).
const MIN_WO_DOT_H: f32 = 1e-7;

/// The half vector of two directions above the surface; `None` when they cancel (to f32 precision).
#[inline]
fn half_vector(wo: Vec3, wi: Vec3) -> Option<Vec3> {
    let sum = wo + wi;
    let len2 = sum.length_squared();
    (len2 > 0.0).then(|| sum / len2.sqrt())
}

impl GlossyLobe for BlinnPhongLobe {
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(h) = half_vector(wo, wi) else { return 0.0 };
        let scale = match self.normalization {
            Normalization::None => 1.0,
            // Real-Time Rendering, 3rd ed., §7.6.
            Normalization::Energy => (self.exponent + 8.0) / (8.0 * PI),
        };
        scale * h.z.clamp(0.0, 1.0).powf(self.exponent)
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        // h ~ D(h) cos θh = (e+2)/(2π) cos^(e+1) θh, then mirror ωo about h.
        let h = sample_power_cosine_hemisphere(u, self.exponent + 1.0);
        Some(reflect(wo, h))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(h) = half_vector(wo, wi) else { return 0.0 };
        let wo_dot_h = wo.dot(h);
        if wo_dot_h <= 0.0 {
            return 0.0;
        }
        // dωh/dωi = 1/(4 ωo·h). The divisor is clamped (2026-11: ωo·h < 10⁻⁷ only when ωo lies within
        // 10⁻⁷ rad of the horizon and h near the normal; without it the density overflows f32 there).
        power_cosine_hemisphere_pdf(h, self.exponent + 1.0) / (4.0 * wo_dot_h.max(MIN_WO_DOT_H))
    }
}

/// The Blinn–Phong model: a Lambertian lobe plus [`BlinnPhongLobe`].
pub type BlinnPhong = DiffuseGlossy<BlinnPhongLobe>;

impl DiffuseGlossy<BlinnPhongLobe> {
    /// The Blinn–Phong model with the given reflectances and lobe.
    #[must_use]
    pub fn blinn_phong(kd: Rgb, ks: Rgb, exponent: f32, normalization: Normalization) -> Self {
        debug_assert!(exponent >= 0.0, "Blinn exponent must be ≥ 0, got {exponent}");
        DiffuseGlossy::new(kd, ks, BlinnPhongLobe { exponent, normalization })
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let kd = p.reflectance("diffuse_reflectance", Rgb::splat(0.5))?;
        let ks = p.reflectance("specular_reflectance", Rgb::splat(0.2))?;
        // The same bound as `phong` (2026-11: lobe width stays far above f32 angular resolution).
        let exponent = p.float_in("exponent", 30.0, 0.0, 1e5)?;
        let normalization = Normalization::from_props(p)?;
        Ok(BlinnPhong::blinn_phong(kd, ks, exponent, normalization))
    }
}

impl crate::bsdf::Examples for DiffuseGlossy<BlinnPhongLobe> {
    /// Specs that `gonio check --all` must pass.
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "blinn_phong"}"#,
        r#"{"type": "blinn_phong", "diffuse_reflectance": 0.0, "specular_reflectance": 0.9, "exponent": 8}"#,
        r#"{"type": "blinn_phong", "diffuse_reflectance": [0.6, 0.3, 0.1], "specular_reflectance": 0.3, "exponent": 80}"#,
        r#"{"type": "blinn_phong", "exponent": 1000}"#,
        r#"{"type": "blinn_phong", "diffuse_reflectance": 0.2, "specular_reflectance": 0.25, "exponent": 1, "normalization": "none"}"#,
    ];

    /// Specs that break physics on purpose, with the check row that must catch them.
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[
        (
            r#"{"type": "blinn_phong", "diffuse_reflectance": 0.5, "specular_reflectance": 0.5, "exponent": 1, "normalization": "none"}"#,
            "albedo max",
        ),
        (r#"{"type": "blinn_phong", "diffuse_reflectance": 0.0, "specular_reflectance": 1.0, "exponent": 8}"#, "albedo max"),
    ];
}

#[cfg(test)]
mod tests {
    use super::super::glossy_mix::testing::hemisphere_integral;
    use super::*;
    use crate::bsdf::BsdfModel;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::verify::reciprocity::reciprocity;

    fn lobe_only(e: f32, normalization: Normalization) -> BlinnPhong {
        BlinnPhong::blinn_phong(Rgb::ZERO, Rgb::ONE, e, normalization)
    }

    fn albedo(b: &BlinnPhong, wo: Vec3) -> f64 {
        hemisphere_integral(400, |wi| b.f(wo, wi).r() as f64 * wi.z as f64)
    }

    #[test]
    fn closed_forms_at_normal_incidence() {
        // e = 0 unnormalised: S = 1 on the hemisphere, ∫ cos θi dω = π.
        let a0 = albedo(&lobe_only(0.0, Normalization::None), Vec3::Z);
        assert!((a0 - std::f64::consts::PI).abs() < 2e-3, "{a0}");
        // e = 0 normalised: S = 1/π, albedo 1 (the factor is exact there).
        let a0n = albedo(&lobe_only(0.0, Normalization::Energy), Vec3::Z);
        assert!((a0n - 1.0).abs() < 2e-3, "{a0n}");
        // The RTR factor overshoots the exact normalisation (Giesen 2009) by at most 7.5 % (e = 8).
        for (e, expect) in [(1.0f32, 1.0243f64), (8.0, 1.0750), (30.0, 1.0478)] {
            let a = albedo(&lobe_only(e, Normalization::Energy), Vec3::Z);
            println!("Blinn-Phong (e+8)/(8π), e = {e}: albedo at normal incidence {a:.4}");
            assert!((a - expect).abs() < 3e-3, "e={e}: {a}");
            let exact = ((e + 2.0) * (e + 4.0) / (8.0 * PI * (2f32.powf(-e / 2.0) + e))) as f64;
            let scale = exact / ((e + 8.0) / (8.0 * PI)) as f64;
            assert!((a * scale - 1.0).abs() < 3e-3, "exact factor, e={e}: {}", a * scale);
        }
        let a1 = albedo(&lobe_only(1.0, Normalization::None), Vec3::Z);
        println!("unnormalised Blinn-Phong, e = 1: albedo at normal incidence {a1:.4}");
        assert!((a1 - 2.8603).abs() < 3e-3, "{a1}");
    }

    #[test]
    fn reciprocal() {
        let r = reciprocity(&lobe_only(20.0, Normalization::Energy), 100_000, 4);
        assert!(r.max_rel_error < 1e-5, "{r:?}");
    }

    #[test]
    fn sampled_half_vectors_follow_the_lobe() {
        let b = lobe_only(200.0, Normalization::Energy);
        let wo = Vec3::new(0.4, -0.3, 0.866).normalize();
        let s = b.sample(wo, 0.5, Vec2::new(0.7, 0.2)).unwrap();
        assert!(half_vector(wo, s.wi).unwrap().z > 0.95);
        // Grazing ωo: many half vectors reflect ωo below the surface, and those give no sample.
        let grazing = Vec3::new(0.999, 0.0, 0.0447).normalize();
        let none = (0..1000).filter(|k| b.sample(grazing, 0.5, Vec2::new((*k as f32 + 0.5) / 1000.0, 0.5)).is_none()).count();
        assert!(none > 0);
    }

    /// A sharp lobe at grazing view is narrower than the default chi-square grid resolves (cos θ cells of
    /// 0.05, 6-point quadrature): with a finer grid the sampled density matches `pdf`.
    #[test]
    fn sharp_grazing_lobe_passes_chi2_on_a_fine_grid() {
        use crate::verify::chi2::{chi2_bsdf, Chi2Config};
        let b = BlinnPhong::blinn_phong(Rgb::new(0.6, 0.3, 0.1), Rgb::splat(0.3), 200.0, Normalization::Energy);
        let wo = crate::verify::energy::direction(0.05, 0.3);
        let cfg = Chi2Config { theta_res: 400, phi_res: 160, integration_res: 8, ..Chi2Config::default() };
        let r = chi2_bsdf(&b, wo, &cfg);
        assert!(r.passed, "{r}");
    }
}
