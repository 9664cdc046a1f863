//! Triangle meshes in world space (`obj`, `ply`, and the built-in `rectangle` and `cube`).
//!
//! | parameter      | type      | default  | meaning                                                       |
//! |----------------|-----------|----------|---------------------------------------------------------------|
//! | `to_world`     | transform | identity | object → world, applied once at load time                     |
//! | `face_normals` | boolean   | false    | ignore vertex normals: shade with the geometric normal        |
//! | `flip_normals` | boolean   | false    | reverse both geometric and shading normals                    |
//!
//! The geometric normal is `normalize((p₁ − p₀) × (p₂ − p₀))` in world space, as in Mitsuba; the shading
//! normal interpolates vertex normals with the barycentrics. A mesh file without normals gets smooth ones
//! unless `face_normals` is set, as in Mitsuba: each face's normal weighted by its angle at the vertex
//! (Thürmer & Wüthrich 1998, "Computing Vertex Normals from Polygonal Facets"). Without texture
//! coordinates, uv = (b₁, b₂).
//! Rays are intersected with Möller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle Intersection".

use super::interaction::{PositionSample, SurfaceInteraction};
use super::mesh_io::VertexAttribute;
use super::{Bounds3, PrimHit, Ray};
use crate::error::{Error, Result};
use crate::math::lanes::{Real, V3};
use crate::math::simd::{Float8, Mask8};
use crate::math::{Frame, Transform};
use crate::sampling::distribution::Distribution1D;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// The most a flat-shaded triangle's unit vertex normals differ, per component ([`Mesh::flat_frames`]):
/// about eight roundings of 1, what computing one normal of a plane from different triangles of it gives.
pub const FLAT_NORMAL_TOLERANCE: f32 = 1e-6;

/// A triangle mesh, already transformed to world space.
#[derive(Clone, Debug)]
pub struct Mesh {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    indices: Vec<[u32; 3]>,
    flip_normals: bool,
    /// Triangle selection proportional to area, for sampling points.
    areas: Distribution1D,
    area: f32,
    /// Unit geometric normal of each triangle (after `flip_normals`; zero for degenerate triangles).
    tri_normals: Vec<Vec3>,
    /// Each flat-shaded triangle's shading frame, constant over it (2026-11: computing it at every hit was
    /// a tenth of a Cornell box's intersection cost): every triangle of a mesh without vertex normals (the
    /// built-in `rectangle` and `cube` among them), and the triangles of a mesh with normals whose three
    /// vertex normals agree to [`FLAT_NORMAL_TOLERANCE`] (the planar parts of a mesh whose normals a file
    /// gave per face or gonio computed, as Mitsuba does, for a mesh file without them). Empty where no
    /// triangle is flat.
    flat_frames: Vec<Option<Frame>>,
    /// Per-vertex attributes (a PLY file's), for `mesh_attribute` textures.
    attributes: Vec<VertexAttribute>,
}

impl Mesh {
    /// [`Mesh::new`] for a mesh file: without normals in the file and without `face_normals`, smooth vertex
    /// normals are computed (as Mitsuba's `obj` and `ply` do).
    #[allow(clippy::too_many_arguments)] // one argument per plugin parameter, as in the table above
    pub fn from_file_data(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        indices: Vec<[u32; 3]>,
        to_world: &Transform,
        face_normals: bool,
        flip_normals: bool,
        at: &str,
    ) -> Result<Mesh> {
        Mesh::build(positions, normals, uvs, indices, to_world, face_normals, flip_normals, at, true)
    }

    /// A mesh from object-space data. `at` names the shape in errors (bad indices, non-finite vertices).
    #[allow(clippy::too_many_arguments)] // one argument per plugin parameter, as in the table above
    pub fn new(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        indices: Vec<[u32; 3]>,
        to_world: &Transform,
        face_normals: bool,
        flip_normals: bool,
        at: &str,
    ) -> Result<Mesh> {
        Mesh::build(positions, normals, uvs, indices, to_world, face_normals, flip_normals, at, false)
    }

