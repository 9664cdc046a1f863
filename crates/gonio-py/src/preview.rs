//! Lit-sphere previews from Python ([`gonio::preview`]): the sweep of a material over a grid of its
//! parameters ([`Sweep`], the code behind `gonio preview --grid`), one point rendered at a time, and the
//! contact sheet. `gonio.preview` and `gonio.distributed.preview` (python/gonio/_preview.py) call these; a
//! point renders the same image in either, bit for bit.

use crate::run_released;
use crate::scene::os_error;
use crate::SpecError;
use gonio::image::Image;
use gonio::math::Vec3;
use gonio::preview::{contact_sheet, GridAxis, Lighting, Sweep};
use gonio::props::Props;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

fn spec_error(e: gonio::Error) -> PyErr {
    os_error(&e, SpecError::new_err)
}

/// The sweep of `spec` (JSON, or XML starting with `<`; `source` names it) over `grid` (JSON: a list of
/// `[name, [value, …]]` pairs).
fn sweep(spec: &str, grid: &str, source: &str) -> gonio::Result<Sweep> {
    let props = if spec.trim_start().starts_with('<') { Props::from_xml_bsdf(spec, source)? } else { Props::from_json(spec)? };
    Sweep::new(props, GridAxis::from_json(grid)?)
}

/// Check a sweep, building every point's material: `(labels, indices, columns)`, per point its label and
/// the index into each parameter's values, and the columns of its contact sheet. Raises `SpecError` naming
/// the parameter (and the value) that is wrong.
#[pyfunction]
#[pyo3(signature = (spec, grid, source = "<string>"))]
fn _preview_sweep(py: Python<'_>, spec: &str, grid: &str, source: &str) -> PyResult<(Vec<String>, Vec<Vec<usize>>, usize)> {
    let sweep = run_released(py, || {
        let sweep = sweep(spec, grid, source)?;
        sweep.check()?;
        Ok(sweep)
    })?
    .map_err(spec_error)?;
    let points = 0..sweep.len();
    Ok((points.clone().map(|i| sweep.label(i)).collect(), points.map(|i| sweep.indices(i)).collect(), sweep.columns()))
}

/// `gonio preview --grid NAME=V1,V2,…` as JSON, the `[name, [value, …]]` pair `grid` takes.
#[pyfunction]
fn _parse_grid_option(text: &str) -> PyResult<String> {
    GridAxis::parse(text).map(|a| a.to_json()).map_err(spec_error)
}

/// How the spheres are lit: `env` — `"gradient"` (the built-in sky), `"constant"` (the white furnace), an
/// image file's path (read once, here) or an (H, W, 3) float32 lat-long image — or `light`, a direction
/// (x, y, z) towards a directional light (+x right, +y up, +z towards the viewer) with a dim ambient.
#[pyclass(module = "gonio._gonio", name = "PreviewLighting", frozen)]
struct PyPreviewLighting(Lighting);

#[pymethods]
impl PyPreviewLighting {
    #[new]
    #[pyo3(signature = (env = None, light = None))]
    fn new(py: Python<'_>, env: Option<&Bound<'_, PyAny>>, light: Option<[f32; 3]>) -> PyResult<Self> {
        let lighting = match (env, light) {
            (Some(_), Some(_)) => return Err(PyValueError::new_err("give `env` or `light`, not both")),
            (None, Some(d)) => {
                let d = Vec3::from(d);
                if !d.is_finite() || d.length_squared() == 0.0 {
                    return Err(PyValueError::new_err(format!("`light` must be a finite non-zero direction (x, y, z), got {d:?}")));
                }
                Lighting::sun(d)
            }
            (None, None) => Lighting::GradientSky,
            (Some(env), None) => {
                if let Ok(name) = env.extract::<PathBuf>() {
                    match Lighting::environment(&name.to_string_lossy()) {
                        Lighting::Environment(path) => {
                            let image =
                                run_released(py, || gonio::image::read_image(&path))?.map_err(|e| os_error(&e, PyValueError::new_err))?;
                            Lighting::EnvironmentImage { image: Arc::new(image), name: path.display().to_string() }
                        }
                        other => other,
                    }
                } else if let Ok(a) = env.extract::<PyReadonlyArrayDyn<'_, f32>>() {
                    let [height, width, 3] = a.shape() else {
                        return Err(PyValueError::new_err(format!(
                            "`env` as an array must have shape (height, width, 3), got {:?}",
                            a.shape()
                        )));
                    };
                    let image = Image { width: *width, height: *height, data: a.as_array().iter().copied().collect() };
                    Lighting::EnvironmentImage { image: Arc::new(image), name: "the `env` array".into() }
                } else {
                    return Err(PyValueError::new_err(format!(
                        "`env` must be \"gradient\", \"constant\", an image file's path or a float32 array of shape (height, width, 3), got {}",
                        env.get_type().name()?
                    )));
                }
            }
        };
        Ok(PyPreviewLighting(lighting))
    }

    /// Pickled as the arguments that build it again (an environment file as its image, read already), so
    /// that `gonio.distributed` sends it to the workers.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let py = slf.py();
        let none = || py.None().into_bound(py);
        let (env, light) = match &slf.get().0 {
            Lighting::GradientSky => ("gradient".into_pyobject(py)?.into_any(), none()),
            Lighting::Constant(_) => ("constant".into_pyobject(py)?.into_any(), none()),
            Lighting::EnvironmentImage { image, .. } => {
                (PyArray1::from_slice(py, &image.data).reshape([image.height, image.width, 3])?.into_any(), none())
            }
            Lighting::Environment(path) => (path.clone().into_pyobject(py)?.into_any(), none()),
            Lighting::Directional { towards_light, .. } => (none(), towards_light.to_array().into_pyobject(py)?.into_any()),
        };
        Ok((slf.get_type().into_any(), (env, light).into_pyobject(py)?.into_any()))
    }
}

