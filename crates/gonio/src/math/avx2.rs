//! Eight lanes in one AVX register: `Avx8`, the [`Real`] that gonio's batch drivers run the kernels on
//! when the CPU has AVX2 and FMA ([`detected`], checked at run time, so one wheel runs everywhere).
//!
//! [`F32x8`](super::lanes::F32x8) writes each operation as a loop over eight `f32`s and leaves it to LLVM's
//! SLP vectoriser to find the vector instructions. That holds for simple kernels but not reliably: a kernel
//! with many steps, or lanes handed to or taken from explicit shuffles, is compiled partly 4-wide, partly
//! scalar, with spills (2026-11, callgrind: roughconductor's `f` went from 54 to 104 instructions per row
//! when its loads became shuffles). Here every operation is its AVX instruction, so the code is what the
//! kernel says, and the moves between rows and lanes are shuffles and gathers:
//!
//! | operation                                  | per eight rows                                     |
//! |--------------------------------------------|----------------------------------------------------|
//! | + − × ÷ √, `mul_add`, compares, `select`   | one instruction                                    |
//! | `min`, `max`, `clamp`, `round`             | two to four                                        |
//! | `Rows::load3`, `Rows::store3`        | 6 loads or 3 stores and 5–9 shuffles (vs 24 scalar moves) |
//! | `Rows::load2`                           | 2 loads, 4 shuffles                                |
//! | [`Real::lerp_table`]                       | 2 gathers and the arithmetic in lanes              |
//!
//! Each operation computes per lane exactly the IEEE operation the `f32` form ([`Real`] for `f32`) does,
//! so a kernel on `Avx8` gives the single calls' results bit for bit (tests below, and
//! `bsdf::tests::batches_equal_single_calls`).
//!
//! It is also the renderer's [`Float8`](super::simd::Float8) in builds that enable AVX2 and FMA at compile
//! time (`-C target-cpu=native` on such a CPU, `x86-64-v3`): one type for both, so that each AVX operation
//! is written once. Its inherent methods are `Float8`'s interface (`load`, `min_or_second`, `bitmask`, …);
//! the renderer's kernels call them where [`Real`] has no such operation.
//!
//! Safety: values of `Avx8` and `Mask8` exist only where the CPU has AVX2 and FMA. In builds that enable
//! both at compile time every CPU the program runs on has them, and the types are public (as `Float8`).
//! In other builds they are crate-private, and values of them exist only inside the batch drivers'
//! `#[target_feature(enable = "avx2,fma")]` functions, which are entered only when [`detected`] says the
//! CPU has those features (`bsdf::lanes`). Their methods use the intrinsics on that basis.

use super::lanes::{Real, Rows, V3};
use super::{Vec2, Vec3};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Whether this CPU has AVX2 and FMA (std caches the answer: a load and a test each).
#[inline(always)]
#[must_use]
pub fn detected() -> bool {
    #[cfg(test)]
    if !super::simd_level::allows(1) {
        return false;
    }
    std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
}

// Public where the build enables AVX2 and FMA (`Avx8` is then `Float8`), else crate-private (module doc).
macro_rules! lane_types {
    ($vis:vis) => {
        /// Eight `f32` lanes in one AVX register (see the module doc).
        #[derive(Clone, Copy, Debug)]
        #[repr(transparent)]
        $vis struct Avx8(__m256);

        /// Eight comparison results: all bits set (true) or clear per lane.
        #[derive(Clone, Copy, Debug)]
        #[repr(transparent)]
        $vis struct Mask8(__m256);
    };
}
#[cfg(all(target_feature = "avx2", target_feature = "fma"))]
lane_types!(pub);
#[cfg(not(all(target_feature = "avx2", target_feature = "fma")))]
lane_types!(pub(crate));

/// `_MM_SHUFFLE(z, y, x, w)`: the elements of the first, first, second and second operand that go to each
/// place of a 128-bit half.
const fn order(z: i32, y: i32, x: i32, w: i32) -> i32 {
    (z << 6) | (y << 4) | (x << 2) | w
}