    /// [`Mesh::new`], and with `smooth_if_missing` [`Mesh::from_file_data`]: the vertex normals computed
    /// where none are given (and `face_normals` is off) before the flat frames, which depend on them
    /// (2026-12: a mesh file's 10⁶ triangles had had their frames made twice, first as if all were flat).
    /// The per-vertex and per-triangle work is done in parallel.
    #[allow(clippy::too_many_arguments)] // one argument per plugin parameter, as in the table above
    fn build(
        positions: Vec<Vec3>,
        normals: Option<Vec<Vec3>>,
        uvs: Option<Vec<Vec2>>,
        indices: Vec<[u32; 3]>,
        to_world: &Transform,
        face_normals: bool,
        flip_normals: bool,
        at: &str,
        smooth_if_missing: bool,
    ) -> Result<Mesh> {
        let n = positions.len();
        if let Some(bad) = indices.iter().flatten().find(|&&i| i as usize >= n) {
            return Err(Error::spec(at, format!("mesh index {bad} is out of range ({n} vertices)")));
        }
        if indices.is_empty() {
            return Err(Error::spec(at, "mesh has no triangles"));
        }
        let positions: Vec<Vec3> = positions.par_iter().map(|&p| to_world.point(p)).collect();
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(Error::spec(at, "mesh has non-finite vertex positions"));
        }
        let normals = if face_normals {
            None
        } else {
            match normals {
                Some(ns) if ns.len() == n => Some(ns.par_iter().map(|&v| to_world.normal(v).normalize_or_zero()).collect()),
                Some(ns) => return Err(Error::spec(at, format!("mesh has {} normals for {n} vertices", ns.len()))),
                None if smooth_if_missing => Some(angle_weighted_normals(&positions, &indices)),
                None => None,
            }
        };
        let uvs = match uvs {
            Some(uv) if uv.len() != n => {
                return Err(Error::spec(at, format!("mesh has {} texture coordinates for {n} vertices", uv.len())))
            }
            other => other,
        };
        let sign = if flip_normals { -1.0 } else { 1.0 };
        let (tri_areas, tri_normals): (Vec<f32>, Vec<Vec3>) = indices
            .par_iter()
            .map(|t| {
                let [p0, p1, p2] = t.map(|i| positions[i as usize]);
                let cross = (p1 - p0).cross(p2 - p0);
                (0.5 * cross.length(), face_normal(cross, sign))
            })
            .unzip();
        let area = tri_areas.iter().map(|&a| f64::from(a)).sum::<f64>() as f32;
        let mut mesh = Mesh {
            positions,
            normals,
            uvs,
            indices,
            flip_normals,
            areas: Distribution1D::new(&tri_areas),
            area,
            tri_normals,
            flat_frames: Vec::new(),
            attributes: Vec::new(),
        };
        mesh.update_flat_frames();
        Ok(mesh)
    }

    /// The mesh with the per-vertex attributes `attributes` (a PLY file's, each `dim` values per vertex).
    #[must_use]
    pub fn with_attributes(self, attributes: Vec<VertexAttribute>) -> Self {
        debug_assert!(attributes.iter().all(|a| a.values.len() == a.dim * self.positions.len()));
        Mesh { attributes, ..self }
    }

    /// The per-vertex attributes, named as Mitsuba names them (`vertex_color`, …).
    #[must_use]
    pub fn attributes(&self) -> &[VertexAttribute] {
        &self.attributes
    }

    /// Attribute `attribute` (of [`Self::attributes`]) at the point `p` of triangle `tri`, interpolated with
    /// the barycentrics of `p`'s projection onto the triangle, as a colour: one value for all three channels,
    /// otherwise the first three (a missing third is 0).
    #[must_use]
    pub fn attribute_at(&self, attribute: usize, tri: u32, p: Vec3) -> crate::spectrum::Rgb {
        let a = &self.attributes[attribute];
        let [p0, e1, e2] = self.triangle_edges(tri);
        let d = p - p0;
        let (d00, d01, d11, d20, d21) = (e1.dot(e1), e1.dot(e2), e2.dot(e2), d.dot(e1), d.dot(e2));
        let den = d00 * d11 - d01 * d01;
        let (b1, b2) = if den > 0.0 { ((d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den) } else { (0.0, 0.0) };
        let idx = self.indices[tri as usize];
        let value = |c: usize| {
            if a.dim == 1 || c < a.dim {
                let c = if a.dim == 1 { 0 } else { c };
                let at = |v: u32| a.values[v as usize * a.dim + c];
                at(idx[0]) * (1.0 - b1 - b2) + at(idx[1]) * b1 + at(idx[2]) * b2
            } else {
                0.0
            }
        };
        crate::spectrum::Rgb::new(value(0), value(1), value(2))
    }

    /// Fill [`Mesh::flat_frames`]. A triangle with vertex normals is flat when they agree to
    /// [`FLAT_NORMAL_TOLERANCE`]: its shading normal is then their normalised sum everywhere on it, where
    /// interpolating them gives a normal that differs by at most that much.
    fn update_flat_frames(&mut self) {
        let n = self.indices.len();
        // A smooth mesh (a scanned or subdivided model, most often) keeps no table at all.
        if !(0..n).into_par_iter().any(|t| self.flat_shading_normal(t).is_some()) {
            self.flat_frames = Vec::new();
            return;
        }
        let frame = |t: usize| {
            let shading = self.flat_shading_normal(t)?;
            // Degenerate triangles (zero normal) are never hit nor sampled: any frame stands for theirs.
            Some(match self.tri_normals[t] {
                Vec3::ZERO => Frame::from_normal(Vec3::Z),
                _ => self.shading_frame(t as u32, shading),
            })
        };
        self.flat_frames = (0..n).into_par_iter().map(frame).collect();
    }

    /// The shading normal of triangle `t` where it is flat-shaded ([`Mesh::flat_frames`]): the geometric
    /// normal without vertex normals, else their normalised sum where they agree.
    fn flat_shading_normal(&self, t: usize) -> Option<Vec3> {
        let Some(ns) = &self.normals else { return Some(self.tri_normals[t]) };
        let [a, b, c] = self.indices[t].map(|i| ns[i as usize]);
        let close = |x: Vec3, y: Vec3| (x - y).abs().max_element() <= FLAT_NORMAL_TOLERANCE;
        if !(close(a, b) && close(a, c) && close(b, c)) {
            return None;
        }
        let sign = if self.flip_normals { -1.0 } else { 1.0 };
        ((a + b + c) * sign).try_normalize()
    }

    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    #[must_use]
    pub fn area(&self) -> f32 {
        self.area
    }

    #[inline]
    fn vertices(&self, tri: u32) -> [Vec3; 3] {
        self.indices[tri as usize].map(|i| self.positions[i as usize])
    }

    #[must_use]
    pub fn triangle_bounds(&self, tri: u32) -> Bounds3 {
        let [p0, p1, p2] = self.vertices(tri);
        Bounds3::from_point(p0).with_point(p1).with_point(p2)
    }

    /// The triangle as (p₀, p₁ − p₀, p₂ − p₀), the form [`intersect_triangle`] takes.
    #[inline]
    #[must_use]
    pub fn triangle_edges(&self, tri: u32) -> [Vec3; 3] {
        let [p0, p1, p2] = self.vertices(tri);
        [p0, p1 - p0, p2 - p0]
    }

    /// Whether triangles `tri` and `tri + 1` form a flat parallelogram that can be intersected as one
    /// primitive (a `rectangle`, a `cube`'s face, a quad of a mesh file split along a diagonal), and if so
    /// the corner k of triangle `tri` opposite the shared diagonal: the parallelogram is
    /// [`Self::corner_edges`]`(tri, k)` with b₁, b₂ in [0, 1], and its points have the barycentrics
    /// [`parallelogram_barycentrics`] in triangle `tri`. Only where nothing on it changes: the mesh is
    /// flat-shaded, the two triangles share two vertices, the fourth vertex is where the parallelogram's
    /// is and the shading frames are the same (to 10⁻⁵ of the edges and of unit length), and, when
    /// `uv_matters`, the texture coordinates are affine over it (the fourth vertex's as extrapolated from
    /// triangle `tri`; without any, uv would be each triangle's own barycentrics).
    #[must_use]
    pub fn parallelogram(&self, tri: u32, uv_matters: bool) -> Option<u8> {
        const TOLERANCE: f32 = 1e-5;
        let (a, b) = (tri as usize, tri as usize + 1);
        if b >= self.indices.len() || (uv_matters && self.uvs.is_none()) {
            return None;
        }
        let (Some(fa), Some(fb)) = (self.flat_frame(tri), self.flat_frame(tri + 1)) else { return None };
        let (ia, ib) = (self.indices[a], self.indices[b]);
        // The corner of `a` not in `b`, and the vertex of `b` not in `a`: exactly one each.
        let mut corners = (0..3).filter(|&k| !ib.contains(&ia[k]));
        let (Some(k), None) = (corners.next(), corners.next()) else { return None };
        let mut fourth = ib.iter().filter(|&i| !ia.contains(i));
        let (Some(&d), None) = (fourth.next(), fourth.next()) else { return None };
        let (c, v1, v2) = (ia[k], ia[(k + 1) % 3], ia[(k + 2) % 3]);
        if ia[(k + 1) % 3] == ia[(k + 2) % 3] || self.tri_normals[a] == Vec3::ZERO || self.tri_normals[b] == Vec3::ZERO {
            return None;
        }
        let p = |i: u32| self.positions[i as usize];
        let size = (p(v1) - p(c)).length().max((p(v2) - p(c)).length());
        if (p(v1) + p(v2) - p(c) - p(d)).length() > TOLERANCE * size {
            return None;
        }
        if [(fa.s, fb.s), (fa.t, fb.t), (fa.n, fb.n)].iter().any(|(x, y)| (*x - *y).length() > TOLERANCE) {
            return None;
        }
        if let (true, Some(uvs)) = (uv_matters, &self.uvs) {
            let uv = |i: u32| uvs[i as usize];
            let scale = (uv(v1) - uv(c)).length().max((uv(v2) - uv(c)).length());
            if (uv(v1) + uv(v2) - uv(c) - uv(d)).length() > TOLERANCE * scale {
                return None;
            }
        }
        Some(k as u8)
    }

    /// Triangle `tri` as (p_k, p_{k+1} − p_k, p_{k+2} − p_k), from its corner `k` (indices mod 3): for
    /// k = 0, [`Self::triangle_edges`].
    #[inline]
    #[must_use]
    pub fn corner_edges(&self, tri: u32, k: u8) -> [Vec3; 3] {
        let v = self.vertices(tri);
        let k = usize::from(k);
        let c = v[k];
        [c, v[(k + 1) % 3] - c, v[(k + 2) % 3] - c]
    }

    /// The texture coordinates of triangle `tri` (or of its parallelogram from corner `k`, where they are
    /// affine over it: [`Self::parallelogram`]) as a function of the point ([`UvMap`]); without texture
    /// coordinates in the mesh, the barycentrics (b₁, b₂) of the triangle (k = 0). Computed in f64.
    #[must_use]
    pub fn uv_map(&self, tri: u32, k: u8) -> UvMap {
        let idx = self.indices[tri as usize];
        let k = usize::from(k);
        let corners = [k, (k + 1) % 3, (k + 2) % 3];
        let uv = |j: usize| match &self.uvs {
            Some(uvs) => uvs[idx[j] as usize].as_dvec2(),
            None => [glam::DVec2::ZERO, glam::DVec2::X, glam::DVec2::Y][j],
        };
        let p = |j: usize| self.positions[idx[j] as usize].as_dvec3();
        let (p0, e1, e2) = (p(corners[0]), p(corners[1]) - p(corners[0]), p(corners[2]) - p(corners[0]));
        let n = e1.cross(e2);
        let nn = n.length_squared();
        if !(nn > 0.0) {
            return UvMap { p0: p0.as_vec3(), gu: Vec3::ZERO, gv: Vec3::ZERO, uv0: uv(corners[0]).as_vec2() };
        }
        // The dual vectors: (p − p₀)·d₁ = b₁ and (p − p₀)·d₂ = b₂ for p = p₀ + b₁ e₁ + b₂ e₂.
        let (d1, d2) = (e2.cross(n) / nn, n.cross(e1) / nn);
        let (du1, du2) = (uv(corners[1]) - uv(corners[0]), uv(corners[2]) - uv(corners[0]));
        UvMap {
            p0: p0.as_vec3(),
            gu: (d1 * du1.x + d2 * du2.x).as_vec3(),
            gv: (d1 * du1.y + d2 * du2.y).as_vec3(),
            uv0: uv(corners[0]).as_vec2(),
        }
    }

    /// `uv` of the hit holds the barycentrics (b₁, b₂).
    #[inline]
    #[must_use]
    pub fn intersect(&self, tri: u32, ray: &Ray) -> Option<PrimHit> {
        let [p0, e1, e2] = self.triangle_edges(tri);
        intersect_triangle(p0, e1, e2, ray)
    }

    /// Geometric and shading normal at barycentrics (b₁, b₂) of triangle `tri`, as a hit there sees them
    /// ([`Self::interaction`]): the shading normal of a flat-shaded triangle is its flat frame's
    /// ([`Mesh::flat_frames`]), so that sampled points and hits agree.
    #[inline]
    fn normals_at(&self, tri: u32, b: Vec2) -> (Vec3, Vec3) {
        let ns = match self.flat_frame(tri) {
            Some(frame) => frame.n,
            None => self.interpolated_normal(tri, b),
        };
        (self.tri_normals[tri as usize], ns)
    }

    /// The vertex normals of triangle `tri` interpolated at barycentrics (b₁, b₂) and normalised (after
    /// `flip_normals`); the geometric normal without vertex normals or where they sum to zero.
    #[inline]
    fn interpolated_normal(&self, tri: u32, b: Vec2) -> Vec3 {
        let ng = self.tri_normals[tri as usize];
        let Some([n0, n1, n2]) = self.vertex_normals(tri) else { return ng };
        smooth_normal::<f32>([n0.into(), n1.into(), n2.into()], b.x, b.y, self.normal_sign(), ng.into()).into()
    }

    /// The vertex normals of triangle `tri` as stored (before `flip_normals`: [`Self::normal_sign`]), where
    /// the mesh has them.
    #[inline]
    #[must_use]
    pub fn vertex_normals(&self, tri: u32) -> Option<[Vec3; 3]> {
        let ns = self.normals.as_ref()?;
        Some(self.indices[tri as usize].map(|i| ns[i as usize]))
    }

    /// −1 where `flip_normals` reverses the vertex normals, else 1.
    #[inline]
    #[must_use]
    pub fn normal_sign(&self) -> f32 {
        if self.flip_normals {
            -1.0
        } else {
            1.0
        }
    }

    #[must_use]
    pub fn interaction(&self, tri: u32, ray: &Ray, hit: &PrimHit, uv: bool) -> SurfaceInteraction {
        let [p0, e1, e2] = self.triangle_edges(tri);
        let b = hit.uv;
        let p = barycentric_point::<f32>(p0.into(), e1.into(), e2.into(), b.x, b.y).into();
        let _ = ray;
        let shading = match self.flat_frame(tri) {
            Some(&f) => f,
            None => self.shading_frame(tri, self.interpolated_normal(tri, b)),
        };
        let uv = if uv { self.uv_at(tri, b) } else { Vec2::ZERO };
        SurfaceInteraction { t: hit.t, p, n: self.tri_normals[tri as usize], shading, uv, shape: 0, prim: tri }
    }

    /// The shading frame around `ns`, oriented as Mitsuba 3 orients it (`src/shapes/mesh.cpp`,
    /// `compute_surface_interaction`, then `SurfaceInteraction::initialize_sh_frame`): the first tangent is
    /// ∂p/∂u made orthogonal to `ns` (Gram–Schmidt), so anisotropic models (`alpha_u` along s) follow the
    /// parameterisation. With texture coordinates ∂p/∂u solves [Δp₁ Δp₂] = [∂p/∂u ∂p/∂v] [Δuv₁ Δuv₂] over
    /// the triangle's edges (pbrt-v4 §6.5.3); without them, or for a degenerate parameterisation, Mitsuba
    /// takes the first edge p₁ − p₀ (observed with Mitsuba 3.9.1).
    fn shading_frame(&self, tri: u32, ns: Vec3) -> Frame {
        Frame::from_normal_and_dp_du(ns, self.dp_du(tri))
    }

    /// ∂p/∂u of triangle `tri`, up to a positive factor, as [`Self::shading_frame`] takes it.
    #[inline]
    #[must_use]
    pub fn dp_du(&self, tri: u32) -> Vec3 {
        let [p0, p1, p2] = self.vertices(tri);
        self.dp_du_of_edges(tri, p1 - p0, p2 - p0)
    }

    /// [`Self::dp_du`] from the triangle's edges e₁ = p₁ − p₀ and e₂ = p₂ − p₀, where the caller has them.
    #[inline]
    #[must_use]
    pub fn dp_du_of_edges(&self, tri: u32, e1: Vec3, e2: Vec3) -> Vec3 {
        let Some(uvs) = &self.uvs else { return e1 };
        let idx = self.indices[tri as usize];
        let (uv0, uv1, uv2) = (uvs[idx[0] as usize], uvs[idx[1] as usize], uvs[idx[2] as usize]);
        let (duv1, duv2) = (uv1 - uv0, uv2 - uv0);
        let det = duv1.x * duv2.y - duv1.y * duv2.x;
        if det == 0.0 {
            e1
        } else {
            (e1 * duv2.y - e2 * duv1.y) / det
        }
    }

    /// ∂p/∂u and ∂p/∂v of triangle `tri`: the solution of [Δp₁ Δp₂] = [∂p/∂u ∂p/∂v] [Δuv₁ Δuv₂] over its
    /// edges (pbrt-v4 §6.5.3, as Mitsuba's `compute_surface_interaction`); the edges p₁ − p₀ and p₂ − p₀
    /// themselves without texture coordinates (uv are then the barycentrics) or where the texture
    /// coordinates are degenerate.
    #[must_use]
    pub fn uv_partials(&self, tri: u32) -> (Vec3, Vec3) {
        let [p0, p1, p2] = self.vertices(tri);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let Some(uvs) = &self.uvs else { return (e1, e2) };
        let idx = self.indices[tri as usize];
        let (uv0, uv1, uv2) = (uvs[idx[0] as usize], uvs[idx[1] as usize], uvs[idx[2] as usize]);
        let (duv1, duv2) = (uv1 - uv0, uv2 - uv0);
        let det = duv1.x * duv2.y - duv1.y * duv2.x;
        if det == 0.0 {
            return (e1, e2);
        }
        ((e1 * duv2.y - e2 * duv1.y) / det, (e2 * duv1.x - e1 * duv2.x) / det)
    }

    /// The shading frame of triangle `tri` where it is flat-shaded ([`Mesh::flat_frames`]; without vertex
    /// normals its `n` is the geometric normal), `None` where it is smooth-shaded.
    #[inline]
    #[must_use]
    pub fn flat_frame(&self, tri: u32) -> Option<&Frame> {
        self.flat_frames.get(tri as usize).and_then(Option::as_ref)
    }

    /// The unit geometric normal of triangle `tri` (after `flip_normals`; zero where it is degenerate).
    #[inline]
    #[must_use]
    pub fn geometric_normal(&self, tri: u32) -> Vec3 {
        self.tri_normals[tri as usize]
    }

    /// The texture coordinates at barycentrics (b₁, b₂) of triangle `tri`: interpolated where the mesh has
    /// them, else (b₁, b₂) themselves (Mitsuba's convention).
    #[inline]
    #[must_use]
    pub fn uv_at(&self, tri: u32, b: Vec2) -> Vec2 {
        match &self.uvs {
            Some(uvs) => {
                let idx = self.indices[tri as usize];
                uvs[idx[0] as usize] * (1.0 - b.x - b.y) + uvs[idx[1] as usize] * b.x + uvs[idx[2] as usize] * b.y
            }
            None => b,
        }
    }

    /// Whether every triangle is flat-shaded ([`Mesh::flat_frames`]): always without vertex normals.
    fn all_flat(&self) -> bool {
        self.normals.is_none() || (!self.flat_frames.is_empty() && self.flat_frames.iter().all(Option::is_some))
    }

    /// The first half of [`Self::sample_position`] for a mesh whose triangles are all flat-shaded: the
    /// triangle chosen by `uc`, as its vertices, unit geometric normal and shading normal, and the density
    /// by area. The point in it is [`uniform_triangle_point`] (in lanes, for the renderer's packets).
    /// `None` for meshes with smooth-shaded triangles.
    #[inline]
    #[must_use]
    pub fn sample_flat_triangle(&self, uc: f32) -> Option<([Vec3; 3], Vec3, Vec3, f32)> {
        if !self.all_flat() {
            return None;
        }
        let tri = self.areas.sample_index(uc) as u32;
        let (ng, ns) = self.normals_at(tri, Vec2::ZERO);
        Some((self.vertices(tri), ng, ns, 1.0 / self.area))
    }

    /// [`Self::sample_flat_triangle`] in lanes, for a mesh of at most eight flat-shaded triangles of
    /// positive total area (a `rectangle` is two, as is a quad of a mesh file with normals); `None` for
    /// others.
    #[must_use]
    pub fn flat_triangles8(&self) -> Option<FlatTriangles8> {
        let n = self.triangle_count();
        if !self.all_flat() || n > LANES || !(self.area > 0.0) {
            return None;
        }
        let mut t = FlatTriangles8 {
            thresholds: [f32::INFINITY; LANES],
            threshold_count: 0,
            vertices: [[[0.0; LANES]; 3]; 3],
            geometric: [[0.0; LANES]; 3],
            shading: [[0.0; LANES]; 3],
            density: 1.0 / self.area,
        };
        for (k, th) in self.areas.index_thresholds().into_iter().enumerate() {
            (t.thresholds[k], t.threshold_count) = (th, k + 1);
        }
        for tri in 0..n {
            for (rows, v) in t.vertices.iter_mut().zip(self.vertices(tri as u32)) {
                for axis in 0..3 {
                    rows[axis][tri] = v[axis];
                }
            }
            let (ng, ns) = self.normals_at(tri as u32, Vec2::ZERO);
            for axis in 0..3 {
                (t.geometric[axis][tri], t.shading[axis][tri]) = (ng[axis], ns[axis]);
            }
        }
        Some(t)
    }

    /// A point uniformly distributed over the whole mesh: a triangle by area, then uniform barycentrics
    /// (the square-root warp, pbrt-v4 §6.5.4 / Osada et al. 2002).
    #[must_use]
    pub fn sample_position(&self, uc: f32, u: Vec2) -> PositionSample {
        let tri = self.areas.sample_index(uc) as u32;
        let su = u.x.sqrt();
        let b = Vec2::new(1.0 - su, u.y * su);
        let [p0, p1, p2] = self.vertices(tri);
        let p = uniform_triangle_point::<f32>(p0.into(), p1.into(), p2.into(), u.x, u.y).into();
        let (ng, ns) = self.normals_at(tri, b);
        PositionSample { p, n: ns, ng, pdf_area: 1.0 / self.area }
    }
}

