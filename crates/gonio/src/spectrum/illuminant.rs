//! Light spectra — CIE standard illuminant D65 and Planck's blackbody — and [`Spectrum`], a function of
//! wavelength of any of the kinds a scene gives.
//!
//! | kind | value at λ (nm) | parameters |
//! |---|---|---|
//! | [`Spectrum::Constant`] | v | v |
//! | [`Spectrum::Tabulated`] | linear interpolation of (λ, value) pairs, 0 outside | a [`PiecewiseLinear`] |
//! | [`Spectrum::Reflectance`], [`Spectrum::Unbounded`], [`Spectrum::Illuminant`] | an RGB colour upsampled by Jakob & Hanika 2019 ([`super::upsample`]); the last times D65 | — |
//! | [`Spectrum::Blackbody`] | Planck's law B(λ, T), scaled | a [`Blackbody`] |
//! | [`Spectrum::D65`] | `scale` × [`d65`] (D65 with luminance 1) | scale |
//!
//! **D65** is tabulated every 5 nm from 300 to 830 nm, the values of CIE 015:2004 *Colorimetry*, 3rd ed.,
//! Table T.1 (CIE S 014-2 / ISO 11664-2 gives the same at 5 nm; 100 at 560 nm), linearly interpolated and 0
//! outside. [`d65`] scales it to luminance 1, Y = ∫ d65(λ) ȳ(λ) dλ · `CIE_Y_NORMALIZATION` = 1 over
//! [360, 830] nm (1/∫ȳ as Mitsuba 3 defines it), so that a white (1, 1, 1) emitter is D65 of luminance 1,
//! as Mitsuba 3's `d65` spectrum is (its `MI_CIE_D65_NORMALIZATION`). The factor is the exact integral of
//! the product of the two piecewise-linear tables ([`d65_normalization`]).
//!
//! **Blackbody**: Planck's law for the spectral radiance of a black body at temperature T,
//! B(λ, T) = 2hc² / λ⁵ / (exp(hc / (λ k_B T)) − 1), with the 2019 SI values of h, c and k_B, in
//! W·m⁻²·sr⁻¹·nm⁻¹ — the units and range of Mitsuba 3's `blackbody` spectrum (0 outside [360, 830] nm).
//!
//! ```
//! use gonio::spectrum::illuminant::{d65, Blackbody, BlackbodyNormalization, Spectrum};
//! assert!((d65(560.0) / d65(300.0) - 100.0 / 0.0341).abs() < 1e-6 * 2932.0);
//! let sun = Spectrum::Blackbody(Blackbody::new(5778.0, BlackbodyNormalization::PeakOne));
//! assert!(sun.eval(501.5) > 0.999);
//! ```

use std::sync::OnceLock;

use crate::math::lanes::Real;

use super::cie::{cie1931_xyz, CIE1931_XYZ, CIE_MAX, CIE_MIN, CIE_SAMPLES, CIE_Y_NORMALIZATION};
use super::piecewise::PiecewiseLinear;
use super::upsample::{RgbIlluminantSpectrum, RgbReflectanceSpectrum, RgbUnboundedSpectrum};

/// First wavelength of [`D65_TABLE`], nm.
pub const D65_MIN: f64 = 300.0;
/// Last wavelength of [`D65_TABLE`], nm.
pub const D65_MAX: f64 = 830.0;
/// Node spacing of [`D65_TABLE`], nm.
pub const D65_STEP: f64 = 5.0;

/// CIE standard illuminant D65 at 300, 305, …, 830 nm (CIE 015:2004 Table T.1; relative, 100 at 560 nm).
#[rustfmt::skip]
pub const D65_TABLE: [f64; 107] = [
    0.0341, 1.6643, 3.2945, 11.7652, 20.236, 28.6447, 37.0535, 38.5011, 39.9488, 42.4302, // 300–345
    44.9117, 45.775, 46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, // 350–395
    82.7549, 87.1204, 91.486, 92.4589, 93.4318, 90.057, 86.6823, 95.7736, 104.865, 110.936, // 400–445
    117.008, 117.41, 117.812, 116.336, 114.861, 115.392, 115.923, 112.367, 108.811, 109.082, // 450–495
    109.354, 108.578, 107.802, 106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, // 500–545
    104.046, 102.023, 100.0, 98.1671, 96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, // 550–595
    90.0062, 89.8026, 89.5991, 88.6489, 87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, // 600–645
    80.0268, 80.1207, 80.2146, 81.2462, 82.2778, 80.281, 78.2842, 74.0027, 69.7213, 70.6652, // 650–695
    71.6091, 72.979, 74.349, 67.9765, 61.604, 65.7448, 69.8856, 72.4863, 75.087, 69.3398, // 700–745
    63.5927, 55.0054, 46.4182, 56.6118, 66.8054, 65.0941, 63.3828, 63.8434, 64.304, 61.8779, // 750–795
    59.4519, 55.7054, 51.959, 54.6998, 57.4406, 58.8765, 60.3125, // 800–830
];

