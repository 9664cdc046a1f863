//! `gonio._gonio` — the compiled half of the `gonio` Python package.
//!
//! Thin, vectorised bindings over [`gonio::Bsdf`]: every method takes arrays of directions of shape (3,) or
//! (N, 3) (float32 or float64, broadcast like numpy), checks them, releases the GIL for the loop over
//! rows and hands back float32 numpy arrays. The pure-Python package (`python/gonio/__init__.py`) adds
//! `load_bsdf`, which accepts dicts, and re-exports everything here.
//!
//! Errors: a bad plugin description raises `gonio.SpecError` (a `ValueError`) carrying gonio's message;
//! bad arrays raise `ValueError` naming the offending row. A panic inside gonio (a bug) is caught and
//! raised as `RuntimeError` rather than unwinding into the interpreter.

use gonio::bsdf::{Bsdf, BsdfFlags, BsdfModel, BsdfSample, PLUGINS};
use gonio::math::{Vec2, Vec3};
use gonio::Rgb;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::panic::{catch_unwind, AssertUnwindSafe};

mod verify;

create_exception!(
    gonio,
    SpecError,
    PyValueError,
    "A plugin description (JSON, XML or dict) that gonio cannot build: unknown type or parameter, a value of the wrong kind or out of range, or text that does not parse. The message starts with where the problem is (a JSON path such as `$.alpha` or `file:line:col`)."
);

/// Largest accepted deviation of |w| from 1 before a direction is rejected (f32 inputs round-tripped
/// through text or float32 arrays are typically within 1e-7; 1e-3 catches forgotten normalisation).
const UNIT_TOLERANCE: f64 = 1e-3;

fn spec_error(e: gonio::Error) -> PyErr {
    SpecError::new_err(e.to_string())
}

/// Run `work` without the GIL, turning a panic (a gonio bug) into `RuntimeError`.
pub(crate) fn run_released<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.allow_threads(|| catch_unwind(AssertUnwindSafe(work))).map_err(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        PyRuntimeError::new_err(format!("internal error in gonio (please report): {what}"))
    })
}

/// An array argument read into f64 rows of `width` numbers: `rows.len() == n * width`, `batched` false
/// for a single row given without the leading axis (shape `(width,)`, or `()` when `width == 1`).
pub(crate) struct Rows {
    values: Vec<f64>,
    pub(crate) n: usize,
    pub(crate) batched: bool,
}

/// Read `obj` (any array-like; float32 and float64 arrays are read without conversion) as rows of
/// `width` numbers. Accepted shapes: `(width,)` and `(N, width)`; for `width == 1` also `()` and `(N,)`.
fn read_rows(obj: &Bound<'_, PyAny>, name: &str, width: usize) -> PyResult<Rows> {
    let (values, shape): (Vec<f64>, Vec<usize>) = if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f32>>() {
        (a.as_array().iter().map(|&v| f64::from(v)).collect(), a.shape().to_vec())
    } else if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        (a.as_array().iter().copied().collect(), a.shape().to_vec())
    } else {
        let np = obj.py().import("numpy")?;
        let converted = np
            .getattr("asarray")?
            .call1((obj, "float64"))
            .map_err(|e| PyValueError::new_err(format!("`{name}` must be an array of numbers: {e}")))?;
        let a = converted.extract::<PyReadonlyArrayDyn<'_, f64>>()?;
        (a.as_array().iter().copied().collect(), a.shape().to_vec())
    };
    let (n, batched) = match (width, shape.as_slice()) {
        (1, []) => (1, false),
        (1, [n]) => (*n, true),
        (w, [k]) if *k == w => (1, false),
        (w, [n, k]) if *k == w => (*n, true),
        _ => {
            let expected = if width == 1 { "a number or shape (N,)".to_string() } else { format!("shape ({width},) or (N, {width})") };
            return Err(PyValueError::new_err(format!("`{name}` must have {expected}, got shape {shape:?}")));
        }
    };
    Ok(Rows { values, n, batched })
}

