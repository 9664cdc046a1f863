//! The error function family: exact `f64` forms (tables, verification, the reference of the tests) and
//! fast `f32` forms over [`Real`] lanes with stated error bounds (the models' Beckmann terms).
//!
//! | function | precision | domain |
//! |---|---|---|
//! | [`erf`], [`erfc`], [`erf_inv`] | `f64`, ≈ 10⁻¹⁵ | ℝ, (−1, 1) |
//! | [`erfc_lanes`] | `f32`, relative ≤ 6·10⁻⁷ | x ≥ 0 |
//! | [`erf_lanes`] | `f32`, absolute ≤ 4·10⁻⁷ | ℝ |
//! | [`erf_inv_lanes`] | `f32`, relative ≤ 5·10⁻⁷ (in its argument 1 − |y| as f32 resolves it) | (−1, 1) |

// The fitted coefficients are written with the f64 digits `tools/fit_special_functions.py` prints; Rust
// stores the nearest f32, the value the fit's error bound was checked with.
#![allow(clippy::excessive_precision)]

use super::exp_log::{exp_split, ln_unit, square_split};
use super::horner;
use crate::math::lanes::Real;
use std::f64::consts::PI as PI64;

/// √π·exp(x²)·erfc(x) for x ≥ 3 by the continued fraction of Abramowitz & Stegun 7.1.14:
/// 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + …)))). 60 terms reach f64 precision for x ≥ 3.
pub(crate) fn erfcx_cf(x: f64) -> f64 {
    debug_assert!(!(x < 3.0), "the continued fraction needs x ≥ 3 (NaN gives NaN)");
    let mut t = x;
    for k in (1..=60).rev() {
        t = x + (k as f64 * 0.5) / t;
    }
    1.0 / t
}

/// The error function, to about 1e-15: the everywhere-positive series of Abramowitz & Stegun 7.1.6,
/// erf x = (2/√π) e^{−x²} Σₙ 2ⁿ x^{2n+1} / (1·3·…·(2n+1)), for |x| < 3, and the continued fraction
/// 7.1.14 for erfc beyond.
#[must_use]
pub fn erf(x: f64) -> f64 {
    let ax = x.abs();
    let r = if ax < 3.0 {
        let x2 = ax * ax;
        let (mut term, mut sum, mut n) = (ax, ax, 0.0);
        while term > 1e-17 * sum {
            n += 1.0;
            term *= 2.0 * x2 / (2.0 * n + 1.0);
            sum += term;
        }
        2.0 / PI64.sqrt() * (-x2).exp() * sum
    } else {
        1.0 - (-ax * ax).exp() / PI64.sqrt() * erfcx_cf(ax)
    };
    r.copysign(x)
}

/// The complementary error function 1 − erf x, accurate relative to its value for x ≥ 3.
#[must_use]
pub fn erfc(x: f64) -> f64 {
    if x >= 3.0 {
        (-x * x).exp() / PI64.sqrt() * erfcx_cf(x)
    } else {
        1.0 - erf(x)
    }
}

/// The inverse error function on (−1, 1): Winitzki's closed-form start (relative error < 2e-3) refined
/// by Newton steps on [`erf`]. Arguments are clamped to ±(1 − 1e-15) (2026-11: ±1 maps to ±∞, which
/// a sampler must not return; the clamp bounds |result| by 5.9).
#[must_use]
pub fn erf_inv(x: f64) -> f64 {
    let x = x.clamp(-1.0 + 1e-15, 1.0 - 1e-15);
    let a = 0.147;
    let ln = (1.0 - x * x).ln();
    let b = 2.0 / (PI64 * a) + 0.5 * ln;
    let mut y = ((b * b - ln / a).sqrt() - b).sqrt().copysign(x);
    for _ in 0..4 {
        let deriv = 2.0 / PI64.sqrt() * (-y * y).exp();
        y -= (erf(y) - x) / deriv;
    }
    y
}

/// P(t) of erfc x = t e^(−x² + P(t)), t = 2/(2 + x), as a polynomial in u = (t − 7/12)·12/5 ∈ [−1, 1] (t
/// ∈ [1/6, 1], x ∈ [0, 10]): the form of Numerical Recipes' `erfcc` (Press et al. 1992, §6.2), fitted
/// anew by `tools/fit_special_functions.py`; fit error 5.7·10⁻⁹.
const ERFC_P: [f32; 11] = [
    -0.558_595_355_523_048_7,
    0.570_307_110_618_579_1,
    0.015_745_168_262_841_606,
    -0.029_470_441_911_266_826,
    -0.001_046_330_870_466_485_2,
    0.003_707_863_013_108_888_6,
    -0.000_273_726_316_914_977_57,
    -0.000_534_843_647_881_003_3,
    0.000_127_266_675_738_273_94,
    5.509_544_928_222_655e-5,
    -2.180_004_011_173_619_3e-5,
];

