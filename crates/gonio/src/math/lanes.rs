//! Numbers in lanes: one formula written once, run on a single `f32` or on many at a time.
//!
//! | item        | what it is                                                                          |
//! |-------------|-------------------------------------------------------------------------------------|
//! | [`Real`]    | the arithmetic a formula needs: + − × ÷, √, fused multiply–add, min/max, comparisons into a mask, `select`, a table lookup |
//! | `f32`       | one lane; its mask is `bool` and `select` a branch — the renderer's single calls      |
//! | [`F32x8`]   | eight lanes as plain Rust: each operation written out per lane, for CPUs without AVX2 (and other architectures) |
//! | `avx2::Avx8`, `avx512::Avx16` | eight or sixteen lanes in one AVX / AVX-512 register, each operation its instruction; what the batch drivers run on where the CPU has them (crate-private unless the build enables AVX2 and FMA: see `math::avx2`) |
//! | `simd::Float8` | the renderer's eight lanes, chosen at compile time: `Avx8` itself where the build enables AVX2 and FMA, else two SSE registers (or an array) |
//! | `twice::Twice<R>` | two registers of `R` as one, their operations alternating (two dependency chains in flight): the AVX-512 drivers run `Twice<Twice<Avx16>>` |
//! | [`V3`]      | a direction of lanes (structure of arrays: x, y and z each one `Real`)               |
//! | `Rows`      | moving a register of rows between slices and lanes (the batch drivers' side)          |
//!
//! A formula generic over [`Real`] computes, in every lane, exactly the IEEE operations it computes on an
//! `f32`, in the same order (every operation is correctly rounded, and Rust never fuses a multiply and an
//! add on its own), so the lanes' result equals the single calls bit for bit. Branches become masks: both
//! sides are computed and [`Real::select`] keeps one per lane; a lane's discarded side may be NaN or
//! infinite, which is harmless. [`Real::any`] lets a formula skip work no lane needs (on an `f32` it is the
//! early return of scalar code). Every lane type passes the same checks (`check_lane_type` in the tests).

