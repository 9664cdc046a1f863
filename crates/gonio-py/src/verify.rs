//! `gonio._gonio.verify` — the verification harness of [`gonio::verify`] for Python: chi-square, reciprocity,
//! energy, the NaN/Inf sweep and the whole `gonio check` report, each returning a result object with the
//! measured figures. Every function releases the GIL while it computes; the results are plain values
//! (numpy arrays for histograms and curves).

use crate::{read_directions, run_released, PyBsdf};
use gonio::math::Vec3;
use gonio::verify::{self, chi2, energy, reciprocity, sweep, CheckConfig};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// A float64 numpy array of shape (rows, cols) from row-major values.
fn matrix<'py>(py: Python<'py>, values: Vec<f64>, rows: usize, cols: usize) -> PyResult<PyObject> {
    Ok(PyArray1::from_vec(py, values).reshape([rows, cols])?.into_any().unbind())
}

fn vec3_f64(py: Python<'_>, w: Vec3) -> PyObject {
    PyArray1::from_vec(py, vec![f64::from(w.x), f64::from(w.y), f64::from(w.z)]).into_any().unbind()
}

fn require(ok: bool, message: impl FnOnce() -> String) -> PyResult<()> {
    if ok {
        Ok(())
    } else {
        Err(PyValueError::new_err(message()))
    }
}

/// A count taken as a Python int: at least 1 (counts are `i64` so that a negative one is a `ValueError`
/// with this message, not an `OverflowError`).
fn at_least_one(name: &str, value: i64) -> PyResult<usize> {
    require(value >= 1, || format!("`{name}` must be at least 1, got {value}"))?;
    usize::try_from(value).map_err(|_| PyValueError::new_err(format!("`{name}` = {value} is too large for this platform")))
}

/// A seed: any non-negative int below 2⁶³.
fn seed_value(seed: i64) -> PyResult<u64> {
    u64::try_from(seed).map_err(|_| PyValueError::new_err(format!("`seed` must be non-negative, got {seed}")))
}

/// One unit direction `wo` of shape (3,).
fn single_direction(obj: &Bound<'_, PyAny>, name: &'static str) -> PyResult<Vec3> {
    let (rows, dirs) = read_directions(obj, name, false)?;
    require(!rows.batched && dirs.len() == 1, || format!("`{name}` must be one direction of shape (3,), got {} rows", rows.n))?;
    Ok(dirs[0])
}

// ---------------------------------------------------------------------------------------------------
// chi2
// ---------------------------------------------------------------------------------------------------

/// The outcome of a chi-square test, with both histograms.
///
/// - `statistic`: Pearson's statistic over the pooled cells; `dof`: pooled cells − 1
/// - `p_value`: P(χ²_dof ≥ statistic); `alpha`: the Šidák-corrected per-test threshold it was compared with
/// - `passed`; `message`: empty, or why the test failed (or a note, such as "no scattering from this wo")
/// - `observed`, `expected`: float64 counts per grid cell, shape (theta_res, phi_res): rows are bins of
///   cos θi over [−1, 1], columns bins of φi over [0, 2π)
/// - `delta_bins`: one `(wi, observed, expected)` per delta lobe direction, sorted by direction
/// - `no_sample_observed`, `no_sample_expected`: samples that were not produced, and N (1 − ∫pdf − Σ delta
///   probabilities)
/// - `pdf_mismatches`: smooth samples whose reported pdf disagreed with `pdf(wo, wi)`
/// - `domain`: the grid in words
#[pyclass(module = "gonio._gonio", name = "Chi2Result", frozen, get_all)]
pub(crate) struct PyChi2Result {
    statistic: f64,
    dof: usize,
    p_value: f64,
    alpha: f64,
    passed: bool,
    message: String,
    observed: PyObject,
    expected: PyObject,
    delta_bins: Vec<(PyObject, f64, f64)>,
    no_sample_observed: f64,
    no_sample_expected: f64,
    pdf_mismatches: usize,
    domain: String,
    /// The one-line summary of the Rust result (`Display`).
    summary: String,
}

