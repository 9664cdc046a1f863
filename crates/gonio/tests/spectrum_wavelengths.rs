//! Hero-wavelength sampling (`gonio::spectrum::wavelengths`): the visible-importance warp as a triplet
//! (sample / pdf / invert) — its constants, normalisation, round trip and a chi-square test — against
//! Mitsuba 3.9.1's `sample_rgb_spectrum` / `pdf_rgb_spectrum`, and the rotation of four wavelengths.

use gonio::sampling::rng::Pcg32;
use gonio::spectrum::wavelengths::{
    invert_visible_wavelength_sample, rotated_samples, sample_uniform_wavelength, sample_visible_wavelength, visible_wavelength_pdf,
    SampledWavelengths, LAMBDA_MAX, LAMBDA_MIN, N_WAVELENGTHS,
};

/// Mitsuba 3.9.1: (u, λ, 1/pdf) from
/// ```text
/// python -c "import mitsuba as mi; mi.set_variant('scalar_spectral'); \
///   [print(u, *map(float, mi.sample_rgb_spectrum(u))) for u in [0.0, 0.05, 0.25, 0.5, 0.75, 0.9, 1.0]]"
/// ```
/// (at u = 1 Mitsuba returns 830.00006, one ulp past the range; gonio clamps to 830).
const MITSUBA_SAMPLES: &[(f32, f64, f64)] = &[
    (0.0, 360.0, 955.272_888_183_593_8),
    (0.05, 397.798_248_291_015_6, 613.157_897_949_218_8),
    (0.25, 479.154_052_734_375, 302.176_818_847_656_25),
    (0.5, 545.903_015_136_718_8, 254.642_715_454_101_56),
    (0.75, 616.856_201_171_875, 344.819_091_796_875),
    (0.9, 686.015_869_140_625, 669.168_762_207_031_2),
    (1.0, 830.0, 4_379.801_269_531_25),
];

/// Mitsuba 3.9.1: (λ, pdf) from `mi.pdf_rgb_spectrum(λ)` (same variant).
const MITSUBA_PDF: &[(f32, f64)] = &[
    (360.0, 0.001_046_822_522_766_888_1),
    (400.0, 0.001_670_796_307_735_145),
    (450.0, 0.002_701_958_874_240_517_6),
    (538.0, 0.003_939_804_155_379_534),
    (600.0, 0.003_248_341_381_549_835),
    (700.0, 0.001_270_516_891_963_78),
    (830.0, 0.000_228_321_208_851_411_94),
];

#[test]
fn matches_mitsuba() {
    for &(u, lambda, inv_pdf) in MITSUBA_SAMPLES {
        let got = sample_visible_wavelength(u);
        // f32 atanh in both; near u = 1 one ulp of the argument moves λ by ~0.01 nm.
        let tolerance = 2e-3 * (1.0 + f64::from((u - 0.5).abs()) * 10.0);
        assert!((f64::from(got) - lambda).abs() < tolerance, "u = {u}: {got} vs {lambda}");
        let pdf = f64::from(visible_wavelength_pdf(got));
        assert!((pdf * inv_pdf - 1.0).abs() < 2e-4, "u = {u}: 1/pdf {} vs {inv_pdf}", 1.0 / pdf);
    }
    for &(lambda, want) in MITSUBA_PDF {
        let got = f64::from(visible_wavelength_pdf(lambda));
        assert!((got / want - 1.0).abs() < 1e-6, "λ = {lambda}: {got} vs {want}");
    }
}

/// The density in f64, from its definition: k / (t₁ − t₀) / cosh²(k (λ − 538)).
fn pdf_f64(lambda: f64) -> f64 {
    let k = 0.0072;
    let t0 = (k * (360.0 - 538.0_f64)).tanh();
    let t1 = (k * (830.0 - 538.0_f64)).tanh();
    k / (t1 - t0) / (k * (lambda - 538.0)).cosh().powi(2)
}

#[test]
fn pdf_is_normalised_and_matches_its_definition() {
    // Midpoint rule on 0.01 nm steps (error ~1e-10 for this smooth density).
    let steps = 47_000;
    let h = f64::from(LAMBDA_MAX - LAMBDA_MIN) / f64::from(steps);
    let mut integral = 0.0;
    for i in 0..steps {
        let lambda = f64::from(LAMBDA_MIN) + (f64::from(i) + 0.5) * h;
        let p = f64::from(visible_wavelength_pdf(lambda as f32));
        assert!((p / pdf_f64(lambda) - 1.0).abs() < 2e-6, "λ = {lambda}: {p} vs {}", pdf_f64(lambda));
        integral += p * h;
    }
    assert!((integral - 1.0).abs() < 1e-5, "∫p = {integral}");
    assert_eq!(visible_wavelength_pdf(359.9), 0.0);
    assert_eq!(visible_wavelength_pdf(830.1), 0.0);
    assert_eq!(visible_wavelength_pdf(f32::NAN), 0.0);
}

