//! `polarizer` — Mitsuba 3's ideal linear polarizer as its *unpolarized* variants render it (the
//! `*_rgb` and `*_spectral` ones, and gonio, which carries no polarization state): a surface that lets
//! light pass straight through, undeviated, and absorbs half of it (an ideal linear polarizer passes half
//! of unpolarized light; Mitsuba 3, `src/bsdfs/polarizer.cpp`, "in unpolarized rendering modes").
//!
//! | parameter       | type              | default | meaning                                             |
//! |-----------------|-------------------|---------|-----------------------------------------------------|
//! | `transmittance` | rgb [0, 1]        | 1       | multiplies what passes (the ½ included once more)    |
//! | `theta`         | float (degrees)   | 0       | the polarizer's rotation: read, no effect without polarization |
//! | `polarizing`    | boolean           | true    | Mitsuba's switch to a neutral-density filter: the same here |
//!
//! A delta transmission to ωi = −ωo (either side) carrying ½ `transmittance`, chosen with probability 1;
//! no reflection, f = 0 and pdf = 0 for every pair of directions. Two polarizers pass a quarter whatever
//! their angles (Malus's law needs the polarization state gonio does not carry): `tu_polarizers`
//! renders as Mitsuba's `llvm_ad_rgb`, not as its `*_polarized` variants.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let p = Bsdf::from_json(r#"{"type": "polarizer", "theta": 45}"#).unwrap();
//! let s = p.sample(Vec3::new(0.6, 0.0, 0.8), 0.3, Vec2::ZERO).unwrap();
//! assert_eq!(s.wi, Vec3::new(-0.6, 0.0, -0.8));
//! assert!((s.weight.g() - 0.5).abs() < 1e-7 && s.pdf == 1.0);
//! ```

use super::lanes::{flag_lanes, sample_one, LaneModel, LaneSample};
use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::Result;
use crate::math::lanes::{Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;

/// An ideal linear polarizer seen by unpolarized light: a half-transmitting pass-through.
#[derive(Clone, Debug, PartialEq)]
pub struct Polarizer {
    pub transmittance: Rgb,
}

impl Polarizer {
    pub fn from_props(p: &Props) -> Result<Self> {
        let _ = p.float_in("theta", 0.0, f32::MIN, f32::MAX)?;
        let _ = p.bool("polarizing", true)?;
        Ok(Polarizer { transmittance: p.reflectance("transmittance", Rgb::ONE)? })
    }

    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// The model in lanes ([`LaneModel`]), which its `sample` runs for one direction.
impl LaneModel for Polarizer {
    #[inline(always)]
    fn f_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> [R; 3] {
        [R::splat(0.0); 3]
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> R {
        R::splat(0.0)
    }

    /// Straight through with ½ `transmittance`, probability 1; none for ωo in the plane.
    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, _uc: R, _ux: R, _uy: R) -> LaneSample<R> {
        let (zero, one) = (R::splat(0.0), R::splat(1.0));
        let value = self.transmittance.0.map(|t| R::splat(0.5 * t));
        LaneSample::delta(wo.neg(), value, one, flag_lanes(BsdfFlags::DELTA_TRANSMISSION), one, !wo.z.eq(zero))
    }
}

impl crate::bsdf::Examples for Polarizer {
    const EXAMPLES: &'static [&'static str] =
        &[r#"{"type": "polarizer"}"#, r#"{"type": "polarizer", "theta": 90, "transmittance": [1, 0.5, 0.2]}"#];
}

impl BsdfModel for Polarizer {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DELTA_TRANSMISSION
    }

    fn f(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        sample_one(self, wo, uc, u)
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    lane_batch_methods!(lanes);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bsdf, Examples};
    use crate::verify::{check, CheckConfig};

    #[test]
    fn examples_pass_every_check() {
        for spec in Polarizer::EXAMPLES {
            let report = check(&Bsdf::from_json(spec).unwrap(), &CheckConfig::quick());
            assert!(report.passed(), "{spec}\n{}", report.to_table());
        }
    }

    /// Half of the light passes, times the transmittance, from either side; nothing reflects.
    #[test]
    fn half_passes_straight_through_from_both_sides() {
        let p = Bsdf::from_json(r#"{"type": "polarizer", "transmittance": [1, 0.5, 0.2]}"#).unwrap();
        for wo in [Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.3, -0.4, -0.866_025_4)] {
            let s = p.sample(wo, 0.7, Vec2::new(0.1, 0.9)).unwrap();
            assert_eq!(s.wi, -wo);
            assert_eq!((s.weight, s.pdf, s.eta), (Rgb::new(0.5, 0.25, 0.1), 1.0, 1.0));
            assert!(s.flags.contains(BsdfFlags::DELTA_TRANSMISSION));
            assert_eq!((p.f(wo, -wo), p.pdf(wo, -wo)), (Rgb::ZERO, 0.0));
        }
        assert!(Bsdf::from_json(r#"{"type": "polarizer", "transmittance": 2}"#).is_err());
    }
}