/// Render point `point` of the sweep of `spec` over `grid` (as `_preview_sweep` takes them): a `size` ×
/// `size` float32 (H, W, 3) linear RGB image at `spp` samples per pixel, and the number of non-finite
/// samples dropped. `threads`: the render's threads (default: all cores).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (spec, grid, point, lighting, size, spp, seed, threads = None, source = "<string>", mode = "rgb"))]
fn _render_preview<'py>(
    py: Python<'py>,
    spec: &str,
    grid: &str,
    point: usize,
    lighting: &PyPreviewLighting,
    size: u32,
    spp: u32,
    seed: u64,
    threads: Option<usize>,
    source: &str,
    mode: &str,
) -> PyResult<(Bound<'py, PyAny>, u64)> {
    let mode = gonio::scene::Mode::parse(mode).map_err(spec_error)?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        if n == 0 {
            return Err(PyValueError::new_err("`threads` must be at least 1"));
        }
        pool = pool.num_threads(n);
    }
    let pool = pool.build().map_err(|e| PyOSError::new_err(format!("cannot start render threads: {e}")))?;
    let lighting = &lighting.0;
    // A sweep holds descriptions that are not `Sync`: it is built inside the pool.
    let out = run_released(py, || {
        pool.install(|| sweep(spec, grid, source)?.render(point, lighting, size, spp, seed, mode, &AtomicBool::new(false)))
    })?
    .map_err(spec_error)?;
    let (h, w) = (out.image.height, out.image.width);
    Ok((PyArray1::from_vec(py, out.image.data).reshape([h, w, 3])?.into_any(), out.nonfinite))
}

/// The contact sheet of `images` ((H, W, 3) float32 each, all the same size): rows of `columns`, scaled by
/// 2^`exposure`, with thin dark gaps — the image `gonio preview` writes.
#[pyfunction]
#[pyo3(signature = (images, columns, exposure = 0.0))]
fn _contact_sheet<'py>(
    py: Python<'py>,
    images: Vec<PyReadonlyArrayDyn<'py, f32>>,
    columns: usize,
    exposure: f32,
) -> PyResult<Bound<'py, PyAny>> {
    let tiles = images
        .iter()
        .enumerate()
        .map(|(i, a)| match a.shape() {
            [height, width, 3] => Ok(Image { width: *width, height: *height, data: a.as_array().iter().copied().collect() }),
            shape => Err(PyValueError::new_err(format!("images[{i}] must have shape (height, width, 3), got {shape:?}"))),
        })
        .collect::<PyResult<Vec<_>>>()?;
    let sheet = contact_sheet(&tiles, columns, exposure).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(PyArray1::from_vec(py, sheet.data).reshape([sheet.height, sheet.width, 3])?.into_any())
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPreviewLighting>()?;
    m.add_function(wrap_pyfunction!(_preview_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(_parse_grid_option, m)?)?;
    m.add_function(wrap_pyfunction!(_render_preview, m)?)?;
    m.add_function(wrap_pyfunction!(_contact_sheet, m)?)?;
    Ok(())
}
