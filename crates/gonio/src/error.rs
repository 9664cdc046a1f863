//! The error type of gonio: every failure a user can cause names where it happened and what was expected.

use std::path::PathBuf;

/// Everything that can go wrong when reading user input. Never a panic: callers print these.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A plugin description (JSON or XML) that is well formed but wrong: unknown type or parameter,
    /// wrong value type, value out of range. `at` is "file:line:col" for XML, a JSON path for JSON.
    #[error("{at}: {message}")]
    Spec { at: String, message: String },
    /// Text that is not valid JSON or XML.
    #[error("{at}: {message}")]
    Syntax { at: String, message: String },
    /// A file that could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A data file (image, mesh) that could be read but is malformed: truncated, an unsupported variant,
    /// a count larger than the file, an index out of range. `at` says where in the file: "line 12" for
    /// text, "byte 1234" for binary, or a record such as "face 17".
    #[error("{}: {at}: {message}", path.display())]
    Format { path: PathBuf, at: String, message: String },
}

impl Error {
    pub(crate) fn spec(at: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Spec { at: at.into(), message: message.into() }
    }
}

impl Error {
    pub(crate) fn format(path: &std::path::Path, at: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Format { path: path.to_path_buf(), at: at.into(), message: message.into() }
    }

    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), source }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
