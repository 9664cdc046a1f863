//! `spot` — a point light that emits in a cone, as Mitsuba 3's `spot`.
//!
//! | parameter      | type      | default            | meaning                                           |
//! |----------------|-----------|--------------------|---------------------------------------------------|
//! | `intensity`    | rgb       | 1                  | radiant intensity I on the axis (W/sr per channel) |
//! | `cutoff_angle` | float     | 20                 | half-angle of the cone, degrees; nothing beyond   |
//! | `beam_width`   | float     | ¾ · `cutoff_angle` | half-angle of the full-intensity core, degrees    |
//! | `to_world`     | transform | identity           | the light sits at `to_world · 0` and shines along `to_world · +z` |
//! | `texture`      | texture   | none               | projected over the cone: multiplies the intensity (below) |
//!
//! Falloff (Mitsuba 3, `src/emitters/spot.cpp`, `falloff_curve`): with θ the angle between the emitted
//! direction and the axis, the intensity is I for θ ≤ `beam_width`, I · (θ_cutoff − θ) / (θ_cutoff − θ_beam)
//! between `beam_width` and `cutoff_angle` (linear in the angle), and 0 from θ_cutoff on (cos θ ≤ cos θ_cutoff).
//! The radiance-carrying irradiance at distance d is I · falloff(θ) / d², a delta distribution in direction.
//!
//! A `texture` is projected as Mitsuba 3's `spot` projects it (`direction_to_uv`): a light-space direction
//! (x, y, z) looks the texture up at uv = (½ + ½ x / (z tan θ_cutoff), ½ + ½ y / (z tan θ_cutoff)), so
//! the texture's square spans the cone's cross-section, its centre on the axis; the intensity in that
//! direction is I · texture(uv) · falloff(θ).

use super::LightSample;
use crate::error::{Error, Result};
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::Rgb;
use crate::texture::Texture;
use glam::{Vec2, Vec3};

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
    /// The projected texture, if any.
    texture: Option<Texture>,
}

impl SpotLight {
    /// Whether a texture is projected (its colour then varies across the beam).
    #[must_use]
    pub fn is_textured(&self) -> bool {
        self.texture.is_some()
    }

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
            texture: None,
        }
    }

    /// The same spot with `texture` projected over its cone (module docs).
    #[must_use]
    pub fn with_texture(mut self, texture: Texture) -> Self {
        self.texture = Some(texture);
        self
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
        let spot = SpotLight::new(p.transform("to_world")?, intensity, cutoff, beam);
        Ok(match p.plugin("texture")? {
            Some(t) => spot.with_texture(Texture::from_props(t)?),
            None => spot,
        })
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

    /// The falloff factor towards the world-space point `p` ([`Self::falloff`]; the texture not included).
    #[must_use]
    pub fn falloff_at(&self, p: Vec3) -> f32 {
        self.falloff(self.to_local.vector(p - self.position))
    }

    /// The texture coordinates a light-space emission direction `local` (inside the cone) projects to.
    #[must_use]
    pub fn direction_to_uv(&self, local: Vec3) -> Vec2 {
        let scale = 0.5 / (local.z * self.cutoff.tan());
        Vec2::new(0.5 + local.x * scale, 0.5 + local.y * scale)
    }

    /// The point source's sample ([`super::point::sample_point_source`]) scaled by the falloff and the
    /// projected texture.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, n: Vec3) -> Option<LightSample> {
        let mut s = super::point::sample_point_source(self.position, self.intensity, p, n)?;
        let local = self.to_local.vector(-s.wi);
        let falloff = self.falloff(local);
        if falloff <= 0.0 {
            return None;
        }
        s.li *= falloff;
        if let Some(t) = &self.texture {
            // falloff > 0 puts the direction inside the cone (θ < θ_cutoff ≤ 180°): z > 0 when the cone is
            // narrower than a hemisphere; a wider one projects its back half through z ≤ 0 as Mitsuba does.
            s.li *= t.eval(self.direction_to_uv(local));
        }
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

    /// The texture's corners and centre land where Mitsuba's `direction_to_uv` puts them: the axis at
    /// (½, ½), a direction at the cutoff angle in the light's +x (or +y) plane at u (or v) = 1.
    #[test]
    fn texture_projects_over_the_cone() {
        let s = SpotLight::new(Transform::IDENTITY, Rgb::ONE, 30.0, 30.0);
        let t = 30f32.to_radians().tan();
        for (local, want) in [
            (Vec3::Z, Vec2::splat(0.5)),
            (Vec3::new(t, 0.0, 1.0), Vec2::new(1.0, 0.5)),
            (Vec3::new(0.0, -t, 1.0), Vec2::new(0.5, 0.0)),
            (Vec3::new(0.5 * t, 0.5 * t, 1.0) * 3.0, Vec2::splat(0.75)),
        ] {
            assert!((s.direction_to_uv(local) - want).length() < 1e-5, "{local}: {}", s.direction_to_uv(local));
        }
        // A checkerboard over the cone: light reaching a point below the axis at u, v < ½ takes colour0.
        let board =
            Texture::from_props(&Props::from_json(r#"{"type": "checkerboard", "color0": [1, 0, 0], "color1": [0, 0, 1]}"#).unwrap())
                .unwrap();
        let s = s.with_texture(board.clone());
        let p = Vec3::new(-0.2 * t, -0.2 * t, 1.0) * 2.0;
        let ls = s.sample_li(p, Vec3::ZERO).unwrap();
        let want = board.eval(s.direction_to_uv(p)) / p.length_squared();
        assert!((0..3).all(|c| (ls.li.0[c] - want.0[c]).abs() < 1e-6) && ls.li.r() > 0.0, "{:?} vs {want:?}", ls.li);
    }
}
