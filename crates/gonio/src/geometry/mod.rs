//! Geometry: rays, bounding boxes, the shapes of Mitsuba's scene format (sphere, rectangle, cube, disk,
//! cylinder, triangle meshes, signed-distance grids, and the mesh file loaders in [`mesh_io`]), surface interactions and the bounding volume hierarchy over all primitives.

pub mod bounds;
pub mod builtin_meshes;
pub mod bvh;
pub mod cylinder;
pub mod disk;
pub mod interaction;
pub mod mesh;
pub mod mesh_io;
pub mod ray;
pub mod sdf_grid;
pub mod shape;
pub mod sphere;

pub use bounds::Bounds3;
pub use bvh::Bvh;
pub use interaction::{PositionSample, SurfaceInteraction};
pub use mesh::Mesh;
pub use ray::Ray;
pub use shape::{PrimHit, Shape};
