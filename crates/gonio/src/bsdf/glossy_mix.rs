//! The shared part of [`phong`](super::phong) and [`blinn_phong`](super::blinn_phong): a Lambertian lobe
//! plus a glossy lobe, f = k_d/π + k_s·S(ωo, ωi), sampled as a two-component mixture.
//!
//! | part                   | type      | meaning                                                       |
//! |------------------------|-----------|---------------------------------------------------------------|
//! | `diffuse_reflectance`  | rgb [0,1] | k_d, the weight of the Lambertian lobe k_d/π                  |
//! | `specular_reflectance` | rgb [0,1] | k_s, the weight of the glossy lobe S                          |
//! | `lobe`                 | [`GlossyLobe`] | S, with its own sampling density                         |
//!
//! One-sided: zero when ωo or ωi lies below the surface. `sample` picks the cosine-weighted hemisphere
//! (Malley's method) with probability p_d = lum(k_d)/(lum(k_d) + lum(k_s)) and the glossy lobe's own
//! sampling otherwise (one-sample MIS over the two lobes, Veach 1997 §9.2.4); `pdf` is the mixture
//! p_d·cos θi/π + (1 − p_d)·p_S(ωi). Directions of the glossy lobe that fall below the surface are
//! discarded (`sample` returns `None`) while `pdf` keeps the lobe's full density: the missing mass is the
//! probability of producing no sample, which the chi-square test counts in its own bin.
//!
//! With the adaptive cell integrals of the chi-square test (2026-11) `gonio check` passes sharp lobes on
//! its default grid: Phong n = 500 and 2000 and Blinn–Phong e = 1000 are among the examples (p-values
//! 0.20–0.28 at every cos θo). The models' tests also run a pure lobe (k_d = 0), whose support boundary
//! cos α = 0 crosses the polar cells, on a finer grid.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let b = Bsdf::from_json(r#"{"type": "phong", "diffuse_reflectance": 0.5, "specular_reflectance": 0.0}"#).unwrap();
//! // With k_s = 0 only the Lambertian lobe is left and every sample has weight k_d.
//! let s = b.sample(Vec3::new(0.0, 0.6, 0.8), 0.3, Vec2::new(0.2, 0.7)).unwrap();
//! assert!((s.weight.r() - 0.5).abs() < 1e-5);
//! ```

use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::Rgb;
use std::f32::consts::FRAC_1_PI;

/// Samples whose mixture density is below this are dropped (2026-11: for ωo within a denormal of the
/// horizon, f and pdf underflow together and cos θi/pdf overflows to Inf; such samples carry a probability
/// below 2π·10⁻³⁰).
const MIN_PDF: f32 = 1e-30;

/// How a glossy lobe is scaled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normalization {
    /// The bare power of a cosine, as the 1970s shading models wrote it: not a density, gains energy.
    None,
    /// Scaled so that the lobe's albedo at normal incidence is (about) 1.
    Energy,
}

impl Normalization {
    /// Reads `normalization = "none" | "energy"` (default `"energy"`).
    pub fn from_props(p: &Props) -> Result<Self> {
        choice(p, "normalization", &[("none", Normalization::None), ("energy", Normalization::Energy)], Normalization::Energy)
    }
}

/// Reads a string parameter that must be one of `options`; `default` when absent.
pub(super) fn choice<T: Copy>(p: &Props, name: &'static str, options: &[(&str, T)], default: T) -> Result<T> {
    let Some(given) = p.string(name)? else { return Ok(default) };
    options.iter().find(|(n, _)| *n == given).map(|(_, v)| *v).ok_or_else(|| {
        let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
        Error::spec(p.at(), format!("parameter `{name}` of `{}` must be one of {}, got `{given}`", p.plugin_type(), names.join(" | ")))
    })
}

/// A glossy lobe S(ωo, ωi) with its own importance sampling. Callers guarantee ωo and ωi above the surface.
pub trait GlossyLobe {
    /// S(ωo, ωi) in sr⁻¹ (without the cosine), ≥ 0 and finite.
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32;
    /// A direction from the lobe's sampling density; it may lie below the surface (the mixture discards it).
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<Vec3>;
    /// The solid-angle density of [`GlossyLobe::sample`] at `wi`.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
}