/// D65 as tabulated (100 at 560 nm), linearly interpolated; 0 outside [300, 830] nm and for NaN.
#[must_use]
pub fn d65_relative(lambda: f64) -> f64 {
    if !(D65_MIN..=D65_MAX).contains(&lambda) {
        return 0.0;
    }
    let t = (lambda - D65_MIN) / D65_STEP;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // t ∈ [0, 106]
    let i0 = (t as usize).min(D65_TABLE.len() - 2);
    let w1 = t - i0 as f64;
    (1.0 - w1).mul_add(D65_TABLE[i0], w1 * D65_TABLE[i0 + 1])
}

/// The factor that gives D65 a luminance of 1: 1 / (∫ D65 ȳ dλ · `CIE_Y_NORMALIZATION`) over [360, 830] nm,
/// the integral exact for the two piecewise-linear tables (their nodes coincide every 5 nm there). About
/// 0.0101013; Mitsuba 3's `MI_CIE_D65_NORMALIZATION` is 0.010101273599490354.
#[must_use]
pub fn d65_normalization() -> f64 {
    static NORMALIZATION: OnceLock<f64> = OnceLock::new();
    *NORMALIZATION.get_or_init(|| {
        // ∫ of a product of two linear functions over a step h: h/6 (2 a₀b₀ + a₀b₁ + a₁b₀ + 2 a₁b₁).
        let h = (CIE_MAX - CIE_MIN) / (CIE_SAMPLES - 1) as f64;
        let mut integral = 0.0;
        for i in 0..CIE_SAMPLES - 1 {
            let lambda = CIE_MIN + h * i as f64;
            let (a0, a1) = (d65_relative(lambda), d65_relative(lambda + h));
            let (b0, b1) = (f64::from(CIE1931_XYZ[i][1]), f64::from(CIE1931_XYZ[i + 1][1]));
            integral += h / 6.0 * (2.0 * a0 * b0 + a0 * b1 + a1 * b0 + 2.0 * a1 * b1);
        }
        1.0 / (integral * CIE_Y_NORMALIZATION)
    })
}

/// D65 with luminance 1 ([`d65_relative`] × [`d65_normalization`]): the spectrum of a white emitter.
#[must_use]
pub fn d65(lambda: f64) -> f64 {
    d65_relative(lambda) * d65_normalization()
}

/// [`d65`] in `f32` lanes, for a renderer's wavelengths: the table times the normalisation, rounded to `f32`
/// once, and interpolated in `f32` (within 10⁻⁶ of [`d65`]'s peak: the position between two nodes is found
/// in `f32`, to a few 10⁻⁶ nm); 0 outside [300, 830] nm and for NaN.
#[inline(always)]
#[must_use]
pub fn d65_at<R: Real>(lambda: R) -> R {
    static TABLE: OnceLock<[f32; D65_TABLE.len()]> = OnceLock::new();
    #[allow(clippy::cast_possible_truncation)]
    let table = TABLE.get_or_init(|| D65_TABLE.map(|v| (v * d65_normalization()) as f32));
    #[allow(clippy::cast_possible_truncation)]
    let (lo, hi) = (D65_MIN as f32, D65_MAX as f32);
    let inside = lambda.ge(R::splat(lo)) & lambda.le(R::splat(hi));
    R::select(inside, ((lambda - lo) / (hi - lo)).lerp_table(table), R::splat(0.0))
}

/// Planck constant h, J·s (SI 2019, exact).
const PLANCK: f64 = 6.626_070_15e-34;
/// Speed of light c, m/s (exact).
const SPEED_OF_LIGHT: f64 = 299_792_458.0;
/// Boltzmann constant k_B, J/K (SI 2019, exact).
const BOLTZMANN: f64 = 1.380_649e-23;
/// Wien's displacement constant b, m·K: the peak of B(λ, T) is at b / T.
const WIEN: f64 = 2.897_771_955e-3;

/// Planck's law: the spectral radiance of a black body at `temperature` K and `lambda` nm, in
/// W·m⁻²·sr⁻¹·nm⁻¹ (0 for T ≤ 0 or λ ≤ 0).
#[must_use]
pub fn planck(lambda: f64, temperature: f64) -> f64 {
    if !(temperature > 0.0) || !(lambda > 0.0) {
        return 0.0;
    }
    let l = lambda * 1e-9;
    // exp_m1 keeps precision where hc/(λkT) is small (long wavelengths, hot bodies).
    let denominator = l.powi(5) * (PLANCK * SPEED_OF_LIGHT / (l * BOLTZMANN * temperature)).exp_m1();
    2.0 * PLANCK * SPEED_OF_LIGHT * SPEED_OF_LIGHT / denominator * 1e-9
}

