//! Beckmann–Spizzichino (Walter et al. 2007 eq. 25; anisotropic form as in Heitz 2014 §5):
//! D = exp(−s²/z²) / (π αx αy z⁴) with s² = (x/αx)² + (y/αy)², in `f32` lanes throughout: its exact Smith
//! Λ (Heitz 2014 §5, not Walter's rational approximation) from the fast error functions of
//! [`crate::numerics::erf`], D·cos sampling (Walter 2007 eq. 28) and a visible-normal sampler with a fixed
//! number of steps (Jakob 2014). The exact `f64` Λ, [`beckmann_lambda`], is kept for tables and tests.

use super::distribution::Distribution;
use crate::math::lanes::{Real, V3};
use crate::math::param::Param;
use crate::numerics::erf::{erf_inv_lanes, erfc, erfc_lanes, erfcx_cf};
use crate::numerics::exp_log::{exp_neg, exp_split, ln_unit, square_split};
use crate::numerics::horner;
use std::f32::consts::PI;
use std::f64::consts::PI as PI64;

/// 1/√π (the f64 digits; Rust stores the nearest f32).
#[allow(clippy::excessive_precision)]
const FRAC_1_SQRT_PI: f32 = 0.564_189_583_547_756_3;

/// The Beckmann distribution with roughness (RMS slope) `alpha_x`, `alpha_y`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann<A = f32> {
    pub alpha_x: A,
    pub alpha_y: A,
}

/// The exact Beckmann Λ for a ≥ 0, a = cot θ / α (Heitz 2014 §5; Walter 2007 eq. 27 approximates its G1):
/// Λ(a) = (erf(a) − 1)/2 + exp(−a²)/(2a√π) = (exp(−a²)/(a√π) − erfc(a))/2.
#[must_use]
pub fn beckmann_lambda(a: f64) -> f64 {
    debug_assert!(!(a < 0.0), "Λ needs a ≥ 0 (NaN gives NaN)");
    if a == 0.0 {
        return f64::INFINITY;
    }
    let sqrt_pi = PI64.sqrt();
    if a < 3.0 {
        0.5 * ((-a * a).exp() / (a * sqrt_pi) - erfc(a))
    } else {
        // erfc(a) = exp(−a²) erfcx(a)/√π... factor exp(−a²) out of both terms (no underflow of the parts).
        0.5 * (-a * a).exp() / sqrt_pi * (1.0 / a - erfcx_cf(a))
    }
}

/// Where [`beckmann_lambda_lanes`] switches from the fit of k ([`LAMBDA_K`]) to the asymptotic fit.
const LAMBDA_SWITCH: f32 = 2.5;

/// k(a) = a e^{a²} Λ(a) = (1/√π − a erfcx a)/2 for a ∈ [0, 2.5], as a polynomial in u = a/1.25 − 1 (fit by
/// `tools/fit_special_functions.py`; fit error 2.6·10⁻⁸ relative, 3.6·10⁻⁷ evaluated in `f32`): Λ(a) =
/// e^{−a²} k(a)/a without erfcx's exponential and division, and without the cancellation of its
/// difference (k is entire, so a polynomial converges fast).
#[allow(clippy::excessive_precision)] // the fit's f64 digits; Rust stores the nearest f32
const LAMBDA_K: [f32; 15] = [
    0.052_205_468_821_129_544,
    -0.066_747_238_925_315_12,
    0.058_849_559_357_083_595,
    -0.042_990_696_688_472_89,
    0.027_714_573_212_844_84,
    -0.016_267_501_000_617_378,
    0.008_853_096_683_133_77,
    -0.004_507_726_396_640_797_6,
    0.002_176_491_322_616_355_5,
    -0.001_036_325_743_534_847_7,
    0.000_461_386_301_424_306,
    -0.000_151_591_891_485_567_4,
    5.912_717_647_620_757e-5,
    -5.289_640_999_447_791e-5,
    2.111_136_076_411_178_2e-5,
];

