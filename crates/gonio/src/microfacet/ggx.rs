//! GGX / Trowbridge–Reitz (Walter et al. 2007 eq. 33; anisotropic form as in Heitz 2014 §5):
//! D = 1 / (π αx αy (s² + z²)²) with s² = (x/αx)² + (y/αy)², its closed-form Smith Λ, D·cos sampling
//! (Walter 2007 eq. 35) and Heitz 2018's visible-normal sampler.

use super::distribution::Distribution;
use crate::math::lanes::{Real, V3};
use crate::math::param::Param;
use crate::math::trig::sin_cos_turn;
use std::f32::consts::PI;

/// The GGX distribution in lanes ([`Real`]: one `f32` or eight at a time). Its inherent methods include the
/// reflection terms from the unnormalised half vector that the GGX kernels use (fewer divisions); the
/// [`Distribution`] implementation forwards to them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx<A = f32> {
    pub alpha_x: A,
    pub alpha_y: A,
}

impl<A: Param> Ggx<A> {
    /// D(ωm) = 1 / (π αx αy (s² + z²)²), zero below the surface (Walter 2007 eq. 33; Heitz 2014 §5).
    #[inline(always)]
    #[must_use]
    pub fn d<R: Real>(&self, wm: V3<R>) -> R {
        // Times 1/α (computed once per batch, outside the loop): no divisions per row but the one below.
        let (x, y) = (wm.x * self.alpha_x.recip::<R>(), wm.y * self.alpha_y.recip::<R>());
        let t = x * x + y * y + wm.z * wm.z;
        let d = R::splat(1.0) / (t * (self.alpha_x.lanes::<R>() * PI * self.alpha_y.lanes::<R>()) * t);
        R::select(wm.z.le(R::splat(0.0)), R::splat(0.0), d)
    }

    /// Smith's Λ of the upper-hemisphere direction (x, y, z ≥ 0): 0 at the pole, ∞ on the horizon.
    #[inline(always)]
    #[must_use]
    pub fn lambda_upper<R: Real>(&self, x: R, y: R, z: R) -> R {
        // α(φ)² sin²θ = αx² x² + αy² y² (the projected roughness of the anisotropic case, times sin²θ).
        let (ax, ay) = (x * self.alpha_x.lanes::<R>(), y * self.alpha_y.lanes::<R>());
        let s2 = ax * ax + ay * ay;
        // Λ = (−1 + √(1 + α² tan²θ))/2, written as t / (2 (1 + √(1 + t))) to avoid cancellation at small t.
        let t = s2 / (z * z);
        let lambda = t / ((R::splat(1.0) + (t + 1.0).sqrt()) * 2.0);
        let zero = R::splat(0.0);
        R::select(s2.eq(zero), zero, R::select(z.eq(zero), R::splat(f32::INFINITY), lambda))
    }

    /// Smith masking G1(ω, ωm) = χ⁺(ω·ωm) / (1 + Λ(ω)) (Heitz 2014 eq. 43), ω seen from its own side.
    #[inline(always)]
    #[must_use]
    pub fn g1<R: Real>(&self, w: V3<R>, wm: V3<R>) -> R {
        // 1 / (1 + Λ) with Λ = t / (2 (1 + √(1 + t))), t = s²/z² (see `lambda_upper`), multiplied through by
        // 2 (1 + √(1 + t)) z² = 2 z (z + q), q = √(z² + s²): G1 = 2z(z + q) / (2z(z + q) + s²). One division
        // and one square root instead of three and one (2026-12: the GGX kernels are bound by them); no
        // difference of nearly equal terms. 0 on the horizon (z = 0), 1 at the pole (s² = 0).
        let z = w.z.abs();
        let (ax, ay) = (w.x * self.alpha_x.lanes::<R>(), w.y * self.alpha_y.lanes::<R>());
        let s2 = ax * ax + ay * ay;
        let zq2 = z * (z + (z * z + s2).sqrt()) * 2.0;
        let zero = R::splat(0.0);
        let g = R::select(s2.eq(zero), R::splat(1.0), zq2 / (zq2 + s2));
        R::select((w.dot(wm) * w.z).le(zero), zero, g)
    }

