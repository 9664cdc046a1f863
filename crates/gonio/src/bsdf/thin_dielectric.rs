//! `thindielectric` — a thin slab of dielectric (a window pane, a soap film) with parallel smooth faces.
//! Light reflects at the front, or enters, bounces between the faces any number of times and leaves
//! through the front (reflection) or the back (transmission, undeviated: the two refractions cancel).
//!
//! Summing the geometric series of inter-reflections with single-interface reflectance R and T = 1 − R:
//! R' = R + T² R / (1 − R²) = 2R / (1 + R), T' = 1 − R' (absorption-free slab; pbrt-v4 §9.5.2's
//! ThinDielectricBxDF, Mitsuba's `thindielectric`).
//!
//! | parameter                | type          | default | meaning                                    |
//! |--------------------------|---------------|---------|--------------------------------------------|
//! | `int_ior`                | float, name or law | `bk7` | index of the slab; may vary with wavelength ([`Dispersion`]) |
//! | `ext_ior`                | float, name or law | `air` | index around it                        |
//! | `dispersive`, `abbe`     |               |         | as for `dielectric` ([`Dispersion`])        |
//! | `specular_reflectance`   | rgb [0,1]     | 1       | multiplier on reflection                    |
//! | `specular_transmittance` | rgb [0,1]     | 1       | multiplier on transmission                  |
//!
//! Symmetric: both sides behave alike. Transmission leaves through the same medium it entered, so there
//! is no radiance scaling and `eta` is 1.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let pane = Bsdf::from_json(r#"{"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0}"#).unwrap();
//! let s = pane.sample(Vec3::Z, 0.5, Vec2::ZERO).unwrap();
//! assert!((s.wi + Vec3::Z).length() < 1e-6); // straight through
//! assert!((s.pdf - (1.0 - 2.0 * 0.04 / 1.04)).abs() < 1e-6);
//! ```

use super::dielectric::{interface_ior, reflect_or_transmit, Dispersion};
use super::lanes::{sample_one, LaneModel, LaneSample};
use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::Result;
use crate::fresnel::fresnel_dielectric_lanes;
use crate::math::lanes::{Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::Rgb;
use std::sync::Arc;

/// A thin dielectric slab.
#[derive(Clone, Debug, PartialEq)]
pub struct ThinDielectric {
    /// Relative index η = int_ior / ext_ior.
    pub eta: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
    /// How η varies with wavelength, if it does ([`Dispersion`]).
    pub dispersion: Option<Arc<Dispersion>>,
}

impl ThinDielectric {
    pub fn from_props(p: &Props) -> Result<Self> {
        let (eta, dispersion) = interface_ior(p)?;
        Ok(ThinDielectric {
            eta,
            dispersion,
            specular_reflectance: p.reflectance("specular_reflectance", Rgb::ONE)?,
            specular_transmittance: p.reflectance("specular_transmittance", Rgb::ONE)?,
        })
    }

    /// Total reflectance R' = 2R/(1 + R) of the slab at incidence cosine `cos_theta` (either side).
    #[must_use]
    pub fn reflected_fraction(&self, cos_theta: f32) -> f32 {
        self.reflected_fraction_lanes(cos_theta)
    }

    /// [`Self::reflected_fraction`] in lanes.
    #[inline(always)]
    fn reflected_fraction_lanes<R: Real>(&self, cos_theta: R) -> R {
        let r = fresnel_dielectric_lanes(cos_theta.abs(), self.eta);
        // Grazing light (R = 1) is reflected entirely: 2·1/(1+1) = 1, no special case needed.
        r * 2.0 / (r + 1.0)
    }

    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// The model in lanes ([`LaneModel`]), which its `sample` runs for one direction.
impl LaneModel for ThinDielectric {
    #[inline(always)]
    fn f_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> [R; 3] {
        [R::splat(0.0); 3]
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> R {
        R::splat(0.0)
    }

    /// [`reflect_or_transmit`] with the slab's r: transmission is undeviated and leaves into the medium it
    /// came from (η = 1); none for ωo in the plane.
    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, _ux: R, _uy: R) -> LaneSample<R> {
        let (zero, one) = (R::splat(0.0), R::splat(1.0));
        let r = self.reflected_fraction_lanes(wo.z);
        let s = reflect_or_transmit(wo, uc, r, self.specular_reflectance, self.specular_transmittance, wo.neg(), one, !wo.z.eq(zero));
        LaneSample { valid: s.valid & !wo.z.eq(zero), ..s }
    }
}

impl crate::bsdf::Examples for ThinDielectric {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "thindielectric"}"#,
        r#"{"type": "thindielectric", "int_ior": 2.4, "specular_reflectance": [1, 0.5, 0.2]}"#,
        r#"{"type": "thindielectric", "int_ior": 1.0, "ext_ior": 1.0}"#,
    ];
}

impl BsdfModel for ThinDielectric {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DELTA_REFLECTION | BsdfFlags::DELTA_TRANSMISSION
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
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::fresnel::fresnel_dielectric;

    #[test]
    fn slab_reflectance_is_the_sum_of_the_interreflection_series() {
        let slab = ThinDielectric { eta: 1.5, specular_reflectance: Rgb::ONE, specular_transmittance: Rgb::ONE, dispersion: None };
        for cos in [1.0f32, 0.6, 0.2, 0.01] {
            let r = fresnel_dielectric(cos, 1.5);
            let t = 1.0 - r;
            // R + T²R + T²R³ + … summed term by term.
            let series: f32 = r + (0..200).map(|k| t * t * r.powi(2 * k + 1)).sum::<f32>();
            assert!((slab.reflected_fraction(cos) - series).abs() < 1e-5, "cos {cos}");
            assert_eq!(slab.reflected_fraction(-cos), slab.reflected_fraction(cos), "both sides alike");
        }
        let s = slab.sample(Vec3::new(0.6, 0.0, -0.8), 0.99, Vec2::ZERO).unwrap();
        assert!((s.wi - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6, "transmission is undeviated");
        assert_eq!(s.eta, 1.0);
    }
}