#[pymethods]
impl PyChi2Result {
    fn __repr__(&self) -> String {
        format!("<gonio.verify.Chi2Result {}>", self.summary)
    }

    fn __str__(&self) -> String {
        self.summary.clone()
    }

    fn __bool__(&self) -> bool {
        self.passed
    }
}

/// Chi-square test of `bsdf.sample(wo, ·, ·)` against `bsdf.pdf(wo, ·)` over the sphere of `wi`, with
/// delta lobes in bins of their own and `None` samples in a "no sample" bin (Pearson 1900; the test as used
/// for BSDFs by Jakob's Mitsuba and pbrt-v4).
///
/// The sphere is cut into `theta_res` × `phi_res` equal-area cells in (cos θ ∈ [−1, 1], φ ∈ [0, 2π)); `samples`
/// samples are counted per cell (observed); the expected count of a cell is N ∫_cell pdf, integrated by
/// Gauss–Legendre quadrature. Cells expected to hold fewer than 5 samples are pooled. The test fails when the
/// p-value is below α' = 1 − (1 − significance)^(1/tests) (Šidák 1967), or at once when a sample has a
/// non-finite or non-positive pdf, a `wi` that is not unit length, or (for smooth lobes) a reported pdf that
/// differs from `bsdf.pdf(wo, wi)` by more than 10⁻³ relative. A `wo` from which the model never scatters
/// and whose pdf is zero everywhere passes with the note "no scattering from this wo".
///
/// `wo` is one unit direction of shape (3,); `theta_res` must be even (the horizon is a cell edge).
#[pyfunction]
#[pyo3(signature = (bsdf, wo, samples = 1_000_000, theta_res = 40, phi_res = 80, significance = 0.01, tests = 1, seed = 0))]
#[allow(clippy::too_many_arguments)]
#[pyo3(name = "chi2")]
fn py_chi2(
    py: Python<'_>,
    bsdf: &PyBsdf,
    wo: &Bound<'_, PyAny>,
    samples: i64,
    theta_res: i64,
    phi_res: i64,
    significance: f64,
    tests: i64,
    seed: i64,
) -> PyResult<PyChi2Result> {
    let wo = single_direction(wo, "wo")?;
    let samples = at_least_one("samples", samples)?;
    require(theta_res >= 2 && theta_res % 2 == 0, || {
        format!("`theta_res` must be even and at least 2 (the horizon is a cell edge), got {theta_res}")
    })?;
    let theta_res = at_least_one("theta_res", theta_res)?;
    let phi_res = at_least_one("phi_res", phi_res)?;
    require(significance > 0.0 && significance < 1.0, || format!("`significance` must be in (0, 1), got {significance}"))?;
    let tests = at_least_one("tests", tests)?;
    let seed = seed_value(seed)?;
    let cfg = chi2::Chi2Config { samples, theta_res, phi_res, significance, tests, seed, ..chi2::Chi2Config::default() };
    let inner = &bsdf.bsdf;
    let r = run_released(py, || chi2::chi2_bsdf(inner, wo, &cfg))?;
    let (rows, cols) = r.res;
    Ok(PyChi2Result {
        statistic: r.statistic,
        dof: r.dof,
        p_value: r.p_value,
        alpha: r.alpha,
        passed: r.passed,
        summary: r.to_string(),
        message: r.message,
        observed: matrix(py, r.observed, rows, cols)?,
        expected: matrix(py, r.expected, rows, cols)?,
        delta_bins: r.delta_bins.iter().map(|d| (vec3_f64(py, d.wi), d.observed, d.expected)).collect(),
        no_sample_observed: r.no_sample_observed,
        no_sample_expected: r.no_sample_expected,
        pdf_mismatches: r.pdf_mismatches,
        domain: r.domain,
    })
}

// ---------------------------------------------------------------------------------------------------
// reciprocity
// ---------------------------------------------------------------------------------------------------