/// The common row count of several arguments (1-row arguments broadcast), and whether any was batched.
fn broadcast(args: &[(&str, &Rows)]) -> PyResult<(usize, bool)> {
    let batched = args.iter().any(|(_, r)| r.batched);
    let mut n = 1;
    for (_, r) in args {
        if r.n != 1 {
            if n != 1 && n != r.n {
                let shapes: Vec<String> = args.iter().map(|(name, r)| format!("{name}: {} rows", r.n)).collect();
                return Err(PyValueError::new_err(format!("cannot broadcast arguments together ({})", shapes.join(", "))));
            }
            n = r.n;
        }
    }
    // numpy semantics: a (0, 3) argument broadcasts the others to zero rows.
    if args.iter().any(|(_, r)| r.n == 0) {
        n = 0;
    }
    Ok((n, batched))
}

/// Directions as `Vec3`s, checked: finite, and unit length unless `normalize` (then non-zero).
pub(crate) fn read_directions(obj: &Bound<'_, PyAny>, name: &str, normalize: bool) -> PyResult<(Rows, Vec<Vec3>)> {
    let rows = read_rows(obj, name, 3)?;
    let mut dirs = Vec::with_capacity(rows.n);
    for (i, w) in rows.values.chunks_exact(3).enumerate() {
        let at = if rows.batched { format!("{name}[{i}]") } else { name.to_string() };
        if !w.iter().all(|v| v.is_finite()) {
            return Err(PyValueError::new_err(format!("{at} = {w:?} is not finite")));
        }
        let len = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        let w = if normalize {
            // len ≥ 0 here; it is infinite when the squares overflow f64.
            if len == 0.0 || !len.is_finite() {
                return Err(PyValueError::new_err(format!("{at} = {w:?} has zero or overflowing length and cannot be normalized")));
            }
            [w[0] / len, w[1] / len, w[2] / len]
        } else {
            if (len - 1.0).abs() > UNIT_TOLERANCE {
                return Err(PyValueError::new_err(format!(
                    "{at} = {w:?} is not a unit vector (|{name}| = {len}); pass normalize=True to normalize it"
                )));
            }
            [w[0], w[1], w[2]]
        };
        dirs.push(Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32));
    }
    Ok((rows, dirs))
}

/// Row `i` of a broadcast argument.
#[inline]
fn pick<T: Copy>(v: &[T], i: usize) -> T {
    if v.len() == 1 {
        v[0]
    } else {
        v[i]
    }
}

/// An (N, 3) float32 array from RGB rows, or shape (3,) when `!batched`.
fn rgb_array<'py>(py: Python<'py>, rows: &[Rgb], batched: bool) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = rows.iter().flat_map(|c| c.0).collect();
    let a = PyArray1::from_vec(py, flat);
    Ok(if batched { a.reshape([rows.len(), 3])?.into_any() } else { a.into_any() })
}

/// An (N, 3) float32 array from directions, or shape (3,) when `!batched`.
fn vec3_array<'py>(py: Python<'py>, rows: &[Vec3], batched: bool) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = rows.iter().flat_map(|w| w.to_array()).collect();
    let a = PyArray1::from_vec(py, flat);
    Ok(if batched { a.reshape([rows.len(), 3])?.into_any() } else { a.into_any() })
}

/// An (N,) array, or a numpy scalar when `!batched`.
fn column<'py, T: numpy::Element>(py: Python<'py>, values: Vec<T>, batched: bool) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_vec(py, values);
    if batched {
        Ok(a.into_any())
    } else {
        a.into_any().get_item(0)
    }
}