/// h(v) = 2a² (1 − a√π e^{a²} erfc a), v = 1/a² ∈ [0, 0.16] (a ≥ 2.5), as a polynomial in u = (v − 0.08)
/// 12.5 (fit by `tools/fit_special_functions.py`; fit error 6·10⁻⁹): Λ(a) = e^{−a²} h / (4a³√π) without
/// the cancellation of the erfc form (h → 1 − 3/(2a²) + … as a → ∞).
#[allow(clippy::excessive_precision)] // the fit's f64 digits; Rust stores the nearest f32
const LAMBDA_H: [f32; 9] = [
    0.898_986_912_766_714_4,
    -0.085_816_698_234_542_29,
    0.012_293_714_794_581_448,
    -0.002_249_510_540_966_345,
    0.000_487_801_642_797_729_87,
    -0.000_117_522_130_645_467_04,
    3.115_170_471_213_036_6e-5,
    -1.238_457_871_060_804_5e-5,
    4.297_592_376_125_147e-6,
];

/// The exact Beckmann Λ(a) of [`beckmann_lambda`] in `f32` lanes for a ≥ 0 (∞ at 0): relative error
/// ≤ 10⁻⁶ against the `f64` form at the same argument wherever Λ is at least f32's smallest normal
/// number (a ≤ 9.2; beyond it is 0), and so G1 = 1/(1 + Λ) within 10⁻⁶ too (test
/// `fast_lambda_matches_f64`: 4.6·10⁻⁷ and 3.0·10⁻⁷ with FMA). Mitsuba's rational G1 (Walter 2007
/// eq. 27) errs by up to 0.35 %.
/// - a < 2.5: Λ = e^{−a²} k(a)/a ([`LAMBDA_K`]);
/// - a ≥ 2.5: Λ = e^{−a²} h(1/a²)/(4a³√π) ([`LAMBDA_H`]), no cancellation.
///
/// e^{−a²} takes a² split exactly ([`square_split`]); 1/a is the one division. (2026-12-06: the near form
/// was e^{−a²} (1/(a√π) − erfcx a)/2, with erfcx's own exponential and two more divisions: Λ was 54 % of
/// the Beckmann `roughconductor`'s batched `f`.)
///
/// Not inlined: one copy per lane type. Inlined into every lane driver (with its ten-step neighbour
/// [`visible_slope_x`]), it made LLVM's loop passes run for over half an hour on one codegen unit
/// (2026-12-04; the array lane types' operations are loops of their own).
#[inline(never)]
#[must_use]
pub fn beckmann_lambda_lanes<R: Real>(a: R) -> R {
    // Beyond 16 Λ underflows to 0 either way; the clamp keeps a² finite (NaN passes).
    let a = R::select(a.gt(R::splat(16.0)), R::splat(16.0), a);
    let (hi, lo) = square_split(a);
    let gauss = exp_split(-hi, -lo);
    let r = R::splat(1.0) / a;
    // Each form only where some lane needs it (a single call computes one).
    let near_lanes = a.lt(R::splat(LAMBDA_SWITCH));
    let mut lambda = R::splat(0.0);
    if R::any(near_lanes) {
        lambda = gauss * horner(a * (1.0 / 1.25) - 1.0, &LAMBDA_K) * r;
    }
    if R::any(!near_lanes) {
        let v = r * r;
        let far = gauss * horner((v - 0.08) * 12.5, &LAMBDA_H) * (v * r * (FRAC_1_SQRT_PI / 4.0));
        lambda = R::select(near_lanes, lambda, far);
    }
    lambda
}

/// The most steps of the visible-slope inversion ([`visible_slope_x`]): the test
/// `visible_slope_matches_the_exact_inverse` bounds the CDF residual after them.
const SLOPE_STEPS: usize = 10;

/// The CDF residual |C(b) − u| below which a lane of [`visible_slope_x`] takes one last Newton step and
/// stops: the step squares it (to ~10⁻¹², below `f32`'s rounding of C, ~10⁻⁷).
const SLOPE_CONVERGED: f32 = 1e-6;

