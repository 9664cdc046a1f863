//! Microfacet theory: normal distributions, masking–shadowing and the sampling of microfacet normals.
//!
//! | item                         | values                                   | meaning                                   |
//! |------------------------------|------------------------------------------|-------------------------------------------|
//! | [`MicrofacetKind`]           | `Blinn`, `Beckmann`, `Ggx`               | shape of the normal distribution D(ωm)    |
//! | `alpha_x`, `alpha_y`         | > 0                                      | roughness along the frame's x and y axes (= RMS slope for Beckmann) |
//! | [`Shadowing`]                | `VCavity`, `Smith`, `SmithCorrelated`, `None` | masking–shadowing term G(ωo, ωi, ωm) |
//! | `visible` (sampling)         | bool                                     | sample D(ωm)·cos θm, or the normals visible from ωo |
//!
//! # Distributions
//! With slopes s² = (x/αx)² + (y/αy)² of ωm = (x, y, z) measured as s²/z² = tan²θm·(cos²φ/αx² + sin²φ/αy²):
//! - **Beckmann** (Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq. 25;
//!   anisotropic form as in Heitz 2014 §5): D = exp(−s²/z²) / (π αx αy z⁴).
//! - **GGX / Trowbridge–Reitz** (Walter 2007 eq. 33; anisotropic form as in Heitz 2014 §5): D = 1 / (π αx αy (s² + z²)²).
//! - **Blinn** (Blinn 1977; normalised as Walter 2007's Phong distribution, eq. 30): D = (e + 2)/(2π) · cos^e θm. gonio stores
//!   Blinn by its equivalent Beckmann roughness α = √(2/(e + 2)) (Walter 2007, §5.2), so e = 2/α² − 2.
//!   Blinn is isotropic only (αx = αy). Blinn has no closed-form Smith Λ; gonio uses the Beckmann Λ of the
//!   equivalent α for it (the usual correspondence, exact only as e → ∞). Blinn has no visible-normal
//!   sampler: asked for one, it samples D·cos (see [`blinn`]).
//!
//! # Masking–shadowing (Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based
//! BRDFs", JCGT 3(2))
//! - Smith masking G1(ω, ωm) = χ⁺(ω·ωm) / (1 + Λ(ω)) (eq. 43), with Λ for Beckmann (Heitz 2014 §5: the exact
//!   erf form, not Walter 2007's rational approximation, eq. 27, evaluated in `f32` lanes within 10⁻⁶:
//!   [`beckmann::beckmann_lambda_lanes`]) and GGX (exact closed form).
//! - `Smith`: separable G = G1(ωo)·G1(ωi) (eq. 98); `SmithCorrelated`: height-correlated
//!   G = χ⁺χ⁺ / (1 + Λ(ωo) + Λ(ωi)) (eq. 99).
//! - `VCavity` (Torrance & Sparrow 1967; Cook & Torrance 1982; Heitz 2014 eq. 72):
//!   G = min(1, 2(n·ωm)(n·ωo)/(ωo·ωm), 2(n·ωm)(n·ωi)/(ωi·ωm)).
//! - [`MicrofacetDistribution::lambda`] takes a *signed* direction: for a direction below the surface it
//!   returns Λ(ω) = −1 − Λ(−ω), so that ∫ max(0, ω·ωm) D(ωm) dωm = cos θ (1 + Λ(ω)) holds on both sides
//!   (Heitz 2014). Masking terms use Λ of the direction folded into the upper hemisphere.
//!
//! # Sampling
//! - `visible = false`: D(ωm)·cos θm, pdf = D·cos θm (Walter 2007 eqs. 28, 29 (Beckmann), 35, 36 (GGX),
//!   31 (Blinn); anisotropic azimuth φ = atan2(αy sin 2πu, αx cos 2πu)).
//! - `visible = true`: the distribution of visible normals D_ωo(ωm) = G1(ωo, ωm) max(0, ωo·ωm) D(ωm) / cos θo
//!   (Heitz & d'Eon 2014): GGX by Heitz 2018, "Sampling the GGX Distribution of Visible Normals"
//!   (JCGT 7(4), Listing 1's construction), Beckmann by Heitz & d'Eon 2014, "Importance Sampling
//!   Microfacet-Based BSDFs using the Distribution of Visible Normals" (§4: stretch to α = 1, sample the
//!   visible slopes — the marginal in the incidence plane by inverting its CDF
//!   C(x) = (1 + erf x)/2 + tan θ e^{−x²}/(2√π), normalised by 1 + Λ, with Jakob 2014's fixed-step Newton
//!   iteration ([`beckmann::visible_slope_x`]), the other slope a unit Gaussian — rotate, unstretch).
//!
//! # Code
//! [`Distribution`] is the trait over [`Real`](crate::math::lanes::Real) lanes, implemented once by [`Ggx`], [`Beckmann`] and
//! [`Blinn`]; [`reflection::ReflectionLobe`] is the Walter 2007 reflection lobe over any of them.
//! [`MicrofacetDistribution`] is the runtime choice of kind and roughness, with an `f32` API: each method
//! matches the kind once and calls the generic code at `R = f32`; [`on_distribution!`] does the same for
//! code that runs in lanes.
//!
//! ```
//! use gonio::microfacet::{MicrofacetDistribution, MicrofacetKind, Shadowing};
//! use gonio::math::{Vec2, Vec3};
//! let ggx = MicrofacetDistribution::new(MicrofacetKind::Ggx, 0.3, 0.3);
//! // At normal incidence GGX's D(n) = 1/(π α²).
//! assert!((ggx.d(Vec3::Z) - 1.0 / (std::f32::consts::PI * 0.09)).abs() < 1e-4);
//! // A visible normal always faces the viewer, and its pdf is the one pdf_wm reports.
//! let wo = Vec3::new(0.6, 0.0, 0.8);
//! let wm = ggx.sample_wm(wo, Vec2::new(0.3, 0.9), true);
//! assert!(wm.dot(wo) > 0.0 && ggx.pdf_wm(wo, wm, true) > 0.0);
//! assert!(ggx.g(wo, wo, Vec3::Z, Shadowing::VCavity) == 1.0);
//! ```

