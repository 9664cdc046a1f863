//! Scenes from Python: `load_scene` (a Mitsuba 3 XML file), `load_dict` (Mitsuba's scene dictionary),
//! `Scene.render` and `look_at`.
//!
//! Rendering runs [`gonio::render::render`] on a worker thread with its own rayon pool while the calling
//! thread waits without the GIL, waking every few milliseconds to update the progress bar and to run
//! Python's signal handlers (`Python::check_signals`): Ctrl-C sets the renderer's cancel flag, the worker
//! stops after its current tile, and `KeyboardInterrupt` is raised with the interpreter in a normal state.

use crate::{panic_error, run_released};
use gonio::math::{Transform, Vec3};
use gonio::scene::{mitsuba_dict, IntegratorKind, Mode, Scene};
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyIsADirectoryError, PyOSError, PyPermissionError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

create_exception!(
    gonio,
    SceneError,
    PyValueError,
    "A scene gonio cannot load: XML or dictionary that does not parse, an unknown or unsupported plugin or parameter, a value out of range, a malformed mesh or image it refers to. The message starts with where the problem is (`file:line:col` or a dictionary path such as `$.ball.bsdf.alpha`)."
);

/// How often the waiting thread wakes to check for Ctrl-C and redraw the progress bar.
const POLL: Duration = Duration::from_millis(20);

/// An I/O error as the matching `OSError` subclass (with errno and file name), anything else as `other`.
pub(crate) fn os_error(e: &gonio::Error, other: impl FnOnce(String) -> PyErr) -> PyErr {
    let gonio::Error::Io { path, source } = e else { return other(e.to_string()) };
    let args = (source.raw_os_error().unwrap_or(0), source.to_string(), path.display().to_string());
    match source.kind() {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(args),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(args),
        _ if path.is_dir() => PyIsADirectoryError::new_err(args),
        _ => PyOSError::new_err(args),
    }
}

fn scene_error(e: gonio::Error) -> PyErr {
    os_error(&e, SceneError::new_err)
}

/// A Python value as JSON for [`mitsuba_dict`]: dicts, lists, tuples, numbers, strings, booleans; numpy
/// arrays and other array-likes (Mitsuba's `ScalarPoint3f`, …) through `numpy.asarray`; transforms
/// (anything with a `matrix` attribute, such as `mitsuba.ScalarTransform4f`) as their 4×4 matrix.
fn to_json(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<serde_json::Value> {
    use serde_json::Value as J;
    if obj.is_instance_of::<PyBool>() {
        return Ok(J::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return Ok(match obj.extract::<i64>() {
            Ok(i) => J::from(i),
            Err(_) => J::from(obj.extract::<f64>()?),
        });
    }
    if obj.is_instance_of::<PyFloat>() {
        let v: f64 = obj.extract()?;
        return serde_json::Number::from_f64(v)
            .map(J::Number)
            .ok_or_else(|| SceneError::new_err(format!("{at}: {v} is not a finite number")));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(J::String(obj.extract()?));
    }
    if let Ok(d) = obj.downcast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| SceneError::new_err(format!("{at}: dictionary keys must be strings, got {k:?}")))?;
            let value = to_json(&v, &format!("{at}.{key}"))?;
            map.insert(key, value);
        }
        return Ok(J::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, v) in obj.try_iter()?.enumerate() {
            items.push(to_json(&v?, &format!("{at}[{i}]"))?);
        }
        return Ok(J::Array(items));
    }
    if obj.is_none() {
        return Err(SceneError::new_err(format!("{at}: None is not a parameter value")));
    }
    let asarray = obj.py().import("numpy")?.getattr("asarray")?;
    let array = match asarray.call1((obj, "float64")) {
        Ok(a) => Ok(a),
        // A transform object is not an array itself; its matrix is.
        Err(_) if obj.hasattr("matrix")? => asarray.call1((obj.getattr("matrix")?, "float64")),
        Err(e) => Err(e),
    }
    .map_err(|_| {
        SceneError::new_err(format!(
            "{at}: a value of type `{}` is not a number, string, list, dict, array or transform",
            obj.get_type().name().map(|n| n.to_string()).unwrap_or_default()
        ))
    })?;
    to_json(&array.call_method0("tolist")?, at)
}

