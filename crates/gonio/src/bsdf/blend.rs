//! `blendbsdf` — Mitsuba's blend of two BSDFs: f = (1 − weight)·f₁ + weight·f₂, where f₁ is the first
//! nested BSDF and f₂ the second (weight 0 shows the first alone, 1 the second). A convex combination, so it
//! conserves energy when both components do. Implemented as a two-term [`Sum`](super::Sum).
//!
//! | parameter | type          | default | meaning                                   |
//! |-----------|---------------|---------|-------------------------------------------|
//! | `weight`  | float [0,1]   | 0.5     | the share of the second nested BSDF       |
//! | (nested)  | two bsdfs     | —       | first and second component, in order      |
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let b = Bsdf::from_json(r#"{"type": "blendbsdf", "weight": 0.25,
//!     "a": {"type": "diffuse", "reflectance": 0.0}, "b": {"type": "diffuse", "reflectance": 1.0}}"#).unwrap();
//! assert!((b.f(Vec3::Z, Vec3::Z).r() - 0.25 / std::f32::consts::PI).abs() < 1e-6);
//! ```

use super::{Bsdf, Sum};
use crate::error::{Error, Result};
use crate::props::Props;

/// A convex blend of two BSDFs.
#[derive(Clone, Debug, PartialEq)]
pub struct BlendBsdf {
    pub weight: f32,
    mix: Sum,
}

impl BlendBsdf {
    /// (1 − weight)·first + weight·second.
    #[must_use]
    pub fn new(first: Bsdf, second: Bsdf, weight: f32) -> Self {
        BlendBsdf { weight, mix: Sum::new(vec![first, second], vec![1.0 - weight, weight]) }
    }

    /// The same blend with another weight in [0, 1] (a texture's value at a hit), as [`Self::new`] would
    /// build it.
    pub fn set_weight(&mut self, weight: f32) {
        debug_assert!((0.0..=1.0).contains(&weight));
        self.weight = weight;
        self.mix.set_weights(vec![1.0 - weight, weight]);
    }

    /// The k-th nested model (0: the first, 1: the second), to change parameters it reads as it is.
    pub(crate) fn mix_mut(&mut self) -> &mut Sum {
        &mut self.mix
    }

    pub(crate) fn model_mut(&mut self, k: usize) -> Option<&mut Bsdf> {
        self.mix.components_mut().get_mut(k)
    }

    /// The two-term sum this blend is.
    #[inline(always)]
    pub(crate) fn mix(&self) -> &Sum {
        &self.mix
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let weight = p.float_in("weight", 0.5, 0.0, 1.0)?;
        let nested = p.nested();
        let [first, second] = nested.as_slice() else {
            return Err(Error::spec(p.at(), format!("`blendbsdf` needs exactly two nested BSDFs, got {}", nested.len())));
        };
        Ok(BlendBsdf::new(Bsdf::from_props(first)?, Bsdf::from_props(second)?, weight))
    }
}

impl crate::bsdf::Examples for BlendBsdf {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "blendbsdf", "a": {"type": "diffuse"}, "b": {"type": "conductor", "material": "Au"}}"#,
        r#"{"type": "blendbsdf", "weight": 0.9, "a": {"type": "diffuse", "reflectance": 1}, "b": {"type": "dielectric"}}"#,
        r#"{"type": "blendbsdf", "weight": 0.0, "a": {"type": "diffuse"}, "b": {"type": "thindielectric"}}"#,
    ];
}

forward_bsdf_model!(BlendBsdf => mix);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::BsdfModel;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::math::Vec3;

    #[test]
    fn weight_follows_mitsuba_zero_is_first_one_is_second() {
        let spec = |w: f32| {
            format!(
                r#"{{"type": "blendbsdf", "weight": {w}, "a": {{"type": "diffuse", "reflectance": 0.1}}, "b": {{"type": "diffuse", "reflectance": 0.9}}}}"#
            )
        };
        let f = |w: f32| Bsdf::from_json(&spec(w)).unwrap().f(Vec3::Z, Vec3::Z).r() * std::f32::consts::PI;
        assert!((f(0.0) - 0.1).abs() < 1e-6);
        assert!((f(1.0) - 0.9).abs() < 1e-6);
        assert!((f(0.5) - 0.5).abs() < 1e-6);
        assert!(Bsdf::from_json(r#"{"type": "blendbsdf", "a": {"type": "diffuse"}}"#).is_err());
    }
}
