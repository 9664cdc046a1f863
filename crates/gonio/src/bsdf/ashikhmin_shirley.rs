//! `ashikhmin_shirley` — Ashikhmin & Shirley 2000, "An Anisotropic Phong BRDF Model" (Journal of Graphics
//! Tools 5(2), 25–32): an anisotropic Phong-like glossy layer with Schlick's Fresnel over a diffuse
//! substrate, whose diffuse term is coupled to the specular one so that the sum conserves energy.
//!
//! | parameter | type          | default | meaning                                                        |
//! |-----------|---------------|---------|----------------------------------------------------------------|
//! | `nu`      | float [0, 1e5]| 100     | Phong exponent along the tangent (x axis of the shading frame)  |
//! | `nv`      | float [0, 1e5]| 100     | Phong exponent along the bitangent (y axis)                     |
//! | `rd`      | rgb [0,1]     | 0.5     | R_d, the diffuse substrate's reflectance                        |
//! | `rs`      | rgb [0,1]     | 0.05    | R_s, the specular reflectance at normal incidence (Schlick's F₀) |
//!
//! # Model (with k₁ = ωo, k₂ = ωi, h = (k₁ + k₂)/|k₁ + k₂| the half vector)
//! The paper's formulas are named here rather than numbered: its JGT and technical-report versions number
//! them differently.
//! - Specular: ρs = √((nu+1)(nv+1))/(8π) · (n·h)^{(nu (h·u)² + nv (h·v)²)/(1 − (n·h)²)}
//!   / ((h·k) max(n·k₁, n·k₂)) · F(k·h).
//! - Fresnel (Schlick 1994's approximation): F(c) = R_s + (1 − R_s)(1 − c)⁵.
//! - Diffuse: ρd = 28 R_d/(23π) (1 − R_s) (1 − (1 − n·k₁/2)⁵)(1 − (1 − n·k₂/2)⁵).
//!   Its albedo is R_d (1 − R_s)(1 − (1 − n·k₁/2)⁵) in closed form — 28/23 normalises it (see the tests).
//!
//! Both terms are symmetric in k₁ and k₂, so the model is reciprocal. The specular term is the half-vector
//! density p_h(h) = √((nu+1)(nv+1))/(2π) (n·h)^{e(φ)}, e(φ) = nu cos²φ + nv sin²φ, pushed to k₂ (Jacobian 1/(4 h·k)) times
//! F/max(n·k₁, n·k₂): its sampling weight is F cos θi / max(cos θo, cos θi) ≤ F, so the specular albedo
//! never exceeds max F. The diffuse term's albedo is R_d (1 − R_s)(1 − (1 − μo/2)⁵) ≤ (1 − R_s), and the
//! sum stays below 1 in every case measured: R_d = 1, R_s = 0 (the worst case: the specular Fresnel rise
//! is not subtracted from the diffuse term) gives a largest albedo of 0.966 and a white furnace of 0.83
//! (nu = nv = 1) and 0.84 (nu = nv = 10) in `gonio check` (2026-11). No check fails at any example, so the
//! model declares no violations.
//!
//! # Sampling
//! The half vector by the paper's sampling formulas: φ = atan(√((nu+1)/(nv+1)) tan(πξ₁/2)) in the first quadrant
//! (ξ₁ remapped to the four quadrants), cos θh = (1 − ξ₂)^{1/(nu cos²φ + nv sin²φ + 1)}, whose density is
//! exactly p_h; then k₂ = reflect(k₁, h) with pdf p_h/(4 k₁·h). Mixed with a cosine-weighted
//! direction for the diffuse term (one-sample MIS, Veach 1997 §9.2.4) with probability in proportion to
//! the lobes' rough albedos (luminance of R_s + (1 − R_s)/21, where 1/21 = 2∫(1 − μ)⁵ μ dμ, against
//! luminance of R_d (1 − R_s)). Half vectors facing away from k₁, or giving k₂ below the surface, produce
//! no sample; `pdf` keeps the lobe's full density (the missing mass is the probability of no sample).
//!
//! The exponent is evaluated as exp(e · ½ ln(1 − sin²θh)) with sin²θh = h_x² + h_y² taken from the
//! components, not from 1 − (n·h)²: at nu = 10⁴ the f32 rounding of n·h near 1 alone would be a 10⁻³
//! relative error (what keeps Blinn e = 2·10⁴ out of `torrance_sparrow`'s examples).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let b = Bsdf::from_json(r#"{"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rd": 0, "rs": 1}"#).unwrap();
//! // At normal incidence and in the mirror direction: h = n, ρs = (nu+1)/(8π) · 1/(1·1) · F(1) = 11/(8π).
//! assert!((b.f(Vec3::Z, Vec3::Z).r() - 11.0 / (8.0 * std::f32::consts::PI)).abs() < 1e-5);
//! let s = b.sample(Vec3::new(0.0, 0.6, 0.8), 0.5, Vec2::new(0.3, 0.4)).unwrap();
//! assert!((s.pdf - b.pdf(Vec3::new(0.0, 0.6, 0.8), s.wi)).abs() <= 1e-5 * s.pdf);
//! ```

