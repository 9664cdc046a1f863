//! Rays, and where to start a ray that leaves a surface so that it does not hit that surface again.
//!
//! # Self-intersection (2026-11)
//! gonio offsets the origin of every spawned ray along the geometric normal, to the side the ray leaves
//! towards, by `RAY_OFFSET · (1 + max |pᵢ|)`: a distance relative to the magnitude of the hit point, because
//! the rounding error of an `f32` intersection grows with it. `RAY_OFFSET = 1e-4` is about 800 ulps of 1.0:
//! well above the error of the sphere (re-projected onto its surface) and triangle tests in scenes of size
//! 1–1000, and far below any feature of interest. pbrt-v4's error bounds (§6.8) are tighter; this scaled
//! offset is simpler and, like Mitsuba's ray epsilon, relative to the scene's scale.

use glam::Vec3;

/// Relative offset of spawned ray origins (see the module docs).
pub const RAY_OFFSET: f32 = 1e-4;

/// A ray `o + t d` for `t` in (0, `tmax`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub o: Vec3,
    /// Direction; unit length for camera and scattered rays.
    pub d: Vec3,
    pub tmax: f32,
}

impl Ray {
    #[inline]
    #[must_use]
    pub fn new(o: Vec3, d: Vec3, tmax: f32) -> Self {
        Ray { o, d, tmax }
    }

    #[inline]
    #[must_use]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// `p` moved off its surface (geometric normal `n`) towards the side of direction `w`.
#[inline]
#[must_use]
pub fn offset_origin(p: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let scale = RAY_OFFSET * (1.0 + p.abs().max_element());
    let side = if n.dot(w) >= 0.0 { 1.0 } else { -1.0 };
    p + n * (scale * side)
}

/// A ray leaving `p` (on a surface with geometric normal `n`) in unit direction `d`.
#[inline]
#[must_use]
pub fn spawn_ray(p: Vec3, n: Vec3, d: Vec3) -> Ray {
    Ray::new(offset_origin(p, n, d), d, f32::INFINITY)
}

/// A shadow ray from `p` (normal `n`) to `target` (on a surface with normal `n_target`, or a point light
/// when `n_target` is zero). Both ends are offset; `tmax` stops just short of the target.
#[inline]
#[must_use]
pub fn spawn_ray_to(p: Vec3, n: Vec3, target: Vec3, n_target: Vec3) -> Ray {
    let o = offset_origin(p, n, target - p);
    let q = if n_target == Vec3::ZERO { target } else { offset_origin(target, n_target, p - target) };
    let delta = q - o;
    let dist = delta.length();
    // 2026-11: stop 1e-5 relative before the target so the light's own surface never occludes it.
    Ray::new(o, delta / dist, dist * (1.0 - 1e-5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_goes_to_the_side_of_the_direction() {
        let p = Vec3::new(10.0, 0.0, 0.0);
        let o = offset_origin(p, Vec3::Z, Vec3::new(0.3, 0.0, -1.0));
        assert!(o.z < 0.0 && o.z > -1e-2);
        let r = spawn_ray_to(Vec3::ZERO, Vec3::Z, Vec3::new(0.0, 0.0, 2.0), -Vec3::Z);
        assert!(r.o.z > 0.0 && r.at(r.tmax).z < 2.0 && (r.d - Vec3::Z).length() < 1e-6);
    }
}