/// Lanes per [`FlatTriangles8`].
const LANES: usize = 8;

/// A flat-shaded mesh of at most eight triangles as rows of lanes ([`Mesh::flat_triangles8`]): the path
/// tracer's next-event estimation chooses a small area light's triangle for eight paths at once, with the
/// same choice and vertices as [`Mesh::sample_flat_triangle`] per lane.
#[derive(Clone, Debug)]
pub struct FlatTriangles8 {
    /// The area CDF's [`Distribution1D::index_thresholds`], +∞ after them, and how many there are.
    thresholds: [f32; LANES],
    threshold_count: usize,
    /// `vertices[v][axis][triangle]`.
    vertices: [[[f32; LANES]; 3]; 3],
    /// `geometric[axis][triangle]`: the unit geometric normals; `shading`, the shading normals.
    geometric: [[f32; LANES]; 3],
    shading: [[f32; LANES]; 3],
    /// 1 / the mesh's area.
    pub density: f32,
}

impl FlatTriangles8 {
    /// The triangle chosen by `uc` in each lane, as its vertices, unit geometric normal and shading normal.
    #[inline(always)]
    #[must_use]
    pub fn sample(&self, uc: Float8) -> ([V3<Float8>; 3], V3<Float8>, V3<Float8>) {
        let (zero, one) = (Float8::splat(0.0), Float8::splat(1.0));
        // The index: how many thresholds lie at or below uc (at most seven; the +∞ after them never do, and
        // are not compared: a rectangle has one threshold).
        let index = self.thresholds[..self.threshold_count.min(LANES - 1)]
            .iter()
            .fold(zero, |k, &t| k + Float8::select(uc.ge(Float8::splat(t)), one, zero));
        let row = |r: &[[f32; LANES]; 3]| {
            let v = lane_rows(r);
            V3::new(v.x.permute(index), v.y.permute(index), v.z.permute(index))
        };
        ([row(&self.vertices[0]), row(&self.vertices[1]), row(&self.vertices[2])], row(&self.geometric), row(&self.shading))
    }
}

