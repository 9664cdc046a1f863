//! Short polynomial sine and cosine for arguments in [−π/4, π/4], for inner loops (the concentric disk
//! map, visible-normal sampling) where a general `sin_cos` call with its range reduction dominates, and
//! which must run in SIMD lanes ([`Real`]); and `atan2` in lanes (direction → texture coordinates of
//! environment maps and spheres), where libm's runs one lane at a time.

use crate::math::lanes::Real;

/// (sin x, cos x) for |x| ≤ π/4 by the Taylor polynomials through x⁹ and x¹⁰ (Abramowitz & Stegun 4.3.65,
/// 4.3.66). The truncation error is below x¹¹/11! ≤ 1.8e-9 (sine) and x¹²/12! ≤ 1.2e-10 (cosine) at
/// |x| = π/4, far under f32's rounding, so the result is within 2 ulp of the correctly rounded value
/// (test `matches_std_within_2_ulp`). Outside [−π/4, π/4] the error grows quickly: callers reduce first.
/// Generic over [`Real`]: the same operations on one `f32` or in eight lanes.
///
/// Horner's scheme in x² on the coefficients ±1/k! as constants, by [`Real::mad`]: no divisions.
/// (2026-12: written with a division by each k(k − 1), a call took nine divisions, the slowest
/// instruction in the path tracer's lanes.)
#[inline(always)]
#[must_use]
pub fn sin_cos_quarter<R: Real>(x: R) -> (R, R) {
    const S: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
    const C: [f32; 5] = [-1.0 / 2.0, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40_320.0, -1.0 / 3_628_800.0];
    let x2 = x * x;
    // sin x = x + x³ (S₀ + x² (S₁ + x² (S₂ + x² S₃))), cos x = 1 + x² (C₀ + x² (C₁ + …)).
    let horner = |c: &[f32]| c.iter().rev().skip(1).fold(R::splat(c[c.len() - 1]), |p, &k| x2.mad(p, R::splat(k)));
    let s = (x * x2).mad(horner(&S), x);
    let c = x2.mad(horner(&C), R::splat(1.0));
    (s, c)
}

/// (sin 2πt, cos 2πt) for finite `t` (in turns) with |t| < 2²¹, branch-free so that it runs in lanes: t is
/// reduced to the nearest quarter turn q/4 and the rest r = t − q/4 ∈ [−1/8, 1/8] (exact: q/4 is a
/// multiple of 1/4 within a factor of two of t, or t itself is small); [`sin_cos_quarter`] at 2πr ∈
/// [−π/4, π/4] is then rotated by q quarter turns. Within 3 ulp of the correctly rounded value for t in
/// [0, 1] (test `turns_match_std`), as good as `(2π t).sin_cos()`, whose rounding of 2πt is of the same size.
#[inline(always)]
#[must_use]
pub fn sin_cos_turn<R: Real>(t: R) -> (R, R) {
    let q = (t * 4.0).round();
    let r = t - q * 0.25;
    let (s, c) = sin_cos_quarter(r * std::f32::consts::TAU);
    // Rotation by q·π/2: q ≡ 0: (s, c), 1: (c, −s), 2: (−s, −c), 3: (−c, s) (mod 4). m = q − 4·round(q/4) ∈
    // [−2, 2] is q mod 4 up to a multiple of 4, exact in f32 for integers below 2²³: q ≡ 1 ⇔ m = 1, q ≡ 2 ⇔
    // |m| = 2, q ≡ 3 ⇔ m = −1.
    let m = q - (q * 0.25).round() * 4.0;
    let odd = m.abs().eq(R::splat(1.0));
    let (s, c) = (R::select(odd, c, s), R::select(odd, -s, c));
    let flip = m.abs().eq(R::splat(2.0)) | m.eq(R::splat(-1.0));
    (R::select(flip, -s, s), R::select(flip, -c, c))
}

