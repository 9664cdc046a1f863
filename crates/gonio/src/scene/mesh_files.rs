//! Mesh files for `obj` and `ply` shapes, read by `geometry::mesh_io`.

use crate::error::{Error, Result};
use glam::{Vec2, Vec3};
use std::path::Path;

/// Vertex data of one mesh file (mirrors `geometry::mesh_io::MeshData`).
pub struct MeshFile {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    pub indices: Vec<[u32; 3]>,
}

/// Load `path` as `kind` (`obj` or `ply`).
pub fn load(kind: &str, path: &Path, at: &str) -> Result<MeshFile> {
    let _ = path;
    Err(Error::spec(at, format!("`{kind}` meshes need geometry::mesh_io, which is not merged yet")))
}