/// A renderable scene: shapes with their materials, lights, camera, film, sampler and integrator. Build
/// one with `gonio.load_scene` or `gonio.load_dict`; `render` it to an (H, W, 3) float32 array.
#[pyclass(module = "gonio._gonio", name = "Scene", frozen)]
pub(crate) struct PyScene {
    scene: Arc<Scene>,
    source: String,
}

impl PyScene {
    fn seed_or_default(&self, seed: Option<i64>) -> PyResult<u64> {
        match seed {
            None => Ok(self.scene.sampler.seed),
            Some(s) => u64::try_from(s).map_err(|_| PyValueError::new_err(format!("`seed` must be non-negative, got {s}"))),
        }
    }

    /// Run `job` (a render of `spp` samples per pixel) on a worker thread with its own pool of `threads`,
    /// while this thread waits without the GIL, redrawing the progress bar and running Python's signal
    /// handlers (module docs). Any error here (Ctrl-C, or raised by the bar) cancels the job and joins the
    /// worker before it is returned.
    fn run<T: Send + 'static>(
        &self,
        py: Python<'_>,
        spp: u32,
        threads: Option<i64>,
        progress: bool,
        job: impl FnOnce(&Scene, &AtomicBool, &(dyn Fn(u64) + Sync)) -> T + Send + 'static,
    ) -> PyResult<T> {
        let mut pool = rayon::ThreadPoolBuilder::new();
        if let Some(n) = threads {
            let n = usize::try_from(n)
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| PyValueError::new_err(format!("`threads` must be at least 1, got {n}")))?;
            pool = pool.num_threads(n);
        }
        let pool = pool.build().map_err(|e| PyOSError::new_err(format!("cannot start render threads: {e}")))?;
        let (w, h) = (self.scene.film.width, self.scene.film.height);
        let total = u64::from(w) * u64::from(h) * u64::from(spp);
        let bar = if progress {
            let b = py.import("gonio._progress")?.getattr("bar")?.call1((total, "gonio render"))?;
            (!b.is_none()).then_some(b)
        } else {
            None
        };

        let cancel = Arc::new(AtomicBool::new(false));
        let done = Arc::new(AtomicU64::new(0));
        let (tx, rx) = mpsc::channel();
        let worker = {
            let (scene, cancel, done) = (self.scene.clone(), cancel.clone(), done.clone());
            std::thread::Builder::new()
                .name("gonio-render".into())
                .spawn(move || {
                    let out =
                        catch_unwind(AssertUnwindSafe(|| pool.install(|| job(&scene, &cancel, &|d| done.store(d, Ordering::Relaxed)))));
                    // The receiver is gone only if the caller stopped waiting; nothing to report then.
                    let _ = tx.send(out);
                })
                .map_err(|e| PyOSError::new_err(format!("cannot start the render thread: {e}")))?
        };
        let mut rx = rx;
        let waited: PyResult<_> = (|| loop {
            // The receiver is `Send` but not `Sync`: move it into the GIL-free closure and back.
            let (got, back) = py.allow_threads(move || (rx.recv_timeout(POLL), rx));
            rx = back;
            match got {
                Ok(out) => return Ok(out),
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(
                        "internal error in gonio: the render thread ended without a result",
                    ))
                }
            }
            py.check_signals()?;
            if let Some(b) = &bar {
                b.call_method1("update", (done.load(Ordering::Relaxed),))?;
            }
        })();
        if waited.is_err() {
            cancel.store(true, Ordering::SeqCst);
        }
        let _ = py.allow_threads(|| worker.join());
        let closed = match &bar {
            Some(b) => b.call_method1("close", (done.load(Ordering::Relaxed),)).map(drop),
            None => Ok(()),
        };
        let out = waited?;
        closed?;
        out.map_err(panic_error)
    }

    fn new(py: Python<'_>, scene: Scene, source: String) -> PyResult<PyScene> {
        if !scene.warnings.is_empty() {
            let warn = py.import("warnings")?.getattr("warn")?;
            for w in &scene.warnings {
                warn.call1((w.as_str(), py.get_type::<pyo3::exceptions::PyUserWarning>(), 3))?;
            }
        }
        Ok(PyScene { scene: Arc::new(scene), source })
    }
}