use crate::math::{Vec2, Vec3};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// The arithmetic of a lane type (see the module doc). Every method is the per-lane `f32` operation of the
/// same name.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f32, Output = Self>
    + Sub<f32, Output = Self>
    + Mul<f32, Output = Self>
    + Div<f32, Output = Self>
{
    /// One comparison result per lane.
    type Mask: Copy + BitAnd<Output = Self::Mask> + BitOr<Output = Self::Mask> + Not<Output = Self::Mask>;
    const LANES: usize;

    fn splat(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// self < o ? self : o, and `self` where `o` is NaN: `f32::min` (the other operand where one is NaN),
    /// with ties of ±0 settled as x86's `minss(self, o)` does (`o`), which is what `f32::min(x, c)` with a
    /// constant `c` — the only form the kernels use — compiles to. Written out so that every lane type
    /// gives the same bits whatever the compiler knows about `o`.
    fn min(self, o: Self) -> Self;
    /// As [`Self::min`], with self > o.
    fn max(self, o: Self) -> Self;
    fn clamp(self, lo: f32, hi: f32) -> Self;
    /// `f32::mul_add`: self · a + b with one rounding.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// self · a + b for speed: fused ([`Self::mul_add`], one instruction) where the build enables FMA,
    /// else a product and a sum (two roundings; the exact fused operation would be a library call per lane).
    /// The choice is the build's, the same for every lane type, so that lanes still equal single calls bit
    /// for bit within one build.
    #[inline(always)]
    #[must_use]
    fn mad(self, a: Self, b: Self) -> Self {
        if cfg!(target_feature = "fma") {
            self.mul_add(a, b)
        } else {
            self * a + b
        }
    }
    /// `f32::round`: to the nearest integer, halves away from zero.
    fn round(self) -> Self;
    /// `self` with its sign flipped where `o`'s sign bit is set (−0 and NaNs included): the bits
    /// `self ^ (o & sign)`.
    fn xor_sign(self, o: Self) -> Self;
    /// 2ⁿ for a whole number n = `self` ∈ [−126, 127]: the float with that exponent and no fraction (the
    /// bits (n + 127) << 23; other arguments give other bits).
    fn pow2(self) -> Self;
    /// (m, e) with `self` = m · 2ᵉ, m ∈ [1, 2) and e whole, for a positive normal `self` (its significand and
    /// exponent bits; other arguments give other numbers).
    fn split_exponent(self) -> (Self, Self);
    /// `f(lane)` in every lane: for scalar code (not vectorised, same results).
    fn map(self, f: impl Fn(f32) -> f32) -> Self;
    /// The piecewise-linear function through `table[k]` at k/(N − 1), on [0, 1] (arguments are clamped to
    /// it; NaN gives NaN): with x·(N − 1) = k + t, (1 − t)·`table[k]` + t·`table[k + 1]`.
    fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self;
    fn lt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn eq(self, o: Self) -> Self::Mask;
    fn ne(self, o: Self) -> Self::Mask;
    fn is_finite(self) -> Self::Mask;
    fn is_nan(self) -> Self::Mask;
    /// `a` where `m` is set, else `b`, per lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Whether any lane of `m` is set.
    fn any(m: Self::Mask) -> bool;
    /// Lane `i`, for code that works lane by lane (a model that cannot vectorise: see
    /// `bsdf::lanes::each_lane`).
    fn lane(self, i: usize) -> f32;
    /// Lane `i` = `f(i)`, for `i` in 0..`LANES`, in that order.
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self;
    /// Bit `i` set where lane `i` of `m` is.
    fn bitmask(m: Self::Mask) -> u64;
}

impl Real for f32 {
    type Mask = bool;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        if self < o || o.is_nan() {
            self
        } else {
            o
        }
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        if self > o || o.is_nan() {
            self
        } else {
            o
        }
    }
    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        f32::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f32::mul_add(self, a, b)
    }
    #[inline(always)]
    fn round(self) -> Self {
        f32::round(self)
    }
    #[inline(always)]
    fn xor_sign(self, o: Self) -> Self {
        f32::from_bits(self.to_bits() ^ (o.to_bits() & 0x8000_0000))
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        f32::from_bits(((self as i32).wrapping_add(127) as u32) << 23)
    }
    #[inline(always)]
    fn split_exponent(self) -> (Self, Self) {
        let bits = self.to_bits();
        (f32::from_bits(bits & 0x007f_ffff | 0x3f80_0000), ((bits >> 23) as i32 - 127) as f32)
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        f(self)
    }
    #[inline(always)]
    fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self {
        let x = self.clamp(0.0, 1.0) * (N - 1) as f32;
        let k = (x as usize).min(N - 2);
        let t = x - k as f32;
        (1.0 - t) * table[k] + t * table[k + 1]
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn ne(self, o: Self) -> bool {
        self != o
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn any(m: bool) -> bool {
        m
    }
    #[inline(always)]
    fn lane(self, _: usize) -> f32 {
        self
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        f(0)
    }
    #[inline(always)]
    fn bitmask(m: bool) -> u64 {
        u64::from(m)
    }
}

/// Eight `f32` lanes, aligned as one 256-bit register.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F32x8(pub [f32; 8]);

/// Eight comparison results: all bits set (true) or clear (false) per lane, the form vector compares
/// produce and blends consume.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M32x8(pub [i32; 8]);

/// `F32x8` (or `M32x8`) from an expression of the lane index `i`, written out once per lane: `[e(0), …,
/// e(7)]`. Not a loop: a loop per operation leaves LLVM one loop to rotate and unroll per operation, and a
/// kernel inlined into a batch driver holds thousands of operations; its loop passes grew with the
/// function's size times its number of loops (2026-12-05: 10 of the 16 CPU-minutes of the library's test
/// build went to `LoopRotate` and `LoopFullUnroll` on the `F32x8` copies of the composites' batch loops).
/// The SLP vectoriser makes vector instructions of the eight expressions as it did of the unrolled loop.
macro_rules! lanes {
    (|$i:ident| $e:expr) => {
        [
            {
                let $i: usize = 0;
                $e
            },
            {
                let $i: usize = 1;
                $e
            },
            {
                let $i: usize = 2;
                $e
            },
            {
                let $i: usize = 3;
                $e
            },
            {
                let $i: usize = 4;
                $e
            },
            {
                let $i: usize = 5;
                $e
            },
            {
                let $i: usize = 6;
                $e
            },
            {
                let $i: usize = 7;
                $e
            },
        ]
    };
    ($t:ident, |$i:ident| $e:expr) => {
        $t(lanes!(|$i| $e))
    };
}

/// Runs `$s` for the lane indices 0 to 7, written out (not a loop; see [`lanes!`]).
macro_rules! each_lane {
    (|$i:ident| $s:expr) => {{
        let _: [(); 8] = lanes!(|$i| $s);
    }};
}

macro_rules! lane_ops {
    ($($tr:ident $f:ident $op:tt),*) => {$(
        impl $tr for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn $f(self, o: F32x8) -> F32x8 { lanes!(F32x8, |i| self.0[i] $op o.0[i]) }
        }
        impl $tr<f32> for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn $f(self, o: f32) -> F32x8 { lanes!(F32x8, |i| self.0[i] $op o) }
        }
    )*};
}
lane_ops!(Add add +, Sub sub -, Mul mul *, Div div /);

