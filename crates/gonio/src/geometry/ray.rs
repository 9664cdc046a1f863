//! Rays, and where to start a ray that leaves a surface so that it does not hit that surface again.
//!
//! # Self-intersection (2026-11)
//! gonio offsets the origin of every spawned ray along the geometric normal, to the side the ray leaves
//! towards, by `RAY_OFFSET · (1 + max |pᵢ|)`: a distance relative to the magnitude of the hit point, because
//! the rounding error of an `f32` intersection grows with it. `RAY_OFFSET = 1e-4` is about 800 ulps of 1.0:
//! well above the error of the sphere (re-projected onto its surface) and triangle tests in scenes of size
//! 1–1000, and far below any feature of interest. pbrt-v4's error bounds (§6.8) are tighter; this scaled
//! offset is simpler and, like Mitsuba's ray epsilon, relative to the scene's scale.

use crate::math::lanes::{Real, V3};
use crate::math::simd::Float8;
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

/// The point o + t d of rays in lanes (or of one ray: the same operations as [`Ray::at`]).
#[inline(always)]
#[must_use]
pub fn ray_point<R: Real>(o: V3<R>, d: V3<R>, t: R) -> V3<R> {
    o.add(d.scale(t))
}

/// `p` moved off its surface (geometric normal `n`) towards the side of direction `w`.
#[inline]
#[must_use]
pub fn offset_origin(p: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    offset_origin_lanes::<f32>(p.into(), n.into(), w.into()).into()
}

/// [`offset_origin`] in lanes (the same operations, in the order glam's `Vec3` does them).
#[inline(always)]
#[must_use]
pub fn offset_origin_lanes<R: Real>(p: V3<R>, n: V3<R>, w: V3<R>) -> V3<R> {
    let scale = (p.x.abs().max(p.y.abs().max(p.z.abs())) + 1.0) * RAY_OFFSET;
    let side = R::select(n.dot(w).ge(R::splat(0.0)), R::splat(1.0), R::splat(-1.0));
    p.add(n.scale(scale * side))
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
    let r = spawn_ray_to_lanes::<f32>(p.into(), n.into(), target.into(), n_target.into());
    Ray::new(r.o.into(), r.d.into(), r.tmax)
}

/// Rays in lanes.
#[derive(Clone, Copy, Debug)]
pub struct RayLanes<R> {
    pub o: V3<R>,
    pub d: V3<R>,
    pub tmax: R,
}

impl RayLanes<Float8> {
    /// Eight rays in lanes (lane `i` is `rays[i]`; `bvh::PacketRays` takes them apart again).
    #[must_use]
    pub fn from_rays(rays: &[Ray; 8]) -> Self {
        let row = |f: fn(&Ray) -> f32| Float8::load(&rays.each_ref().map(f));
        RayLanes {
            o: V3::new(row(|r| r.o.x), row(|r| r.o.y), row(|r| r.o.z)),
            d: V3::new(row(|r| r.d.x), row(|r| r.d.y), row(|r| r.d.z)),
            tmax: row(|r| r.tmax),
        }
    }
}

/// [`spawn_ray_to`] in lanes.
#[inline(always)]
#[must_use]
pub fn spawn_ray_to_lanes<R: Real>(p: V3<R>, n: V3<R>, target: V3<R>, n_target: V3<R>) -> RayLanes<R> {
    let o = offset_origin_lanes(p, n, target.sub(p));
    let zero = R::splat(0.0);
    let point = n_target.x.eq(zero) & n_target.y.eq(zero) & n_target.z.eq(zero);
    let q = V3::select(point, target, offset_origin_lanes(target, n_target, p.sub(target)));
    let delta = q.sub(o);
    let dist = delta.length();
    // 2026-11: stop 1e-5 relative before the target so the light's own surface never occludes it.
    RayLanes { o, d: delta.div(dist), tmax: dist * (1.0 - 1e-5) }
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
