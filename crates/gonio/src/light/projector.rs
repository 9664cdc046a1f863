//! `projector` — a point light that projects an image, as Mitsuba 3's `projector`: the reciprocal of a
//! pinhole `perspective` camera (the same parameters and pixel-to-direction mapping).
//!
//! | parameter      | type            | default  | meaning                                                      |
//! |----------------|-----------------|----------|--------------------------------------------------------------|
//! | `irradiance`   | texture or rgb  | 1        | irradiance on the virtual image plane at z = 1 (before `scale` and π, below) |
//! | `scale`        | float           | 1        | multiplies the irradiance                                    |
//! | `fov`          | float           | —        | field of view in degrees along `fov_axis`                    |
//! | `fov_axis`     | string          | `x`      | `x`, `y`, `smaller`, `larger` or `diagonal`                  |
//! | `focal_length` | string          | `50mm`   | instead of `fov`: a 35 mm film equivalent (diagonal)         |
//! | `to_world`     | transform       | identity | the light sits at `to_world · 0` and looks along `to_world · +z` |
//!
//! A point x whose light-space position (x, y, z) has z > 0 projects to the image point (u, v) of
//! [`crate::math::perspective::project`] (the image's aspect is the texture's width over height); outside
//! [0, 1]² it gets nothing. The radiance-carrying irradiance arriving at x (the delta sample's value,
//! Mitsuba 3.9.1's `Projector::sample_direction`) is π · scale · E(u, v) / (z² cos θ), with θ the angle
//! between the light's axis and the direction to x: the radiant intensity π · scale · E / cos³ θ (the
//! inverse of a pinhole camera's importance), so that the plane z = 1 receives π · scale · E(u, v) — a
//! constant texture lights a plane facing it evenly.

use super::LightSample;
use crate::error::{Error, Result};
use crate::math::perspective::{project, tan_half_angles};
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::Rgb;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// What a projector projects.
#[derive(Clone, Debug, PartialEq)]
enum Irradiance {
    Uniform(Rgb),
    Texture(Texture),
}

#[derive(Clone, Debug, PartialEq)]
pub struct ProjectorLight {
    pub position: Vec3,
    to_local: Transform,
    /// `to_world · +z`, as given (not normalised: Mitsuba's cos θ uses it so).
    axis: Vec3,
    irradiance: Irradiance,
    scale: f32,
    tan_x: f32,
    tan_y: f32,
}

impl ProjectorLight {
    pub fn from_props(p: &Props) -> Result<Self> {
        let irradiance = match p.plugin("irradiance") {
            Ok(Some(t)) => Irradiance::Texture(Texture::from_props(t)?),
            _ => Irradiance::Uniform(p.rgb_in("irradiance", Rgb::ONE, 0.0, f32::MAX)?),
        };
        let (width, height) = match &irradiance {
            Irradiance::Texture(t) => t.resolution(),
            Irradiance::Uniform(_) => (1, 1),
        };
        let aspect = width as f32 / height as f32;
        let (fov, axis) = p.field_of_view()?;
        let (tan_x, tan_y) = tan_half_angles(fov, &axis, aspect).map_err(|e| Error::spec(p.at_param("fov_axis"), e))?;
        let to_world = p.transform("to_world")?;
        Ok(ProjectorLight {
            position: to_world.point(Vec3::ZERO),
            to_local: to_world.inverse(),
            axis: to_world.vector(Vec3::Z),
            irradiance,
            scale: p.float_in("scale", 1.0, 0.0, f32::MAX)?,
            tan_x,
            tan_y,
        })
    }

    /// The projected irradiance at image point `uv` (times `scale`, without π).
    fn irradiance_at(&self, uv: Vec2) -> Rgb {
        let e = match &self.irradiance {
            Irradiance::Uniform(e) => *e,
            Irradiance::Texture(t) => t.eval(uv),
        };
        e * self.scale
    }

    /// The mean luminance of π · scale · E over the image (for the choice among lights: a 16 × 16 grid of
    /// lookups).
    #[must_use]
    pub fn mean_intensity(&self) -> f32 {
        let n = 16;
        let sum: f32 = (0..n * n)
            .map(|i| self.irradiance_at(Vec2::new(((i % n) as f32 + 0.5) / n as f32, ((i / n) as f32 + 0.5) / n as f32)).luminance())
            .sum();
        PI * sum / (n * n) as f32
    }