impl Neg for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn neg(self) -> F32x8 {
        lanes!(F32x8, |i| -self.0[i])
    }
}

impl BitAnd for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn bitand(self, o: M32x8) -> M32x8 {
        lanes!(M32x8, |i| self.0[i] & o.0[i])
    }
}

impl BitOr for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn bitor(self, o: M32x8) -> M32x8 {
        lanes!(M32x8, |i| self.0[i] | o.0[i])
    }
}

impl Not for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn not(self) -> M32x8 {
        lanes!(M32x8, |i| !self.0[i])
    }
}

impl M32x8 {
    /// Lane `i` as a `bool`.
    #[inline(always)]
    #[must_use]
    pub fn get(self, i: usize) -> bool {
        self.0[i] != 0
    }
}

/// A mask lane from a `bool`: all bits set for true.
#[inline(always)]
fn bits(b: bool) -> i32 {
    -i32::from(b)
}

impl Real for F32x8 {
    type Mask = M32x8;
    const LANES: usize = 8;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        F32x8([v; 8])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        lanes!(F32x8, |i| self.0[i].sqrt())
    }
    #[inline(always)]
    fn abs(self) -> Self {
        lanes!(F32x8, |i| self.0[i].abs())
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        lanes!(F32x8, |i| Real::min(self.0[i], o.0[i]))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        lanes!(F32x8, |i| Real::max(self.0[i], o.0[i]))
    }
    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        lanes!(F32x8, |i| self.0[i].clamp(lo, hi))
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        lanes!(F32x8, |i| self.0[i].mul_add(a.0[i], b.0[i]))
    }
    #[inline(always)]
    fn round(self) -> Self {
        lanes!(F32x8, |i| self.0[i].round())
    }
    #[inline(always)]
    fn xor_sign(self, o: Self) -> Self {
        lanes!(F32x8, |i| Real::xor_sign(self.0[i], o.0[i]))
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        lanes!(F32x8, |i| Real::pow2(self.0[i]))
    }
    #[inline(always)]
    fn split_exponent(self) -> (Self, Self) {
        (lanes!(F32x8, |i| Real::split_exponent(self.0[i]).0), lanes!(F32x8, |i| Real::split_exponent(self.0[i]).1))
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        lanes!(F32x8, |i| f(self.0[i]))
    }
    #[inline(always)]
    fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self {
        self.map(|x| x.lerp_table(table))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i] < o.0[i]))
    }
    #[inline(always)]
    fn le(self, o: Self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i] <= o.0[i]))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i] > o.0[i]))
    }
    #[inline(always)]
    fn ge(self, o: Self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i] >= o.0[i]))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i] == o.0[i]))
    }
    #[inline(always)]
    fn ne(self, o: Self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i] != o.0[i]))
    }
    #[inline(always)]
    fn is_finite(self) -> M32x8 {
        // |x| < ∞ is false for ±∞ and NaN: one compare, where `f32::is_finite` works on the bits.
        lanes!(M32x8, |i| bits(self.0[i].abs() < f32::INFINITY))
    }
    #[inline(always)]
    fn is_nan(self) -> M32x8 {
        lanes!(M32x8, |i| bits(self.0[i].is_nan()))
    }
    #[inline(always)]
    fn select(m: M32x8, a: Self, b: Self) -> Self {
        lanes!(F32x8, |i| if m.0[i] != 0 { a.0[i] } else { b.0[i] })
    }
    #[inline(always)]
    fn any(m: M32x8) -> bool {
        let v = m.0;
        (v[0] | v[1] | v[2] | v[3] | v[4] | v[5] | v[6] | v[7]) != 0
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.0[i]
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        lanes!(F32x8, |i| f(i))
    }
    #[inline(always)]
    fn bitmask(m: M32x8) -> u64 {
        let b: [u64; 8] = lanes!(|i| u64::from(m.0[i] != 0) << i);
        b[0] | b[1] | b[2] | b[3] | b[4] | b[5] | b[6] | b[7]
    }
}

