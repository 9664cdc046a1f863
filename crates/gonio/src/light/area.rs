//! `area` — a shape that emits a constant radiance from the side its normal points to (Mitsuba's
//! convention: the back side is dark).
//!
//! | parameter  | type | default | meaning              |
//! |------------|------|---------|----------------------|
//! | `radiance` | rgb  | 1       | emitted radiance L_e |
//!
//! Spheres are sampled in the cone they subtend; other shapes by area (uniform over the shape), converted
//! to solid angle with p_ω = p_A · d² / |cos θ_l| (pbrt-v4 eq. 4.9 / §12.2). See [`Shape::sample_from`].

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
        let (ps, pdf) = shape.sample_from(p, uc, u)?;
        let wi = (ps.p - p).normalize_or_zero();
        // One-sided emission: the sampled point must face the reference point.
        if ps.n.dot(-wi) <= 0.0 || !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        Some(LightSample { wi, li: self.radiance, pdf, delta: false, shadow: spawn_ray_to(p, n, ps.p, ps.ng) })
    }

    /// Solid-angle density with which [`Self::sample_li`] from `p` produces the point `hit` on the light.
    #[must_use]
    pub fn pdf_li(&self, shape: &Shape, p: Vec3, hit: &SurfaceInteraction) -> f32 {
        shape.pdf_from(p, hit.p, hit.n)
    }
}