/// Texture coordinates over a flat triangle or parallelogram as an affine function of the point
/// ([`Mesh::uv_map`]): uv = uv₀ + ((p − p₀)·g_u, (p − p₀)·g_v), p₀ a corner and uv₀ its coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct UvMap {
    pub p0: Vec3,
    pub gu: Vec3,
    pub gv: Vec3,
    pub uv0: Vec2,
}

impl UvMap {
    /// The texture coordinates at `p` (a point of the plane).
    #[inline(always)]
    #[must_use]
    pub fn at(&self, p: Vec3) -> Vec2 {
        let q = p - self.p0;
        self.uv0 + Vec2::new(q.dot(self.gu), q.dot(self.gv))
    }
}

/// The barycentrics (b₁, b₂) in a triangle of the point at (s, t) along the edges from its corner `k`
/// ([`Mesh::corner_edges`]): the weights of corners k, k + 1, k + 2 are 1 − s − t, s, t. For the
/// parallelogram of [`Mesh::parallelogram`] they extrapolate beyond the triangle (a weight below zero),
/// which is exact for what is affine over it.
#[inline]
#[must_use]
pub fn parallelogram_barycentrics(k: u8, st: Vec2) -> Vec2 {
    let rest = 1.0 - st.x - st.y;
    match k {
        0 => st,
        1 => Vec2::new(rest, st.x),
        _ => Vec2::new(st.y, rest),
    }
}

/// The point p₀ + b₁ e₁ + b₂ e₂ of the triangle with corner p₀ and edges e₁, e₂, in lanes. From the
/// barycentrics rather than as o + t d, which is less accurate (pbrt-v4 §6.8.6).
#[inline(always)]
#[must_use]
pub fn barycentric_point<R: Real>(p0: V3<R>, e1: V3<R>, e2: V3<R>, b1: R, b2: R) -> V3<R> {
    p0.add(e1.scale(b1)).add(e2.scale(b2))
}

/// The unit geometric normal of a triangle whose edges e₁ = p₁ − p₀ and e₂ = p₂ − p₀ have the cross
/// product `cross` = e₁ × e₂ (zero where it is degenerate), times `sign` (−1 reverses it, for
/// `flip_normals`): [`Mesh::geometric_normal`], which holds it for each triangle, and the same numbers
/// where a caller has the edges.
#[inline]
#[must_use]
pub fn face_normal(cross: Vec3, sign: f32) -> Vec3 {
    cross.normalize_or_zero() * sign
}

/// The shading normal at barycentrics (b₁, b₂) of a triangle with vertex normals `n` (as stored; `sign`
/// −1 reverses them, for `flip_normals`): their interpolation, normalised, or `ng` where it has no length
/// (as glam's `try_normalize` decides) — in lanes, and for one triangle ([`Mesh::interaction`]).
#[inline(always)]
#[must_use]
pub fn smooth_normal<R: Real>(n: [V3<R>; 3], b1: R, b2: R, sign: R, ng: V3<R>) -> V3<R> {
    let one = R::splat(1.0);
    let sum = n[0].scale(one - b1 - b2).add(n[1].scale(b1)).add(n[2].scale(b2)).scale(sign);
    let rcp = one / sum.length();
    V3::select(rcp.gt(R::splat(0.0)) & rcp.lt(R::splat(f32::INFINITY)), sum.scale(rcp), ng)
}

/// The point of triangle (p₀, p₁, p₂) at barycentrics (1 − √u₁, u₂ √u₁) — uniform by area for uniform
/// (u₁, u₂) (the square-root warp, pbrt-v4 §6.5.4) — in lanes.
#[inline(always)]
#[must_use]
pub fn uniform_triangle_point<R: Real>(p0: V3<R>, p1: V3<R>, p2: V3<R>, ux: R, uy: R) -> V3<R> {
    let su = ux.sqrt();
    let (bx, by) = (R::splat(1.0) - su, uy * su);
    p0.scale(R::splat(1.0) - bx - by).add(p1.scale(bx)).add(p2.scale(by))
}

/// Vertex normals as the angle-weighted mean of the adjacent face normals (world space, unit length;
/// a vertex of degenerate faces only gets the zero vector, and shading falls back to the face normal).
fn angle_weighted_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    // Each triangle's three terms in parallel (the arc cosines are most of the work), then summed per
    // vertex in triangle order, as one pass would.
    let terms: Vec<Option<[Vec3; 3]>> = indices
        .par_iter()
        .map(|tri| {
            let p = tri.map(|i| positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize()?;
            Some(std::array::from_fn(|k| {
                let (a, b) = ((p[(k + 1) % 3] - p[k]).normalize_or_zero(), (p[(k + 2) % 3] - p[k]).normalize_or_zero());
                n * a.dot(b).clamp(-1.0, 1.0).acos()
            }))
        })
        .collect();
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for (tri, terms) in indices.iter().zip(&terms) {
        for (&i, &term) in tri.iter().zip(terms.iter().flatten()) {
            normals[i as usize] += term;
        }
    }
    normals.par_iter().map(|n| n.normalize_or_zero()).collect()
}

/// Möller–Trumbore for the triangle p₀ + b₁ e₁ + b₂ e₂; the hit's `uv` holds (b₁, b₂).
///
/// The determinant and Cramer's-rule numerators of Möller & Trumbore 1997 (eq. 5) are scalar triple
/// products, rewritten with a·(b×c) = b·(c×a) so that only the ray-dependent cross product remains per
/// test: with m = e₂ × e₁ (per triangle), t′ = p₀ − o and r = d × t′,
///   det = d·m,   b₁ = e₂·r / det,   b₂ = −e₁·r / det,   t = t′·m / det.
/// One cross product per test instead of two (2026-11: a ninth of the packet test's arithmetic). As in the
/// paper's division-deferring variant, the barycentric conditions are tested on the numerators, their signs
/// flipped with det's
/// (b₁ ≥ 0 ⇔ U ≥ 0, b₁ + b₂ ≤ 1 ⇔ U + V ≤ |det|), and the division (t) only follows a pass (2026-11:
/// divisions had been a tenth of a Cornell box render's time, in the packet tests).
#[inline]
#[must_use]
pub fn intersect_triangle(p0: Vec3, e1: Vec3, e2: Vec3, ray: &Ray) -> Option<PrimHit> {
    let (ne1, m) = (-e1, e2.cross(e1));
    let (hit, t, b1, b2) =
        intersect_triangle_lanes::<f32>(ray.o.into(), ray.d.into(), p0.into(), e2.into(), ne1.into(), m.into(), 1.0, ray.tmax);
    hit.then_some(PrimHit { t, uv: Vec2::new(b1, b2) })
}

