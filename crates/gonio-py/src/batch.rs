//! The batched loops behind `Bsdf.f`, `pdf` and `sample`: arguments are read in place from numpy
//! (contiguous float32 or float64 arrays are not copied), rows are checked and evaluated in one pass,
//! in parallel over chunks of rows on rayon's threads, and results are written straight into freshly
//! allocated numpy arrays. Everything in the loop runs without the GIL.

use gonio::math::Vec3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

/// Rows per parallel task: large enough to amortise scheduling, small enough to balance 2–64 cores.
const CHUNK: usize = 8192;

/// An array argument's numbers: borrowed from numpy when possible, else converted.
enum Numbers<'py> {
    F32(PyReadonlyArrayDyn<'py, f32>),
    F64(PyReadonlyArrayDyn<'py, f64>),
    Owned(Vec<f64>),
}

/// One argument of a batched call: rows of `width` numbers.
pub(crate) struct Arg<'py> {
    numbers: Numbers<'py>,
    pub(crate) name: &'static str,
    pub(crate) width: usize,
    /// Number of rows (1 for an argument given without the leading axis).
    pub(crate) n: usize,
    /// Whether the argument had the leading (N) axis.
    pub(crate) batched: bool,
}

impl<'py> Arg<'py> {
    /// Read `obj` (any array-like) as rows of `width` numbers. Accepted shapes: `(width,)` and
    /// `(N, width)`; for `width == 1` also `()` and `(N,)`.
    pub(crate) fn read(obj: &Bound<'py, PyAny>, name: &'static str, width: usize) -> PyResult<Self> {
        let (numbers, shape) = if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'py, f32>>() {
            let shape = a.shape().to_vec();
            (
                if a.is_c_contiguous() { Numbers::F32(a) } else { Numbers::Owned(a.as_array().iter().map(|&v| f64::from(v)).collect()) },
                shape,
            )
        } else if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'py, f64>>() {
            let shape = a.shape().to_vec();
            (if a.is_c_contiguous() { Numbers::F64(a) } else { Numbers::Owned(a.as_array().iter().copied().collect()) }, shape)
        } else {
            let np = obj.py().import("numpy")?;
            let converted = np
                .getattr("asarray")?
                .call1((obj, "float64"))
                .map_err(|e| PyValueError::new_err(format!("`{name}` must be an array of numbers: {e}")))?;
            let a = converted.extract::<PyReadonlyArrayDyn<'_, f64>>()?;
            (Numbers::Owned(a.as_array().iter().copied().collect()), a.shape().to_vec())
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
        Ok(Arg { numbers, name, width, n, batched })
    }

    /// A `Send` view of the numbers, broadcasting a single row.
    pub(crate) fn column(&self) -> Column<'_> {
        let data = match &self.numbers {
            // Both are contiguous (checked in `read`), so `as_slice` cannot fail.
            Numbers::F32(a) => Slice::F32(a.as_slice().unwrap_or(&[])),
            Numbers::F64(a) => Slice::F64(a.as_slice().unwrap_or(&[])),
            Numbers::Owned(v) => Slice::F64(v),
        };
        Column { data, width: self.width, single: self.n == 1 }
    }
}

#[derive(Clone, Copy)]
enum Slice<'a> {
    F32(&'a [f32]),
    F64(&'a [f64]),
}

/// Row `i`, number `c` of an argument, as f64; a 1-row argument broadcasts.
#[derive(Clone, Copy)]
pub(crate) struct Column<'a> {
    data: Slice<'a>,
    width: usize,
    single: bool,
}

