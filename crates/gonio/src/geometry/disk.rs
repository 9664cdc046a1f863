//! `disk` — Mitsuba's unit disk in the z = 0 plane of object space, normal +z.
//!
//! | parameter      | type      | default  | meaning                    |
//! |----------------|-----------|----------|----------------------------|
//! | `to_world`     | transform | identity | object → world             |
//! | `flip_normals` | boolean   | false    | the normal points along −z |
//!
//! Rays are intersected in object space; uv = (r, φ/2π) as Mitsuba's disk.

use super::interaction::{PositionSample, SurfaceInteraction};
use super::{Bounds3, PrimHit, Ray};
use crate::math::{Frame, Transform};
use crate::sampling::warp::sample_uniform_disk_concentric;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A (possibly sheared) disk in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Disk {
    to_world: Transform,
    /// World-space unit normal (after `flip_normals`).
    normal: Vec3,
    area: f32,
}

impl Disk {
    #[must_use]
    pub fn new(to_world: Transform, flip_normals: bool) -> Self {
        let n = to_world.normal(Vec3::Z).normalize();
        let area = PI * to_world.vector(Vec3::X).cross(to_world.vector(Vec3::Y)).length();
        Disk { to_world, normal: if flip_normals { -n } else { n }, area }
    }

    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        // The bounding box of the transformed unit square holds the transformed disk.
        [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
            .iter()
            .fold(Bounds3::EMPTY, |b, &(x, y)| b.with_point(self.to_world.point(Vec3::new(x, y, 0.0))))
    }

    #[must_use]
    pub fn area(&self) -> f32 {
        self.area
    }

    /// The world-space unit normal (the side an area light on the disk emits to).
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        let o = self.to_world.inverse().point(ray.o);
        let d = self.to_world.inverse().vector(ray.d);
        if d.z == 0.0 {
            return None;
        }
        let t = -o.z / d.z;
        if !(t > 0.0 && t < ray.tmax) {
            return None;
        }
        let q = o + d * t;
        (q.x * q.x + q.y * q.y <= 1.0).then_some(PrimHit { t, uv: Vec2::new(q.x, q.y) })
    }

    /// The shading frame at object-space (x, y): Mitsuba 3's (`src/shapes/disk.cpp`), whose ∂p/∂u is the
    /// radial direction (u is the radius), [`Frame::from_normal`]'s at the centre.
    fn frame(&self, x: f32, y: f32) -> Frame {
        Frame::from_normal_and_dp_du(self.normal, self.to_world.vector(Vec3::new(x, y, 0.0)))
    }

    /// ∂p/∂u and ∂p/∂v at the surface point `p` for u = r, v = φ/2π: (cos φ, sin φ, 0) and 2π (−y, x, 0)
    /// in object space (φ = 0 at the centre), mapped to world space.
    #[must_use]
    pub fn uv_partials(&self, p: Vec3) -> (Vec3, Vec3) {
        let q = self.to_world.inverse().point(p);
        let r = q.x.hypot(q.y);
        let radial = if r > 0.0 { Vec3::new(q.x / r, q.y / r, 0.0) } else { Vec3::X };
        (self.to_world.vector(radial), self.to_world.vector(Vec3::new(-q.y, q.x, 0.0) * (2.0 * PI)))
    }

    /// The interaction for a hit whose `uv` holds the object-space (x, y).
    #[must_use]
    pub fn interaction(&self, ray: &Ray, hit: &PrimHit, uv: bool) -> SurfaceInteraction {
        let (x, y) = (hit.uv.x, hit.uv.y);
        let p = self.to_world.point(Vec3::new(x, y, 0.0));
        let _ = ray;
        let uv = if uv {
            let mut phi = y.atan2(x);
            if phi < 0.0 {
                phi += 2.0 * PI;
            }
            Vec2::new((x * x + y * y).sqrt(), phi / (2.0 * PI))
        } else {
            Vec2::ZERO
        };
        SurfaceInteraction { t: hit.t, p, n: self.normal, shading: self.frame(x, y), uv, shape: 0, prim: 0 }
    }

    /// A point uniformly distributed over the disk (an affine map keeps uniform densities uniform).
    #[must_use]
    pub fn sample_position(&self, u: Vec2) -> PositionSample {
        let q = sample_uniform_disk_concentric(u);
        let p = self.to_world.point(Vec3::new(q.x, q.y, 0.0));
        PositionSample { p, n: self.normal, ng: self.normal, pdf_area: 1.0 / self.area }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first shading tangent is Mitsuba 3's ∂p/∂u, the radial direction (u is the radius), Duff's at
    /// the centre; the values were read from Mitsuba 3.9.1 (`scalar_rgb`, `si.sh_frame.s`), for the disk
    /// turned 30° about z too (the radial direction does not turn with it).
    #[test]
    fn shading_tangent_is_mitsubas() {
        for to_world in [Transform::IDENTITY, Transform::rotate(Vec3::Z, 30.0).unwrap()] {
            let d = Disk::new(to_world, false);
            for (x, y, s) in
                [(0.3, 0.4, Vec3::new(0.6, 0.8, 0.0)), (-0.5, 0.1, Vec3::new(-0.980_580_7, 0.196_116_13, 0.0)), (0.0, 0.0, Vec3::X)]
            {
                let r = Ray::new(Vec3::new(x, y, 3.0), -Vec3::Z, 10.0);
                let f = d.interaction(&r, &d.intersect(&r).unwrap(), true).shading;
                assert!((f.s - s).length() < 1e-5 && (f.s.cross(f.t) - f.n).length() < 1e-5, "at ({x}, {y}): {}", f.s);
            }
        }
    }

    #[test]
    fn scaled_disk_area_and_hit() {
        let d = Disk::new(Transform::scale(Vec3::new(2.0, 3.0, 1.0)).unwrap(), false);
        assert!((d.area() - 6.0 * PI).abs() < 1e-4);
        let r = Ray::new(Vec3::new(1.9, 0.0, 1.0), -Vec3::Z, 10.0);
        let h = d.intersect(&r).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
        assert!(d.intersect(&Ray::new(Vec3::new(2.1, 0.0, 1.0), -Vec3::Z, 10.0)).is_none());
        assert!((d.interaction(&r, &h, true).n - Vec3::Z).length() < 1e-6);
    }
}
