//! `twosided` — make one-sided reflection models reflect on both sides (Mitsuba's `twosided`): a direction
//! pair below the surface is mirrored through the surface plane (z → −z) and handed to the back model.
//!
//! | parameter | type        | default        | meaning                                          |
//! |-----------|-------------|----------------|--------------------------------------------------|
//! | (nested)  | 1 or 2 bsdf | —              | front model, and optionally a different back one |
//!
//! Nested models must be purely reflective (a transmissive model already has two sides).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let d = Bsdf::from_json(r#"{"type": "twosided", "x": {"type": "diffuse", "reflectance": 1}}"#).unwrap();
//! assert!(d.f(-Vec3::Z, -Vec3::Z).r() > 0.3);
//! ```

use super::lanes::{f_one, pdf_one, sample_one, LaneSample};
use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// A BSDF that reflects on both sides.
#[derive(Clone, Debug, PartialEq)]
pub struct TwoSided {
    front: Box<Bsdf>,
    back: Box<Bsdf>,
    /// Whether the back is the front's model (one nested BSDF): lanes on either side then run it once.
    mirrored: bool,
}

impl TwoSided {
    /// `front` on the +z side, `back` (mirrored) on the −z side.
    #[must_use]
    pub fn new(front: Bsdf, back: Bsdf) -> Self {
        let mirrored = front == back;
        TwoSided { front: Box::new(front), back: Box::new(back), mirrored }
    }

    /// The model of both sides, where one nested model is both (the front and the back are equal).
    pub(crate) fn both_sides(&mut self) -> Option<&mut Bsdf> {
        self.mirrored.then_some(&mut *self.front)
    }

    /// The models built from the k-th of `count` nested descriptions, to change parameters they read as
    /// they are: one nested model is both sides; of two, the front (k = 0) or the back (k = 1), after
    /// which the sides are run as one only if they are still equal (as [`Self::new`] decides).
    /// Calls `f` on each; returns how many.
    pub(crate) fn for_sides(&mut self, k: usize, count: usize, f: &mut dyn FnMut(&mut Bsdf)) -> usize {
        match (count, k) {
            (1, 0) => {
                f(&mut self.front);
                f(&mut self.back);
                2
            }
            (2, 0 | 1) => {
                f(if k == 0 { &mut self.front } else { &mut self.back });
                self.mirrored = self.front == self.back;
                1
            }
            _ => 0,
        }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let nested = p.nested();
        let models = nested.iter().map(|n| Bsdf::from_props(n)).collect::<Result<Vec<_>>>()?;
        for (m, n) in models.iter().zip(&nested) {
            if m.flags().intersects(BsdfFlags::TRANSMISSION) {
                return Err(Error::spec(n.at(), format!("`twosided` accepts only reflecting BSDFs; `{}` transmits", m.plugin_name())));
            }
        }
        let mut it = models.into_iter();
        match (it.next(), it.next(), it.next()) {
            (Some(front), None, None) => Ok(TwoSided::new(front.clone(), front)),
            (Some(front), Some(back), None) => Ok(TwoSided::new(front, back)),
            _ => Err(Error::spec(p.at(), format!("`twosided` needs one or two nested BSDFs, got {}", nested.len()))),
        }
    }
}

impl crate::bsdf::Examples for TwoSided {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "twosided", "a": {"type": "diffuse"}}"#,
        r#"{"type": "twosided", "a": {"type": "diffuse", "reflectance": 1}, "b": {"type": "conductor", "material": "Ag"}}"#,
    ];
}

impl BsdfModel for TwoSided {
    fn flags(&self) -> BsdfFlags {
        self.front.flags() | self.back.flags()
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

impl TwoSided {
    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// `w` mirrored through the surface (z → −z) in the lanes of `m`.
#[inline(always)]
fn flip_where<R: Real>(m: R::Mask, w: V3<R>) -> V3<R> {
    V3::new(w.x, w.y, R::select(m, -w.z, w.z))
}

impl TwoSided {
    /// Runs `side(model, wo, lanes)` for the front's lanes and the back's (wo below the surface: the
    /// directions mirrored into the back model's upper hemisphere), and keeps each lane's own, where
    /// `select(lanes, a, b)` merges two results. A mirrored model runs once for both sides.
    #[inline(always)]
    fn per_side<R: Real, T: Copy>(
        &self,
        wo: V3<R>,
        active: R::Mask,
        none: T,
        side: impl Fn(&Bsdf, V3<R>, R::Mask) -> T,
        select: impl Fn(R::Mask, T, T) -> T,
    ) -> T {
        let back = wo.z.lt(R::splat(0.0));
        let wo = flip_where(back, wo);
        let sides = if self.mirrored {
            [(&*self.front, active), (&*self.front, !super::lanes::all::<R>())]
        } else {
            [(&*self.front, active & !back), (&*self.back, active & back)]
        };
        // One loop (one copy of the nested models' lane code), each side where it has lanes.
        let mut out = none;
        for (model, lanes) in sides {
            if R::any(lanes) {
                out = select(lanes, side(model, wo, lanes), out);
            }
        }
        out
    }

    /// [`Bsdf::f_lanes_where`] of `twosided`.
    #[inline(always)]
    pub(crate) fn f_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        let wi = flip_where(wo.z.lt(R::splat(0.0)), wi);
        let select = |m: R::Mask, a: [R; 3], b: [R; 3]| channels!(|c| R::select(m, a[c], b[c]));
        self.per_side(wo, active, [R::splat(0.0); 3], |m, wo, lanes| m.leaf_f(wo, wi, lanes), select)
    }

    /// [`Bsdf::pdf_lanes_where`] of `twosided`.
    #[inline(always)]
    pub(crate) fn pdf_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        let wi = flip_where(wo.z.lt(R::splat(0.0)), wi);
        self.per_side(wo, active, R::splat(0.0), |m, wo, lanes| m.leaf_pdf(wo, wi, lanes), R::select)
    }

    /// [`Bsdf::sample_lanes_where`] of `twosided`: the sampled direction mirrored back on the back side.
    #[inline(always)]
    pub(crate) fn sample_lanes_where<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        let back = wo.z.lt(R::splat(0.0));
        let none = LaneSample::none(!super::lanes::all::<R>());
        let s = self.per_side(wo, active, none, |m, wo, lanes| m.leaf_sample(wo, uc, ux, uy, lanes), LaneSample::select);
        LaneSample { wi: flip_where(back, s.wi), ..s }
    }
}

lane_model_where!(TwoSided);

#[cfg(test)]
mod tests {
    use super::*;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;

    #[test]
    fn back_side_mirrors_the_front_or_uses_its_own_model() {
        let t = Bsdf::from_json(
            r#"{"type": "twosided", "f": {"type": "diffuse", "reflectance": 0.2}, "b": {"type": "diffuse", "reflectance": 0.8}}"#,
        )
        .unwrap();
        let (wo, wi) = (Vec3::new(0.0, 0.6, -0.8), Vec3::new(0.6, 0.0, -0.8));
        assert!((t.f(wo, wi).r() - 0.8 / std::f32::consts::PI).abs() < 1e-6);
        assert!((t.f(-wo, -wi).r() - 0.2 / std::f32::consts::PI).abs() < 1e-6);
        assert!(t.f(wo, -wi).is_black(), "no transmission");
        let s = t.sample(wo, 0.5, Vec2::new(0.3, 0.7)).unwrap();
        assert!(s.wi.z < 0.0 && (s.weight.r() - 0.8).abs() < 1e-6);
        assert!(Bsdf::from_json(r#"{"type": "twosided", "a": {"type": "dielectric"}}"#).is_err());
    }
}
