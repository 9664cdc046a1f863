use pyo3::prelude::*;
#[pymodule]
fn _gonio(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