    /// z + q, q = √(z² + α(φ)² sin²θ) with z = |cos θ| (`w` need not be unit: the ratio is scale-free):
    /// Smith's G1 = 2z(z + q) / (2z(z + q) + s²) of [`g1`](Self::g1) is 2z / (z + q), since
    /// (z + q)² = 2z² + 2zq + s². So G1 / (2 cos θ) = 1 / (z + q), finite down to the horizon.
    #[inline(always)]
    fn masking_sum<R: Real>(&self, w: V3<R>) -> R {
        let z = w.z.abs();
        let (ax, ay) = (w.x * self.alpha_x.lanes::<R>(), w.y * self.alpha_y.lanes::<R>());
        z + (z * z + ax * ax + ay * ay).sqrt()
    }

    /// D's denominator for the unnormalised half vector h with l = |h|²: D(h/|h|) = l² / (π αx αy t²),
    /// t = (hx/αx)² + (hy/αy)² + hz² ([`d`](Self::d) multiplied through by |h|⁴; no normalisation).
    #[inline(always)]
    fn d_unnormalised<R: Real>(&self, h: V3<R>, l: R) -> (R, R) {
        let (x, y) = (h.x * self.alpha_x.recip::<R>(), h.y * self.alpha_y.recip::<R>());
        let t = x * x + y * y + h.z * h.z;
        (l * l, t * (self.alpha_x.lanes::<R>() * PI * self.alpha_y.lanes::<R>()) * t)
    }

    /// The microfacet reflection term D(ωh) G1(ωo, ωh) G1(ωi, ωh) / (4 cos θo cos θi) (Walter 2007 eq. 20
    /// without F, separable Smith G of eq. 23) from the unnormalised half vector h = ωo + ωi, l = |h|²,
    /// for ωo, ωi above the surface and both on ωh's front side (the caller selects the other lanes away).
    /// With G1 / (2 cos θ) = 1 / (z + q) ([`masking_sum`](Self::masking_sum)) and D from
    /// [`d_unnormalised`](Self::d_unnormalised) it is l² / (π αx αy t² (zo + qo)(zi + qi)): one division
    /// and two square roots, where the normalised steps take five and three (2026-12). Symmetric in ωo,
    /// ωi bit for bit. Within f32 underflow or overflow it is not finite; callers report 0 there.
    #[inline(always)]
    #[must_use]
    pub fn reflection_term<R: Real>(&self, wo: V3<R>, wi: V3<R>, h: V3<R>, l: R) -> R {
        let (num, den) = self.d_unnormalised(h, l);
        num / (den * (self.masking_sum(wo) * self.masking_sum(wi)))
    }

    /// [`Distribution::pdf_reflected`] of visible normals from the unnormalised half vector h = ωo + ωi,
    /// l = |h|²: G1(ωo) D / (4 cos θo) = l² / (2π αx αy t² (zo + qo)) (see
    /// [`reflection_term`](Self::reflection_term)); 0 unless ωo is above the surface and ωo·h > 0, and
    /// where not finite.
    #[inline(always)]
    #[must_use]
    pub fn pdf_reflected_visible_h<R: Real>(&self, wo: V3<R>, h: V3<R>, l: R) -> R {
        let zero = R::splat(0.0);
        let (num, den) = self.d_unnormalised(h, l);
        let pdf = num / (den * self.masking_sum(wo) * 2.0);
        let pdf = R::select(wo.z.le(zero) | wo.dot(h).le(zero), zero, pdf);
        R::select(pdf.is_finite(), pdf, zero)
    }

