//! Fitting from Python: `gonio.fit` runs [`gonio::fit`] — the metric, the direction set and the optimiser
//! of `gonio fit` — on any `Bsdf` (a measured file loaded with `load_bsdf`, or an analytic model).

use crate::{run_released, PyBsdf, SpecError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// Fit each of `models` (names from `fit_models()`) to `target`; returns one dict per model, in order:
/// `model`, `values` (parameter → value), `spec` (the fitted model as JSON text), `error` (E of Ngan et
/// al. 2005), `relative_error`, `per_angle` ((θi band start in degrees, RMS error / RMS signal) per 10°),
/// `seconds`, and `xml`: the file `gonio fit -o` writes (a comment naming `source`, then the `<bsdf>`).
/// `strata` (2…64) sets the direction set as `gonio fit --strata` does. The GIL is released.
#[pyfunction]
#[pyo3(signature = (target, models, strata = 12, source = "<bsdf>"))]
fn fit<'py>(py: Python<'py>, target: PyRef<'py, PyBsdf>, models: Vec<String>, strata: usize, source: &str) -> PyResult<Bound<'py, PyList>> {
    if !(2..=64).contains(&strata) {
        return Err(PyValueError::new_err(format!("`strata` must be in [2, 64], got {strata}")));
    }
    // Every name first, so a typo fails before the (slow) fits.
    let chosen =
        models.iter().map(|m| gonio::fit::model(m)).collect::<Result<Vec<_>, _>>().map_err(|e| SpecError::new_err(e.to_string()))?;
    let bsdf = &target.bsdf;
    let results = run_released(py, || {
        let set = gonio::fit::pairs(bsdf, strata);
        chosen
            .iter()
            .map(|m| {
                let start = std::time::Instant::now();
                gonio::fit::fit(m, &set).map(|f| (f, start.elapsed().as_secs_f64(), set.len()))
            })
            .collect::<Result<Vec<_>, _>>()
    })?
    .map_err(|e| SpecError::new_err(e.to_string()))?;
    let out = PyList::empty(py);
    for (f, seconds, pairs) in results {
        let d = PyDict::new(py);
        d.set_item("model", f.model)?;
        let values = PyDict::new(py);
        for (name, value) in &f.values {
            values.set_item(*name, *value)?;
        }
        d.set_item("values", values)?;
        d.set_item("spec", f.spec.to_string())?;
        d.set_item("error", f.error)?;
        d.set_item("relative_error", f.relative_error)?;
        d.set_item("per_angle", f.per_angle.clone())?;
        d.set_item("seconds", seconds)?;
        d.set_item("xml", gonio::fit::fit_file(&f, source, pairs))?;
        out.append(d)?;
    }
    Ok(out)
}

/// The models `fit` knows: (name, what it is) pairs, as `gonio fit --list` prints them.
#[pyfunction]
fn fit_models() -> Vec<(&'static str, &'static str)> {
    gonio::fit::MODELS.iter().map(|m| (m.name, m.about)).collect()
}

/// The plugin that reads a measured file by its extension (`merl` for `.binary`, `measured` for RGL's
/// `.bsdf`), or `None`.
#[pyfunction]
fn measured_plugin(path: std::path::PathBuf) -> Option<&'static str> {
    gonio::measured::plugin_for_file(&path)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(fit_models, m)?)?;
    m.add_function(wrap_pyfunction!(measured_plugin, m)?)?;
    Ok(())
}
