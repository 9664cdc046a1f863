//! `sphere` — Mitsuba's analytic sphere.
//!
//! | parameter      | type      | default   | meaning                                                  |
//! |----------------|-----------|-----------|----------------------------------------------------------|
//! | `center`       | point     | (0, 0, 0) | centre in object space                                   |
//! | `radius`       | float     | 1         | radius in object space                                   |
//! | `to_world`     | transform | identity  | object → world; must be a similarity (uniform scale)     |
//! | `flip_normals` | boolean   | false     | normals point inwards                                    |
//!
//! A mirroring `to_world` turns the normals inwards too, as Mitsuba 3 does (observed with 3.9.1).
//!
//! The quadratic is solved with the discriminant in the form of pbrt-v4 §6.8.5 (eq. 6.10),
//! b² − 4ac = 4a (r² − |o − (b/2a) d|²), which keeps its precision for distant spheres.
//!
//! The shading frame is Mitsuba 3's (`src/shapes/sphere.cpp`, `compute_surface_interaction`, then
//! `SurfaceInteraction::initialize_sh_frame`): `s` is ∂p/∂u of the parameterisation u = φ/2π, v = θ/π
//! (the direction of increasing φ about the object's z axis) made orthogonal to `n`, and `t = n × s`, so an
//! anisotropic model's `alpha_u` runs along the parallels and its highlight converges at the poles. At the
//! poles, where ∂p/∂u vanishes, the frame is [`Frame::from_normal`]'s, as Mitsuba's is there.

use super::interaction::{PositionSample, SurfaceInteraction};
use super::{Bounds3, PrimHit, Ray};
use crate::math::frame::{tangents, tangents_along};
use crate::math::lanes::{Real, V3};
use crate::math::simd::Float8;
use crate::math::trig::{atan2, sin_cos_turn};
use crate::math::{Frame, Transform};
use crate::sampling::warp::{sample_uniform_sphere, uniform_sphere};
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
    /// The unit world direction `a` with ∂p/∂u ∝ a × (outward normal): the object's z axis, negated when
    /// `to_world` mirrors (a mirror turns the cross product around).
    pole_axis: Vec3,
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
        // Object space ∂p/∂u = 2π (−y, x, 0) = 2π ẑ × p; the linear part r·Q (Q orthogonal) maps it to
        // 2π r det(Q) (Qẑ × Qp), Qp being the outward normal.
        let z = axes[2] / r;
        let pole_axis = if full.flips_handedness() { -z } else { z };
        // Mitsuba turns a sphere's normals inwards when `to_world` mirrors (observed with Mitsuba 3.9.1:
        // scale(1, 1, −1) gives n = −outward), so the flag flips with the handedness.
        let flip_normals = flip_normals ^ full.flips_handedness();
        Some(Sphere { center: c, radius: r, flip_normals, to_object: full.inverse(), pole_axis })
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
        let (t, hit) = intersect_sphere::<f32>(ray.o.into(), ray.d.into(), self.center.into(), self.radius, ray.tmax);
        hit.then_some(PrimHit { t, uv: Vec2::ZERO })
    }

    /// The texture coordinates at the point with outward normal `outward`: Mitsuba's parametrisation,
    /// u = φ / 2π, v = θ / π in object space, the angles by [`atan2`] (θ = atan2(√(x² + y²), z), which
    /// keeps its precision at the poles, where acos z of an `f32` does not).
    #[must_use]
    pub fn uv_at(&self, outward: Vec3) -> Vec2 {
        let local = self.to_object.vector(outward).normalize();
        let mut phi = atan2(local.y, local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(phi / (2.0 * PI), atan2((local.x * local.x + local.y * local.y).sqrt(), local.z) / PI)
    }

    /// ∂p/∂u and ∂p/∂v at the surface point `p` for u = φ/2π, v = θ/π in object space: 2π (−y, x, 0) and
    /// π (z cos φ, z sin φ, −sin θ) there (φ = 0 at the poles), mapped to world space.
    #[must_use]
    pub fn uv_partials(&self, p: Vec3) -> (Vec3, Vec3) {
        let q = self.to_object.point(p);
        let rd = q.x.hypot(q.y);
        let (cos_phi, sin_phi) = if rd > 0.0 { (q.x / rd, q.y / rd) } else { (1.0, 0.0) };
        let to_world = self.to_object.inverse();
        (to_world.vector(Vec3::new(-q.y, q.x, 0.0) * (2.0 * PI)), to_world.vector(Vec3::new(q.z * cos_phi, q.z * sin_phi, -rd) * PI))
    }

    /// The interaction at parameter `t` of `ray`; the point is re-projected onto the surface.
    #[must_use]
    pub fn interaction(&self, ray: &Ray, t: f32, uv: bool) -> SurfaceInteraction {
        let (p, outward) = sphere_surface::<f32>(ray.o.into(), ray.d.into(), t, self.center.into(), self.radius);
        let (p, outward) = (Vec3::from(p), Vec3::from(outward));
        let n = if self.flip_normals { -outward } else { outward };
        let uv = if uv { self.uv_at(outward) } else { Vec2::ZERO };
        let (s, tangent) = sphere_tangents::<f32>(self.pole_axis.into(), outward.into(), n.into());
        SurfaceInteraction { t, p, n, shading: Frame { s: s.into(), t: tangent.into(), n }, uv, shape: 0, prim: 0 }
    }

    /// The unit world direction `a` with ∂p/∂u ∝ a × (outward normal), for [`sphere_tangents`].
    #[inline]
    #[must_use]
    pub fn pole_axis(&self) -> Vec3 {
        self.pole_axis
    }

    /// A point on the sphere sampled from reference point `p`: uniformly in the cone of directions the
    /// sphere subtends when `p` is outside (pbrt-v4 §6.2.4), else uniformly by area. The density is in
    /// solid angle at `p`. [`sample_sphere_from`] at one lane.
    #[must_use]
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<(PositionSample, f32)> {
        let (q, n, pdf, valid) = sample_sphere_from::<f32>(self.center.into(), self.radius, self.flip_normals, p.into(), u.x, u.y);
        let n = Vec3::from(n);
        valid.then(|| (PositionSample { p: q.into(), n, ng: n, pdf_area: 1.0 / self.area() }, pdf))
    }

    /// The solid-angle density with which [`Self::sample_from`] at `p` produces the surface point `q`.
    #[must_use]
    pub fn pdf_from(&self, p: Vec3, q: Vec3, n: Vec3) -> f32 {
        let to_center = self.center - p;
        match sphere_cone::<f32>(to_center.length_squared(), self.radius * self.radius) {
            (true, _, cone_pdf) => cone_pdf,
            (false, ..) => {
                let d = q - p;
                let cos = n.dot(d.normalize_or_zero()).abs();
                if cos == 0.0 {
                    0.0
                } else {
                    d.length_squared() / (cos * self.area())
                }
            }
        }
    }

    /// A point uniformly distributed over the surface.
    #[must_use]
    pub fn sample_position(&self, u: Vec2) -> PositionSample {
        let outward = sample_uniform_sphere(u);
        let n = if self.flip_normals { -outward } else { outward };
        PositionSample { p: self.center + outward * self.radius, n, ng: n, pdf_area: 1.0 / self.area() }
    }
}

