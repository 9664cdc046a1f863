//! Mesh files for `obj`, `ply` and `serialized` shapes, read by [`crate::geometry::mesh_io`]; errors keep the file's
//! own location and are prefixed with the shape's place in the scene.

use crate::error::{Error, Result};
use crate::geometry::mesh_io::{load_obj, load_ply, load_serialized, MeshData};
use std::path::Path;

/// Load `path` as `kind` (`obj`, `ply` or `serialized`, of which mesh number `shape_index`); `at` is the
/// shape element.
pub fn load(kind: &str, path: &Path, shape_index: usize, at: &str) -> Result<MeshData> {
    let loaded = match kind {
        "obj" => load_obj(path),
        "ply" => load_ply(path),
        "serialized" => load_serialized(path, shape_index),
        other => return Err(Error::spec(at, format!("`{other}` is not a mesh file format (expected obj, ply or serialized)"))),
    };
    loaded.map_err(|e| Error::spec(at, format!("cannot load the {kind} mesh: {e}")))
}
