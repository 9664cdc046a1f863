//! The batched loops behind `Bsdf.f`, `pdf` and `sample`: arguments are read in place from numpy
//! (contiguous float32 rows are used as `Vec3`/`Vec2` slices without a copy; float64 and broadcast rows
//! are converted per chunk) and handed a chunk at a time to the model's batch methods
//! ([`gonio::bsdf::BsdfModel::f_batch_checked`] and friends: one `match` on the model per chunk, SIMD
//! loops), which write straight into the result arrays. Float32 rows are checked by those methods in the
//! same pass ([`UNIT_BAND`]; a chunk they do not settle is checked row by row, exactly); converted rows are
//! checked while converted. Chunks run in parallel on rayon's threads, without the GIL.

use gonio::bsdf::RowCheck;
use gonio::math::{Vec2, Vec3};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use std::ops::Range;

/// Rows per parallel task: large enough to amortise scheduling, small enough to balance 2–64 cores and
/// for a task's inputs, outputs and `sample`'s buffer of results (about 60 bytes a row) to stay in cache.
const CHUNK: usize = 4096;

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

    /// The numbers of a float32 argument with N rows, in place; `None` for other storage or one row.
    fn in_place(&self) -> Option<&[f32]> {
        match self.data {
            Slice::F32(s) if !self.single => Some(s),
            _ => None,
        }
    }

    /// Rows `rows` of a float32 width-3 argument as `Vec3`s, in place and unchecked (see
    /// [`Self::in_place`]).
    pub(crate) fn vec3_in_place(&self, rows: Range<usize>) -> Option<&[Vec3]> {
        let s = &self.in_place()?[3 * rows.start..3 * rows.end];
        // SAFETY: `Vec3` is `#[repr(C)]` of three `f32` (size 12, alignment 4), and `s` holds exactly
        // 3·len floats, so it is `len` `Vec3`s; the borrow keeps the array alive and unchanged.
        Some(unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<Vec3>(), rows.len()) })
    }

    /// Rows `rows` of a float32 width-1 argument, in place and unchecked.
    pub(crate) fn f32_in_place(&self, rows: Range<usize>) -> Option<&[f32]> {
        Some(&self.in_place()?[rows])
    }

    /// Rows `rows` of a float32 width-2 argument as `Vec2`s, in place and unchecked.
    pub(crate) fn vec2_in_place(&self, rows: Range<usize>) -> Option<&[Vec2]> {
        let s = &self.in_place()?[2 * rows.start..2 * rows.end];
        // SAFETY: `Vec2` is `#[repr(C)]` of two `f32`; `s` holds 2·len floats (see `vec3_in_place`).
        Some(unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<Vec2>(), rows.len()) })
    }

    /// Rows `rows` as directions (see [`crate::to_direction`]), or `None` when any is not acceptable.
    /// Unit float32 rows are read in place (a numpy row of three float32 is laid out as a `Vec3`); other
    /// storage is converted into `buf`. One tight loop per storage type, without per-row dispatch, so that
    /// the check of a million rows costs about what reading them does.
    pub(crate) fn directions<'b>(&'b self, rows: Range<usize>, normalize: bool, buf: &'b mut Vec<Vec3>) -> Option<&'b [Vec3]> {
        buf.clear();
        if normalize || self.single {
            // Rare or cheap: the general path.
            for i in rows {
                buf.push(crate::to_direction(self.row3(i), normalize)?);
            }
            return Some(buf);
        }
        match self.data {
            Slice::F32(s) => {
                let s = &s[3 * rows.start..3 * rows.end];
                let ok = s.chunks_exact(3).fold(true, |ok, w| ok & crate::is_unit(f64::from(w[0]), f64::from(w[1]), f64::from(w[2])));
                // SAFETY: `Vec3` is `#[repr(C)]` of three `f32` (size 12, alignment 4), and `s` holds
                // exactly 3·len floats, so it is `len` `Vec3`s; the borrow keeps the array alive and unchanged.
                ok.then(|| unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<Vec3>(), rows.len()) })
            }
            Slice::F64(s) => {
                let mut ok = true;
                for w in s[3 * rows.start..3 * rows.end].chunks_exact(3) {
                    ok &= crate::is_unit(w[0], w[1], w[2]);
                    buf.push(Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32));
                }
                ok.then_some(&buf[..])
            }
        }
    }

    /// Rows `rows` of a width-1 argument as `f32`, or `None` when any is outside [0, 1] (checked before
    /// rounding to `f32`). Float32 arrays are read in place.
    pub(crate) fn unit_numbers<'b>(&'b self, rows: Range<usize>, buf: &'b mut Vec<f32>) -> Option<&'b [f32]> {
        match self.data {
            Slice::F32(s) if !self.single => {
                let s = &s[rows];
                s.iter().fold(true, |ok, v| ok & (0.0..=1.0).contains(v)).then_some(s)
            }
            _ => {
                buf.clear();
                for i in rows {
                    let v = self.get(i, 0);
                    if !(0.0..=1.0).contains(&v) {
                        return None;
                    }
                    buf.push(v as f32);
                }
                Some(buf)
            }
        }
    }

    /// Rows `rows` of a width-2 argument as `Vec2`s, each number in [0, 1] (see [`Self::unit_numbers`]).
    pub(crate) fn unit_pairs<'b>(&'b self, rows: Range<usize>, buf: &'b mut Vec<Vec2>) -> Option<&'b [Vec2]> {
        match self.data {
            Slice::F32(s) if !self.single => {
                let s = &s[2 * rows.start..2 * rows.end];
                let ok = s.iter().fold(true, |ok, v| ok & (0.0..=1.0).contains(v));
                // SAFETY: `Vec2` is `#[repr(C)]` of two `f32`; `s` holds 2·len floats (see `directions`).
                ok.then(|| unsafe { std::slice::from_raw_parts(s.as_ptr().cast::<Vec2>(), rows.len()) })
            }
            _ => {
                buf.clear();
                for i in rows {
                    let (a, b) = (self.get(i, 0), self.get(i, 1));
                    if !((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)) {
                        return None;
                    }
                    buf.push(Vec2::new(a as f32, b as f32));
                }
                Some(buf)
            }
        }
    }
}

