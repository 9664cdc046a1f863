//! `perspective` — Mitsuba's pinhole camera —, `thinlens` and `orthographic`.
//!
//! | parameter   | type      | default  | meaning                                                       |
//! |-------------|-----------|----------|---------------------------------------------------------------|
//! | `fov`       | float     | —        | field of view in degrees along `fov_axis`                     |
//! | `fov_axis`  | string    | `x`      | `x`, `y`, `smaller`, `larger` or `diagonal`                   |
//! | `focal_length` | string | `50mm`   | instead of `fov`: a lens on 35 mm film (36 × 24 mm), giving the diagonal field of view 2 atan(√(36² + 24²) / 2f) — Mitsuba's default when neither is given |
//! | `to_world`  | transform | identity | camera → world                                                |
//! | `near_clip` | float     | 0.01     | rays start at this depth                                      |
//! | `far_clip`  | float     | 10000    | and end at this one                                           |
//! | `focus_distance` | float | 0     | accepted and ignored: Mitsuba 3's pinhole `perspective` reads it too (for `thinlens`-style scenes) and its image does not depend on it |
//!
//! `thinlens` takes the parameters of `perspective` (its `focus_distance` now used) and:
//!
//! | parameter         | type  | default    | meaning                                                     |
//! |-------------------|-------|------------|-------------------------------------------------------------|
//! | `aperture_radius` | float | (required) | radius of the lens in scene units; 0 is a pinhole           |
//! | `focus_distance`  | float | `far_clip` | distance from the lens to the plane in focus (camera z), > 0 |
//!
//! As Mitsuba 3's (`src/sensors/thinlens.cpp`): the lens point a = `aperture_radius` · (Shirley–Chiu's
//! concentric map of the lens sample) in the plane z = 0, the point in focus f = `focus_distance` ·
//! ((1 − 2 sx) tan(fov_x/2), (1 − 2 sy) tan(fov_y/2), 1) (the pinhole's direction scaled to the focal
//! plane), the ray from a towards f, started at camera depth `near_clip` and ended at `far_clip`. So a
//! point on the focal plane is seen through the whole lens from one film position, and a point at depth z
//! from a disk of film positions — on the plane z = 1, of diameter 2 A |z − f| / (z f), the thin lens's
//! circle of confusion (pbrt-v4 §5.2.3). The lens takes two numbers of the sample's stream after the
//! pixel offset; a pinhole takes none. `to_world` must not scale (Mitsuba refuses it too: the lens would
//! scale with it).
//!
//! `orthographic` takes `to_world`, `near_clip` and `far_clip`: as Mitsuba 3's (`orthographic_projection`),
//! film position (sx, sy) starts its ray at (1 − 2 sx, (1 − 2 sy) / aspect, near_clip) in camera space (the
//! image spans [−1, 1] across, so a `<scale>` in `to_world` sets the view's size) and every ray runs along
//! `to_world · +z` (normalised), `far_clip − near_clip` long.
//!
//! In camera space the camera looks down +z with +y up and **+x to the left of the image** (Mitsuba's
//! convention; `lookat`'s local x is up × direction). A film position (sx, sy) ∈ [0, 1]², (0, 0) the
//! top-left corner, maps to the direction ((1 − 2 sx) tan(fov_x/2), (1 − 2 sy) tan(fov_y/2), 1).

use crate::error::{Error, Result};
use crate::geometry::ray::RayLanes;
use crate::geometry::Ray;
use crate::math::lanes::{Real, V3};
use crate::math::Transform;
use crate::props::Props;
use crate::sampling::warp::concentric_disk;
use glam::{Vec2, Vec3};

/// A perspective or orthographic camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    to_world: Transform,
    /// Half the image's extent in camera space: on the plane z = 1 (perspective: tan of half the field of
    /// view), or on the near plane (orthographic: 1 and 1 / aspect).
    tan_half_x: f32,
    tan_half_y: f32,
    near: f32,
    far: f32,
    /// For an orthographic camera, the rays' world direction (`to_world · +z`, normalised).
    orthographic: Option<Vec3>,
    /// The thin lens's radius (0: a pinhole) and the camera-space depth in focus.
    aperture_radius: f32,
    focus_distance: f32,
}

impl Camera {
    /// A camera for a film of `width × height` pixels with field of view `fov_deg` along `axis`.
    #[allow(clippy::too_many_arguments)] // one argument per plugin parameter, as in the table above
    pub fn new(to_world: Transform, fov_deg: f32, axis: &str, width: u32, height: u32, near: f32, far: f32, at: &str) -> Result<Self> {
        let (tan_half_x, tan_half_y) =
            crate::math::perspective::tan_half_angles(fov_deg, axis, width as f32 / height as f32).map_err(|e| Error::spec(at, e))?;
        Ok(Camera { to_world, tan_half_x, tan_half_y, near, far, orthographic: None, aperture_radius: 0.0, focus_distance: far })
    }