/// [`intersect_triangle`] in lanes — of triangles for one ray ([`Triangle8`]) or of rays for one triangle —
/// with the per-triangle terms precomputed (−e₁ and m = e₂ × e₁), the same operations in every lane: the
/// lanes hit within (0, tmax), and their t, b₁, b₂ (meaningful in those lanes only). `diagonal` is 1 for
/// the triangle, and 0 for the parallelogram p₀ + b₁ e₁ + b₂ e₂ with b₁, b₂ in [0, 1] (two triangles of a
/// mesh tested as one: [`Mesh::parallelogram`]); see [`triangle_numerators`].
#[inline(always)]
#[must_use]
#[allow(clippy::too_many_arguments)] // the ray and the precomputed terms of the test
pub fn intersect_triangle_lanes<R: Real>(
    o: V3<R>,
    d: V3<R>,
    p0: V3<R>,
    e2: V3<R>,
    ne1: V3<R>,
    m: V3<R>,
    diagonal: R,
    tmax: R,
) -> (R::Mask, R, R, R) {
    let n = triangle_numerators(o, d, p0, e2, ne1, m, diagonal);
    if !R::any(n.inside) {
        let zero = R::splat(0.0);
        return (n.inside, zero, zero, zero);
    }
    let t = n.tt / n.abs_det;
    (n.inside & t.gt(R::splat(0.0)) & t.lt(tmax), t, n.u / n.abs_det, n.v / n.abs_det)
}

/// The division-free part of [`intersect_triangle_lanes`]: whether the ray's line passes inside each
/// triangle (the callers test t's sign), and the numerators of b₁, b₂ and t with det's sign moved onto
/// them, and |det|.
struct Numerators<R: Real> {
    inside: R::Mask,
    u: R,
    v: R,
    tt: R,
    abs_det: R,
}

/// The division-free part of [`intersect_triangle_lanes`] (see there). The far side is b₁ + b₂ ≤ 1 for a
/// triangle and b₁ ≤ 1, b₂ ≤ 1 for a parallelogram, tested for both as b₁ + `diagonal` · b₂ ≤ 1 and
/// b₂ ≤ 1 (which b₁ ≥ 0 and b₁ + b₂ ≤ 1 imply for a triangle; its sum is the same bits as before,
/// 1 · b₂ + b₁ being b₁ + b₂ rounded once).
#[inline(always)]
fn triangle_numerators<R: Real>(o: V3<R>, d: V3<R>, p0: V3<R>, e2: V3<R>, ne1: V3<R>, m: V3<R>, diagonal: R) -> Numerators<R> {
    // Dot and cross products by `Real::mad`: fused where the build has FMA (2026-12: about a fifth fewer
    // instructions in this test, which is most of a Cornell box render's traversal).
    let dot = |a: V3<R>, b: V3<R>| a.z.mad(b.z, a.y.mad(b.y, a.x * b.x));
    let cross = |a: V3<R>, b: V3<R>| V3::new(a.y.mad(b.z, -(b.y * a.z)), a.z.mad(b.x, -(b.z * a.x)), a.x.mad(b.y, -(b.x * a.y)));
    let det = dot(d, m);
    let tp = p0.sub(o);
    let r = cross(d, tp);
    let zero = R::splat(0.0);
    // The numerators with det's sign moved onto them (a negation is exact; by its sign bit, so det = −0
    // flips them too, which changes no hit: see below).
    let (u, v, tt, abs_det) = (dot(e2, r).xor_sign(det), dot(ne1, r).xor_sign(det), dot(tp, m).xor_sign(det), det.abs());
    // Comparisons with NaN are false: degenerate lanes drop out. det = 0 and t ≤ 0 need no test of their
    // own: where |det| = 0 the conditions leave only u = v = 0, and then t = tt / 0 is ±∞ or NaN, which the
    // callers' 0 < t < tmax rejects (as it does t ≤ 0, tt ≤ 0's).
    let inside = u.ge(zero) & v.ge(zero) & diagonal.mad(v, u).le(abs_det) & v.le(abs_det);
    Numerators { inside, u, v, tt, abs_det }
}

/// The lanes of [`intersect_triangle_lanes`] hit within (0, tmax) and their t (the same bits), without its
/// branch: t is divided out in every lane. For one ray against a leaf's eight triangles, whether any of
/// them passes the division-free tests is a coin toss to the branch predictor, and a wrong guess costs more
/// than the division it would save (2026-12, a path tracer's packets on the Cornell box, gonio-bench/benches/bvh.rs
/// `packets`: closest hits 6–10 % and shadow rays about 10 % faster with [`Triangle8::nearest`] and
/// [`Triangle8::any`] on this than on the branching test; and a packet's rays against one triangle,
/// [`Triangle8::intersect_rays`], the same way: see `RAYS_PER_TRIANGLE` in `scene`).
#[inline(always)]
#[allow(clippy::too_many_arguments)] // the ray and the precomputed terms of the test
fn intersect_triangle_lanes_t<R: Real>(
    o: V3<R>,
    d: V3<R>,
    p0: V3<R>,
    e2: V3<R>,
    ne1: V3<R>,
    m: V3<R>,
    diagonal: R,
    tmax: R,
) -> (R::Mask, R) {
    let n = triangle_numerators(o, d, p0, e2, ne1, m, diagonal);
    let t = n.tt / n.abs_det;
    (n.inside & t.gt(R::splat(0.0)) & t.lt(tmax), t)
}

/// Rows x, y, z of eight lanes, as lanes.
#[inline(always)]
fn lane_rows(r: &[[f32; 8]; 3]) -> V3<Float8> {
    V3::new(Float8::load(&r[0]), Float8::load(&r[1]), Float8::load(&r[2]))
}

/// Eight triangles in structure-of-arrays form, for [`intersect_triangle`] on eight at once (see
/// [`Float8`] for the registers that takes), with its per-triangle terms precomputed: p₀, e₂, −e₁ and
/// m = e₂ × e₁, each as rows x, y, z of eight lanes. Lanes without a triangle are zero, which the test
/// rejects (determinant 0). A lane may hold a parallelogram instead (two triangles of a mesh:
/// [`Mesh::parallelogram`]), its `diagonal` 0 rather than 1 ([`intersect_triangle_lanes`]).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Triangle8 {
    p0: [[f32; 8]; 3],
    e2: [[f32; 8]; 3],
    neg_e1: [[f32; 8]; 3],
    m: [[f32; 8]; 3],
    diagonal: [f32; 8],
}

impl Default for Triangle8 {
    fn default() -> Self {
        let zero = [[0.0; 8]; 3];
        Triangle8 { p0: zero, e2: zero, neg_e1: zero, m: zero, diagonal: [1.0; 8] }
    }
}

/// The hits of a ray on a [`Triangle8`]: bit `i` of `mask` is set when lane `i` is hit within (0, tmax).
#[derive(Clone, Copy, Debug)]
pub struct Hit8 {
    pub mask: u32,
    pub t: [f32; 8],
    pub b1: [f32; 8],
    pub b2: [f32; 8],
}

impl Triangle8 {
    /// Lane `from_lane` of `from` into lane `lane`.
    #[inline(always)]
    pub fn copy_lane(&mut self, lane: usize, from: &Triangle8, from_lane: usize) {
        for axis in 0..3 {
            self.p0[axis][lane] = from.p0[axis][from_lane];
            self.e2[axis][lane] = from.e2[axis][from_lane];
            self.neg_e1[axis][lane] = from.neg_e1[axis][from_lane];
            self.m[axis][lane] = from.m[axis][from_lane];
        }
        self.diagonal[lane] = from.diagonal[from_lane];
    }

    /// Ray `i` of `rays` against the triangle in lane `i`, in every lane at once, with no distance limit:
    /// the lanes hit, and their points p₀ + b₁ e₁ + b₂ e₂ and barycentrics (b₁, b₂) — those of
    /// [`Self::intersect_lane`] and [`Mesh::interaction`] for the ray alone, bit for bit.
    #[inline(always)]
    #[must_use]
    pub fn points_of_rays(&self, o: V3<Float8>, d: V3<Float8>) -> (Mask8, V3<Float8>, Float8, Float8) {
        let (p0, e2, ne1, m) = (lane_rows(&self.p0), lane_rows(&self.e2), lane_rows(&self.neg_e1), lane_rows(&self.m));
        let (hit, _, b1, b2) = intersect_triangle_lanes(o, d, p0, e2, ne1, m, Float8::load(&self.diagonal), Float8::splat(f32::INFINITY));
        (hit, barycentric_point(p0, ne1.neg(), e2, b1, b2), b1, b2)
    }

    /// Put the triangle (p₀, e₁ = p₁ − p₀, e₂ = p₂ − p₀) in lane `lane`, or with `parallelogram` the
    /// parallelogram p₀ + b₁ e₁ + b₂ e₂, b₁, b₂ in [0, 1].
    pub fn set(&mut self, lane: usize, [p0, e1, e2]: [Vec3; 3], parallelogram: bool) {
        // The same f32 operations as in `intersect_triangle`, so that lanes agree with it bit for bit.
        let (ne1, m) = (-e1, e2.cross(e1));
        for axis in 0..3 {
            self.p0[axis][lane] = p0[axis];
            self.e2[axis][lane] = e2[axis];
            self.neg_e1[axis][lane] = ne1[axis];
            self.m[axis][lane] = m[axis];
        }
        self.diagonal[lane] = if parallelogram { 0.0 } else { 1.0 };
    }