/// The squared lengths, computed in f32, of directions that surely pass [`crate::is_unit`] (in f64: |w|² in
/// [(1 − 10⁻³)², (1 + 10⁻³)²]): that interval narrowed by 10⁻⁶ relative at either end. The f32 sum of three
/// squares is within 3 roundings (2·10⁻⁷ relative) of the exact one, and a square that overflows or
/// underflows lands far outside. The batch methods test float32 rows against it in their own pass; a chunk
/// with a row outside is checked exactly.
pub(crate) const UNIT_BAND: RowCheck = RowCheck {
    lo: ((1.0 - crate::UNIT_TOLERANCE) * (1.0 - crate::UNIT_TOLERANCE) * (1.0 + 1e-6)) as f32,
    hi: ((1.0 + crate::UNIT_TOLERANCE) * (1.0 + crate::UNIT_TOLERANCE) * (1.0 - 1e-6)) as f32,
};

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
pub(crate) fn for_chunks(n: usize, chunk: impl Fn(Range<usize>) -> bool + Sync) -> bool {
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
    /// Elements `start..start + len`, to be overwritten (they may be uninitialised: never read them first).
    ///
    /// # Safety
    /// The range is within the array and no other task touches it while the slice lives.
    #[inline]
    pub(crate) unsafe fn slice<'a>(self, start: usize, len: usize) -> &'a mut [T] {
        std::slice::from_raw_parts_mut(self.0.add(start), len)
    }
}

/// A new, uninitialised, contiguous 1-D numpy array of `len` elements and a pointer to fill it.
/// Every element must be written before the array is handed to Python.
///
/// Arrays of at least [`POOLED_BYTES`] live in memory from [`pool`] (see there why); smaller ones are
/// numpy's own.
pub(crate) fn output<T: numpy::Element>(py: Python<'_>, len: usize) -> PyResult<(Bound<'_, PyArray1<T>>, Out<T>)> {
    let bytes = len * std::mem::size_of::<T>();
    if bytes < pool::POOLED_BYTES {
        // SAFETY: the array is fresh and C-contiguous; callers write every element before returning it.
        let a = unsafe { PyArray1::<T>::new(py, [len], false) };
        let ptr = a.data();
        return Ok((a, Out(ptr)));
    }
    let block = pool::take(bytes);
    let ptr = block.as_ptr().cast::<T>();
    let container = Bound::new(py, block)?;
    // SAFETY: the block holds `bytes` = len·size_of::<T>() bytes aligned to 64 (more than any element
    // needs), and it is not freed nor reused before `container`, the array's base object, is dropped. The
    // view is only used to describe the memory to numpy (its elements are not read here).
    let view = unsafe { numpy::ndarray::ArrayView1::from_shape_ptr(len, ptr.cast_const()) };
    let a = unsafe { PyArray1::<T>::borrow_from_array(&view, container.into_any()) };
    Ok((a, Out(ptr)))
}

