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
use crate::math::lanes::{Real, V3};
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};

/// For a point `q` on an emitter (shading normal `nq`) sampled from `p` with solid-angle density `pdf`: the
/// unit direction from `p` towards it, and whether the sample counts — one-sided emission: `q` must face
/// `p` — with a positive, finite density. In lanes.
#[inline(always)]
pub fn towards<R: Real>(p: V3<R>, q: V3<R>, nq: V3<R>, pdf: R) -> (V3<R>, R::Mask) {
    // `Vec3::normalize_or_zero`.
    let d = q.sub(p);
    let rcp = R::splat(1.0) / d.length();
    let zero = R::splat(0.0);
    let wi = V3::select(rcp.is_finite() & rcp.gt(zero), d.scale(rcp), V3::new(zero, zero, zero));
    (wi, !nq.dot(wi.neg()).le(zero) & pdf.gt(zero) & pdf.is_finite())
}

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
        let (wi, valid) = towards::<f32>(p.into(), ps.p.into(), ps.n.into(), pdf);
        valid.then(|| LightSample { wi: wi.into(), li: self.radiance, pdf, delta: false, shadow: spawn_ray_to(p, n, ps.p, ps.ng) })
    }

    /// Solid-angle density with which [`Self::sample_li`] from `p` produces the point `hit` on the light.
    #[must_use]
    pub fn pdf_li(&self, shape: &Shape, p: Vec3, hit: &SurfaceInteraction) -> f32 {
        shape.pdf_from(p, hit.p, hit.n)
    }
}
