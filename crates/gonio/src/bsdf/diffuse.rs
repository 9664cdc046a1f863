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

use super::lanes::{f_one, flag_lanes, pdf_one, sample_one, LaneModel, LaneSample};
use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::Result;
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{cosine_hemisphere, cosine_hemisphere_density};
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
        f_one(self, wo, wi)
    }

    #[inline(always)]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        sample_one(self, wo, uc, u)
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_one(self, wo, wi)
    }

    lane_batch_methods!(lanes);
}

impl Diffuse {
    /// Every configuration has the kernel below (a copy: three numbers).
    #[inline(always)]
    fn lanes(&self) -> Option<Self> {
        Some(self.clone())
    }
}

impl LaneModel for Diffuse {
    #[inline(always)]
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3] {
        diffuse_f(channels!(|c| R::splat(self.reflectance.0[c])), wo, wi)
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        diffuse_pdf(wo, wi)
    }

    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, _uc: R, ux: R, uy: R) -> LaneSample<R> {
        diffuse_sample(channels!(|c| R::splat(self.reflectance.0[c])), wo, ux, uy)
    }
}

/// The Lambertian `f` with a reflectance per lane (the kernel of [`Diffuse`], and of the renderer's packets,
/// whose lanes hit different diffuse surfaces).
#[inline(always)]
pub fn diffuse_f<R: Real>(reflectance: [R; 3], wo: V3<R>, wi: V3<R>) -> [R; 3] {
    let zero = R::splat(0.0);
    let below = wo.z.le(zero) | wi.z.le(zero);
    channels!(|c| R::select(below, zero, reflectance[c] * FRAC_1_PI))
}

/// The Lambertian `pdf` (it does not depend on the reflectance).
#[inline(always)]
pub fn diffuse_pdf<R: Real>(wo: V3<R>, wi: V3<R>) -> R {
    R::select(wo.z.le(R::splat(0.0)), R::splat(0.0), cosine_hemisphere_density(wi.z))
}

/// The Lambertian `sample` with a reflectance per lane.
#[inline(always)]
pub fn diffuse_sample<R: Real>(reflectance: [R; 3], wo: V3<R>, ux: R, uy: R) -> LaneSample<R> {
    let wi = cosine_hemisphere(ux, uy);
    let pdf = cosine_hemisphere_density(wi.z);
    // pdf is finite; a sample wherever it is positive (not on the horizon).
    let valid = !wo.z.le(R::splat(0.0)) & pdf.gt(R::splat(0.0));
    let f = channels!(|c| reflectance[c] * FRAC_1_PI);
    // f·cos/pdf = (ρ/π)·cos/(cos/π) = ρ: set exactly rather than through a division.
    LaneSample { wi, f, pdf, weight: reflectance, flags: flag_lanes(BsdfFlags::DIFFUSE_REFLECTION), eta: R::splat(1.0), valid }
}