/// erfc x for x ≥ 0 (and NaN for NaN), relative error ≤ 6·10⁻⁷ against the `f64` [`erfc`] at the same
/// argument, down to f32's smallest normal number: it is 0 beyond x ≈ 9.2 (erfc x < 1.6·10⁻³⁸). The
/// Gaussian factor takes x² split exactly ([`square_split`]), so the bound holds in the tail too, where
/// a rounded x² would cost x²·2⁻²⁴ (5·10⁻⁶ at x = 9).
#[inline(always)]
#[must_use]
pub fn erfc_lanes<R: Real>(x: R) -> R {
    debug_assert!(!(R::any(x.lt(R::splat(0.0)))), "erfc_lanes needs x ≥ 0");
    // Beyond 10 the result underflows anyway; the clamp keeps t inside the fitted range (NaN passes).
    let x = R::select(x.gt(R::splat(10.0)), R::splat(10.0), x);
    let t = R::splat(2.0) / (x + 2.0);
    let p = horner((t - 7.0 / 12.0) * 2.4, &ERFC_P);
    let (hi, lo) = square_split(x);
    exp_split(-hi, p - lo) * t
}

/// erf x for any x as 1 − erfc |x| with x's sign: absolute error ≤ 4·10⁻⁷ (so relative only away from 0;
/// the Beckmann terms need erf where it is near ±1).
#[inline(always)]
#[must_use]
pub fn erf_lanes<R: Real>(x: R) -> R {
    let one = R::splat(1.0);
    (one - erfc_lanes(x.abs())).xor_sign(x)
}

/// erf⁻¹ y / y as a polynomial in u = (w − 2.5)/2.5, w = −ln(1 − y²) < 5 (|y| < 0.9966), the form of
/// Giles 2012, "Approximating the erfinv function" (GPU Computing Gems Jade, ch. 10), fitted anew; fit
/// error 1.0·10⁻⁸ relative.
const ERF_INV_CENTRAL: [f32; 10] = [
    1.501_409_358_809_364_7,
    0.616_600_740_309_879,
    -0.026_108_650_988_689_686,
    -0.019_574_433_779_223_68,
    0.008_528_993_486_899_353,
    -0.000_483_446_081_609_275_66,
    -0.000_845_244_247_417_655_3,
    0.000_282_828_574_392_554_73,
    3.537_710_807_112_807e-5,
    -3.277_132_570_497_121_5e-5,
];

/// erf⁻¹ y / y beyond, as a polynomial in u = (s − (√5 − 2)/2) / ((4 − √5)/2), s = √w − 3 ∈ [√5 − 3, 1];
/// fit error 6·10⁻⁹ relative.
const ERF_INV_TAIL: [f32; 10] = [
    2.951_328_561_531_345,
    0.885_158_439_835_674_7,
    0.005_570_225_816_418_527,
    -0.003_709_356_957_655_408_6,
    0.002_341_951_218_410_326_4,
    -0.001_376_789_250_699_796_7,
    0.000_624_059_679_143_097_4,
    -0.000_127_224_489_205_673_23,
    -6.650_175_399_020_635e-5,
    4.044_914_816_085_156e-5,
];

/// The largest f32 below 1: arguments of [`erf_inv_lanes`] are clamped to ±this (erf⁻¹ = ±3.85), so that
/// a sampler never returns an infinite slope.
pub const ERF_INV_CLAMP: f32 = 1.0 - f32::EPSILON / 2.0;

