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
//! **Dispersion keeps every wavelength.** The slab's directions do not depend on its index (the mirror
//! direction, or straight through), only the split between them does. So in spectral mode a dispersive
//! slab takes a relative index per channel, one per wavelength of the path ([`ThinDielectric::set_wavelengths`]),
//! rather than following the hero wavelength alone as a dispersive `dielectric` must: with R'_c the slab's
//! reflectance at channel c's index, reflection is chosen with probability P = (R'_0 + R'_1 + R'_2)/3 and
//! its value in channel c is R'_c (transmission: 1 − P and 1 − R'_c), so each channel's expectation is its
//! own wavelength's, unbiased, and no wavelength's estimate is dropped (less colour noise behind dispersive
//! panes than pbrt-v4's termination would give).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let pane = Bsdf::from_json(r#"{"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0}"#).unwrap();
//! let s = pane.sample(Vec3::Z, 0.5, Vec2::ZERO).unwrap();
//! assert!((s.wi + Vec3::Z).length() < 1e-6); // straight through
//! assert!((s.pdf - (1.0 - 2.0 * 0.04 / 1.04)).abs() < 1e-6);
//! ```

use super::dielectric::{interface_ior, reflect_or_transmit, split_sample, Dispersion};
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
    /// In spectral mode, the relative index at each channel's wavelength, where they differ
    /// ([`Self::set_wavelengths`]); `None`: `eta` for every channel.
    pub eta_channels: Option<[f32; 3]>,
}

impl ThinDielectric {
    pub fn from_props(p: &Props) -> Result<Self> {
        let (eta, dispersion) = interface_ior(p)?;
        Ok(ThinDielectric {
            eta,
            dispersion,
            eta_channels: None,
            specular_reflectance: p.reflectance("specular_reflectance", Rgb::ONE)?,
            specular_transmittance: p.reflectance("specular_transmittance", Rgb::ONE)?,
        })
    }

    /// The slab at the wavelengths `lambda` (nm, one per channel) of a path in spectral mode, where it is
    /// dispersive: the relative index of each channel's wavelength (one index, `eta`, where the three are
    /// the same wavelength, as for a model at one wavelength). A slab that does not disperse is unchanged.
    pub fn set_wavelengths(&mut self, lambda: [f32; 3]) {
        let Some(law) = &self.dispersion else { return };
        let etas = lambda.map(|l| law.eta(l));
        self.eta = etas[0];
        self.eta_channels = (etas[1] != etas[0] || etas[2] != etas[0]).then_some(etas);
    }

    /// Total reflectance R' = 2R/(1 + R) of the slab at incidence cosine `cos_theta` (either side).
    #[must_use]
    pub fn reflected_fraction(&self, cos_theta: f32) -> f32 {
        slab_reflectance(cos_theta, self.eta)
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
        let s = match self.eta_channels {
            None => {
                let r = slab_reflectance(wo.z, self.eta);
                reflect_or_transmit(wo, uc, r, self.specular_reflectance, self.specular_transmittance, wo.neg(), one, !wo.z.eq(zero))
            }
            Some(etas) => {
                // One index per channel: the split chosen by the channels' mean reflectance, each channel's
                // value its own (module docs).
                let r = etas.map(|eta| slab_reflectance(wo.z, eta));
                let p = (r[0] + r[1] + r[2]) * (1.0 / 3.0);
                let reflected = std::array::from_fn(|c| r[c] * self.specular_reflectance.0[c]);
                let transmitted = std::array::from_fn(|c| (one - r[c]) * self.specular_transmittance.0[c]);
                split_sample(wo, uc, p, reflected, transmitted, wo.neg(), one, !wo.z.eq(zero))
            }
        };
        LaneSample { valid: s.valid & !wo.z.eq(zero), ..s }
    }
}

/// The slab's reflectance R' = 2R/(1 + R) at incidence cosine `cos_theta` (either side) and relative
/// index `eta`, in lanes.
#[inline(always)]
fn slab_reflectance<R: Real>(cos_theta: R, eta: f32) -> R {
    let r = fresnel_dielectric_lanes(cos_theta.abs(), eta);
    // Grazing light (R = 1) is reflected entirely: 2·1/(1+1) = 1, no special case needed.
    r * 2.0 / (r + 1.0)
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
        let slab = ThinDielectric {
            eta: 1.5,
            specular_reflectance: Rgb::ONE,
            specular_transmittance: Rgb::ONE,
            dispersion: None,
            eta_channels: None,
        };
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

    /// A dispersive slab keeps every wavelength (issue 30): at three wavelengths, each channel's value in
    /// either direction is that of the slab at that channel's wavelength alone, and the direction is chosen
    /// by the channels' mean reflectance. At one wavelength it is the slab of that index, bit for bit.
    #[test]
    fn a_dispersive_slab_keeps_every_wavelength() {
        let spec = r#"{"type": "thindielectric", "int_ior": "sf11", "specular_reflectance": [1, 0.8, 0.6]}"#;
        let slab = || match crate::bsdf::Bsdf::from_json(spec).unwrap() {
            crate::bsdf::Bsdf::ThinDielectric(t) => t,
            other => panic!("{other:?}"),
        };
        let at = |lambda: [f32; 3]| {
            let mut t = slab();
            t.set_wavelengths(lambda);
            t
        };
        let three = at([420.0, 550.0, 680.0]);
        let etas = three.eta_channels.expect("three indices");
        assert!(etas[0] > etas[1] && etas[1] > etas[2], "normal dispersion: {etas:?}");
        for cos in [0.95f32, 0.5, 0.1] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let r = etas.map(|eta| slab_reflectance(cos, eta));
            let p = (r[0] + r[1] + r[2]) / 3.0;
            for (uc, reflected) in [(0.0, true), (0.999_9, false)] {
                let s = three.sample(wo, uc, Vec2::ZERO).unwrap();
                assert_eq!(s.wi.z > 0.0, reflected);
                assert!((s.pdf - if reflected { p } else { 1.0 - p }).abs() < 1e-6);
                for (c, l) in [420.0f32, 550.0, 680.0].into_iter().enumerate() {
                    let alone = at([l; 3]);
                    assert!(alone.eta_channels.is_none() && alone.eta == etas[c]);
                    let a = alone.sample(wo, uc, Vec2::ZERO).unwrap();
                    assert_eq!(a.wi, s.wi);
                    // The value (f · pdf for a delta lobe: weight × pdf) of channel c at its own index.
                    let (got, want) = (s.weight.0[c] * s.pdf, a.weight.0[c] * a.pdf);
                    assert!((got - want).abs() < 1e-6, "cos {cos}, channel {c}: {got} against {want}");
                }
            }
        }
        // Not dispersive: nothing to set.
        let mut plain = ThinDielectric::from_props(&Props::from_json(r#"{"type": "thindielectric"}"#).unwrap()).unwrap();
        let before = plain.clone();
        plain.set_wavelengths([420.0, 550.0, 680.0]);
        assert_eq!(plain, before);
    }
}