    /// An orthographic camera for a film of `width × height` pixels (module docs); `None` when `to_world`
    /// maps +z to nothing.
    #[must_use]
    pub fn orthographic(to_world: Transform, width: u32, height: u32, near: f32, far: f32) -> Option<Self> {
        let dir = to_world.vector(Vec3::Z).try_normalize()?;
        let aspect = width as f32 / height as f32;
        Some(Camera {
            to_world,
            tan_half_x: 1.0,
            tan_half_y: 1.0 / aspect,
            near,
            far,
            orthographic: Some(dir),
            aperture_radius: 0.0,
            focus_distance: far,
        })
    }

    /// This camera with a thin lens of radius `aperture_radius` (0: a pinhole) focused at camera depth
    /// `focus_distance` (module doc). `to_world` should be a rigid motion.
    #[must_use]
    pub fn with_thin_lens(self, aperture_radius: f32, focus_distance: f32) -> Self {
        debug_assert!(aperture_radius >= 0.0 && focus_distance > 0.0);
        Camera { aperture_radius, focus_distance, ..self }
    }

    /// Whether rays need a lens sample: a thin lens of radius > 0 (see [`Self::rays_through_lens`]).
    #[inline]
    #[must_use]
    pub fn has_lens(&self) -> bool {
        self.aperture_radius > 0.0
    }

    /// Read `perspective`, `thinlens` or `orthographic` parameters (the film size comes from the nested film).
    pub fn from_props(p: &Props, width: u32, height: u32) -> Result<Self> {
        if p.plugin_type() == "orthographic" {
            let (near, far) = (p.float_positive("near_clip", 1e-2)?, p.float_positive("far_clip", 1e4)?);
            if far <= near {
                return Err(Error::spec(p.at_param("far_clip"), format!("`far_clip` ({far}) must exceed `near_clip` ({near})")));
            }
            return Camera::orthographic(p.transform("to_world")?, width, height, near, far)
                .ok_or_else(|| Error::spec(p.at_param("to_world"), "`to_world` maps the viewing direction +z to zero"));
        }
        let thin_lens = p.plugin_type() == "thinlens";
        if p.plugin_type() != "perspective" && !thin_lens {
            return Err(Error::spec(
                p.at(),
                format!("unsupported sensor `{}` (gonio has: perspective, thinlens, orthographic)", p.plugin_type()),
            ));
        }
        let (fov, axis) = p.field_of_view()?;
        let near = p.float_positive("near_clip", 1e-2)?;
        let far = p.float_positive("far_clip", 1e4)?;
        if far <= near {
            return Err(Error::spec(p.at_param("far_clip"), format!("`far_clip` ({far}) must exceed `near_clip` ({near})")));
        }
        let to_world = p.transform("to_world")?;
        let camera = Camera::new(to_world, fov, &axis, width, height, near, far, p.at_param("fov_axis"))?;
        if !thin_lens {
            // A pinhole has everything in focus: Mitsuba's `perspective` accepts the parameter and ignores it.
            let _ = p.float_in("focus_distance", 0.0, 0.0, f32::MAX)?;
            return Ok(camera);
        }
        if !p.has("aperture_radius") {
            return Err(Error::spec(p.at(), "`thinlens` needs an `aperture_radius` (the lens radius in scene units; 0 for a pinhole)"));
        }
        // Mitsuba makes 0 its smallest positive float, which renders as a pinhole; gonio takes 0 as a pinhole.
        let aperture = p.float_in("aperture_radius", 0.0, 0.0, f32::MAX)?;
        let focus = p.float_positive("focus_distance", far)?;
        // 2026-12: 1e-3 tolerates rounding in a written `lookat` or matrix, not a real scale.
        if [Vec3::X, Vec3::Y, Vec3::Z].iter().any(|&a| (to_world.vector(a).length() - 1.0).abs() > 1e-3) {
            return Err(Error::spec(
                p.at_param("to_world"),
                "a `thinlens` sensor's `to_world` must not scale (rotate and translate only; the lens would scale with it)",
            ));
        }
        Ok(camera.with_thin_lens(aperture, focus))
    }

    /// The primary ray through film position `s` ∈ [0, 1]² (top-left origin) and, for a thin lens, the
    /// lens centre.
    #[inline]
    #[must_use]
    pub fn ray(&self, s: Vec2) -> Ray {
        self.ray_through_lens(s, Vec2::splat(0.5))
    }