/// The longest last step (in b = erf x) a converged lane of [`visible_slope_x`] takes.
const SLOPE_LAST_STEP: f32 = 1e-4;

/// The x slope (in ωo's incidence plane) of a visible normal of the α = 1 Beckmann distribution, seen from
/// the direction with sin θ, cos θ > 0, for the uniform number `u` — Jakob 2014, "An Improved Visible
/// Normal Sampling Routine for the Beckmann Distribution" (tech. report, ETH Zürich): the CDF of the slope
/// x (Heitz & d'Eon 2014 §4), written in b = erf x,
/// C(b) = (1 + b + tan θ e^{−x²}/√π) / (1 + c + tan θ e^{−cot²θ}/√π), c = erf(cot θ), b ∈ (−1, c],
/// is increasing with C'(b) ∝ 1 − x tan θ ≥ 0 (no vanishing derivative in the tails, as C'(x) has). It is
/// inverted by Newton's method on b from Jakob's fitted start b₀ = c − (1 + c)(1 − u)^{p(θ)},
/// p(θ) = 1 + θ(−0.876 + θ(0.4265 − 0.0594 θ)) (his eq. 14 and the fit after it), kept inside the bracket
/// of values known to lie below and above the root (bisection where a step leaves it). A lane stops after
/// the step from a residual below [`SLOPE_CONVERGED`] (a step no longer than [`SLOPE_LAST_STEP`]; 2.9 steps
/// on average over the test's grid of θ and u), or after [`SLOPE_STEPS`]; a stopped lane is left as it is
/// while the others go on, so that every lane's result is its single call's, bit for bit (2026-12-05: the
/// fixed ten steps were a quarter of a render of Beckmann
/// rough plastic under the `direct` integrator). Error: |C(x) − u| ≤ 10⁻⁵ (the
/// tolerance at which Jakob's iteration stops) over θ ∈ [0°, 89.9°], u ∈ [0, 1] against the exact `f64`
/// CDF, and |x − C⁻¹(u)| ≤ 10⁻⁴ for u ∈ [0.001, 0.999] (test `visible_slope_matches_the_exact_inverse`).
/// b is clamped to ±(1 − 2⁻²⁴) (|x| ≤ 3.85, see [`erf_inv_lanes`]): the slopes beyond carry less than
/// 2·10⁻⁸ of the probability.
///
/// Not inlined (see [`beckmann_lambda_lanes`]); a call per lane batch against its Newton steps.
#[inline(never)]
#[must_use]
pub fn visible_slope_x<R: Real>(sin_theta: R, cos_theta: R, u: R) -> R {
    let one = R::splat(1.0);
    // tan θ = 0 and cot θ = ∞ at normal incidence.
    let tan_theta = sin_theta / cos_theta;
    let cot_theta = cos_theta / sin_theta;
    // Beyond 10, erfc and e^{−x²} are 0 in f32 (NaN passes). A lane with ωo below the surface (cot θ < 0)
    // is one whose sample the caller rejects: it is taken at the horizon, so that erfc's domain holds, and
    // takes no Newton step (iterating it could only hold its packet's loop longer).
    let below_surface = cot_theta.lt(R::splat(0.0));
    let cot = R::select(cot_theta.gt(R::splat(10.0)), R::splat(10.0), cot_theta);
    let cot = R::select(below_surface, R::splat(0.0), cot);
    let c = one - erfc_lanes(cot);
    let (hi, lo) = square_split(cot);
    let norm = one / (one + c + tan_theta * exp_split(-hi, -lo) * FRAC_1_SQRT_PI);
    // The start: θ = acos(cos θ) by Abramowitz & Stegun 4.4.45 (|error| ≤ 6.7·10⁻⁵, ample for a start),
    // then Jakob's fit.
    let z = cos_theta;
    let theta = (one - z).max(R::splat(0.0)).sqrt() * horner(z, &[1.570_728_8, -0.212_114_4, 0.074_261, -0.018_729_3]);
    let p = horner(theta, &[1.0, -0.876, 0.4265, -0.0594]);
    let mut b = c - (one + c) * exp_neg(p * ln_unit(one - u));
    let (mut below, mut above) = (-one, c);
    let mut running = !below_surface;
    for _ in 0..SLOPE_STEPS {
        // Outside the bracket (or NaN from a vanishing derivative): bisect.
        let start = R::select(b.ge(below) & b.le(above), b, (below + above) * 0.5);
        let x = erf_inv_lanes(start);
        let (hi, lo) = square_split(x);
        let value = norm * (one + start + tan_theta * exp_split(-hi, -lo) * FRAC_1_SQRT_PI) - u;
        let deriv = norm * (one - x * tan_theta);
        let high = value.gt(R::splat(0.0));
        above = R::select(running & high, start, above);
        below = R::select(running & !high, start, below);
        // NaN counts as converged: more steps would not help it.
        let converged = !value.abs().gt(R::splat(SLOPE_CONVERGED));
        // A last step that is long or leaves the bracket is not taken: `start` is close enough, and the
        // step is long only where the derivative vanishes (at the top, b = c, as u → 1: 0/0 there).
        let delta = value / deriv;
        let step = start - delta;
        let wild = !(step.ge(below) & step.le(above)) | !delta.abs().le(R::splat(SLOPE_LAST_STEP));
        let step = R::select(converged & wild, start, step);
        b = R::select(running, step, b);
        running = running & !converged;
        if !R::any(running) {
            break;
        }
    }
    b = R::select(b.ge(below) & b.le(above), b, (below + above) * 0.5);
    // The slope 0 below the surface: a rejected lane's numbers stay tame downstream.
    R::select(below_surface, R::splat(0.0), erf_inv_lanes(b))
}