impl Column<'_> {
    #[inline]
    pub(crate) fn get(&self, i: usize, c: usize) -> f64 {
        let k = if self.single { c } else { i * self.width + c };
        match self.data {
            Slice::F32(s) => f64::from(s[k]),
            Slice::F64(s) => s[k],
        }
    }

    #[inline]
    pub(crate) fn row3(&self, i: usize) -> [f64; 3] {
        [self.get(i, 0), self.get(i, 1), self.get(i, 2)]
    }

    /// Rows `rows` as directions (see [`crate::to_direction`]) into `out` (cleared first); false when
    /// any is not acceptable. One tight loop per storage type, without per-row dispatch, so that the
    /// check of a million rows costs about what reading them does.
    pub(crate) fn directions(&self, rows: std::ops::Range<usize>, normalize: bool, out: &mut Vec<Vec3>) -> bool {
        out.clear();
        if normalize || self.single {
            // Rare or cheap: the general path.
            for i in rows {
                match crate::to_direction(self.row3(i), normalize) {
                    Some(w) => out.push(w),
                    None => return false,
                }
            }
            return true;
        }
        let mut ok = true;
        match self.data {
            Slice::F32(s) => {
                for w in s[3 * rows.start..3 * rows.end].chunks_exact(3) {
                    let (x, y, z) = (f64::from(w[0]), f64::from(w[1]), f64::from(w[2]));
                    ok &= crate::is_unit(x, y, z);
                    out.push(Vec3::new(w[0], w[1], w[2]));
                }
            }
            Slice::F64(s) => {
                for w in s[3 * rows.start..3 * rows.end].chunks_exact(3) {
                    ok &= crate::is_unit(w[0], w[1], w[2]);
                    out.push(Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32));
                }
            }
        }
        ok
    }
}

/// The common row count of several arguments (1-row arguments broadcast), and whether any was batched.
pub(crate) fn broadcast(args: &[&Arg<'_>]) -> PyResult<(usize, bool)> {
    let batched = args.iter().any(|a| a.batched);
    let mut n = 1;
    for a in args {
        if a.n != 1 {
            if n != 1 && n != a.n {
                let shapes: Vec<String> = args.iter().map(|a| format!("{}: {} rows", a.name, a.n)).collect();
                return Err(PyValueError::new_err(format!("cannot broadcast arguments together ({})", shapes.join(", "))));
            }
            n = a.n;
        }
    }
    // numpy semantics: a (0, k) argument broadcasts the others to zero rows.
    if args.iter().any(|a| a.n == 0) {
        n = 0;
    }
    Ok((n, batched))
}

/// Run `chunk(rows)` over consecutive ranges of rows covering `0..n`, in parallel when there are many;
/// true when every chunk succeeded (the caller then finds and reports the first failing row).
pub(crate) fn for_chunks(n: usize, chunk: impl Fn(std::ops::Range<usize>) -> bool + Sync) -> bool {
    let range = |c: usize| c * CHUNK..n.min((c + 1) * CHUNK);
    if n <= CHUNK {
        chunk(0..n)
    } else {
        (0..n.div_ceil(CHUNK)).into_par_iter().all(|c| chunk(range(c)))
    }
}

/// A pointer to the first element of an output array, shared by the tasks that fill disjoint rows.
#[derive(Clone, Copy)]
pub(crate) struct Out<T>(*mut T);

// SAFETY: every task writes a disjoint set of indices of an array nobody else can see yet.
unsafe impl<T: Send> Send for Out<T> {}
unsafe impl<T: Send> Sync for Out<T> {}

impl<T> Out<T> {
    /// Write `v` at index `i`.
    ///
    /// # Safety
    /// `i` is within the array and no other task writes index `i`.
    #[inline]
    pub(crate) unsafe fn write(self, i: usize, v: T) {
        self.0.add(i).write(v);
    }
}

/// A new, uninitialised, contiguous 1-D numpy array of `len` elements and a pointer to fill it.
/// Every element must be written before the array is handed to Python.
pub(crate) fn output<T: numpy::Element>(py: Python<'_>, len: usize) -> (Bound<'_, PyArray1<T>>, Out<T>) {
    // SAFETY: the array is fresh and C-contiguous; callers write every element before returning it.
    let a = unsafe { PyArray1::<T>::new(py, [len], false) };
    let ptr = a.data();
    (a, Out(ptr))
}

/// Shape a filled output: (N, width) when `batched`, else the single row ((width,), or a numpy scalar
/// for width 1).
pub(crate) fn finish<'py, T: numpy::Element>(a: Bound<'py, PyArray1<T>>, width: usize, batched: bool) -> PyResult<Bound<'py, PyAny>> {
    match (batched, width) {
        (true, 1) => Ok(a.into_any()),
        (true, w) => {
            let n = a.len() / w;
            Ok(a.reshape([n, w])?.into_any())
        }
        (false, 1) => a.into_any().get_item(0),
        (false, _) => Ok(a.into_any()),
    }
}
