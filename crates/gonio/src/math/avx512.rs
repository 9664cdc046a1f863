//! Sixteen lanes in one AVX-512 register: `Avx16`, the [`Real`] the batch drivers use when the CPU has
//! AVX-512F ([`detected`], at run time), as `Avx8` is with AVX2.
//!
//! Why a second width: the kernels of the glossy models are bound by division and square root (a GGX
//! conductor's `f` takes 34 of them per eight rows, most in the Fresnel term), and where AVX-512 is native
//! (AMD Zen 4/5, Intel since Ice Lake) one 512-bit `vdivps`/`vsqrtps` issues as often as a 256-bit one:
//! twice the rows per cycle (2026-11, measured on the Zen 5 build machine: 0.7–1.0 ns per instruction for
//! both widths). Mitsuba's LLVM backend compiles its kernels 16 wide on such CPUs for the same reason.
//!
//! Each operation computes per lane the IEEE operation of the `f32` form, as in `Avx8`, so
//! results are the same bit for bit (tests below and `bsdf::tests::batches_equal_single_calls`). The
//! moves between rows and lanes are two-source permutes (`vpermt2ps`): six for 16 rows of three numbers.
//!
//! Only built by compilers that have the AVX-512 target features (Rust ≥ 1.89; `build.rs` sets
//! `gonio_avx512`), so gonio still builds with its MSRV (1.80), without this path. Safety: as for `Avx8`,
//! `Avx16` is crate-private and its values exist only inside the drivers' `#[target_feature(enable =
//! "avx512f,avx2,fma")]` functions, entered only when [`detected`] says the CPU has AVX-512F.
// The intrinsics and target features are stable since 1.89, which `build.rs` checks before this module
// is compiled at all.
#![allow(clippy::incompatible_msrv)]

use super::lanes::{Real, Rows, V3};
use super::{Vec2, Vec3};
use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Whether this CPU has AVX-512F (and AVX2 and FMA, which the drivers' functions enable alongside).
#[inline(always)]
#[must_use]
pub fn detected() -> bool {
    #[cfg(test)]
    if !super::simd_level::allows(2) {
        return false;
    }
    std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
}

/// Sixteen `f32` lanes in one AVX-512 register (see the module doc).
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct Avx16(__m512);

/// `$e` with the intrinsics in scope; see the module doc for why they may run.
macro_rules! avx {
    ($e:expr) => {
        // SAFETY: `Avx16` values exist only after `detected()` (module doc).
        unsafe { $e }
    };
}

/// Entry `i` (0..64, per lane) of a 64-number table held in four registers `t`: a two-source permute of
/// each half, and the index's bit 5 picks the half.
#[inline(always)]
fn lookup64(t: &[__m512; 4], i: __m512i) -> __m512 {
    avx!({
        let (lo, hi) = (_mm512_permutex2var_ps(t[0], i, t[1]), _mm512_permutex2var_ps(t[2], i, t[3]));
        _mm512_mask_blend_ps(_mm512_test_epi32_mask(i, _mm512_set1_epi32(32)), lo, hi)
    })
}

/// Sixteen lane indices for the two-source permutes.
#[inline(always)]
fn indices(i: [i32; 16]) -> __m512i {
    avx!(_mm512_loadu_si512(i.as_ptr().cast()))
}

/// For lane k of the x (c = 0), y (1) or z (2) of 16 rows of three numbers, the number 3k + c of the 48:
/// the first permute takes those of the first 32 numbers (registers a, b; indices below 32), the second
/// keeps its result (index k) and takes the rest from the third register (16 + n − 32).
const fn load3_indices(c: usize) -> ([i32; 16], [i32; 16]) {
    let (mut first, mut second) = ([0; 16], [0; 16]);
    let mut k = 0;
    while k < 16 {
        let n = 3 * k + c;
        if n < 32 {
            first[k] = n as i32;
            second[k] = k as i32;
        } else {
            second[k] = (n - 16) as i32;
        }
        k += 1;
    }
    (first, second)
}

/// For place e of register j of 16 rows of three numbers (number n = 16j + e, the lane n / 3 of x, y or z
/// by n mod 3): the first permute takes x and y lanes (index k, 16 + k), the second keeps those (index e)
/// and takes the z lanes (16 + k).
const fn store3_indices(j: usize) -> ([i32; 16], [i32; 16]) {
    let (mut first, mut second) = ([0; 16], [0; 16]);
    let mut e = 0;
    while e < 16 {
        let n = 16 * j + e;
        let (k, c) = (n / 3, n % 3);
        match c {
            0 => first[e] = k as i32,
            1 => first[e] = 16 + k as i32,
            _ => {}
        }
        second[e] = if c == 2 { 16 + k as i32 } else { e as i32 };
        e += 1;
    }
    (first, second)
}

const LOAD3: [([i32; 16], [i32; 16]); 3] = [load3_indices(0), load3_indices(1), load3_indices(2)];
const STORE3: [([i32; 16], [i32; 16]); 3] = [store3_indices(0), store3_indices(1), store3_indices(2)];

impl Avx16 {
    /// The lanes as an array (for `map`).
    #[inline(always)]
    pub(crate) fn to_array(self) -> [f32; 16] {
        let mut a = [0.0; 16];
        avx!(_mm512_storeu_ps(a.as_mut_ptr(), self.0));
        a
    }

    #[inline(always)]
    fn compare<const PREDICATE: i32>(self, o: Avx16) -> __mmask16 {
        avx!(_mm512_cmp_ps_mask::<PREDICATE>(self.0, o.0))
    }

    /// Flips the bits set in `bits` (the sign: `-x`).
    #[inline(always)]
    fn xor(self, bits: i32) -> Avx16 {
        Avx16(avx!(_mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(self.0), _mm512_set1_epi32(bits)))))
    }
}

