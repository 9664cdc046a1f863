//! The distribution trait: D, Λ, G1, G and the sampling of microfacet normals, written once over
//! [`Real`] lanes. A distribution ([`Ggx`](super::Ggx), [`Beckmann`](super::Beckmann),
//! [`Blinn`](super::Blinn)) supplies D, Λ, the radial part of D·cos sampling and its visible-normal
//! sampler; the rest (G1, every shadowing form, the sampling densities) is derived here from those.

use super::Shadowing;
use crate::math::lanes::{Real, V3};
use crate::math::trig::sin_cos_turn;

/// A microfacet normal distribution over [`Real`] lanes (see the module doc of [`super`] for the
/// formulas). Directions are in the shading frame (normal = +z); `wm` is a unit microfacet normal.
pub trait Distribution: Copy + std::fmt::Debug {
    /// Whether [`sample_visible`](Self::sample_visible) samples the visible normals; where not (Blinn),
    /// asking for visible normals samples D·cos.
    const HAS_VISIBLE: bool = true;

    /// The roughness along the frame's x and y axes, in lanes.
    fn alphas<R: Real>(&self) -> (R, R);

    /// The normal distribution D(ωm) in sr⁻¹, 0 below the surface; ∫ D(ωm) cos θm dωm = 1.
    fn d<R: Real>(&self, wm: V3<R>) -> R;

    /// Smith's Λ of the upper-hemisphere direction (x, y, z ≥ 0; need not be unit): 0 at the pole, ∞ on
    /// the horizon.
    fn lambda_upper<R: Real>(&self, x: R, y: R, z: R) -> R;

    /// tan²θm of a normal drawn from D·cos given its azimuth, from the radial sample `ux`, where
    /// `a` = cos²φ/αx² + sin²φ/αy² (Walter 2007 eqs. 28, 35, 31; ∞ is the horizon).
    fn tan2_d_cos<R: Real>(&self, ux: R, a: R) -> R;

    /// A normal drawn from the visible normals D_ωo(ωm) = G1(ωo, ωm) max(0, ωo·ωm) D(ωm) / cos θo
    /// (Heitz & d'Eon 2014) for `wo.z > 0`. Distributions without such a sampler
    /// ([`HAS_VISIBLE`](Self::HAS_VISIBLE) false) sample D·cos.
    fn sample_visible<R: Real>(&self, wo: V3<R>, ux: R, uy: R) -> V3<R>;

    /// Smith masking G1(ω, ωm) = χ⁺(ω·ωm) / (1 + Λ(ω)) (Heitz 2014 eq. 43), ω seen from its own side.
    #[inline(always)]
    fn g1<R: Real>(&self, w: V3<R>, wm: V3<R>) -> R {
        let zero = R::splat(0.0);
        let g = R::splat(1.0) / (self.lambda_upper(w.x, w.y, w.z.abs()) + 1.0);
        R::select((w.dot(wm) * w.z).le(zero), zero, g)
    }

    /// Smith's Λ(ω) of a signed direction: Λ ≥ 0 above the surface and Λ(ω) = −1 − Λ(−ω) below, so that
    /// ∫ max(0, ω·ωm) D(ωm) dωm = cos θ (1 + Λ(ω)) holds on both sides (Heitz 2014).
    #[inline(always)]
    fn lambda<R: Real>(&self, w: V3<R>) -> R {
        let up = self.lambda_upper(w.x, w.y, w.z.abs());
        R::select(w.z.lt(R::splat(0.0)), -up - 1.0, up)
    }

