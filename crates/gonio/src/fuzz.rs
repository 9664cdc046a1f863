//! The bodies of the fuzz targets: one function per file format, taking the raw bytes of a file and
//! calling the same loader a user's file goes through. The cargo-fuzz project in `fuzz/` calls these, and
//! `tests/fuzz_regressions.rs` replays the committed corpora and crash files through them on stable.
//!
//! Each function must return for any input, never panic and never hang; errors are expected and only
//! checked for naming the file they came from (every loader promises that, see [`crate::error::Error`]).
//!
//! | target        | loader                                                                     |
//! |---------------|----------------------------------------------------------------------------|
//! | `xml_scene`   | [`mitsuba_xml::load_str`] + [`Scene::build`], files resolved in `fuzz/files`  |
//! | `obj`, `ply`  | [`mesh_io::obj_from_bytes`], [`mesh_io::ply_from_bytes`], then [`Mesh::from_file_data`] |
//! | `serialized`  | [`mesh_io::serialized_from_bytes`] (meshes 0 and 1)                         |
//! | `merl`        | [`MerlTable::from_reader`]                                                  |
//! | `tensor_file` | [`TensorFile::parse`] + [`Measured::from_file`], then f / sample / pdf      |
//! | `exr`, `hdr`, `png` | [`crate::image::decode_image`] (the extension picks the format when the magic does not) |
//! | `bsdf_json`   | [`Bsdf::from_json`], then f / sample / pdf                                  |
//!
//! `xml_scene` and `bsdf_json` give `roughplastic` the smooth coating's tables in closed form instead of
//! integrating them (seconds per α and η): see [`fast_coating_tables`].

use crate::bsdf::rough_plastic::{TableScope, TableSource};
use crate::bsdf::{Bsdf, BsdfModel, Measured};
use crate::error::Result;
use crate::geometry::mesh_io::{self, MeshData};
use crate::geometry::Mesh;
use crate::math::{Transform, Vec2, Vec3};
use crate::measured::tensor_file::TensorFile;
use crate::measured::MerlTable;
use crate::scene::{mitsuba_xml, Scene};
use std::path::Path;

/// The directory `<include>`, mesh and image file names of the `xml_scene` target resolve against: a few
/// tiny files (an include, an include cycle, meshes, an image) kept beside the fuzz project.
pub const FILES_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/files");

/// A target's body: the content of one file.
pub type Target = fn(&[u8]);

/// Every target by name, as the fuzz project and the regression test name them.
pub const TARGETS: &[(&str, Target)] = &[
    ("xml_scene", xml_scene),
    ("obj", obj),
    ("ply", ply),
    ("serialized", serialized),
    ("merl", merl),
    ("tensor_file", tensor_file),
    ("exr", exr),
    ("hdr", hdr),
    ("png", png),
    ("bsdf_json", bsdf_json),
];

/// An error must name the file it is about.
fn check_names<T>(result: Result<T>, name: &str) -> Option<T> {
    match result {
        Ok(v) => Some(v),
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains(name), "the error does not name `{name}`: {text}");
            None
        }
    }
}

/// `roughplastic` integrates coating tables for each (distribution, α, η) it meets: 3.2 s of CPU per
/// table on this machine, more than 5 s of wall time under load (2026-12), against the fuzzers' 10 s and
/// the regression replay's 5 s per input. The first fuzz runs (2026-11) stopped on it and the targets then
/// skipped every input mentioning `roughplastic`, so its parameter handling was never fuzzed. Caching
/// does not help a fuzzer, which meets a new α or η at almost every input (and the α grid,
/// [`TableSource::AlphaGrid`], still integrates two nodes per new α), so the targets that build BSDFs
/// hold a [`TableScope`] of [`TableSource::Smooth`]: the tables are the smooth coating's, in closed form, and
/// everything else — parsing, range checks, the η = 1 and anisotropy refusals, energy compensation, f /
/// sample / pdf at the model's own α and η — is the model's own code. The integration is tested at the
/// ends of the parameter ranges instead (`rough_plastic::tests::tables_are_finite_at_the_parameter_extremes`).
fn fast_coating_tables() -> TableScope {
    TableScope::new(TableSource::Smooth)
}

/// A Mitsuba XML scene: defaults, `$` substitution, refs, includes, transforms, then the scene build
/// (`roughplastic` with closed-form coating tables: [`fast_coating_tables`]).
pub fn xml_scene(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _tables = fast_coating_tables();
    if let Ok(desc) = mitsuba_xml::load_str(text, "fuzz.xml", Path::new(FILES_DIR), &[]) {
        let _ = Scene::build(desc);
    }
}

/// A loaded mesh must also build (indices in range, normals computed).
fn build_mesh(mesh: Option<MeshData>) {
    if let Some(m) = mesh {
        let _ = Mesh::from_file_data(m.positions, m.normals, m.uvs, m.indices, &Transform::IDENTITY, false, false, "fuzz");
    }
}

pub fn obj(data: &[u8]) {
    build_mesh(check_names(mesh_io::obj_from_bytes(Path::new("fuzz.obj"), data), "fuzz.obj"));
}

pub fn ply(data: &[u8]) {
    build_mesh(check_names(mesh_io::ply_from_bytes(Path::new("fuzz.ply"), data), "fuzz.ply"));
}

pub fn serialized(data: &[u8]) {
    for index in [0, 1] {
        build_mesh(check_names(mesh_io::serialized_from_bytes(Path::new("fuzz.serialized"), data, index), "fuzz.serialized"));
    }
}

pub fn merl(data: &[u8]) {
    let _ = check_names(MerlTable::from_reader(Path::new("fuzz.binary"), data, data.len() as u64), "fuzz.binary");
}

/// A few fixed queries, including grazing and below-the-horizon directions.
fn exercise(bsdf: &Bsdf) {
    let dirs = [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.8, 0.6), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.6, -0.8)];
    for &wo in &dirs {
        for &wi in &dirs {
            let _ = bsdf.f(wo, wi);
            let _ = bsdf.pdf(wo, wi);
        }
        for u in [0.0, 0.3, 0.999_999] {
            let _ = bsdf.sample(wo, u, Vec2::new(u, 1.0 - u));
        }
    }
}

pub fn tensor_file(data: &[u8]) {
    let path = Path::new("fuzz.bsdf");
    let measured = TensorFile::parse(path, data.to_vec()).and_then(Measured::from_file);
    if let Some(m) = check_names(measured, "fuzz.bsdf") {
        exercise(&Bsdf::Measured(m));
    }
}

fn image(data: &[u8], name: &str) {
    let _ = check_names(crate::image::decode_image(Path::new(name), data), name);
}

pub fn exr(data: &[u8]) {
    image(data, "fuzz.exr");
}

pub fn hdr(data: &[u8]) {
    image(data, "fuzz.hdr");
}

pub fn png(data: &[u8]) {
    image(data, "fuzz.png");
}

/// A BSDF in Mitsuba's dictionary form, as `gonio check --spec` and Python take it ([`Bsdf::from_json`];
/// `roughplastic` with closed-form coating tables: [`fast_coating_tables`]).
pub fn bsdf_json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _tables = fast_coating_tables();
    if let Ok(bsdf) = Bsdf::from_json(text) {
        exercise(&bsdf);
    }
}