    /// The triangle in lane `lane` as (p₀, e₁, e₂), the arguments of [`intersect_triangle`] it was set from.
    #[inline(always)]
    #[must_use]
    pub fn edges(&self, lane: usize) -> [Vec3; 3] {
        let row = |r: &[[f32; 8]; 3]| Vec3::new(r[0][lane], r[1][lane], r[2][lane]);
        [row(&self.p0), -row(&self.neg_e1), row(&self.e2)]
    }

    /// Lane `lane`'s triangle or parallelogram against one ray, by the scalar test: the hit within
    /// (0, ray.tmax), its `uv` the coordinates (b₁, b₂) along e₁ and e₂.
    #[inline]
    #[must_use]
    pub fn intersect_lane(&self, lane: usize, ray: &Ray) -> Option<PrimHit> {
        let row = |r: &[[f32; 8]; 3]| V3::new(r[0][lane], r[1][lane], r[2][lane]);
        let (hit, t, b1, b2) = intersect_triangle_lanes::<f32>(
            ray.o.into(),
            ray.d.into(),
            row(&self.p0),
            row(&self.e2),
            row(&self.neg_e1),
            row(&self.m),
            self.diagonal[lane],
            ray.tmax,
        );
        hit.then_some(PrimHit { t, uv: Vec2::new(b1, b2) })
    }

    /// [`intersect_triangle`] on all eight lanes, operation for operation, up to the comparisons: the
    /// lanes hit within (0, tmax) and their t, b₁, b₂ (as the scalar test computes them).
    #[inline(always)]
    fn lanes(&self, ray: &Ray, tmax: f32) -> (Mask8, Float8, Float8, Float8) {
        let (p0, e2, ne1, m) = (lane_rows(&self.p0), lane_rows(&self.e2), lane_rows(&self.neg_e1), lane_rows(&self.m));
        intersect_triangle_lanes(V3::splat(ray.o), V3::splat(ray.d), p0, e2, ne1, m, Float8::load(&self.diagonal), Float8::splat(tmax))
    }

    /// The lanes hit within (0, tmax) and their t, by [`intersect_triangle_lanes_t`] (no branch).
    #[inline(always)]
    fn lanes_t(&self, ray: &Ray, tmax: f32) -> (Mask8, Float8) {
        let (p0, e2, ne1, m) = (lane_rows(&self.p0), lane_rows(&self.e2), lane_rows(&self.neg_e1), lane_rows(&self.m));
        intersect_triangle_lanes_t(V3::splat(ray.o), V3::splat(ray.d), p0, e2, ne1, m, Float8::load(&self.diagonal), Float8::splat(tmax))
    }

    /// Whether lane `lane` holds a triangle (padding and other shapes are zero).
    #[inline(always)]
    #[must_use]
    pub fn has(&self, lane: usize) -> bool {
        self.m[0][lane] != 0.0 || self.m[1][lane] != 0.0 || self.m[2][lane] != 0.0
    }

    /// The triangle in lane `lane` tested against eight rays (one per lane of `o`, `d`, `tmax`): the rays
    /// that hit it and their distances, as [`intersect_triangle`] computes them, without a branch (by
    /// [`intersect_triangle_lanes_t`]).
    #[inline(always)]
    #[must_use]
    pub fn intersect_rays(&self, lane: usize, o: V3<Float8>, d: V3<Float8>, tmax: Float8) -> (Mask8, Float8) {
        let row = |r: &[[f32; 8]; 3]| V3::new(Float8::splat(r[0][lane]), Float8::splat(r[1][lane]), Float8::splat(r[2][lane]));
        intersect_triangle_lanes_t(
            o,
            d,
            row(&self.p0),
            row(&self.e2),
            row(&self.neg_e1),
            row(&self.m),
            Float8::splat(self.diagonal[lane]),
            tmax,
        )
    }

    /// The lanes hit within (0, tmax), with their distances and barycentrics.
    #[inline(always)]
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Hit8 {
        let (ok, t, b1, b2) = self.lanes(ray, tmax);
        Hit8 { mask: ok.bitmask(), t: t.to_array(), b1: b1.to_array(), b2: b2.to_array() }
    }

    /// The nearest lane hit within (0, tmax), and its distance: what closest-hit traversal needs (the
    /// barycentrics of the triangle finally hit, where they are needed, are recomputed by
    /// [`Self::intersect_lane`], rather than kept for every packet on the way).
    #[inline(always)]
    #[must_use]
    pub fn nearest(&self, ray: &Ray, tmax: f32) -> Option<(f32, u32)> {
        let (ok, t) = self.lanes_t(ray, tmax);
        let mask = ok.bitmask();
        if mask == 0 {
            return None;
        }
        let t = t.to_array();
        let mut lane = mask.trailing_zeros();
        let mut rest = mask & (mask - 1);
        // Usually one lane; else the smallest t, the first lane among equals (as a scan in lane order).
        while rest != 0 {
            let l = rest.trailing_zeros();
            rest &= rest - 1;
            if t[l as usize] < t[lane as usize] {
                lane = l;
            }
        }
        Some((t[lane as usize], lane))
    }