    /// The primary ray through film position `s` and lens sample `u` ∈ [0, 1]² (which a pinhole ignores).
    #[inline]
    #[must_use]
    pub fn ray_through_lens(&self, s: Vec2, u: Vec2) -> Ray {
        let r = self.rays_through_lens(s.x, s.y, u.x, u.y);
        Ray::new(r.o.into(), r.d.into(), r.tmax)
    }

    /// [`Self::ray_through_lens`] in lanes: film positions (`x`, `y`), lens samples (`ux`, `uy`).
    #[inline(always)]
    #[must_use]
    pub fn rays_through_lens<R: Real>(&self, x: R, y: R, ux: R, uy: R) -> RayLanes<R> {
        if !self.has_lens() {
            return self.rays(x, y);
        }
        let (one, two) = (R::splat(1.0), R::splat(2.0));
        let (lx, ly) = concentric_disk(ux, uy);
        let (ax, ay) = (lx * R::splat(self.aperture_radius), ly * R::splat(self.aperture_radius));
        // The point in focus seen from this film position, on the plane z = focus_distance.
        let f = R::splat(self.focus_distance);
        let (fx, fy) = ((one - two * x) * R::splat(self.tan_half_x) * f, (one - two * y) * R::splat(self.tan_half_y) * f);
        let d = V3::new(fx - ax, fy - ay, f).normalize();
        // From the lens point to camera depth near_clip, and on to far_clip.
        let inv_z = one / d.z;
        let o = V3::new(ax, ay, R::splat(0.0)).add(d.scale(R::splat(self.near) * inv_z));
        RayLanes { o: self.to_world.point_lanes(o), d: self.to_world.vector_lanes(d), tmax: R::splat(self.far - self.near) * inv_z }
    }

    /// [`Self::ray`] for film positions (`x`, `y`) in lanes ([`Real`]: one `f32` or eight).
    #[inline(always)]
    #[must_use]
    pub fn rays<R: Real>(&self, x: R, y: R) -> RayLanes<R> {
        let (one, two) = (R::splat(1.0), R::splat(2.0));
        if let Some(dir) = self.orthographic {
            let near =
                V3::new((one - two * x) * R::splat(self.tan_half_x), (one - two * y) * R::splat(self.tan_half_y), R::splat(self.near));
            return RayLanes { o: self.to_world.point_lanes(near), d: V3::splat(dir), tmax: R::splat(self.far - self.near) };
        }
        let local = V3::new((one - two * x) * R::splat(self.tan_half_x), (one - two * y) * R::splat(self.tan_half_y), one);
        let d = self.to_world.vector_lanes(local);
        let len = d.length();
        let o = V3::splat(self.to_world.point(Vec3::ZERO)).add(d.scale(R::splat(self.near)));
        RayLanes { o, d: d.div(len), tmax: R::splat(self.far - self.near) * len }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn left_of_the_image_is_camera_plus_x() {
        let look = Transform::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y).unwrap();
        let cam = Camera::new(look, 90.0, "x", 2, 1, 1e-2, 1e4, "t").unwrap();
        // Looking down −z with +y up, the left edge of the image sees world −x, the top sees +y.
        let left = cam.ray(Vec2::new(0.0, 0.5));
        assert!(left.d.x < 0.0 && (left.d.x - left.d.z).abs() < 1e-5, "{:?}", left.d);
        let top = cam.ray(Vec2::new(0.5, 0.0));
        assert!(top.d.y > 0.0 && (top.d.y - 0.5 * -top.d.z).abs() < 1e-5, "{:?}", top.d);
        assert!(Camera::new(look, 90.0, "z", 2, 1, 1e-2, 1e4, "t").is_err());
    }

    /// `rays`, on one `f32` (`ray`) and in eight lanes, gives bit for bit the ray that glam's `Vec3` and
    /// `Mat4` operations give: direction (1 − 2s) · tan(fov/2) in camera space taken to world space and
    /// normalised by division, origin at the near plane, `tmax` the far plane.
    #[test]
    fn rays_in_lanes_match() {
        use crate::math::simd::Float8;
        let look = Transform::look_at(Vec3::new(0.3, 2.0, 5.0), Vec3::new(0.0, 0.5, 0.0), Vec3::Y).unwrap();
        let cam = Camera::new(look, 39.3, "x", 400, 160, 0.1, 1e3, "t").unwrap();
        let mut rng = crate::sampling::Pcg32::new(4, 1);
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for _ in 0..100 {
            let s: [Vec2; 8] = std::array::from_fn(|_| rng.next_vec2());
            let lanes = cam.rays(Float8::from_fn(|i| s[i].x), Float8::from_fn(|i| s[i].y));
            for (i, s) in s.iter().enumerate() {
                let local = Vec3::new((1.0 - 2.0 * s.x) * cam.tan_half_x, (1.0 - 2.0 * s.y) * cam.tan_half_y, 1.0);
                let d = look.vector(local);
                let want = Ray::new(look.point(Vec3::ZERO) + d * cam.near, d / d.length(), (cam.far - cam.near) * d.length());
                let one = cam.ray(*s);
                assert_eq!((bits(one.o), bits(one.d), one.tmax.to_bits()), (bits(want.o), bits(want.d), want.tmax.to_bits()));
                let lane = |v: &V3<Float8>| Vec3::new(v.x.lane(i), v.y.lane(i), v.z.lane(i));
                assert_eq!(
                    (bits(lane(&lanes.o)), bits(lane(&lanes.d)), lanes.tmax.lane(i).to_bits()),
                    (bits(want.o), bits(want.d), want.tmax.to_bits())
                );
            }
        }
    }

