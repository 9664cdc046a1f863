//! What a ray found: the surface interaction record, and points sampled on a shape's surface.

use crate::math::Frame;
use glam::{Vec2, Vec3};

/// A ray–surface intersection, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// Ray parameter of the hit.
    pub t: f32,
    pub p: Vec3,
    /// Geometric normal, unit length, the shape's outward side (after `flip_normals`).
    pub n: Vec3,
    /// Shading frame; `shading.n` is the interpolated normal for meshes with vertex normals.
    pub shading: Frame,
    /// Texture coordinates, where the scene asked for them (its material is textured); else zero.
    pub uv: Vec2,
    /// Index of the shape in the scene.
    pub shape: u32,
    /// Index of the primitive (triangle) within the shape.
    pub prim: u32,
}

/// A point sampled on a surface with its density with respect to area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionSample {
    pub p: Vec3,
    /// Unit normal at `p` (the shading normal: the side that emits for area lights).
    pub n: Vec3,
    /// Geometric normal (for ray offsetting).
    pub ng: Vec3,
    pub pdf_area: f32,
}
