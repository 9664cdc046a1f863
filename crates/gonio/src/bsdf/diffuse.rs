//! `diffuse` — the Lambertian reflector: f = ρ/π (Lambert 1760; pbrt-v4 §9.2).
//!
//! | parameter     | type      | default | meaning                                   |
//! |---------------|-----------|---------|-------------------------------------------|
//! | `reflectance` | rgb [0,1] | 0.5     | ρ, the albedo: fraction of light reflected |
//!
//! One-sided like Mitsuba's `diffuse`: light arriving from below the surface is absorbed (wrap in
//! `twosided` to reflect on both sides). Sampled by Malley's method (cosine-weighted hemisphere), so a
//! sample's weight is exactly ρ.
//!
//! ```
//! use gonio::bsdf::{BsdfModel, Diffuse};
//! use gonio::math::Vec3;
//! let d = Diffuse::new(gonio::Rgb::splat(0.8));
//! assert!((d.f(Vec3::Z, Vec3::Z).r() - 0.8 / std::f32::consts::PI).abs() < 1e-7);
//! ```

use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::Result;
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::Rgb;
use std::f32::consts::FRAC_1_PI;

/// The Lambertian reflector.
#[derive(Clone, Debug, PartialEq)]
pub struct Diffuse {
    pub reflectance: Rgb,
}

impl Diffuse {
    #[must_use]
    pub fn new(reflectance: Rgb) -> Self {
        Diffuse { reflectance }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        Ok(Diffuse::new(p.reflectance("reflectance", Rgb::splat(0.5))?))
    }
}

impl crate::bsdf::Examples for Diffuse {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "diffuse"}"#,
        r#"{"type": "diffuse", "reflectance": [1, 1, 1]}"#,
        r#"{"type": "diffuse", "reflectance": [0.9, 0.05, 0.0]}"#,
    ];
}

impl BsdfModel for Diffuse {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    #[inline(always)]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.reflectance * FRAC_1_PI
    }

    #[inline(always)]
    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi);
        // f·cos/pdf = (ρ/π)·cos/(cos/π) = ρ: set exactly rather than through a division that is 0/0 on the
        // horizon.
        let mut s = BsdfSample::smooth(wi, self.reflectance * FRAC_1_PI, pdf, BsdfFlags::DIFFUSE_REFLECTION, 1.0)?;
        s.weight = self.reflectance;
        Some(s)
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }
}