/// `$e` with the intrinsics in scope; see the module doc for why they may run.
macro_rules! avx {
    ($e:expr) => {
        // SAFETY: `Avx8` and `Mask8` values exist only after `detected()` (module doc).
        unsafe { $e }
    };
}

/// `Float8`'s interface (see the module doc): operations [`Real`] does not have, and [`Real`]'s own as
/// inherent methods, which the renderer's kernels call without importing the trait.
impl Avx8 {
    /// The lanes as an array.
    ///
    /// Where `Avx8` is the renderer's `Float8`, the value passes through an empty `asm` statement first, so
    /// that LLVM cannot see where it came from. Otherwise it turns `store(select(m, x, load(p)), p)` —
    /// updating some lanes of a row in memory, as the path tracer's packets do all the time — into a masked
    /// store (`vmaskmovps`), which AMD's Zen 3 runs far slower than a plain store. 2026-12: the 47 masked
    /// stores in `path::radiance` and the instructions right after them held 12 % (Cornell box) and 17 %
    /// (material spheres) of the profile's samples; without them renders took 0.92 × the time, with the
    /// same images.
    #[inline(always)]
    #[must_use]
    pub fn to_array(self) -> [f32; 8] {
        let mut a = [0.0; 8];
        #[allow(unused_mut)]
        let mut v = self.0;
        // SAFETY: an empty asm statement: it reads and writes only the register holding v.
        #[cfg(all(target_feature = "avx2", target_feature = "fma"))]
        unsafe {
            std::arch::asm!("/* {0} */", inout(ymm_reg) v, options(pure, nomem, nostack, preserves_flags));
        }
        avx!(_mm256_storeu_ps(a.as_mut_ptr(), v));
        a
    }

