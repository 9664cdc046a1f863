//! `gonio.lobe_data`, `gonio.slice_data`, `gonio.albedo_data`: the numbers of [`gonio::plot`] as numpy
//! arrays — the same functions `gonio plot` draws from, so a notebook and the command line show the same
//! values bit for bit. Every value array has a last axis of four channels: r, g, b and the Rec. 709
//! luminance ([`Channel::ALL`]), float32; angles are float64 degrees.

use crate::{run_released, PyBsdf};
use gonio::plot::{albedo_data, lobe_data, slice_data, Channel};
use gonio::Rgb;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The four channels of each value, row-major, as a float32 array of shape `shape + (4,)`.
fn channels(py: Python<'_>, values: &[Rgb], shape: &[usize]) -> PyResult<PyObject> {
    let flat: Vec<f32> = values.iter().flat_map(|&v| Channel::ALL.map(|c| c.of(v))).collect();
    let mut dims = shape.to_vec();
    dims.push(4);
    Ok(PyArray1::from_vec(py, flat).reshape(dims)?.into_any().unbind())
}

fn angles(py: Python<'_>, values: Vec<f64>) -> PyObject {
    PyArray1::from_vec(py, values).into_any().unbind()
}

/// A count that must not be negative (a negative one is a `ValueError` naming it).
fn count(name: &str, value: i64) -> PyResult<usize> {
    usize::try_from(value).map_err(|_| PyValueError::new_err(format!("`{name}` must not be negative, got {value}")))
}

fn value_error(e: gonio::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The lobe of a model for one viewing angle θo: f·|cos θi| (sr⁻¹) in two planes and over the sphere.
///
/// ωo = (sin θo, 0, cos θo). `angles` (degrees, [−180°, 180°]) parameterise both planes: in the plane
/// of incidence ωi = (sin a, 0, cos a) (mirror direction at a = −θo), in the perpendicular plane
/// ωi = cos a·ωr + sin a·ŷ (a = angle from the mirror direction ωr). The grid has ωi at polar angle
/// `grid_theta[i]` (0° to 90°, or 180° for models that transmit) and azimuth `grid_phi[j]`.
#[pyclass(module = "gonio._gonio", name = "LobeData", frozen, get_all)]
pub(crate) struct PyLobeData {
    /// θo in degrees.
    theta_o: f64,
    /// (samples,) float64: the angles of both planes, degrees.
    angles: PyObject,
    /// (samples, 4) float32: f·|cos θi| in the plane of incidence; columns r, g, b, lum.
    incidence: PyObject,
    /// (samples, 4) float32: f·|cos θi| in the perpendicular plane; columns r, g, b, lum.
    perpendicular: PyObject,
    /// (grid_theta,) float64: polar angles of the grid, degrees.
    grid_theta: PyObject,
    /// (grid_phi,) float64: azimuths of the grid, degrees.
    grid_phi: PyObject,
    /// (grid_theta, grid_phi, 4) float32: f·|cos θi| over the sphere.
    grid: PyObject,
}

#[pymethods]
impl PyLobeData {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let n = self.angles.bind(py).len()?;
        let g = self.grid.bind(py).getattr("shape")?.repr()?.to_string();
        Ok(format!("LobeData(theta_o={}, {n} angles per plane, grid {g})", self.theta_o))
    }
}

/// f on MERL's θh × θd grid at one φd (see `gonio.slice_data`).
#[pyclass(module = "gonio._gonio", name = "SliceData", frozen, get_all)]
pub(crate) struct PySliceData {
    /// φd in degrees.
    phi_d: f64,
    /// (n_h,) float64: θh of each column, degrees (square-root spacing: 90·((i + ½)/n_h)²).
    theta_h: PyObject,
    /// (n_d,) float64: θd of each row, degrees (90·(j + ½)/n_d).
    theta_d: PyObject,
    /// (n_d, n_h, 4) float32: f (sr⁻¹), NaN where ωo or ωi is below the horizon; columns r, g, b, lum.
    values: PyObject,
}

#[pymethods]
impl PySliceData {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let g = self.values.bind(py).getattr("shape")?.repr()?.to_string();
        Ok(format!("SliceData(phi_d={}, values {g})", self.phi_d))
    }
}

