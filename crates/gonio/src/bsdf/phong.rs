//! `phong` — the Phong lobe around the mirror direction, the lecture's counter-example of a BRDF:
//! f = k_d/π + k_s·S(ωo, ωi), with cos α = max(0, r·ωi) and r = reflect(ωo) the mirror direction.
//!
//! | parameter              | type              | default      | meaning                                         |
//! |------------------------|-------------------|--------------|-------------------------------------------------|
//! | `diffuse_reflectance`  | rgb [0,1]         | 0.5          | k_d, weight of the Lambertian lobe k_d/π        |
//! | `specular_reflectance` | rgb [0,1]         | 0.2          | k_s, weight of the specular lobe                |
//! | `exponent`             | float [0, 10⁵]    | 30           | n, the Phong exponent (larger: sharper)         |
//! | `normalization`        | `none` \| `energy` | `energy`    | `none`: S = cosⁿα; `energy`: S = (n+2)/(2π) cosⁿα |
//! | `form`                 | `modified` \| `original` | `modified` | `original` divides S by cos θi (Phong 1975 read as a BRDF) |
//!
//! (Defaults as in Mitsuba 0.6's `phong` plugin.)
//!
//! # The forms and where they break physics
//! - **Phong 1975** ("Illumination for Computer Generated Pictures", CACM 18(6), 311–317) wrote
//!   reflected *intensity* as k_s cosⁿα. Read as a BRDF that is f·cos θi = k_s cosⁿα, i.e.
//!   `form = "original"`: S/cos θi. Not reciprocal, since f(ωo, ωi)/f(ωi, ωo) = cos θo/cos θi: measured
//!   relative error 0.9994 (the largest possible is 1; at wo = (0.916, 0.402, 0.00007), a grazing pair),
//!   while the modified form measures exactly 0. Its *rendering* albedo ∫ f cos θi dωi stays bounded (the
//!   1/cos θi cancels: 0.83 for the example `k_d = 0.2, k_s = 0.6, n = 20`), but the energy reflected for
//!   light arriving from ωi, ∫ f cos θo dωo = a_modified(ωi)/cos θi, grows without bound at grazing
//!   incidence: by quadrature for k_s = 1, n = 20, energy-normalised, 1.00 at cos θi = 0.5, 1.47 at 0.1,
//!   2.31 at 0.05 and 4.92 at 0.02.
//! - **Unnormalised** (`normalization = "none"`): S = cosⁿα integrates to ∫ cosⁿα cos θi dωi = 2π/(n+2)
//!   at normal incidence, 2.094 for n = 1: with k_s = 1 the surface reflects twice the light it receives.
//!   The example `k_d = k_s = 0.5, n = 1` measures a maximal albedo of 1.53 at cos θo = 0.984 (1.547 at
//!   normal incidence) and a white furnace of 1.27.
//! - **Modified, normalised** (`energy`, the default): S = (n+2)/(2π) cosⁿα (Lewis 1994, "Making Shaders
//!   More Physically Plausible", Computer Graphics Forum 13(2), the normalised Phong lobe; Lafortune & Willems
//!   1994, "Using the Modified Phong Reflectance Model for Physically Based Rendering", KU Leuven CW 197).
//!   Reciprocal (r·ωi = 2 cos θo cos θi − ωo·ωi is symmetric) and the lobe's albedo is exactly 1 at normal
//!   incidence (measured 1.0000 by quadrature) and smaller elsewhere, where part of the lobe falls below the
//!   surface: energy is conserved whenever k_d + k_s ≤ 1.
//!
//! Sampling mixes cosine-weighted hemisphere sampling (k_d) with the power-cosine lobe around r,
//! cos α = u^(1/(n+1)), density (n+1)/(2π) cosⁿα, in proportion to the luminances of k_d and k_s (see
//! [`glossy_mix`](super::glossy_mix)); lobe directions below the surface give no sample.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let b = Bsdf::from_json(r#"{"type": "phong", "diffuse_reflectance": 0, "specular_reflectance": 1, "exponent": 10}"#).unwrap();
//! // At the mirror direction cos α = 1: f = (n+2)/(2π).
//! let wo = Vec3::new(0.6, 0.0, 0.8);
//! let f = b.f(wo, Vec3::new(-0.6, 0.0, 0.8)).r();
//! assert!((f - 12.0 / (2.0 * std::f32::consts::PI)).abs() < 1e-4);
//! ```

use super::glossy_mix::{choice, DiffuseGlossy, GlossyLobe, Normalization};
use crate::error::Result;
use crate::math::{Frame, Vec2, Vec3};
use crate::props::Props;
use crate::sampling::warp::{power_cosine_hemisphere_pdf, sample_power_cosine_hemisphere};
use crate::spectrum::Rgb;
use std::f32::consts::PI;

/// Whether S is read as a BRDF lobe (modified) or as Phong's reflected intensity (original: S/cos θi).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhongForm {
    Modified,
    Original,
}

