//! `torrance_sparrow` — the lecture's microfacet model: f = D·G·F / (4 cos θo cos θi) with the normalised
//! Blinn distribution, V-cavity masking–shadowing and a conductor's Fresnel term (Torrance & Sparrow 1967;
//! Cook & Torrance 1982, eq. 4 with D of Blinn 1977; the 4 in the denominator as in Walter 2007 eq. 20).
//! Distribution and shadowing are selectable, so the lecture's model and the modern ones
//! (`roughconductor` is `distribution = beckmann|ggx, shadowing = smith`) are one family.
//!
//! | parameter              | type             | default     | meaning                                          |
//! |------------------------|------------------|-------------|--------------------------------------------------|
//! | `distribution`         | `blinn` \| `beckmann` \| `ggx` | `blinn` | the microfacet distribution            |
//! | `exponent`             | float [0, 1e8]   | —           | Blinn exponent e (instead of `alpha`; any distribution: α = √(2/(e+2))) |
//! | `alpha`                | float [1e-4, 10] | 0.1 (e ≈ 198) | roughness                                       |
//! | `alpha_u`, `alpha_v`   | float [1e-4, 10] | `alpha`     | anisotropic roughness (Beckmann and GGX only)     |
//! | `shadowing`            | `vcavity` \| `smith` \| `smith_correlated` \| `none` | `vcavity` | masking–shadowing: V-cavity, Smith separable or correlated, or none |
//! | `material`             | string           | `"none"`    | named metal for F; `none` gives F = 1             |
//! | `eta`, `k`             | rgb ≥ 0          | preset      | complex index η + i k (instead of `material`)     |
//! | `specular_reflectance` | rgb [0,1]        | 1           | multiplier (not physical)                          |
//! | `sample_visible`       | bool             | true        | sample visible normals, or D·cos (Blinn always samples D·cos) |
//!
//! The Fresnel term is always a conductor's (η + i k, as in [`Conductor`]); a dielectric coating belongs
//! to layered models. V-cavity G = min(1, 2(n·ωh)(n·ωo)/(ωo·ωh), 2(n·ωh)(n·ωi)/(ωi·ωh)) (Heitz 2014,
//! eq. 72). `shadowing = none` (G = 1) is a teaching switch that shows why G exists: its albedo exceeds 1
//! at grazing angles. The evaluation and sampling are those of [`MicrofacetConductor`], shared with
//! `roughconductor`; sampling never depends on the shadowing form, and the pdf is exactly the sampler's.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let ts = Bsdf::from_json(r#"{"type": "torrance_sparrow", "exponent": 100, "material": "Al"}"#).unwrap();
//! // In the mirror configuration at normal incidence G = 1 and D = (e+2)/(2π):
//! // f = F(1)·102/(2π)/4.
//! let f = ts.f(Vec3::Z, Vec3::Z).g();
//! let (eta, k) = gonio::spectrum::named::conductor("Al").unwrap();
//! let fresnel = gonio::fresnel::fresnel_conductor(1.0, eta.g(), k.g());
//! assert!((f / (fresnel * 102.0 / (8.0 * std::f32::consts::PI)) - 1.0).abs() < 1e-5);
//! ```

use super::rough_conductor::{MicrofacetConductor, MicrofacetParams};
use super::Conductor;
use crate::error::Result;
use crate::microfacet::{MicrofacetDistribution, MicrofacetKind, Shadowing};
use crate::props::Props;

/// The Torrance–Sparrow family of microfacet conductors.
#[derive(Clone, Debug, PartialEq)]
pub struct TorranceSparrow(pub MicrofacetConductor);

impl TorranceSparrow {
    const PARAMS: MicrofacetParams = MicrofacetParams {
        kinds: &[MicrofacetKind::Blinn, MicrofacetKind::Beckmann, MicrofacetKind::Ggx],
        default_kind: MicrofacetKind::Blinn,
        default_alpha: 0.1,
        shadowing: Some(Shadowing::VCavity),
        exponent: true,
    };

    /// The lecture's model: Blinn exponent `exponent`, V-cavity shadowing, Fresnel of `fresnel`.
    #[must_use]
    pub fn new(exponent: f32, fresnel: Conductor) -> Self {
        TorranceSparrow(MicrofacetConductor::new(MicrofacetDistribution::blinn(exponent), Shadowing::VCavity, true, fresnel))
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        MicrofacetConductor::from_props(p, &Self::PARAMS).map(TorranceSparrow)
    }
}