/// `[e(0), e(1), e(2)]`, one expression per RGB channel: `channels!(|c| f[c] * s)`. A macro, not a function
/// taking a closure (nor `array::map`): closures carry no `#[inline(always)]`, and one left as a call in a
/// batch loop is compiled without the loop's AVX2 and keeps it from being vectorised (2026-11: seen in
/// callgrind, a third of the instructions of roughconductor's `f`).
macro_rules! channels {
    (|$c:ident| $e:expr) => {
        [
            {
                let $c = 0;
                $e
            },
            {
                let $c = 1;
                $e
            },
            {
                let $c = 2;
                $e
            },
        ]
    };
}
pub(crate) use channels;

/// A direction (or any 3-vector) of lanes: x, y and z each a [`Real`]. The operations are those of
/// [`Vec3`] written out in the order `glam` evaluates them, so `V3<f32>` gives `Vec3`'s results bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3<R> {
    pub x: R,
    pub y: R,
    pub z: R,
}

// Named methods rather than operator traits: `R`'s operators are generic, and the few vector operations
// the kernels need read as well spelt out.
#[allow(clippy::should_implement_trait)]
impl<R: Real> V3<R> {
    #[inline(always)]
    pub fn new(x: R, y: R, z: R) -> Self {
        V3 { x, y, z }
    }

    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        V3::new(R::splat(v.x), R::splat(v.y), R::splat(v.z))
    }

    #[inline(always)]
    #[must_use]
    pub fn dot(self, o: Self) -> R {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    #[must_use]
    pub fn length(self) -> R {
        self.dot(self).sqrt()
    }

    /// `Vec3::normalize`: times the reciprocal of the length.
    #[inline(always)]
    #[must_use]
    pub fn normalize(self) -> Self {
        self.scale(R::splat(1.0) / self.length())
    }

    #[inline(always)]
    #[must_use]
    pub fn scale(self, s: R) -> Self {
        V3::new(self.x * s, self.y * s, self.z * s)
    }

    /// Each component divided by `s` (`Vec3 / f32`).
    #[inline(always)]
    #[must_use]
    pub fn div(self, s: R) -> Self {
        V3::new(self.x / s, self.y / s, self.z / s)
    }

    #[inline(always)]
    #[must_use]
    pub fn add(self, o: Self) -> Self {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }

    #[inline(always)]
    #[must_use]
    pub fn sub(self, o: Self) -> Self {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }

    #[inline(always)]
    #[must_use]
    pub fn neg(self) -> Self {
        V3::new(-self.x, -self.y, -self.z)
    }

    #[inline(always)]
    #[must_use]
    pub fn cross(self, o: Self) -> Self {
        V3::new(self.y * o.z - o.y * self.z, self.z * o.x - o.z * self.x, self.x * o.y - o.x * self.y)
    }

    /// `a` where `m` is set, else `b`, per lane.
    #[inline(always)]
    #[must_use]
    pub fn select(m: R::Mask, a: Self, b: Self) -> Self {
        V3::new(R::select(m, a.x, b.x), R::select(m, a.y, b.y), R::select(m, a.z, b.z))
    }
}

impl From<Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        V3::new(v.x, v.y, v.z)
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

