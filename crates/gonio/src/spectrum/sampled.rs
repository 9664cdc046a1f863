//! What a path carries in the renderer's spectral mode, and the conversions at the places its values are
//! used.
//!
//! A path carries [`PATH_WAVELENGTHS`] = 3 wavelengths in the three channels the renderer's lanes hold
//! (its throughput, its radiance, every model's values): the hero-wavelength method of Wilkie et al.
//! (EGSR 2014) with three wavelengths in place of their four, stratified in sample space as
//! [`super::wavelengths`] describes (`uc + i/3` wrapped) and each drawn with the visible-importance
//! density. Each of the three is an unbiased estimate on its own. Three where Mitsuba 3 and pbrt-v4 carry
//! four gives a path's colour estimate far more variance (2–35× per sRGB channel for a flat spectrum), so
//! the path tracer stratifies `uc` over a pixel's samples instead (`integrator::wavelength_stratum`): the
//! channels are there in RGB mode already, and a pixel's colour noise ends up below four independent
//! wavelengths per path (docs/spectral.md).
//!
//! RGB values are taken to spectra where they are used, by the Jakob & Hanika 2019 sigmoid polynomial of
//! the process-wide table ([`super::upsample::srgb_table`], its trilinear `fetch`, as Mitsuba 3 looks its
//! table up at run time):
//! - a reflectance (a `diffuse` surface's colour, constant or textured) as the bounded spectrum of its
//!   colour clamped to [0, 1] ([`reflectance_at`]);
//! - emission as Mitsuba 3's RGB illuminant: 2·max(rgb) × the polynomial of rgb / (2·max) × D65 of
//!   luminance 1 ([`emission_at`]). It is linear in a scale factor, so emission already multiplied by a
//!   light's falloff, a distance or an MIS weight converts to the same spectrum times that factor.

use super::illuminant::d65_at;
use super::named::xyz_to_linear_srgb;
use super::observer::wavelengths_to_xyz;
use super::upsample::srgb_table;
use super::wavelengths::{sample_visible_wavelength, visible_wavelength_pdf};
use super::Rgb;
use crate::math::lanes::Real;

/// Wavelengths per path in spectral mode (module docs).
pub const PATH_WAVELENGTHS: usize = 3;

/// A path's wavelengths (nm, the hero first) and the density of each (nm⁻¹) from one sample `uc` ∈ [0, 1],
/// in lanes.
#[inline(always)]
#[must_use]
pub fn sample_path_wavelengths<R: Real>(uc: R) -> ([R; PATH_WAVELENGTHS], [R; PATH_WAVELENGTHS]) {
    let lambda: [R; PATH_WAVELENGTHS] = std::array::from_fn(|i| {
        #[allow(clippy::cast_precision_loss)]
        let u = uc + i as f32 / PATH_WAVELENGTHS as f32;
        sample_visible_wavelength(R::select(u.gt(R::splat(1.0)), u - 1.0, u))
    });
    (lambda, lambda.map(visible_wavelength_pdf))
}

/// A reflectance `rgb` (clamped to [0, 1]) at the wavelengths `lambda`.
#[inline]
#[must_use]
pub fn reflectance_at(rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        // A grey is flat: its polynomial is a constant (and the table's is within its rounding of it).
        return [rgb[0].clamp(0.0, 1.0); PATH_WAVELENGTHS];
    }
    let polynomial = srgb_table().fetch(Rgb(rgb));
    lambda.map(|l| polynomial.eval(l))
}

/// Emission `rgb` (any values; negative ones count as 0, NaN stays NaN) at the wavelengths `lambda`: Mitsuba
/// 3's spectrum of an RGB emitter (module docs), [`unbounded_at`] times D65.
#[inline]
#[must_use]
pub fn emission_at(rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
    let s = unbounded_at(rgb, lambda);
    std::array::from_fn(|c| s[c] * d65_at(lambda[c]))
}

/// An unbounded value `rgb` (negative components count as 0, NaN stays NaN) at the wavelengths `lambda`:
/// 2·max(rgb) times the sigmoid polynomial of rgb / (2·max), a grey exactly flat.
#[inline]
#[must_use]
pub fn unbounded_at(rgb: [f32; 3], lambda: [f32; PATH_WAVELENGTHS]) -> [f32; PATH_WAVELENGTHS] {
    if rgb.iter().any(|v| v.is_nan()) {
        return [f32::NAN; PATH_WAVELENGTHS];
    }
    let rgb = rgb.map(|v| v.max(0.0));
    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        // A grey's polynomial is flat at 1/2.
        return [rgb[0]; PATH_WAVELENGTHS];
    }
    let scale = 2.0 * rgb[0].max(rgb[1]).max(rgb[2]);
    if !scale.is_finite() {
        return [f32::INFINITY; PATH_WAVELENGTHS];
    }
    let polynomial = srgb_table().fetch(Rgb(rgb.map(|v| v / scale)));
    lambda.map(|l| scale * polynomial.eval(l))
}

