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

use batch::{broadcast, finish, for_chunks, output, Arg, Out};
use gonio::bsdf::{Bsdf, BsdfFlags, BsdfModel, RowCheck, SampleColumns, PLUGINS};
use gonio::math::{Vec2, Vec3};
use gonio::props::Props;
use gonio::scene::spectral::{check_bsdf, given_spectra, reflectances_at, Dependence, GivenSpectra};
use gonio::spectrum::wavelengths::{LAMBDA_MAX, LAMBDA_MIN};
use gonio::Rgb;
use numpy::{PyArray1, PyArrayDyn, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rayon::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

mod batch;
mod explore;
mod fit;
mod image;
mod plot;
mod preview;
mod scene;
mod verify;

create_exception!(
    gonio,
    SpecError,
    PyValueError,
    "A plugin description (JSON, XML or dict) that gonio cannot build: unknown type or parameter, a value of the wrong kind or out of range, or text that does not parse. The message starts with where the problem is (a JSON path such as `$.alpha` or `file:line:col`)."
);

/// Largest accepted deviation of |w| from 1 before a direction is rejected (f32 inputs round-tripped
/// through text or float32 arrays are typically within 1e-7; 1e-3 catches forgotten normalisation).
pub(crate) const UNIT_TOLERANCE: f64 = 1e-3;

fn spec_error(e: gonio::Error) -> PyErr {
    SpecError::new_err(e.to_string())
}

/// Run `work` without the GIL, turning a panic (a gonio bug) into `RuntimeError`.
pub(crate) fn run_released<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.allow_threads(|| catch_unwind(AssertUnwindSafe(work))).map_err(panic_error)
}

/// A caught panic (a gonio bug) as `RuntimeError`.
pub(crate) fn panic_error(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    PyRuntimeError::new_err(format!("internal error in gonio (please report): {what}"))
}

/// A direction as gonio takes it: finite and of unit length (within [`UNIT_TOLERANCE`]), or normalised
/// when `normalize` (then it must be non-zero). `None` when it is not acceptable.
#[inline]
fn to_direction(w: [f64; 3], normalize: bool) -> Option<Vec3> {
    if !w.iter().all(|v| v.is_finite()) {
        return None;
    }
    if normalize {
        let len = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        // len ≥ 0 here; it is infinite when the squares overflow f64.
        if len == 0.0 || !len.is_finite() {
            return None;
        }
        Some(Vec3::new((w[0] / len) as f32, (w[1] / len) as f32, (w[2] / len) as f32))
    } else if is_unit(w[0], w[1], w[2]) {
        Some(Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32))
    } else {
        None
    }
}

/// |(x, y, z)| within [`UNIT_TOLERANCE`] of 1, compared on the squared length (no square root); false for
/// NaN or infinite components, whose squared length is NaN or infinite.
#[inline]
pub(crate) fn is_unit(x: f64, y: f64, z: f64) -> bool {
    const LO: f64 = (1.0 - UNIT_TOLERANCE) * (1.0 - UNIT_TOLERANCE);
    const HI: f64 = (1.0 + UNIT_TOLERANCE) * (1.0 + UNIT_TOLERANCE);
    let l2 = x * x + y * y + z * z;
    (LO..=HI).contains(&l2)
}

/// Why `to_direction` rejected `w`, given as row `i` of argument `name`.
fn direction_error(name: &str, batched: bool, i: usize, w: [f64; 3], normalize: bool) -> PyErr {
    let at = if batched { format!("{name}[{i}]") } else { name.to_string() };
    let len = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    PyValueError::new_err(if !w.iter().all(|v| v.is_finite()) {
        format!("{at} = {w:?} is not finite")
    } else if normalize {
        format!("{at} = {w:?} has zero or overflowing length and cannot be normalized")
    } else {
        format!("{at} = {w:?} is not a unit vector (|{name}| = {len}); pass normalize=True to normalize it")
    })
}

/// Directions as `Vec3`s, checked: finite, and unit length unless `normalize` (then non-zero).
pub(crate) fn read_directions<'py>(obj: &Bound<'py, PyAny>, name: &'static str, normalize: bool) -> PyResult<(Arg<'py>, Vec<Vec3>)> {
    let arg = Arg::read(obj, name, 3)?;
    let col = arg.column();
    let mut dirs = Vec::with_capacity(arg.n);
    for i in 0..arg.n {
        let w = col.row3(i);
        dirs.push(to_direction(w, normalize).ok_or_else(|| direction_error(name, arg.batched, i, w, normalize))?);
    }
    Ok((arg, dirs))
}