/// A reflection model. Build one with `gonio.load_bsdf`; evaluate it with `f`, `pdf`, `sample`, `albedo`.
///
/// Directions `wo` (towards the viewer) and `wi` (towards the light) point away from the surface and are
/// given in the local shading frame, normal = +z. `f` excludes the cosine (Mitsuba's `eval` is
/// `f · |cos θi|`).
#[pyclass(module = "gonio._gonio", name = "Bsdf", frozen)]
pub(crate) struct PyBsdf {
    pub(crate) bsdf: Bsdf,
    /// The description it was built from, for `__repr__`.
    pub(crate) spec: String,
}

#[pymethods]
impl PyBsdf {
    /// f(wo, wi): the BSDF value in sr⁻¹ without the cosine, float32 RGB of shape (N, 3), or (3,) when both
    /// directions have shape (3,). Zero for delta lobes (see `sample`).
    #[pyo3(signature = (wo, wi, *, normalize = false))]
    fn f<'py>(&self, py: Python<'py>, wo: &Bound<'py, PyAny>, wi: &Bound<'py, PyAny>, normalize: bool) -> PyResult<Bound<'py, PyAny>> {
        let (ro, wo) = read_directions(wo, "wo", normalize)?;
        let (ri, wi) = read_directions(wi, "wi", normalize)?;
        let (n, batched) = broadcast(&[("wo", &ro), ("wi", &ri)])?;
        let bsdf = &self.bsdf;
        let out = run_released(py, || (0..n).map(|i| bsdf.f(pick(&wo, i), pick(&wi, i))).collect::<Vec<Rgb>>())?;
        rgb_array(py, &out, batched)
    }

    /// The solid-angle density with which `sample` produces `wi` from `wo` (smooth lobes only), float32 of
    /// shape (N,), or a scalar when both directions have shape (3,).
    #[pyo3(signature = (wo, wi, *, normalize = false))]
    fn pdf<'py>(&self, py: Python<'py>, wo: &Bound<'py, PyAny>, wi: &Bound<'py, PyAny>, normalize: bool) -> PyResult<Bound<'py, PyAny>> {
        let (ro, wo) = read_directions(wo, "wo", normalize)?;
        let (ri, wi) = read_directions(wi, "wi", normalize)?;
        let (n, batched) = broadcast(&[("wo", &ro), ("wi", &ri)])?;
        let bsdf = &self.bsdf;
        let out = run_released(py, || (0..n).map(|i| bsdf.pdf(pick(&wo, i), pick(&wi, i))).collect::<Vec<f32>>())?;
        column(py, out, batched)
    }

    /// Sample `wi` given `wo` (shape (3,) or (N, 3)), `uc` (lobe choice; a number or shape (N,)) and `u`
    /// (direction; shape (2,) or (N, 2)), all in [0, 1). Returns a `BsdfSample` of arrays; rows where the
    /// model does not scatter have `valid == False` and zeros elsewhere.
    #[pyo3(signature = (wo, uc, u, *, normalize = false))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        uc: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
        normalize: bool,
    ) -> PyResult<PySample> {
        let (ro, wo) = read_directions(wo, "wo", normalize)?;
        let ruc = read_rows(uc, "uc", 1)?;
        let ru = read_rows(u, "u", 2)?;
        let (n, batched) = broadcast(&[("wo", &ro), ("uc", &ruc), ("u", &ru)])?;
        let ucs: Vec<f32> = ruc.values.iter().map(|&v| v as f32).collect();
        let us: Vec<Vec2> = ru.values.chunks_exact(2).map(|v| Vec2::new(v[0] as f32, v[1] as f32)).collect();
        for (name, vals) in [("uc", &ruc.values), ("u", &ru.values)] {
            if let Some(i) = vals.iter().position(|v| !(0.0..=1.0).contains(v)) {
                let row = if name == "u" { i / 2 } else { i };
                return Err(PyValueError::new_err(format!("{name}[{row}] = {} is outside [0, 1]", vals[i])));
            }
        }
        let bsdf = &self.bsdf;
        let samples = run_released(py, || {
            (0..n).map(|i| bsdf.sample(pick(&wo, i), pick(&ucs, i), pick(&us, i))).collect::<Vec<Option<BsdfSample>>>()
        })?;
        let get = |s: &Option<BsdfSample>| {
            s.unwrap_or(BsdfSample { wi: Vec3::ZERO, f: Rgb::ZERO, pdf: 0.0, weight: Rgb::ZERO, flags: BsdfFlags::NONE, eta: 0.0 })
        };
        let all: Vec<BsdfSample> = samples.iter().map(get).collect();
        Ok(PySample {
            wi: vec3_array(py, &all.iter().map(|s| s.wi).collect::<Vec<_>>(), batched)?.unbind(),
            f: rgb_array(py, &all.iter().map(|s| s.f).collect::<Vec<_>>(), batched)?.unbind(),
            pdf: column(py, all.iter().map(|s| s.pdf).collect(), batched)?.unbind(),
            weight: rgb_array(py, &all.iter().map(|s| s.weight).collect::<Vec<_>>(), batched)?.unbind(),
            flags: column(py, all.iter().map(|s| s.flags.0).collect(), batched)?.unbind(),
            eta: column(py, all.iter().map(|s| s.eta).collect(), batched)?.unbind(),
            valid: column(py, samples.iter().map(Option::is_some).collect(), batched)?.unbind(),
        })
    }

    /// Directional albedo ∫ f(wo, wi) |cos θi| dωi, estimated with `samples` of the model's own sampling
    /// (seeded, so reproducible). Float32 RGB of shape (N, 3), or (3,) for a single `wo`.
    #[pyo3(signature = (wo, *, samples = 100_000, seed = 0, normalize = false))]
    fn albedo<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        samples: usize,
        seed: u64,
        normalize: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        if samples == 0 {
            return Err(PyValueError::new_err("`samples` must be at least 1"));
        }
        let (ro, wo) = read_directions(wo, "wo", normalize)?;
        let bsdf = &self.bsdf;
        let out = run_released(py, || {
            wo.iter()
                .enumerate()
                .map(|(i, &w)| gonio::verify::energy::albedo(bsdf, w, samples, seed.wrapping_add(i as u64)))
                .collect::<Vec<Rgb>>()
        })?;
        rgb_array(py, &out, ro.batched)
    }

    /// The model's lobes as a bit set (see `gonio.BsdfFlags`).
    #[getter]
    fn flags(&self) -> u32 {
        self.bsdf.flags().0
    }

    /// The plugin name, as in Mitsuba's `type` (`"diffuse"`, `"conductor"`, …).
    #[getter]
    fn plugin(&self) -> &'static str {
        self.bsdf.plugin_name()
    }

    /// The JSON or XML text the model was built from.
    #[getter]
    fn spec(&self) -> &str {
        &self.spec
    }

    fn __repr__(&self) -> String {
        let mut spec: String = self.spec.split_whitespace().collect::<Vec<_>>().join(" ");
        if spec.chars().count() > 120 {
            spec = spec.chars().take(117).collect::<String>() + "...";
        }
        format!("<gonio.Bsdf {} ({}) {}>", self.bsdf.plugin_name(), self.bsdf.flags().describe(), spec)
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.downcast::<PyBsdf>().map(|o| o.get().bsdf == self.bsdf).unwrap_or(false)
    }

    fn __hash__(&self) -> PyResult<isize> {
        Err(pyo3::exceptions::PyTypeError::new_err("unhashable type: 'gonio.Bsdf'"))
    }
}

