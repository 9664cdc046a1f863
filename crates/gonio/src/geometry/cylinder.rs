//! `cylinder` — Mitsuba's open cylinder (no caps) about the segment p0 → p1.
//!
//! | parameter      | type      | default   | meaning                                                 |
//! |----------------|-----------|-----------|---------------------------------------------------------|
//! | `p0`           | point     | (0, 0, 0) | object-space start of the centre line                   |
//! | `p1`           | point     | (0, 0, 1) | object-space end of the centre line                     |
//! | `radius`       | float     | 1         | radius in object space                                  |
//! | `flip_normals` | boolean   | false     | normals point inwards                                   |
//! | `to_world`     | transform | identity  | object → world; may rotate, move and scale, but scale x and y alike and not shear |
//!
//! As Mitsuba 3 (`src/shapes/cylinder.cpp`), the object is `to_world · translate(p0) · to_frame(p1 − p0) ·
//! scale(radius, radius, |p1 − p0|)` applied to the unit cylinder x² + y² = 1, 0 ≤ z ≤ 1, where
//! `to_frame(d)` takes +z to d/|d| and x, y to the tangents of [`crate::math::frame::tangents`] (Duff et
//! al. 2017, Mitsuba's `coordinate_system`). gonio keeps the world-space frame (orthonormal axes, radius r,
//! length L) and intersects in it, so rays keep their parameter t.
//!
//! - **Intersection**: the quadratic (dx² + dy²) t² + 2 (dx ox + dy oy) t + ox² + oy² − r² = 0 in the
//!   cylinder's frame, its discriminant in the form of pbrt-v4 §6.8.5 (eq. 6.10, as the sphere's) and the
//!   roots by the cancellation-free q = −½ (b ± √disc) (pbrt-v4 §B.2.3). The nearer root counts where its
//!   point lies within 0 ≤ z ≤ L, else the farther one (the inside seen through the open end), as Mitsuba's
//!   `ray_intersect_preliminary`.
//! - **uv** = (φ / 2π, z / L), φ ∈ [0, 2π) about the axis from the frame's x; ∂p/∂u = 2π (−y, x, 0),
//!   ∂p/∂v = (0, 0, L), n = ∂p/∂u × ∂p/∂v normalised (outward), the shading frame's s along ∂p/∂u, as
//!   Mitsuba's (`initialize_sh_frame`).
//! - **Area** 2π r L; **sampling** uniform by area, (r cos 2πu₁, r sin 2πu₁, L u₀), as Mitsuba's
//!   `sample_position`.
//! - A mirroring `to_world` turns the normals inwards, as for the sphere (the cross product above turns
//!   round).

use super::interaction::{PositionSample, SurfaceInteraction};
use super::{Bounds3, PrimHit, Ray};
use crate::math::frame::{tangents, tangents_along};
use crate::math::lanes::{Real, V3};
use crate::math::{Frame, Transform};
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::PI;

/// Why a `cylinder`'s parameters do not make a cylinder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CylinderError {
    /// p0 = p1: no axis.
    NoAxis,
    /// `to_world` shears or scales x and y differently: the cross-section would not be a circle.
    NotCircular,
}

/// An open cylinder in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Cylinder {
    /// World → the cylinder's frame (orthonormal: the axis is +z, the centre line from 0 to `length`).
    to_object: Transform,
    /// The cylinder's frame → world (the inverse of `to_object`, a rigid motion, possibly a mirror).
    to_world: Transform,
    radius: f32,
    length: f32,
    /// The normals point inwards (`flip_normals`, toggled by a mirroring `to_world`).
    flip_normals: bool,
}