use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::Result;
use crate::fresnel::reflect;
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::Rgb;
use std::f32::consts::{FRAC_PI_2, PI};

/// Largest accepted exponent: beyond 10⁵ the lobe (width ~1/√nu) approaches the f32 resolution of a
/// half vector (2026-11: same reasoning as `roughconductor`'s α ≥ 10⁻⁴).
const EXPONENT_MAX: f32 = 1e5;

/// Samples whose mixture density is below this are dropped (2026-11: as in `glossy_mix`: within a denormal
/// of the horizon f and pdf underflow together and cos θi/pdf overflows).
const MIN_PDF: f32 = 1e-30;

/// Ashikhmin & Shirley's anisotropic Phong BRDF.
#[derive(Clone, Debug, PartialEq)]
pub struct AshikhminShirley {
    pub nu: f32,
    pub nv: f32,
    pub rd: Rgb,
    pub rs: Rgb,
    /// The probability of sampling the specular lobe (see the module doc).
    specular_prob: f32,
}

impl AshikhminShirley {
    /// The model with exponents `nu`, `nv` ≥ 0 and reflectances `rd`, `rs` in [0, 1].
    #[must_use]
    pub fn new(nu: f32, nv: f32, rd: Rgb, rs: Rgb) -> Self {
        debug_assert!(nu >= 0.0 && nv >= 0.0, "exponents must be ≥ 0");
        let ls = rs.luminance();
        let specular = ls + (1.0 - ls) / 21.0;
        let diffuse = rd.luminance() * (1.0 - ls);
        AshikhminShirley { nu, nv, rd, rs, specular_prob: specular / (specular + diffuse) }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let nu = p.float_in("nu", 100.0, 0.0, EXPONENT_MAX)?;
        let nv = p.float_in("nv", 100.0, 0.0, EXPONENT_MAX)?;
        Ok(AshikhminShirley::new(nu, nv, p.reflectance("rd", Rgb::splat(0.5))?, p.reflectance("rs", Rgb::splat(0.05))?))
    }

    /// √((nu+1)(nv+1)), the normalisation of the half-vector density.
    #[inline]
    fn norm(&self) -> f32 {
        ((self.nu + 1.0) * (self.nv + 1.0)).sqrt()
    }

    /// The half-vector density p_h(h) = √((nu+1)(nv+1))/(2π) (n·h)^{e(φ)}, 0 below the surface.
    #[must_use]
    pub fn half_vector_pdf(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let (x2, y2) = (h.x * h.x, h.y * h.y);
        let s2 = x2 + y2;
        if s2 == 0.0 {
            return self.norm() / (2.0 * PI);
        }
        // e(φ) = nu cos²φ + nv sin²φ, and ln(n·h) from sin²θh (see the module doc; above 45° n·h is
        // far enough from 1 for its own logarithm).
        let e = (self.nu * x2 + self.nv * y2) / s2;
        let log_cos = if s2 < 0.5 { 0.5 * (-s2).ln_1p() } else { h.z.ln() };
        self.norm() / (2.0 * PI) * (e * log_cos).exp()
    }

    /// Schlick's Fresnel F(c) = R_s + (1 − R_s)(1 − c)⁵.
    #[inline]
    fn fresnel(&self, cos: f32) -> Rgb {
        let m = (1.0 - cos).clamp(0.0, 1.0);
        let m5 = m * m * m * m * m;
        self.rs + (Rgb::ONE - self.rs) * m5
    }

    /// The diffuse term ρd (for both directions above the surface).
    #[must_use]
    pub fn diffuse(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let g = |mu: f32| {
            let m = 1.0 - 0.5 * mu;
            1.0 - m * m * m * m * m
        };
        self.rd * (Rgb::ONE - self.rs) * (28.0 / (23.0 * PI) * g(wo.z) * g(wi.z))
    }

    /// The specular term ρs (for both directions above the surface).
    #[must_use]
    pub fn specular(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let h = (wo + wi).normalize();
        // k₁·h = k₂·h exactly, not in f32: average, so that ρs(k₁, k₂) = ρs(k₂, k₁) bit for bit.
        let hk = 0.5 * (wo.dot(h) + wi.dot(h));
        if !(hk > 0.0) {
            return Rgb::ZERO;
        }
        // ρs = p_h / (4 h·k) · F / max(n·k₁, n·k₂).
        let value = self.half_vector_pdf(h) / (4.0 * hk * wo.z.max(wi.z));
        if !value.is_finite() {
            return Rgb::ZERO;
        }
        self.fresnel(hk) * value
    }