/// The error for the first unacceptable row of the arguments (directions first, then numbers in
/// [0, 1]), in argument order; called after a batched loop found that some row failed.
fn first_bad_row(directions: &[&Arg<'_>], unit_numbers: &[&Arg<'_>], normalize: bool) -> PyErr {
    for a in directions {
        let col = a.column();
        for i in 0..a.n {
            let w = col.row3(i);
            if to_direction(w, normalize).is_none() {
                return direction_error(a.name, a.batched, i, w, normalize);
            }
        }
    }
    for a in unit_numbers {
        let col = a.column();
        for i in 0..a.n {
            for c in 0..a.width {
                let v = col.get(i, c);
                if !(0.0..=1.0).contains(&v) {
                    return PyValueError::new_err(format!("{}[{i}] = {v} is outside [0, 1]", a.name));
                }
            }
        }
    }
    PyRuntimeError::new_err("internal error in gonio: a row was rejected but every row is valid")
}

/// The skeleton of every batched method: `chunk(rows)` over consecutive ranges of rows covering `0..n`, in
/// parallel and without the GIL; a chunk returns false when one of its rows is unacceptable, and the error
/// then names the first such row of `directions` (unit vectors) or `unit_numbers` (in [0, 1]).
fn over_rows(
    py: Python<'_>,
    n: usize,
    directions: &[&Arg<'_>],
    unit_numbers: &[&Arg<'_>],
    normalize: bool,
    chunk: impl Fn(std::ops::Range<usize>) -> bool + Sync + Send,
) -> PyResult<()> {
    if run_released(py, || for_chunks(n, chunk))? {
        Ok(())
    } else {
        Err(first_bad_row(directions, unit_numbers, normalize))
    }
}

/// `f` and `pdf`: on each chunk of the broadcast pairs, `eval_checked(wo, wi, out, band)` for float32
/// arrays read in place (checking them in its pass, see [`batch::UNIT_BAND`]) or, for other arguments,
/// `eval(wo, wi, out)` on the converted and checked rows; `width` numbers per pair go straight into the
/// result array, shaped (N, width), or the single row for unbatched arguments.
fn over_pairs<'py>(
    py: Python<'py>,
    wo: &Bound<'py, PyAny>,
    wi: &Bound<'py, PyAny>,
    normalize: bool,
    width: usize,
    eval: impl Fn(&[Vec3], &[Vec3], &mut [f32]) + Sync + Send,
    eval_checked: impl Fn(&[Vec3], &[Vec3], &mut [f32], RowCheck) -> bool + Sync + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let (ao, ai) = (Arg::read(wo, "wo", 3)?, Arg::read(wi, "wi", 3)?);
    let (n, batched) = broadcast(&[&ao, &ai])?;
    let (out, ptr) = output::<f32>(py, width * n)?;
    let (co, ci) = (ao.column(), ai.column());
    over_rows(py, n, &[&ao, &ai], &[], normalize, |rows| {
        // SAFETY: rows `rows` of the output are this task's own and within the array.
        let out = unsafe { ptr.slice(width * rows.start, width * rows.len()) };
        let (mut bo, mut bi) = (Vec::new(), Vec::new());
        if let (false, Some(wo), Some(wi)) = (normalize, co.vec3_in_place(rows.clone()), ci.vec3_in_place(rows.clone())) {
            // Checked in the batch's pass; exactly, row by row, only where that leaves doubt.
            return eval_checked(wo, wi, out, batch::UNIT_BAND)
                || (co.directions(rows.clone(), false, &mut bo).is_some() && ci.directions(rows, false, &mut bi).is_some());
        }
        let (Some(wo), Some(wi)) = (co.directions(rows.clone(), normalize, &mut bo), ci.directions(rows.clone(), normalize, &mut bi))
        else {
            return false;
        };
        eval(wo, wi, out);
        true
    })?;
    finish(out, width, batched)
}

/// `out` (3 floats per row) as `Rgb`s.
fn rgb_rows(out: &mut [f32]) -> &mut [Rgb] {
    // SAFETY: `Rgb` is `#[repr(transparent)]` over `[f32; 3]` (alignment 4) and `out` holds 3 floats per row.
    unsafe { std::slice::from_raw_parts_mut(out.as_mut_ptr().cast::<Rgb>(), out.len() / 3) }
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
    /// How it depends on wavelength, as spectral mode reads it, or why spectral mode does not take it
    /// (`scene::spectral::check_bsdf`): what `wavelengths=` of `f`, `pdf` and `sample` needs.
    pub(crate) spectral: Result<Dependence, String>,
    /// The colours it was given as tables, which `wavelengths=` reads as given (`scene::spectral::given_spectra`).
    pub(crate) given: GivenSpectra,
}

impl PyBsdf {
    /// The model built from `props` (a description `spec`), with its spectral reading.
    pub(crate) fn new(props: &Props, spec: String) -> gonio::Result<Self> {
        let bsdf = Bsdf::from_props(props)?;
        Ok(PyBsdf { bsdf, spec, spectral: check_bsdf(props).map_err(|e| e.to_string()), given: given_spectra(props) })
    }

    /// The model at each row's wavelength (nm, column `lambda` of `n` rows), for `wavelengths=`: each
    /// distinct wavelength's copy of the model set as spectral mode sets a path's
    /// (`scene::spectral::reflectances_at`, all three channels at that wavelength), and the rows it serves.
    fn at_wavelengths(&self, lambda: &Arg<'_>, n: usize) -> PyResult<Vec<(Bsdf, Vec<usize>)>> {
        if let Err(e) = &self.spectral {
            return Err(SpecError::new_err(format!("wavelengths: {e}")));
        }
        let col = lambda.column();
        let mut groups: Vec<(f32, Vec<usize>)> = Vec::new();
        let mut index: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
        for i in 0..n {
            let l = col.get(i, 0);
            if !(f64::from(LAMBDA_MIN)..=f64::from(LAMBDA_MAX)).contains(&l) {
                return Err(PyValueError::new_err(format!(
                    "wavelengths[{i}] = {l}: expected a wavelength in [{LAMBDA_MIN}, {LAMBDA_MAX}] nm"
                )));
            }
            #[allow(clippy::cast_possible_truncation)]
            let l = l as f32;
            let g = *index.entry(l.to_bits()).or_insert_with(|| {
                groups.push((l, Vec::new()));
                groups.len() - 1
            });
            groups[g].1.push(i);
        }
        Ok(groups.into_iter().map(|(l, rows)| (self.model_at(l), rows)).collect())
    }

    /// The model with every channel at wavelength `l` nm, as spectral mode sets a path's
    /// (`scene::spectral::reflectances_at`); `self.spectral` checked by the caller.
    fn model_at(&self, l: f32) -> Bsdf {
        let mut model = self.bsdf.clone();
        reflectances_at(&mut model, [l; 3], &self.given);
        model
    }
}

impl PyBsdf {
    /// `sample` with `wavelengths=`: each row's sample of the model at its wavelength.
    fn sample_at_wavelengths<'py>(
        &self,
        py: Python<'py>,
        (wo, uc, u, wavelengths): (&Bound<'py, PyAny>, &Bound<'py, PyAny>, &Bound<'py, PyAny>, &Bound<'py, PyAny>),
        normalize: bool,
    ) -> PyResult<PySample> {
        let (ao, auc, au, al) =
            (Arg::read(wo, "wo", 3)?, Arg::read(uc, "uc", 1)?, Arg::read(u, "u", 2)?, Arg::read(wavelengths, "wavelengths", 1)?);
        let (n, batched) = broadcast(&[&ao, &auc, &au, &al])?;
        let (mut bo, mut buc, mut bu) = (Vec::new(), Vec::new(), Vec::new());
        let (co, cuc, cu) = (ao.column(), auc.column(), au.column());
        let (Some(wo), Some(uc), Some(u)) =
            (co.directions(0..n, normalize, &mut bo), cuc.unit_numbers(0..n, &mut buc), cu.unit_pairs(0..n, &mut bu))
        else {
            return Err(first_bad_row(&[&ao], &[&auc, &au], normalize));
        };
        let groups = self.at_wavelengths(&al, n)?;
        let (mut wi, mut f, mut pdf, mut weight) = (vec![0.0f32; 3 * n], vec![0.0f32; n], vec![0.0f32; n], vec![0.0f32; n]);
        let (mut flags, mut eta, mut valid) = (vec![0u32; n], vec![0.0f32; n], vec![false; n]);
        for (model, rows) in &groups {
            for &r in rows {
                if let Some(s) = model.sample(wo[r], uc[r], u[r]) {
                    wi[3 * r..3 * r + 3].copy_from_slice(&s.wi.to_array());
                    (f[r], pdf[r], weight[r], flags[r], eta[r], valid[r]) = (s.f.r(), s.pdf, s.weight.r(), s.flags.0, s.eta, true);
                }
            }
        }
        Ok(PySample {
            wi: finish(PyArray1::from_vec(py, wi), 3, batched)?.unbind(),
            f: finish(PyArray1::from_vec(py, f), 1, batched)?.unbind(),
            pdf: finish(PyArray1::from_vec(py, pdf), 1, batched)?.unbind(),
            weight: finish(PyArray1::from_vec(py, weight), 1, batched)?.unbind(),
            flags: finish(PyArray1::from_vec(py, flags), 1, batched)?.unbind(),
            eta: finish(PyArray1::from_vec(py, eta), 1, batched)?.unbind(),
            valid: finish(PyArray1::from_vec(py, valid), 1, batched)?.unbind(),
        })
    }
}