/// erf⁻¹ y on (−1, 1), |y| clamped to [`ERF_INV_CLAMP`]; NaN gives NaN. Relative error ≤ 5·10⁻⁷ against
/// the `f64` [`erf_inv`] at the same argument (test `fast_erf_family_matches_f64`): 1 − y² is formed as
/// (1 − |y|)(1 + |y|), exact in its factors, so the bound holds up to the clamp.
#[inline(always)]
#[must_use]
pub fn erf_inv_lanes<R: Real>(y: R) -> R {
    let a = y.abs();
    let a = R::select(a.gt(R::splat(ERF_INV_CLAMP)), R::splat(ERF_INV_CLAMP), a);
    let one = R::splat(1.0);
    let w = -ln_unit((one - a) * (one + a));
    // Each polynomial only where some lane needs it (the tail is |y| > 0.9966: rare).
    let central_lanes = w.lt(R::splat(5.0));
    let mut ratio = R::splat(0.0);
    if R::any(central_lanes) {
        ratio = horner((w - 2.5) * 0.4, &ERF_INV_CENTRAL);
    }
    if R::any(!central_lanes) {
        let s = w.sqrt() - 3.0;
        // The middle (√5 − 2)/2 and half-width (4 − √5)/2 of s's range.
        let tail = horner((s - 0.118_033_988_749_894_9) * 1.133_830_541_363_598_3, &ERF_INV_TAIL);
        ratio = R::select(central_lanes, ratio, tail);
    }
    (ratio * a).xor_sign(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lanes::F32x8;

    #[test]
    fn erf_and_its_inverse_match_reference_values() {
        // Reference values: erf(0.5), erf(1), erf(2), erfc(3), erfc(5), erfc(10) (A&S Table 7.1 / mpmath).
        assert!((erf(0.5) - 0.520_499_877_813_046_5).abs() < 1e-15);
        assert!((erf(1.0) - 0.842_700_792_949_714_9).abs() < 1e-15);
        assert!((erf(-2.0) + 0.995_322_265_018_952_7).abs() < 1e-15);
        assert!((erfc(3.0) / 2.209_049_699_858_544e-5 - 1.0).abs() < 1e-13);
        assert!((erfc(5.0) / 1.537_459_794_428_035e-12 - 1.0).abs() < 1e-13);
        assert!((erfc(10.0) / 2.088_487_583_762_545e-45 - 1.0).abs() < 1e-13);
        assert!((erf(2.999_999) - erf(3.000_001)).abs() < 3e-10, "the two branches meet");
        for x in [-0.999_999, -0.7, -0.1, 0.0, 0.3, 0.9, 0.999_999_9] {
            assert!((erf(erf_inv(x)) - x).abs() < 1e-14, "erf_inv({x})");
        }
    }

    #[test]
    fn fast_erf_family_matches_f64() {
        let n = 200_000;
        let (mut erfc_rel, mut erf_abs, mut inv_rel) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..=n {
            // erfc over [0, 9.2] (beyond, under f32's smallest normal).
            let x = 9.2 * i as f32 / n as f32;
            let want = erfc(x as f64);
            erfc_rel = erfc_rel.max((erfc_lanes(x) as f64 / want - 1.0).abs());
            let xs = 8.0 * i as f32 / n as f32 - 4.0;
            erf_abs = erf_abs.max((erf_lanes(xs) as f64 - erf(xs as f64)).abs());
            // erf⁻¹ uniformly in y and towards ±1 (1 − |y| down to 2⁻²⁴).
            let y = 2.0 * i as f32 / n as f32 - 1.0;
            let near_one = 1.0 - (-(24.0 * i as f32 / n as f32)).exp2();
            for y in [y, near_one, -near_one] {
                let y = y.clamp(-ERF_INV_CLAMP, ERF_INV_CLAMP);
                if y != 0.0 {
                    inv_rel = inv_rel.max((erf_inv_lanes(y) as f64 / erf_inv(y as f64) - 1.0).abs());
                }
            }
        }
        eprintln!("erfc relative {erfc_rel:.2e}, erf absolute {erf_abs:.2e}, erf⁻¹ relative {inv_rel:.2e}");
        assert!(erfc_rel <= 6e-7 && erf_abs <= 4e-7 && inv_rel <= 5e-7, "{erfc_rel} {erf_abs} {inv_rel}");
        assert_eq!(erf_inv_lanes(0.0f32), 0.0);
        assert!(erf_inv_lanes(1.0f32).is_finite() && erf_inv_lanes(-1.0f32) == -erf_inv_lanes(1.0f32));
        assert!(erfc_lanes(f32::INFINITY) == 0.0 && erfc_lanes(f32::NAN).is_nan() && erf_inv_lanes(f32::NAN).is_nan());
        let xs = F32x8([0.0, 0.3, 1.0, 2.5, 4.0, 9.0, 12.0, 0.01]);
        let (c8, i8) = (erfc_lanes(xs), erf_inv_lanes(xs * 0.1));
        for i in 0..8 {
            assert_eq!(c8.0[i].to_bits(), erfc_lanes(xs.0[i]).to_bits());
            assert_eq!(i8.0[i].to_bits(), erf_inv_lanes(xs.0[i] * 0.1).to_bits());
        }
    }
}
