//! What the film records of a spectral path: the CIE 1931 observer's estimate of the path's colour from
//! its four sampled wavelengths, as linear sRGB.
//!
//! A pixel's colour is the integral of its radiance against the colour-matching functions,
//! XYZ = ∫ L(λ) (x̄, ȳ, z̄)(λ) dλ · `CIE_Y_NORMALIZATION`, with Mitsuba 3's constant (1/∫ȳ as its
//! 1000-point sum gives it, so L = 1 everywhere has Y = 1000/999 by the exact integral). A
//! path carrying wavelengths λᵢ drawn with densities pᵢ ([`SampledWavelengths`]) estimates it without
//! bias by the average over its wavelengths of the one-sample estimates
//!
//! ```text
//! XYZ ≈ (1/4) Σᵢ L(λᵢ) (x̄, ȳ, z̄)(λᵢ) / pᵢ · CIE_Y_NORMALIZATION
//! ```
//!
//! — each term alone is an unbiased estimate, so a terminated wavelength (pᵢ = 0, see
//! [`SampledWavelengths::terminate_secondary`]) contributes nothing and the hero's density, divided by 4,
//! keeps the sum unbiased. The estimate goes to linear sRGB through
//! [`super::named::xyz_to_linear_srgb`]. This is Mitsuba 3's film conversion (`spectrum_to_srgb`, which
//! receives L/p: its sensor folds 1/p into the path weight) and pbrt-v4's `SampledSpectrum::ToXYZ`.
//!
//! Conventions. A radiance of 1 at every wavelength is the *equal-energy* white E, linear sRGB
//! ≈ (1.2049, 0.9482, 0.9093), not (1, 1, 1); what renders as (1, 1, 1) is D65 of luminance 1
//! ([`super::illuminant::d65`]) — the spectrum of a white RGB emitter, and of a white reflectance lit by
//! one — as in Mitsuba 3's spectral variants.
//!
//! ```
//! use gonio::spectrum::observer::sampled_to_linear_srgb;
//! use gonio::spectrum::wavelengths::SampledWavelengths;
//! let swl = SampledWavelengths::sample_visible(0.3);
//! let rgb = sampled_to_linear_srgb(&swl, [1.0, 0.5, 0.25, 2.0]);
//! assert!((rgb.g() - 0.648_573).abs() < 1e-5); // Mitsuba 3.9.1's spectrum_to_srgb(L / p, λ)
//! ```

use super::cie::{cie1931_xyz, CIE_Y_NORMALIZATION};
use super::named::xyz_to_linear_srgb;
use super::wavelengths::{SampledWavelengths, N_WAVELENGTHS};
use super::Rgb;

/// The film's XYZ estimate from one path's radiance at its sampled wavelengths (module docs). Wavelengths
/// with density 0 are skipped; a non-finite radiance propagates (the film's NaN checks see it).
#[must_use]
pub fn sampled_to_xyz(wavelengths: &SampledWavelengths, radiance: [f32; N_WAVELENGTHS]) -> [f64; 3] {
    wavelengths_to_xyz(wavelengths.lambda(), wavelengths.pdf(), radiance)
}

/// [`sampled_to_xyz`] for any number of wavelengths `lambda` drawn with densities `pdf` (the estimate's
/// average is over all `N`, terminated ones included).
#[must_use]
pub fn wavelengths_to_xyz<const N: usize>(lambda: [f32; N], pdf: [f32; N], radiance: [f32; N]) -> [f64; 3] {
    let mut xyz = [0.0_f64; 3];
    for ((lambda, pdf), l) in lambda.into_iter().zip(pdf).zip(radiance) {
        if pdf == 0.0 {
            continue;
        }
        let weight = f64::from(l) / f64::from(pdf);
        let cmf = cie1931_xyz(f64::from(lambda));
        for c in 0..3 {
            xyz[c] += weight * cmf[c];
        }
    }
    #[allow(clippy::cast_precision_loss)]
    let scale = CIE_Y_NORMALIZATION / N as f64;
    xyz.map(|v| v * scale)
}

/// [`sampled_to_xyz`] as linear sRGB (unclamped: a single path's estimate may be negative in a channel).
#[must_use]
pub fn sampled_to_linear_srgb(wavelengths: &SampledWavelengths, radiance: [f32; N_WAVELENGTHS]) -> Rgb {
    #[allow(clippy::cast_possible_truncation)]
    Rgb(xyz_to_linear_srgb(sampled_to_xyz(wavelengths, radiance)).map(|v| v as f32))
}