/// The result of `Bsdf.sample`: numpy arrays with one row per sample (or squeezed for a single `wo`).
///
/// - `wi` (N, 3) float32: the sampled direction towards the light
/// - `f` (N, 3) float32: f(wo, wi); for a delta lobe the coefficient of the Dirac delta
/// - `pdf` (N,) float32: solid-angle density; for a delta lobe the probability of choosing it
/// - `weight` (N, 3) float32: f · |cos θi| / pdf
/// - `flags` (N,) uint32: the sampled lobe (see `gonio.BsdfFlags`)
/// - `eta` (N,) float32: relative index ηt/ηi along the path (1 for reflection)
/// - `valid` (N,) bool: False where the model does not scatter (all other fields are zero there)
#[pyclass(module = "gonio._gonio", name = "BsdfSample", frozen, get_all)]
struct PySample {
    wi: PyObject,
    f: PyObject,
    pdf: PyObject,
    weight: PyObject,
    flags: PyObject,
    eta: PyObject,
    valid: PyObject,
}

#[pymethods]
impl PySample {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let mut parts = Vec::new();
        for (name, v) in [
            ("wi", &self.wi),
            ("f", &self.f),
            ("pdf", &self.pdf),
            ("weight", &self.weight),
            ("flags", &self.flags),
            ("eta", &self.eta),
            ("valid", &self.valid),
        ] {
            parts.push(format!("{name}={}", v.bind(py).repr()?));
        }
        Ok(format!("BsdfSample({})", parts.join(", ")))
    }

    /// Number of samples (1 for a squeezed single sample).
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        let valid = self.valid.bind(py);
        match valid.downcast::<PyArrayDyn<bool>>() {
            Ok(a) => Ok(a.len()),
            Err(_) => Ok(1),
        }
    }
}