/// `f` or `pdf` with `wavelengths=`: `eval(model at the row's wavelength, wo, wi)` per row, one number each.
fn over_pairs_at_wavelengths<'py>(
    py: Python<'py>,
    bsdf: &PyBsdf,
    (wo, wi, wavelengths): (&Bound<'py, PyAny>, &Bound<'py, PyAny>, &Bound<'py, PyAny>),
    normalize: bool,
    eval: impl Fn(&Bsdf, Vec3, Vec3) -> f32,
) -> PyResult<Bound<'py, PyAny>> {
    let (ao, ai, al) = (Arg::read(wo, "wo", 3)?, Arg::read(wi, "wi", 3)?, Arg::read(wavelengths, "wavelengths", 1)?);
    let (n, batched) = broadcast(&[&ao, &ai, &al])?;
    let (mut bo, mut bi, co, ci) = (Vec::new(), Vec::new(), ao.column(), ai.column());
    let (Some(dirs_o), Some(dirs_i)) = (co.directions(0..n, normalize, &mut bo), ci.directions(0..n, normalize, &mut bi)) else {
        return Err(first_bad_row(&[&ao, &ai], &[], normalize));
    };
    let groups = bsdf.at_wavelengths(&al, n)?;
    let mut values = vec![0.0f32; n];
    for (model, rows) in &groups {
        for &r in rows {
            values[r] = eval(model, dirs_o[r], dirs_i[r]);
        }
    }
    finish(PyArray1::from_vec(py, values), 1, batched)
}

