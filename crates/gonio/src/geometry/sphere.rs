//! `sphere` — Mitsuba's analytic sphere.
//!
//! | parameter      | type      | default   | meaning                                                  |
//! |----------------|-----------|-----------|----------------------------------------------------------|
//! | `center`       | point     | (0, 0, 0) | centre in object space                                   |
//! | `radius`       | float     | 1         | radius in object space                                   |
//! | `to_world`     | transform | identity  | object → world; must be a similarity (uniform scale)     |
//! | `flip_normals` | boolean   | false     | normals point inwards                                    |
//!
//! The quadratic is solved with the discriminant in the form of pbrt-v4 §6.8.5 (eq. 6.10),
//! b² − 4ac = 4a (r² − |o − (b/2a) d|²), which keeps its precision for distant spheres.

use super::interaction::{PositionSample, SurfaceInteraction};
use super::{Bounds3, PrimHit, Ray};
use crate::math::{Frame, Transform};
use crate::sampling::warp::sample_uniform_sphere;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A sphere in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    pub flip_normals: bool,
    /// World → object rotation, for texture coordinates.
    to_object: Transform,
}

impl Sphere {
    /// The sphere `to_world · translate(center) · scale(radius)` applied to the unit sphere. `None` when the
    /// transform is not a similarity (a sphere would become an ellipsoid).
    #[must_use]
    pub fn new(center: Vec3, radius: f32, to_world: Transform, flip_normals: bool) -> Option<Self> {
        let full = to_world.then_after(Transform::translate(center).then_after(Transform::scale(Vec3::splat(radius))?));
        let c = full.point(Vec3::ZERO);
        let axes = [full.vector(Vec3::X), full.vector(Vec3::Y), full.vector(Vec3::Z)];
        let r = axes[0].length();
        // 2026-11: 1e-3 relative tolerates rounding in user-written matrices, not real non-uniform scales.
        if axes.iter().any(|a| (a.length() - r).abs() > 1e-3 * r) || !(r > 0.0) || !c.is_finite() {
            return None;
        }
        Some(Sphere { center: c, radius: r, flip_normals, to_object: full.inverse() })
    }

    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        Bounds3 { min: self.center - Vec3::splat(self.radius), max: self.center + Vec3::splat(self.radius) }
    }

    #[must_use]
    pub fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        let oc = ray.o - self.center;
        let a = ray.d.length_squared();
        let b = 2.0 * ray.d.dot(oc);
        let c = oc.length_squared() - self.radius * self.radius;
        let v = oc - ray.d * (b / (2.0 * a));
        let disc = 4.0 * a * (self.radius * self.radius - v.length_squared());
        if disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        let q = if b < 0.0 { -0.5 * (b - root) } else { -0.5 * (b + root) };
        let (mut t0, mut t1) = (q / a, c / q);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let t = if t0 > 0.0 { t0 } else { t1 };
        (t > 0.0 && t < ray.tmax).then_some(PrimHit { t, uv: Vec2::ZERO })
    }

    /// The interaction at parameter `t` of `ray`; the point is re-projected onto the surface.
    #[must_use]
    pub fn interaction(&self, ray: &Ray, t: f32) -> SurfaceInteraction {
        let outward = (ray.at(t) - self.center).normalize();
        let p = self.center + outward * self.radius;
        let n = if self.flip_normals { -outward } else { outward };
        // Mitsuba's parametrisation: u = φ / 2π, v = θ / π in object space.
        let local = self.to_object.vector(outward).normalize();
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let uv = Vec2::new(phi / (2.0 * PI), local.z.clamp(-1.0, 1.0).acos() / PI);
        SurfaceInteraction { t, p, n, shading: Frame::from_normal(n), uv, shape: 0, prim: 0 }
    }

    /// A point uniformly distributed over the surface.
    #[must_use]
    pub fn sample_position(&self, u: Vec2) -> PositionSample {
        let outward = sample_uniform_sphere(u);
        let n = if self.flip_normals { -outward } else { outward };
        PositionSample { p: self.center + outward * self.radius, n, ng: n, pdf_area: 1.0 / self.area() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_from_outside_and_inside() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 5.0), 1.0, Transform::IDENTITY, false).unwrap();
        let h = s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z, f32::INFINITY)).unwrap();
        assert!((h.t - 4.0).abs() < 1e-5);
        let h = s.intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::Z, f32::INFINITY)).unwrap();
        assert!((h.t - 1.0).abs() < 1e-5);
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::X, f32::INFINITY)).is_none());
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::Z, 3.0)).is_none());
        let si = s.interaction(&Ray::new(Vec3::ZERO, Vec3::Z, f32::INFINITY), 4.0);
        assert!((si.n + Vec3::Z).length() < 1e-5);
    }

    #[test]
    fn to_world_scales_and_moves() {
        let t = Transform::translate(Vec3::X).then_after(Transform::scale(Vec3::splat(2.0)).unwrap());
        let s = Sphere::new(Vec3::ZERO, 1.5, t, false).unwrap();
        assert!((s.radius - 3.0).abs() < 1e-6 && (s.center - Vec3::X).length() < 1e-6);
        assert!(Sphere::new(Vec3::ZERO, 1.0, Transform::scale(Vec3::new(1.0, 2.0, 1.0)).unwrap(), false).is_none());
    }
}
