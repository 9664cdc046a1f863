//! The CIE 1931 2° standard observer colour-matching functions x̄, ȳ, z̄, tabulated every 5 nm from
//! 360 nm to 830 nm, and their linear interpolant.
//!
//! Source: CIE 1931 2° standard observer (CIE 015:2004, table T.4; the 5 nm tabulation distributed by
//! CVRL, <http://cvrl.ioo.ucl.ac.uk/>). The numbers are the single-precision values Mitsuba 3 carries in
//! its `src/core/spectrum.cpp` (`cie1931_tbl`), so that colour reductions done here agree with Mitsuba's
//! to rounding. Mitsuba evaluates the table by linear interpolation between the 5 nm nodes and returns
//! zero outside [360, 830] nm; [`cie1931_xyz`] does the same. (A 1 nm table sampled from that
//! interpolant would hold no more information; the official 1 nm CIE tabulation is a different curve
//! between the nodes and would not reproduce Mitsuba.)
//!
//! Generated with Mitsuba 3.9.1 (`pip install mitsuba==3.9.1`, numpy), one Rust row per node (shortest
//! decimal that round-trips the `f32`, exponents then shortened from `e-05` to `e-5`):
//! ```text
//! python -c "import mitsuba as mi, numpy as np; mi.set_variant('scalar_rgb'); \
//!   [print('    [%s], // %d nm' % (', '.join(repr(np.float32(float(c))).removeprefix('np.float32(')[:-1] \
//!    for c in mi.cie1931_xyz(360.0 + 5 * i)), 360 + 5 * i)) for i in range(95)]"
//! ```

/// Shortest wavelength of the table, in nm.
pub const CIE_MIN: f64 = 360.0;
/// Longest wavelength of the table, in nm.
pub const CIE_MAX: f64 = 830.0;
/// Number of 5 nm nodes from [`CIE_MIN`] to [`CIE_MAX`] inclusive.
pub const CIE_SAMPLES: usize = 95;

/// 1 / ∫ȳ(λ) dλ as Mitsuba 3 defines it (`MI_CIE_Y_NORMALIZATION`): scaling by it gives a spectrum equal
/// to 1 everywhere a luminance Y of 1.
pub const CIE_Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06; // = 106.7502593994140625, an f32

/// x̄, ȳ, z̄ at 360, 365, …, 830 nm.
#[rustfmt::skip]
pub const CIE1931_XYZ: [[f32; 3]; CIE_SAMPLES] = [
    [0.0001299, 3.917e-6, 0.0006061], // 360 nm
    [0.0002321, 6.965e-6, 0.001086], // 365 nm
    [0.0004149, 1.239e-5, 0.001946], // 370 nm
    [0.0007416, 2.202e-5, 0.003486], // 375 nm
    [0.001368, 3.9e-5, 0.006450001], // 380 nm
    [0.002236, 6.4e-5, 0.01054999], // 385 nm
    [0.004243, 0.00012, 0.02005001], // 390 nm
    [0.00765, 0.000217, 0.03621], // 395 nm
    [0.01431, 0.000396, 0.06785001], // 400 nm
    [0.02319, 0.00064, 0.1102], // 405 nm
    [0.04351, 0.00121, 0.2074], // 410 nm
    [0.07763, 0.00218, 0.3713], // 415 nm
    [0.13438, 0.004, 0.6456], // 420 nm
    [0.21477, 0.0073, 1.0390501], // 425 nm
    [0.2839, 0.0116, 1.3856], // 430 nm
    [0.3285, 0.01684, 1.62296], // 435 nm
    [0.34828, 0.023, 1.74706], // 440 nm
    [0.34806, 0.0298, 1.7826], // 445 nm
    [0.3362, 0.038, 1.77211], // 450 nm
    [0.3187, 0.048, 1.7441], // 455 nm
    [0.2908, 0.06, 1.6692], // 460 nm
    [0.2511, 0.0739, 1.5281], // 465 nm
    [0.19536, 0.09098, 1.28764], // 470 nm
    [0.1421, 0.1126, 1.0419], // 475 nm
    [0.09564, 0.13902, 0.8129501], // 480 nm
    [0.05795001, 0.1693, 0.6162], // 485 nm
    [0.03201, 0.20802, 0.46518], // 490 nm
    [0.0147, 0.2586, 0.3533], // 495 nm
    [0.0049, 0.323, 0.272], // 500 nm
    [0.0024, 0.4073, 0.2123], // 505 nm
    [0.0093, 0.503, 0.1582], // 510 nm
    [0.0291, 0.6082, 0.1117], // 515 nm
    [0.06327, 0.71, 0.07824999], // 520 nm
    [0.1096, 0.7932, 0.05725001], // 525 nm
    [0.1655, 0.862, 0.04216], // 530 nm
    [0.2257499, 0.9148501, 0.02984], // 535 nm
    [0.2904, 0.954, 0.0203], // 540 nm
    [0.3597, 0.9803, 0.0134], // 545 nm
    [0.4334499, 0.9949501, 0.008749999], // 550 nm
    [0.5120501, 1.0, 0.005749999], // 555 nm
    [0.5945, 0.995, 0.0039], // 560 nm
    [0.6784, 0.9786, 0.002749999], // 565 nm
    [0.7621, 0.952, 0.0021], // 570 nm
    [0.8425, 0.9154, 0.0018], // 575 nm
    [0.9163, 0.87, 0.001650001], // 580 nm
    [0.9786, 0.8163, 0.0014], // 585 nm
    [1.0263, 0.757, 0.0011], // 590 nm
    [1.0567, 0.6949, 0.001], // 595 nm
    [1.0622, 0.631, 0.0008], // 600 nm
    [1.0456, 0.5668, 0.0006], // 605 nm
    [1.0026, 0.503, 0.00034], // 610 nm
    [0.9384, 0.4412, 0.00024], // 615 nm
    [0.8544499, 0.381, 0.00019], // 620 nm
    [0.7514, 0.321, 1e-4], // 625 nm
    [0.6424, 0.265, 4.999999e-5], // 630 nm
    [0.5419, 0.217, 3e-5], // 635 nm
    [0.4479, 0.175, 2e-5], // 640 nm
    [0.3608, 0.1382, 1e-5], // 645 nm
    [0.2835, 0.107, 0.0], // 650 nm
    [0.2187, 0.0816, 0.0], // 655 nm
    [0.1649, 0.061, 0.0], // 660 nm
    [0.1212, 0.04458, 0.0], // 665 nm
    [0.0874, 0.032, 0.0], // 670 nm
    [0.0636, 0.0232, 0.0], // 675 nm
    [0.04677, 0.017, 0.0], // 680 nm
    [0.0329, 0.01192, 0.0], // 685 nm
    [0.0227, 0.00821, 0.0], // 690 nm
    [0.01584, 0.005723, 0.0], // 695 nm
    [0.01135916, 0.004102, 0.0], // 700 nm
    [0.008110916, 0.002929, 0.0], // 705 nm
    [0.005790346, 0.002091, 0.0], // 710 nm
    [0.004109457, 0.001484, 0.0], // 715 nm
    [0.002899327, 0.001047, 0.0], // 720 nm
    [0.00204919, 0.00074, 0.0], // 725 nm
    [0.001439971, 0.00052, 0.0], // 730 nm
    [0.0009999493, 0.0003611, 0.0], // 735 nm
    [0.0006900786, 0.0002492, 0.0], // 740 nm
    [0.0004760213, 0.0001719, 0.0], // 745 nm
    [0.0003323011, 0.00012, 0.0], // 750 nm
    [0.0002348261, 8.48e-5, 0.0], // 755 nm
    [0.0001661505, 6e-5, 0.0], // 760 nm
    [0.000117413, 4.24e-5, 0.0], // 765 nm
    [8.307527e-5, 3e-5, 0.0], // 770 nm
    [5.870652e-5, 2.12e-5, 0.0], // 775 nm
    [4.150994e-5, 1.499e-5, 0.0], // 780 nm
    [2.935326e-5, 1.06e-5, 0.0], // 785 nm
    [2.067383e-5, 7.4657e-6, 0.0], // 790 nm
    [1.455977e-5, 5.2578e-6, 0.0], // 795 nm
    [1.025398e-5, 3.7029e-6, 0.0], // 800 nm
    [7.221456e-6, 2.6078e-6, 0.0], // 805 nm
    [5.085868e-6, 1.8366e-6, 0.0], // 810 nm
    [3.581652e-6, 1.2934e-6, 0.0], // 815 nm
    [2.522525e-6, 9.1093e-7, 0.0], // 820 nm
    [1.776509e-6, 6.4153e-7, 0.0], // 825 nm
    [1.251141e-6, 4.5181e-7, 0.0], // 830 nm
];