    /// Heitz 2018, JCGT 7(4): stretch ωo to the α = 1 configuration, sample the projected hemisphere of
    /// its visible half-disk, reproject, unstretch. Needs `wo.z > 0`.
    #[inline(always)]
    #[must_use]
    pub fn sample_visible<R: Real>(&self, wo: V3<R>, ux: R, uy: R) -> V3<R> {
        let zero = R::splat(0.0);
        let vh = V3::new(wo.x * self.alpha_x.lanes::<R>(), wo.y * self.alpha_y.lanes::<R>(), wo.z).normalize();
        // Orthonormal basis around vh (T1 is horizontal; degenerate at normal incidence).
        let len2 = vh.x * vh.x + vh.y * vh.y;
        // (Its z, 0 / √len2, is 0 wherever len2 > 0 selects it: not divided.)
        let len = len2.sqrt();
        let t1 = V3::select(len2.gt(zero), V3::new(-vh.y / len, vh.x / len, zero), V3::splat(crate::math::Vec3::X));
        let t2 = vh.cross(t1);
        // A uniform point on the unit disk, squeezed onto the visible half: p2 blends towards the
        // half-disk's straight edge by s = (1 + cos θv)/2.
        let r = ux.sqrt();
        // φ = 2π u.y; the polynomial sine and cosine run in lanes.
        let (sin_phi, cos_phi) = sin_cos_turn(uy);
        let p1 = r * cos_phi;
        let s = (vh.z + 1.0) * 0.5;
        let one = R::splat(1.0);
        let p2 = (one - s) * (one - p1 * p1).max(zero).sqrt() + s * r * sin_phi;
        // Project onto the hemisphere around vh.
        let nh = t1.scale(p1).add(t2.scale(p2)).add(vh.scale((one - p1 * p1 - p2 * p2).max(zero).sqrt()));
        // Unstretch (the normal transforms with the inverse transpose).
        V3::new(nh.x * self.alpha_x.lanes::<R>(), nh.y * self.alpha_y.lanes::<R>(), nh.z.max(zero)).normalize()
    }
}

impl<A: Param> Ggx<A> {
    /// tan²θm = u / ((1 − u) A(φ)) (Walter 2007 eq. 35 with the anisotropic A(φ)); ∞ at u = 1.
    #[inline(always)]
    fn tan2_of_sample<R: Real>(ux: R, a: R) -> R {
        ux / ((R::splat(1.0) - ux) * a)
    }
}

impl<A: Param> Distribution for Ggx<A> {
    #[inline(always)]
    fn alphas<R: Real>(&self) -> (R, R) {
        (self.alpha_x.lanes(), self.alpha_y.lanes())
    }
    #[inline(always)]
    fn d<R: Real>(&self, wm: V3<R>) -> R {
        Ggx::d(self, wm)
    }
    #[inline(always)]
    fn lambda_upper<R: Real>(&self, x: R, y: R, z: R) -> R {
        Ggx::lambda_upper(self, x, y, z)
    }
    #[inline(always)]
    fn tan2_d_cos<R: Real>(&self, ux: R, a: R) -> R {
        Self::tan2_of_sample(ux, a)
    }
    #[inline(always)]
    fn sample_visible<R: Real>(&self, wo: V3<R>, ux: R, uy: R) -> V3<R> {
        Ggx::sample_visible(self, wo, ux, uy)
    }
    #[inline(always)]
    fn g1<R: Real>(&self, w: V3<R>, wm: V3<R>) -> R {
        Ggx::g1(self, w, wm)
    }
    #[inline(always)]
    fn smith_reflection_term<R: Real>(&self, wo: V3<R>, wi: V3<R>, h: V3<R>, l: R) -> R {
        self.reflection_term(wo, wi, h, l)
    }
    #[inline(always)]
    fn pdf_reflected_visible_h<R: Real>(&self, wo: V3<R>, h: V3<R>, l: R) -> R {
        Ggx::pdf_reflected_visible_h(self, wo, h, l)
    }
}