impl crate::bsdf::Examples for TorranceSparrow {
    /// Examples for `gonio check --all`, defaults and extremes down to α = 0.001; they pass the full
    /// standard since the chi-square cell integrals became adaptive (2026-11). Blinn e = 2·10⁴ (α ≈ 0.01)
    /// joined last: it failed at cos θo = 0.7 (p = 4.5·10⁻⁷, 30 counts expected in the "no sample" bin,
    /// 8 cells at the quadrature's depth limit) while D was cos^e θm from the f32 z, whose rounding
    /// (6·10⁻⁸) e turned into 10⁻³ relative noise per node; D from sin²θm (see
    /// [`crate::microfacet`]) has 10⁻⁶, and the example passes (p = 0.088, 0.024, 0.010, 0.042 at seed 0;
    /// 0.48, 0.31, 0.88, 0.95 at seed 7).
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "torrance_sparrow"}"#,
        r#"{"type": "torrance_sparrow", "exponent": 20}"#,
        r#"{"type": "torrance_sparrow", "exponent": 0}"#,
        r#"{"type": "torrance_sparrow", "exponent": 30, "sample_visible": false, "material": "Cu"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "beckmann", "alpha": 1.0, "shadowing": "vcavity"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "ggx", "alpha": 0.3, "shadowing": "smith_correlated"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "ggx", "alpha": 1.0, "shadowing": "smith_correlated", "sample_visible": false}"#,
        r#"{"type": "torrance_sparrow", "distribution": "ggx", "alpha_u": 0.05, "alpha_v": 1.0, "shadowing": "vcavity"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "beckmann", "alpha": 0.5, "shadowing": "smith"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "beckmann", "alpha_u": 0.02, "alpha_v": 0.4, "shadowing": "vcavity"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "ggx", "alpha": 0.01, "shadowing": "smith"}"#,
        r#"{"type": "torrance_sparrow", "distribution": "ggx", "alpha": 0.001, "shadowing": "vcavity", "sample_visible": false}"#,
        r#"{"type": "torrance_sparrow", "exponent": 20000, "material": "Au"}"#,
    ];
}

forward_bsdf_model!(TorranceSparrow => 0);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;
    use crate::bsdf::BsdfModel;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::math::Vec3;
    use crate::spectrum::Rgb;
    use crate::verify::energy;

    #[test]
    fn vcavity_with_a_uniform_blinn_lobe() {
        // Blinn e = 0 is D = 1/π, normals up to the horizon; V-cavity keeps it below unit albedo.
        let b = Bsdf::from_json(r#"{"type": "torrance_sparrow", "exponent": 0}"#).unwrap();
        for mu in [1.0f32, 0.5, 0.2, 0.05] {
            let a = energy::albedo_at(&b, mu, 1 << 18, 2).r();
            eprintln!("V-cavity, Blinn e = 0, cosθo = {mu}: albedo {a}");
            assert!(a < 1.0);
        }
    }

    #[test]
    fn the_lecture_formula_term_by_term() {
        let ts = TorranceSparrow::new(50.0, Conductor::new(Rgb::splat(0.2), Rgb::splat(3.0)));
        let wo = Vec3::new(0.95, 0.1, 0.15).normalize();
        let wi = Vec3::new(-0.7, 0.2, 0.3).normalize();
        let h = (wo + wi).normalize();
        let d = 52.0 / (2.0 * std::f32::consts::PI) * h.z.powf(50.0);
        let g = 1f32.min(2.0 * h.z * wo.z / wo.dot(h)).min(2.0 * h.z * wi.z / wi.dot(h));
        let f = crate::fresnel::fresnel_conductor(wo.dot(h), 0.2, 3.0);
        let expect = d * g * f / (4.0 * wo.z * wi.z);
        assert!((ts.f(wo, wi).r() / expect - 1.0).abs() < 1e-5);
        assert!(g < 1.0, "this configuration is shadowed");
    }

    #[test]
    fn without_shadowing_energy_is_not_conserved() {
        let b = Bsdf::from_json(r#"{"type": "torrance_sparrow", "distribution": "ggx", "alpha": 0.5, "shadowing": "none"}"#).unwrap();
        let grazing = energy::albedo_at(&b, 0.05, 65_536, 1).r();
        eprintln!("shadowing none, GGX α=0.5, cosθo=0.05: albedo {grazing}");
        assert!(grazing > 1.1);
    }

    #[test]
    fn parameters_are_checked() {
        for bad in [
            r#"{"type": "torrance_sparrow", "alpha_u": 0.1, "alpha_v": 0.2}"#,
            r#"{"type": "torrance_sparrow", "exponent": 10, "alpha": 0.1}"#,
            r#"{"type": "torrance_sparrow", "exponent": -1}"#,
            r#"{"type": "torrance_sparrow", "shadowing": "cavity"}"#,
            r#"{"type": "torrance_sparrow", "distribution": "phong"}"#,
        ] {
            assert!(Bsdf::from_json(bad).is_err(), "{bad}");
        }
        let b = Bsdf::from_json(r#"{"type": "torrance_sparrow", "exponent": 100}"#).unwrap();
        let Bsdf::TorranceSparrow(TorranceSparrow(m)) = b else { panic!() };
        assert_eq!(m.distribution, MicrofacetDistribution::blinn(100.0));
        assert_eq!(m.shadowing, Shadowing::VCavity);
    }
}
