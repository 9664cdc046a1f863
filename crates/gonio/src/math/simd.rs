//! Eight `f32` lanes in machine registers ([`Float8`]), for the renderer's kernels: the 8-wide BVH node
//! test, the eight-primitive packet tests, and the path tracer that runs eight paths at once. Where
//! every instruction counts, the loops of [`F32x8`](super::lanes::F32x8) are not reliably vectorised
//! (2026-11: in the traversal kernels LLVM's SLP vectoriser left a mix of scalar, 128-bit and 256-bit
//! instructions, and the BVH took more instructions per ray than its 4-wide predecessor).
//!
//! | build                                   | [`Float8`] is                         | one operation is          |
//! |-----------------------------------------|---------------------------------------|---------------------------|
//! | x86-64 with AVX2 and FMA (`-C target-cpu=native` on such a CPU, `x86-64-v3`) | one `__m256`: `math::avx2`'s `Avx8`, the batch kernels' lane type | one instruction |
//! | x86-64 without them (the portable build) | two `__m128` (SSE2, always present)  | two instructions          |
//! | other targets                           | `[f32; 8]`                            | a loop over the lanes     |
//!
//! Every operation is the IEEE `f32` operation per lane, so the three give the same results bit for bit,
//! and [`Float8`] implements [`Real`](super::lanes::Real) with `f32`'s semantics (NaN handling of `min`/`max` included): a
//! formula written over `Real` computes in each lane what it computes on one `f32`. Besides, the kernels
//! use `min_or_second` and `max_or_second`, with the semantics of x86's `minps` / `maxps` (the second
//! operand where either is NaN), one instruction where `f32::min` needs three.
//!
//! Store-to-load forwarding: a load of all eight lanes right after stores of single lanes to the same
//! place cannot take its value from those stores (they are narrower) and waits until they have left the
//! store buffer. Kernels that fill lanes one at a time therefore build the register instead:
//! [`Float8::with_lane`] (a blend), or [`Float8::new`] from numbers already in registers (2026-12: the
//! packet leaf tests' distances and `Pcg32x8::next_f32`, the material spheres about 4 % faster).

// The x86 intrinsics are `unsafe fn` before Rust 1.87 (gonio's MSRV is 1.80) and safe afterwards where
// the feature is enabled, as SSE2 always is on x86-64 and AVX is in the builds that select it: the
// `unsafe` blocks around them are needed by old compilers and redundant for new ones.
#![allow(unused_unsafe)]

/// With AVX2 and FMA enabled at compile time `Float8` is the batch kernels' `Avx8` (one AVX register,
/// each operation its instruction), written once in `math::avx2`.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2", target_feature = "fma"))]
mod imp {
    pub use crate::math::avx2::{Avx8 as Float8, Mask8};
}

#[cfg(all(target_arch = "x86_64", not(all(target_feature = "avx2", target_feature = "fma"))))]
// `add`, `neg`, `not`, …: each backend's operations, which the operator traits (below, once for all
// three) call.
#[allow(clippy::should_implement_trait)]
mod imp {
    use std::arch::x86_64::*;

    /// Eight lanes in two SSE registers (lanes 0–3, 4–7).
    #[derive(Clone, Copy, Debug)]
    pub struct Float8(pub(super) __m128, pub(super) __m128);

    /// Eight comparison results (all bits set per true lane).
    #[derive(Clone, Copy, Debug)]
    pub struct Mask8(pub(super) __m128, pub(super) __m128);

    macro_rules! both {
        ($t:ident, $f:ident, $a:expr, $b:expr) => {
            $t(unsafe { $f($a.0, $b.0) }, unsafe { $f($a.1, $b.1) })
        };
    }

    macro_rules! cmp {
        ($name:ident, $f:ident) => {
            #[inline(always)]
            pub fn $name(self, o: Self) -> Mask8 {
                both!(Mask8, $f, self, o)
            }
        };
    }