/// The outcome of a reciprocity test.
///
/// - `max_rel_error`: largest relative error |a − b| / max(a, b) over all pairs and channels
/// - `worst`: the pair `(wo, wi)` (float64 arrays of shape (3,)) where it occurred, or None
/// - `compared`: how many pairs had a non-negligible value
#[pyclass(module = "gonio._gonio", name = "ReciprocityResult", frozen, get_all)]
pub(crate) struct PyReciprocityResult {
    max_rel_error: f64,
    worst: Option<(PyObject, PyObject)>,
    compared: usize,
}

#[pymethods]
impl PyReciprocityResult {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let worst = match &self.worst {
            Some((wo, wi)) => format!("wo={}, wi={}", wo.bind(py).str()?, wi.bind(py).str()?),
            None => "None".into(),
        };
        Ok(format!(
            "<gonio.verify.ReciprocityResult max_rel_error={:.3e} over {} pairs, worst at {worst}>",
            self.max_rel_error, self.compared
        ))
    }
}

/// Helmholtz reciprocity: compare f(wo, wi) with f(wi, wo) at `pairs` random direction pairs over the whole
/// sphere. For transmission through an interface of relative index η the reciprocal quantity is
/// f(ωo, ωi) / η_o² = f(ωi, ωo) / η_i² (Veach 1997, eq. 5.14). Values below 1e-12 sr⁻¹ on both sides are
/// not compared. `gonio check` holds `max_rel_error` to < 1e-5.
#[pyfunction]
#[pyo3(signature = (bsdf, pairs = 100_000, seed = 0))]
#[pyo3(name = "reciprocity")]
fn py_reciprocity(py: Python<'_>, bsdf: &PyBsdf, pairs: i64, seed: i64) -> PyResult<PyReciprocityResult> {
    let pairs = at_least_one("pairs", pairs)?;
    let seed = seed_value(seed)?;
    let inner = &bsdf.bsdf;
    let r = run_released(py, || reciprocity::reciprocity(inner, pairs, seed))?;
    Ok(PyReciprocityResult {
        max_rel_error: r.max_rel_error,
        worst: r.worst.map(|(wo, wi)| (vec3_f64(py, wo), vec3_f64(py, wi))),
        compared: r.compared,
    })
}

// ---------------------------------------------------------------------------------------------------
// energy
// ---------------------------------------------------------------------------------------------------

/// Directional albedo over θo on one side of the surface, and the white furnace.
///
/// - `side`: `"above"` or `"below"`
/// - `cos_theta_o`: float64 (N,), signed (negative below): N midpoints of (0, 1], azimuth φo = 0.3
/// - `albedo`: float64 (N, 3), a(ωo) = ∫ f(ωo, ωi) |cos θi| dωi per channel
/// - `white_furnace`: float64 (3,), (1/π) ∫ a(ωo) |cos θo| dωo = 2 ∫₀¹ a(μ) μ dμ (midpoint rule)
/// - `max_albedo`, `max_albedo_cos_theta_o`: the largest channel of the albedo, and where it occurred
#[pyclass(module = "gonio._gonio", name = "EnergyResult", frozen, get_all)]
pub(crate) struct PyEnergyResult {
    side: &'static str,
    cos_theta_o: PyObject,
    albedo: PyObject,
    white_furnace: PyObject,
    max_albedo: f64,
    max_albedo_cos_theta_o: f64,
}

#[pymethods]
impl PyEnergyResult {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "<gonio.verify.EnergyResult {}: max albedo {:.6} at cosθo={:+.3}, white furnace {}>",
            self.side,
            self.max_albedo,
            self.max_albedo_cos_theta_o,
            self.white_furnace.bind(py).str()?
        ))
    }
}

