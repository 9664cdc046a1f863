//! `sum` — a linear combination Σₖ wₖ fₖ of nested BSDFs: "a BRDF is usually a sum of components"
//! (a diffuse base plus a glossy or mirror lobe). gonio's own plugin; `blendbsdf` is built on it.
//!
//! | parameter | type            | default   | meaning                                              |
//! |-----------|-----------------|-----------|------------------------------------------------------|
//! | (nested)  | bsdf, ≥ 1       | —         | the components, under any names, in the order given  |
//! | `weights` | list of floats ≥ 0 | all 1  | wₖ, one per component                                |
//!
//! Not energy conserving by construction: with Σ wₖ > 1 the albedo may exceed 1, which `gonio check`
//! reports. Sampling picks component k with probability wₖ/Σw (one-sample MIS, Veach 1997 §9.2.4),
//! then evaluates the whole mixture at the sampled direction so that `pdf` and `weight` are those of the
//! mixture; a sampled delta lobe keeps its own discrete probability times wₖ/Σw.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let s = Bsdf::from_json(r#"{"type": "sum", "weights": [0.5, 0.25],
//!     "a": {"type": "diffuse", "reflectance": 1.0}, "b": {"type": "diffuse", "reflectance": 1.0}}"#).unwrap();
//! assert!((s.f(Vec3::Z, Vec3::Z).r() - 0.75 / std::f32::consts::PI).abs() < 1e-6);
//! ```

use super::lanes::{f_one, pdf_one, sample_one, LaneSample};
use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// A weighted sum of BSDFs.
#[derive(Clone, Debug, PartialEq)]
pub struct Sum {
    components: Vec<Bsdf>,
    weights: Vec<f32>,
    /// Selection probabilities wₖ / Σw.
    probs: Vec<f32>,
}

impl Sum {
    /// A sum of `components` with `weights` (non-negative, not all zero, as many as components).
    ///
    /// # Panics
    /// In debug builds, when the lengths differ or a weight is negative.
    #[must_use]
    pub fn new(components: Vec<Bsdf>, weights: Vec<f32>) -> Self {
        let mut sum = Sum { components, weights: Vec::new(), probs: Vec::new() };
        sum.set_weights(weights);
        sum
    }

    /// New weights for the same components (non-negative, as many as components), with their selection
    /// probabilities.
    pub(crate) fn set_weights(&mut self, weights: Vec<f32>) {
        debug_assert_eq!(self.components.len(), weights.len());
        debug_assert!(weights.iter().all(|w| *w >= 0.0));
        let total: f32 = weights.iter().sum();
        self.probs = weights.iter().map(|w| if total > 0.0 { w / total } else { 0.0 }).collect();
        self.weights = weights;
    }

    #[must_use]
    pub fn components(&self) -> &[Bsdf] {
        &self.components
    }

    /// The components, to change parameters they read as they are (`Bsdf::reflectance_slot`).
    pub(crate) fn components_mut(&mut self) -> &mut [Bsdf] {
        &mut self.components
    }

    #[must_use]
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let nested = p.nested();
        if nested.is_empty() {
            return Err(Error::spec(p.at(), "`sum` needs at least one nested BSDF"));
        }
        let components = nested.into_iter().map(Bsdf::from_props).collect::<Result<Vec<_>>>()?;
        let weights = match p.floats("weights")? {
            None => vec![1.0; components.len()],
            Some(w) => {
                if w.len() != components.len() {
                    return Err(Error::spec(p.at(), format!("`sum` has {} nested BSDFs but {} weights", components.len(), w.len())));
                }
                if w.iter().any(|v| *v < 0.0) || w.iter().all(|v| *v == 0.0) {
                    return Err(Error::spec(p.at(), "`sum` weights must be ≥ 0 and not all zero"));
                }
                w.into_iter().map(|v| v as f32).collect()
            }
        };
        Ok(Sum::new(components, weights))
    }
}

impl crate::bsdf::Examples for Sum {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "sum", "weights": [0.7, 0.3], "base": {"type": "diffuse", "reflectance": 1.0}, "coat": {"type": "conductor"}}"#,
        r#"{"type": "sum", "weights": [0.5, 0.5], "a": {"type": "diffuse"}, "b": {"type": "dielectric"}}"#,
        r#"{"type": "sum", "weights": [1, 0], "a": {"type": "diffuse"}, "b": {"type": "conductor", "material": "Au"}}"#,
    ];
}