    /// `a` where the mask is set, else `b` (SSE2 has no blend).
    #[inline(always)]
    fn blend(m: __m128, a: __m128, b: __m128) -> __m128 {
        unsafe { _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)) }
    }

    /// Towards zero: through integers below 2²³ (larger floats are integers already), sign kept.
    #[inline(always)]
    fn trunc4(x: __m128) -> __m128 {
        unsafe {
            let sign = _mm_set1_ps(-0.0);
            let ax = _mm_andnot_ps(sign, x);
            let small = _mm_cmplt_ps(ax, _mm_set1_ps(8_388_608.0));
            let t = _mm_cvtepi32_ps(_mm_cvttps_epi32(ax));
            _mm_or_ps(blend(small, t, ax), _mm_and_ps(x, sign))
        }
    }

    impl Float8 {
        #[inline(always)]
        pub fn splat(v: f32) -> Self {
            let x = unsafe { _mm_set1_ps(v) };
            Float8(x, x)
        }
        #[inline(always)]
        pub fn load(a: &[f32; 8]) -> Self {
            // SAFETY: `a` holds eight floats (two groups of four); the loads have no alignment requirement.
            unsafe { Float8(_mm_loadu_ps(a.as_ptr()), _mm_loadu_ps(a.as_ptr().add(4))) }
        }
        /// Lanes from eight numbers in registers.
        #[inline(always)]
        pub fn new(a: [f32; 8]) -> Self {
            // SAFETY: SSE, which x86-64 always has.
            unsafe { Float8(_mm_setr_ps(a[0], a[1], a[2], a[3]), _mm_setr_ps(a[4], a[5], a[6], a[7])) }
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 8] {
            let mut a = [0.0f32; 8];
            // SAFETY: `a` has room for eight floats; the stores have no alignment requirement.
            unsafe {
                _mm_storeu_ps(a.as_mut_ptr(), self.0);
                _mm_storeu_ps(a.as_mut_ptr().add(4), self.1);
            }
            a
        }
        #[inline(always)]
        pub fn add(self, o: Self) -> Self {
            both!(Float8, _mm_add_ps, self, o)
        }
        #[inline(always)]
        pub fn sub(self, o: Self) -> Self {
            both!(Float8, _mm_sub_ps, self, o)
        }
        #[inline(always)]
        pub fn mul(self, o: Self) -> Self {
            both!(Float8, _mm_mul_ps, self, o)
        }
        #[inline(always)]
        pub fn div(self, o: Self) -> Self {
            both!(Float8, _mm_div_ps, self, o)
        }
        #[inline(always)]
        pub fn sqrt(self) -> Self {
            unsafe { Float8(_mm_sqrt_ps(self.0), _mm_sqrt_ps(self.1)) }
        }
        #[inline(always)]
        pub fn min_or_second(self, o: Self) -> Self {
            both!(Float8, _mm_min_ps, self, o)
        }
        #[inline(always)]
        pub fn max_or_second(self, o: Self) -> Self {
            both!(Float8, _mm_max_ps, self, o)
        }
        /// Towards zero (`f32::trunc`).
        #[inline(always)]
        pub fn trunc(self) -> Self {
            Float8(trunc4(self.0), trunc4(self.1))
        }
        /// `f32::mul_add` per lane (the exact fused operation, in software where the build has no FMA).
        #[inline(always)]
        pub fn mul_add(self, a: Self, b: Self) -> Self {
            let (x, y, z) = (self.to_array(), a.to_array(), b.to_array());
            Float8::load(&std::array::from_fn(|i| x[i].mul_add(y[i], z[i])))
        }
        /// The bits of `self` where `m` is set, zero elsewhere.
        #[inline(always)]
        pub fn and_mask(self, m: Mask8) -> Self {
            both!(Float8, _mm_and_ps, self, m)
        }
        /// `a` where `m` is set, else `b`.
        #[inline(always)]
        pub fn select(m: Mask8, a: Self, b: Self) -> Self {
            Float8(blend(m.0, a.0, b.0), blend(m.1, a.1, b.1))
        }
        /// The bits of `self` with the sign bit of `o` flipped into them (`self ^ (o & sign)`).
        #[inline(always)]
        pub fn xor_sign(self, o: Self) -> Self {
            let sign = Float8::splat(-0.0);
            let s = both!(Float8, _mm_and_ps, o, sign);
            both!(Float8, _mm_xor_ps, self, s)
        }
        /// 2ⁿ for whole numbers n ∈ [−126, 127] (`Real::pow2`).
        #[inline(always)]
        pub fn pow2(self) -> Self {
            // SAFETY: SSE2 is part of x86_64.
            let half =
                |x: __m128| unsafe { _mm_castsi128_ps(_mm_slli_epi32::<23>(_mm_add_epi32(_mm_cvttps_epi32(x), _mm_set1_epi32(127)))) };
            Float8(half(self.0), half(self.1))
        }
        /// (m, e) with self = m · 2ᵉ, m ∈ [1, 2), for positive normal numbers (`Real::split_exponent`).
        #[inline(always)]
        pub fn split_exponent(self) -> (Self, Self) {
            // SAFETY: SSE2 is part of x86_64.
            let half = |x: __m128| unsafe {
                let bits = _mm_castps_si128(x);
                let m = _mm_or_si128(_mm_and_si128(bits, _mm_set1_epi32(0x007f_ffff)), _mm_set1_epi32(0x3f80_0000));
                (_mm_castsi128_ps(m), _mm_cvtepi32_ps(_mm_sub_epi32(_mm_srli_epi32::<23>(bits), _mm_set1_epi32(127))))
            };
            let (a, b) = (half(self.0), half(self.1));
            (Float8(a.0, b.0), Float8(a.1, b.1))
        }
        #[inline(always)]
        pub fn abs(self) -> Self {
            let sign = Float8::splat(-0.0);
            both!(Float8, _mm_andnot_ps, sign, self)
        }
        #[inline(always)]
        pub fn neg(self) -> Self {
            let sign = Float8::splat(-0.0);
            both!(Float8, _mm_xor_ps, self, sign)
        }
        cmp!(lt, _mm_cmplt_ps);
        cmp!(le, _mm_cmple_ps);
        cmp!(gt, _mm_cmpgt_ps);
        cmp!(ge, _mm_cmpge_ps);
        cmp!(eq, _mm_cmpeq_ps);
        // `!=`: true where either is NaN, as for `f32`.
        cmp!(ne, _mm_cmpneq_ps);
        // Either is NaN.
        cmp!(unordered, _mm_cmpunord_ps);
    }

    impl Mask8 {
        #[inline(always)]
        pub fn and(self, o: Self) -> Self {
            both!(Mask8, _mm_and_ps, self, o)
        }
        #[inline(always)]
        pub fn or(self, o: Self) -> Self {
            both!(Mask8, _mm_or_ps, self, o)
        }
        #[inline(always)]
        pub fn not(self) -> Self {
            let ones = unsafe { _mm_castsi128_ps(_mm_set1_epi32(-1)) };
            unsafe { Mask8(_mm_xor_ps(self.0, ones), _mm_xor_ps(self.1, ones)) }
        }
        #[inline(always)]
        pub fn bitmask(self) -> u32 {
            unsafe { (_mm_movemask_ps(self.0) | (_mm_movemask_ps(self.1) << 4)) as u32 }
        }
        /// Lane `i` set where bit `i` of `bits` is.
        #[inline(always)]
        pub fn from_bitmask(bits: u32) -> Self {
            unsafe {
                let (lo, hi) = (_mm_setr_epi32(1, 2, 4, 8), _mm_setr_epi32(16, 32, 64, 128));
                let b = _mm_set1_epi32(bits as i32);
                Mask8(
                    _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, lo), lo)),
                    _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(b, hi), hi)),
                )
            }
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
// `add`, `neg`, `not`, …: each backend's operations, which the operator traits (below, once for all
// three) call.
#[allow(clippy::should_implement_trait)]
mod imp {
    /// Eight lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct Float8(pub(super) [f32; 8]);