impl<A: Param> Distribution for Beckmann<A> {
    #[inline(always)]
    fn alphas<R: Real>(&self) -> (R, R) {
        (self.alpha_x.lanes(), self.alpha_y.lanes())
    }

    /// D = exp(−s²/z²) / (π αx αy z⁴), 0 below the surface and where z⁴ underflows (exp(−s²/z²) is 0 there
    /// already: 2026-11, avoids 0/0).
    #[inline(always)]
    fn d<R: Real>(&self, wm: V3<R>) -> R {
        let zero = R::splat(0.0);
        let z2 = wm.z * wm.z;
        let cos4 = z2 * z2;
        let (x, y) = (wm.x * self.alpha_x.recip::<R>(), wm.y * self.alpha_y.recip::<R>());
        let d = exp_neg(-(x * x + y * y) / z2) / (cos4 * (self.alpha_x.lanes::<R>() * PI * self.alpha_y.lanes::<R>()));
        R::select(wm.z.le(zero) | cos4.eq(zero), zero, d)
    }

    /// Λ(a), a = z / √(αx² x² + αy² y²) ([`beckmann_lambda_lanes`]).
    #[inline(always)]
    fn lambda_upper<R: Real>(&self, x: R, y: R, z: R) -> R {
        let zero = R::splat(0.0);
        // α(φ)² sin²θ = αx² x² + αy² y² (the projected roughness of the anisotropic case, times sin²θ).
        let (ax, ay) = (x * self.alpha_x.lanes::<R>(), y * self.alpha_y.lanes::<R>());
        let s2 = ax * ax + ay * ay;
        let lambda = beckmann_lambda_lanes(z / s2.sqrt());
        R::select(s2.eq(zero), zero, R::select(z.eq(zero), R::splat(f32::INFINITY), lambda))
    }

    /// tan²θm = −ln(1 − u) / A(φ) (Walter 2007 eq. 28 with the anisotropic A(φ)); 1 − u = 0 is taken as
    /// f32's smallest normal number.
    #[inline(always)]
    fn tan2_d_cos<R: Real>(&self, ux: R, a: R) -> R {
        -ln_unit(R::splat(1.0) - ux) / a
    }