/// The CIE 1931 colour-matching functions (x̄, ȳ, z̄) at `lambda` nm: linear interpolation between the
/// 5 nm nodes of [`CIE1931_XYZ`], zero outside [[`CIE_MIN`], [`CIE_MAX`]] (and for NaN).
#[must_use]
pub fn cie1931_xyz(lambda: f64) -> [f64; 3] {
    if !(CIE_MIN..=CIE_MAX).contains(&lambda) {
        return [0.0; 3];
    }
    // Position in units of the 5 nm node spacing; the last interval is closed at 830 nm.
    let t = (lambda - CIE_MIN) * ((CIE_SAMPLES - 1) as f64 / (CIE_MAX - CIE_MIN));
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // t ∈ [0, 94] here
    let i0 = (t as usize).min(CIE_SAMPLES - 2);
    let w1 = t - i0 as f64;
    let w0 = 1.0 - w1;
    let (a, b) = (CIE1931_XYZ[i0], CIE1931_XYZ[i0 + 1]);
    [0, 1, 2].map(|c| w0.mul_add(f64::from(a[c]), w1 * f64::from(b[c])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_and_interpolation() {
        // ȳ peaks at 1 at 555 nm (node 39); Mitsuba 3.9.1's `mi.cie1931_xyz(555.0)` prints
        // [0.51205, 1, 0.00575] (to 6 digits; the stored `f32` values are these).
        let at_555 = cie1931_xyz(555.0);
        for (v, want) in at_555.iter().zip([f64::from(0.512_050_1_f32), 1.0, f64::from(0.005_749_999_f32)]) {
            assert!((v - want).abs() <= 1e-12 * want, "{v} vs {want}");
        }
        let mid = cie1931_xyz(557.5);
        let (a, b) = (cie1931_xyz(555.0), cie1931_xyz(560.0));
        for c in 0..3 {
            assert!((mid[c] - 0.5 * (a[c] + b[c])).abs() < 1e-12);
        }
        assert!((cie1931_xyz(830.0)[1] - f64::from(4.5181e-7_f32)).abs() < 1e-18);
        assert_eq!(cie1931_xyz(359.9), [0.0; 3]);
        assert_eq!(cie1931_xyz(830.1), [0.0; 3]);
        assert_eq!(cie1931_xyz(f64::NAN), [0.0; 3]);
    }
}