pub mod beckmann;
pub mod blinn;
pub mod distribution;
pub mod ggx;
pub mod gtr1;
pub mod reflection;
#[cfg(test)]
mod tests;

pub use crate::numerics::erf::{erf, erf_inv, erfc};
pub use beckmann::{beckmann_lambda, Beckmann};
pub use blinn::{alpha_from_blinn_exponent, blinn_exponent_from_alpha, Blinn};
pub use distribution::Distribution;
pub use ggx::Ggx;
pub use gtr1::Gtr1;

use crate::math::lanes::V3;
use crate::math::param::PerLane;
use crate::math::{Vec2, Vec3};

/// The shape of a microfacet normal distribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MicrofacetKind {
    /// Normalised Blinn, D ∝ cos^e θm with e = 2/α² − 2 (isotropic only).
    Blinn,
    /// Beckmann–Spizzichino (Gaussian slopes).
    Beckmann,
    /// GGX / Trowbridge–Reitz.
    Ggx,
}

impl MicrofacetKind {
    /// All kinds, in the order of their plugin names.
    pub const ALL: [MicrofacetKind; 3] = [MicrofacetKind::Blinn, MicrofacetKind::Beckmann, MicrofacetKind::Ggx];

    /// The plugin name (`blinn`, `beckmann`, `ggx`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            MicrofacetKind::Blinn => "blinn",
            MicrofacetKind::Beckmann => "beckmann",
            MicrofacetKind::Ggx => "ggx",
        }
    }

    /// The kind with this plugin name.
    #[must_use]
    pub fn parse(name: &str) -> Option<MicrofacetKind> {
        MicrofacetKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// Which masking–shadowing function G(ωo, ωi, ωm) to use (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Shadowing {
    /// Torrance–Sparrow / Cook–Torrance V-cavities (Heitz 2014 eq. 72).
    VCavity,
    /// Smith, separable: G1(ωo)·G1(ωi) (Heitz 2014 eq. 98). Mitsuba's `roughconductor`.
    Smith,
    /// Smith, height-correlated: 1/(1 + Λ(ωo) + Λ(ωi)) (Heitz 2014 eq. 99).
    SmithCorrelated,
    /// No masking or shadowing (G = 1): a teaching switch; not energy conserving at grazing angles.
    None,
}

impl Shadowing {
    pub const ALL: [Shadowing; 4] = [Shadowing::VCavity, Shadowing::Smith, Shadowing::SmithCorrelated, Shadowing::None];