    /// An orthographic camera scaled by 1.5 and looking along −x from (5, 0, 3): the image's corners start
    /// their rays where Mitsuba 3's `orthographic_projection` puts them, all rays parallel.
    #[test]
    fn orthographic_rays_start_on_the_scaled_near_plane() {
        let to_world = Transform::look_at(Vec3::new(5.0, 0.0, 3.0), Vec3::new(0.0, 0.0, 3.0), Vec3::Z)
            .unwrap()
            .then_after(Transform::scale(Vec3::new(1.5, 1.5, 1.0)).unwrap());
        let cam = Camera::orthographic(to_world, 200, 100, 1.0, 1000.0).unwrap();
        // Camera +x is the image's left: world −y here (looking along −x with +z up); +y is world +z.
        for (s, want) in [
            (Vec2::new(0.0, 0.0), Vec3::new(4.0, -1.5, 3.75)),
            (Vec2::new(1.0, 1.0), Vec3::new(4.0, 1.5, 2.25)),
            (Vec2::new(0.5, 0.5), Vec3::new(4.0, 0.0, 3.0)),
        ] {
            let r = cam.ray(s);
            assert!((r.o - want).length() < 1e-5 && (r.d - Vec3::NEG_X).length() < 1e-6, "{s}: {:?} {:?}", r.o, r.d);
            assert!((r.tmax - 999.0).abs() < 1e-3);
        }
        let p = Props::from_json(r#"{"type": "orthographic", "near_clip": 1, "far_clip": 1000}"#).unwrap();
        assert_eq!(Camera::from_props(&p, 200, 100).unwrap(), Camera::orthographic(Transform::IDENTITY, 200, 100, 1.0, 1000.0).unwrap());
        p.finish().unwrap();
        let p = Props::from_json(r#"{"type": "orthographic", "fov": 30}"#).unwrap();
        let _ = Camera::from_props(&p, 4, 4).unwrap();
        assert!(p.finish().unwrap_err().to_string().contains("unknown parameter `fov` for `orthographic`"));
    }

    /// Mitsuba's pinhole accepts `focus_distance` (scenes written for `thinlens` give it); the camera is
    /// the same with it as without.
    #[test]
    fn focus_distance_is_accepted_and_changes_nothing() {
        let plain = Props::from_json(r#"{"type": "perspective", "fov": 40}"#).unwrap();
        let focused = Props::from_json(r#"{"type": "perspective", "fov": 40, "focus_distance": 6.0}"#).unwrap();
        let (a, b) = (Camera::from_props(&plain, 64, 48).unwrap(), Camera::from_props(&focused, 64, 48).unwrap());
        focused.finish().unwrap();
        assert_eq!(a, b);
        let negative = Props::from_json(r#"{"type": "perspective", "focus_distance": -1}"#).unwrap();
        assert!(Camera::from_props(&negative, 4, 4).unwrap_err().to_string().contains("focus_distance"));
    }

    /// Horizontal fields of view Mitsuba 3.9.1 reports (`x_fov`) for these sensors.
    #[test]
    fn fields_of_view_match_mitsuba() {
        let x_fov = |xml: &str, w: u32, h: u32| {
            let p = Props::from_json(xml).unwrap();
            let c = Camera::from_props(&p, w, h).unwrap();
            2.0 * c.tan_half_x.atan().to_degrees()
        };
        for (xml, w, h, want) in [
            (r#"{"type": "perspective"}"#, 48, 48, 34.022_057),
            (r#"{"type": "perspective"}"#, 64, 32, 42.311_714),
            (r#"{"type": "perspective"}"#, 32, 64, 21.902_138),
            (r#"{"type": "perspective", "fov": 30, "fov_axis": "diagonal"}"#, 64, 32, 26.954_737),
            (r#"{"type": "perspective", "fov": 30, "fov_axis": "smaller"}"#, 64, 32, 56.373_57),
        ] {
            let got = x_fov(xml, w, h);
            assert!((got - want).abs() < 1e-3, "{xml} {w}×{h}: {got} vs {want}");
        }
    }
}
