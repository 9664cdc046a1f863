//! `read_image` / `write_image` over [`gonio::image`]: EXR (float32), PNG (8-bit sRGB) and Radiance HDR,
//! as (H, W, 3) float32 linear RGB arrays. Writes are atomic.

use crate::run_released;
use crate::scene::os_error;
use gonio::image::Image;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Read an image file (EXR, HDR, PNG or JPEG; the format from its first bytes, else its extension) as
/// linear RGB: a float32 array of shape (height, width, 3), top row first. PNG and JPEG are sRGB-decoded;
/// alpha is dropped and grey images are expanded to three channels. Raises `FileNotFoundError` (and other
/// `OSError`s) when the file cannot be read, `ValueError` when it is not a valid image.
#[pyfunction]
fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let image = run_released(py, || gonio::image::read_image(&path))?.map_err(|e| os_error(&e, PyValueError::new_err))?;
    Ok(PyArray1::from_vec(py, image.data).reshape([image.height, image.width, 3])?.into_any())
}

/// Write linear RGB to `path`, atomically (a temporary file renamed over the target): `.exr` as float32,
/// `.png` as 8-bit sRGB (clamped to [0, 1]), `.hdr` as Radiance RGBE (negatives as 0). `array` is float32
/// or float64 of shape (height, width, 3), or (height, width) for grey. Raises `ValueError` for another
/// shape, dtype or extension, `FileNotFoundError` when the directory does not exist.
#[pyfunction]
fn write_image(py: Python<'_>, path: PathBuf, array: &Bound<'_, PyAny>) -> PyResult<()> {
    let (data, shape): (Vec<f32>, Vec<usize>) = if let Ok(a) = array.extract::<PyReadonlyArrayDyn<'_, f32>>() {
        (a.as_array().iter().copied().collect(), a.shape().to_vec())
    } else if let Ok(a) = array.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        (a.as_array().iter().map(|&v| v as f32).collect(), a.shape().to_vec())
    } else {
        let dtype = array.getattr("dtype").map(|d| d.to_string()).unwrap_or_else(|_| array.get_type().to_string());
        return Err(PyValueError::new_err(format!(
            "write_image expects a float32 or float64 numpy array of linear RGB, got {dtype} (convert integer images with e.g. `a / 255`, then decode sRGB)"
        )));
    };
    let (height, width, data) = match shape.as_slice() {
        [h, w, 3] => (*h, *w, data),
        [h, w] => (*h, *w, data.iter().flat_map(|&v| [v; 3]).collect()),
        _ => return Err(PyValueError::new_err(format!("write_image expects shape (height, width, 3) or (height, width), got {shape:?}"))),
    };
    if width == 0 || height == 0 {
        return Err(PyValueError::new_err(format!("write_image: the image has no pixels (shape {shape:?})")));
    }
    let image = Image { width, height, data };
    run_released(py, || gonio::image::write_image(&path, &image))?.map_err(|e| os_error(&e, PyValueError::new_err))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    Ok(())
}
