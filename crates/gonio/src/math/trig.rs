//! Short polynomial sine and cosine for arguments in [−π/4, π/4], for inner loops (the concentric disk
//! map) where a general `sin_cos` call with its range reduction dominates.

/// (sin x, cos x) for |x| ≤ π/4 by the Taylor polynomials through x⁹ and x¹⁰ (Abramowitz & Stegun 4.3.65,
/// 4.3.66). The truncation error is below x¹¹/11! ≤ 1.8e-9 (sine) and x¹²/12! ≤ 1.2e-10 (cosine) at
/// |x| = π/4, far under f32's rounding, so the result is within 2 ulp of the correctly rounded value
/// (test `matches_std_within_2_ulp`). Outside [−π/4, π/4] the error grows quickly: callers reduce first.
#[inline(always)]
#[must_use]
pub fn sin_cos_quarter(x: f32) -> (f32, f32) {
    let x2 = x * x;
    // Horner in x²: sin x = x (1 − x²/3! (1 − x²/(4·5) (1 − x²/(6·7) (1 − x²/(8·9))))), likewise cos.
    let s = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
    let c = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0))));
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