/// The cone of directions a sphere of squared radius `r2` subtends from a point at squared distance `dc2`
/// from its centre, in lanes: whether the point is outside (2026-11: beyond 1.0001 r², so that points on,
/// or rounding-close to, the surface take the area-sampling path), cos θmax, and the uniform density in
/// the cone, 1 / (2π (1 − cos θmax)), with 1 − cos θmax as sin²θmax / (1 + cos θmax) to keep its
/// precision for small or distant spheres. Shared by the sampling and [`Sphere::pdf_from`].
#[inline(always)]
fn sphere_cone<R: Real>(dc2: R, r2: R) -> (R::Mask, R, R) {
    let one = R::splat(1.0);
    let sin2 = r2 / dc2;
    let cos_max = (one - sin2).max(R::splat(0.0)).sqrt();
    let one_minus_cos = sin2 / (one + cos_max);
    (dc2.gt(r2 * 1.0001), cos_max, one / (one_minus_cos * (2.0 * PI)))
}

/// [`Sphere::sample_from`] in lanes, each lane with a sphere of its own (centre, radius, and whether its
/// normals point inwards): from the points `p` with the numbers (`ux`, `uy`), the point, its normal (the
/// shading and the geometric one), the solid-angle density at `p`, and whether the sample is valid.
/// Outside the sphere, the direction is drawn uniformly in the cone it subtends (pbrt-v4 §6.2.4: z = 1 −
/// ux (1 − cos θmax) about the axis to the centre, φ = 2π uy by [`sin_cos_turn`]) and the point is where it
/// meets the sphere (or, for a grazing direction that misses by rounding, the ray's point closest to the
/// centre), re-projected onto the surface; inside (or on) it, the point is uniform by area.
#[inline(always)]
#[must_use]
pub fn sample_sphere_from<R: Real>(center: V3<R>, radius: R, inward: R::Mask, p: V3<R>, ux: R, uy: R) -> (V3<R>, V3<R>, R, R::Mask) {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let r2 = radius * radius;
    let to_center = center.sub(p);
    let dc2 = to_center.dot(to_center);
    let (outside, cos_max, cone_pdf) = sphere_cone(dc2, r2);
    let axis = to_center.scale(one / dc2.sqrt());
    let z = one - ux * (one - cos_max);
    let rho = (one - z * z).max(zero).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turn(uy);
    let (s, t) = tangents(axis);
    let w = s.scale(rho * cos_phi).add(t.scale(rho * sin_phi)).add(axis.scale(z));
    let (t_hit, hit) = intersect_sphere(p, w, center, radius, R::splat(f32::INFINITY));
    let t_cone = R::select(hit, t_hit, to_center.dot(w));
    let (_, cone_outward) = sphere_surface(p, w, t_cone, center, radius);
    // By area, the density converted to solid angle at `p`.
    let area_outward = uniform_sphere(ux, uy);
    let d = center.add(area_outward.scale(radius)).sub(p);
    let dist2 = d.dot(d);
    let cos = area_outward.dot(d).abs() / dist2.sqrt();
    let area_pdf = dist2 / (cos * r2 * (4.0 * PI));
    let outward = V3::select(outside, cone_outward, area_outward);
    let n = V3::select(inward, outward.neg(), outward);
    (center.add(outward.scale(radius)), n, R::select(outside, cone_pdf, area_pdf), outside | cos.gt(zero))
}