impl Cylinder {
    /// The cylinder of Mitsuba's parameters (module doc).
    ///
    /// # Errors
    /// [`CylinderError`] when `p0 == p1` or `to_world` does not keep the cross-section a circle.
    pub fn new(p0: Vec3, p1: Vec3, radius: f32, to_world: Transform, flip_normals: bool) -> Result<Self, CylinderError> {
        debug_assert!(radius > 0.0, "the radius is checked by the loader");
        let d = p1 - p0;
        let len = d.length();
        if !(len > 0.0) || !len.is_finite() {
            return Err(CylinderError::NoAxis);
        }
        let n = d / len;
        let (s, t) = tangents::<f32>(n.into());
        // The object's axes in world space, scaled by the radius (x, y) and the length (z).
        let a = to_world.vector(Vec3::from(s) * radius);
        let b = to_world.vector(Vec3::from(t) * radius);
        let c = to_world.vector(n * len);
        let (ra, rb, length) = (a.length(), b.length(), c.length());
        // 2026-12: 1e-3 relative tolerates rounding in user-written matrices, not real shears or
        // non-uniform scales (Mitsuba warns at 1e-6 and renders something else).
        let tol = 1e-3;
        let circular = (ra - rb).abs() <= tol * ra
            && a.dot(b).abs() <= tol * ra * rb
            && a.dot(c).abs() <= tol * ra * length
            && b.dot(c).abs() <= tol * rb * length;
        if !circular || !(ra > 0.0) || !(length > 0.0) || !ra.is_finite() || !length.is_finite() {
            return Err(CylinderError::NotCircular);
        }
        let origin = to_world.point(p0);
        let frame = Mat4::from_cols((a / ra).extend(0.0), (b / rb).extend(0.0), (c / length).extend(0.0), origin.extend(1.0));
        let to_world_rigid = Transform::from_matrix(frame).ok_or(CylinderError::NotCircular)?;
        let flip_normals = flip_normals ^ to_world_rigid.flips_handedness();
        Ok(Cylinder { to_object: to_world_rigid.inverse(), to_world: to_world_rigid, radius: ra, length, flip_normals })
    }

    #[must_use]
    pub fn radius(&self) -> f32 {
        self.radius
    }

    #[must_use]
    pub fn length(&self) -> f32 {
        self.length
    }

    /// The bounding box of the two end circles (which holds the cylinder): per axis, a circle of radius r
    /// spanned by unit vectors u, v reaches r √(uᵢ² + vᵢ²) from its centre.
    #[must_use]
    pub fn bounds(&self) -> Bounds3 {
        let (u, v) = (self.to_world.vector(Vec3::X), self.to_world.vector(Vec3::Y));
        let reach = (u * u + v * v).powf(0.5) * self.radius;
        let (c0, c1) = (self.to_world.point(Vec3::ZERO), self.to_world.point(Vec3::new(0.0, 0.0, self.length)));
        Bounds3 { min: c0.min(c1) - reach, max: c0.max(c1) + reach }
    }

    #[must_use]
    pub fn area(&self) -> f32 {
        2.0 * PI * self.radius * self.length
    }

    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<PrimHit> {
        let o = self.to_object.point(ray.o);
        let d = self.to_object.vector(ray.d);
        let (t, hit) = intersect_cylinder::<f32>(o.into(), d.into(), self.radius, self.length, ray.tmax);
        hit.then_some(PrimHit { t, uv: Vec2::ZERO })
    }

    /// The point of the surface nearest to world point `p` (its object-space (x, y) moved onto the circle,
    /// as Mitsuba moves a hit along the normal), the outward unit normal there and the object-space point.
    fn surface(&self, p: Vec3) -> (Vec3, Vec3, Vec3) {
        let local = self.to_object.point(p);
        let rho = local.x.hypot(local.y);
        let radial = if rho > 0.0 { Vec3::new(local.x / rho, local.y / rho, 0.0) } else { Vec3::X };
        let on = Vec3::new(radial.x * self.radius, radial.y * self.radius, local.z);
        (self.to_world.point(on), self.to_world.vector(radial), on)
    }

    /// ∂p/∂u = 2π (−y, x, 0) and ∂p/∂v = (0, 0, L) (module doc) at the surface point `p`, in world space.
    #[must_use]
    pub fn uv_partials(&self, p: Vec3) -> (Vec3, Vec3) {
        let (_, _, local) = self.surface(p);
        (self.to_world.vector(Vec3::new(-local.y, local.x, 0.0) * (2.0 * PI)), self.to_world.vector(Vec3::new(0.0, 0.0, self.length)))
    }