/// How a [`Spectrum::Blackbody`] is scaled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlackbodyNormalization {
    /// Absolute spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹, 0 outside [360, 830] nm: Mitsuba 3's `blackbody`.
    Radiance,
    /// Divided by its maximum over all wavelengths (Wien's peak λ = b/T), so the peak is 1: pbrt-v4's
    /// `BlackbodySpectrum`. Not cut to [360, 830] nm.
    PeakOne,
    /// Scaled to luminance 1 (Y = ∫ B ȳ dλ · `CIE_Y_NORMALIZATION` = 1 over [360, 830] nm), like [`d65`],
    /// so a blackbody emitter differs from a D65 one only in colour.
    LuminanceOne,
}

/// ∫ B ȳ dλ over [360, 830] nm by Simpson's rule on 0.5 nm steps (ȳ is linear on each 5 nm interval and B
/// smooth, so the rule's error is far below f32 rounding).
fn blackbody_luminance_integral(temperature: f64) -> f64 {
    let n = 940; // an even number of 0.5 nm steps over [360, 830]
    let h = (CIE_MAX - CIE_MIN) / f64::from(n);
    let mut sum = 0.0;
    for i in 0..=n {
        let lambda = CIE_MIN + h * f64::from(i);
        let weight = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        sum += weight * planck(lambda, temperature) * cie1931_xyz(lambda)[1];
    }
    sum * h / 3.0
}

/// Planck's law at a temperature, scaled as a [`BlackbodyNormalization`] says (the factor computed once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blackbody {
    temperature: f64,
    normalization: BlackbodyNormalization,
    /// What B is multiplied by.
    factor: f64,
}

impl Blackbody {
    /// A black body at `temperature` K (Mitsuba's `temperature`). A temperature ≤ 0 or NaN gives a
    /// spectrum that is 0 everywhere.
    #[must_use]
    pub fn new(temperature: f64, normalization: BlackbodyNormalization) -> Self {
        let factor = match normalization {
            BlackbodyNormalization::Radiance => 1.0,
            BlackbodyNormalization::PeakOne => 1.0 / planck(WIEN / temperature * 1e9, temperature),
            BlackbodyNormalization::LuminanceOne => 1.0 / (blackbody_luminance_integral(temperature) * CIE_Y_NORMALIZATION),
        };
        // A zero temperature makes the factors 1/0: keep the spectrum 0, not NaN.
        let factor = if factor.is_finite() { factor } else { 0.0 };
        Blackbody { temperature, normalization, factor }
    }

    /// The temperature, K.
    #[must_use]
    pub fn temperature(&self) -> f64 {
        self.temperature
    }

    /// The normalisation.
    #[must_use]
    pub fn normalization(&self) -> BlackbodyNormalization {
        self.normalization
    }

    /// The scaled radiance at `lambda` nm (0 outside [360, 830] nm unless [`BlackbodyNormalization::PeakOne`]).
    #[must_use]
    pub fn eval(&self, lambda: f64) -> f64 {
        let cut = self.normalization != BlackbodyNormalization::PeakOne;
        if cut && !(CIE_MIN..=CIE_MAX).contains(&lambda) {
            return 0.0;
        }
        planck(lambda, self.temperature) * self.factor
    }
}

/// A function of wavelength (nm), of the kinds a scene file gives (module docs).
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f64),
    /// (λ, value) pairs, linearly interpolated, 0 outside the table.
    Tabulated(PiecewiseLinear),
    /// A bounded RGB reflectance upsampled to a spectrum in [0, 1].
    Reflectance(RgbReflectanceSpectrum),
    /// An unbounded RGB value (an index, a scale) upsampled: scale × a sigmoid polynomial.
    Unbounded(RgbUnboundedSpectrum),
    /// An RGB emission upsampled: scale × a sigmoid polynomial × [`d65`].
    Illuminant(RgbIlluminantSpectrum),
    /// Planck's law, scaled.
    Blackbody(Blackbody),
    /// `scale` × [`d65`].
    D65 { scale: f64 },
}

impl Spectrum {
    /// The value at `lambda` nm.
    #[must_use]
    pub fn eval(&self, lambda: f64) -> f64 {
        #[allow(clippy::cast_possible_truncation)] // the upsampled spectra are f32 functions
        let lambda_f32 = lambda as f32;
        match self {
            Spectrum::Constant(v) => *v,
            Spectrum::Tabulated(table) => table.eval(lambda),
            Spectrum::Reflectance(s) => f64::from(s.eval(lambda_f32)),
            Spectrum::Unbounded(s) => f64::from(s.eval(lambda_f32)),
            Spectrum::Illuminant(s) => f64::from(s.eval(lambda_f32)),
            Spectrum::Blackbody(b) => b.eval(lambda),
            Spectrum::D65 { scale } => scale * d65(lambda),
        }
    }
}