#[pymethods]
impl PyScene {
    /// Render the scene; returns linear RGB as a float32 array of shape (height, width, 3), top row first,
    /// or (height, width, C) with the further channels of an `aov` integrator after the RGB, named by
    /// `channels` (as `mitsuba.render` returns its AOVs, in the order of Mitsuba's film).
    ///
    /// - `spp`: samples per pixel (default: the scene's sampler `sample_count`)
    /// - `seed`: random seed (default: the sampler's `seed`); the image depends on the seed only, not on
    ///   the number of threads, and equals `gonio render --seed` bit for bit
    /// - `threads`: worker threads (default: all cores)
    /// - `progress`: show a progress bar on stderr when it is a terminal (or in Jupyter with tqdm)
    ///
    /// The GIL is released while rendering. Ctrl-C stops the render within a tile and raises
    /// `KeyboardInterrupt`; the scene and the interpreter stay usable.
    #[pyo3(signature = (spp = None, seed = None, threads = None, progress = true))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        spp: Option<i64>,
        seed: Option<i64>,
        threads: Option<i64>,
        progress: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let spp = match spp {
            None => self.scene.sampler.sample_count,
            Some(s) => u32::try_from(s)
                .ok()
                .filter(|&s| s >= 1)
                .ok_or_else(|| PyValueError::new_err(format!("`spp` must be an integer in [1, 2³²), got {s}")))?,
        };
        let seed = self.seed_or_default(seed)?;
        let out =
            self.run(py, spp, threads, progress, move |scene, cancel, progress| gonio::render::render(scene, spp, seed, cancel, progress))?;
        warn_nonfinite(py, out.nonfinite)?;
        let (w, h) = (self.scene.film.width as usize, self.scene.film.height as usize);
        let k = 3 + out.aovs.names.len();
        let data = if k == 3 {
            out.data
        } else {
            let further = out.aovs.data.chunks_exact(k - 3);
            out.data.chunks_exact(3).zip(further).flat_map(|(rgb, more)| rgb.iter().chain(more).copied()).collect()
        };
        let image = PyArray1::from_vec(py, data).reshape([h, w, k])?;
        Ok(image.into_any())
    }

    /// Render the samples with indices `first … first + count − 1` of every pixel and return their sums,
    /// not divided: a part of a render that adds up with the parts of other ranges (what
    /// `gonio.distributed.render` runs on each machine). Returns a dict:
    ///
    /// - `sum`: float64 array (height, width, C), the per-pixel sums of the (filter-weighted) samples, C
    ///   as in `render` (3, or more with an `aov` integrator: `channels`)
    /// - `weight`: float64 array (height, width) of summed filter weights, or `None` for the box filter
    /// - `first`, `spp`: the range summed (`spp` < `count` only when interrupted: then Ctrl-C raises
    ///   `KeyboardInterrupt` as `render` does, so a returned part is always whole)
    /// - `nonfinite`: samples that were NaN or infinite, dropped (counted as black); `seconds`
    ///
    /// Sample k of a pixel is the same in any range, so parts of disjoint ranges added (float64 `+`)
    /// and developed with `gonio.develop(sum, weight, spp)` give `render(spp, seed)`: bit for bit for the
    /// range 0 … spp − 1, and to the last bit of the float32 image for any split (docs/distributed.md).
    #[pyo3(signature = (first, count, seed = None, threads = None, progress = false))]
    fn render_samples<'py>(
        &self,
        py: Python<'py>,
        first: i64,
        count: i64,
        seed: Option<i64>,
        threads: Option<i64>,
        progress: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let range =
            u32::try_from(first).ok().zip(u32::try_from(count).ok()).and_then(|(a, n)| Some(a..a.checked_add(n)?)).ok_or_else(|| {
                PyValueError::new_err(format!("`first` and `count` must be ≥ 0 with first + count < 2³², got {first} and {count}"))
            })?;
        let seed = self.seed_or_default(seed)?;
        let spp = range.end - range.start;
        let part = self.run(py, spp, threads, progress, move |scene, cancel, progress| {
            gonio::render::render_samples(scene, seed, range, cancel, progress)
        })?;
        let (w, h, k) = (part.film.width as usize, part.film.height as usize, part.film.channels());
        let out = PyDict::new(py);
        out.set_item("sum", PyArray1::from_slice(py, part.film.sums()).reshape([h, w, k])?)?;
        match part.film.weights() {
            Some(wt) => out.set_item("weight", PyArray1::from_slice(py, wt).reshape([h, w])?)?,
            None => out.set_item("weight", py.None())?,
        }
        out.set_item("first", part.first)?;
        out.set_item("spp", part.spp_done)?;
        out.set_item("nonfinite", part.nonfinite)?;
        out.set_item("seconds", part.seconds)?;
        Ok(out)
    }

    /// The names of the channels `render` returns: `["R", "G", "B"]`, then an `aov` integrator's further
    /// channels as Mitsuba 3 names them (`image.R`, …, `image.A`, `nn.X`, …, `dd.y.T`).
    #[getter]
    fn channels(&self) -> Vec<String> {
        self.scene.integrator.channels()
    }

    /// `"rgb"` or `"spectral"`: how the scene was loaded (`load_scene(..., mode=...)`).
    #[getter]
    fn mode(&self) -> &'static str {
        self.scene.mode().name()
    }

    /// Image width in pixels (the film's `width`).
    #[getter]
    fn width(&self) -> u32 {
        self.scene.film.width
    }

    /// Image height in pixels (the film's `height`).
    #[getter]
    fn height(&self) -> u32 {
        self.scene.film.height
    }

    /// Samples per pixel `render` takes by default (the sampler's `sample_count`).
    #[getter]
    fn spp(&self) -> u32 {
        self.scene.sampler.sample_count
    }

    /// The seed `render` takes by default (the sampler's `seed`).
    #[getter]
    fn seed(&self) -> u64 {
        self.scene.sampler.seed
    }

    /// Number of shapes.
    #[getter]
    fn shape_count(&self) -> usize {
        self.scene.shapes.len()
    }

    /// Number of lights (area lights included).
    #[getter]
    fn light_count(&self) -> usize {
        self.scene.lights.len()
    }

    /// Number of primitives (triangles, spheres, disks) in the acceleration structure.
    #[getter]
    fn primitive_count(&self) -> usize {
        self.scene.primitive_count()
    }

    /// Where the scene came from: the file name, or `"<dict>"`.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// Things the loader accepted but approximates (also issued as `UserWarning`s at load time).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene.warnings.clone()
    }

    fn __repr__(&self) -> String {
        let s = &self.scene;
        let integrator = match &s.integrator {
            IntegratorKind::Path { max_depth, .. } => format!("path, max_depth {max_depth}"),
            IntegratorKind::Direct { .. } => "direct".to_string(),
            IntegratorKind::Aov { .. } => format!("aov, {} channels", s.integrator.channels().len()),
        };
        format!(
            "<gonio.Scene {}: {}×{}, {} spp, {} shapes ({} primitives), {} lights, {integrator}>",
            self.source,
            s.film.width,
            s.film.height,
            s.sampler.sample_count,
            s.shapes.len(),
            s.primitive_count(),
            s.lights.len()
        )
    }
}

