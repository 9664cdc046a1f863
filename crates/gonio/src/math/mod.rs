//! Vectors (re-exported from `glam`), the shading frame and spherical coordinates.

pub mod frame;
pub mod lanes;
pub mod simd;
pub mod spherical;
pub mod transform;
pub mod trig;

pub use frame::Frame;
pub use glam::{DVec3, Vec2, Vec3};
pub use transform::Transform;
