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

use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// A BSDF that reflects on both sides.
#[derive(Clone, Debug, PartialEq)]
pub struct TwoSided {
    front: Box<Bsdf>,
    back: Box<Bsdf>,
}

#[inline]
fn flip(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

impl TwoSided {
    /// `front` on the +z side, `back` (mirrored) on the −z side.
    #[must_use]
    pub fn new(front: Bsdf, back: Bsdf) -> Self {
        TwoSided { front: Box::new(front), back: Box::new(back) }
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

    /// The model for the side of `wo`, and whether directions must be mirrored.
    #[inline]
    fn side(&self, wo: Vec3) -> (&Bsdf, bool) {
        if wo.z < 0.0 {
            (&self.back, true)
        } else {
            (&self.front, false)
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
        match self.side(wo) {
            (m, true) => m.f(flip(wo), flip(wi)),
            (m, false) => m.f(wo, wi),
        }
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        match self.side(wo) {
            (m, true) => m.sample(flip(wo), uc, u).map(|s| BsdfSample { wi: flip(s.wi), ..s }),
            (m, false) => m.sample(wo, uc, u),
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.side(wo) {
            (m, true) => m.pdf(flip(wo), flip(wi)),
            (m, false) => m.pdf(wo, wi),
        }
    }
}

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