/// f = k_d/π + k_s·S: a Lambertian lobe plus the glossy lobe `L`.
#[derive(Clone, Debug, PartialEq)]
pub struct DiffuseGlossy<L> {
    pub diffuse_reflectance: Rgb,
    pub specular_reflectance: Rgb,
    pub lobe: L,
    /// p_d, the probability of sampling the Lambertian lobe.
    diffuse_prob: f32,
}

impl<L: GlossyLobe> DiffuseGlossy<L> {
    /// The mixture of `kd`/π and `ks`·`lobe`, sampled in proportion to their luminances.
    #[must_use]
    pub fn new(kd: Rgb, ks: Rgb, lobe: L) -> Self {
        debug_assert!(kd.min_component() >= 0.0 && ks.min_component() >= 0.0, "reflectances must be ≥ 0");
        let (ld, ls) = (kd.luminance(), ks.luminance());
        // Both black: sample the (zero) diffuse lobe, so that sampling still has a well-defined density.
        let diffuse_prob = if ld + ls > 0.0 { ld / (ld + ls) } else { 1.0 };
        DiffuseGlossy { diffuse_reflectance: kd, specular_reflectance: ks, lobe, diffuse_prob }
    }

    /// The probability p_d with which `sample` picks the Lambertian lobe.
    #[must_use]
    pub fn diffuse_probability(&self) -> f32 {
        self.diffuse_prob
    }
}

impl<L: GlossyLobe> BsdfModel for DiffuseGlossy<L> {
    fn flags(&self) -> BsdfFlags {
        let mut flags = BsdfFlags::NONE;
        if !self.diffuse_reflectance.is_black() || self.specular_reflectance.is_black() {
            flags = flags | BsdfFlags::DIFFUSE_REFLECTION;
        }
        if !self.specular_reflectance.is_black() {
            flags = flags | BsdfFlags::GLOSSY_REFLECTION;
        }
        flags
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.diffuse_reflectance * FRAC_1_PI + self.specular_reflectance * self.lobe.eval(wo, wi)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let (wi, lobe) = if uc < self.diffuse_prob {
            (sample_cosine_hemisphere(u), BsdfFlags::DIFFUSE_REFLECTION)
        } else {
            (self.lobe.sample(wo, u)?, BsdfFlags::GLOSSY_REFLECTION)
        };
        if wi.z <= 0.0 {
            return None;
        }
        // Either lobe may have produced wi: f and pdf are those of the whole mixture.
        let pdf = self.pdf(wo, wi);
        if pdf.is_nan() || pdf <= MIN_PDF {
            return None;
        }
        BsdfSample::smooth(wi, self.f(wo, wi), pdf, lobe, 1.0)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let p = self.diffuse_prob;
        let glossy = if p < 1.0 { (1.0 - p) * self.lobe.pdf(wo, wi) } else { 0.0 };
        p * cosine_hemisphere_pdf(wi) + glossy
    }
}

/// Test helpers shared by the models built on [`DiffuseGlossy`].
#[cfg(test)]
pub(super) mod testing {
    /// ∫ g(ω) dω over the upper hemisphere by the midpoint rule in (θ, φ), in f64.
    pub fn hemisphere_integral(steps: usize, g: impl Fn(crate::math::Vec3) -> f64) -> f64 {
        let (dt, dp) = (std::f64::consts::FRAC_PI_2 / steps as f64, 2.0 * std::f64::consts::PI / (4 * steps) as f64);
        let mut sum = 0.0;
        for i in 0..steps {
            let theta = (i as f64 + 0.5) * dt;
            for j in 0..4 * steps {
                let phi = (j as f64 + 0.5) * dp;
                let w = crate::math::Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                sum += g(w) * theta.sin() * dt * dp;
            }
        }
        sum
    }
}