    /// Lanes from eight numbers in registers (`vinsertps` and the like: see [`crate::math::simd`] on
    /// store-to-load forwarding).
    #[cfg_attr(not(all(target_feature = "avx2", target_feature = "fma")), allow(dead_code))]
    #[inline(always)]
    #[must_use]
    pub fn new(a: [f32; 8]) -> Self {
        Avx8(avx!(_mm256_setr_ps(a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7])))
    }

    /// The lanes of an AVX register.
    #[cfg_attr(not(all(target_feature = "avx2", target_feature = "fma")), allow(dead_code))]
    #[inline(always)]
    #[must_use]
    pub(crate) fn from_m256(v: __m256) -> Self {
        Avx8(v)
    }

    /// Lanes from an array.
    #[inline(always)]
    #[must_use]
    pub fn load(a: &[f32; 8]) -> Self {
        Avx8(avx!(_mm256_loadu_ps(a.as_ptr())))
    }

    /// Every lane `v`.
    #[inline(always)]
    #[must_use]
    pub fn splat(v: f32) -> Self {
        Avx8(avx!(_mm256_set1_ps(v)))
    }

    #[inline(always)]
    #[must_use]
    pub fn sqrt(self) -> Self {
        Avx8(avx!(_mm256_sqrt_ps(self.0)))
    }

    #[inline(always)]
    #[must_use]
    pub fn abs(self) -> Self {
        Avx8(avx!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)))
    }

    /// x86's `minps`: `self < o ? self : o` (the second operand where either is NaN), one instruction.
    #[inline(always)]
    #[must_use]
    pub fn min_or_second(self, o: Self) -> Self {
        Avx8(avx!(_mm256_min_ps(self.0, o.0)))
    }

    /// x86's `maxps`: `self > o ? self : o` (the second operand where either is NaN).
    #[inline(always)]
    #[must_use]
    pub fn max_or_second(self, o: Self) -> Self {
        Avx8(avx!(_mm256_max_ps(self.0, o.0)))
    }

    /// Lane `i` is lane `idx[i]` of `self`, for whole numbers `idx` in 0..8 (a lookup in a table of eight:
    /// one `vpermps`). The renderer's; the batch kernels have no use for it.
    #[cfg_attr(not(all(target_feature = "avx2", target_feature = "fma")), allow(dead_code))]
    #[inline(always)]
    #[must_use]
    pub fn permute(self, idx: Self) -> Self {
        Avx8(avx!(_mm256_permutevar8x32_ps(self.0, _mm256_cvttps_epi32(idx.0))))
    }

    /// The smallest lane: three shuffles and three `vminps` (as `min_or_second` across the lanes: a NaN
    /// lane may or may not win). The renderer's; the batch kernels have no use for it.
    #[cfg_attr(not(all(target_feature = "avx2", target_feature = "fma")), allow(dead_code))]
    #[inline(always)]
    #[must_use]
    pub fn min_lane(self) -> f32 {
        avx!({
            let m = _mm256_min_ps(self.0, _mm256_permute2f128_ps::<1>(self.0, self.0));
            let m = _mm256_min_ps(m, _mm256_permute_ps::<0b0100_1110>(m));
            _mm256_cvtss_f32(_mm256_min_ps(m, _mm256_permute_ps::<0b1011_0001>(m)))
        })
    }

    /// Towards zero (`f32::trunc`).
    #[inline(always)]
    #[must_use]
    pub fn trunc(self) -> Self {
        Avx8(avx!(_mm256_round_ps::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(self.0)))
    }

    /// The bits of `self` with the sign bit of `o` flipped into them (`self ^ (o & sign)`).
    #[inline(always)]
    #[must_use]
    pub fn xor_sign(self, o: Self) -> Self {
        Avx8(avx!(_mm256_xor_ps(self.0, _mm256_and_ps(o.0, _mm256_set1_ps(-0.0)))))
    }

    /// `a` where `m` is set, else `b`.
    #[inline(always)]
    #[must_use]
    pub fn select(m: Mask8, a: Self, b: Self) -> Self {
        Avx8(avx!(_mm256_blendv_ps(b.0, a.0, m.0)))
    }

    #[inline(always)]
    fn compare<const PREDICATE: i32>(self, o: Avx8) -> Mask8 {
        Mask8(avx!(_mm256_cmp_ps::<PREDICATE>(self.0, o.0)))
    }

    #[inline(always)]
    #[must_use]
    pub fn lt(self, o: Self) -> Mask8 {
        self.compare::<_CMP_LT_OQ>(o)
    }
    #[inline(always)]
    #[must_use]
    pub fn le(self, o: Self) -> Mask8 {
        self.compare::<_CMP_LE_OQ>(o)
    }
    #[inline(always)]
    #[must_use]
    pub fn gt(self, o: Self) -> Mask8 {
        self.compare::<_CMP_GT_OQ>(o)
    }
    #[inline(always)]
    #[must_use]
    pub fn ge(self, o: Self) -> Mask8 {
        self.compare::<_CMP_GE_OQ>(o)
    }
    #[inline(always)]
    #[must_use]
    pub fn eq(self, o: Self) -> Mask8 {
        self.compare::<_CMP_EQ_OQ>(o)
    }
    /// True where either is NaN, as `!=`.
    #[inline(always)]
    #[must_use]
    pub fn ne(self, o: Self) -> Mask8 {
        self.compare::<_CMP_NEQ_UQ>(o)
    }
    /// True where either is NaN.
    #[inline(always)]
    #[must_use]
    pub fn unordered(self, o: Self) -> Mask8 {
        self.compare::<_CMP_UNORD_Q>(o)
    }
}

// `from_bitmask` is for the renderer, which uses these types only where they are `Float8`.
#[cfg_attr(not(all(target_feature = "avx2", target_feature = "fma")), allow(dead_code))]
impl Mask8 {
    /// Bit `i` set where lane `i` is.
    #[inline(always)]
    #[must_use]
    pub fn bitmask(self) -> u32 {
        avx!(_mm256_movemask_ps(self.0)) as u32
    }

    /// Lane `i` set where bit `i` of `bits` is.
    #[inline(always)]
    #[must_use]
    pub fn from_bitmask(bits: u32) -> Self {
        avx!({
            let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let b = _mm256_and_si256(_mm256_set1_epi32(bits as i32), lane_bits);
            Mask8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(b, lane_bits)))
        })
    }
}