fn warn_nonfinite(py: Python<'_>, nonfinite: u64) -> PyResult<()> {
    if nonfinite > 0 {
        let warn = py.import("warnings")?.getattr("warn")?;
        let message = format!("{nonfinite} non-finite samples dropped (counted as black)");
        warn.call1((message, py.get_type::<pyo3::exceptions::PyRuntimeWarning>(), 2))?;
    }
    Ok(())
}

/// The image of summed samples (`Scene.render_samples`' `sum` and `weight`, several parts added) holding
/// `spp` samples per pixel: the box filter's means, or weighted sums over summed weights, as float32
/// (height, width, C) — the same development as `Scene.render`'s. `weight` is `None` for the box filter.
#[pyfunction]
#[pyo3(signature = (sum, weight, spp))]
fn develop<'py>(
    py: Python<'py>,
    sum: numpy::PyReadonlyArray3<'py, f64>,
    weight: Option<numpy::PyReadonlyArray2<'py, f64>>,
    spp: u32,
) -> PyResult<Bound<'py, PyAny>> {
    let shape = sum.shape();
    let (h, w, k) = (shape[0], shape[1], shape[2]);
    if k < 3 {
        return Err(PyValueError::new_err(format!("develop: `sum` must have shape (height, width, C ≥ 3), got {shape:?}")));
    }
    if let Some(wt) = &weight {
        if wt.shape() != [h, w] {
            return Err(PyValueError::new_err(format!("develop: `weight` must have shape ({h}, {w}), got {:?}", wt.shape())));
        }
    }
    let too_big = || PyValueError::new_err(format!("develop: a {w}×{h} image is larger than a film may be"));
    let (w32, h32) = (u32::try_from(w).map_err(|_| too_big())?, u32::try_from(h).map_err(|_| too_big())?);
    let sum = sum.as_array().iter().copied().collect::<Vec<f64>>();
    let weight = weight.map(|wt| wt.as_array().iter().copied().collect::<Vec<f64>>());
    let film = gonio::film::Film::from_sums(w32, h32, k, &sum, weight.as_deref()).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(PyArray1::from_vec(py, film.mean(spp)).reshape([h, w, k])?.into_any())
}

