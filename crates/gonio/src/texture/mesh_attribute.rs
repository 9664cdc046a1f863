//! `mesh_attribute` — a mesh's per-vertex values as a texture (Mitsuba 3's `mesh_attribute`), e.g. the
//! vertex colours of a PLY file.
//!
//! | parameter | type   | default | meaning                                                              |
//! |-----------|--------|---------|----------------------------------------------------------------------|
//! | `name`    | string | —       | the attribute, `vertex_…` as the mesh names it (`vertex_color` for a PLY file's colours) |
//! | `scale`   | float  | 1       | factor on the values                                                 |
//!
//! The value at a hit interpolates the triangle's three vertex values with the hit's barycentrics
//! ([`crate::geometry::Mesh::attribute_at`]); a one-value attribute gives all three channels, a
//! colour's scalar lookup is its luminance. It reads the surface, not texture coordinates: only a BSDF
//! parameter on a mesh that has the attribute can take it (checked when the scene is built). Per-face
//! attributes (`face_…`) are not read yet.

use crate::error::{Error, Result};
use crate::props::Props;

/// A mesh attribute by name, scaled.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttribute {
    pub name: String,
    pub scale: f32,
    /// Where the texture was given (for errors about the shape it is used on).
    pub at: String,
}

impl MeshAttribute {
    pub fn from_props(p: &Props) -> Result<Self> {
        let name = p.string("name")?.ok_or_else(|| Error::spec(p.at(), "`mesh_attribute` needs a `name` (e.g. vertex_color)"))?;
        if name.starts_with("face_") {
            return Err(Error::spec(p.at_param("name"), format!("`{name}`: per-face attributes are not supported yet (only `vertex_…`)")));
        }
        if !name.starts_with("vertex_") {
            return Err(Error::spec(p.at_param("name"), format!("`{name}`: an attribute's name starts with `vertex_` (or `face_`)")));
        }
        let scale = p.float_in("scale", 1.0, f32::MIN, f32::MAX)?;
        Ok(MeshAttribute { name, scale, at: p.at().to_string() })
    }
}