/// The point at distance `t` along the ray (o, d) re-projected onto the sphere, and the outward unit normal
/// there, in lanes.
#[inline(always)]
#[must_use]
pub fn sphere_surface<R: Real>(o: V3<R>, d: V3<R>, t: R, center: V3<R>, radius: R) -> (V3<R>, V3<R>) {
    let outward = o.add(d.scale(t)).sub(center).normalize();
    (center.add(outward.scale(radius)), outward)
}

/// The shading tangents (s, t) at the sphere point with outward unit normal `outward` and shading normal `n`
/// (`outward`, or its negation for flipped normals), `pole_axis` being [`Sphere::pole_axis`], in lanes:
/// Mitsuba 3's frame (see the module doc). At the poles, where ∂p/∂u vanishes, those of
/// [`Frame::from_normal`].
#[inline(always)]
#[must_use]
pub fn sphere_tangents<R: Real>(pole_axis: V3<R>, outward: V3<R>, n: V3<R>) -> (V3<R>, V3<R>) {
    // ∂p/∂u, up to its positive length 2π r sin θ.
    tangents_along(n, pole_axis.cross(outward))
}

/// The nearer hit in (0, tmax) of the ray o + t d with the sphere (`center`, `radius`), in lanes (of rays,
/// or of spheres): the distance and whether it is hit.
#[inline(always)]
#[must_use]
pub fn intersect_sphere<R: Real>(o: V3<R>, d: V3<R>, center: V3<R>, radius: R, tmax: R) -> (R, R::Mask) {
    let oc = o.sub(center);
    let a = d.dot(d);
    let b = d.dot(oc) * 2.0;
    let r2 = radius * radius;
    let c = oc.dot(oc) - r2;
    let v = oc.sub(d.scale(b / (a * 2.0)));
    let disc = a * 4.0 * (r2 - v.dot(v));
    let zero = R::splat(0.0);
    let root = disc.sqrt();
    let q = R::select(b.lt(zero), (b - root) * -0.5, (b + root) * -0.5);
    let (t0, t1) = (q / a, c / q);
    let swap = t0.gt(t1);
    let (t0, t1) = (R::select(swap, t1, t0), R::select(swap, t0, t1));
    let t = R::select(t0.gt(zero), t0, t1);
    (t, !disc.lt(zero) & t.gt(zero) & t.lt(tmax))
}

/// Up to eight spheres in structure-of-arrays form, for [`intersect_sphere`] on eight at once with one ray.
/// Lanes without a sphere are masked out.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sphere8 {
    center: [[f32; 8]; 3],
    radius: [f32; 8],
    lanes: u32,
}