    /// Eight comparison results.
    #[derive(Clone, Copy, Debug)]
    pub struct Mask8(pub(super) [bool; 8]);

    macro_rules! each {
        ($t:ident, |$i:ident| $e:expr) => {{
            let mut r = $t([Default::default(); 8]);
            for $i in 0..8 {
                r.0[$i] = $e;
            }
            r
        }};
    }

    macro_rules! cmp {
        ($name:ident, $op:tt) => {
            #[inline(always)]
            pub fn $name(self, o: Self) -> Mask8 {
                each!(Mask8, |i| self.0[i] $op o.0[i])
            }
        };
    }

    impl Float8 {
        #[inline(always)]
        pub fn splat(v: f32) -> Self {
            Float8([v; 8])
        }
        #[inline(always)]
        pub fn load(a: &[f32; 8]) -> Self {
            Float8(*a)
        }
        /// Lanes from eight numbers.
        #[inline(always)]
        pub fn new(a: [f32; 8]) -> Self {
            Float8(a)
        }
        #[inline(always)]
        pub fn to_array(self) -> [f32; 8] {
            self.0
        }
        #[inline(always)]
        pub fn add(self, o: Self) -> Self {
            each!(Float8, |i| self.0[i] + o.0[i])
        }
        #[inline(always)]
        pub fn sub(self, o: Self) -> Self {
            each!(Float8, |i| self.0[i] - o.0[i])
        }
        #[inline(always)]
        pub fn mul(self, o: Self) -> Self {
            each!(Float8, |i| self.0[i] * o.0[i])
        }
        #[inline(always)]
        pub fn div(self, o: Self) -> Self {
            each!(Float8, |i| self.0[i] / o.0[i])
        }
        #[inline(always)]
        pub fn sqrt(self) -> Self {
            each!(Float8, |i| self.0[i].sqrt())
        }
        #[inline(always)]
        pub fn min_or_second(self, o: Self) -> Self {
            each!(Float8, |i| if self.0[i] < o.0[i] { self.0[i] } else { o.0[i] })
        }
        #[inline(always)]
        pub fn max_or_second(self, o: Self) -> Self {
            each!(Float8, |i| if self.0[i] > o.0[i] { self.0[i] } else { o.0[i] })
        }
        #[inline(always)]
        pub fn trunc(self) -> Self {
            each!(Float8, |i| self.0[i].trunc())
        }
        #[inline(always)]
        pub fn mul_add(self, a: Self, b: Self) -> Self {
            each!(Float8, |i| self.0[i].mul_add(a.0[i], b.0[i]))
        }
        #[inline(always)]
        pub fn and_mask(self, m: Mask8) -> Self {
            each!(Float8, |i| if m.0[i] { self.0[i] } else { 0.0 })
        }
        #[inline(always)]
        pub fn select(m: Mask8, a: Self, b: Self) -> Self {
            each!(Float8, |i| if m.0[i] { a.0[i] } else { b.0[i] })
        }
        #[inline(always)]
        pub fn xor_sign(self, o: Self) -> Self {
            each!(Float8, |i| f32::from_bits(self.0[i].to_bits() ^ (o.0[i].to_bits() & 0x8000_0000)))
        }
        #[inline(always)]
        pub fn pow2(self) -> Self {
            each!(Float8, |i| crate::math::lanes::Real::pow2(self.0[i]))
        }
        #[inline(always)]
        pub fn split_exponent(self) -> (Self, Self) {
            use crate::math::lanes::Real;
            (each!(Float8, |i| self.0[i].split_exponent().0), each!(Float8, |i| self.0[i].split_exponent().1))
        }
        #[inline(always)]
        pub fn abs(self) -> Self {
            each!(Float8, |i| self.0[i].abs())
        }
        #[inline(always)]
        pub fn neg(self) -> Self {
            each!(Float8, |i| -self.0[i])
        }
        cmp!(lt, <);
        cmp!(le, <=);
        cmp!(gt, >);
        cmp!(ge, >=);
        cmp!(eq, ==);
        cmp!(ne, !=);
        #[inline(always)]
        pub fn unordered(self, o: Self) -> Mask8 {
            each!(Mask8, |i| self.0[i].is_nan() || o.0[i].is_nan())
        }
    }

