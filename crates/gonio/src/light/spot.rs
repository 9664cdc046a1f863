//! `spot` — a point light that emits in a cone, as Mitsuba 3's `spot`.
//!
//! | parameter      | type      | default            | meaning                                           |
//! |----------------|-----------|--------------------|---------------------------------------------------|
//! | `intensity`    | rgb       | 1                  | radiant intensity I on the axis (W/sr per channel) |
//! | `cutoff_angle` | float     | 20                 | half-angle of the cone, degrees; nothing beyond   |
//! | `beam_width`   | float     | ¾ · `cutoff_angle` | half-angle of the full-intensity core, degrees    |
//! | `to_world`     | transform | identity           | the light sits at `to_world · 0` and shines along `to_world · +z` |
//!
//! Falloff (Mitsuba 3, `src/emitters/spot.cpp`, `falloff_curve`): with θ the angle between the emitted
//! direction and the axis, the intensity is I for θ ≤ `beam_width`, I · (θ_cutoff − θ) / (θ_cutoff − θ_beam)
//! between `beam_width` and `cutoff_angle` (linear in the angle), and 0 from θ_cutoff on (cos θ ≤ cos θ_cutoff).
//! The radiance-carrying irradiance at distance d is I · falloff(θ) / d², a delta distribution in direction.

use super::LightSample;
use crate::error::{Error, Result};
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::Rgb;
use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub struct SpotLight {
    pub position: Vec3,
    to_local: Transform,
    pub intensity: Rgb,
    /// Cutoff and beam half-angles in radians, and their cosines.
    cutoff: f32,
    beam: f32,
    cos_cutoff: f32,
    cos_beam: f32,
}

impl SpotLight {
    /// A spot at `to_world · 0` shining along `to_world · +z`; angles in degrees, 0 < beam ≤ cutoff ≤ 180
    /// (the caller checks).
    #[must_use]
    pub fn new(to_world: Transform, intensity: Rgb, cutoff_deg: f32, beam_deg: f32) -> Self {
        let (cutoff, beam) = (cutoff_deg.to_radians(), beam_deg.to_radians());
        SpotLight {
            position: to_world.point(Vec3::ZERO),
            to_local: to_world.inverse(),
            intensity,
            cutoff,
            beam,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
        }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let cutoff = p.float_in("cutoff_angle", 20.0, 0.0, 180.0)?;
        if !(cutoff > 0.0) {
            return Err(Error::spec(p.at_param("cutoff_angle"), "`cutoff_angle` must be > 0 degrees"));
        }
        let beam = p.float_in("beam_width", 0.75 * cutoff, 0.0, 180.0)?;
        if beam > cutoff {
            return Err(Error::spec(
                p.at_param("beam_width"),
                format!("`beam_width` ({beam}°) must not exceed `cutoff_angle` ({cutoff}°)"),
            ));
        }
        let intensity = p.rgb_in("intensity", Rgb::ONE, 0.0, f32::MAX)?;
        Ok(SpotLight::new(p.transform("to_world")?, intensity, cutoff, beam))
    }

    /// The falloff factor in [0, 1] for a light-space emission direction `local` (module docs).
    #[must_use]
    pub fn falloff(&self, local: Vec3) -> f32 {
        let cos_theta = local.normalize_or_zero().z;
        if !(cos_theta > self.cos_cutoff) {
            0.0
        } else if cos_theta >= self.cos_beam {
            1.0
        } else {
            // Between the two cones, linear in the angle; beam < cutoff here, so the division is safe.
            ((self.cutoff - cos_theta.clamp(-1.0, 1.0).acos()) / (self.cutoff - self.beam)).clamp(0.0, 1.0)
        }
    }

    /// The point source's sample ([`super::point::sample_point_source`]) scaled by the falloff.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, n: Vec3) -> Option<LightSample> {
        let mut s = super::point::sample_point_source(self.position, self.intensity, p, n)?;
        let falloff = self.falloff(self.to_local.vector(-s.wi));
        if falloff <= 0.0 {
            return None;
        }
        s.li *= falloff;
        Some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falloff_is_mitsubas_linear_ramp_in_angle() {
        // Shining down −y from the origin: to_world rotates +z onto −y.
        let to_world = Transform::rotate(Vec3::X, 90.0).unwrap();
        let s = SpotLight::new(to_world, Rgb::splat(2.0), 30.0, 10.0);
        let dir = |deg: f32| Vec3::new(0.0, -deg.to_radians().cos(), deg.to_radians().sin());
        for (deg, want) in [(0.0, 1.0), (9.9, 1.0), (20.0, 0.5), (25.0, 0.25), (30.5, 0.0), (90.0, 0.0)] {
            let got = s.falloff(s.to_local.vector(dir(deg)));
            assert!((got - want).abs() < 1e-3, "{deg}°: {got} vs {want}");
        }
        // Irradiance-carrying radiance at a point 2 below and 20° off axis: I · ½ / d².
        let p = dir(20.0) * 2.0;
        let ls = s.sample_li(p, Vec3::ZERO).unwrap();
        assert!(ls.delta && (ls.li.r() - 2.0 * 0.5 / 4.0).abs() < 1e-3, "{:?}", ls.li);
        assert!(s.sample_li(dir(40.0), Vec3::ZERO).is_none());
    }
}