macro_rules! binary {
    ($($tr:ident $f:ident $intrinsic:ident),*) => {$(
        impl $tr for Avx16 {
            type Output = Avx16;
            #[inline(always)]
            fn $f(self, o: Avx16) -> Avx16 { Avx16(avx!($intrinsic(self.0, o.0))) }
        }
        impl $tr<f32> for Avx16 {
            type Output = Avx16;
            #[inline(always)]
            fn $f(self, o: f32) -> Avx16 { Avx16(avx!($intrinsic(self.0, _mm512_set1_ps(o)))) }
        }
    )*};
}
binary!(Add add _mm512_add_ps, Sub sub _mm512_sub_ps, Mul mul _mm512_mul_ps, Div div _mm512_div_ps);

impl Neg for Avx16 {
    type Output = Avx16;
    #[inline(always)]
    fn neg(self) -> Avx16 {
        self.xor(i32::MIN)
    }
}

/// A mask register: bit i for lane i.
#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct Mask16(__mmask16);

impl std::ops::BitAnd for Mask16 {
    type Output = Mask16;
    #[inline(always)]
    fn bitand(self, o: Mask16) -> Mask16 {
        Mask16(self.0 & o.0)
    }
}

impl std::ops::BitOr for Mask16 {
    type Output = Mask16;
    #[inline(always)]
    fn bitor(self, o: Mask16) -> Mask16 {
        Mask16(self.0 | o.0)
    }
}

impl std::ops::Not for Mask16 {
    type Output = Mask16;
    #[inline(always)]
    fn not(self) -> Mask16 {
        Mask16(!self.0)
    }
}

