//! Measured reflectance data: the file formats gonio reads measured materials from, and the virtual
//! gonioreflectometer.
//!
//! - [`merl_file`]: the MERL BRDF table (Matusik et al. 2003), read by the [`merl`](crate::bsdf::merl) BSDF;
//! - [`gonioreflectometer`]: tabulates any model into a MERL table;
//! - [`tensor_file`]: the `tensor_file` container of Mitsuba and the RGL material database
//!   (read by the [`measured`](crate::bsdf::measured) BSDF).

pub mod gonioreflectometer;
pub mod merl_file;
pub mod tensor_file;

pub use merl_file::{Interpolation, MerlTable};

/// The plugin that reads a measured file, by its extension (`.binary`: `merl`; `.bsdf`: Mitsuba's
/// `measured`, RGL's format), or `None` for any other file.
#[must_use]
pub fn plugin_for_file(path: &std::path::Path) -> Option<&'static str> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("binary") => Some("merl"),
        Some("bsdf") => Some("measured"),
        _ => None,
    }
}

/// Tables shared by the tests: generating one costs 1.46 M evaluations of f, so each is made once.
#[cfg(test)]
pub(crate) mod fixtures {
    use super::gonioreflectometer::measure;
    use super::MerlTable;
    use crate::bsdf::Bsdf;
    use std::path::PathBuf;
    use std::sync::OnceLock;

    /// A Lambertian base plus a GGX copper lobe, as used by the reader tests.
    pub const SMOOTH_SPEC: &str = r#"{"type": "sum", "weights": [1, 1],
        "a": {"type": "diffuse", "reflectance": [0.2, 0.1, 0.05]},
        "b": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, "material": "Cu"}}"#;

    /// A scratch directory for this test process, shared by its tests (the tabulated fixture below is a
    /// 35 MB file that several tests read, so it lives as long as the process). Statics are never
    /// dropped, so the directory outlives the process; the first call removes those of test processes
    /// that have ended (a `/proc/<pid>` check; elsewhere nothing is removed), so that `cargo test` does not
    /// leave one 35 MB file behind per run (2026-12).
    pub fn scratch_dir() -> PathBuf {
        const PREFIX: &str = "gonio-merl-tests-";
        static DIR: OnceLock<PathBuf> = OnceLock::new();
        DIR.get_or_init(|| {
            let tmp = std::env::temp_dir();
            if std::path::Path::new("/proc/self").exists() {
                for entry in std::fs::read_dir(&tmp).into_iter().flatten().flatten() {
                    let name = entry.file_name().to_string_lossy().into_owned();
                    let ended = name
                        .strip_prefix(PREFIX)
                        .and_then(|pid| pid.parse::<u32>().ok())
                        .is_some_and(|pid| !std::path::Path::new(&format!("/proc/{pid}")).exists());
                    if ended {
                        let _ = std::fs::remove_dir_all(entry.path());
                    }
                }
            }
            let dir = tmp.join(format!("{PREFIX}{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            dir
        })
        .clone()
    }

    /// [`SMOOTH_SPEC`] tabulated at the cell centres, written with gonio's writer and read back: the
    /// model, the path of the file and the table as read.
    pub fn smooth() -> &'static (Bsdf, PathBuf, MerlTable) {
        static CELL: OnceLock<(Bsdf, PathBuf, MerlTable)> = OnceLock::new();
        CELL.get_or_init(|| {
            let model = Bsdf::from_json(SMOOTH_SPEC).unwrap();
            let table = measure(&model, 1, "smooth").unwrap();
            let path = scratch_dir().join("smooth.binary");
            table.write(&path).unwrap();
            let read = MerlTable::read(&path).unwrap();
            (model, path, read)
        })
    }
}