/// What the film records of a path: its radiance at its wavelengths as linear sRGB (the CIE 1931 observer's
/// estimate, [`super::observer`]).
#[must_use]
pub fn path_to_linear_srgb(lambda: [f32; PATH_WAVELENGTHS], pdf: [f32; PATH_WAVELENGTHS], radiance: [f32; PATH_WAVELENGTHS]) -> Rgb {
    #[allow(clippy::cast_possible_truncation)]
    Rgb(xyz_to_linear_srgb(wavelengths_to_xyz(lambda, pdf, radiance)).map(|v| v as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The film's average over `n` paths whose wavelengths are stratified in `uc`, of radiance `l(λ)`.
    fn film_mean(n: usize, l: impl Fn([f32; 3]) -> [f32; 3]) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for i in 0..n {
            #[allow(clippy::cast_precision_loss)]
            let (lambda, pdf) = sample_path_wavelengths((i as f32 + 0.5) / n as f32);
            let rgb = path_to_linear_srgb(lambda, pdf, l(lambda));
            for (s, v) in sum.iter_mut().zip(rgb.0) {
                *s += f64::from(v);
            }
        }
        #[allow(clippy::cast_precision_loss)]
        sum.map(|v| v / n as f64)
    }

    #[test]
    fn path_wavelengths_are_stratified_hero_rotations() {
        let (lambda, pdf) = sample_path_wavelengths(0.2);
        let u = [0.2f32, 0.2 + 1.0 / 3.0, 0.2 + 2.0 / 3.0];
        // (Within rounding: the inlined copies may fuse their multiplies and adds differently.)
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * b.abs();
        for c in 0..3 {
            assert!(close(lambda[c], sample_visible_wavelength(u[c])), "{lambda:?}");
            assert!(close(pdf[c], visible_wavelength_pdf(lambda[c])), "{pdf:?}");
        }
        assert!(lambda[0] < lambda[1] && lambda[1] < lambda[2], "{lambda:?}");
        // Wrapped past 1.
        let (lambda, _) = sample_path_wavelengths(0.9);
        assert!(close(lambda[1], sample_visible_wavelength(0.9 + 1.0 / 3.0 - 1.0)), "{lambda:?}");
    }

    #[test]
    fn white_emission_films_as_white_and_grey_reflectance_as_grey() {
        // A white RGB emitter is D65 of luminance 1: linear sRGB (1, 1, 1) (Mitsuba 3's convention).
        let white = film_mean(20_000, |lambda| emission_at([1.0, 1.0, 1.0], lambda));
        for c in white {
            assert!((c - 1.0).abs() < 2e-3, "{white:?}");
        }
        // Lit by it, a grey reflectance 0.3 gives 0.3 (its spectrum is flat: exactly 0.3 at every λ).
        assert_eq!(reflectance_at([0.3; 3], [400.0, 550.0, 700.0]), [0.3; 3]);
        let grey = film_mean(20_000, |lambda| {
            let (e, r) = (emission_at([1.0; 3], lambda), reflectance_at([0.3; 3], lambda));
            std::array::from_fn(|c| e[c] * r[c])
        });
        for c in grey {
            assert!((c - 0.3).abs() < 1e-3, "{grey:?}");
        }
    }

    #[test]
    fn colours_come_back_through_the_observer() {
        // RGB → spectrum → film within the table lookup's precision (docs/spectral.md: worst 6e-3 over the
        // gamut), for emitters of any scale and for reflectances under a white light.
        for rgb in [[0.8f32, 0.1, 0.1], [0.1, 0.6, 0.2], [0.2, 0.3, 0.9], [0.9, 0.9, 0.2], [0.05, 0.02, 0.01]] {
            for scale in [1.0f32, 25.0] {
                let e = rgb.map(|v| v * scale);
                let back = film_mean(20_000, |lambda| emission_at(e, lambda));
                for c in 0..3 {
                    assert!((back[c] - f64::from(e[c])).abs() < 1e-2 * f64::from(scale), "emission {e:?} → {back:?}");
                }
            }
            let back = film_mean(20_000, |lambda| {
                let (w, r) = (emission_at([1.0; 3], lambda), reflectance_at(rgb, lambda));
                std::array::from_fn(|c| w[c] * r[c])
            });
            for c in 0..3 {
                assert!((back[c] - f64::from(rgb[c])).abs() < 1e-2, "reflectance {rgb:?} → {back:?}");
            }
        }
    }

    #[test]
    fn emission_scales_linearly_and_keeps_nan() {
        let lambda = [420.0, 555.0, 680.0];
        let (a, b) = (emission_at([0.7, 0.2, 0.4], lambda), emission_at([7.0, 2.0, 4.0], lambda));
        for c in 0..3 {
            assert!((b[c] - 10.0 * a[c]).abs() <= 1e-5 * b[c], "{a:?} {b:?}");
        }
        assert!(emission_at([f32::NAN, 0.0, 0.0], lambda).iter().all(|v| v.is_nan()));
        assert_eq!(emission_at([0.0; 3], lambda), [0.0; 3]);
        assert_eq!(emission_at([-1.0, 0.0, 0.0], lambda), [0.0; 3]);
    }
}
