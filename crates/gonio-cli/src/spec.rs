//! Reading a BSDF argument: a JSON object in Mitsuba's dictionary form, or a path to an XML file holding
//! one `<bsdf>` element (or a JSON file).

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