/// Energy conservation: the directional albedo a(ωo) = ∫ f(ωo, ωi) |cos θi| dωi at `angles` values of
/// cos θo spread over (0, 1] (midpoints, so the horizon itself is never hit) on `side` (`"above"` or
/// `"below"`), each from `samples` samples (rounded up to a square) of the model's own sampling, stratified;
/// and the white furnace (1/π) ∫ a(ωo) |cos θo| dωo. For transmission the radiance factor (ηᵢ/ηₜ)² is
/// undone: energy, not radiance, is what must be conserved (Veach 1997, §5.2). `gonio check` holds both
/// to ≤ 1 + 1e-3 on every side the model scatters from (see `scatters_from_below`).
#[pyfunction]
#[pyo3(signature = (bsdf, angles = 32, samples = 65_536, seed = 0, side = "above"))]
#[pyo3(name = "energy")]
fn py_energy(py: Python<'_>, bsdf: &PyBsdf, angles: i64, samples: i64, seed: i64, side: &str) -> PyResult<PyEnergyResult> {
    let angles = at_least_one("angles", angles)?;
    let samples = at_least_one("samples", samples)?;
    let seed = seed_value(seed)?;
    let (sign, side) = match side {
        "above" => (1.0f32, "above"),
        "below" => (-1.0f32, "below"),
        other => return Err(PyValueError::new_err(format!("`side` must be \"above\" or \"below\", got {other:?}"))),
    };
    let inner = &bsdf.bsdf;
    let (curve, furnace) = run_released(py, || {
        let curve = energy::albedo_curve(inner, angles, sign, samples, seed);
        let furnace = energy::white_furnace(&curve);
        (curve, furnace)
    })?;
    // The same reduction as `gonio check`: the largest channel, first occurrence on ties.
    let (mu, worst) =
        curve.iter().map(|(mu, a)| (*mu, a.max_component())).fold((0.0, f32::MIN), |acc, x| if x.1 > acc.1 { x } else { acc });
    Ok(PyEnergyResult {
        side,
        cos_theta_o: PyArray1::from_vec(py, curve.iter().map(|(mu, _)| f64::from(*mu)).collect()).into_any().unbind(),
        albedo: matrix(py, curve.iter().flat_map(|(_, a)| a.0.map(f64::from)).collect(), curve.len(), 3)?,
        white_furnace: PyArray1::from_vec(py, furnace.0.map(f64::from).to_vec()).into_any().unbind(),
        max_albedo: f64::from(worst),
        max_albedo_cos_theta_o: f64::from(mu),
    })
}

/// Whether the model does anything for light arriving from below (transmissive or two-sided models): the
/// sides `gonio check` measures the energy of.
#[pyfunction]
#[pyo3(name = "scatters_from_below")]
fn py_scatters_from_below(bsdf: &PyBsdf) -> bool {
    verify::scatters_from_below(&bsdf.bsdf)
}

// ---------------------------------------------------------------------------------------------------
// sweep
// ---------------------------------------------------------------------------------------------------

/// The outcome of a NaN/Inf sweep.
///
/// - `queries`: number of (wo, wi, uc, u) queries run, each exercising `f`, `pdf` and `sample`
/// - `bad`: queries with any non-finite or negative output
/// - `first_bad`: the first bad query, described, or None
#[pyclass(module = "gonio._gonio", name = "SweepResult", frozen, get_all)]
pub(crate) struct PySweepResult {
    queries: usize,
    bad: usize,
    first_bad: Option<String>,
}

#[pymethods]
impl PySweepResult {
    fn __repr__(&self) -> String {
        match &self.first_bad {
            Some(first) => format!("<gonio.verify.SweepResult {} of {} queries bad; first: {first}>", self.bad, self.queries),
            None => format!("<gonio.verify.SweepResult {} of {} queries bad>", self.bad, self.queries),
        }
    }
}

