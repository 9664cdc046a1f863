//! `area` — a shape that emits a constant radiance from the side its normal points to (Mitsuba's
//! convention: the back side is dark).
//!
//! | parameter  | type | default | meaning              |
//! |------------|------|---------|----------------------|
//! | `radiance` | rgb  | 1       | emitted radiance L_e |
//!
//! Sampled by area (uniform over the shape), converted to solid angle with p_ω = p_A · d² / |cos θ_l|
//! (pbrt-v4 eq. 4.9 / §12.2).

use super::LightSample;
use crate::geometry::ray::spawn_ray_to;
use crate::geometry::{Shape, SurfaceInteraction};
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};

/// Emission from shape number `shape`.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    pub shape: u32,
    pub radiance: Rgb,
}

impl AreaLight {
    /// Radiance leaving a point with shading normal `n` in direction `w` (towards the viewer).
    #[inline]
    #[must_use]
    pub fn radiance_towards(&self, n: Vec3, w: Vec3) -> Rgb {
        if n.dot(w) > 0.0 {
            self.radiance
        } else {
            Rgb::ZERO
        }
    }

    #[must_use]
    pub fn sample_li(&self, shape: &Shape, p: Vec3, n: Vec3, uc: f32, u: Vec2) -> Option<LightSample> {
        let ps = shape.sample_position(uc, u);
        let d = ps.p - p;
        let dist2 = d.length_squared();
        if !(dist2 > 0.0) {
            return None;
        }
        let wi = d / dist2.sqrt();
        let cos_l = ps.n.dot(-wi);
        if cos_l <= 0.0 {
            return None;
        }
        let pdf = ps.pdf_area * dist2 / cos_l;
        Some(LightSample { wi, li: self.radiance, pdf, delta: false, shadow: spawn_ray_to(p, n, ps.p, ps.ng) })
    }

    /// Solid-angle density with which [`Self::sample_li`] from `p` produces the point `hit` on the light.
    #[must_use]
    pub fn pdf_li(&self, shape: &Shape, p: Vec3, hit: &SurfaceInteraction) -> f32 {
        let d = hit.p - p;
        let dist2 = d.length_squared();
        let cos_l = hit.shading.n.dot(-d).abs() / dist2.sqrt();
        if cos_l == 0.0 {
            return 0.0;
        }
        dist2 / (cos_l * shape.area())
    }
}
