//! Hero-wavelength sampling: the four wavelengths a path carries in spectral mode.
//!
//! Wavelengths are drawn over [[`LAMBDA_MIN`], [`LAMBDA_MAX`]] = [360, 830] nm (the range of the CIE 1931
//! tables, [`super::cie`]) with the *visible-importance* density of Radziszewski, Boryczko & Alda, "An
//! improved technique for full spectral rendering", Journal of WSCG 17 (2009), which pbrt-v4
//! (`SampleVisibleWavelengths`) and Mitsuba 3 (`sample_rgb_spectrum`) both use:
//!
//! ```text
//! p(λ) = A / cosh²(k (λ − λ₀)),   k = 0.0072 nm⁻¹, λ₀ = 538 nm,   λ ∈ [360, 830] nm.
//! ```
//!
//! Because d/dx tanh x = 1 / cosh² x, the CDF is closed form and so is its inverse. With
//! `t₀ = tanh(k (360 − λ₀))` and `t₁ = tanh(k (830 − λ₀))`:
//!
//! ```text
//! A = k / (t₁ − t₀),   P(λ) = (tanh(k (λ − λ₀)) − t₀) / (t₁ − t₀),   λ(u) = λ₀ + atanh(t₀ + u (t₁ − t₀)) / k.
//! ```
//!
//! A path carries [`N_WAVELENGTHS`] = 4 wavelengths from one sample `uc`: the *hero* at `uc` and three more
//! at `uc + i/4` wrapped to [0, 1) (Wilkie et al., "Hero wavelength spectral sampling", EGSR 2014). The
//! rotation is done in sample space, before the warp, as pbrt-v4 (`SampleVisible`) and Mitsuba 3
//! (`sample_shifted`) do, so each of the four is distributed by p(λ) on its own and the four are stratified
//! in the CDF.
//!
//! ```
//! use gonio::spectrum::wavelengths::{visible_wavelength_pdf, SampledWavelengths};
//! let swl = SampledWavelengths::sample_visible(0.3);
//! assert!((swl.lambda()[0] - 493.685_6).abs() < 1e-3); // Mitsuba 3: sample_rgb_spectrum(0.3)
//! assert_eq!(swl.pdf()[1], visible_wavelength_pdf(swl.lambda()[1]));
//! ```

use crate::math::lanes::Real;
use crate::numerics::exp_log::{atanh, exp_neg};

/// Shortest sampled wavelength, in nm (the CIE 1931 tables' first node).
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest sampled wavelength, in nm (the CIE 1931 tables' last node).
pub const LAMBDA_MAX: f32 = 830.0;
/// Number of wavelengths a path carries.
pub const N_WAVELENGTHS: usize = 4;

/// k of the visible-importance density, in nm⁻¹ (Radziszewski et al. 2009).
const VISIBLE_K: f32 = 0.0072;
/// λ₀, the centre of the visible-importance density, in nm.
const VISIBLE_CENTER: f32 = 538.0;
/// t₀ = tanh(k (360 − 538)), in f64: −0.856910625469828.
const VISIBLE_T0: f64 = -0.856_910_625_469_828;
/// t₁ − t₀ = tanh(k (830 − 538)) − t₀, in f64: 1.8275019724100978.
const VISIBLE_T_RANGE: f64 = 1.827_501_972_410_097_8;
/// A = k / (t₁ − t₀), the density's normalisation, in nm⁻¹.
#[allow(clippy::cast_possible_truncation)] // the f32 rounding of the f64 constant is intended
const VISIBLE_NORM: f32 = (0.0072 / VISIBLE_T_RANGE) as f32;

/// Draws one wavelength (nm) from the visible-importance density p(λ) (module docs) by inverting its CDF
/// (atanh by [`atanh`]: within 3·10⁻⁴ nm of the exact inverse by its bound), in lanes. `uc` ∈ [0, 1]; the
/// result lies in [[`LAMBDA_MIN`], [`LAMBDA_MAX`]] (clamped against f32 rounding).
#[inline]
#[must_use]
pub fn sample_visible_wavelength<R: Real>(uc: R) -> R {
    #[allow(clippy::cast_possible_truncation)]
    let (t0, range) = (VISIBLE_T0 as f32, VISIBLE_T_RANGE as f32);
    let lambda = atanh(uc * range + t0) / VISIBLE_K + VISIBLE_CENTER;
    // atanh of the f32 argument can land a fraction of an ulp outside the range at uc = 0 or 1.
    lambda.clamp(LAMBDA_MIN, LAMBDA_MAX)
}

/// The visible-importance density p(λ) in nm⁻¹: A / cosh²(k (λ − 538)) on [360, 830] nm, zero outside
/// (and for NaN).
#[inline]
#[must_use]
pub fn visible_wavelength_pdf<R: Real>(lambda: R) -> R {
    let inside = lambda.ge(R::splat(LAMBDA_MIN)) & lambda.le(R::splat(LAMBDA_MAX));
    // cosh z = (e^|z| + e^−|z|)/2, |z| ≤ 2.2 on the range.
    let e = exp_neg(-((lambda - VISIBLE_CENTER) * VISIBLE_K).abs());
    let c = (R::splat(1.0) / e + e) * 0.5;
    R::select(inside, R::splat(VISIBLE_NORM) / (c * c), R::splat(0.0))
}

/// The inverse of [`sample_visible_wavelength`]: the CDF P(λ) of the visible-importance density, i.e. the
/// `uc` that samples `lambda`. Clamped to [0, 1] for λ outside [360, 830] nm.
#[inline]
#[must_use]
pub fn invert_visible_wavelength_sample(lambda: f32) -> f32 {
    #[allow(clippy::cast_possible_truncation)]
    let (t0, range) = (VISIBLE_T0 as f32, VISIBLE_T_RANGE as f32);
    (((VISIBLE_K * (lambda - VISIBLE_CENTER)).tanh() - t0) / range).clamp(0.0, 1.0)
}

/// Draws one wavelength uniformly on [360, 830] nm (the reference strategy; its pdf is 1/470 nm⁻¹).
#[inline]
#[must_use]
pub fn sample_uniform_wavelength(uc: f32) -> f32 {
    debug_assert!((0.0..=1.0).contains(&uc), "uc = {uc} is not in [0, 1]");
    (LAMBDA_MIN + uc * (LAMBDA_MAX - LAMBDA_MIN)).min(LAMBDA_MAX)
}

/// The `N_WAVELENGTHS` stratified samples `uc + i/4` (i = 0 … 3), wrapped to [0, 1); entry 0 is `uc`.
#[inline]
#[must_use]
pub fn rotated_samples(uc: f32) -> [f32; N_WAVELENGTHS] {
    std::array::from_fn(|i| {
        #[allow(clippy::cast_precision_loss)]
        let u = uc + i as f32 / N_WAVELENGTHS as f32;
        // uc ∈ [0, 1] gives u ∈ [0, 1.75]: one wrap suffices; uc = 1 stays 1 for the hero.
        if u > 1.0 {
            u - 1.0
        } else {
            u
        }
    })
}

/// The wavelengths a path carries and the density each was drawn with.
///
/// A `pdf` of 0 marks a wavelength that no longer contributes (see [`Self::terminate_secondary`]); the film
/// ([`super::observer`]) skips it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    lambda: [f32; N_WAVELENGTHS],
    pdf: [f32; N_WAVELENGTHS],
}