    /// The delta sample towards the light from `p` (normal `n`): module docs.
    #[must_use]
    pub fn sample_li(&self, p: Vec3, n: Vec3) -> Option<LightSample> {
        let local = self.to_local.point(p);
        if !(local.z > 0.0) {
            return None;
        }
        let (u, v) = project(local, self.tan_x, self.tan_y);
        if !((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)) {
            return None;
        }
        let mut s = super::point::sample_point_source(self.position, Rgb::ONE, p, n)?;
        let cos = -self.axis.dot(s.wi);
        s.li = self.irradiance_at(Vec2::new(u, v)) * (PI / (local.z * local.z * cos));
        Some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn projector(json: &str) -> ProjectorLight {
        ProjectorLight::from_props(&Props::from_json(json).unwrap()).unwrap()
    }

    /// A uniform projector lights the plane z = 1 in front of it with π · scale · E wherever its frame
    /// reaches, nothing beyond; a point twice as far (z = 2) gets a quarter.
    #[test]
    fn uniform_projection_lights_a_facing_plane_evenly() {
        let l = projector(r#"{"type": "projector", "fov": 60, "scale": 2, "irradiance": {"type": "rgb", "value": [1, 0.5, 0.25]}}"#);
        let up = Vec3::new(0.0, 0.0, -1.0);
        let t = 30f32.to_radians().tan();
        let want = Rgb::new(1.0, 0.5, 0.25) * (2.0 * PI);
        for (x, y) in [(0.0, 0.0), (0.9 * t, 0.0), (-0.5 * t, 0.7 * t)] {
            let s = l.sample_li(Vec3::new(x, y, 1.0), up).unwrap();
            assert!(s.delta && s.pdf == 1.0);
            // The irradiance on the plane: the sample's radiance-carrying value times the plane's cosine.
            let e = s.li * s.wi.dot(up);
            for c in 0..3 {
                assert!((e.0[c] - want.0[c]).abs() < 1e-5 * want.0[c], "at ({x}, {y}): {e:?}");
            }
        }
        assert!(l.sample_li(Vec3::new(1.1 * t, 0.0, 1.0), up).is_none(), "outside the frame");
        assert!(l.sample_li(Vec3::new(0.0, 0.0, -1.0), -up).is_none(), "behind the light");
        let far = l.sample_li(Vec3::new(0.0, 0.0, 2.0), up).unwrap().li;
        assert!((far.0[1] - PI * 0.25).abs() < 1e-5, "{far:?}");
    }

    /// The light arriving at points in front of `docs/scenes/emitter_projector_textured.xml`'s projector
    /// (flower.bmp, fov 32, scale 85.8), as Mitsuba 3.9.1 `scalar_rgb`'s `sample_direction` gives it (from
    /// `tools/projector_reference.py`): the image the right way round, and the scale.
    #[test]
    fn flower_projection_matches_mitsuba() {
        let file = "/work/shared/data/mitsuba-scenes/mitsuba-renderer__mitsuba-data/common/textures/flower.bmp";
        let m = Transform::look_at(Vec3::new(4.0, 0.0, 5.5), Vec3::new(0.0, 0.0, 1.0), Vec3::new(-1.0, 0.0, 0.0)).unwrap().matrix;
        let rows: Vec<String> = (0..4).map(|r| format!("{:?}", m.row(r).to_array())).collect();
        let l = projector(&format!(
            r#"{{"type": "projector", "fov": 32, "scale": 85.8, "irradiance": {{"type": "bitmap", "filename": "{file}"}},
                "to_world": [{}]}}"#,
            rows.join(", ")
        ));
        #[rustfmt::skip]
        #[allow(clippy::excessive_precision)] // Mitsuba's printed digits
        let mitsuba = [
            (-0.994442, -0.473741, 1.180765, [1.38982, 1.749869, 0.7662886]),
            (0.197189, -0.730568, 0.959876, [4.021882, 5.046559, 1.689778]),
            (-0.050277, -0.612470, 1.140746, [3.931263, 4.164472, 1.082058]),
            (-0.927187, -0.195789, 1.010044, [6.17017, 1.404089, 2.630645]),
            (-0.166493, 0.156237, 1.142703, [7.431003, 1.217876, 2.009953]),
            (1.095041, -0.388438, 1.089128, [2.223983, 3.375559, 0.9045529]),
            (0.470918, -0.373103, 0.700894, [1.586403, 2.251081, 0.8093376]),
            (1.136305, -0.362878, 0.888392, [1.305037, 2.033149, 0.4184165]),
            (0.940107, 0.153293, 0.982786, [2.001079, 2.222215, 1.323761]),
            (0.655865, -0.845377, 1.124179, [1.040859, 1.037962, 0.5348285]),
            (-0.301815, -0.736465, 1.096300, [3.065896, 3.133897, 0.660653]),
            (1.035513, -0.527056, 1.078054, [1.908542, 2.90512, 0.5001952]),
        ];
        for (x, y, z, want) in mitsuba {
            let li = l.sample_li(Vec3::new(x, y, z), Vec3::ZERO).unwrap().li;
            for c in 0..3 {
                assert!((li.0[c] - want[c]).abs() < 1e-4 * want[c], "at ({x}, {y}, {z}): {li:?} against {want:?}");
            }
        }
    }
}
