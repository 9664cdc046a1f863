//! The microfacet reflection lobe of Walter et al. 2007, "Microfacet Models for Refraction through Rough
//! Surfaces", written once over the distribution and the lanes: f = F(ωo·ωh) D(ωh) G(ωo, ωi, ωh) /
//! (4 cos θo cos θi) with ωh = (ωo + ωi)/|ωo + ωi| (eq. 20), sampled by drawing ωh and reflecting ωo about
//! it, pdf(ωi) = pdf(ωh) / (4 ωo·ωh) (eq. 14). The models multiply in their own Fresnel term (a conductor's,
//! a dielectric coating's).
//!
//! Every term is taken from the unnormalised half vector h = ωo + ωi and l = |h|²: ωo·ωh = ωi·ωh = |h|/2
//! exactly (ωo·h + ωi·h = h·h), so F's cosine is √l/2 and f(ωo, ωi) = f(ωi, ωo) bit for bit.

use super::distribution::Distribution;
use super::Shadowing;
use crate::fresnel::reflect_lanes;
use crate::math::lanes::{Real, V3};

/// A reflection lobe: a distribution, its masking–shadowing form and whether visible normals are sampled
/// (runtime choices, the same for every lane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectionLobe<D> {
    pub distribution: D,
    pub shadowing: Shadowing,
    pub visible: bool,
}

/// The lobe's value at a pair of directions, before the Fresnel term.
#[derive(Clone, Copy, Debug)]
pub struct LobeValue<R: Real> {
    /// D G / (4 cos θo cos θi), meaningful where `ok`.
    pub value: R,
    /// ωo·ωh = |ωo + ωi|/2, the Fresnel term's cosine.
    pub cos_theta_d: R,
    /// Where the lobe is non-zero: both directions above the surface and on ωh's front side, and the value
    /// finite (within f32 underflow of the horizon 4 cos θo cos θi rounds to 0, and only an unshadowed
    /// model gets there with D > 0: its f is unbounded there; 2026-11, reported as 0, never NaN/Inf).
    pub ok: R::Mask,
}

/// A sampled direction and the lanes where it is one.
#[derive(Clone, Copy, Debug)]
pub struct LobeSample<R: Real> {
    pub wi: V3<R>,
    pub valid: R::Mask,
}

impl<D: Distribution> ReflectionLobe<D> {
    /// D(ωh) G(ωo, ωi, ωh) / (4 cos θo cos θi) (see [`LobeValue`]).
    #[inline(always)]
    pub fn eval<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> LobeValue<R> {
        let zero = R::splat(0.0);
        let h = wo.add(wi);
        let l = h.dot(h);
        let d = &self.distribution;
        let value = match self.shadowing {
            Shadowing::Smith => d.smith_reflection_term(wo, wi, h, l),
            shadowing => {
                let wm = h.scale(R::splat(1.0) / l.sqrt());
                d.d(wm) * d.g(wo, wi, wm, shadowing) / (wo.z * wi.z * 4.0)
            }
        };
        let ok = wo.z.gt(zero) & wi.z.gt(zero) & wo.dot(h).gt(zero) & wi.dot(h).gt(zero) & value.is_finite();
        LobeValue { value, cos_theta_d: l.sqrt() * 0.5, ok }
    }

    /// The solid-angle density of [`sample`](Self::sample): pdf(ωh) / (4 ωo·ωh); 0 unless both directions
    /// are above the surface.
    #[inline(always)]
    pub fn pdf<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        let zero = R::splat(0.0);
        let h = wo.add(wi);
        let l = h.dot(h);
        let d = &self.distribution;
        let pdf = if d.samples_visible(self.visible) {
            d.pdf_reflected_visible_h(wo, h, l)
        } else {
            d.pdf_reflected(wo, h.scale(R::splat(1.0) / l.sqrt()), false)
        };
        R::select(wo.z.le(zero) | wi.z.le(zero), zero, pdf)
    }

    /// Draw ωh (visible normals or D·cos), reflect ωo about it; valid where ωo and ωi are above the
    /// surface (and ωi is not NaN) and ωh faces ωo. A D·cos normal facing away from ωo reflects it to the
    /// direction whose half vector is −ωh, where [`pdf`](Self::pdf) (D(−ωh) = 0) does not count it: such a
    /// sample is rejected, so that the density of the accepted ones is `pdf` (a model mixing this lobe with
    /// another would otherwise weight it by the other lobe's density).
    #[inline(always)]
    pub fn sample<R: Real>(&self, wo: V3<R>, ux: R, uy: R) -> LobeSample<R> {
        let zero = R::splat(0.0);
        let wm = self.distribution.sample_wm(wo, ux, uy, self.visible);
        let wi = reflect_lanes(wo, wm).normalize();
        LobeSample { wi, valid: !wo.z.le(zero) & wo.dot(wm).gt(zero) & !(wi.z.is_nan() | wi.z.le(zero)) }
    }
}