/// Build a model from a JSON object in Mitsuba's dictionary form, e.g. `{"type": "conductor", "material": "Au"}`.
#[pyfunction]
fn from_json(py: Python<'_>, text: &str) -> PyResult<PyBsdf> {
    let text_owned = text.to_owned();
    let bsdf = run_released(py, || Bsdf::from_json(&text_owned))?.map_err(spec_error)?;
    Ok(PyBsdf { bsdf, spec: text.to_owned() })
}

/// Build a model from an XML document whose root (or only `<bsdf>` child) is a `<bsdf>` element; `source`
/// names it in error messages.
#[pyfunction]
#[pyo3(signature = (text, source = "<string>"))]
fn from_xml(py: Python<'_>, text: &str, source: &str) -> PyResult<PyBsdf> {
    let (text_owned, source_owned) = (text.to_owned(), source.to_owned());
    let bsdf = run_released(py, || Bsdf::from_xml(&text_owned, &source_owned))?.map_err(spec_error)?;
    Ok(PyBsdf { bsdf, spec: text.to_owned() })
}

/// The plugin names gonio understands.
#[pyfunction]
fn plugins(py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
    PyTuple::new(py, PLUGINS.iter().copied())
}

/// Example JSON specs per plugin (defaults and extreme parameters), as used by `gonio check --all`.
#[pyfunction]
fn examples(py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
    PyTuple::new(py, Bsdf::examples())
}

#[pymodule]
fn _gonio(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("SpecError", m.py().get_type::<SpecError>())?;
    m.add_class::<PyBsdf>()?;
    m.add_class::<PySample>()?;
    m.add_function(wrap_pyfunction!(from_json, m)?)?;
    m.add_function(wrap_pyfunction!(from_xml, m)?)?;
    m.add_function(wrap_pyfunction!(plugins, m)?)?;
    m.add_function(wrap_pyfunction!(examples, m)?)?;
    verify::register(m)?;
    for (name, bit) in [
        ("FLAG_REFLECTION", BsdfFlags::REFLECTION),
        ("FLAG_TRANSMISSION", BsdfFlags::TRANSMISSION),
        ("FLAG_DIFFUSE", BsdfFlags::DIFFUSE),
        ("FLAG_GLOSSY", BsdfFlags::GLOSSY),
        ("FLAG_DELTA", BsdfFlags::DELTA),
    ] {
        m.add(name, bit.0)?;
    }
    Ok(())
}
