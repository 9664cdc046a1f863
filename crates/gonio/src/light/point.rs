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
use crate::geometry::ray::spawn_ray_to;
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
    let d = position - p;
    let dist2 = d.length_squared();
    if !(dist2 > 0.0) {
        return None;
    }
    let wi = d / dist2.sqrt();
    let shadow = if n == Vec3::ZERO {
        crate::geometry::Ray::new(p, wi, dist2.sqrt() * (1.0 - 1e-5))
    } else {
        spawn_ray_to(p, n, position, Vec3::ZERO)
    };
    Some(LightSample { wi, li: intensity / dist2, pdf: 1.0, delta: true, shadow })
}