    impl Mask8 {
        #[inline(always)]
        pub fn and(self, o: Self) -> Self {
            each!(Mask8, |i| self.0[i] & o.0[i])
        }
        #[inline(always)]
        pub fn or(self, o: Self) -> Self {
            each!(Mask8, |i| self.0[i] | o.0[i])
        }
        #[inline(always)]
        pub fn not(self) -> Self {
            each!(Mask8, |i| !self.0[i])
        }
        #[inline(always)]
        pub fn bitmask(self) -> u32 {
            (0..8).fold(0, |m, i| m | (u32::from(self.0[i]) << i))
        }
        #[inline(always)]
        pub fn from_bitmask(bits: u32) -> Self {
            each!(Mask8, |i| bits >> i & 1 == 1)
        }
    }
}

pub use imp::{Float8, Mask8};

impl Float8 {
    /// Lane `i` of `f(i)`.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        Float8::load(&std::array::from_fn(f))
    }

    /// Lane `i`.
    #[inline(always)]
    #[must_use]
    pub fn lane(self, i: usize) -> f32 {
        self.to_array()[i]
    }

    /// `f32::floor` per lane, from [`Float8::trunc`]: a lane whose truncation lies above it (a negative
    /// non-integer) is one less. Exact: both are integers below 2²³ in magnitude there.
    #[inline(always)]
    #[must_use]
    pub fn floor(self) -> Self {
        let t = self.trunc();
        t - Float8::select(t.gt(self), Float8::splat(1.0), Float8::splat(0.0))
    }

    /// These lanes with lane `lane` set to `v`, in registers (see the module doc on store-to-load
    /// forwarding).
    #[inline(always)]
    #[must_use]
    pub fn with_lane(self, lane: usize, v: f32) -> Self {
        Float8::select(Mask8::from_bitmask(1 << lane), Float8::splat(v), self)
    }
}