impl Real for Avx16 {
    type Mask = Mask16;
    const LANES: usize = 16;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        Avx16(avx!(_mm512_set1_ps(v)))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Avx16(avx!(_mm512_sqrt_ps(self.0)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Avx16(avx!(_mm512_abs_ps(self.0)))
    }
    #[inline(always)]
    fn xor_sign(self, o: Self) -> Self {
        let (a, b) = (avx!(_mm512_castps_si512(self.0)), avx!(_mm512_castps_si512(o.0)));
        let sign = avx!(_mm512_and_si512(b, _mm512_set1_epi32(i32::MIN)));
        Avx16(avx!(_mm512_castsi512_ps(_mm512_xor_si512(a, sign))))
    }
    #[inline(always)]
    fn pow2(self) -> Self {
        let n = avx!(_mm512_add_epi32(_mm512_cvttps_epi32(self.0), _mm512_set1_epi32(127)));
        Avx16(avx!(_mm512_castsi512_ps(_mm512_slli_epi32::<23>(n))))
    }
    #[inline(always)]
    fn split_exponent(self) -> (Self, Self) {
        let bits = avx!(_mm512_castps_si512(self.0));
        let m = avx!(_mm512_or_si512(_mm512_and_si512(bits, _mm512_set1_epi32(0x007f_ffff)), _mm512_set1_epi32(0x3f80_0000)));
        let e = avx!(_mm512_sub_epi32(_mm512_srli_epi32::<23>(bits), _mm512_set1_epi32(127)));
        (Avx16(avx!(_mm512_castsi512_ps(m))), Avx16(avx!(_mm512_cvtepi32_ps(e))))
    }
    /// `vminps(self, o)` is self < o ? self : o, the `f32` form's result but where `o` is NaN.
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Avx16::select(o.is_nan(), self, Avx16(avx!(_mm512_min_ps(self.0, o.0))))
    }
    /// As [`Self::min`], with self > o.
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Avx16::select(o.is_nan(), self, Avx16(avx!(_mm512_max_ps(self.0, o.0))))
    }
    #[inline(always)]
    fn clamp(self, lo: f32, hi: f32) -> Self {
        let (lo, hi) = (Avx16::splat(lo), Avx16::splat(hi));
        let x = Avx16::select(self.lt(lo), lo, self);
        Avx16::select(x.gt(hi), hi, x)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Avx16(avx!(_mm512_fmadd_ps(self.0, a.0, b.0)))
    }
    /// As `Avx8::round`: the integer part t, and one more in magnitude where x − t is at least one half.
    #[inline(always)]
    fn round(self) -> Self {
        let t = Avx16(avx!(_mm512_roundscale_ps::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(self.0)));
        let sign = Avx16(avx!(_mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(self.0), _mm512_set1_epi32(i32::MIN)))));
        let step = Avx16(avx!(_mm512_castsi512_ps(_mm512_or_si512(_mm512_castps_si512(sign.0), _mm512_castps_si512(_mm512_set1_ps(1.0))))));
        Avx16::select((self - t).abs().ge(Avx16::splat(0.5)), t + step, t)
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        let a = self.to_array().map(f);
        Avx16(avx!(_mm512_loadu_ps(a.as_ptr())))
    }
    /// As `Avx8::lerp_table`: the index arithmetic and interpolation in lanes, two gathers (two-source
    /// permutes for a table of 64).
    #[inline(always)]
    fn lerp_table<const N: usize>(self, table: &[f32; N]) -> Self {
        const { assert!(N >= 2 && N < (1 << 24)) };
        let x = self.clamp(0.0, 1.0) * (N - 1) as f32;
        let (k, below, above) = avx!({
            // NaN converts to i32::MIN, which the clamp turns into 0, as `as usize` does; k ≤ N − 2 keeps
            // both gathers within the table.
            let k = _mm512_cvttps_epi32(x.0);
            let k = _mm512_min_epi32(_mm512_max_epi32(k, _mm512_setzero_si512()), _mm512_set1_epi32(N as i32 - 2));
            let p = table.as_ptr();
            let (below, above) = if N == 64 {
                // The table in four registers, looked up by two-source permutes (the index's bit 5 picks
                // the pair): the same numbers as the gathers, for a fraction of their cost (2026-12:
                // roughplastic's T(μ) tables have 64 nodes and `f` looks up two).
                let t = [_mm512_loadu_ps(p), _mm512_loadu_ps(p.add(16)), _mm512_loadu_ps(p.add(32)), _mm512_loadu_ps(p.add(48))];
                (lookup64(&t, k), lookup64(&t, _mm512_add_epi32(k, _mm512_set1_epi32(1))))
            } else {
                (_mm512_i32gather_ps::<4>(k, p), _mm512_i32gather_ps::<4>(k, p.add(1)))
            };
            (Avx16(_mm512_cvtepi32_ps(k)), Avx16(below), Avx16(above))
        });
        let t = x - k;
        (Avx16::splat(1.0) - t) * below + t * above
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Mask16 {
        Mask16(self.compare::<_CMP_LT_OQ>(o))
    }
    #[inline(always)]
    fn le(self, o: Self) -> Mask16 {
        Mask16(self.compare::<_CMP_LE_OQ>(o))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Mask16 {
        Mask16(self.compare::<_CMP_GT_OQ>(o))
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Mask16 {
        Mask16(self.compare::<_CMP_GE_OQ>(o))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Mask16 {
        Mask16(self.compare::<_CMP_EQ_OQ>(o))
    }
    /// True where either is NaN, as `!=`.
    #[inline(always)]
    fn ne(self, o: Self) -> Mask16 {
        Mask16(self.compare::<_CMP_NEQ_UQ>(o))
    }
    #[inline(always)]
    fn is_finite(self) -> Mask16 {
        self.abs().lt(Avx16::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn is_nan(self) -> Mask16 {
        Mask16(self.compare::<_CMP_UNORD_Q>(self))
    }
    #[inline(always)]
    fn select(m: Mask16, a: Self, b: Self) -> Self {
        Avx16(avx!(_mm512_mask_blend_ps(m.0, b.0, a.0)))
    }
    #[inline(always)]
    fn any(m: Mask16) -> bool {
        m.0 != 0
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f32 {
        self.to_array()[i]
    }
    #[inline(always)]
    fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        <Avx16 as Rows>::load(&std::array::from_fn::<f32, 16, _>(f))
    }
    #[inline(always)]
    fn bitmask(m: Mask16) -> u64 {
        u64::from(m.0)
    }
}

impl Rows for Avx16 {
    #[inline(always)]
    fn load(v: &[f32]) -> Self {
        let v: &[f32; 16] = v.try_into().expect("sixteen numbers");
        Avx16(avx!(_mm512_loadu_ps(v.as_ptr())))
    }

    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        let out: &mut [f32; 16] = out.try_into().expect("sixteen numbers");
        avx!(_mm512_storeu_ps(out.as_mut_ptr(), self.0));
    }

    #[inline(always)]
    fn load3(v: &[Vec3]) -> V3<Self> {
        let v: &[Vec3; 16] = v.try_into().expect("sixteen directions");
        // `Vec3` is `#[repr(C)]` of three `f32`s (size 12, alignment 4): sixteen are 48 floats.
        let p = v.as_ptr().cast::<f32>();
        let (a, b, c) = avx!((_mm512_loadu_ps(p), _mm512_loadu_ps(p.add(16)), _mm512_loadu_ps(p.add(32))));
        let part = |(first, second): ([i32; 16], [i32; 16])| {
            Avx16(avx!(_mm512_permutex2var_ps(_mm512_permutex2var_ps(a, indices(first), b), indices(second), c)))
        };
        V3::new(part(LOAD3[0]), part(LOAD3[1]), part(LOAD3[2]))
    }

    #[inline(always)]
    fn load2(v: &[Vec2]) -> (Self, Self) {
        let v: &[Vec2; 16] = v.try_into().expect("sixteen pairs");
        // `Vec2` is `#[repr(C)]` of two `f32`s (size 8, alignment 4): sixteen are 32 floats.
        let p = v.as_ptr().cast::<f32>();
        let (a, b) = avx!((_mm512_loadu_ps(p), _mm512_loadu_ps(p.add(16))));
        let part = |c: i32| Avx16(avx!(_mm512_permutex2var_ps(a, indices(std::array::from_fn(|k| 2 * k as i32 + c)), b)));
        (part(0), part(1))
    }

    #[inline(always)]
    fn store3(x: Self, y: Self, z: Self, out: &mut [[f32; 3]]) {
        let out: &mut [[f32; 3]; 16] = out.try_into().expect("sixteen rows");
        let p = out.as_mut_ptr().cast::<f32>();
        for (j, (first, second)) in STORE3.into_iter().enumerate() {
            avx!(_mm512_storeu_ps(
                p.add(16 * j),
                _mm512_permutex2var_ps(_mm512_permutex2var_ps(x.0, indices(first), y.0), indices(second), z.0)
            ));
        }
    }

    /// Lanes holding whole numbers in [0, 2³¹) (flag bits; checked in debug builds) as `u32`: `v as u32`.
    #[inline(always)]
    fn store_u32(self, out: &mut [u32]) {
        debug_assert!(self.to_array().iter().all(|&x| x == x.trunc() && (0.0..2_147_483_648.0).contains(&x)));
        let out: &mut [u32; 16] = out.try_into().expect("sixteen numbers");
        avx!(_mm512_storeu_si512(out.as_mut_ptr().cast(), _mm512_cvttps_epi32(self.0)));
    }

    /// The mask's bits as 1 or 0 in 32-bit lanes, narrowed to bytes.
    #[inline(always)]
    fn store_mask(m: Mask16, out: &mut [bool]) {
        let out: &mut [bool; 16] = out.try_into().expect("sixteen flags");
        avx!(_mm_storeu_si128(out.as_mut_ptr().cast(), _mm512_cvtepi32_epi8(_mm512_maskz_set1_epi32(m.0, 1))));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The index tables put every number where it belongs (checked on plain arrays, on any CPU).
    #[test]
    fn permute_indices_move_rows() {
        let numbers: Vec<usize> = (0..48).collect();
        let permute = |a: &[usize], idx: [i32; 16], b: &[usize]| -> Vec<usize> {
            idx.iter().map(|&i| if i < 16 { a[i as usize] } else { b[i as usize - 16] }).collect()
        };
        let lanes: Vec<Vec<usize>> = (0..3)
            .map(|c| {
                let (first, second) = LOAD3[c];
                permute(&permute(&numbers[..16], first, &numbers[16..32]), second, &numbers[32..])
            })
            .collect();
        for (c, lane) in lanes.iter().enumerate() {
            assert_eq!(*lane, (0..16).map(|k| 3 * k + c).collect::<Vec<_>>());
        }
        for (j, &(first, second)) in STORE3.iter().enumerate() {
            assert_eq!(permute(&permute(&lanes[0], first, &lanes[1]), second, &lanes[2]), (16 * j..16 * j + 16).collect::<Vec<_>>());
        }
    }

    /// The lane-type checks of `math::lanes` (every operation the `f32` one, bit for bit; rows move
    /// exactly), run with AVX-512 enabled, on CPUs that have it.
    #[test]
    fn avx16_is_a_lane_type() {
        #[target_feature(enable = "avx512f,avx2,fma")]
        unsafe fn run() {
            crate::math::lanes::check_lane_type::<Avx16>();
        }
        if detected() {
            // SAFETY: the CPU has the features.
            unsafe { run() }
        }
    }
}
