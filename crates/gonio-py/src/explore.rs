//! `gonio._gonio.Explorer`: the explorer's requests answered in the extension ([`gonio::explore`], the
//! code behind `gonio explore`), for the Jupyter widget of `gonio.explore`, and the page's script and
//! style sheet (the repository's `web/`, the same files the CLI serves).

use crate::run_released;
use gonio::explore::Explorer;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::PathBuf;

/// The widget's JavaScript module (also the page's) and its style sheet.
const EXPLORER_JS: &str = include_str!("../../../web/explorer.js");
const EXPLORER_CSS: &str = include_str!("../../../web/explorer.css");

/// Answers the explorer's requests (`/api/models`, `/api/plot`, `/api/sphere`, …) as `gonio explore` does.
#[pyclass(module = "gonio._gonio", name = "Explorer", frozen)]
pub struct PyExplorer(Explorer);

#[pymethods]
impl PyExplorer {
    /// `data`: a folder of measured files the page may load; `files`: more measured files; `environment`:
    /// the environment map of the lit sphere (else the built-in sky); `initial`: JSON specs shown first.
    #[new]
    #[pyo3(signature = (data = None, files = Vec::new(), environment = None, initial = Vec::new()))]
    fn new(data: Option<PathBuf>, files: Vec<PathBuf>, environment: Option<PathBuf>, initial: Vec<String>) -> Self {
        PyExplorer(Explorer::new(data, files, environment, initial))
    }

    /// The answer to `path` with the URL-encoded `query`: `(status, content_type, body)`.
    fn handle<'py>(&self, py: Python<'py>, path: &str, query: &str) -> PyResult<(u16, &'static str, Bound<'py, PyBytes>)> {
        let reply = run_released(py, || self.0.handle(path, query))?;
        Ok((reply.status, reply.content_type, PyBytes::new(py, &reply.body)))
    }
}

/// The page's JavaScript module and style sheet: `(js, css)`.
#[pyfunction]
fn _explorer_page() -> (&'static str, &'static str) {
    (EXPLORER_JS, EXPLORER_CSS)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyExplorer>()?;
    m.add_function(wrap_pyfunction!(_explorer_page, m)?)?;
    Ok(())
}