/// The Phong lobe around the mirror direction.
#[derive(Clone, Debug, PartialEq)]
pub struct PhongLobe {
    /// n ≥ 0.
    pub exponent: f32,
    pub normalization: Normalization,
    pub form: PhongForm,
}

/// The original form divides by cos θi; below this the divisor is clamped (2026-11: keeps f finite for the
/// denormal directions of the NaN sweep; the clamped band has solid angle ~2π·10⁻⁷ sr).
const MIN_COS_THETA_I: f32 = 1e-7;

/// The mirror direction of `wo` about the normal +z.
#[inline]
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

impl GlossyLobe for PhongLobe {
    fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        let cos_alpha = mirror(wo).dot(wi);
        if cos_alpha <= 0.0 {
            return 0.0;
        }
        let scale = match self.normalization {
            Normalization::None => 1.0,
            // Lewis 1994: ∫ cosⁿα cos θ dω = 2π/(n+2) when the lobe is centred on the normal.
            Normalization::Energy => (self.exponent + 2.0) / (2.0 * PI),
        };
        let s = scale * cos_alpha.min(1.0).powf(self.exponent);
        match self.form {
            PhongForm::Modified => s,
            PhongForm::Original => s / wi.z.max(MIN_COS_THETA_I),
        }
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        let local = sample_power_cosine_hemisphere(u, self.exponent);
        Some(Frame::from_normal(mirror(wo)).to_world(local))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        // The density is a function of cos α = r·ωi alone.
        power_cosine_hemisphere_pdf(Vec3::new(0.0, 0.0, mirror(wo).dot(wi).min(1.0)), self.exponent)
    }
}

/// The Phong model: a Lambertian lobe plus [`PhongLobe`].
pub type Phong = DiffuseGlossy<PhongLobe>;

impl DiffuseGlossy<PhongLobe> {
    /// The Phong model with the given reflectances and lobe.
    #[must_use]
    pub fn phong(kd: Rgb, ks: Rgb, exponent: f32, normalization: Normalization, form: PhongForm) -> Self {
        debug_assert!(exponent >= 0.0, "Phong exponent must be ≥ 0, got {exponent}");
        DiffuseGlossy::new(kd, ks, PhongLobe { exponent, normalization, form })
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let kd = p.reflectance("diffuse_reflectance", Rgb::splat(0.5))?;
        let ks = p.reflectance("specular_reflectance", Rgb::splat(0.2))?;
        // Up to 10⁵ the lobe (width ~√(2/n) = 4.5e-3 rad) stays far wider than f32's angular resolution
        // near the peak, ~3e-4 rad (2026-11).
        let exponent = p.float_in("exponent", 30.0, 0.0, 1e5)?;
        let normalization = Normalization::from_props(p)?;
        let form = choice(p, "form", &[("modified", PhongForm::Modified), ("original", PhongForm::Original)], PhongForm::Modified)?;
        Ok(Phong::phong(kd, ks, exponent, normalization, form))
    }
}

impl crate::bsdf::Examples for DiffuseGlossy<PhongLobe> {
    /// Specs that `gonio check --all` must pass.
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "phong"}"#,
        r#"{"type": "phong", "diffuse_reflectance": 0.05, "specular_reflectance": 0.9, "exponent": 1}"#,
        r#"{"type": "phong", "diffuse_reflectance": [0.6, 0.3, 0.1], "specular_reflectance": 0.3, "exponent": 60}"#,
        r#"{"type": "phong", "diffuse_reflectance": 0.3, "specular_reflectance": 0.6, "exponent": 0}"#,
        r#"{"type": "phong", "exponent": 500}"#,
        r#"{"type": "phong", "exponent": 2000}"#,
    ];

    /// Specs that break physics on purpose, with the check row that must catch them.
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[
        (
            r#"{"type": "phong", "diffuse_reflectance": 0.5, "specular_reflectance": 0.5, "exponent": 1, "normalization": "none"}"#,
            "albedo max",
        ),
        (
            r#"{"type": "phong", "diffuse_reflectance": 0.2, "specular_reflectance": 0.6, "exponent": 20, "form": "original"}"#,
            "reciprocity",
        ),
    ];
}

#[cfg(test)]
mod tests {
    use super::super::glossy_mix::testing::hemisphere_integral;
    use super::*;
    use crate::bsdf::BsdfModel;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::verify::reciprocity::reciprocity;

    fn lobe_only(n: f32, normalization: Normalization, form: PhongForm) -> Phong {
        Phong::phong(Rgb::ZERO, Rgb::ONE, n, normalization, form)
    }

    /// ∫ f(ωo, ωi) cos θi dωi by quadrature.
    fn albedo(b: &Phong, wo: Vec3) -> f64 {
        hemisphere_integral(400, |wi| b.f(wo, wi).r() as f64 * wi.z as f64)
    }

