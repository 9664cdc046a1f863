//! e^x and ln x in [`Real`] lanes, from the operations `Real` has (the power of two of the range reduction
//! made and taken apart through the exponent bits, [`Real::pow2`] and [`Real::split_exponent`]), so that one
//! formula gives the same bits on an `f32` and in every lane type.

// Constants are written with the digits of their f64 derivation; Rust stores the nearest f32.
#![allow(clippy::excessive_precision)]

use super::horner;
use crate::math::lanes::Real;

/// ln 2 split for Cody–Waite reduction: `LN2_HI` has 9 significant bits, so n·`LN2_HI` is exact for
/// |n| < 2¹⁵; `LN2_HI` + `LN2_LO` = ln 2 to 2·10⁻¹².
const LN2_HI: f32 = 0.693_359_375;
const LN2_LO: f32 = -2.121_944_4e-4;

/// Below this e^x is under f32's smallest normal number (e^−87.34 ≈ 1.18·10⁻³⁸).
const EXP_MIN_ARG: f32 = -87.0;

/// 1/k!, k = 0…8: e^r on |r| ≤ 0.5 by Taylor's polynomial; the remainder r⁹/9! ≤ 5.4·10⁻⁹.
const EXP_TAYLOR: [f32; 9] = [1.0, 1.0, 0.5, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0, 1.0 / 40_320.0];

/// e^(hi + lo) for hi ≤ 0 and |lo| ≤ 2, with hi carried exactly through the range reduction: where the
/// argument is a sum whose large part is exact (−x² split by [`square_split`]), the result keeps the
/// accuracy that a rounded argument would lose (e^x's condition number is |x|: 87·2⁻²⁴ = 5·10⁻⁶ at the
/// bottom of the range). Relative error ≤ 3·10⁻⁷ (4 ulp) against e^(hi + lo) in `f64` (test
/// `exp_and_ln_match_f64`). Where hi + lo < −87 it returns 0 (the true value is below 1.6·10⁻³⁸; flushing
/// it keeps every result normal); NaN gives NaN.
#[inline(always)]
#[must_use]
pub fn exp_split<R: Real>(hi: R, lo: R) -> R {
    let x = hi + lo;
    let under = x.lt(R::splat(EXP_MIN_ARG));
    // n = round(x / ln 2) ∈ [−126, 0] (x clamped so that 2ⁿ stays normal; those lanes are zeroed below).
    let n = (x.max(R::splat(EXP_MIN_ARG)) * std::f32::consts::LOG2_E).round();
    // r = hi − n ln 2 + lo: hi − n·LN2_HI is exact where the two are within a factor of two (Sterbenz), as
    // they are whenever hi is large; |r| ≤ ln 2 / 2 + rounding.
    let r = ((R::select(under, R::splat(0.0), hi) - n * LN2_HI) - n * LN2_LO) + R::select(under, R::splat(0.0), lo);
    let p = horner(r, &EXP_TAYLOR);
    R::select(under, R::splat(0.0), p * n.pow2())
}

/// e^x for x ≤ 0 ([`exp_split`] with lo = 0; the same bound).
#[inline(always)]
#[must_use]
pub fn exp_neg<R: Real>(x: R) -> R {
    exp_split(x, R::splat(0.0))
}

/// (hi, lo) with hi + lo = x² to within 2⁻⁴⁸ x² and hi exact: x = xh + xl with xh of 12 significant bits
/// (Veltkamp's split, c = 4097 x; xh = c − (c − x)), hi = xh², lo = 2 xh xl + xl². Needs |x| < 2¹¹⁵
/// (no overflow of 4097 x) and unfused arithmetic, which `Real`'s operators are.
#[inline(always)]
#[must_use]
pub fn square_split<R: Real>(x: R) -> (R, R) {
    let c = x * 4097.0;
    let xh = c - (c - x);
    let xl = x - xh;
    (xh * xh, xh * xl * 2.0 + xl * xl)
}

/// 1/(2k + 1), k = 1…4: ln m = 2 atanh s = 2 (s + s³/3 + s⁵/5 + …), s = (m − 1)/(m + 1), |s| ≤ 0.1716 for
/// m ∈ [√½, √2]; the remainder 2 s¹¹/11 ≤ 7.6·10⁻¹⁰.
const ATANH_SERIES: [f32; 4] = [1.0 / 3.0, 1.0 / 5.0, 1.0 / 7.0, 1.0 / 9.0];

/// ln x for x ∈ (0, 1], arguments below f32's smallest normal taken as that (ln = −87.34); NaN gives NaN.
/// x = m·2ᵉ with m ∈ [√½, √2) (from its exponent bits, [`Real::split_exponent`]), then ln m from the atanh
/// series and e ln 2 in two parts. Relative error ≤ 2·10⁻⁷ (test `exp_and_ln_match_f64`; near x = 1, where
/// ln x → 0, too).
#[inline(always)]
#[must_use]
pub fn ln_unit<R: Real>(x: R) -> R {
    let tiny = R::splat(f32::MIN_POSITIVE);
    // (A select, not `max`: NaN passes, and is given back at the end.)
    let (m, e) = R::select(x.lt(tiny), tiny, x).split_exponent();
    let big = m.gt(R::splat(std::f32::consts::SQRT_2));
    let (m, e) = (R::select(big, m * 0.5, m), R::select(big, e + 1.0, e));
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let ln_m = (s * s2 * 2.0).mad(horner(s2, &ATANH_SERIES), s * 2.0);
    R::select(x.is_nan(), x, e * LN2_HI + (e * LN2_LO + ln_m))
}