impl BsdfModel for Sum {
    fn flags(&self) -> BsdfFlags {
        self.components.iter().zip(&self.weights).filter(|(_, w)| **w > 0.0).fold(BsdfFlags::NONE, |acc, (c, _)| acc | c.flags())
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

impl Sum {
    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

impl Sum {
    /// [`Bsdf::f_lanes_where`] of `sum`: Σₖ wₖ fₖ.
    #[inline(always)]
    pub(crate) fn f_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        self.components.iter().zip(&self.weights).fold([R::splat(0.0); 3], |acc, (c, &w)| {
            let f = c.leaf_f(wo, wi, active);
            channels!(|k| acc[k] + f[k] * w)
        })
    }

    /// [`Bsdf::pdf_lanes_where`] of `sum`: Σₖ pₖ pdfₖ over the components that can be chosen.
    #[inline(always)]
    pub(crate) fn pdf_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        self.components
            .iter()
            .zip(&self.probs)
            .filter(|(_, p)| **p > 0.0)
            .fold(R::splat(0.0), |acc, (c, &p)| acc + c.leaf_pdf(wo, wi, active) * p)
    }

    /// [`Bsdf::sample_lanes_where`] of `sum`: component k chosen by `uc` with probability pₖ (`uc`
    /// rescaled for its own use), then a smooth direction weighted by the whole mixture's f and pdf (every
    /// component's smooth lobes may have produced it), a delta direction by its own probability times pₖ.
    #[inline(always)]
    pub(crate) fn sample_lanes_where<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        let none = !super::lanes::all::<R>();
        let Some(last) = self.probs.iter().rposition(|p| *p > 0.0) else {
            return LaneSample::none(none);
        };
        let (mut s, mut taken, mut start) = (LaneSample::none(none), none, 0.0f32);
        for (k, (c, (&w, &p))) in self.components.iter().zip(self.weights.iter().zip(&self.probs)).enumerate() {
            if p > 0.0 {
                // The last component that can be chosen takes the lanes left (rounding in Σp).
                let here = !taken & if k == last { !none } else { uc.lt(R::splat(start + p)) };
                taken = taken | here;
                if R::any(active & here) {
                    let u = ((uc - start) / p).clamp(0.0, 1.0 - f32::EPSILON);
                    let sk = c.leaf_sample(wo, u, ux, uy, active & here);
                    let sk =
                        LaneSample { f: channels!(|i| sk.f[i] * w), pdf: sk.pdf * p, weight: channels!(|i| sk.weight[i] * (w / p)), ..sk };
                    s = LaneSample::select(here, sk, s);
                }
            }
            start += p;
        }
        // Smooth directions: the mixture's f and pdf there.
        let smooth = s.valid & !s.is_delta();
        if !R::any(smooth) {
            return s;
        }
        let (f, pdf) = (self.f_lanes_where(wo, s.wi, smooth), self.pdf_lanes_where(wo, s.wi, smooth));
        let mixed = LaneSample { eta: s.eta, ..LaneSample::smooth(s.wi, f, pdf, s.flags, smooth) };
        LaneSample::select(smooth, mixed, s)
    }
}

lane_model_where!(Sum);

#[cfg(test)]
mod tests {
    use super::*;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;

    #[test]
    fn mixture_of_smooth_and_delta_lobes() {
        let s = Bsdf::from_json(
            r#"{"type": "sum", "weights": [0.6, 0.2], "a": {"type": "diffuse", "reflectance": 1}, "b": {"type": "conductor"}}"#,
        )
        .unwrap();
        let wo = Vec3::new(0.6, 0.0, 0.8);
        // Selection probabilities 0.75 / 0.25.
        let d = s.sample(wo, 0.9, Vec2::splat(0.3)).unwrap();
        assert!(d.flags.has_delta());
        assert!((d.pdf - 0.25).abs() < 1e-6 && (d.weight.r() - 0.2 / 0.25).abs() < 1e-5);
        let m = s.sample(wo, 0.1, Vec2::splat(0.3)).unwrap();
        assert!(!m.flags.has_delta());
        assert!((m.pdf - 0.75 * m.wi.z / std::f32::consts::PI).abs() < 1e-6);
        assert!((m.weight.r() - 0.6 / 0.75).abs() < 1e-5);
        assert_eq!(s.flags(), BsdfFlags::DIFFUSE_REFLECTION | BsdfFlags::DELTA_REFLECTION);
    }

    #[test]
    fn weights_are_validated() {
        for bad in [
            r#"{"type": "sum", "weights": [1], "a": {"type": "diffuse"}, "b": {"type": "diffuse"}}"#,
            r#"{"type": "sum", "weights": [-1, 1], "a": {"type": "diffuse"}, "b": {"type": "diffuse"}}"#,
            r#"{"type": "sum", "weights": [0, 0], "a": {"type": "diffuse"}, "b": {"type": "diffuse"}}"#,
            r#"{"type": "sum"}"#,
        ] {
            assert!(Bsdf::from_json(bad).is_err(), "{bad}");
        }
    }
}
