//! The closed set of shapes. A shape has one or more primitives (a mesh has one per triangle); the scene's
//! BVH indexes (shape, primitive) pairs.

use super::cylinder::Cylinder;
use super::disk::Disk;
use super::interaction::{PositionSample, SurfaceInteraction};
use super::mesh::Mesh;
use super::sdf_grid::SdfGrid;
use super::sphere::Sphere;
use super::{Bounds3, Ray};
use crate::math::lanes::{Real, V3};
use glam::Vec2;

/// The solid-angle density at `p` of a point `q` (geometric normal `ng`) sampled with area density
/// `pdf_area`: p_ω = p_A d² / |cos θ| (pbrt-v4 eq. 4.9), in lanes; valid where `q` is not seen edge-on
/// (nor at `p`).
#[inline(always)]
pub fn solid_angle_density<R: Real>(p: V3<R>, q: V3<R>, ng: V3<R>, pdf_area: R) -> (R, R::Mask) {
    let d = q.sub(p);
    let dist2 = d.dot(d);
    let cos = ng.dot(d).abs() / dist2.sqrt();
    let zero = R::splat(0.0);
    (pdf_area * dist2 / cos, cos.gt(zero) & dist2.gt(zero))
}

/// A ray's hit on one primitive, before the full interaction is computed: the ray parameter and
/// shape-specific coordinates (barycentrics for triangles, object-space (x, y) for disks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    pub t: f32,
    pub uv: Vec2,
}

/// Any gonio shape, in world space.
#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    Disk(Disk),
    Cylinder(Cylinder),
    Mesh(Mesh),
    /// Never an area light (refused at load, as by Mitsuba): no area or position sampling.
    SdfGrid(SdfGrid),
}

impl Shape {
    #[must_use]
    pub fn primitive_count(&self) -> usize {
        match self {
            Shape::Mesh(m) => m.triangle_count(),
            Shape::SdfGrid(g) => g.primitive_count(),
            Shape::Sphere(_) | Shape::Disk(_) | Shape::Cylinder(_) => 1,
        }
    }

    #[must_use]
    pub fn primitive_bounds(&self, prim: u32) -> Bounds3 {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Disk(d) => d.bounds(),
            Shape::Cylinder(c) => c.bounds(),
            Shape::Mesh(m) => m.triangle_bounds(prim),
            Shape::SdfGrid(g) => g.voxel_bounds(prim),
        }
    }

    #[inline]
    #[must_use]
    pub fn intersect(&self, prim: u32, ray: &Ray) -> Option<PrimHit> {
        match self {
            Shape::Mesh(m) => m.intersect(prim, ray),
            Shape::Sphere(s) => s.intersect(ray),
            Shape::Disk(d) => d.intersect(ray),
            Shape::Cylinder(c) => c.intersect(ray),
            Shape::SdfGrid(g) => g.intersect(prim, ray),
        }
    }

    /// The full interaction of a hit found by [`Shape::intersect`]; `shape` and `prim` are filled in. Texture
    /// coordinates only with `uv` (else zero): spheres, disks and cylinders need an arc tangent for them.
    #[must_use]
    pub fn interaction(&self, shape: u32, prim: u32, ray: &Ray, hit: &PrimHit, uv: bool) -> SurfaceInteraction {
        let mut si = match self {
            Shape::Mesh(m) => m.interaction(prim, ray, hit, uv),
            Shape::Sphere(s) => s.interaction(ray, hit.t, uv),
            Shape::Disk(d) => d.interaction(ray, hit, uv),
            Shape::Cylinder(c) => c.interaction(ray, hit.t, uv),
            Shape::SdfGrid(g) => g.interaction(prim, ray, hit),
        };
        si.shape = shape;
        si.prim = prim;
        si
    }

    /// ∂p/∂u and ∂p/∂v (world space) at the point `p` of primitive `prim`, of the parameterisation that
    /// gives the shape its texture coordinates (Mitsuba's, shape by shape): what `bumpmap` perturbs. An
    /// `sdfgrid` has no parameterisation (its uv are 0): its shading frame's tangents `s`, `t` stand in.
    #[must_use]
    pub fn uv_partials(&self, prim: u32, p: glam::Vec3, shading: &crate::math::Frame) -> (glam::Vec3, glam::Vec3) {
        match self {
            Shape::Mesh(m) => m.uv_partials(prim),
            Shape::Sphere(s) => s.uv_partials(p),
            Shape::Disk(d) => d.uv_partials(p),
            Shape::Cylinder(c) => c.uv_partials(p),
            Shape::SdfGrid(_) => (shading.s, shading.t),
        }
    }

    #[must_use]
    pub fn area(&self) -> f32 {
        match self {
            Shape::Sphere(s) => s.area(),
            Shape::Disk(d) => d.area(),
            Shape::Cylinder(c) => c.area(),
            Shape::Mesh(m) => m.area(),
            // Mitsuba's too: it is never sampled.
            Shape::SdfGrid(_) => 0.0,
        }
    }

    /// A point on the surface sampled for lighting a reference point `p`, with its solid-angle density at
    /// `p`: spheres sample the cone they subtend, other shapes sample by area (p_ω = p_A d² / |cos θ|).
    /// `None` when the point is seen edge-on.
    #[must_use]
    pub fn sample_from(&self, p: glam::Vec3, uc: f32, u: Vec2) -> Option<(PositionSample, f32)> {
        if let Shape::Sphere(s) = self {
            return s.sample_from(p, u);
        }
        let ps = self.sample_position(uc, u);
        let (pdf, valid) = solid_angle_density::<f32>(p.into(), ps.p.into(), ps.ng.into(), ps.pdf_area);
        valid.then_some((ps, pdf))
    }

    /// The solid-angle density with which [`Self::sample_from`] at `p` finds the surface point `q` (geometric
    /// normal `n`).
    #[must_use]
    pub fn pdf_from(&self, p: glam::Vec3, q: glam::Vec3, n: glam::Vec3) -> f32 {
        if let Shape::Sphere(s) = self {
            return s.pdf_from(p, q, n);
        }
        let d = q - p;
        let dist2 = d.length_squared();
        let cos = n.dot(d).abs() / dist2.sqrt();
        if cos == 0.0 {
            0.0
        } else {
            dist2 / (cos * self.area())
        }
    }

    /// A point uniformly distributed over the surface, density 1/area.
    #[must_use]
    pub fn sample_position(&self, uc: f32, u: Vec2) -> PositionSample {
        match self {
            Shape::Sphere(s) => s.sample_position(u),
            Shape::Disk(d) => d.sample_position(u),
            Shape::Cylinder(c) => c.sample_position(u),
            Shape::Mesh(m) => m.sample_position(uc, u),
            Shape::SdfGrid(_) => unreachable!("an sdfgrid is never an area light (refused at load)"),
        }
    }
}