    /// Heitz & d'Eon 2014, §4: stretch ωo to the α = 1 configuration, sample the visible slopes there
    /// (x by [`visible_slope_x`], y a unit Gaussian: erf⁻¹(2u − 1)), rotate to ωo's azimuth, unstretch.
    #[inline(always)]
    fn sample_visible<R: Real>(&self, wo: V3<R>, ux: R, uy: R) -> V3<R> {
        let zero = R::splat(0.0);
        let one = R::splat(1.0);
        // 1. Stretch.
        let v = V3::new(wo.x * self.alpha_x.lanes::<R>(), wo.y * self.alpha_y.lanes::<R>(), wo.z).normalize();
        let sin2 = v.x * v.x + v.y * v.y;
        let sin_theta = sin2.sqrt();
        let tilted = sin2.gt(zero);
        let (cos_phi, sin_phi) = (R::select(tilted, v.x / sin_theta, one), R::select(tilted, v.y / sin_theta, zero));
        // 2. The slopes for α = 1 with ωo in the xz plane.
        let slope_x = visible_slope_x(sin_theta, v.z, ux);
        let slope_y = erf_inv_lanes(uy * 2.0 - 1.0);
        // 3. Rotate to ωo's azimuth, 4. unstretch, 5. the normal of that slope.
        let px = (cos_phi * slope_x - sin_phi * slope_y) * self.alpha_x.lanes::<R>();
        let py = (sin_phi * slope_x + cos_phi * slope_y) * self.alpha_y.lanes::<R>();
        V3::new(-px, -py, one).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::lanes::F32x8;
    use crate::numerics::erf;

    #[test]
    fn beckmann_lambda_matches_its_erf_form_and_known_values() {
        // Λ(1) = (erf 1 − 1)/2 + e^{−1}/(2√π) = 0.024 148 0...
        let expect = 0.5 * (0.842_700_792_949_714_9 - 1.0) + (-1.0f64).exp() / (2.0 * PI64.sqrt());
        assert!((beckmann_lambda(1.0) - expect).abs() < 1e-15);
        // Continuity across the series/continued-fraction switch, and the asymptote
        // Λ ≈ e^{−a²}/(4a³√π) for large a.
        assert!((beckmann_lambda(2.999_999_9) / beckmann_lambda(3.000_000_1) - 1.0).abs() < 1e-5);
        let a = 6.0f64;
        let asym = (-a * a).exp() / (4.0 * a * a * a * PI64.sqrt()) * (1.0 - 1.5 / (a * a) + 3.75 / (a * a * a * a));
        assert!((beckmann_lambda(a) / asym - 1.0).abs() < 1e-3);
    }

    #[test]
    fn fast_lambda_matches_f64() {
        // a = cot θ / α over θ < 90° and α ∈ [10⁻⁴, 10]: a from 10⁻⁶ up; uniformly on [0, 9.2] and
        // geometrically below 1.
        let n = 200_000;
        let (mut worst_lambda, mut worst_g1) = (0.0f64, 0.0f64);
        for i in 1..=n {
            for a in [9.2 * i as f32 / n as f32, (-20.0 * i as f32 / n as f32).exp2()] {
                let want = beckmann_lambda(a as f64);
                let got = beckmann_lambda_lanes(a) as f64;
                if want >= f32::MIN_POSITIVE as f64 {
                    worst_lambda = worst_lambda.max((got / want - 1.0).abs());
                }
                worst_g1 = worst_g1.max(((1.0 + want) / (1.0 + got) - 1.0).abs());
            }
        }
        eprintln!("Beckmann Λ worst relative error {worst_lambda:.2e}, G1 {worst_g1:.2e}");
        assert!(worst_lambda <= 1e-6 && worst_g1 <= 1e-6, "{worst_lambda} {worst_g1}");
        assert_eq!(beckmann_lambda_lanes(0.0f32), f32::INFINITY);
        assert_eq!(beckmann_lambda_lanes(20.0f32), 0.0);
        assert!(beckmann_lambda_lanes(f32::NAN).is_nan());
        let a = F32x8([1e-4, 0.3, 1.0, 2.49, 2.51, 5.0, 9.0, 30.0]);
        let l = beckmann_lambda_lanes(a);
        assert!((0..8).all(|i| l.0[i].to_bits() == beckmann_lambda_lanes(a.0[i]).to_bits()));
    }

    /// The exact inverse in `f64`: C(x) = (1 + erf x)/2 + tan θ e^{−x²}/(2√π) on (−∞, cot θ] at
    /// u C(cot θ), by Newton's method safeguarded with bisection to 10⁻¹³.
    fn exact_slope_x(sin_theta: f64, cos_theta: f64, u: f64) -> f64 {
        let tan_theta = sin_theta / cos_theta;
        let cdf = |x: f64| 0.5 * (1.0 + erf::erf(x)) + tan_theta * (-x * x).exp() / (2.0 * PI64.sqrt());
        let (mut lo, mut hi) = (-8.0, (cos_theta / sin_theta).min(8.0));
        let target = u * cdf(hi);
        let mut x = 0.5 * (lo + hi);
        for _ in 0..200 {
            let value = cdf(x) - target;
            if value > 0.0 {
                hi = x;
            } else {
                lo = x;
            }
            let deriv = (1.0 - x * tan_theta) * (-x * x).exp() / PI64.sqrt();
            let mut next = x - value / deriv;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - x).abs() < 1e-13 * (1.0 + x.abs()) {
                return next;
            }
            x = next;
        }
        x
    }