/// The files a Mitsuba 3 XML scene is read from: the scene file, its `<include>`s, then every asset it
/// names (meshes, images, measured data, spectra), each once. `defines` as for `load_scene`.
#[pyfunction]
#[pyo3(signature = (path, **defines))]
fn scene_files(py: Python<'_>, path: PathBuf, defines: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<PathBuf>> {
    let overrides = overrides(defines)?;
    let desc = run_released(py, || gonio::scene::mitsuba_xml::load_file(&path, &overrides))?.map_err(scene_error)?;
    Ok(desc.files)
}

fn overrides(defines: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, String)>> {
    let mut overrides = Vec::new();
    for (k, v) in defines.map(|d| d.iter().collect::<Vec<_>>()).unwrap_or_default() {
        let value = if v.is_instance_of::<PyBool>() { v.extract::<bool>()?.to_string() } else { v.str()?.to_string() };
        overrides.push((k.extract::<String>()?, value));
    }
    Ok(overrides)
}

/// Load a Mitsuba 3 XML scene file. `defines` override its `<default name=… value=…>` parameters, as
/// `-D name=value` does on the command line (values are converted with `str`). `mode` is `"rgb"` or
/// `"spectral"` (three sampled wavelengths per path; docs/spectral.md), as `gonio render --mode`.
#[pyfunction]
#[pyo3(signature = (path, *, mode = "rgb", **defines))]
fn load_scene(py: Python<'_>, path: PathBuf, mode: &str, defines: Option<&Bound<'_, PyDict>>) -> PyResult<PyScene> {
    let overrides = overrides(defines)?;
    let source = path.display().to_string();
    let mode = Mode::parse(mode).map_err(scene_error)?;
    let scene = run_released(py, || Scene::load_in(&path, &overrides, mode))?.map_err(scene_error)?;
    PyScene::new(py, scene, source)
}