/// Lanes that the batch drivers (`bsdf::lanes`) fill from slices of rows and empty into them, each time
/// exactly [`Real::LANES`] rows (the slices' lengths are checked). Implemented by [`F32x8`] (element by
/// element) and on x86-64 by `avx2::Avx8` and `avx512::Avx16` (shuffles); all move the same numbers.
pub(crate) trait Rows: Real {
    fn load(v: &[f32]) -> Self;
    fn store(self, out: &mut [f32]);
    /// The x, y and z of the rows.
    fn load3(v: &[Vec3]) -> V3<Self>;
    /// The x and y of the rows.
    fn load2(v: &[Vec2]) -> (Self, Self);
    /// Lanes x, y and z as rows of three numbers.
    fn store3(x: Self, y: Self, z: Self, out: &mut [[f32; 3]]);
    /// `v as u32` per lane, for whole numbers in [0, 2³¹) (flag bits).
    fn store_u32(self, out: &mut [u32]);
    fn store_mask(m: Self::Mask, out: &mut [bool]);
}

impl Rows for F32x8 {
    #[inline(always)]
    fn load(v: &[f32]) -> Self {
        F32x8::load(v)
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        out.copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn load3(v: &[Vec3]) -> V3<Self> {
        V3::load(v)
    }
    #[inline(always)]
    fn load2(v: &[Vec2]) -> (Self, Self) {
        F32x8::load2(v)
    }
    #[inline(always)]
    fn store3(x: Self, y: Self, z: Self, out: &mut [[f32; 3]]) {
        let out: &mut [[f32; 3]; 8] = out.try_into().expect("eight rows");
        each_lane!(|l| out[l] = [x.0[l], y.0[l], z.0[l]]);
    }
    #[inline(always)]
    fn store_u32(self, out: &mut [u32]) {
        let out: &mut [u32; 8] = out.try_into().expect("eight numbers");
        each_lane!(|l| out[l] = self.0[l] as u32);
    }
    #[inline(always)]
    fn store_mask(m: M32x8, out: &mut [bool]) {
        let out: &mut [bool; 8] = out.try_into().expect("eight flags");
        each_lane!(|l| out[l] = m.get(l));
    }
}

impl V3<F32x8> {
    /// Eight `Vec3`s (exactly eight) as lanes.
    #[inline(always)]
    #[must_use]
    pub fn load(v: &[Vec3]) -> Self {
        let v: &[Vec3; 8] = v.try_into().expect("eight directions");
        V3::new(lanes!(F32x8, |i| v[i].x), lanes!(F32x8, |i| v[i].y), lanes!(F32x8, |i| v[i].z))
    }

    /// Lane `i` as a `Vec3`.
    #[inline(always)]
    #[must_use]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }
}

impl F32x8 {
    /// Eight numbers (exactly eight).
    #[inline(always)]
    #[must_use]
    pub fn load(v: &[f32]) -> Self {
        let v: &[f32; 8] = v.try_into().expect("eight numbers");
        F32x8(*v)
    }