#[pymethods]
impl PyBsdf {
    /// f(wo, wi): the BSDF value in sr⁻¹ without the cosine, float32 RGB of shape (N, 3), or (3,) when both
    /// directions have shape (3,). Zero for delta lobes (see `sample`). With `wavelengths` (nm, a number or
    /// shape (N,)), the value at each row's wavelength as spectral mode renders the model: shape (N,).
    #[pyo3(signature = (wo, wi, *, normalize = false, wavelengths = None))]
    fn f<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        normalize: bool,
        wavelengths: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let Some(l) = wavelengths {
            return over_pairs_at_wavelengths(py, self, (wo, wi, l), normalize, |m, wo, wi| m.f(wo, wi).r());
        }
        let bsdf = &self.bsdf;
        over_pairs(
            py,
            wo,
            wi,
            normalize,
            3,
            |wo, wi, out| bsdf.f_batch(wo, wi, rgb_rows(out)),
            |wo, wi, out, band| bsdf.f_batch_checked(wo, wi, rgb_rows(out), band),
        )
    }

    /// The solid-angle density with which `sample` produces `wi` from `wo` (smooth lobes only), float32 of
    /// shape (N,), or a scalar when both directions have shape (3,); with `wavelengths`, the model's at each
    /// row's wavelength (as `f`).
    #[pyo3(signature = (wo, wi, *, normalize = false, wavelengths = None))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        normalize: bool,
        wavelengths: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let Some(l) = wavelengths {
            return over_pairs_at_wavelengths(py, self, (wo, wi, l), normalize, |m, wo, wi| m.pdf(wo, wi));
        }
        let bsdf = &self.bsdf;
        over_pairs(
            py,
            wo,
            wi,
            normalize,
            1,
            |wo, wi, out| bsdf.pdf_batch(wo, wi, out),
            |wo, wi, out, band| bsdf.pdf_batch_checked(wo, wi, out, band),
        )
    }

    /// Sample `wi` given `wo` (shape (3,) or (N, 3)), `uc` (lobe choice; a number or shape (N,)) and `u`
    /// (direction; shape (2,) or (N, 2)), all in [0, 1]. Returns a `BsdfSample` of arrays; rows where the
    /// model does not scatter have `valid == False` and zeros elsewhere. With `wavelengths` (as `f`), each
    /// row samples the model at its wavelength (a dispersive glass refracts each its own way), and `f` and
    /// `weight` are one number per row.
    #[pyo3(signature = (wo, uc, u, *, normalize = false, wavelengths = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        uc: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
        normalize: bool,
        wavelengths: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<PySample> {
        if let Some(l) = wavelengths {
            return self.sample_at_wavelengths(py, (wo, uc, u, l), normalize);
        }
        let (ao, auc, au) = (Arg::read(wo, "wo", 3)?, Arg::read(uc, "uc", 1)?, Arg::read(u, "u", 2)?);
        let (n, batched) = broadcast(&[&ao, &auc, &au])?;
        let (wi_out, wi_ptr) = output::<f32>(py, 3 * n)?;
        let (f_out, f_ptr) = output::<f32>(py, 3 * n)?;
        let (pdf_out, pdf_ptr) = output::<f32>(py, n)?;
        let (weight_out, weight_ptr) = output::<f32>(py, 3 * n)?;
        let (flags_out, flags_ptr) = output::<u32>(py, n)?;
        let (eta_out, eta_ptr) = output::<f32>(py, n)?;
        let (valid_out, valid_ptr) = output::<bool>(py, n)?;
        let (co, cuc, cu, bsdf) = (ao.column(), auc.column(), au.column(), &self.bsdf);
        over_rows(py, n, &[&ao], &[&auc, &au], normalize, |rows| {
            let (start, len) = (rows.start, rows.len());
            // SAFETY: rows `rows` of every output are this task's own and within the arrays; `Vec3` is
            // `#[repr(C)]` of three `f32` and `Rgb` `#[repr(transparent)]` over `[f32; 3]`, so 3·len floats
            // are `len` of either.
            let mut columns = unsafe {
                let rows3 = |p: Out<f32>| p.slice(3 * start, 3 * len).as_mut_ptr();
                SampleColumns {
                    wi: std::slice::from_raw_parts_mut(rows3(wi_ptr).cast::<Vec3>(), len),
                    f: std::slice::from_raw_parts_mut(rows3(f_ptr).cast::<Rgb>(), len),
                    pdf: pdf_ptr.slice(start, len),
                    weight: std::slice::from_raw_parts_mut(rows3(weight_ptr).cast::<Rgb>(), len),
                    flags: flags_ptr.slice(start, len),
                    eta: eta_ptr.slice(start, len),
                    valid: valid_ptr.slice(start, len),
                }
            };
            let (mut wo_buf, mut uc_buf, mut u_buf) = (Vec::new(), Vec::new(), Vec::new());
            let exact = |wo_buf: &mut Vec<Vec3>, uc_buf: &mut Vec<f32>, u_buf: &mut Vec<Vec2>| {
                co.directions(rows.clone(), normalize, wo_buf).is_some()
                    && cuc.unit_numbers(rows.clone(), uc_buf).is_some()
                    && cu.unit_pairs(rows.clone(), u_buf).is_some()
            };
            if let (false, Some(wo), Some(uc), Some(u)) =
                (normalize, co.vec3_in_place(rows.clone()), cuc.f32_in_place(rows.clone()), cu.vec2_in_place(rows.clone()))
            {
                // Checked in the batch's pass; exactly, row by row, only where that leaves doubt.
                return bsdf.sample_batch_checked(wo, uc, u, &mut columns, batch::UNIT_BAND) || exact(&mut wo_buf, &mut uc_buf, &mut u_buf);
            }
            let (Some(wo), Some(uc), Some(u)) = (
                co.directions(rows.clone(), normalize, &mut wo_buf),
                cuc.unit_numbers(rows.clone(), &mut uc_buf),
                cu.unit_pairs(rows.clone(), &mut u_buf),
            ) else {
                return false;
            };
            bsdf.sample_batch(wo, uc, u, &mut columns);
            true
        })?;
        Ok(PySample {
            wi: finish(wi_out, 3, batched)?.unbind(),
            f: finish(f_out, 3, batched)?.unbind(),
            pdf: finish(pdf_out, 1, batched)?.unbind(),
            weight: finish(weight_out, 3, batched)?.unbind(),
            flags: finish(flags_out, 1, batched)?.unbind(),
            eta: finish(eta_out, 1, batched)?.unbind(),
            valid: finish(valid_out, 1, batched)?.unbind(),
        })
    }

    /// Directional albedo ∫ f(wo, wi) |cos θi| dωi, estimated with `samples` of the model's own sampling
    /// (seeded, so reproducible: row i uses seed `seed + i`). Float32 RGB of shape (N, 3), or (3,) for a
    /// single `wo`. Rows are computed in parallel.
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
        let (ao, wo) = read_directions(wo, "wo", normalize)?;
        let bsdf = &self.bsdf;
        let rows = run_released(py, || {
            wo.par_iter()
                .enumerate()
                .map(|(i, &w)| gonio::verify::energy::albedo(bsdf, w, samples, seed.wrapping_add(i as u64)))
                .collect::<Vec<Rgb>>()
        })?;
        let flat: Vec<f32> = rows.iter().flat_map(|c| c.0).collect();
        finish(PyArray1::from_vec(py, flat), 3, ao.batched)
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

    /// This model at one wavelength (nm, in [360, 830]) as spectral mode renders it there — its colours'
    /// spectra, a metal's η and k, a dispersive glass's index at that wavelength, in all three channels —
    /// for `gonio.verify` (its functions take it as any model; `verify.check(..., wavelengths=...)` runs
    /// them per wavelength). Raises `SpecError` for a model spectral mode does not take, naming the
    /// parameter, and for a model already at one wavelength.
    fn at_wavelength(&self, nm: f64) -> PyResult<PyBsdf> {
        if let Err(e) = &self.spectral {
            return Err(SpecError::new_err(format!("at_wavelength: {e}")));
        }
        if !(f64::from(LAMBDA_MIN)..=f64::from(LAMBDA_MAX)).contains(&nm) {
            return Err(PyValueError::new_err(format!("at_wavelength({nm}): expected a wavelength in [{LAMBDA_MIN}, {LAMBDA_MAX}] nm")));
        }
        #[allow(clippy::cast_possible_truncation)]
        let l = nm as f32;
        Ok(PyBsdf {
            bsdf: self.model_at(l),
            spec: format!("{} @ {l} nm", self.spec),
            spectral: Err(format!("the model is already at {l} nm")),
            given: GivenSpectra::NONE,
        })
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
    run_released(py, || Props::from_json(&text_owned).and_then(|p| PyBsdf::new(&p, text_owned.clone())))?.map_err(spec_error)
}