/// The memory of large result arrays, kept for reuse.
///
/// Why: a 10⁶-row `sample` returns 49 MB in seven arrays. From numpy's allocator (glibc `malloc`) that
/// memory goes back to the kernel when the arrays are freed (it is the top of the heap, beyond the trim
/// threshold), so every call faulted its pages in again: 4 800 page faults, 18–25 ms of a call whose
/// arithmetic takes 4 (2026-11, measured with `getrusage` and `perf`: `clear_page_erms` and fault
/// handling). Mitsuba's Dr.Jit keeps its allocations in a cache for the same reason. Here a freed result's
/// block returns to a small pool, and the next call's arrays of about the same size take it (best fit,
/// at most a quarter larger), so repeated calls touch warm, mapped pages. The pool keeps at most
/// [`CACHED_BYTES`] (older blocks are freed first); [`release`] empties it.
pub(crate) mod pool {
    use pyo3::prelude::*;
    use std::alloc::{alloc, dealloc, handle_alloc_error, Layout};
    use std::cmp::Reverse;
    use std::ptr::NonNull;
    use std::sync::Mutex;

    /// Arrays from this size on use the pool (smaller ones are recycled by `malloc` itself: glibc serves
    /// them from its heap, whose top is only trimmed beyond 128 KiB and more).
    pub(crate) const POOLED_BYTES: usize = 256 << 10;
    /// The most memory the pool keeps while no array uses it.
    pub(crate) const CACHED_BYTES: usize = 256 << 20;
    /// Alignment of a block: a cache line, and enough for any numpy element type.
    const ALIGN: usize = 64;

    /// A block of memory from [`take`]: freed explicitly, by [`free`] (no `Drop`).
    struct Memory {
        ptr: NonNull<u8>,
        bytes: usize,
    }

    // SAFETY: plain memory, owned by exactly one `Memory` (or the `Block` holding it).
    unsafe impl Send for Memory {}
    unsafe impl Sync for Memory {}

    fn layout(bytes: usize) -> Layout {
        Layout::from_size_align(bytes, ALIGN).expect("array size fits in memory")
    }

    /// The memory of one result array (the array's base object): back to the cache when the array goes.
    #[pyclass(module = "gonio._gonio", name = "_Block", frozen)]
    pub(crate) struct Block(Memory);

    impl Block {
        /// The first byte.
        pub(crate) fn as_ptr(&self) -> *mut u8 {
            self.0.ptr.as_ptr()
        }
    }

    impl Drop for Block {
        fn drop(&mut self) {
            give_back(Memory { ptr: self.0.ptr, bytes: self.0.bytes });
        }
    }

    /// Cached memory, oldest first, and its total size.
    static CACHE: Mutex<(Vec<Memory>, usize)> = Mutex::new((Vec::new(), 0));

    fn free(m: Memory) {
        // SAFETY: allocated in `take` with this layout, and owned by `m` alone.
        unsafe { dealloc(m.ptr.as_ptr(), layout(m.bytes)) };
    }

    /// A block of at least `bytes` bytes (contents unspecified): the smallest cached one that is at most a
    /// quarter larger, of those the last returned (the likeliest still in the CPU's caches), else a new
    /// allocation.
    pub(crate) fn take(bytes: usize) -> Block {
        let bytes = bytes.max(1);
        {
            let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
            let fits = |m: &Memory| m.bytes >= bytes && m.bytes - bytes <= bytes / 4;
            let best = cache.0.iter().enumerate().filter(|(_, m)| fits(m)).min_by_key(|&(i, m)| (m.bytes, Reverse(i))).map(|(i, _)| i);
            if let Some(i) = best {
                let m = cache.0.remove(i);
                cache.1 -= m.bytes;
                return Block(m);
            }
        }
        let layout = layout(bytes);
        // SAFETY: the layout has a non-zero size.
        let ptr = NonNull::new(unsafe { alloc(layout) }).unwrap_or_else(|| handle_alloc_error(layout));
        Block(Memory { ptr, bytes })
    }

    /// Keep `m` for reuse, freeing the oldest cached memory beyond [`CACHED_BYTES`].
    fn give_back(m: Memory) {
        if m.bytes > CACHED_BYTES {
            return free(m);
        }
        let evicted = {
            let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
            cache.1 += m.bytes;
            cache.0.push(m);
            let mut evicted = Vec::new();
            while cache.1 > CACHED_BYTES {
                let old = cache.0.remove(0);
                cache.1 -= old.bytes;
                evicted.push(old);
            }
            evicted
        };
        evicted.into_iter().for_each(free);
    }

    /// Free every cached block; the number of bytes freed.
    pub(crate) fn release() -> usize {
        let (cached, bytes) = std::mem::take(&mut *CACHE.lock().unwrap_or_else(|e| e.into_inner()));
        cached.into_iter().for_each(free);
        bytes
    }

    /// The number of bytes cached (not in use by any array).
    pub(crate) fn cached() -> usize {
        CACHE.lock().unwrap_or_else(|e| e.into_inner()).1
    }
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