impl Sphere8 {
    /// Put `sphere` in lane `lane`.
    pub fn set(&mut self, lane: usize, sphere: &Sphere) {
        for axis in 0..3 {
            self.center[axis][lane] = sphere.center[axis];
        }
        self.radius[lane] = sphere.radius;
        self.lanes |= 1 << lane;
    }

    /// The lanes holding a sphere (bit mask).
    #[inline(always)]
    #[must_use]
    pub fn lanes(&self) -> u32 {
        self.lanes
    }

    /// The sphere in lane `lane` tested against eight rays (one per lane of `o`, `d`, `tmax`): the rays that
    /// hit it and their distances, as [`Sphere::intersect`] computes them.
    #[inline(always)]
    #[must_use]
    pub fn intersect_rays(&self, lane: usize, o: V3<Float8>, d: V3<Float8>, tmax: Float8) -> (crate::math::simd::Mask8, Float8) {
        let center = V3::new(Float8::splat(self.center[0][lane]), Float8::splat(self.center[1][lane]), Float8::splat(self.center[2][lane]));
        let (t, hit) = intersect_sphere(o, d, center, Float8::splat(self.radius[lane]), tmax);
        (hit, t)
    }

    /// The lanes hit within (0, tmax) (bit mask) and their distances, as [`Sphere::intersect`] computes them.
    #[inline(always)]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> (u32, [f32; 8]) {
        let row = |r: &[f32; 8]| Float8::load(r);
        let center = V3::new(row(&self.center[0]), row(&self.center[1]), row(&self.center[2]));
        let (t, hit) = intersect_sphere(V3::splat(ray.o), V3::splat(ray.d), center, row(&self.radius), Float8::splat(tmax));
        (hit.bitmask() & self.lanes, t.to_array())
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
        let si = s.interaction(&Ray::new(Vec3::ZERO, Vec3::Z, f32::INFINITY), 4.0, true);
        assert!((si.n + Vec3::Z).length() < 1e-5);
    }

    /// The cone density integrates to one over the visible cap, and samples land on the near side.
    #[test]
    fn cone_sampling_is_consistent() {
        let s = Sphere::new(Vec3::new(0.0, 0.0, 4.0), 1.0, Transform::IDENTITY, false).unwrap();
        let mut rng = crate::sampling::Pcg32::new(5, 5);
        let expected = 1.0 / (2.0 * PI * (1.0 - (15.0f32 / 16.0).sqrt()));
        for _ in 0..1000 {
            let (ps, pdf) = s.sample_from(Vec3::ZERO, rng.next_vec2()).unwrap();
            assert!(((ps.p - s.center).length() - 1.0).abs() < 1e-5 && ps.p.z < 4.0 + 1e-3);
            assert!((pdf / expected - 1.0).abs() < 1e-4 && (s.pdf_from(Vec3::ZERO, ps.p, ps.n) - pdf).abs() < 1e-3 * pdf);
        }
    }

    /// In lanes, each lane with a sphere of its own (from outside, from inside, with normals in and out),
    /// the samples are the single calls' bit for bit; inside, the density is the area density over the
    /// solid angle (|q − p|² / (cos · area)) and the normal faces as the flag says.
    #[test]
    fn lanes_sample_each_lanes_sphere_as_single_calls() {
        use crate::math::lanes::F32x8;
        let mut rng = crate::sampling::Pcg32::new(9, 2);
        let mut next = || rng.next_f32();
        let spheres: Vec<Sphere> = (0..8)
            .map(|i| Sphere::new(Vec3::new(i as f32, 1.0, 2.0), 0.5 + 0.2 * i as f32, Transform::IDENTITY, i % 3 == 0).unwrap())
            .collect();
        for round in 0..50 {
            // Lanes 0–2 inside their sphere, the others outside.
            let p: Vec<Vec3> = spheres
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let d = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                    s.center + d * s.radius * if i < 3 { 0.9 * next() } else { 1.5 + 4.0 * next() }
                })
                .collect();
            let (ux, uy): (Vec<f32>, Vec<f32>) = (0..8).map(|_| (next(), next())).unzip();
            let centers: Vec<Vec3> = spheres.iter().map(|s| s.center).collect();
            let lanes = |f: &dyn Fn(usize) -> f32| F32x8::load(&(0..8).map(f).collect::<Vec<f32>>());
            let radius = lanes(&|i| spheres[i].radius);
            let inward = lanes(&|i| f32::from(u8::from(spheres[i].flip_normals))).gt(F32x8::splat(0.0));
            let (q, n, pdf, valid) =
                sample_sphere_from(V3::load(&centers), radius, inward, V3::load(&p), lanes(&|i| ux[i]), lanes(&|i| uy[i]));
            for (i, s) in spheres.iter().enumerate() {
                let single = s.sample_from(p[i], Vec2::new(ux[i], uy[i]));
                assert_eq!(single.is_some(), valid.get(i), "round {round} lane {i}");
                let Some((ps, single_pdf)) = single else { continue };
                assert_eq!((q.lane(i).to_array(), n.lane(i).to_array()), (ps.p.to_array(), ps.n.to_array()), "round {round} lane {i}");
                assert_eq!(pdf.0[i].to_bits(), single_pdf.to_bits(), "round {round} lane {i}");
                let outward = (ps.p - s.center) / s.radius;
                assert!((ps.n - if s.flip_normals { -outward } else { outward }).length() < 1e-6);
                if i < 3 {
                    let d = ps.p - p[i];
                    let expect = d.length_squared() / (outward.dot(d.normalize()).abs() * s.area());
                    assert!((single_pdf / expect - 1.0).abs() < 1e-4, "inside: {single_pdf} against {expect}");
                }
            }
        }
    }

    #[test]
    fn to_world_scales_and_moves() {
        let t = Transform::translate(Vec3::X).then_after(Transform::scale(Vec3::splat(2.0)).unwrap());
        let s = Sphere::new(Vec3::ZERO, 1.5, t, false).unwrap();
        assert!((s.radius - 3.0).abs() < 1e-6 && (s.center - Vec3::X).length() < 1e-6);
        assert!(Sphere::new(Vec3::ZERO, 1.0, Transform::scale(Vec3::new(1.0, 2.0, 1.0)).unwrap(), false).is_none());
    }

    /// Mitsuba 3.9.1 (`scalar_rgb`): the shading frames `si.sh_frame` of the rays from `o` towards `target`,
    /// as (o, target, s, t); the shapes of [`shading_frame_is_mitsubas`].
    type MitsubaFrame = ([f32; 3], [f32; 3], [f32; 3], [f32; 3]);

    fn check_frames(sphere: &Sphere, frames: &[MitsubaFrame]) {
        for &(o, target, s, t) in frames {
            let (o, s, t) = (Vec3::from(o), Vec3::from(s), Vec3::from(t));
            let ray = Ray::new(o, (Vec3::from(target) - o).normalize(), f32::INFINITY);
            let hit = sphere.intersect(&ray).unwrap();
            let f = sphere.interaction(&ray, hit.t, true).shading;
            // 2026-12: 2e-5 absorbs the f32 rounding of two renderers computing the same point.
            assert!((f.s - s).length() < 2e-5 && (f.t - t).length() < 2e-5, "from {o}: s {} t {}, Mitsuba s {s} t {t}", f.s, f.t);
            assert!((f.s.cross(f.t) - f.n).length() < 1e-5 && f.s.dot(f.n).abs() < 1e-5);
        }
    }

    /// The shading frame is Mitsuba 3's: s along ∂p/∂u (the parallels of the object's z axis), t = n × s,
    /// Duff's frame at the poles; for flipped normals, a rotated, scaled and moved sphere and a mirrored
    /// one. The frames were read from Mitsuba 3.9.1 (`scalar_rgb`, `shape.ray_intersect`, `si.sh_frame`).
    #[test]
    fn shading_frame_is_mitsubas() {
        const O: [f32; 3] = [0.0; 3];
        let unit = [
            ([3.0, 0.5, 0.8], O, [-0.164_398_98, 0.986_394, 0.0], [-0.250_924_02, -0.041_820_668, 0.967_103_06]),
            ([-2.0, 1.0, 2.0], O, [-0.447_213_6, -0.894_427_2, 0.0], [0.596_284_8, -0.298_142_4, 0.745_356]),
            ([0.2, 0.1, -4.0], O, [-0.447_213_56, 0.894_427_1, 0.0], [0.893_032_9, 0.446_516_45, 0.055_814_568]),
            ([0.3, -3.0, 0.2], O, [0.995_037_14, 0.099_503_726, 0.0], [-0.006_586_186, 0.065_861_85, 0.997_807_1]),
            // The poles, where ∂p/∂u vanishes.
            ([0.0, 0.0, 5.0], O, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, -5.0], O, [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]),
        ];
        check_frames(&Sphere::new(Vec3::ZERO, 1.0, Transform::IDENTITY, false).unwrap(), &unit);
        let flipped = [
            ([3.0, 0.5, 0.8], O, [-0.164_398_98, 0.986_394, 0.0], [0.250_924_02, 0.041_820_668, -0.967_103_06]),
            ([0.0, 0.0, 5.0], O, [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]),
        ];
        check_frames(&Sphere::new(Vec3::ZERO, 1.0, Transform::IDENTITY, true).unwrap(), &flipped);
        // Mitsuba: translate([0.5, -0.2, 0.1]) @ rotate([1, 1, 0] / √2, 40) @ scale(1.5) (Mitsuba's `rotate` takes
        // the axis as given: unnormalised, its matrix is not a rotation).
        let moved = Transform::translate(Vec3::new(0.5, -0.2, 0.1))
            .then_after(Transform::rotate(Vec3::new(1.0, 1.0, 0.0), 40.0).unwrap().then_after(Transform::scale(Vec3::splat(1.5)).unwrap()));
        let c = [0.5, -0.2, 0.1];
        let turned = [
            ([3.5, 0.3, 0.9], c, [-0.285_681_96, 0.740_193_96, 0.608_686_15], [-0.091_518_916, -0.653_326_1, 0.751_524_8]),
            ([0.8, -3.2, 0.3], c, [0.872_676_1, 0.054_920_882, -0.485_201_18], [0.478_099_26, 0.105_936_19, 0.871_893_76]),
            ([-1.5, 0.8, 2.1], c, [-0.559_244_2, -0.814_996_3, -0.151_746_1], [0.492_748_86, -0.473_993_57, 0.729_745_7]),
        ];
        check_frames(&Sphere::new(Vec3::ZERO, 1.0, moved, false).unwrap(), &turned);
        // A mirror turns Mitsuba's normals inwards (n = −outward) and keeps s.
        let mirrored = [
            ([3.0, 0.5, 0.8], O, [-0.164_398_98, 0.986_394, 0.0], [0.250_924_02, 0.041_820_668, -0.967_103_06]),
            ([-2.0, 1.0, 2.0], O, [-0.447_213_6, -0.894_427_2, 0.0], [-0.596_284_8, 0.298_142_4, -0.745_356]),
        ];
        let mirror = Sphere::new(Vec3::ZERO, 1.0, Transform::scale(Vec3::new(1.0, 1.0, -1.0)).unwrap(), false).unwrap();
        check_frames(&mirror, &mirrored);
        let mirror_x = Sphere::new(Vec3::ZERO, 1.0, Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap(), false).unwrap();
        let s = [0.164_398_98, -0.986_394, 0.0];
        check_frames(&mirror_x, &[([6.0, 1.0, 2.0], O, s, [-0.308_097_7, -0.051_349_61, 0.949_968_04])]);
        let ray = Ray::new(Vec3::new(3.0, 0.5, 0.8), Vec3::new(-3.0, -0.5, -0.8).normalize(), f32::INFINITY);
        let si = mirror.interaction(&ray, mirror.intersect(&ray).unwrap().t, true);
        assert!((si.n + si.p).length() < 1e-5, "inward normal {}", si.n);
    }

    /// The eight-sphere test agrees with the scalar one, lane by lane, bit for bit.
    #[test]
    fn eight_wide_test_matches_scalar() {
        let mut rng = crate::sampling::Pcg32::new(8, 1);
        let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - Vec3::splat(2.0);
        for _ in 0..2000 {
            let spheres: Vec<Sphere> =
                (0..7).map(|_| Sphere::new(v(), 0.2 + v().x.abs() * 0.3, Transform::IDENTITY, false).unwrap()).collect();
            let mut packet = Sphere8::default();
            for (lane, s) in spheres.iter().enumerate() {
                packet.set(lane, s);
            }
            let ray = Ray::new(v() * 2.0, (v() + Vec3::splat(1e-3)).normalize(), 6.0);
            let (mask, t) = packet.intersect(&ray, ray.tmax);
            assert_eq!(mask & 128, 0, "the empty lane is never hit");
            for (lane, s) in spheres.iter().enumerate() {
                let scalar = s.intersect(&ray);
                assert_eq!(scalar.is_some(), mask & (1 << lane) != 0);
                if let Some(h) = scalar {
                    assert_eq!(h.t.to_bits(), t[lane].to_bits());
                }
            }
        }
    }
}