/// Build a scene from Mitsuba 3's scene dictionary, the form `mitsuba.load_dict` takes:
///
/// ```python
/// gonio.load_dict({
///     "type": "scene",
///     "integrator": {"type": "path", "max_depth": 8},
///     "sensor": {"type": "perspective", "fov": 40,
///                "to_world": gonio.look_at([0, 1, 5], [0, 0, 0], [0, 1, 0]),
///                "film": {"type": "hdrfilm", "width": 320, "height": 240},
///                "sampler": {"type": "independent", "sample_count": 16}},
///     "gold": {"type": "roughconductor", "material": "Au", "alpha": 0.2},
///     "ball": {"type": "sphere", "radius": 0.5, "bsdf": {"type": "ref", "id": "gold"}},
///     "light": {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}},
/// })
/// ```
///
/// Every value with a `"type"` is a plugin; its class (shape, emitter, bsdf, …) follows from the type as
/// in Mitsuba. Top-level keys are ids (unless `"id"` is given) that `{"type": "ref", "id": …}` refers to.
/// `to_world` is a 4×4 matrix: a nested list, a numpy array, or anything with a `matrix` attribute
/// (`mitsuba.ScalarTransform4f`). Points are `[x, y, z]`; colours `[r, g, b]`, a number or
/// `{"type": "rgb", "value": …}`. Relative file names are relative to the working directory. Raises
/// `gonio.SceneError` (a `ValueError`) naming the dictionary path (`$.ball.bsdf.alpha`) of the problem.
/// `mode` is `"rgb"` or `"spectral"`, as for `load_scene`.
#[pyfunction]
#[pyo3(signature = (scene, *, mode = "rgb"))]
fn load_dict(py: Python<'_>, scene: &Bound<'_, PyAny>, mode: &str) -> PyResult<PyScene> {
    let mode = Mode::parse(mode).map_err(scene_error)?;
    if !scene.is_instance_of::<PyDict>() {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "load_dict expects a dict, got {}",
            scene.get_type().name().map(|n| n.to_string()).unwrap_or_default()
        )));
    }
    let value = to_json(scene, "$")?;
    let scene =
        run_released(py, || mitsuba_dict::load_value(&value, "<dict>").and_then(|d| Scene::build_in(d, mode)))?.map_err(scene_error)?;
    PyScene::new(py, scene, "<dict>".into())
}

/// The camera-to-world matrix looking from `origin` towards `target` with `up` upwards, as a 4×4 float64
/// array for a sensor's `to_world` — the matrix of Mitsuba's `<lookat>` (and of
/// `ScalarTransform4f().look_at(...)`), computed exactly as gonio's XML loader does.
#[pyfunction]
#[pyo3(signature = (origin, target, up = [0.0, 1.0, 0.0]))]
fn look_at<'py>(py: Python<'py>, origin: [f32; 3], target: [f32; 3], up: [f32; 3]) -> PyResult<Bound<'py, PyAny>> {
    let t = Transform::look_at(Vec3::from(origin), Vec3::from(target), Vec3::from(up))
        .ok_or_else(|| PyValueError::new_err("look_at: origin equals target, or `up` is parallel to the view direction"))?;
    let rows: Vec<f64> = t.matrix.transpose().to_cols_array().iter().map(|&v| f64::from(v)).collect();
    Ok(PyArray1::from_vec(py, rows).reshape([4, 4])?.into_any())
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(load_dict, m)?)?;
    m.add_function(wrap_pyfunction!(look_at, m)?)?;
    m.add_function(wrap_pyfunction!(develop, m)?)?;
    m.add_function(wrap_pyfunction!(scene_files, m)?)?;
    Ok(())
}