    /// The plugin name (`vcavity`, `smith`, `smith_correlated`, `none`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Shadowing::VCavity => "vcavity",
            Shadowing::Smith => "smith",
            Shadowing::SmithCorrelated => "smith_correlated",
            Shadowing::None => "none",
        }
    }

    /// The shadowing with this plugin name.
    #[must_use]
    pub fn parse(name: &str) -> Option<Shadowing> {
        Shadowing::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// A microfacet normal distribution: its kind and its roughness along x and y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicrofacetDistribution {
    pub kind: MicrofacetKind,
    pub alpha_x: f32,
    pub alpha_y: f32,
}

/// `$body` with `$d` bound to the [`Distribution`] of the [`MicrofacetDistribution`] `$dist` (a [`Ggx`],
/// [`Beckmann`] or [`Blinn`]): the kind is matched once, and `$body` is compiled for each.
#[macro_export]
#[doc(hidden)]
macro_rules! on_distribution {
    ($dist:expr, |$d:ident| $body:expr) => {{
        let dist: &$crate::microfacet::MicrofacetDistribution = &$dist;
        match dist.kind {
            $crate::microfacet::MicrofacetKind::Ggx => {
                let $d = $crate::microfacet::Ggx { alpha_x: dist.alpha_x, alpha_y: dist.alpha_y };
                $body
            }
            $crate::microfacet::MicrofacetKind::Beckmann => {
                let $d = $crate::microfacet::Beckmann { alpha_x: dist.alpha_x, alpha_y: dist.alpha_y };
                $body
            }
            $crate::microfacet::MicrofacetKind::Blinn => {
                let $d = $crate::microfacet::Blinn { alpha: dist.alpha_x };
                $body
            }
        }
    }};
}
pub use on_distribution;

impl MicrofacetDistribution {
    /// A distribution of kind `kind` with roughness `alpha_x`, `alpha_y` (> 0; equal for Blinn).
    #[must_use]
    pub fn new(kind: MicrofacetKind, alpha_x: f32, alpha_y: f32) -> Self {
        debug_assert!(alpha_x > 0.0 && alpha_y > 0.0, "roughness must be positive");
        debug_assert!(kind != MicrofacetKind::Blinn || alpha_x == alpha_y, "Blinn is isotropic");
        MicrofacetDistribution { kind, alpha_x, alpha_y }
    }

    /// Set roughness parameter `name` to `alpha` (> 0): `alpha` both, `alpha_u` the roughness along x,
    /// `alpha_v` along y (for Beckmann and GGX: Blinn is isotropic). Whether the distribution has `name`.
    pub fn set_roughness(&mut self, name: &str, alpha: f32) -> bool {
        debug_assert!(alpha > 0.0, "roughness must be positive");
        let Some((x, y)) = self.roughness_axes(name) else { return false };
        if x {
            self.alpha_x = alpha;
        }
        if y {
            self.alpha_y = alpha;
        }
        true
    }

    /// This distribution's kind with the roughness (`ax`, `ay`) of each lane of a packet, as `ggx` or
    /// `beckmann` make of it; `None` for Blinn (its exponent is one number for all lanes).
    pub fn per_lane<K>(
        &self,
        (ax, ay): (PerLane, PerLane),
        ggx: impl FnOnce(Ggx<PerLane>) -> K,
        beckmann: impl FnOnce(Beckmann<PerLane>) -> K,
    ) -> Option<K> {
        match self.kind {
            MicrofacetKind::Ggx => Some(ggx(Ggx { alpha_x: ax, alpha_y: ay })),
            MicrofacetKind::Beckmann => Some(beckmann(Beckmann { alpha_x: ax, alpha_y: ay })),
            MicrofacetKind::Blinn => None,
        }
    }

    /// Which roughnesses parameter `name` sets: (along x, along y) — `alpha` both, `alpha_u` x, `alpha_v`
    /// y (the last two for Beckmann and GGX: Blinn is isotropic); `None` for other names.
    #[must_use]
    pub fn roughness_axes(&self, name: &str) -> Option<(bool, bool)> {
        match (name, self.kind) {
            ("alpha", _) => Some((true, true)),
            ("alpha_u", MicrofacetKind::Beckmann | MicrofacetKind::Ggx) => Some((true, false)),
            ("alpha_v", MicrofacetKind::Beckmann | MicrofacetKind::Ggx) => Some((false, true)),
            _ => None,
        }
    }