/// [`Float8::permute`] where `Float8` is two SSE registers or an array (AVX2's is one instruction, in
/// `math::avx2`).
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2", target_feature = "fma")))]
impl Float8 {
    /// Lane `i` is lane `idx[i]` of `self`, for whole numbers `idx` in 0..8 (a lookup in a table of eight).
    #[inline(always)]
    #[must_use]
    pub fn permute(self, idx: Float8) -> Self {
        let (a, idx) = (self.to_array(), idx.to_array());
        Float8::from_fn(|i| a[idx[i] as usize & 7])
    }
}

/// [`Float8::min_lane`] where `Float8` is two SSE registers or an array (AVX2's is shuffles, in
/// `math::avx2`).
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2", target_feature = "fma")))]
impl Float8 {
    /// The smallest lane (as `min_or_second` across the lanes: a NaN lane may or may not win).
    #[inline(always)]
    #[must_use]
    pub fn min_lane(self) -> f32 {
        let a = self.to_array();
        let m = |x: f32, y: f32| if x < y { x } else { y };
        m(m(m(a[0], a[1]), m(a[2], a[3])), m(m(a[4], a[5]), m(a[6], a[7])))
    }
}

impl Mask8 {
    /// Whether lane `i` is set.
    #[inline(always)]
    #[must_use]
    pub fn lane(self, i: usize) -> bool {
        self.bitmask() >> i & 1 == 1
    }
}

/// The operators, `Real` and (for the tests) `Rows` of the SSE and array backends, written once over their
/// inherent operations; `Avx8` has its own (`math::avx2`).
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2", target_feature = "fma")))]
mod common {
    use super::{Float8, Mask8};
    use crate::math::lanes::Real;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

    macro_rules! float_ops {
    ($($tr:ident $f:ident),*) => {$(
        impl $tr for Float8 {
            type Output = Float8;
            #[inline(always)]
            fn $f(self, o: Float8) -> Float8 { Float8::$f(self, o) }
        }
        impl $tr<f32> for Float8 {
            type Output = Float8;
            #[inline(always)]
            fn $f(self, o: f32) -> Float8 { Float8::$f(self, Float8::splat(o)) }
        }
    )*};
}
    float_ops!(Add add, Sub sub, Mul mul, Div div);

    impl Neg for Float8 {
        type Output = Float8;
        #[inline(always)]
        fn neg(self) -> Float8 {
            Float8::neg(self)
        }
    }

    impl BitAnd for Mask8 {
        type Output = Mask8;
        #[inline(always)]
        fn bitand(self, o: Mask8) -> Mask8 {
            self.and(o)
        }
    }

