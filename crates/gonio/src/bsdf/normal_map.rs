//! `normalmap` — a nested model seen in a shading frame turned to a normal read from a texture (Mitsuba 3's
//! `normalmap`): normal mapping, detail without geometry.
//!
//! | parameter   | type          | default     | meaning                                                      |
//! |-------------|---------------|-------------|--------------------------------------------------------------|
//! | `normalmap` | rgb (texture) | (½, ½, 1)   | the normal in the shading frame, each component x ↦ (x + 1)/2 (a `bitmap` with `raw` = true) |
//! | (nested)    | bsdf          | —           | the model the normal map turns                               |
//!
//! With n′ = normalize(2c − 1) from the texture's colour c, the frame F′ has normal n′, first tangent the
//! shading frame's first tangent (∂p/∂u) made perpendicular to n′, and t′ = n′ × s′. The nested model sees
//! ωo′ = F′ωo and ωi′ = F′ωi; where ωi lies on opposite sides of the two frames (cos θi · cos θi′ ≤ 0) nothing
//! scatters (Mitsuba's test). gonio's f excludes the cosine, which the integrator takes in the shading frame,
//! so f = f_nested(ωo′, ωi′) |cos θi′| / |cos θi| (Mitsuba's `eval` returns f_nested |cos θi′|); the density
//! and a sample's weight are the nested model's. Not reciprocal (a shading normal is not): its perturbed
//! examples are kept as `reciprocity` violations.
//!
//! Where gonio differs from Mitsuba 3.9.1: 3.9.1 also bends the mapped normal with the viewing direction
//! (its fix for black regions at grazing angles; docs/mitsuba-compatibility.md measures it: 0.5 % on
//! `t_normalmap`); gonio does not yet. And Mitsuba takes the frame's tangent from ∂p/∂u in world space
//! while n′ is in the shading frame (its `NormalMap::frame`), a tangent that turns an anisotropic nested model
//! by an angle that depends on the surface's orientation in the world; gonio uses ∂p/∂u in the shading
//! frame, as the texture's normal is. Isotropic nested models (the common case) see no difference.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let flat = Bsdf::from_json(r#"{"type": "normalmap", "normalmap": [0.5, 0.5, 1], "b": {"type": "diffuse", "reflectance": 0.5}}"#).unwrap();
//! let (wo, wi) = (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.48, 0.0, 0.877_496_4));
//! assert!((flat.f(wo, wi).r() - 0.5 / std::f32::consts::PI).abs() < 1e-6); // (½, ½, 1) is the normal +z
//! ```

use super::lanes::{f_one, pdf_one, sample_one, LaneSample};
use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Frame, Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// A nested model in the frame of a mapped normal.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The texture's colour c (the normal is 2c − 1).
    pub normalmap: Rgb,
    nested: Box<Bsdf>,
}

impl NormalMap {
    #[must_use]
    pub fn new(normalmap: Rgb, nested: Bsdf) -> Self {
        NormalMap { normalmap, nested: Box::new(nested) }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let normalmap = p.rgb_in("normalmap", Rgb::new(0.5, 0.5, 1.0), f32::MIN, f32::MAX)?;
        let nested = p.nested();
        match nested.as_slice() {
            [one] => Ok(NormalMap::new(normalmap, Bsdf::from_props(one)?)),
            _ => Err(Error::spec(p.at(), format!("`normalmap` needs exactly one nested BSDF, got {}", nested.len()))),
        }
    }

    /// The frame F′ of the mapped normal, in the shading frame (module docs); the shading frame itself
    /// where the colour encodes no direction (c = (½, ½, ½)).
    #[must_use]
    pub fn frame(&self) -> Frame {
        let [r, g, b] = self.normalmap.0;
        let Some(n) = Vec3::new(2.0 * r - 1.0, 2.0 * g - 1.0, 2.0 * b - 1.0).try_normalize() else {
            return Frame::from_normal(Vec3::Z);
        };
        match (Vec3::X - n * n.x).try_normalize() {
            Some(s) => Frame { s, t: n.cross(s), n },
            None => Frame::from_normal(n),
        }
    }

    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// `v` in the frame (s, t, n), in lanes.
#[inline(always)]
fn to_frame<R: Real>(f: &Frame, v: V3<R>) -> V3<R> {
    V3::new(v.dot(V3::splat(f.s)), v.dot(V3::splat(f.t)), v.dot(V3::splat(f.n)))
}

/// |cos θi′| / |cos θi| where ωi is on the same side of both frames, else 0 (nothing scatters there).
#[inline(always)]
fn cosine_ratio<R: Real>(cos: R, cos_mapped: R) -> R {
    let zero = R::splat(0.0);
    R::select((cos * cos_mapped).gt(zero), cos_mapped.abs() / cos.abs(), zero)
}

/// The nested f times the cosine ratio; 0 where that overflows (ωi within ~10⁻³⁸ of the horizon, where
/// f · cos θi, what counts, is bounded).
#[inline(always)]
fn scaled<R: Real>(f: [R; 3], ratio: R) -> [R; 3] {
    channels!(|c| {
        let v = f[c] * ratio;
        R::select(v.is_finite(), v, R::splat(0.0))
    })
}

impl NormalMap {
    /// [`Bsdf::f_lanes_where`] of `normalmap`: the nested f in the mapped frame times the cosine ratio.
    #[inline(always)]
    pub(crate) fn f_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        let frame = self.frame();
        let mapped = to_frame(&frame, wi);
        let ratio = cosine_ratio(wi.z, mapped.z);
        scaled(self.nested.leaf_f(to_frame(&frame, wo), mapped, active & ratio.gt(R::splat(0.0))), ratio)
    }