    /// Masking–shadowing G(ωo, ωi, ωm) of the form `shadowing`, for reflection (ωo, ωi on the side of ωm);
    /// 0 where either direction sees ωm's back. `shadowing` is the same for every lane (a `match` per call).
    #[inline(always)]
    fn g<R: Real>(&self, wo: V3<R>, wi: V3<R>, wm: V3<R>, shadowing: Shadowing) -> R {
        let zero = R::splat(0.0);
        let one = R::splat(1.0);
        let (o_m, i_m) = (wo.dot(wm), wi.dot(wm));
        let g = match shadowing {
            // Torrance & Sparrow 1967; Heitz 2014 eq. 72.
            Shadowing::VCavity => {
                let two_nm = wm.z.abs() * 2.0;
                one.min(two_nm * wo.z.abs() / o_m.abs()).min(two_nm * wi.z.abs() / i_m.abs())
            }
            // Heitz 2014 eq. 98.
            Shadowing::Smith => self.g1(wo, wm) * self.g1(wi, wm),
            // Heitz 2014 eq. 99. 1 + (Λo + Λi): the inner sum commutes, so G(ωo, ωi) = G(ωi, ωo) bit for bit.
            Shadowing::SmithCorrelated => {
                let (lo, li) = (self.lambda_upper(wo.x, wo.y, wo.z.abs()), self.lambda_upper(wi.x, wi.y, wi.z.abs()));
                one / ((lo + li) + 1.0)
            }
            Shadowing::None => one,
        };
        R::select((o_m * wo.z).le(zero) | (i_m * wi.z).le(zero), zero, g)
    }

    /// Whether asking for visible normals samples them ([`HAS_VISIBLE`](Self::HAS_VISIBLE)).
    #[inline(always)]
    fn samples_visible(&self, visible: bool) -> bool {
        visible && Self::HAS_VISIBLE
    }

    /// A microfacet normal drawn from D(ωm)·cos θm (Walter 2007 eqs. 28, 35, 31) with the anisotropic
    /// azimuth φ = atan2(αy sin 2πuy, αx cos 2πuy), whose density is D·cos.
    #[inline(always)]
    fn sample_d_cos<R: Real>(&self, ux: R, uy: R) -> V3<R> {
        let (alpha_x, alpha_y): (R, R) = self.alphas();
        let zero = R::splat(0.0);
        let one = R::splat(1.0);
        // (cos φ, sin φ) ∝ (αx cos 2πuy, αy sin 2πuy): no arc tangent.
        let (s, c) = sin_cos_turn(uy);
        let (px, py) = (c * alpha_x, s * alpha_y);
        let r = (px * px + py * py).sqrt();
        let (cos_phi, sin_phi) = (px / r, py / r);
        let a = cos_phi * cos_phi * (R::splat(1.0) / (alpha_x * alpha_x)) + sin_phi * sin_phi * (R::splat(1.0) / (alpha_y * alpha_y));
        let tan2 = self.tan2_d_cos(ux, a);
        // tan² = ∞ is the horizon. sin θ from tan²θ directly: √(1 − cos²θ) loses it to f32 rounding for
        // narrow lobes (2026-11: chi-square failed at α = 0.01).
        let finite = tan2.is_finite();
        let cos_theta = R::select(finite, one / (tan2 + 1.0).sqrt(), zero);
        let sin_theta = R::select(finite, (tan2 / (tan2 + 1.0)).sqrt(), one);
        V3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
    }

    /// A microfacet normal drawn from D·cos (`visible` false) or from the normals visible from `wo` (which
    /// must then be above the surface); its density is [`pdf_wm`](Self::pdf_wm).
    #[inline(always)]
    fn sample_wm<R: Real>(&self, wo: V3<R>, ux: R, uy: R, visible: bool) -> V3<R> {
        if self.samples_visible(visible) {
            self.sample_visible(wo, ux, uy)
        } else {
            self.sample_d_cos(ux, uy)
        }
    }

    /// The solid-angle density of a normal drawn from D·cos (`visible` false) or from the normals visible
    /// from `wo` (0 for `wo` not above the surface).
    #[inline(always)]
    fn pdf_wm<R: Real>(&self, wo: V3<R>, wm: V3<R>, visible: bool) -> R {
        let zero = R::splat(0.0);
        if !self.samples_visible(visible) {
            return self.d(wm) * wm.z.max(zero);
        }
        let pdf = self.g1(wo, wm) * wo.dot(wm).max(zero) * self.d(wm) / wo.z;
        R::select(wo.z.le(zero), zero, pdf)
    }