/// NaN/Inf sweep: query `f`, `pdf` and `sample` with random and degenerate inputs — directions on the
/// horizon, exactly on the poles, wi = −wo, wi = wo, denormal components, lengths off by 1e-6, sample
/// coordinates at 0 and just below 1 — and demand finite, non-negative answers everywhere. Runs at least
/// `queries` queries (rounded up to whole chunks of 16 384, each with its own random stream; a quarter of
/// them built from degenerate directions and sample values).
#[pyfunction]
#[pyo3(signature = (bsdf, queries = 1_000_000, seed = 0))]
#[pyo3(name = "sweep")]
fn py_sweep(py: Python<'_>, bsdf: &PyBsdf, queries: i64, seed: i64) -> PyResult<PySweepResult> {
    let queries = at_least_one("queries", queries)?;
    let seed = seed_value(seed)?;
    let inner = &bsdf.bsdf;
    let r = run_released(py, || sweep::sweep(inner, queries, seed))?;
    Ok(PySweepResult { queries: r.queries, bad: r.bad, first_bad: r.first_bad })
}

// ---------------------------------------------------------------------------------------------------
// check
// ---------------------------------------------------------------------------------------------------

/// One line of a report: what was checked (`check`, e.g. `chi2 cosθo=+0.30`), the measured figure
/// (`measured`), the limit it is held to, as text (`limit`, e.g. `< 1e-5`), `passed`, and context
/// (`detail`: the worst case, a reason).
#[pyclass(module = "gonio._gonio", name = "CheckRow", frozen, get_all)]
#[derive(Clone)]
pub(crate) struct PyCheckRow {
    check: String,
    measured: f64,
    limit: String,
    passed: bool,
    detail: String,
}

#[pymethods]
impl PyCheckRow {
    fn __repr__(&self) -> String {
        format!(
            "CheckRow(check={:?}, measured={}, limit={:?}, passed={}, detail={:?})",
            self.check,
            self.measured,
            self.limit,
            if self.passed { "True" } else { "False" },
            self.detail
        )
    }

    /// The row as a dict with the keys of `gonio check --json`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("check", &self.check)?;
        d.set_item("measured", self.measured)?;
        d.set_item("limit", &self.limit)?;
        d.set_item("passed", self.passed)?;
        d.set_item("detail", &self.detail)?;
        Ok(d)
    }
}

/// The result of `check`: `name`, `rows` (a list of `CheckRow`) and `passed` (every row passed).
/// `str(report)` is the table `gonio check` prints; `to_dict()` the object `gonio check --json` prints.
#[pyclass(module = "gonio._gonio", name = "Report", frozen)]
pub(crate) struct PyReport {
    report: verify::Report,
}

#[pymethods]
impl PyReport {
    #[getter]
    fn name(&self) -> &str {
        &self.report.name
    }

    #[getter]
    fn passed(&self) -> bool {
        self.report.passed()
    }

    #[getter]
    fn rows(&self) -> Vec<PyCheckRow> {
        self.report
            .rows
            .iter()
            .map(|r| PyCheckRow {
                check: r.check.clone(),
                measured: r.measured,
                limit: r.limit.clone(),
                passed: r.passed,
                detail: r.detail.clone(),
            })
            .collect()
    }

    /// `{"name", "passed", "checks": [{"check", "measured", "limit", "passed", "detail"}, …]}`, as
    /// `gonio check --json` prints it (except that a non-finite `measured` stays a float here).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("name", &self.report.name)?;
        d.set_item("passed", self.report.passed())?;
        let checks = PyList::empty(py);
        for row in self.rows() {
            checks.append(row.to_dict(py)?)?;
        }
        d.set_item("checks", checks)?;
        Ok(d)
    }

    fn __str__(&self) -> String {
        self.report.to_table()
    }

    fn __repr__(&self) -> String {
        let failed: Vec<&str> = self.report.rows.iter().filter(|r| !r.passed).map(|r| r.check.as_str()).collect();
        let verdict = if failed.is_empty() { "passed".to_string() } else { format!("FAILED: {}", failed.join(", ")) };
        format!("<gonio.verify.Report {} ({} checks) {verdict}>", self.report.name, self.report.rows.len())
    }

    fn __bool__(&self) -> bool {
        self.report.passed()
    }
}

