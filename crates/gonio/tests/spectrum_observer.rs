//! The film's spectral → RGB estimate (`gonio::spectrum::observer`): Mitsuba 3.9.1's `spectrum_to_srgb`
//! on the same wavelengths, and the conventions of what integrates to which white, by Monte Carlo over
//! hero-wavelength samples.

use gonio::sampling::rng::Pcg32;
use gonio::spectrum::cie::{CIE1931_XYZ, CIE_Y_NORMALIZATION};
use gonio::spectrum::illuminant::d65;
use gonio::spectrum::named::{spectrum_to_rgb, xyz_to_linear_srgb};
use gonio::spectrum::observer::{sampled_to_linear_srgb, sampled_to_xyz};
use gonio::spectrum::upsample::{RgbIlluminantSpectrum, RgbReflectanceSpectrum};
use gonio::spectrum::wavelengths::SampledWavelengths;
use gonio::spectrum::Rgb;

/// Mitsuba 3.9.1, the four wavelengths of sample 0.3 and a radiance (1, 0.5, 0.25, 2):
/// ```text
/// python -c "import mitsuba as mi; mi.set_variant('scalar_spectral'); \
///   l, w = mi.sample_rgb_spectrum(mi.Spectrum([0.3, 0.55, 0.8, 0.05])); L = mi.Spectrum([1., .5, .25, 2.]); \
///   print(l, w, mi.spectrum_to_xyz(L * w, l), mi.spectrum_to_srgb(L * w, l))"
/// ```
const MITSUBA_LAMBDA: [f64; 4] = [493.685_607_910_156_25, 558.738_220_214_843_8, 635.380_554_199_218_8, 397.798_248_291_015_6];
const MITSUBA_XYZ: [f64; 3] = [0.345_029_443_502_426_15, 0.514_957_427_978_515_6, 0.407_629_132_270_813];
const MITSUBA_SRGB: [f64; 3] = [0.123_276_457_190_513_61, 0.648_572_981_357_574_5, 0.345_117_479_562_759_4];

#[test]
fn matches_mitsuba_spectrum_to_srgb() {
    let swl = SampledWavelengths::sample_visible(0.3);
    for (got, want) in swl.lambda().iter().zip(MITSUBA_LAMBDA) {
        assert!((f64::from(*got) - want).abs() < 1e-3, "{got} vs {want}");
    }
    let radiance = [1.0, 0.5, 0.25, 2.0];
    let xyz = sampled_to_xyz(&swl, radiance);
    let rgb = sampled_to_linear_srgb(&swl, radiance);
    for c in 0..3 {
        // Mitsuba works in f32 throughout.
        assert!((xyz[c] / MITSUBA_XYZ[c] - 1.0).abs() < 2e-5, "XYZ {xyz:?} vs {MITSUBA_XYZ:?}");
        assert!((f64::from(rgb.0[c]) - MITSUBA_SRGB[c]).abs() < 1e-5, "sRGB {rgb} vs {MITSUBA_SRGB:?}");
    }
}

/// The mean of the film's estimate over `n` paths, each with its own hero sample, for the radiance
/// `spectrum`; optionally with the secondaries terminated.
fn mean_estimate(n: usize, terminate: bool, spectrum: impl Fn(f32) -> f32) -> [f64; 3] {
    let mut rng = Pcg32::new(17, 1);
    let mut sum = [0.0; 3];
    for i in 0..n {
        // Stratified hero samples, jittered.
        let uc = ((i as f32 + rng.next_f32()) / n as f32).min(1.0);
        let mut swl = SampledWavelengths::sample_visible(uc);
        if terminate {
            swl.terminate_secondary();
        }
        let rgb = sampled_to_linear_srgb(&swl, swl.lambda().map(&spectrum));
        for (total, v) in sum.iter_mut().zip(rgb.0) {
            *total += f64::from(v);
        }
    }
    sum.map(|v| v / n as f64)
}

fn assert_close(got: [f64; 3], want: [f64; 3], tolerance: f64, what: &str) {
    for c in 0..3 {
        assert!((got[c] - want[c]).abs() < tolerance, "{what}: {got:?} vs {want:?}");
    }
}

#[test]
fn conventions_constant_one_and_d65() {
    let n = 200_000;
    // Radiance 1: the equal-energy white, ∫ (x̄, ȳ, z̄) dλ · CIE_Y_NORMALIZATION — exact by the trapezoid
    // rule on the 5 nm nodes, where the functions are linear. (The RGB-mode reduction of a flat spectrum,
    // Mitsuba's 1000-point sum scaled by 470/1000 nm, is 999/1000 of it, to the sum's 3e-6.)
    let mut integral = [0.0; 3];
    for (i, node) in CIE1931_XYZ.iter().enumerate() {
        let weight = if i == 0 || i == CIE1931_XYZ.len() - 1 { 2.5 } else { 5.0 };
        for c in 0..3 {
            integral[c] += weight * f64::from(node[c]) * CIE_Y_NORMALIZATION;
        }
    }
    let equal_energy = xyz_to_linear_srgb(integral);
    // Mitsuba's MI_CIE_Y_NORMALIZATION is 1/∫ȳ for that 1000-point sum, so the exact integral gives
    // Y = 1000/999 (observed 1.0010002); gonio's film uses Mitsuba's constant, to render what it renders.
    assert!((integral[1] - 1000.0 / 999.0).abs() < 1e-6, "Y of radiance 1: {}", integral[1]);
    assert_close(mean_estimate(n, false, |_| 1.0), equal_energy, 2e-4, "radiance 1");
    let rgb_mode = spectrum_to_rgb(&[360.0, 830.0], &[1.0, 1.0]).to_f64();
    assert_close(rgb_mode.map(|v| v * 1000.0 / 999.0), equal_energy, 1e-5, "RGB-mode flat spectrum");
    // D65 of luminance 1 (a white emitter; a reflectance of 1 under it): (1, 1, 1).
    assert_close(mean_estimate(n, false, |l| d65(f64::from(l)) as f32), [1.0; 3], 1e-3, "D65");
    // Terminated secondaries: still unbiased (noisier: one wavelength per path).
    assert_close(mean_estimate(n, true, |l| d65(f64::from(l)) as f32), [1.0; 3], 3e-3, "D65, hero only");
}

/// An RGB emitter's spectrum, and an RGB reflectance lit by a white emitter, render as their RGB.
#[test]
fn upsampled_colours_render_as_themselves() {
    let n = 200_000;
    for rgb in [Rgb::new(0.8, 0.1, 0.1), Rgb::new(0.1, 0.8, 0.3), Rgb::new(0.2, 0.3, 0.9), Rgb::new(0.5, 0.5, 0.5)] {
        let reflectance = RgbReflectanceSpectrum::new(rgb);
        let lit = mean_estimate(n, false, |l| reflectance.eval(l) * d65(f64::from(l)) as f32);
        assert_close(lit, rgb.to_f64(), 2e-3, &format!("reflectance {rgb} under D65"));
        let emission = RgbIlluminantSpectrum::new(rgb * 5.0);
        let emitted = mean_estimate(n, false, |l| emission.eval(l));
        assert_close(emitted, (rgb * 5.0).to_f64(), 1e-2, &format!("emission {}", rgb * 5.0));
    }
}