    #[test]
    fn normalised_lobe_has_unit_albedo_at_normal_incidence() {
        for n in [0.0, 1.0, 10.0, 100.0] {
            let a = albedo(&lobe_only(n, Normalization::Energy, PhongForm::Modified), Vec3::Z);
            println!("normalised modified Phong, n = {n}: albedo at normal incidence {a:.5}");
            assert!((a - 1.0).abs() < 2e-3, "n={n}: {a}");
            // Off normal incidence part of the lobe is below the surface: less.
            let wo = Vec3::new(0.8, 0.0, 0.6);
            assert!(albedo(&lobe_only(n, Normalization::Energy, PhongForm::Modified), wo) < a);
        }
    }

    #[test]
    fn unnormalised_lobe_gains_energy() {
        // ∫ cos α cos θi dω = 2π/3 at normal incidence.
        let a = albedo(&lobe_only(1.0, Normalization::None, PhongForm::Modified), Vec3::Z);
        println!("unnormalised Phong, n = 1: albedo at normal incidence {a:.5}");
        assert!((a - 2.0 * std::f64::consts::PI / 3.0).abs() < 2e-3, "{a}");
    }

    #[test]
    fn original_form_is_not_reciprocal_and_gains_energy_at_grazing_incidence() {
        let original = lobe_only(20.0, Normalization::Energy, PhongForm::Original);
        let modified = lobe_only(20.0, Normalization::Energy, PhongForm::Modified);
        let r = reciprocity(&original, 100_000, 3);
        println!("original Phong: reciprocity error {:.4} at {:?}", r.max_rel_error, r.worst);
        assert!(r.max_rel_error > 0.5);
        assert_eq!(reciprocity(&modified, 100_000, 3).max_rel_error, 0.0);
        // Light arriving from ωi: ∫ f(ωo, ωi) cos θo dωo = a_modified(ωi)/cos θi.
        let reflected = |mu: f32| {
            let wi = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            hemisphere_integral(400, |wo| original.f(wo, wi).r() as f64 * wo.z as f64)
        };
        let out: Vec<f64> = [0.5f32, 0.1, 0.05, 0.02].iter().map(|mu| reflected(*mu)).collect();
        println!("original Phong: reflected energy for light at cos θi = 0.5, 0.1, 0.05, 0.02: {out:.4?}");
        assert!(out[0] < 1.01 && out[1] > 1.3 && out[2] > out[1] && out[3] > out[2], "{out:?}");
    }

    #[test]
    fn sampling_matches_the_lobe() {
        let b = Phong::phong(Rgb::splat(0.3), Rgb::splat(0.6), 50.0, Normalization::Energy, PhongForm::Modified);
        let wo = Vec3::new(0.5, 0.2, 0.7).normalize();
        // Glossy samples cluster around the mirror direction.
        let s = b.sample(wo, 0.99, Vec2::new(0.9, 0.3)).unwrap();
        assert!(mirror(wo).dot(s.wi) > 0.9);
        assert!((b.diffuse_probability() - 1.0 / 3.0).abs() < 1e-6);
        // Below the surface: none.
        assert!(b.sample(-wo, 0.5, Vec2::splat(0.5)).is_none());
        assert_eq!(b.pdf(wo, Vec3::new(0.0, 0.6, -0.8)), 0.0);
    }

    #[test]
    fn bad_parameters_are_rejected() {
        for bad in [
            r#"{"type": "phong", "normalization": "unit"}"#,
            r#"{"type": "phong", "form": "blinn"}"#,
            r#"{"type": "phong", "exponent": -1}"#,
            r#"{"type": "phong", "specular_reflectance": 1.5}"#,
        ] {
            assert!(crate::bsdf::Bsdf::from_json(bad).is_err(), "{bad}");
        }
    }

    /// Cases beyond the default chi-square grid (cos θ cells of 0.05, 6-point quadrature): a sharp lobe,
    /// and a pure lobe at grazing view whose support ends (cos α = 0) inside the polar cells, where all
    /// quadrature points miss the sliver of non-zero density. On a finer grid both match `pdf`.
    #[test]
    fn hard_cases_pass_chi2_on_a_fine_grid() {
        use crate::verify::chi2::{chi2_bsdf, Chi2Config};
        use crate::verify::energy::direction;
        let cases = [
            (Phong::phong(Rgb::splat(0.3), Rgb::splat(0.6), 2000.0, Normalization::Energy, PhongForm::Modified), 0.7),
            (Phong::phong(Rgb::ZERO, Rgb::splat(0.95), 1.0, Normalization::Energy, PhongForm::Modified), 0.05),
        ];
        for (k, (b, mu)) in cases.iter().enumerate() {
            let cfg = Chi2Config {
                theta_res: 400,
                phi_res: 160,
                integration_res: 10,
                tests: cases.len(),
                seed: k as u64,
                ..Chi2Config::default()
            };
            let r = chi2_bsdf(b, direction(*mu, 0.3), &cfg);
            assert!(r.passed, "case {k}: {r}");
        }
    }
}