    impl BitOr for Mask8 {
        type Output = Mask8;
        #[inline(always)]
        fn bitor(self, o: Mask8) -> Mask8 {
            self.or(o)
        }
    }

    impl Not for Mask8 {
        type Output = Mask8;
        #[inline(always)]
        fn not(self) -> Mask8 {
            Mask8::not(self)
        }
    }

    impl Real for Float8 {
        type Mask = Mask8;
        const LANES: usize = 8;

        #[inline(always)]
        fn splat(v: f32) -> Self {
            Float8::splat(v)
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            Float8::sqrt(self)
        }
        #[inline(always)]
        fn abs(self) -> Self {
            Float8::abs(self)
        }
        #[inline(always)]
        fn xor_sign(self, o: Self) -> Self {
            Float8::xor_sign(self, o)
        }
        #[inline(always)]
        fn pow2(self) -> Self {
            Float8::pow2(self)
        }
        #[inline(always)]
        fn split_exponent(self) -> (Self, Self) {
            Float8::split_exponent(self)
        }
        /// `f32::min`: `o` where `o < self`, and `o` where `self` is NaN — what `f32::min(self, o)` compiles to.
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            // minps(self, o) is `o` on ties of ±0 and where self is NaN, as `Real::min` specifies.
            Float8::select(o.unordered(o), self, self.min_or_second(o))
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            Float8::select(o.unordered(o), self, self.max_or_second(o))
        }
        /// `f32::clamp`: NaN stays NaN.
        #[inline(always)]
        fn clamp(self, lo: f32, hi: f32) -> Self {
            let (lo, hi) = (Float8::splat(lo), Float8::splat(hi));
            let x = Float8::select(self.lt(lo), lo, self);
            Float8::select(x.gt(hi), hi, x)
        }
        #[inline(always)]
        fn mul_add(self, a: Self, b: Self) -> Self {
            Float8::mul_add(self, a, b)
        }
        /// `f32::round`: to the nearest integer, halves away from zero. `self − trunc(self)` is exact.
        #[inline(always)]
        fn round(self) -> Self {
            let t = self.trunc();
            let away = (self - t).abs().ge(Float8::splat(0.5));
            Float8::select(away, t + Float8::splat(1.0).xor_sign(self), t)
        }
        #[inline(always)]
        fn map(self, f: impl Fn(f32) -> f32) -> Self {
            let a = self.to_array();
            Float8::from_fn(|i| f(a[i]))
        }
        #[inline(always)]
        fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self {
            self.map(|x| x.lerp_table(table))
        }
        #[inline(always)]
        fn lt(self, o: Self) -> Mask8 {
            Float8::lt(self, o)
        }
        #[inline(always)]
        fn le(self, o: Self) -> Mask8 {
            Float8::le(self, o)
        }
        #[inline(always)]
        fn gt(self, o: Self) -> Mask8 {
            Float8::gt(self, o)
        }
        #[inline(always)]
        fn ge(self, o: Self) -> Mask8 {
            Float8::ge(self, o)
        }
        #[inline(always)]
        fn eq(self, o: Self) -> Mask8 {
            Float8::eq(self, o)
        }
        #[inline(always)]
        fn ne(self, o: Self) -> Mask8 {
            Float8::ne(self, o)
        }
        /// |x| < ∞: false for ±∞ and NaN.
        #[inline(always)]
        fn is_finite(self) -> Mask8 {
            self.abs().lt(Float8::splat(f32::INFINITY))
        }
        #[inline(always)]
        fn is_nan(self) -> Mask8 {
            self.unordered(self)
        }
        #[inline(always)]
        fn select(m: Mask8, a: Self, b: Self) -> Self {
            Float8::select(m, a, b)
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
            Float8::load(&std::array::from_fn(f))
        }
        #[inline(always)]
        fn bitmask(m: Mask8) -> u64 {
            u64::from(m.bitmask())
        }
    }

    /// Rows in and out of [`Float8`], so that it passes the checks every lane type passes
    /// ([`check_lane_type`](crate::math::lanes::check_lane_type)); the renderer moves its lanes itself.
    #[cfg(test)]
    impl crate::math::lanes::Rows for Float8 {
        fn load(v: &[f32]) -> Self {
            Float8::load(v.try_into().expect("eight numbers"))
        }
        fn store(self, out: &mut [f32]) {
            out.copy_from_slice(&self.to_array());
        }
        fn load3(v: &[crate::math::Vec3]) -> crate::math::lanes::V3<Self> {
            crate::math::lanes::V3::new(Float8::from_fn(|i| v[i].x), Float8::from_fn(|i| v[i].y), Float8::from_fn(|i| v[i].z))
        }
        fn load2(v: &[crate::math::Vec2]) -> (Self, Self) {
            (Float8::from_fn(|i| v[i].x), Float8::from_fn(|i| v[i].y))
        }
        fn store3(x: Self, y: Self, z: Self, out: &mut [[f32; 3]]) {
            for (l, r) in out.iter_mut().enumerate() {
                *r = [x.lane(l), y.lane(l), z.lane(l)];
            }
        }
        fn store_u32(self, out: &mut [u32]) {
            for (l, o) in out.iter_mut().enumerate() {
                *o = self.lane(l) as u32;
            }
        }
        fn store_mask(m: Mask8, out: &mut [bool]) {
            for (l, o) in out.iter_mut().enumerate() {
                *o = m.lane(l);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lanes::Real;

    const A: [f32; 8] = [0.5, -1.5, 0.0, -0.0, f32::INFINITY, f32::NAN, 3.0e-39, -2.5];
    const B: [f32; 8] = [2.0, -1.5, -0.0, 1.0, 1.0, 0.5, -7.0, f32::NAN];

    /// Bit for bit, except that a NaN result may be any NaN: IEEE 754 leaves the sign and payload of the
    /// NaN of an invalid operation open, and builds differ (2026-12: in the unoptimised test build the
    /// lanes' 0 / −0 gave 0x7fc00000, the scalar division x86's default NaN 0xffc00000).
    fn same(l: Float8, f: &dyn Fn(f32, f32) -> f32) -> bool {
        (0..8).all(|i| {
            let (got, want) = (l.lane(i), f(A[i], B[i]));
            got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan())
        })
    }

    fn mask(m: Mask8, f: &dyn Fn(f32, f32) -> bool) -> bool {
        (0..8).all(|i| m.lane(i) == f(A[i], B[i]))
    }

    /// The checks every lane type passes, `lerp_table` and row moves included.
    #[test]
    fn passes_the_lane_type_checks() {
        crate::math::lanes::check_lane_type::<Float8>();
    }

    /// Every operation is the `f32` one per lane, bit for bit, NaN and infinities included.
    #[test]
    fn lanes_are_scalar_operations() {
        let (x, y) = (Float8::load(&A), Float8::load(&B));
        assert!(same(x + y, &|p, q| p + q) && same(x - y, &|p, q| p - q) && same(x * y, &|p, q| p * q));
        assert!(same(x / y, &|p, q| p / q) && same(Float8::splat(-2.5), &|_, _| -2.5) && same(-x, &|p, _| -p));
        assert!(same(x.min_or_second(y), &|p, q| if p < q { p } else { q }));
        assert!(same(x.max_or_second(y), &|p, q| if p > q { p } else { q }));
        // Signed zeros aside, which `f32::min` may return either of (and constant folding and code do differ).
        let close = |l: Float8, f: &dyn Fn(f32, f32) -> f32| {
            (0..8).all(|i| l.lane(i) == f(A[i], B[i]) || (l.lane(i).is_nan() && f(A[i], B[i]).is_nan()))
        };
        assert!(close(Real::min(x, y), &f32::min) && close(Real::max(x, y), &f32::max));
        assert!(same(Real::sqrt(x), &|p, _| p.sqrt()) && same(Real::abs(x), &|p, _| p.abs()));
        assert!(same(Real::clamp(x, -1.0, 1.0), &|p, _| p.clamp(-1.0, 1.0)));
        assert!(same(Real::mul_add(x, y, x), &|p, q| p.mul_add(q, p)) && same(x.trunc(), &|p, _| p.trunc()));
        assert!(same(Float8::select(x.lt(y), x, y), &|p, q| if p < q { p } else { q }));
        assert!(mask(x.lt(y), &|p, q| p < q) && mask(x.le(y), &|p, q| p <= q) && mask(x.gt(y), &|p, q| p > q));
        assert!(mask(x.ge(y), &|p, q| p >= q) && mask(x.ne(y), &|p, q| p != q) && mask(x.eq(y), &|p, q| p == q));
        assert!(mask(Real::is_finite(x), &|p, _| p.is_finite()) && mask(Real::is_nan(y), &|_, q| q.is_nan()));
        assert!(mask(x.le(y) & x.ge(y), &|p, q| p == q) && mask(x.lt(y) | x.gt(y), &|p, q| p.partial_cmp(&q).is_some_and(|o| o.is_ne())));
        assert!(mask(!x.lt(y), &|p, q| !(p < q)) && mask(x.le(y) & !x.lt(y), &|p, q| p == q));
        assert!(mask(Mask8::from_bitmask(0b1010_0110), &|_, _| false) || Mask8::from_bitmask(0b1010_0110).bitmask() == 0b1010_0110);
    }

    /// `new` is `load`, and `with_lane` replaces exactly its lane, bit for bit.
    #[test]
    fn lanes_built_in_registers() {
        assert!(same(Float8::new(A), &|p, _| p));
        for (lane, &b) in B.iter().enumerate() {
            let x = Float8::load(&A).with_lane(lane, b);
            assert!((0..8).all(|i| x.lane(i).to_bits() == if i == lane { B[i] } else { A[i] }.to_bits()), "lane {lane}");
        }
    }

    /// `lanes` computes `one` in each lane, bit for bit (any NaN for a NaN), on the special values of
    /// `first` and on random numbers across magnitudes.
    fn matches_across_magnitudes(first: &[[f32; 8]], lanes: impl Fn(Float8) -> Float8, one: impl Fn(f32) -> f32) {
        let mut rng = crate::sampling::Pcg32::new(4, 4);
        for k in 0..2000 {
            let scale = [0.5f32, 3.0, 1e3, 1e7, 3e8][k % 5];
            let v: [f32; 8] = first.get(k).copied().unwrap_or_else(|| std::array::from_fn(|_| (rng.next_f32() * 2.0 - 1.0) * scale));
            let r = lanes(Float8::load(&v));
            for (i, &x) in v.iter().enumerate() {
                assert!(r.lane(i).to_bits() == one(x).to_bits() || (one(x).is_nan() && r.lane(i).is_nan()), "{x}");
            }
        }
    }

    /// `round` is `f32::round` (halves away from zero, signed zeros kept).
    #[test]
    fn round_matches_std() {
        let first = [[0.5, -0.5, 1.5, -2.5, -0.3, 0.49999997, 8_388_609.0, -0.0]];
        matches_across_magnitudes(&first, Real::round, f32::round);
    }

    /// `floor` is `f32::floor` (signed zeros, infinities and NaN kept).
    #[test]
    fn floor_matches_std() {
        let first = [
            [0.5, -0.5, -1.0, -0.0, 0.0, -0.99999994, -8_388_609.0, f32::NEG_INFINITY],
            [f32::INFINITY, f32::NAN, -f32::MIN_POSITIVE, 1e-40, -1e-40, 2.0, -3.5, f32::MAX],
        ];
        matches_across_magnitudes(&first, Float8::floor, f32::floor);
    }

    /// `min_lane` is the smallest lane wherever it sits, infinities and subnormals included.
    #[test]
    fn min_lane_is_the_smallest() {
        let mut rng = crate::sampling::Pcg32::new(4, 4);
        for k in 0..2000 {
            let mut a: [f32; 8] = std::array::from_fn(|_| (rng.next_f32() - 0.5) * 1e3);
            let specials = [f32::INFINITY, f32::NEG_INFINITY, 1e-40, -1e-40, f32::MAX, 0.0];
            a[k % 8] = specials[k % specials.len()];
            let want = a.iter().copied().fold(f32::INFINITY, f32::min);
            assert_eq!(Float8::load(&a).min_lane(), want, "{a:?}");
        }
    }
}