    /// Sample h (see the module doc).
    fn sample_half_vector(&self, u: Vec2) -> Vec3 {
        // ξ₁ picks a quadrant and a position t in it; mirror alternate quadrants so the map is continuous.
        let x = (u.x * 4.0).min(4.0 - f32::EPSILON);
        let quadrant = x as u32;
        let t = x - quadrant as f32;
        let k = ((self.nu + 1.0) / (self.nv + 1.0)).sqrt();
        // tan φ = k tan(πt/2): (cos φ, sin φ) ∝ (cos(πt/2), k sin(πt/2)), well defined at t → 1.
        let (s, c) = (FRAC_PI_2 * t).sin_cos();
        let len = (c * c + k * k * s * s).sqrt();
        let (mut cos_phi, mut sin_phi) = (c / len, k * s / len);
        match quadrant {
            0 => {}
            1 => cos_phi = -cos_phi,
            2 => (cos_phi, sin_phi) = (-cos_phi, -sin_phi),
            _ => sin_phi = -sin_phi,
        }
        let e = self.nu * cos_phi * cos_phi + self.nv * sin_phi * sin_phi;
        // cos θh = (1 − ξ₂)^{1/(e+1)}; sin θh from the logarithm (exp_m1), not √(1 − cos²), for narrow lobes.
        let log_cos = (1.0 - u.y).max(f32::MIN_POSITIVE).ln() / (e + 1.0);
        let cos_theta = log_cos.exp();
        let sin_theta = (-(2.0 * log_cos).exp_m1()).max(0.0).sqrt();
        Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
    }

    /// The density of the specular sampler at `wi`: p_h(h)/(4 ωo·h).
    fn specular_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize();
        let hk = wo.dot(h);
        if !(hk > 0.0) {
            return 0.0;
        }
        let pdf = self.half_vector_pdf(h) / (4.0 * hk);
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }
}

impl BsdfModel for AshikhminShirley {
    fn flags(&self) -> BsdfFlags {
        if self.rd.is_black() {
            BsdfFlags::GLOSSY_REFLECTION
        } else {
            BsdfFlags::GLOSSY_REFLECTION | BsdfFlags::DIFFUSE_REFLECTION
        }
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.specular(wo, wi) + self.diffuse(wo, wi)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let (wi, lobe) = if uc < self.specular_prob {
            let h = self.sample_half_vector(u);
            if !(wo.dot(h) > 0.0) {
                return None;
            }
            (reflect(wo, h).normalize(), BsdfFlags::GLOSSY_REFLECTION)
        } else {
            (sample_cosine_hemisphere(u), BsdfFlags::DIFFUSE_REFLECTION)
        };
        if !(wi.z > 0.0) {
            return None;
        }
        // Either lobe may have produced wi: f and pdf are those of the whole mixture.
        let pdf = self.pdf(wo, wi);
        if pdf.is_nan() || pdf <= MIN_PDF {
            return None;
        }
        let s = BsdfSample::smooth(wi, self.f(wo, wi), pdf, lobe, 1.0)?;
        s.weight.is_finite().then_some(s)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let p = self.specular_prob;
        p * self.specular_pdf(wo, wi) + (1.0 - p) * cosine_hemisphere_pdf(wi)
    }
}