/// atanh x = ½ ln((1 + x)/(1 − x)) for x ∈ (−1, 1), as −½ sign(x) ln((1 − |x|)/(1 + |x|)) by [`ln_unit`]
/// (whose argument is then in (0, 1]); ±1 and beyond give ±43.7 (ln of f32's smallest normal), NaN gives NaN.
/// Absolute error within 1.5·10⁻⁷ + 3·10⁻⁷ |atanh x| + 3·10⁻⁸/(1 − |x|) (the roundings of the quotient; test
/// `atanh_matches_f64`): accurate in absolute terms (a sampled wavelength's 3·10⁻⁴ nm), not relative ones near 0.
#[inline(always)]
#[must_use]
pub fn atanh<R: Real>(x: R) -> R {
    let a = x.abs();
    (ln_unit((R::splat(1.0) - a) / (a + 1.0)) * 0.5).abs().xor_sign(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lanes::F32x8;

    /// Relative error of `got` against `want` (both ≠ 0), in f64.
    fn rel(got: f32, want: f64) -> f64 {
        (got as f64 / want - 1.0).abs()
    }

    #[test]
    fn exp_and_ln_match_f64() {
        let (mut worst_exp, mut worst_split, mut worst_ln) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..=400_000 {
            let x = -87.0 * i as f32 / 400_000.0;
            worst_exp = worst_exp.max(rel(exp_neg(x), (x as f64).exp()));
            // −a² for a up to 9.3 through the split.
            let a = 9.3 * i as f32 / 400_000.0;
            let (hi, lo) = square_split(a);
            worst_split = worst_split.max(rel(exp_split(-hi, -lo + 0.25), (-(a as f64) * (a as f64) + 0.25).exp()));
            // ln over (0, 1]: uniformly and across the binades.
            let y = (i as f32 + 0.5) / 400_000.5;
            let z = (-(i as f32) / 4000.0).exp2();
            for v in [y, z, 1.0 - y * 1e-3] {
                let want = (v as f64).ln();
                let got = ln_unit(v);
                if want != 0.0 {
                    worst_ln = worst_ln.max(rel(got, want));
                }
            }
        }
        eprintln!("exp {worst_exp:.2e}, exp of split squares {worst_split:.2e}, ln {worst_ln:.2e}");
        assert!(worst_exp <= 3e-7 && worst_split <= 3e-7, "{worst_exp} {worst_split}");
        assert!(worst_ln <= 2e-7, "{worst_ln}");
        assert_eq!(ln_unit(1.0f32), 0.0);
        assert_eq!(exp_neg(0.0f32), 1.0);
        assert_eq!(exp_neg(-88.0f32), 0.0);
        assert_eq!(exp_neg(f32::NEG_INFINITY), 0.0);
        assert!(exp_neg(f32::NAN).is_nan() && ln_unit(f32::NAN).is_nan());
        assert_eq!(ln_unit(0.0f32), ln_unit(f32::MIN_POSITIVE));
        // Lanes give the single calls' bits.
        let xs = F32x8([-0.1, -1.0, -10.0, -50.0, -86.9, -87.5, 0.0, -3.3]);
        let (e8, l8) = (exp_neg(xs), ln_unit(exp_neg(xs)));
        for i in 0..8 {
            assert_eq!(e8.0[i].to_bits(), exp_neg(xs.0[i]).to_bits());
            assert_eq!(l8.0[i].to_bits(), ln_unit(exp_neg(xs.0[i])).to_bits());
        }
    }

    #[test]
    fn atanh_matches_f64() {
        let mut worst = 0.0f64;
        for i in -400_000..=400_000 {
            let x = 0.99 * i as f32 / 400_000.0;
            let want = f64::from(x).atanh();
            let bound = 1.5e-7 + 3e-7 * want.abs() + 3e-8 / (1.0 - f64::from(x.abs()));
            let err = (f64::from(atanh(x)) - want).abs();
            assert!(err <= bound, "atanh({x}) = {} against {want}", atanh(x));
            worst = worst.max(err / bound);
        }
        assert!(atanh(0.0f32) == 0.0 && atanh(-0.0f32).is_sign_negative() && atanh(f32::NAN).is_nan());
        assert!((atanh(1.0f32) - 43.668).abs() < 0.01 && (atanh(-1.0f32) + 43.668).abs() < 0.01);
        let lanes = F32x8::from_fn(|i| -0.9 + 0.25 * i as f32);
        for i in 0..8 {
            assert_eq!(atanh(lanes).lane(i).to_bits(), atanh(lanes.lane(i)).to_bits());
        }
        eprintln!("atanh: worst error {worst:.3} of its bound");
    }
}
