//! `point` — an isotropic point light.
//!
//! | parameter   | type      | default   | meaning                                     |
//! |-------------|-----------|-----------|---------------------------------------------|
//! | `position`  | point     | (0, 0, 0) | location (alternatively `to_world`'s origin) |
//! | `to_world`  | transform | identity  | places the light at `to_world · (0, 0, 0)`  |
//! | `intensity` | rgb       | 1         | radiant intensity I (W/sr per channel)      |
//!
//! Irradiance-carrying radiance at distance d: I / d² (a delta distribution in direction).

use super::LightSample;
use crate::geometry::ray::{spawn_ray_to_lanes, RayLanes};
use crate::math::lanes::{Real, V3};
use crate::spectrum::Rgb;
use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Rgb,
}

impl PointLight {
    #[must_use]
    pub fn sample_li(&self, p: Vec3, n: Vec3) -> Option<LightSample> {
        sample_point_source(self.position, self.intensity, p, n)
    }
}

/// Light from an isotropic point source of `intensity` at `position` arriving at `p` (normal `n`, or zero
/// in a medium): inverse-square radiance, a delta sample, and the shadow ray to the source. Shared by
/// [`PointLight`] and [`super::spot::SpotLight`] (which scales it by its falloff).
#[must_use]
pub(crate) fn sample_point_source(position: Vec3, intensity: Rgb, p: Vec3, n: Vec3) -> Option<LightSample> {
    let (wi, inv_dist2, valid, shadow) = point_source_lanes::<f32>(position.into(), p.into(), n.into());
    if !valid {
        return None;
    }
    let wi = Vec3::from(wi);
    let shadow = if n == Vec3::ZERO {
        crate::geometry::Ray::new(p, wi, (position - p).length() * (1.0 - 1e-5))
    } else {
        crate::geometry::Ray::new(shadow.o.into(), shadow.d.into(), shadow.tmax)
    };
    Some(LightSample { wi, li: intensity * inv_dist2, pdf: 1.0, delta: true, shadow })
}

/// [`sample_point_source`] at points `p` (normals `n`) in lanes, each lane with its source at `position`:
/// the direction to it, 1 / distance² (the intensity's factor), whether the point is not at the source,
/// and the shadow ray from the surface (for a zero normal, in a medium, the caller's own ray).
#[inline(always)]
#[must_use]
pub fn point_source_lanes<R: Real>(position: V3<R>, p: V3<R>, n: V3<R>) -> (V3<R>, R, R::Mask, RayLanes<R>) {
    let d = position.sub(p);
    let dist2 = d.dot(d);
    let zero = R::splat(0.0);
    (d.div(dist2.sqrt()), R::splat(1.0) / dist2, dist2.gt(zero), spawn_ray_to_lanes(p, n, position, V3::new(zero, zero, zero)))
}