    /// [`Bsdf::pdf_lanes_where`] of `normalmap`: the nested density (solid angle does not depend on the
    /// frame), 0 where ωi is on opposite sides of the two frames.
    #[inline(always)]
    pub(crate) fn pdf_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        let frame = self.frame();
        let mapped = to_frame(&frame, wi);
        let kept = (wi.z * mapped.z).gt(R::splat(0.0));
        R::select(kept, self.nested.leaf_pdf(to_frame(&frame, wo), mapped, active & kept), R::splat(0.0))
    }

    /// [`Bsdf::sample_lanes_where`] of `normalmap`: the nested model's sample in the mapped frame, turned
    /// back; its weight and density as they are, f times the cosine ratio; none where ωi lands on opposite
    /// sides of the two frames.
    #[inline(always)]
    pub(crate) fn sample_lanes_where<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        let frame = self.frame();
        let s = self.nested.leaf_sample(to_frame(&frame, wo), uc, ux, uy, active);
        let wi = V3::splat(frame.s).scale(s.wi.x).add(V3::splat(frame.t).scale(s.wi.y)).add(V3::splat(frame.n).scale(s.wi.z));
        let ratio = cosine_ratio(wi.z, s.wi.z);
        LaneSample { wi, f: scaled(s.f, ratio), valid: s.valid & ratio.gt(R::splat(0.0)), ..s }
    }
}

lane_model_where!(NormalMap);

impl crate::bsdf::Examples for NormalMap {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "normalmap", "b": {"type": "diffuse"}}"#,
        r#"{"type": "normalmap", "normalmap": [0.5, 0.5, 1], "b": {"type": "roughconductor", "alpha": 0.3}}"#,
    ];
    /// A turned normal makes f(ωo, ωi) ≠ f(ωi, ωo): the cosine ratio differs (module docs).
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[
        (r#"{"type": "normalmap", "normalmap": [0.7, 0.4, 0.9], "b": {"type": "diffuse", "reflectance": 0.8}}"#, "reciprocity"),
        (r#"{"type": "normalmap", "normalmap": [0.3, 0.6, 0.95], "b": {"type": "roughplastic", "alpha": 0.2}}"#, "reciprocity"),
    ];
}

impl BsdfModel for NormalMap {
    fn flags(&self) -> BsdfFlags {
        self.nested.flags()
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        f_one(self, wo, wi)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        sample_one(self, wo, uc, u)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_one(self, wo, wi)
    }

    lane_batch_methods!(lanes);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Examples;
    use crate::verify::{check, expect_violation, CheckConfig};

    #[test]
    fn examples_pass_every_check_and_turned_normals_break_only_reciprocity() {
        for spec in NormalMap::EXAMPLES {
            let report = check(&Bsdf::from_json(spec).unwrap(), &CheckConfig::quick());
            assert!(report.passed(), "{spec}\n{}", report.to_table());
        }
        for (spec, kind) in NormalMap::VIOLATIONS {
            let report = check(&Bsdf::from_json(spec).unwrap(), &CheckConfig::quick());
            expect_violation(&report, kind).unwrap_or_else(|e| panic!("{spec}: {e}"));
        }
    }

    /// A diffuse model under a turned normal: f = ρ/π |cos θi′| / |cos θi| on the side both frames share,
    /// 0 beyond; samples come back in the shading frame with the nested weight.
    #[test]
    fn a_turned_normal_is_seen_by_the_nested_model() {
        let m = NormalMap::new(Rgb::new(0.8, 0.5, 0.9), Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.6}"#).unwrap());
        let n = Vec3::new(0.6, 0.0, 0.8).normalize();
        assert!((m.frame().n - n).length() < 1e-6);
        let wo = Vec3::new(0.0, 0.6, 0.8);
        for wi in [Vec3::new(0.48, 0.0, 0.877_496_4), Vec3::new(-0.9, 0.1, 0.424_264)] {
            let wi = wi.normalize();
            let cos_mapped = wi.dot(n);
            let want = if cos_mapped > 0.0 { 0.6 / std::f32::consts::PI * cos_mapped / wi.z } else { 0.0 };
            assert!((m.f(wo, wi).r() - want).abs() < 1e-6, "{wi}: {} against {want}", m.f(wo, wi).r());
        }
        let s = m.sample(wo, 0.5, Vec2::new(0.3, 0.7)).unwrap();
        assert!(s.wi.z > 0.0 && s.wi.dot(n) > 0.0 && (s.weight.r() - 0.6).abs() < 1e-5);
        assert!((s.pdf - m.pdf(wo, s.wi)).abs() < 1e-5 && (s.pdf - s.wi.dot(n) / std::f32::consts::PI).abs() < 1e-5);
    }
}
