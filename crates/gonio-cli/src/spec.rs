//! Reading a BSDF argument: a JSON object in Mitsuba's dictionary form, or a path to an XML file holding
//! one `<bsdf>` element (or a JSON file), a MERL table (`.binary`) or an RGL measurement (`.bsdf`).

use gonio::{Bsdf, Error};
use std::path::Path;

/// Load the BSDF named by a command-line argument.
pub fn load_bsdf(arg: &str) -> Result<Bsdf, Error> {
    let trimmed = arg.trim_start();
    if trimmed.starts_with('{') {
        return Bsdf::from_json(trimmed);
    }
    if trimmed.starts_with('<') {
        return Bsdf::from_xml(trimmed, "<argument>");
    }
    let path = Path::new(arg);
    // Measured data: by extension, through the plugin registry (`merl`, and Mitsuba's `measured`).
    let plugin = match path.extension().and_then(|e| e.to_str()) {
        Some("binary") => Some("merl"),
        Some("bsdf") => Some("measured"),
        _ => None,
    };
    if let Some(plugin) = plugin {
        return Bsdf::from_json(&serde_json::json!({"type": plugin, "filename": arg}).to_string());
    }
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    if text.trim_start().starts_with('{') {
        Bsdf::from_json(&text).map_err(|e| match e {
            Error::Spec { at, message } => Error::Spec { at: format!("{}: {at}", path.display()), message },
            Error::Syntax { at, message } => Error::Syntax { at: format!("{}: {at}", path.display()), message },
            other => other,
        })
    } else {
        Bsdf::from_xml(&text, &path.display().to_string())
    }
}
