//! `directional` — a light infinitely far away: parallel rays of irradiance E along one direction, as
//! Mitsuba 3's `directional`.
//!
//! | parameter    | type      | default  | meaning                                                     |
//! |--------------|-----------|----------|-------------------------------------------------------------|
//! | `irradiance` | rgb       | 1        | E, on a surface facing the light (W/m² per channel)         |
//! | `direction`  | vector    | —        | the direction light travels in (alternative to `to_world`)  |
//! | `to_world`   | transform | identity | light travels along `to_world · +z`                         |
//!
//! A surface with normal n receives E · max(0, −n·d), d the direction of travel: a delta distribution in
//! direction, sampled with density 1.

use super::LightSample;
use crate::error::{Error, Result};
use crate::geometry::ray::spawn_ray;
use crate::geometry::Ray;
use crate::props::Props;
use crate::spectrum::Rgb;
use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction the light travels in.
    pub direction: Vec3,
    pub irradiance: Rgb,
}

impl DirectionalLight {
    pub fn from_props(p: &Props) -> Result<Self> {
        let direction = match p.vector("direction")? {
            Some(_) if p.has("to_world") => return Err(Error::spec(p.at_param("direction"), "give `direction` or `to_world`, not both")),
            Some(d) => d,
            None => p.transform("to_world")?.vector(Vec3::Z),
        };
        let direction = direction.try_normalize().ok_or_else(|| Error::spec(p.at_param("direction"), "the light's direction is zero"))?;
        Ok(DirectionalLight { direction, irradiance: p.rgb_in("irradiance", Rgb::ONE, 0.0, f32::MAX)? })
    }

    #[must_use]
    pub fn sample_li(&self, p: Vec3, n: Vec3) -> Option<LightSample> {
        let wi = -self.direction;
        let shadow = if n == Vec3::ZERO { Ray::new(p, wi, f32::INFINITY) } else { spawn_ray(p, n, wi) };
        Some(LightSample { wi, li: self.irradiance, pdf: 1.0, delta: true, shadow })
    }
}