/// The directional albedo against θo (see `gonio.albedo_data`).
#[pyclass(module = "gonio._gonio", name = "AlbedoData", frozen, get_all)]
pub(crate) struct PyAlbedoData {
    /// (angles,) float64: θo in degrees, 90·(k + ½)/angles.
    theta_o: PyObject,
    /// (angles, 4) float32: ∫ f |cos θi| dωi at each θo; columns r, g, b, lum.
    albedo: PyObject,
}

#[pymethods]
impl PyAlbedoData {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("AlbedoData({} angles)", self.theta_o.bind(py).len()?))
    }
}

#[pyfunction]
#[pyo3(name = "lobe_data", signature = (bsdf, theta_o, *, samples = 721, grid_theta = 31, grid_phi = 72))]
fn py_lobe_data(
    py: Python<'_>,
    bsdf: PyRef<'_, PyBsdf>,
    theta_o: f64,
    samples: i64,
    grid_theta: i64,
    grid_phi: i64,
) -> PyResult<PyLobeData> {
    let (samples, gt, gp) = (count("samples", samples)?, count("grid_theta", grid_theta)?, count("grid_phi", grid_phi)?);
    let model = &bsdf.bsdf;
    let lobe = run_released(py, || lobe_data(model, theta_o, samples, gt, gp))?.map_err(value_error)?;
    let (nt, np) = (lobe.grid.theta.len(), lobe.grid.phi.len());
    Ok(PyLobeData {
        theta_o: lobe.theta_o,
        incidence: channels(py, &lobe.incidence, &[lobe.angles.len()])?,
        perpendicular: channels(py, &lobe.perpendicular, &[lobe.angles.len()])?,
        grid: channels(py, &lobe.grid.values, &[nt, np])?,
        angles: angles(py, lobe.angles),
        grid_theta: angles(py, lobe.grid.theta),
        grid_phi: angles(py, lobe.grid.phi),
    })
}

#[pyfunction]
#[pyo3(name = "slice_data", signature = (bsdf, phi_d = 90.0, *, theta_h = 90, theta_d = 90))]
fn py_slice_data(py: Python<'_>, bsdf: PyRef<'_, PyBsdf>, phi_d: f64, theta_h: i64, theta_d: i64) -> PyResult<PySliceData> {
    let (nh, nd) = (count("theta_h", theta_h)?, count("theta_d", theta_d)?);
    let model = &bsdf.bsdf;
    let s = run_released(py, || slice_data(model, phi_d, nh, nd))?.map_err(value_error)?;
    Ok(PySliceData {
        phi_d: s.phi_d,
        values: channels(py, &s.values, &[s.theta_d.len(), s.theta_h.len()])?,
        theta_h: angles(py, s.theta_h),
        theta_d: angles(py, s.theta_d),
    })
}

#[pyfunction]
#[pyo3(name = "albedo_data", signature = (bsdf, *, angles = 30, samples = 16_384, seed = 0))]
fn py_albedo_data(py: Python<'_>, bsdf: PyRef<'_, PyBsdf>, angles: i64, samples: i64, seed: i64) -> PyResult<PyAlbedoData> {
    let (n, samples) = (count("angles", angles)?, count("samples", samples)?);
    let seed = u64::try_from(seed).map_err(|_| PyValueError::new_err(format!("`seed` must not be negative, got {seed}")))?;
    let model = &bsdf.bsdf;
    let a = run_released(py, || albedo_data(model, n, samples, seed))?.map_err(value_error)?;
    Ok(PyAlbedoData {
        albedo: channels(py, &a.albedo, &[a.theta_o.len()])?,
        theta_o: PyArray1::from_vec(py, a.theta_o).into_any().unbind(),
    })
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLobeData>()?;
    m.add_class::<PySliceData>()?;
    m.add_class::<PyAlbedoData>()?;
    m.add_function(wrap_pyfunction!(py_lobe_data, m)?)?;
    m.add_function(wrap_pyfunction!(py_slice_data, m)?)?;
    m.add_function(wrap_pyfunction!(py_albedo_data, m)?)?;
    Ok(())
}