    /// The normalised Blinn distribution with exponent `exponent` ≥ 0.
    #[must_use]
    pub fn blinn(exponent: f32) -> Self {
        let alpha = alpha_from_blinn_exponent(exponent);
        MicrofacetDistribution::new(MicrofacetKind::Blinn, alpha, alpha)
    }

    /// This distribution's roughness as a [`Ggx`] (whatever its kind).
    #[inline(always)]
    #[must_use]
    pub fn ggx(&self) -> Ggx {
        Ggx { alpha_x: self.alpha_x, alpha_y: self.alpha_y }
    }

    /// Whether αx ≠ αy.
    #[must_use]
    pub fn is_anisotropic(&self) -> bool {
        self.alpha_x != self.alpha_y
    }

    /// The normal distribution D(ωm) in sr⁻¹ (zero below the surface). ∫ D(ωm) cos θm dωm = 1.
    #[must_use]
    #[inline(always)]
    pub fn d(&self, wm: Vec3) -> f32 {
        on_distribution!(self, |d| d.d(V3::from(wm)))
    }

    /// Smith's Λ(ω) (Heitz 2014 §5) for a signed direction `w`: Λ ≥ 0 above the surface, and Λ(ω) = −1 − Λ(−ω) below.
    /// Infinite on the horizon.
    #[must_use]
    pub fn lambda(&self, w: Vec3) -> f32 {
        on_distribution!(self, |d| d.lambda(V3::from(w)))
    }

    /// Smith masking G1(ω, ωm) = χ⁺(ω·ωm) / (1 + Λ(ω)) (Heitz 2014 eq. 43), for ω on either side
    /// (seen from its own side).
    #[must_use]
    #[inline(always)]
    pub fn g1(&self, w: Vec3, wm: Vec3) -> f32 {
        on_distribution!(self, |d| d.g1(V3::from(w), V3::from(wm)))
    }

    /// Masking–shadowing G(ωo, ωi, ωm) of the chosen form, for reflection (ωo, ωi on the side of ωm).
    #[must_use]
    #[inline(always)]
    pub fn g(&self, wo: Vec3, wi: Vec3, wm: Vec3, shadowing: Shadowing) -> f32 {
        on_distribution!(self, |d| d.g(V3::from(wo), V3::from(wi), V3::from(wm), shadowing))
    }

    /// Sample a microfacet normal: of D(ωm) cos θm, or (`visible`, needs `wo.z > 0`) of the normals
    /// visible from `wo` (Blinn: D·cos). The density is [`pdf_wm`](Self::pdf_wm).
    #[must_use]
    #[inline(always)]
    pub fn sample_wm(&self, wo: Vec3, u: Vec2, visible: bool) -> Vec3 {
        // NaN passes (and gives NaN): the checked batches feed bad rows through before rejecting them.
        debug_assert!(!visible || !(wo.z <= 0.0), "visible normals are sampled for directions above the surface");
        on_distribution!(self, |d| d.sample_wm(V3::from(wo), u.x, u.y, visible).into())
    }

    /// The solid-angle density of [`sample_wm`](Self::sample_wm) at `wm`.
    #[must_use]
    #[inline(always)]
    pub fn pdf_wm(&self, wo: Vec3, wm: Vec3, visible: bool) -> f32 {
        on_distribution!(self, |d| d.pdf_wm(V3::from(wo), V3::from(wm), visible))
    }

    /// The solid-angle density of ωi = reflect(ωo, ωm) when ωm is drawn by [`sample_wm`](Self::sample_wm):
    /// pdf(ωm) / (4 |ωo·ωm|) (Walter 2007 eq. 14).
    #[must_use]
    #[inline(always)]
    pub fn pdf_reflected(&self, wo: Vec3, wm: Vec3, visible: bool) -> f32 {
        on_distribution!(self, |d| d.pdf_reflected(V3::from(wo), V3::from(wm), visible))
    }

    /// The solid-angle density of ωi refracted from ωo about ωm with relative index `eta` = ηi/ηo, when ωm
    /// is drawn by [`sample_wm`](Self::sample_wm): pdf(ωm) η² |ωi·ωm| / (ωo·ωm + η ωi·ωm)² (Walter 2007
    /// eqs. 16, 17).
    #[must_use]
    pub fn pdf_refracted(&self, wo: Vec3, wi: Vec3, wm: Vec3, eta: f32, visible: bool) -> f32 {
        on_distribution!(self, |d| d.pdf_refracted(V3::from(wo), V3::from(wi), V3::from(wm), eta, visible))
    }
}