macro_rules! binary {
    ($($tr:ident $f:ident $intrinsic:ident),*) => {$(
        impl $tr for Avx8 {
            type Output = Avx8;
            #[inline(always)]
            fn $f(self, o: Avx8) -> Avx8 { Avx8(avx!($intrinsic(self.0, o.0))) }
        }
        impl $tr<f32> for Avx8 {
            type Output = Avx8;
            #[inline(always)]
            fn $f(self, o: f32) -> Avx8 { Avx8(avx!($intrinsic(self.0, _mm256_set1_ps(o)))) }
        }
    )*};
}
binary!(Add add _mm256_add_ps, Sub sub _mm256_sub_ps, Mul mul _mm256_mul_ps, Div div _mm256_div_ps);

impl Neg for Avx8 {
    type Output = Avx8;
    /// Flips the sign bit, as `-x` does.
    #[inline(always)]
    fn neg(self) -> Avx8 {
        Avx8(avx!(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))))
    }
}

impl BitAnd for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn bitand(self, o: Mask8) -> Mask8 {
        Mask8(avx!(_mm256_and_ps(self.0, o.0)))
    }
}

impl BitOr for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn bitor(self, o: Mask8) -> Mask8 {
        Mask8(avx!(_mm256_or_ps(self.0, o.0)))
    }
}

impl Not for Mask8 {
    type Output = Mask8;
    #[inline(always)]
    fn not(self) -> Mask8 {
        Mask8(avx!(_mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))))
    }
}