    /// The x and y of eight `Vec2`s (exactly eight).
    #[inline(always)]
    #[must_use]
    pub fn load2(v: &[Vec2]) -> (Self, Self) {
        let v: &[Vec2; 8] = v.try_into().expect("eight pairs");
        (lanes!(F32x8, |i| v[i].x), lanes!(F32x8, |i| v[i].y))
    }
}

/// The checks every lane type passes (`F32x8` here, `Avx8` and `Avx16` in their modules): each operation
/// is the `f32` operation per lane, bit for bit — NaN, ±0, infinities and subnormals included, `round` at
/// and between halves, `lerp_table` across and beyond its range — and rows move exactly.
#[cfg(test)]
pub(crate) fn check_lane_type<R: Rows>() {
    let n = R::LANES;
    let get = |v: R| {
        let mut o = vec![0.0; n];
        v.store(&mut o);
        o
    };
    const VALUES: [f32; 16] =
        [0.5, -1.5, 0.0, -0.0, f32::INFINITY, f32::NAN, 3.0e-39, 2.5, 2.0, -1.5, -0.0, 0.0, 1.0, 0.5, -7.0, f32::NEG_INFINITY];
    // `pow2` is the power of two at every whole exponent f32 has as a normal number, and `split_exponent`
    // takes positive normal numbers apart into exactly that power and a significand in [1, 2).
    for e in -126..=127 {
        let p: Vec<f32> = (0..n).map(|i| (e - i as i32).max(-126) as f32).collect();
        let got = get(R::load(&p).pow2());
        for i in 0..n {
            assert_eq!(got[i].to_bits(), (2.0f64.powi(p[i] as i32) as f32).to_bits(), "pow2({})", p[i]);
        }
        let x: Vec<f32> = (0..n).map(|i| (2.0f64.powi(e) * (1.0 + i as f64 / n as f64 + 1e-3)) as f32).collect();
        let (m, k) = R::load(&x).split_exponent();
        let (m, k) = (get(m), get(k));
        for i in 0..n {
            assert!((1.0..2.0).contains(&m[i]) && k[i] == e as f32, "split_exponent({}) = ({}, {})", x[i], m[i], k[i]);
            assert_eq!(m[i] as f64 * 2.0f64.powi(e), x[i] as f64, "split_exponent({})", x[i]);
        }
    }
    for shift in 0..16 {
        let a: Vec<f32> = (0..n).map(|i| VALUES[(i + shift) % 16]).collect();
        let b: Vec<f32> = (0..n).map(|i| VALUES[(7 * i + shift + 3) % 16]).collect();
        let (x, y) = (R::load(&a), R::load(&b));
        let same = |v: R, f: &dyn Fn(f32, f32) -> f32, what: &str| {
            let v = get(v);
            for i in 0..n {
                assert_eq!(v[i].to_bits(), f(a[i], b[i]).to_bits(), "{what}({}, {})", a[i], b[i]);
            }
        };
        same(x + y, &|p, q| p + q, "+");
        same(x - y, &|p, q| p - q, "-");
        same(x * y, &|p, q| p * q, "*");
        same(x / y, &|p, q| p / q, "/");
        same(x + 0.25, &|p, _| p + 0.25, "+ f32");
        same(x - 3.0, &|p, _| p - 3.0, "- f32");
        same(x * 1.5, &|p, _| p * 1.5, "* f32");
        same(x / 3.0, &|p, _| p / 3.0, "/ f32");
        same(-x, &|p, _| -p, "neg");
        same(x.abs(), &|p, _| p.abs(), "abs");
        same(x.sqrt(), &|p, _| p.sqrt(), "sqrt");
        same(x.min(y), &Real::min, "min");
        same(x.max(y), &Real::max, "max");
        same(x.clamp(0.0, 1.0), &|p, _| p.clamp(0.0, 1.0), "clamp");
        same(x.mul_add(y, x), &|p, q| p.mul_add(q, p), "mul_add");
        same(x.round(), &|p, _| p.round(), "round");
        same(x.mad(y, x), &|p, q| p.mad(q, p), "mad");
        same(x.xor_sign(y), &|p, q| f32::from_bits(p.to_bits() ^ (q.to_bits() & 0x8000_0000)), "xor_sign");
        same(x.map(|v| v * 2.0 + 1.0), &|p, _| p * 2.0 + 1.0, "map");
        same(R::select(x.lt(y), x, y), &|p, q| if p < q { p } else { q }, "select");
        same(R::from_fn(|i| x.lane(i) - y.lane(i)), &|p, q| p - q, "lane, from_fn");
        let lt = R::bitmask(x.lt(y));
        assert_eq!(lt, (0..n).fold(0u64, |m, i| m | u64::from(a[i] < b[i]) << i), "bitmask");
        let mask = |m: R::Mask, f: &dyn Fn(f32, f32) -> bool, what: &str| {
            let mut o = vec![false; n];
            R::store_mask(m, &mut o);
            for i in 0..n {
                assert_eq!(o[i], f(a[i], b[i]), "{what}({}, {})", a[i], b[i]);
            }
        };
        mask(x.lt(y), &|p, q| p < q, "<");
        mask(x.le(y), &|p, q| p <= q, "<=");
        mask(x.gt(y), &|p, q| p > q, ">");
        mask(x.ge(y), &|p, q| p >= q, ">=");
        mask(x.eq(y), &|p, q| p == q, "==");
        mask(x.ne(y), &|p, q| p != q, "!=");
        mask(x.is_finite(), &|p, _| p.is_finite(), "is_finite");
        mask(x.is_nan(), &|p, _| p.is_nan(), "is_nan");
        mask(!x.lt(y) & x.is_finite() | y.is_nan(), &|p, q| !(p < q) && p.is_finite() || q.is_nan(), "mask logic");
        assert_eq!(R::any(x.is_nan() | y.is_nan()), a.iter().chain(&b).any(|v| v.is_nan()));
        assert!(!R::any(x.is_nan() & x.is_finite()));
    }
    // `round` at and between halves, near 2²³ and beyond.
    let mut xs: Vec<f32> = (-4000..=4000).map(|i| i as f32 / 8.0).collect();
    xs.extend([0.499_999_97, -0.499_999_97, 8_388_607.5, -8_388_607.5, 16_777_217.0, 1e30, -1e-40, 1e-40]);
    // `lerp_table` across and beyond [0, 1], at its nodes.
    let table: [f32; 64] = std::array::from_fn(|k| ((k as f32) * 0.37).sin() + 1.5);
    let mut ts: Vec<f32> = (0..=6400).map(|i| i as f32 / 6400.0).collect();
    ts.extend((0..64).map(|k| k as f32 / 63.0));
    ts.extend([-1.0, -0.0, 1.0, 1.0 + f32::EPSILON, 2.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-30, 0.999_999_9]);
    // And a table of another size (the AVX-512 lanes look a table of 64 up by permutes, others by gathers).
    let short: [f32; 33] = std::array::from_fn(|k| ((k as f32) * 0.61).cos() + 2.5);
    let mut ts_short = ts.clone();
    let round = (&|v: R| v.round()) as &dyn Fn(R) -> R;
    let lookup = (&|v: R| v.lerp_table(&table)) as &dyn Fn(R) -> R;
    let lookup_short = (&|v: R| v.lerp_table(&short)) as &dyn Fn(R) -> R;
    for (xs, lanes, one) in [
        (&mut xs, round, (&|v: f32| v.round()) as &dyn Fn(f32) -> f32),
        (&mut ts, lookup, &|v: f32| v.lerp_table(&table)),
        (&mut ts_short, lookup_short, &|v: f32| v.lerp_table(&short)),
    ] {
        while xs.len() % n != 0 {
            xs.push(0.5);
        }
        for c in xs.chunks_exact(n) {
            let got = get(lanes(R::load(c)));
            for (l, &x) in c.iter().enumerate() {
                assert_eq!(got[l].to_bits(), one(x).to_bits(), "lane {l}: {x}");
            }
        }
    }
    // Rows in and out.
    let v: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f32, -(i as f32) - 0.5, 100.0 + i as f32)).collect();
    let l = R::load3(&v);
    let (x, y, z) = (get(l.x), get(l.y), get(l.z));
    for i in 0..n {
        assert_eq!(Vec3::new(x[i], y[i], z[i]), v[i]);
    }
    let mut back = vec![[0.0; 3]; n];
    R::store3(l.x, l.y, l.z, &mut back);
    assert!(back.iter().zip(&v).all(|(b, w)| *b == w.to_array()));
    let w: Vec<Vec2> = (0..n).map(|i| Vec2::new(i as f32 + 0.25, -(i as f32))).collect();
    let (x, y) = R::load2(&w);
    let (x, y) = (get(x), get(y));
    assert!((0..n).all(|i| Vec2::new(x[i], y[i]) == w[i]));
    let flags: Vec<f32> = (0..n).map(|i| [0.0, 1.0, 5.0, 9.0, 16.0, 31.0, 3.0][i % 7]).collect();
    let mut out = vec![7; n];
    R::load(&flags).store_u32(&mut out);
    assert!(out.iter().zip(&flags).all(|(&o, &f)| o == f as u32));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32x8_is_a_lane_type() {
        check_lane_type::<F32x8>();
    }

    /// `Real::min` and `max` on `f32` are what `f32::min(x, c)` and `max` with a constant `c` (the form the
    /// kernels use) give, ties of ±0 and NaN included.
    #[test]
    fn min_and_max_are_std_with_constants() {
        use std::hint::black_box;
        for x in [-0.0f32, 0.0, 1.0, -1.0, 0.5, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-40] {
            let x = black_box(x);
            for (real, std) in [
                (Real::max(x, 0.0), x.max(0.0)),
                (Real::min(x, 0.0), x.min(0.0)),
                (Real::min(x, 1.0), x.min(1.0)),
                (Real::max(x, -0.0), x.max(-0.0)),
                (Real::min(x, -0.0), x.min(-0.0)),
            ] {
                assert_eq!(real.to_bits(), std.to_bits(), "{x}");
            }
        }
    }
}
