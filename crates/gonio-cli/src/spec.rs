//! Reading a BSDF argument: a JSON object in Mitsuba's dictionary form, or a path to an XML file holding
//! one `<bsdf>` element (or a JSON file), a MERL table (`.binary`) or an RGL measurement (`.bsdf`).

use gonio::props::Props;
use gonio::{Bsdf, Error};
use std::path::Path;

/// Load the BSDF named by a command-line argument.
pub fn load_bsdf(arg: &str) -> Result<Bsdf, Error> {
    Bsdf::from_props(&load_props(arg)?).map_err(|e| in_json_file(arg, e))
}

/// Errors located by a JSON path (`$.alpha`) in a JSON *file* also name the file.
pub fn in_json_file(arg: &str, e: Error) -> Error {
    let is_file = !arg.trim_start().starts_with(['{', '<']);
    match e {
        Error::Spec { at, message } if is_file && at.starts_with('$') => Error::Spec { at: format!("{arg}: {at}"), message },
        Error::Syntax { at, message } if is_file && at.starts_with("JSON spec") => Error::Syntax { at: format!("{arg}: {at}"), message },
        other => other,
    }
}

pub use gonio::measured::plugin_for_file as measured_plugin;

/// The plugin description named by a command-line argument, not yet built (it may hold textures, which
/// `gonio::scene::Material` evaluates; a plain `Bsdf` takes none).
pub fn load_props(arg: &str) -> Result<Props, Error> {
    let trimmed = arg.trim_start();
    if trimmed.starts_with('{') {
        return Props::from_json(trimmed);
    }
    if trimmed.starts_with('<') {
        return Props::from_xml_bsdf(trimmed, "<argument>");
    }
    let path = Path::new(arg);
    if let Some(plugin) = measured_plugin(path) {
        return Props::from_json(&serde_json::json!({"type": plugin, "filename": arg}).to_string());
    }
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    if text.trim_start().starts_with('{') {
        Props::from_json(&text).map_err(|e| in_json_file(arg, e))
    } else {
        Props::from_xml_bsdf(&text, &path.display().to_string())
    }
}