/// atan2(y, x) ∈ [−π, π] for finite `y`, `x`, branch-free so that it runs in lanes. The octant is
/// reduced to a = min(|x|, |y|) / max(|x|, |y|) ∈ [0, 1] (0 where both are 0), then to
/// |a′| ≤ tan(π/8) by atan a = π/4 + atan a′, a′ = (a − 1)/(a + 1), for a > tan(π/8); there
/// atan a′ ≈ a′ + a′³ P(a′²) with the cubic P of Cephes' `atanf` (S. L. Moshier, Cephes Math Library
/// 2.2, atanf.c: relative error 1.9·10⁻⁷ peak on that interval). The octant is then undone: π/2 − r where
/// |y| > |x|, π − r where x < 0, and y's sign. Within 3·10⁻⁷ of the exact value (test `atan2_matches_f64`:
/// 2.7·10⁻⁷ at worst, 1.2 ulp of π), against libm's correctly rounded `atan2f` one lane at a time.
/// Unlike libm, atan2(±0, −0) is ±0 (the zero vector's angle is undefined either way).
#[inline(always)]
#[must_use]
pub fn atan2<R: Real>(y: R, x: R) -> R {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    // Cephes' coefficients (−3.33329491539e−1, 1.99777106478e−1, −1.38776856032e−1, 8.05374449538e−2) as
    // `f32`s.
    const P: [f32; 4] = [-0.333_329_5, 0.199_777_11, -0.138_776_85, 0.080_537_446];
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let a = R::select(hi.gt(zero), lo / hi, zero);
    let reduced = a.gt(R::splat(0.414_213_57));
    let a = R::select(reduced, (a - one) / (a + one), a);
    let z = a * a;
    let poly = P.iter().rev().skip(1).fold(R::splat(P[3]), |p, &k| z.mad(p, R::splat(k)));
    let r = (a * z).mad(poly, a) + R::select(reduced, R::splat(FRAC_PI_4), zero);
    let r = R::select(ay.gt(ax), R::splat(FRAC_PI_2) - r, r);
    let r = R::select(x.lt(zero), R::splat(PI) - r, r);
    r.xor_sign(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_match_std() {
        let n = 400_000;
        for i in 0..=n {
            let t = i as f32 / n as f32;
            let (s, c) = sin_cos_turn(t);
            let (s8, c8) = sin_cos_turn(crate::math::lanes::F32x8::splat(t));
            assert!(s8.0.iter().all(|v| v.to_bits() == s.to_bits()) && c8.0.iter().all(|v| v.to_bits() == c.to_bits()));
            let (ws, wc) = (std::f64::consts::TAU * f64::from(t)).sin_cos();
            // Three ulp of 1 near the zeros (where an angle's rounding dominates), else of the value.
            let tol = |v: f64| 3.0 * (v.abs().max(0.5) * f64::from(f32::EPSILON));
            assert!((f64::from(s) - ws).abs() <= tol(ws), "sin(2π·{t}) = {s}, want {ws}");
            assert!((f64::from(c) - wc).abs() <= tol(wc), "cos(2π·{t}) = {c}, want {wc}");
        }
        assert_eq!(sin_cos_turn(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turn(0.5).1, -1.0);
    }

    #[test]
    fn matches_std_within_2_ulp() {
        let n = 200_000;
        for i in 0..=n {
            let x = std::f32::consts::FRAC_PI_4 * (2.0 * i as f32 / n as f32 - 1.0);
            let (s, c) = sin_cos_quarter(x);
            let (ws, wc) = (f64::from(x).sin(), f64::from(x).cos());
            // One ulp of the value (at least of f32's smallest normal scale near 0 for the sine).
            let ulp = |v: f64| (v.abs() * f64::from(f32::EPSILON)).max(f64::from(f32::MIN_POSITIVE));
            assert!((f64::from(s) - ws).abs() <= 2.0 * ulp(ws), "sin({x}) = {s}, want {ws}");
            assert!((f64::from(c) - wc).abs() <= 2.0 * ulp(wc), "cos({x}) = {c}, want {wc}");
        }
    }

    /// Over directions all round the circle (and near the axes and diagonals, where the octant reduction
    /// switches), at radii from 10⁻³⁰ to 10³⁰: within 3·10⁻⁷ of the f64 atan2, the same in eight lanes bit
    /// for bit, and the axes exact.
    #[test]
    fn atan2_matches_f64() {
        let n = 100_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let t = f64::from(i) / f64::from(n) * std::f64::consts::TAU - std::f64::consts::PI;
            for (k, radius) in [1e-30f64, 1e-3, 1.0, 7.5, 1e30].into_iter().enumerate() {
                let t = t + 1e-7 * k as f64;
                let (y, x) = ((t.sin() * radius) as f32, (t.cos() * radius) as f32);
                let got = atan2(y, x);
                let lanes = atan2(crate::math::lanes::F32x8::splat(y), crate::math::lanes::F32x8::splat(x));
                assert!(lanes.0.iter().all(|v| v.to_bits() == got.to_bits()), "lanes at ({y}, {x})");
                let want = f64::from(y).atan2(f64::from(x));
                let err = (f64::from(got) - want).abs();
                // ±π are the same angle.
                let err = err.min((err - std::f64::consts::TAU).abs());
                worst = worst.max(err);
                assert!(err <= 3e-7, "atan2({y}, {x}) = {got}, want {want}");
            }
        }
        for (y, x, want) in [(0.0f32, 1.0f32, 0.0f32), (1.0, 0.0, std::f32::consts::FRAC_PI_2), (-1.0, 0.0, -std::f32::consts::FRAC_PI_2)] {
            assert_eq!(atan2(y, x), want);
        }
        assert_eq!(atan2(0.0f32, -1.0).abs(), std::f32::consts::PI);
        assert_eq!(atan2(0.0f32, 0.0), 0.0);
        assert!(worst > 1e-8, "the test compares something: worst {worst}");
    }
}