impl Real for Avx8 {
    type Mask = Mask8;
    const LANES: usize = 8;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        Avx8::splat(v)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Avx8::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Avx8::abs(self)
    }
    #[inline(always)]
    fn xor_sign(self, o: Self) -> Self {
        Avx8::xor_sign(self, o)
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        let n = avx!(_mm256_add_epi32(_mm256_cvttps_epi32(self.0), _mm256_set1_epi32(127)));
        Avx8(avx!(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(n))))
    }
    #[inline(always)]
    fn split_exponent(self) -> (Self, Self) {
        let bits = avx!(_mm256_castps_si256(self.0));
        let m = avx!(_mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi32(0x007f_ffff)), _mm256_set1_epi32(0x3f80_0000)));
        let e = avx!(_mm256_sub_epi32(_mm256_srli_epi32::<23>(bits), _mm256_set1_epi32(127)));
        (Avx8(avx!(_mm256_castsi256_ps(m))), Avx8(avx!(_mm256_cvtepi32_ps(e))))
    }
    /// `minps(self, o)` is self < o ? self : o, the `f32` form's result but where `o` is NaN.
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Avx8::select(o.is_nan(), self, self.min_or_second(o))
    }
    /// As [`Self::min`], with self > o.
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Avx8::select(o.is_nan(), self, self.max_or_second(o))
    }
    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        let (lo, hi) = (Avx8::splat(lo), Avx8::splat(hi));
        let x = Avx8::select(self.lt(lo), lo, self);
        Avx8::select(x.gt(hi), hi, x)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Avx8(avx!(_mm256_fmadd_ps(self.0, a.0, b.0)))
    }
    /// Halves away from zero: the integer part t (exact), and one more in magnitude where the rest
    /// x − t (exact) is at least one half. ±∞ and NaN stay (their rest is NaN).
    #[inline(always)]
    fn round(self) -> Self {
        let t = self.trunc();
        Avx8::select((self - t).abs().ge(Avx8::splat(0.5)), t + Avx8::splat(1.0).xor_sign(self), t)
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        Avx8::load(&self.to_array().map(f))
    }
    /// The index arithmetic and the interpolation in lanes, the two table entries of each lane by gathers:
    /// per lane the operations of the `f32` form.
    #[inline(always)]
    fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self {
        const { assert!(N >= 2 && N < (1 << 24)) };
        let x = self.clamp(0.0, 1.0) * (N - 1) as f32;
        let (k, below, above) = avx!({
            // `x as usize` truncates; NaN (the only value outside [0, N − 1] here) converts to i32::MIN,
            // which the clamp turns into 0, as `as usize` does. With k ≤ N − 2 both gathers stay within
            // the table.
            let k = _mm256_cvttps_epi32(x.0);
            let k = _mm256_min_epi32(_mm256_max_epi32(k, _mm256_setzero_si256()), _mm256_set1_epi32(N as i32 - 2));
            let p = table.as_ptr();
            (Avx8(_mm256_cvtepi32_ps(k)), Avx8(_mm256_i32gather_ps::<4>(p, k)), Avx8(_mm256_i32gather_ps::<4>(p.add(1), k)))
        });
        let t = x - k;
        (Avx8::splat(1.0) - t) * below + t * above
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Mask8 {
        Avx8::lt(self, o)
    }
    #[inline(always)]
    fn le(self, o: Self) -> Mask8 {
        Avx8::le(self, o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Mask8 {
        Avx8::gt(self, o)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Mask8 {
        Avx8::ge(self, o)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Mask8 {
        Avx8::eq(self, o)
    }
    /// True where either is NaN, as `!=`.
    #[inline(always)]
    fn ne(self, o: Self) -> Mask8 {
        Avx8::ne(self, o)
    }
    #[inline(always)]
    fn is_finite(self) -> Mask8 {
        self.abs().lt(Avx8::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn is_nan(self) -> Mask8 {
        self.unordered(self)
    }
    #[inline(always)]
    fn select(m: Mask8, a: Self, b: Self) -> Self {
        Avx8::select(m, a, b)
    }
    #[inline(always)]
    fn any(m: Mask8) -> bool {
        m.bitmask() != 0
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        Avx8::load(&std::array::from_fn(f))
    }
    #[inline(always)]
    fn bitmask(m: Mask8) -> u64 {
        u64::from(m.bitmask())
    }
}

impl Rows for Avx8 {
    #[inline(always)]
    fn load(v: &[f32]) -> Self {
        let v: &[f32; 8] = v.try_into().expect("eight numbers");
        Avx8(avx!(_mm256_loadu_ps(v.as_ptr())))
    }

    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        let out: &mut [f32; 8] = out.try_into().expect("eight numbers");
        avx!(_mm256_storeu_ps(out.as_mut_ptr(), self.0));
    }

    /// Rows 0–3 fill the low halves of three registers, rows 4–7 the high halves: m03 = x0 y0 z0 x1,
    /// m14 = y1 z1 x2 y2, m25 = z2 x3 y3 z3; five shuffles sort them into x, y and z.
    #[inline(always)]
    fn load3(v: &[Vec3]) -> V3<Self> {
        let v: &[Vec3; 8] = v.try_into().expect("eight directions");
        // `Vec3` is `#[repr(C)]` of three `f32`s (size 12, alignment 4): eight are 24 floats.
        let p = v.as_ptr().cast::<f32>();
        avx!({
            let half = |k: usize| _mm_loadu_ps(p.add(k));
            let m03 = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(half(0)), half(12));
            let m14 = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(half(4)), half(16));
            let m25 = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(half(8)), half(20));
            let xy = _mm256_shuffle_ps::<{ order(2, 1, 3, 2) }>(m14, m25); // x2 y2 x3 y3
            let yz = _mm256_shuffle_ps::<{ order(1, 0, 2, 1) }>(m03, m14); // y0 z0 y1 z1
            V3::new(
                Avx8(_mm256_shuffle_ps::<{ order(2, 0, 3, 0) }>(m03, xy)),
                Avx8(_mm256_shuffle_ps::<{ order(3, 1, 2, 0) }>(yz, xy)),
                Avx8(_mm256_shuffle_ps::<{ order(3, 0, 3, 1) }>(yz, m25)),
            )
        })
    }

    #[inline(always)]
    fn load2(v: &[Vec2]) -> (Self, Self) {
        let v: &[Vec2; 8] = v.try_into().expect("eight pairs");
        // `Vec2` is `#[repr(C)]` of two `f32`s (size 8, alignment 4): eight are 16 floats.
        let p = v.as_ptr().cast::<f32>();
        avx!({
            let (r03, r47) = (_mm256_loadu_ps(p), _mm256_loadu_ps(p.add(8)));
            let a = _mm256_permute2f128_ps::<0x20>(r03, r47); // rows 0, 1 | 4, 5
            let b = _mm256_permute2f128_ps::<0x31>(r03, r47); // rows 2, 3 | 6, 7
            (Avx8(_mm256_shuffle_ps::<{ order(2, 0, 2, 0) }>(a, b)), Avx8(_mm256_shuffle_ps::<{ order(3, 1, 3, 1) }>(a, b)))
        })
    }

    /// The inverse of [`Self::load3`]: six shuffles into m03, m14, m25 (see there), three permutes into
    /// memory order.
    #[inline(always)]
    fn store3(x: Self, y: Self, z: Self, out: &mut [[f32; 3]]) {
        let out: &mut [[f32; 3]; 8] = out.try_into().expect("eight rows");
        let p = out.as_mut_ptr().cast::<f32>();
        avx!({
            let (x, y, z) = (x.0, y.0, z.0);
            let xy = _mm256_shuffle_ps::<{ order(2, 0, 2, 0) }>(x, y); // x0 x2 y0 y2
            let yz = _mm256_shuffle_ps::<{ order(3, 1, 3, 1) }>(y, z); // y1 y3 z1 z3
            let zx = _mm256_shuffle_ps::<{ order(3, 1, 2, 0) }>(z, x); // z0 z2 x1 x3
            let m03 = _mm256_shuffle_ps::<{ order(2, 0, 2, 0) }>(xy, zx); // x0 y0 z0 x1
            let m14 = _mm256_shuffle_ps::<{ order(3, 1, 2, 0) }>(yz, xy); // y1 z1 x2 y2
            let m25 = _mm256_shuffle_ps::<{ order(3, 1, 3, 1) }>(zx, yz); // z2 x3 y3 z3
            _mm256_storeu_ps(p, _mm256_permute2f128_ps::<0x20>(m03, m14));
            _mm256_storeu_ps(p.add(8), _mm256_permute2f128_ps::<0x30>(m25, m03));
            _mm256_storeu_ps(p.add(16), _mm256_permute2f128_ps::<0x31>(m14, m25));
        });
    }

    /// Lanes holding whole numbers in [0, 2³¹) (flag bits; checked in debug builds) as `u32`: `v as u32`.
    #[inline(always)]
    fn store_u32(self, out: &mut [u32]) {
        debug_assert!(self.to_array().iter().all(|&x| x == x.trunc() && (0.0..2_147_483_648.0).contains(&x)));
        let out: &mut [u32; 8] = out.try_into().expect("eight numbers");
        avx!(_mm256_storeu_si256(out.as_mut_ptr().cast(), _mm256_cvttps_epi32(self.0)));
    }

    /// Each lane's 0 or −1 (as `i32`) packed to a byte and masked to the `bool` 0 or 1.
    #[inline(always)]
    fn store_mask(m: Mask8, out: &mut [bool]) {
        let out: &mut [bool; 8] = out.try_into().expect("eight flags");
        avx!({
            let m = _mm256_castps_si256(m.0);
            let words = _mm_packs_epi32(_mm256_castsi256_si128(m), _mm256_extracti128_si256::<1>(m));
            let bytes = _mm_and_si128(_mm_packs_epi16(words, words), _mm_set1_epi8(1));
            _mm_storel_epi64(out.as_mut_ptr().cast(), bytes);
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane-type checks of `math::lanes` (every operation the `f32` one, bit for bit; rows move
    /// exactly), run with AVX2 and FMA enabled, on CPUs that have them.
    #[test]
    fn avx8_is_a_lane_type() {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn run() {
            crate::math::lanes::check_lane_type::<Avx8>();
        }
        if detected() {
            // SAFETY: the CPU has the features.
            unsafe { run() }
        }
    }
}
