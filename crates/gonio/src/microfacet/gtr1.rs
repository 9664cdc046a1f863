//! GTR1, the "generalized Trowbridge–Reitz" distribution with γ = 1 (Burley 2012, "Physically Based
//! Shading at Disney", Appendix B.2): D(ωm) = (α² − 1) / (π ln(α²) (1 + (α² − 1) cos²θm)), isotropic,
//! with a long tail; the clearcoat lobe of `principled`. Sampled from D·cos θm (the inversion given there):
//! φ = 2π u₁, cos²θm = (1 − (α²)^(1 − u₂)) / (1 − α²). No Smith Λ: `principled` masks its clearcoat with
//! GGX's at α = 0.25, as Burley does.
//!
//! Defined for 0 < α < 1 (at α = 1 it is the uniform D = 1/π, a limit the formula reaches only as 0/0).

use crate::math::lanes::{Real, V3};
use crate::math::trig::sin_cos_turn;
use crate::math::{Vec2, Vec3};
use crate::numerics::exp_log::exp_neg;
use std::f32::consts::PI;

/// The GTR1 distribution of roughness `alpha` ∈ (0, 1), in lanes ([`Real`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gtr1 {
    alpha2: f32,
    /// ln α² (< 0), computed once.
    ln_alpha2: f32,
}

impl Gtr1 {
    /// The distribution of roughness `alpha` (0 < α < 1).
    #[must_use]
    pub fn new(alpha: f32) -> Self {
        debug_assert!(alpha > 0.0 && alpha < 1.0, "GTR1 needs 0 < α < 1, got {alpha}");
        let alpha2 = alpha * alpha;
        Gtr1 { alpha2, ln_alpha2: alpha2.ln() }
    }

    /// D(ωm) of a unit normal, 0 below the surface.
    #[inline(always)]
    #[must_use]
    pub fn d<R: Real>(&self, wm: V3<R>) -> R {
        // 1 + (α² − 1) cos²θ written as sin²θ + α² cos²θ: no cancellation at the pole, where the peak of a
        // small α is (2026-12: the first form lost 10 % of D's integral to f32 rounding at α = 0.001).
        let t = wm.x * wm.x + wm.y * wm.y + wm.z * wm.z * self.alpha2;
        let d = R::splat((self.alpha2 - 1.0) / (PI * self.ln_alpha2)) / t;
        R::select(wm.z.gt(R::splat(0.0)), d, R::splat(0.0))
    }

    /// The density of [`sample`](Self::sample): D(ωm) cos θm.
    #[inline(always)]
    #[must_use]
    pub fn pdf<R: Real>(&self, wm: V3<R>) -> R {
        self.d(wm) * wm.z
    }

    /// A normal drawn from D·cos θm: azimuth 2π `ux`, cos²θm = (1 − (α²)^(1 − `uy`)) / (1 − α²).
    #[inline(always)]
    #[must_use]
    pub fn sample<R: Real>(&self, ux: R, uy: R) -> V3<R> {
        let zero = R::splat(0.0);
        let (sin_phi, cos_phi) = sin_cos_turn(ux);
        // (α²)^(1 − u) = e^((1 − u) ln α²), an argument ≤ 0.
        let power = exp_neg((R::splat(1.0) - uy) * self.ln_alpha2);
        let cos2 = (R::splat(1.0) - power) / (1.0 - self.alpha2);
        // sin²θ = (p − α²)/(1 − α²) directly: 1 − cos²θ loses it near the pole.
        let sin2 = (power - self.alpha2) / (1.0 - self.alpha2);
        let sin_theta = sin2.max(zero).sqrt();
        V3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos2.max(zero).sqrt())
    }

    /// The sample (u₁, u₂) that [`sample`](Self::sample) maps to the upper-hemisphere normal `wm`.
    #[must_use]
    pub fn invert(&self, wm: Vec3) -> Vec2 {
        let phi = wm.y.atan2(wm.x);
        let u1 = if phi < 0.0 { phi / (2.0 * PI) + 1.0 } else { phi / (2.0 * PI) };
        // 1 − u₂ = ln(1 − cos²θ (1 − α²)) / ln α², the argument written as sin²θ + α² cos²θ.
        let u2 = 1.0 - (wm.x * wm.x + wm.y * wm.y + wm.z * wm.z * self.alpha2).ln() / self.ln_alpha2;
        Vec2::new(u1, u2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// D·cos θm integrates to 1 over the hemisphere: 2π ∫ D cos θ sin θ dθ by the midpoint rule in ln θ
    /// (the peak, of width α in θ, is resolved at every α), directions built from θ in f32 as the models do.
    #[test]
    fn d_cos_is_normalised() {
        for alpha in [0.001f32, 0.01, 0.1, 0.5, 0.9] {
            let g = Gtr1::new(alpha);
            let (lo, hi) = ((1e-8f64).ln(), (std::f64::consts::FRAC_PI_2).ln());
            let n = 100_000;
            let h = (hi - lo) / n as f64;
            let mut sum = 0.0f64;
            for k in 0..n {
                let theta = (lo + (k as f64 + 0.5) * h).exp();
                let w = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
                sum += g.d::<f32>(w.into()) as f64 * theta.cos() * theta.sin() * theta * h;
            }
            let integral = 2.0 * std::f64::consts::PI * sum;
            assert!((integral - 1.0).abs() < 1e-4, "α = {alpha}: ∫ D cos = {integral}");
        }
    }

    #[test]
    fn sample_and_invert_round_trip() {
        let mut rng = crate::sampling::Pcg32::new(5, 0);
        for alpha in [0.001f32, 0.05, 0.1, 0.7] {
            let g = Gtr1::new(alpha);
            for _ in 0..1000 {
                let u = Vec2::new(rng.next_f32() * 0.98 + 0.01, rng.next_f32() * 0.98 + 0.01);
                let wm: Vec3 = g.sample::<f32>(u.x, u.y).into();
                assert!((wm.length() - 1.0).abs() < 1e-5 && wm.z >= 0.0);
                let back = g.invert(wm);
                assert!((back - u).abs().max_element() < 2e-3, "α = {alpha}: {u} → {wm} → {back}");
            }
        }
    }

    /// The samples' density is D cos: the fraction with cos²θm > c is D cos integrated over that cap in
    /// closed form, 1 − ln(1 − c (1 − α²)) / ln α² (the inverse of the sampler at cos² = c).
    #[test]
    fn samples_follow_d_cos() {
        let g = Gtr1::new(0.1);
        let mut rng = crate::sampling::Pcg32::new(9, 0);
        let n = 200_000;
        for c in [0.5f32, 0.9, 0.99, 0.999] {
            let inside = (0..n).filter(|_| g.sample::<f32>(rng.next_f32(), rng.next_f32()).z.powi(2) > c).count();
            let expect = 1.0 - (1.0 - c * (1.0 - 0.01)).ln() / 0.01f32.ln();
            let got = inside as f32 / n as f32;
            assert!((got - expect).abs() < 4e-3, "cos² > {c}: {got} vs {expect}");
        }
    }
}