impl crate::bsdf::Examples for AshikhminShirley {
    /// Defaults and extremes: exponents 1, 10, 1000, 10⁴, 20:1 anisotropy both ways, white and black
    /// substrates, a pure specular layer; grazing incidence is among every check's directions.
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "ashikhmin_shirley"}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 1, "nv": 1, "rd": 0.5, "rs": 0.5}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rd": [0.8, 0.4, 0.1], "rs": 0.04}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 1000, "nv": 1000, "rd": 0.2, "rs": [0.9, 0.6, 0.3]}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 10000, "nv": 10000, "rd": 0.5, "rs": 0.1}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 1000, "nv": 50, "rd": 0.3, "rs": 0.3}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 10, "nv": 200, "rd": 0.6, "rs": 0.05}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 10000, "nv": 500, "rd": 0.0, "rs": 1.0}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 1, "nv": 20, "rd": 0.0, "rs": 1.0}"#,
        r#"{"type": "ashikhmin_shirley", "nu": 100, "nv": 100, "rd": 1.0, "rs": 0.5}"#,
    ];
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::glossy_mix::testing::hemisphere_integral;
    use crate::bsdf::Bsdf;
    use crate::verify::energy;

    #[test]
    fn half_vector_density_is_normalised() {
        // ∫ p_h dωh = 1 over the hemisphere for any nu, nv: the paper's normalisation of the specular lobe.
        for (nu, nv) in [(0.0, 0.0), (1.0, 1.0), (10.0, 200.0), (100.0, 5.0), (1000.0, 1000.0)] {
            let b = AshikhminShirley::new(nu, nv, Rgb::ZERO, Rgb::ONE);
            let total = hemisphere_integral(800, |h| b.half_vector_pdf(h) as f64);
            eprintln!("nu={nu} nv={nv}: ∫ p_h = {total:.6}");
            assert!((total - 1.0).abs() < 2e-3, "nu={nu} nv={nv}: {total}");
        }
    }

    #[test]
    fn diffuse_albedo_has_the_closed_form() {
        // ∫ ρd cos θi dωi = R_d (1 − R_s)(1 − (1 − μo/2)⁵): 28/(23π) · 2π · 23/56 = 1.
        let b = AshikhminShirley::new(10.0, 10.0, Rgb::splat(0.8), Rgb::splat(0.25));
        for mu in [1.0f32, 0.6, 0.2, 0.02] {
            let wo = energy::direction(mu, 0.4);
            let a = hemisphere_integral(400, |wi| b.diffuse(wo, wi).r() as f64 * wi.z as f64);
            let expect = 0.8 * 0.75 * (1.0 - (1.0 - 0.5 * mu as f64).powi(5));
            assert!((a - expect).abs() < 1e-4, "μ={mu}: {a} vs {expect}");
        }
    }

    #[test]
    fn specular_albedo_at_normal_incidence_has_the_closed_form() {
        // R_s = 1 (F = 1), ωo = n: the weight is cos θi = cos 2θh, so with c = cos θh the albedo is
        // ∫_{1/√2}^1 (n+1) cⁿ (2c² − 1) dc = (n+1) [2(1 − 2^{−(n+3)/2})/(n+3) − (1 − 2^{−(n+1)/2})/(n+1)].
        for n in [1.0f64, 10.0, 100.0] {
            let b = AshikhminShirley::new(n as f32, n as f32, Rgb::ZERO, Rgb::ONE);
            let expect =
                (n + 1.0) * (2.0 * (1.0 - 2f64.powf(-(n + 3.0) / 2.0)) / (n + 3.0) - (1.0 - 2f64.powf(-(n + 1.0) / 2.0)) / (n + 1.0));
            let a = energy::albedo(&b, Vec3::Z, 1 << 18, 7).r() as f64;
            eprintln!("n={n}: albedo {a:.5}, closed form {expect:.5}");
            assert!((a - expect).abs() < 2e-3, "n={n}: {a} vs {expect}");
        }
    }

    #[test]
    fn the_paper_formula_term_by_term() {
        let b = AshikhminShirley::new(30.0, 300.0, Rgb::splat(0.4), Rgb::splat(0.1));
        let wo = Vec3::new(0.5, 0.1, 0.86).normalize();
        let wi = Vec3::new(-0.45, 0.05, 0.89).normalize();
        let h = (wo + wi).normalize();
        let (hk, exp) =
            (wo.dot(h) as f64, (30.0 * h.x as f64 * h.x as f64 + 300.0 * h.y as f64 * h.y as f64) / (1.0 - h.z as f64 * h.z as f64));
        let fresnel = 0.1 + 0.9 * (1.0 - hk).powi(5);
        let rho_s =
            (31.0f64 * 301.0).sqrt() / (8.0 * std::f64::consts::PI) * (h.z as f64).powf(exp) / (hk * (wo.z.max(wi.z) as f64)) * fresnel;
        let g = |mu: f64| 1.0 - (1.0 - mu / 2.0).powi(5);
        let rho_d = 28.0 * 0.4 / (23.0 * std::f64::consts::PI) * 0.9 * g(wo.z as f64) * g(wi.z as f64);
        let f = b.f(wo, wi).r() as f64;
        assert!((f / (rho_s + rho_d) - 1.0).abs() < 1e-4, "{f} vs {}", rho_s + rho_d);
    }

    #[test]
    fn parameters_are_checked() {
        for bad in [
            r#"{"type": "ashikhmin_shirley", "nu": -1}"#,
            r#"{"type": "ashikhmin_shirley", "nv": 1e6}"#,
            r#"{"type": "ashikhmin_shirley", "rd": 1.5}"#,
            r#"{"type": "ashikhmin_shirley", "exponent": 10}"#,
        ] {
            assert!(Bsdf::from_json(bad).is_err(), "{bad}");
        }
        let Bsdf::AshikhminShirley(b) = Bsdf::from_json(r#"{"type": "ashikhmin_shirley"}"#).unwrap() else { panic!() };
        assert_eq!((b.nu, b.nv, b.rd, b.rs), (100.0, 100.0, Rgb::splat(0.5), Rgb::splat(0.05)));
    }
}
