//! Vectors (re-exported from `glam`), the shading frame and spherical coordinates.

#[cfg(target_arch = "x86_64")]
pub mod avx2;
pub mod frame;
pub mod lanes;
pub mod spherical;
pub mod transform;
pub mod trig;

pub use frame::Frame;
pub use glam::{DVec3, Vec2, Vec3};
pub use transform::Transform;
