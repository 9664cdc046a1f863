//! `mask` — an opacity mask over another model (Mitsuba 3's `mask`): with probability α (the opacity) light
//! meets the nested model, otherwise it passes straight through as if the surface were not there.
//!
//! | parameter | type              | default | meaning                                            |
//! |-----------|-------------------|---------|----------------------------------------------------|
//! | `opacity` | float (texture)   | 0.5     | α, clamped to [0, 1] as Mitsuba does                |
//! | (nested)  | bsdf              | —       | the model where the surface is opaque              |
//!
//! f = α · f_nested, pdf = α · pdf_nested, and a null lobe: a delta transmission to wi = −wo carrying
//! 1 − α, chosen with probability 1 − α (weight 1, relative index 1). Mitsuba 3, `src/bsdfs/mask.cpp`.
//! A textured opacity is a grey value per hit (an image's luminance, as Mitsuba's `eval_1`).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let m = Bsdf::from_json(r#"{"type": "mask", "opacity": 0.25, "b": {"type": "diffuse", "reflectance": 0.8}}"#).unwrap();
//! let s = m.sample(Vec3::Z, 0.9, Vec2::new(0.5, 0.5)).unwrap(); // uc ≥ α: the null lobe
//! assert_eq!(s.wi, -Vec3::Z);
//! assert!((s.weight.r() - 1.0).abs() < 1e-6);
//! ```

use super::lanes::{f_one, flag_lanes, pdf_one, sample_one, LaneSample};
use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// A nested model seen with probability `opacity`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mask {
    opacity: f32,
    nested: Box<Bsdf>,
}

impl Mask {
    /// The model it masks.
    pub(crate) fn nested_mut(&mut self) -> &mut Bsdf {
        &mut self.nested
    }

    /// `nested` with opacity `opacity` (clamped to [0, 1]).
    #[must_use]
    pub fn new(opacity: f32, nested: Bsdf) -> Self {
        Mask { opacity: opacity.clamp(0.0, 1.0), nested: Box::new(nested) }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        // Mitsuba clamps the opacity instead of rejecting it; so does gonio, for textures and constants alike.
        let opacity = p.float_in("opacity", 0.5, f32::MIN, f32::MAX)?;
        let nested = p.nested();
        match nested.as_slice() {
            [one] => Ok(Mask::new(opacity, Bsdf::from_props(one)?)),
            _ => Err(Error::spec(p.at(), format!("`mask` needs exactly one nested BSDF, got {}", nested.len()))),
        }
    }
}

impl crate::bsdf::Examples for Mask {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "mask", "b": {"type": "diffuse"}}"#,
        r#"{"type": "mask", "opacity": 0.2, "b": {"type": "twosided", "c": {"type": "diffuse", "reflectance": 0.9}}}"#,
        r#"{"type": "mask", "opacity": 0.7, "b": {"type": "roughconductor", "alpha": 0.3, "material": "Au"}}"#,
        r#"{"type": "mask", "opacity": 1, "b": {"type": "dielectric"}}"#,
    ];
}

impl BsdfModel for Mask {
    fn flags(&self) -> BsdfFlags {
        let nested = if self.opacity > 0.0 { self.nested.flags() } else { BsdfFlags::NONE };
        if self.opacity < 1.0 {
            nested | BsdfFlags::DELTA_TRANSMISSION
        } else {
            nested
        }
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

impl Mask {
    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

impl Mask {
    /// [`Bsdf::f_lanes_where`] of `mask`: the nested model's f times the opacity α.
    #[inline(always)]
    pub(crate) fn f_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        self.nested.leaf_f(wo, wi, active).map(|v| v * self.opacity)
    }

    /// [`Bsdf::pdf_lanes_where`] of `mask`: the nested model's density times α.
    #[inline(always)]
    pub(crate) fn pdf_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        self.nested.leaf_pdf(wo, wi, active) * self.opacity
    }

    /// [`Bsdf::sample_lanes_where`] of `mask`: with probability α the nested model (f and pdf both scale
    /// by α, the weight does not), else straight through (a delta transmission of weight 1).
    #[inline(always)]
    pub(crate) fn sample_lanes_where<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        let nested = uc.lt(R::splat(self.opacity));
        let null = 1.0 - self.opacity;
        let through = LaneSample::delta(
            wo.neg(),
            [R::splat(null); 3],
            R::splat(null),
            flag_lanes(BsdfFlags::DELTA_TRANSMISSION),
            R::splat(1.0),
            active & !nested,
        );
        if !R::any(active & nested) {
            return through;
        }
        let s = self.nested.leaf_sample(wo, uc / self.opacity, ux, uy, active & nested);
        let s = LaneSample { f: channels!(|c| s.f[c] * self.opacity), pdf: s.pdf * self.opacity, ..s };
        LaneSample::select(nested, s, through)
    }
}

lane_model_where!(Mask);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Examples;
    use crate::verify::{check, CheckConfig};

    #[test]
    fn examples_pass_every_check() {
        for spec in Mask::EXAMPLES {
            let report = check(&Bsdf::from_json(spec).unwrap(), &CheckConfig::quick());
            assert!(report.passed(), "{spec}\n{}", report.to_table());
        }
    }

    #[test]
    fn opacity_scales_the_nested_model_and_the_rest_passes_through() {
        let m = Mask::new(0.3, Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.5}"#).unwrap());
        let (wo, wi) = (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.48, 0.0, 0.877_496_4));
        assert!((m.f(wo, wi).r() - 0.3 * 0.5 / std::f32::consts::PI).abs() < 1e-6);
        assert!((m.pdf(wo, wi) - 0.3 * wi.z / std::f32::consts::PI).abs() < 1e-6);
        // uc below α: the diffuse lobe (weight ρ); above: straight through (weight 1, probability 1 − α).
        let s = m.sample(wo, 0.1, Vec2::new(0.3, 0.4)).unwrap();
        assert!(s.wi.z > 0.0 && (s.weight.r() - 0.5).abs() < 1e-6 && (s.pdf - m.pdf(wo, s.wi)).abs() < 1e-6);
        let t = m.sample(wo, 0.5, Vec2::new(0.3, 0.4)).unwrap();
        assert!(t.wi == -wo && t.flags.contains(BsdfFlags::DELTA_TRANSMISSION) && (t.pdf - 0.7).abs() < 1e-6 && t.weight.r() == 1.0);
        assert!(Mask::new(7.0, Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap()).opacity == 1.0);
    }
}