    /// Whether any lane is hit within (0, tmax) (for shadow rays: nothing but the mask is stored).
    #[inline(always)]
    #[must_use]
    pub fn any(&self, ray: &Ray, tmax: f32) -> bool {
        self.lanes_t(ray, tmax).0.bitmask() != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        let p = vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)];
        Mesh::new(p, None, None, vec![[0, 1, 2], [2, 3, 0]], &Transform::IDENTITY, false, false, "test").unwrap()
    }

    #[test]
    fn quad_area_hit_and_normal() {
        let m = quad();
        assert!((m.area() - 4.0).abs() < 1e-6);
        let r = Ray::new(Vec3::new(0.3, 0.2, 2.0), -Vec3::Z, 10.0);
        let h = (0..2).find_map(|t| m.intersect(t, &r).map(|h| (t, h))).unwrap();
        assert!((h.1.t - 2.0).abs() < 1e-6);
        let si = m.interaction(h.0, &r, &h.1, true);
        assert!((si.n - Vec3::Z).length() < 1e-6 && (si.p - Vec3::new(0.3, 0.2, 0.0)).length() < 1e-6);
    }

    /// The first shading tangent follows ∂p/∂u (Mitsuba's convention, which anisotropic models rely on):
    /// u grows along −y here, and the mesh is tilted so that ∂p/∂u is not orthogonal to the shading normal.
    #[test]
    fn shading_tangent_follows_dp_du() {
        let p = vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)];
        let uv = vec![Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0), Vec2::new(0.0, 0.0)];
        let tilt = Transform::rotate(Vec3::X, 30.0).unwrap();
        let m = Mesh::new(p, None, Some(uv), vec![[0, 1, 2], [2, 3, 0]], &tilt, false, false, "test").unwrap();
        let r = Ray::new(tilt.point(Vec3::new(0.3, 0.2, 0.0)) + tilt.vector(Vec3::Z) * 2.0, -tilt.vector(Vec3::Z), 10.0);
        let h = (0..2).find_map(|t| m.intersect(t, &r).map(|h| (t, h))).unwrap();
        let f = m.interaction(h.0, &r, &h.1, true).shading;
        assert!((f.s - tilt.vector(-Vec3::Y)).length() < 1e-5, "{:?}", f.s);
        assert!((f.s.cross(f.t) - f.n).length() < 1e-5 && f.s.dot(f.n).abs() < 1e-6);
    }

    /// Without texture coordinates the first shading tangent is the first edge p₁ − p₀ made orthogonal to
    /// the normal, as Mitsuba 3 takes it; s and t were read from Mitsuba 3.9.1 (`scalar_rgb`,
    /// `si.sh_frame`) for one triangle with its vertices in two orders.
    #[test]
    fn shading_tangent_without_uvs_is_the_first_edge() {
        let (a, b, c) = (Vec3::new(-1.0, -1.0, 0.0), Vec3::new(2.0, -1.0, 0.2), Vec3::new(-1.0, 2.0, 0.1));
        let cases = [
            (vec![a, b, c], Vec3::new(0.997_785_15, 0.0, 0.066_519_015), Vec3::new(-0.002_211_166_8, 0.999_447_35, 0.033_167_504)),
            (vec![b, c, a], Vec3::new(-0.706_910_4, 0.706_910_4, -0.023_563_683), Vec3::new(-0.704_171_6, -0.706_521_45, -0.070_495_49)),
        ];
        for (p, s, t) in cases {
            let m = Mesh::new(p, None, None, vec![[0, 1, 2]], &Transform::IDENTITY, false, false, "test").unwrap();
            let r = Ray::new(Vec3::new(0.3, -0.2, 3.0), -Vec3::Z, 10.0);
            let f = m.interaction(0, &r, &m.intersect(0, &r).unwrap(), false).shading;
            assert!((f.s - s).length() < 1e-5 && (f.t - t).length() < 1e-5, "s {} t {}", f.s, f.t);
        }
    }

    /// A triangle whose vertex normals agree to [`FLAT_NORMAL_TOLERANCE`] is flat-shaded, with a shading
    /// normal within that of the interpolated one everywhere on it (and its geometric normal its own);
    /// normals that differ by more are interpolated; `flip_normals` turns the flat frame too.
    #[test]
    fn triangles_whose_normals_agree_are_flat() {
        use crate::geometry::shape::PrimHit;
        let positions = vec![Vec3::ZERO, Vec3::new(2.0, 0.0, 0.1), Vec3::new(0.0, 1.0, -0.1)];
        let tilt = |e: f32| vec![Vec3::Y, Vec3::new(e, 1.0, 0.0).normalize(), Vec3::new(0.0, 1.0, e).normalize()];
        let mesh = |e: f32, flip: bool| {
            Mesh::new(positions.clone(), Some(tilt(e)), None, vec![[0, 1, 2]], &Transform::IDENTITY, false, flip, "t").unwrap()
        };
        assert!(mesh(1e-5, false).flat_frame(0).is_none(), "normals 10⁻⁵ apart are interpolated");
        for flip in [false, true] {
            let m = mesh(4e-7, flip);
            let frame = *m.flat_frame(0).expect("normals 4·10⁻⁷ apart are flat");
            let ray = Ray::new(Vec3::new(0.3, 5.0, 0.2), -Vec3::Y, f32::INFINITY);
            for b in [Vec2::new(0.1, 0.1), Vec2::new(0.8, 0.1), Vec2::new(0.05, 0.9), Vec2::splat(1.0 / 3.0)] {
                let si = m.interaction(0, &ray, &PrimHit { t: 1.0, uv: b }, false);
                assert_eq!(si.shading, frame);
                assert_eq!(si.n, m.geometric_normal(0));
                let interpolated = m.interpolated_normal(0, b);
                assert!((si.shading.n - interpolated).abs().max_element() <= FLAT_NORMAL_TOLERANCE, "{b}: {:?}", si.shading.n);
                // A point sampled on it (as on an area light) carries the normal a hit there sees.
                assert_eq!(m.sample_position(0.5, b).n, frame.n);
                assert!(si.shading.n.dot(Vec3::Y) * if flip { -1.0 } else { 1.0 } > 0.99);
            }
        }
    }

    #[test]
    fn smooth_normals_of_a_tent_bisect_its_faces() {
        let p = vec![
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let idx = vec![[0, 1, 2], [1, 3, 4], [1, 4, 2]];
        let m = Mesh::from_file_data(p, None, None, idx, &Transform::IDENTITY, false, false, "t").unwrap();
        let n = m.normals.as_ref().unwrap()[1];
        assert!(n.x.abs() < 1e-5 && n.z > 0.99, "{n}");
    }

    #[test]
    fn bad_index_is_an_error() {
        let e = Mesh::new(vec![Vec3::ZERO], None, None, vec![[0, 1, 2]], &Transform::IDENTITY, false, false, "f.obj").unwrap_err();
        assert!(e.to_string().starts_with("f.obj: mesh index 1"), "{e}");
    }

    #[test]
    fn samples_lie_on_the_mesh() {
        let m = quad();
        let mut rng = crate::sampling::Pcg32::new(1, 1);
        for _ in 0..100 {
            let s = m.sample_position(rng.next_f32(), rng.next_vec2());
            assert!(s.p.z == 0.0 && s.p.x.abs() <= 1.0 && s.p.y.abs() <= 1.0 && (s.pdf_area - 0.25).abs() < 1e-6);
        }
    }

    /// The lanes choose the triangle [`Mesh::sample_flat_triangle`] chooses, with its vertices and normals,
    /// for random u and for u at and next to every CDF step, on meshes of one to eight triangles of unequal
    /// areas, without vertex normals and with flat ones (here against the winding: the shading normal is
    /// theirs, as for a hit).
    #[test]
    fn flat_triangles8_choose_as_the_cdf() {
        let mut rng = crate::sampling::Pcg32::new(11, 3);
        for (n, with_normals) in (1..=8usize).flat_map(|n| [(n, false), (n, true)]) {
            let positions: Vec<Vec3> = (0..3 * n).map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 3.0).collect();
            let indices: Vec<[u32; 3]> = (0..n as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
            let flat = |t: usize| {
                let [a, b, c] = [0, 1, 2].map(|k| positions[3 * t + k]);
                (c - a).cross(b - a).normalize()
            };
            let normals = with_normals.then(|| (0..3 * n).map(|i| flat(i / 3)).collect());
            let mesh = Mesh::new(positions.clone(), normals, None, indices, &Transform::IDENTITY, !with_normals, false, "test").unwrap();
            let table = mesh.flat_triangles8().expect("a small flat mesh");
            let mut us: Vec<f32> = (0..64).map(|_| rng.next_f32()).collect();
            for t in mesh.areas.index_thresholds() {
                us.extend([t, f32::from_bits(t.to_bits() - 1), f32::from_bits(t.to_bits() + 1)]);
            }
            us.extend([0.0, 1.0 - f32::EPSILON / 2.0]);
            for chunk in us.chunks(8) {
                let uc = Float8::from_fn(|i| chunk.get(i).copied().unwrap_or(0.0));
                let (vertices, ng, ns) = table.sample(uc);
                for (i, &u) in chunk.iter().enumerate() {
                    let (want, want_ng, want_ns, density) = mesh.sample_flat_triangle(u).unwrap();
                    for (v, w) in vertices.iter().zip(want) {
                        assert_eq!(Vec3::new(v.x.lane(i), v.y.lane(i), v.z.lane(i)), w, "n = {n}, u = {u}");
                    }
                    assert_eq!(Vec3::new(ng.x.lane(i), ng.y.lane(i), ng.z.lane(i)), want_ng);
                    assert_eq!(Vec3::new(ns.x.lane(i), ns.y.lane(i), ns.z.lane(i)), want_ns);
                    assert_eq!(table.density, density);
                    // The shading normal is the one a point sampled on the triangle carries.
                    let on = mesh.sample_position(u, Vec2::new(0.3, 0.6));
                    assert_eq!((on.ng, on.n), (want_ng, want_ns));
                    assert!(want_ng.dot(want_ns) > if with_normals { -1.0001 } else { 0.9999 }, "{want_ng} {want_ns}");
                    if with_normals {
                        assert!(want_ng.dot(want_ns) < -0.9999);
                    }
                }
            }
        }
        let smooth = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            Some(vec![Vec3::Z, Vec3::new(0.1, 0.0, 1.0).normalize(), Vec3::Z]),
            None,
            vec![[0, 1, 2]],
            &Transform::IDENTITY,
            false,
            false,
            "test",
        )
        .unwrap();
        assert!(smooth.flat_triangles8().is_none(), "smooth-shaded meshes sample by their vertex normals");
    }

    /// The 8-wide test agrees with the scalar one, lane by lane, bit for bit.
    #[test]
    fn eight_wide_test_matches_scalar() {
        let mut rng = crate::sampling::Pcg32::new(9, 2);
        let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        for _ in 0..2000 {
            let tris: Vec<[Vec3; 3]> = (0..7).map(|_| [v(), v() * 0.7, v() * 0.7]).collect();
            let mut packet = Triangle8::default();
            for (lane, t) in tris.iter().enumerate() {
                packet.set(lane, *t, lane % 3 == 1);
            }
            let ray =
                Ray::new(v() * 3.0, crate::sampling::warp::sample_uniform_sphere(Vec2::new(v().x * 0.5 + 0.5, v().y * 0.5 + 0.5)), 4.0);
            let h = packet.intersect(&ray, ray.tmax);
            assert_eq!(h.mask & 128, 0, "the empty lane is never hit");
            for (lane, t) in tris.iter().enumerate() {
                // Parallelograms (every third lane) against the scalar test of their lane.
                let scalar = if lane % 3 == 1 { packet.intersect_lane(lane, &ray) } else { intersect_triangle(t[0], t[1], t[2], &ray) };
                assert_eq!(scalar.is_some(), h.mask & (1 << lane) != 0);
                if let Some(s) = scalar {
                    assert_eq!((s.t, s.uv.x, s.uv.y), (h.t[lane], h.b1[lane], h.b2[lane]));
                }
            }
        }
    }

    /// A packet's eight rays against each triangle of a [`Triangle8`] (the leaf test by triangle): the
    /// rays hit and their distances equal the scalar test's, bit for bit, and the empty lane hits nothing.
    #[test]
    fn rays_against_one_triangle_match_scalar() {
        let mut rng = crate::sampling::Pcg32::new(4, 7);
        let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        let mut hits = 0;
        for _ in 0..2000 {
            let tris: Vec<[Vec3; 3]> = (0..7).map(|_| [v(), v() * 0.7, v() * 0.7]).collect();
            let mut packet = Triangle8::default();
            for (lane, t) in tris.iter().enumerate() {
                packet.set(lane, *t, lane % 3 == 1);
            }
            // Each ray aimed near a point of one of the triangles (barycentrics in [-0.2, 1.2]: some
            // miss), with a length that sometimes ends before it.
            let rays: [Ray; 8] = std::array::from_fn(|i| {
                let [p0, p1, p2] = tris[i % 7];
                let (o, b) = (v() * 3.0, v() * 0.7 + Vec3::splat(0.5));
                let target = p0 + (p1 - p0) * b.x + (p2 - p0) * b.y * (1.0 - b.x).max(0.0);
                Ray::new(o, (target - o).try_normalize().unwrap_or(Vec3::Z), 1.0 + 4.0 * b.z)
            });
            let lanes = |f: fn(&Ray) -> Vec3| {
                V3::new(Float8::from_fn(|i| f(&rays[i]).x), Float8::from_fn(|i| f(&rays[i]).y), Float8::from_fn(|i| f(&rays[i]).z))
            };
            let (o, d, tmax) = (lanes(|r| r.o), lanes(|r| r.d), Float8::from_fn(|i| rays[i].tmax));
            for lane in 0..8 {
                let (hit, t) = packet.intersect_rays(lane, o, d, tmax);
                let (hit, t) = (hit.bitmask(), t.to_array());
                for (i, ray) in rays.iter().enumerate() {
                    let scalar = match tris.get(lane) {
                        Some(_) if lane % 3 == 1 => packet.intersect_lane(lane, ray),
                        Some(tri) => intersect_triangle(tri[0], tri[1], tri[2], ray),
                        None => None,
                    };
                    assert_eq!(scalar.is_some(), hit & (1 << i) != 0, "triangle {lane}, ray {i}");
                    if let Some(s) = scalar {
                        assert_eq!(s.t.to_bits(), t[i].to_bits());
                        hits += 1;
                    }
                }
            }
        }
        assert!(hits > 1000, "only {hits} hits: the test would not show a wrong distance");
    }

    /// [`Mesh::uv_map`] gives at a triangle's points what [`Mesh::uv_at`] gives at their barycentrics, from
    /// each corner, with texture coordinates and without (where uv are the barycentrics).
    #[test]
    fn uv_map_matches_the_barycentric_uv() {
        let mut rng = crate::sampling::Pcg32::new(8, 3);
        let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        for round in 0..200 {
            let positions = vec![v() * 5.0 + Vec3::splat(20.0), v(), v()];
            let uvs = (round % 2 == 0).then(|| vec![Vec2::new(0.1, 0.2), Vec2::new(3.0, -1.0), Vec2::new(0.5, 2.5)]);
            let Ok(mesh) = Mesh::new(positions, None, uvs, vec![[0, 1, 2]], &Transform::IDENTITY, true, false, "t") else { continue };
            let (b1, b2) = (v().x * 0.5 + 0.5, v().y * 0.5 + 0.5);
            let b = Vec2::new(b1, b2 * (1.0 - b1));
            let [p0, e1, e2] = mesh.triangle_edges(0);
            let p = p0 + e1 * b.x + e2 * b.y;
            let want = mesh.uv_at(0, b);
            for k in 0..3 {
                let got = mesh.uv_map(0, k).at(p);
                assert!((got - want).length() < 1e-4 * (1.0 + want.length()), "corner {k}: {got} against {want}");
            }
        }
    }

    /// A parallelogram lane is hit where one of its two triangles is: rays are classified by where they
    /// cross its plane (in f64), those within 10⁻⁴ of its border skipped, and the hit's distance and
    /// coordinates agree with that crossing.
    #[test]
    fn parallelogram_is_its_two_triangles() {
        let mut rng = crate::sampling::Pcg32::new(5, 11);
        let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..4000 {
            let (p0, e1, e2) = (v(), v(), v());
            let mut packet = Triangle8::default();
            packet.set(3, [p0, e1, e2], true);
            // Aimed at coordinates in [-0.3, 1.3]².
            let (o, st) = (v() * 4.0, Vec2::new(v().x, v().y) * 0.8 + Vec2::splat(0.5));
            let target = p0 + e1 * st.x + e2 * st.y;
            let ray = Ray::new(o, (target - o).normalize(), 100.0);
            // The crossing in f64: o + t d = p0 + s e1 + u e2.
            let f = |a: Vec3| a.as_dvec3();
            let (d, e1d, e2d) = (f(ray.d), f(e1), f(e2));
            let n = e1d.cross(e2d);
            let t = n.dot(f(p0) - f(ray.o)) / n.dot(d);
            let q = f(ray.o) + d * t - f(p0);
            let (s_, u_) = (q.cross(e2d).dot(n) / n.length_squared(), e1d.cross(q).dot(n) / n.length_squared());
            let margin = [s_, u_, 1.0 - s_, 1.0 - u_].into_iter().fold(f64::INFINITY, f64::min);
            if margin.abs() < 1e-4 || n.length() < 1e-3 || t < 1e-3 {
                continue;
            }
            let hit = packet.intersect_lane(3, &ray);
            assert_eq!(hit.is_some(), margin > 0.0, "crossing at ({s_}, {u_})");
            let Some(hit) = hit else {
                outside += 1;
                continue;
            };
            inside += 1;
            assert!((f64::from(hit.t) - t).abs() < 1e-3 * t, "t {} against {t}", hit.t);
            assert!((f64::from(hit.uv.x) - s_).abs() < 1e-3 && (f64::from(hit.uv.y) - u_).abs() < 1e-3);
            // The triangle half holding the point agrees with the parallelogram.
            let half = if s_ + u_ < 1.0 { intersect_triangle(p0, e1, e2, &ray) } else { intersect_triangle(p0 + e1 + e2, -e1, -e2, &ray) };
            if (s_ + u_ - 1.0).abs() > 1e-4 {
                assert!(half.is_some_and(|h| (h.t - hit.t).abs() <= 1e-3 * hit.t), "{half:?} against {hit:?}");
            }
        }
        assert!(inside > 500 && outside > 500, "{inside} rays inside, {outside} outside");
    }

    /// Which neighbouring triangles are taken as a parallelogram: a rectangle's two (its corner 1, or 2
    /// when a mirroring transform reversed the winding), each of a cube's faces, a pair whose vertex normals
    /// agree, and not a folded pair, a smooth-shaded one, a trapezoid, nor texture coordinates that are not
    /// affine over it.
    #[test]
    fn parallelograms_are_found_where_nothing_changes() {
        use crate::geometry::builtin_meshes::{cube, rectangle};
        let rect = rectangle(&Transform::IDENTITY, false, "t").unwrap();
        assert_eq!(rect.parallelogram(0, true), Some(1));
        assert_eq!(rect.parallelogram(1, true), None, "no third triangle");
        let mirrored = rectangle(&Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap(), false, "t").unwrap();
        assert_eq!(mirrored.parallelogram(0, true), Some(2));
        let tilted =
            Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 37.0).unwrap().then_after(Transform::scale(Vec3::new(0.3, 2.0, 1.0)).unwrap());
        let box_ = cube(&tilted, false, "t").unwrap();
        for face in 0..6 {
            assert!(box_.parallelogram(2 * face, true).is_some(), "face {face}");
            assert!(box_.parallelogram(2 * face + 1, true).is_none(), "across faces {face}, {}", face + 1);
        }
        let quad = |p3: Vec3, uv3: Vec2, normals: Option<Vec<Vec3>>| {
            let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), p3];
            let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::ONE, uv3];
            Mesh::new(positions, normals, Some(uvs), vec![[0, 1, 2], [0, 2, 3]], &Transform::IDENTITY, false, false, "t").unwrap()
        };
        assert_eq!(quad(Vec3::Y, Vec2::Y, None).parallelogram(0, true), Some(1));
        assert_eq!(quad(Vec3::new(0.0, 1.0, 0.5), Vec2::Y, None).parallelogram(0, true), None, "folded");
        assert_eq!(quad(Vec3::new(0.2, 1.0, 0.0), Vec2::Y, None).parallelogram(0, true), None, "a trapezoid");
        assert_eq!(quad(Vec3::Y, Vec2::new(0.3, 1.0), None).parallelogram(0, true), None, "uv not affine");
        assert_eq!(quad(Vec3::Y, Vec2::new(0.3, 1.0), None).parallelogram(0, false), Some(1), "uv unused");
        let tilted = Vec3::new(0.1, 0.0, 1.0).normalize();
        assert_eq!(quad(Vec3::Y, Vec2::Y, Some(vec![Vec3::Z, Vec3::Z, tilted, Vec3::Z])).parallelogram(0, true), None, "smooth-shaded");
        assert_eq!(quad(Vec3::Y, Vec2::Y, Some(vec![Vec3::Z; 4])).parallelogram(0, true), Some(1), "normals that agree");
        // Texture coordinates over a parallelogram's far half, extrapolated from the first triangle.
        let q = quad(Vec3::Y, Vec2::Y, None);
        // The texture coordinates as a function of the point agree, on both halves and outside them.
        for (x, y) in [(0.25, 0.75), (0.9, 0.1), (0.5, 0.5), (1.5, -0.2)] {
            let uv = q.uv_map(0, 1).at(Vec3::new(x, y, 0.0));
            assert!((uv - Vec2::new(x, y)).length() < 1e-6, "({x}, {y}): {uv}");
        }
        // Corner 1 of the first triangle is (1, 0), its edges go to (1, 1) and (0, 0): (0.75, 0.75) along
        // them is the point (0.25, 0.75), in the second triangle, where uv = (x, y).
        let b = parallelogram_barycentrics(1, Vec2::new(0.75, 0.75));
        assert!((q.uv_at(0, b) - Vec2::new(0.25, 0.75)).length() < 1e-6, "{}", q.uv_at(0, b));
    }
}