/// Run every check of `gonio check` on `bsdf`: chi-square at the test directions (cos θo ∈ {0.98, 0.7, 0.3,
/// 0.05}, and the same below the surface when the model scatters there; one Šidák family), consistency of
/// `sample` with `f` and `pdf` (< 1e-4), reciprocity (< 1e-5), albedo and white furnace on each side
/// (≤ 1 + 1e-3), and the NaN/Inf sweep (0 bad queries). `samples` is per chi-square test, `sweep` the number
/// of sweep queries; the other sizes are those of `gonio check`, so the same `seed` gives the same figures
/// as `gonio check --json --seed SEED`. The report is named after the model's spec. `family` is the
/// number of chi-square tests the significance is shared among (Šidák): by default this model's
/// (`chi2_tests(bsdf)`); `gonio check --all` uses the sum over every model it checks.
#[pyfunction]
#[pyo3(signature = (bsdf, samples = 1_000_000, sweep = 1_000_000, seed = 0, family = None))]
#[pyo3(name = "check")]
fn py_check(py: Python<'_>, bsdf: &PyBsdf, samples: i64, sweep: i64, seed: i64, family: Option<i64>) -> PyResult<PyReport> {
    let samples = at_least_one("samples", samples)?;
    let sweep = at_least_one("sweep", sweep)?;
    let seed = seed_value(seed)?;
    let family = family.map(|f| at_least_one("family", f)).transpose()?;
    let cfg = CheckConfig { chi2_samples: samples, sweep_queries: sweep, seed, sidak_family: family, ..CheckConfig::default() };
    let (inner, name) = (&bsdf.bsdf, bsdf.spec.as_str());
    let report = run_released(py, || verify::check_named(inner, name, &cfg))?;
    Ok(PyReport { report })
}

/// How many chi-square tests `check` runs on `bsdf` (its test directions, on each side it scatters from).
#[pyfunction]
#[pyo3(name = "chi2_tests")]
fn py_chi2_tests(bsdf: &PyBsdf) -> usize {
    verify::test_directions(&bsdf.bsdf).len()
}

/// Whether `report` shows the violation `row` that a non-physical model is kept to teach (a row whose
/// check starts with `row` fails, and every other row passes): `None` when it does, else what went wrong.
#[pyfunction]
#[pyo3(name = "expect_violation")]
fn py_expect_violation(report: &PyReport, row: &str) -> Option<String> {
    verify::expect_violation(&report.report, row).err()
}

/// The non-physical example specs `gonio check --all` also runs, each with the check row it must fail.
#[pyfunction]
#[pyo3(name = "violations")]
fn py_violations() -> Vec<(&'static str, &'static str)> {
    gonio::Bsdf::violations()
}

/// Add the `verify` submodule to `_gonio`.
pub(crate) fn register(parent: &Bound<'_, PyModule>) -> PyResult<()> {
    let m = PyModule::new(parent.py(), "verify")?;
    m.add_class::<PyChi2Result>()?;
    m.add_class::<PyReciprocityResult>()?;
    m.add_class::<PyEnergyResult>()?;
    m.add_class::<PySweepResult>()?;
    m.add_class::<PyCheckRow>()?;
    m.add_class::<PyReport>()?;
    m.add_function(wrap_pyfunction!(py_chi2, &m)?)?;
    m.add_function(wrap_pyfunction!(py_reciprocity, &m)?)?;
    m.add_function(wrap_pyfunction!(py_energy, &m)?)?;
    m.add_function(wrap_pyfunction!(py_scatters_from_below, &m)?)?;
    m.add_function(wrap_pyfunction!(py_sweep, &m)?)?;
    m.add_function(wrap_pyfunction!(py_check, &m)?)?;
    m.add_function(wrap_pyfunction!(py_chi2_tests, &m)?)?;
    m.add_function(wrap_pyfunction!(py_expect_violation, &m)?)?;
    m.add_function(wrap_pyfunction!(py_violations, &m)?)?;
    parent.add_submodule(&m)
}