    #[test]
    fn visible_slope_matches_the_exact_inverse() {
        // The residual |C(x) − u| of the returned slope, C the exact normalised CDF in f64, and the slope's
        // distance from the exact inverse where the density is not tiny.
        let (mut worst_u, mut worst_x) = (0.0f64, 0.0f64);
        for t in 0..=180 {
            let theta = (89.9f64 * t as f64 / 180.0).to_radians();
            let (s, c) = (theta.sin() as f32, theta.cos() as f32);
            let (sd, cd) = (s as f64, c as f64);
            let tan_theta = sd / cd;
            let cdf = |x: f64| 0.5 * (1.0 + erf::erf(x)) + tan_theta * (-x * x).exp() / (2.0 * PI64.sqrt());
            let top = if s > 0.0 { cdf(cd / sd) } else { 1.0 };
            for k in 0..=2000 {
                let u = k as f32 / 2000.0;
                let x = visible_slope_x(s, c, u) as f64;
                assert!(x.is_finite(), "θ={theta} u={u}");
                worst_u = worst_u.max((cdf(x) / top - u as f64).abs());
                let exact = exact_slope_x(sd, cd, u as f64);
                if (0.001..0.999).contains(&u) {
                    worst_x = worst_x.max((x - exact).abs());
                }
            }
        }
        eprintln!("Beckmann visible slope: worst CDF residual {worst_u:.2e}, worst slope error {worst_x:.2e}");
        assert!(worst_u <= 1e-5 && worst_x <= 1e-4, "{worst_u} {worst_x}");
        // Lanes give the single calls' bits.
        let (s, c, u) = (
            F32x8([0.0, 0.1, 0.5, 0.9, 0.99, 1.0, 0.3, 0.7]),
            F32x8([1.0, 0.99, 0.86, 0.43, 0.14, 1e-3, 0.95, 0.71]),
            F32x8([0.5, 0.0, 1.0, 0.3, 0.9, 0.99, 1e-7, 0.6]),
        );
        let x = visible_slope_x(s, c, u);
        assert!((0..8).all(|i| x.0[i].to_bits() == visible_slope_x(s.0[i], c.0[i], u.0[i]).to_bits()));
    }
}