    /// The density of ωi = reflect(ωo, ωm) when ωm is drawn as [`pdf_wm`](Self::pdf_wm) says: pdf(ωm) /
    /// (4 |ωo·ωm|) (Walter 2007 eq. 14); 0 where not finite ([`scattered_density`]). For visible normals
    /// ωo·ωm cancels: G1 D / (4 cos θo) where ωo·ωm > 0 (one division instead of two).
    #[inline(always)]
    fn pdf_reflected<R: Real>(&self, wo: V3<R>, wm: V3<R>, visible: bool) -> R {
        let zero = R::splat(0.0);
        if !self.samples_visible(visible) {
            return scattered_density(self.pdf_wm(wo, wm, false), R::splat(1.0) / (wo.dot(wm).abs() * 4.0));
        }
        let pdf = self.g1(wo, wm) * self.d(wm) / (wo.z * 4.0);
        let pdf = R::select(wo.z.le(zero) | wo.dot(wm).le(zero), zero, pdf);
        R::select(pdf.is_finite(), pdf, zero)
    }

    /// The density of ωi refracted from ωo about ωm with relative index `eta` = ηi/ηo, when ωm is drawn as
    /// [`pdf_wm`](Self::pdf_wm) says: pdf(ωm) η² |ωi·ωm| / (ωo·ωm + η ωi·ωm)² (Walter 2007 eqs. 16, 17).
    #[inline(always)]
    fn pdf_refracted<R: Real>(&self, wo: V3<R>, wi: V3<R>, wm: V3<R>, eta: R, visible: bool) -> R {
        let denom = wo.dot(wm) + eta * wi.dot(wm);
        scattered_density(self.pdf_wm(wo, wm, visible), eta * eta * wi.dot(wm).abs() / (denom * denom))
    }

    /// The microfacet reflection term D(ωh) G1(ωo, ωh) G1(ωi, ωh) / (4 cos θo cos θi) (Walter 2007 eq. 20
    /// without F, separable Smith G of eq. 23) from the unnormalised half vector h = ωo + ωi, l = |h|², for
    /// ωo, ωi above the surface and on ωh's front side (the caller selects the other lanes away); not
    /// finite within f32 underflow or overflow. Symmetric in ωo, ωi bit for bit.
    #[inline(always)]
    fn smith_reflection_term<R: Real>(&self, wo: V3<R>, wi: V3<R>, h: V3<R>, l: R) -> R {
        let wm = h.scale(R::splat(1.0) / l.sqrt());
        self.d(wm) * (self.g1(wo, wm) * self.g1(wi, wm)) / (wo.z * wi.z * 4.0)
    }

    /// [`pdf_reflected`](Self::pdf_reflected) of visible normals from the unnormalised half vector
    /// h = ωo + ωi, l = |h|²: G1(ωo) D / (4 cos θo); 0 unless ωo is above the surface and ωo·h > 0, and
    /// where not finite.
    #[inline(always)]
    fn pdf_reflected_visible_h<R: Real>(&self, wo: V3<R>, h: V3<R>, l: R) -> R {
        self.pdf_reflected(wo, h.scale(R::splat(1.0) / l.sqrt()), true)
    }
}

/// pdf(ωm) · |dωm/dωi|, the density of a direction scattered about a sampled microfacet normal; 0 where it
/// is not finite. Within f32 underflow of the horizon (ωo·ωm → 0, or ωo + η ωi → 0 for refraction) the
/// Jacobian overflows while the direction has no measurable density (2026-11: one guard for every
/// microfacet BSDF, which used to repeat it).
#[inline(always)]
pub(crate) fn scattered_density<R: Real>(pdf_wm: R, jacobian: R) -> R {
    let pdf = pdf_wm * jacobian;
    R::select(pdf.is_finite(), pdf, R::splat(0.0))
}