    /// The interaction at parameter `t` of `ray`; the point is re-projected onto the surface.
    #[must_use]
    pub fn interaction(&self, ray: &Ray, t: f32, uv: bool) -> SurfaceInteraction {
        let (p, outward, local) = self.surface(ray.at(t));
        let n = if self.flip_normals { -outward } else { outward };
        let uv = if uv {
            let mut phi = local.y.atan2(local.x);
            if phi < 0.0 {
                phi += 2.0 * PI;
            }
            Vec2::new(phi / (2.0 * PI), local.z / self.length)
        } else {
            Vec2::ZERO
        };
        // ∂p/∂u = 2π (−y, x, 0) in the frame.
        let dp_du = self.to_world.vector(Vec3::new(-local.y, local.x, 0.0) * (2.0 * PI));
        let (s, tangent) = tangents_along::<f32>(n.into(), dp_du.into());
        SurfaceInteraction { t, p, n, shading: Frame { s: s.into(), t: tangent.into(), n }, uv, shape: 0, prim: 0 }
    }

    /// A point uniformly distributed over the surface, density 1 / area.
    #[must_use]
    pub fn sample_position(&self, u: Vec2) -> PositionSample {
        let (sin, cos) = (2.0 * PI * u.y).sin_cos();
        let p = self.to_world.point(Vec3::new(cos * self.radius, sin * self.radius, u.x * self.length));
        let outward = self.to_world.vector(Vec3::new(cos, sin, 0.0));
        let n = if self.flip_normals { -outward } else { outward };
        PositionSample { p, n, ng: n, pdf_area: 1.0 / self.area() }
    }
}

/// The hit in (0, tmax) of the ray o + t d with the open cylinder x² + y² = r², 0 ≤ z ≤ `length` (in its
/// frame), in lanes: the nearer root where its point lies between the ends, else the farther one (module
/// doc); the distance and whether it is hit. Rays along the axis (dx = dy = 0) miss.
#[inline(always)]
#[must_use]
pub fn intersect_cylinder<R: Real>(o: V3<R>, d: V3<R>, radius: R, length: R, tmax: R) -> (R, R::Mask) {
    let zero = R::splat(0.0);
    let a = d.x * d.x + d.y * d.y;
    let b = (d.x * o.x + d.y * o.y) * 2.0;
    let r2 = radius * radius;
    let c = o.x * o.x + o.y * o.y - r2;
    // b² − 4ac = 4a (r² − |o⊥ − (b/2a) d⊥|²): the distance of the axis from the ray's closest point,
    // without the cancellation of b² − 4ac for distant origins (pbrt-v4 eq. 6.10).
    let k = b / (a * 2.0);
    let (vx, vy) = (o.x - d.x * k, o.y - d.y * k);
    let disc = a * 4.0 * (r2 - (vx * vx + vy * vy));
    let root = disc.max(zero).sqrt();
    let q = R::select(b.lt(zero), (b - root) * -0.5, (b + root) * -0.5);
    let (t0, t1) = (q / a, c / q);
    let swap = t0.gt(t1);
    let (near, far) = (R::select(swap, t1, t0), R::select(swap, t0, t1));
    let within = |t: R| {
        let z = o.z + d.z * t;
        t.gt(zero) & t.lt(tmax) & z.ge(zero) & z.le(length)
    };
    let (near_ok, far_ok) = (within(near), within(far));
    let t = R::select(near_ok, near, far);
    (t, a.gt(zero) & disc.ge(zero) & (near_ok | far_ok))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_cylinder_hits() {
        let c = Cylinder::new(Vec3::ZERO, Vec3::Z, 1.0, Transform::IDENTITY, false).unwrap();
        // From outside, through the side: the near wall.
        let h = c.intersect(&Ray::new(Vec3::new(-3.0, 0.0, 0.5), Vec3::X, f32::INFINITY)).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        // From inside: the far wall.
        let h = c.intersect(&Ray::new(Vec3::new(0.0, 0.0, 0.5), Vec3::X, f32::INFINITY)).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
        // Along the axis: no wall.
        assert!(c.intersect(&Ray::new(Vec3::new(0.2, 0.0, -1.0), Vec3::Z, f32::INFINITY)).is_none());
    }
}