impl SampledWavelengths {
    /// Four stratified wavelengths from one sample `uc` ∈ [0, 1] with the visible-importance density: the
    /// hero at `uc`, the others at `uc + i/4` wrapped (module docs).
    #[must_use]
    pub fn sample_visible(uc: f32) -> Self {
        let lambda = rotated_samples(uc).map(sample_visible_wavelength);
        SampledWavelengths { lambda, pdf: lambda.map(visible_wavelength_pdf) }
    }

    /// Four stratified wavelengths uniform on [360, 830] nm (pdf 1/470 nm⁻¹ each).
    #[must_use]
    pub fn sample_uniform(uc: f32) -> Self {
        let lambda = rotated_samples(uc).map(sample_uniform_wavelength);
        SampledWavelengths { lambda, pdf: [1.0 / (LAMBDA_MAX - LAMBDA_MIN); N_WAVELENGTHS] }
    }

    /// Given wavelengths and densities, e.g. to evaluate at fixed wavelengths (a density of 1 per
    /// wavelength and a radiance of `L(λ)` makes the film's estimate a plain sum).
    #[must_use]
    pub fn new(lambda: [f32; N_WAVELENGTHS], pdf: [f32; N_WAVELENGTHS]) -> Self {
        debug_assert!(pdf.iter().all(|p| *p >= 0.0), "densities must be non-negative: {pdf:?}");
        SampledWavelengths { lambda, pdf }
    }

    /// The wavelengths, in nm; entry 0 is the hero.
    #[inline]
    #[must_use]
    pub fn lambda(&self) -> [f32; N_WAVELENGTHS] {
        self.lambda
    }

    /// The density each wavelength was drawn with, in nm⁻¹ (0 for a terminated wavelength).
    #[inline]
    #[must_use]
    pub fn pdf(&self) -> [f32; N_WAVELENGTHS] {
        self.pdf
    }

    /// Keeps only the hero wavelength, for a path that has met a wavelength-dependent event it cannot
    /// follow for all four at once (a dispersive refraction). pbrt-v4's rule (`TerminateSecondary`): the
    /// secondaries' densities become 0, and the hero's is divided by 4 — the film averages over the four
    /// slots, so the hero's estimate L/(p/4)/4 = L/p stays unbiased on its own. Idempotent.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for p in &mut self.pdf[1..] {
            *p = 0.0;
        }
        #[allow(clippy::cast_precision_loss)]
        let n = N_WAVELENGTHS as f32;
        self.pdf[0] /= n;
    }

    /// Whether [`Self::terminate_secondary`] has been applied (every secondary density is 0).
    #[inline]
    #[must_use]
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}