#[test]
fn sample_and_invert_round_trip() {
    for i in 0..=10_000 {
        let u = i as f32 / 10_000.0;
        let lambda = sample_visible_wavelength(u);
        assert!((LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda), "u = {u}: λ = {lambda}");
        let back = invert_visible_wavelength_sample(lambda);
        assert!((back - u).abs() < 3e-6, "u = {u}: λ = {lambda}, back {back}");
    }
    // The CDF's derivative is the pdf (central differences over ±0.5 nm, in f32).
    for lambda in [380.0_f32, 450.0, 538.0, 620.0, 760.0] {
        let dp = (invert_visible_wavelength_sample(lambda + 0.5) - invert_visible_wavelength_sample(lambda - 0.5)) / 1.0;
        let p = visible_wavelength_pdf(lambda);
        assert!((dp / p - 1.0).abs() < 2e-3, "λ = {lambda}: dP/dλ {dp} vs p {p}");
    }
    assert_eq!(invert_visible_wavelength_sample(300.0), 0.0);
    assert_eq!(invert_visible_wavelength_sample(900.0), 1.0);
}

/// Chi-square of 10⁶ samples in 47 bins of 10 nm against the exact bin probabilities (differences of the
/// f64 CDF); bins with expected count < 5 would be pooled, none are. Threshold: the 0.999 quantile of
/// χ²(46) ≈ 81.4.
#[test]
fn chi_square() {
    let bins = 47;
    let n = 1_000_000;
    let mut counts = vec![0_u64; bins];
    let mut rng = Pcg32::new(7, 11);
    for _ in 0..n {
        let lambda = sample_visible_wavelength(rng.next_f32());
        let bin = (((lambda - LAMBDA_MIN) / 10.0) as usize).min(bins - 1);
        counts[bin] += 1;
    }
    let cdf = |lambda: f64| {
        let k = 0.0072;
        let t0 = (k * (360.0 - 538.0_f64)).tanh();
        let t1 = (k * (830.0 - 538.0_f64)).tanh();
        ((k * (lambda - 538.0)).tanh() - t0) / (t1 - t0)
    };
    let mut chi2 = 0.0;
    for (i, &c) in counts.iter().enumerate() {
        let lo = 360.0 + 10.0 * i as f64;
        let expected = n as f64 * (cdf(lo + 10.0) - cdf(lo));
        assert!(expected >= 5.0);
        chi2 += (c as f64 - expected).powi(2) / expected;
    }
    assert!(chi2 < 81.4, "χ² = {chi2} over {} degrees of freedom", bins - 1);
}

#[test]
fn four_rotated_wavelengths() {
    for uc in [0.0_f32, 0.1, 0.249, 0.25, 0.5, 0.8, 0.999_999, 1.0] {
        let u = rotated_samples(uc);
        assert_eq!(u[0], uc);
        for (i, &ui) in u.iter().enumerate() {
            assert!((0.0..=1.0).contains(&ui), "{uc}: {u:?}");
            // Equally spaced by 1/4 modulo 1.
            let d = (ui - uc - i as f32 * 0.25).rem_euclid(1.0);
            assert!(!(1e-6..=1.0 - 1e-6).contains(&d), "{uc}: {u:?}");
        }
        let swl = SampledWavelengths::sample_visible(uc);
        assert_eq!(swl.lambda().len(), N_WAVELENGTHS);
        for ((&ui, lambda), pdf) in u.iter().zip(swl.lambda()).zip(swl.pdf()) {
            assert_eq!(lambda, sample_visible_wavelength(ui));
            assert_eq!(pdf, visible_wavelength_pdf(lambda));
            assert!(pdf > 0.0);
        }
        let uniform = SampledWavelengths::sample_uniform(uc);
        assert_eq!(uniform.lambda()[2], sample_uniform_wavelength(u[2]));
        assert!(uniform.pdf().iter().all(|&p| (p * 470.0 - 1.0).abs() < 1e-6));
    }
}

#[test]
fn terminating_secondaries_keeps_the_hero_unbiased() {
    let mut swl = SampledWavelengths::sample_visible(0.37);
    let hero_pdf = swl.pdf()[0];
    assert!(!swl.secondary_terminated());
    swl.terminate_secondary();
    assert!(swl.secondary_terminated());
    assert_eq!(swl.pdf(), [hero_pdf / 4.0, 0.0, 0.0, 0.0]);
    swl.terminate_secondary(); // idempotent
    assert_eq!(swl.pdf(), [hero_pdf / 4.0, 0.0, 0.0, 0.0]);
}