/// Build a model from an XML document whose root (or only `<bsdf>` child) is a `<bsdf>` element; `source`
/// names it in error messages.
#[pyfunction]
#[pyo3(signature = (text, source = "<string>"))]
fn from_xml(py: Python<'_>, text: &str, source: &str) -> PyResult<PyBsdf> {
    let (text_owned, source_owned) = (text.to_owned(), source.to_owned());
    run_released(py, || Props::from_xml_bsdf(&text_owned, &source_owned).and_then(|p| PyBsdf::new(&p, text_owned.clone())))?
        .map_err(spec_error)
}

/// Free the memory kept for reuse by large result arrays (see `batch::pool`); the number of bytes freed.
#[pyfunction]
fn _release_buffers() -> usize {
    batch::pool::release()
}

/// The number of bytes kept for reuse by large result arrays and not in use.
#[pyfunction]
fn _cached_buffer_bytes() -> usize {
    batch::pool::cached()
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
    m.add_function(wrap_pyfunction!(_release_buffers, m)?)?;
    m.add_function(wrap_pyfunction!(_cached_buffer_bytes, m)?)?;
    m.add_class::<batch::pool::Block>()?;
    verify::register(m)?;
    scene::register(m)?;
    image::register(m)?;
    plot::register(m)?;
    preview::register(m)?;
    explore::register(m)?;
    fit::register(m)?;
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
