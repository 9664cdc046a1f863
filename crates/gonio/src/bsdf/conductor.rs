//! `conductor` — a perfectly smooth metal: mirror reflection weighted by the exact Fresnel equations of a
//! conductor with complex index η + i k (Born & Wolf §14.2; pbrt-v4 §9.3.6 and eq. 9.5).
//!
//! | parameter              | type          | default  | meaning                                              |
//! |------------------------|---------------|----------|------------------------------------------------------|
//! | `material`             | string        | `"none"` | named metal (`Au`, `Ag`, `Al`, `Cu`, `Cr`, `W`, …); `none` reflects 100 % |
//! | `eta`                  | rgb ≥ 0       | preset   | real part η of the relative complex index (instead of `material`) |
//! | `k`                    | rgb ≥ 0       | preset   | imaginary part k (absorption) of the index           |
//! | `specular_reflectance` | rgb [0,1]     | 1        | multiplier on the reflected light (not physical, for artists) |
//!
//! One-sided (light from below is absorbed). A single delta lobe: `sample` returns the mirror direction
//! with probability 1 and weight F(cos θo)·`specular_reflectance`.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let mirror = Bsdf::from_json(r#"{"type": "conductor"}"#).unwrap();
//! let s = mirror.sample(Vec3::new(0.6, 0.0, 0.8), 0.5, Vec2::splat(0.5)).unwrap();
//! assert!((s.wi - Vec3::new(-0.6, 0.0, 0.8)).length() < 1e-6);
//! assert_eq!(s.weight, gonio::Rgb::ONE);
//! ```

use super::lanes::{flag_lanes, sample_one, LaneModel, LaneSample};
use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::fresnel::{fresnel_conductor_rgb, fresnel_conductor_rgb_lanes, reflect_lanes};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::Props;
use crate::spectrum::piecewise::PiecewiseLinear;
use crate::spectrum::sampled::unbounded_at;
use crate::spectrum::{named, Rgb};
use std::sync::Arc;

/// A smooth conductor.
#[derive(Clone, Debug, PartialEq)]
pub struct Conductor {
    /// Real part of the complex index; `None` (with `k`) for the 100 % reflecting `material = "none"`.
    pub eta_k: Option<(Rgb, Rgb)>,
    pub specular_reflectance: Rgb,
    /// The named metal `eta_k` was reduced from (`material`), whose spectra spectral mode reads
    /// ([`named::conductor_spectra`]); `None` for an index given as `eta`/`k` and for the mirror.
    pub metal: Option<&'static str>,
    /// `eta` and `k` where they were given as tables (`<spectrum>` pairs or `.spd` files; `eta_k` holds
    /// their RGB reductions), which spectral mode reads.
    pub tables: [Option<Arc<PiecewiseLinear>>; 2],
}

impl Conductor {
    /// A conductor with complex index `eta + i k`.
    #[must_use]
    pub fn new(eta: Rgb, k: Rgb) -> Self {
        Conductor { eta_k: Some((eta, k)), specular_reflectance: Rgb::ONE, metal: None, tables: [None, None] }
    }

    /// The perfect mirror (`material = "none"`).
    #[must_use]
    pub fn mirror() -> Self {
        Conductor { eta_k: None, specular_reflectance: Rgb::ONE, metal: None, tables: [None, None] }
    }

    /// Read `material` or `eta`/`k`, and `specular_reflectance`. Rough conductors read their Fresnel term
    /// through this too, so the parameters mean the same in every conductor plugin.
    pub fn from_props(p: &Props) -> Result<Self> {
        let material = p.string("material")?;
        let metal = material.as_deref().and_then(|m| named::CONDUCTORS.iter().copied().find(|&n| n == m && n != "none"));
        let has_index = p.has("eta") || p.has("k");
        let eta = p.rgb_in("eta", Rgb::ZERO, 0.0, f32::MAX)?;
        let k = p.rgb_in("k", Rgb::ZERO, 0.0, f32::MAX)?;
        let specular_reflectance = p.reflectance("specular_reflectance", Rgb::ONE)?;
        let eta_k = match (material, has_index) {
            (Some(_), true) => {
                return Err(Error::spec(p.at(), format!("give either `material` or `eta`/`k` to `{}`, not both", p.plugin_type())))
            }
            (None, true) => {
                if (0..3).any(|c| eta.0[c] + k.0[c] <= 0.0) {
                    return Err(Error::spec(p.at(), format!("`{}` needs eta + k > 0 in every channel", p.plugin_type())));
                }
                Some((eta, k))
            }
            (None, false) => None,
            (Some(m), false) if m == "none" => None,
            (Some(m), false) => Some(named::conductor(&m).ok_or_else(|| {
                Error::spec(p.at(), format!("unknown conductor material `{m}`; expected one of: {}", named::CONDUCTORS.join(", ")))
            })?),
        };
        let tables = index_tables(p, eta, k)?;
        Ok(Conductor { eta_k, specular_reflectance, metal, tables })
    }

    /// This conductor at the wavelengths `lambda` (nm) in its three channels (spectral mode;
    /// `scene::spectral`): a named metal's η and k from its spectra, `eta` and `k` from their tables where
    /// they were given as tables, else from their colours' unbounded spectra ([`unbounded_at`]).
    pub fn set_wavelengths(&mut self, lambda: [f32; 3]) {
        #[allow(clippy::cast_possible_truncation)]
        let at = |s: &crate::spectrum::piecewise::PiecewiseLinear| Rgb(lambda.map(|l| s.eval_clamped(f64::from(l)) as f32));
        self.eta_k = match (self.metal.and_then(named::conductor_spectra), self.eta_k) {
            (Some(spectra), _) => Some((at(&spectra.0), at(&spectra.1))),
            (None, Some((eta, k))) => {
                let [eta_table, k_table] = &self.tables;
                let one =
                    |table: &Option<Arc<PiecewiseLinear>>, rgb: Rgb| table.as_deref().map_or_else(|| Rgb(unbounded_at(rgb.0, lambda)), at);
                Some((one(eta_table, eta), one(k_table, k)))
            }
            (None, None) => None,
        };
    }

    /// Fresnel reflectance times `specular_reflectance` at incidence cosine `cos_theta_i` ≥ 0.
    #[must_use]
    #[inline(always)]
    pub fn reflectance(&self, cos_theta_i: f32) -> Rgb {
        let fresnel = match self.eta_k {
            Some((eta, k)) => fresnel_conductor_rgb(cos_theta_i, eta, k),
            None => Rgb::ONE,
        };
        fresnel * self.specular_reflectance
    }
}

/// `eta` and `k` where they were given as tables, checked: every value ≥ 0, and η + k > 0 at every nm of
/// the visible range (360–830) as spectral mode reads them (the colour `eta`, `k` where not a table), as
/// the colours must be in every channel.
fn index_tables(p: &Props, eta_rgb: Rgb, k_rgb: Rgb) -> Result<[Option<Arc<PiecewiseLinear>>; 2]> {
    let tables = [p.spectrum_table("eta"), p.spectrum_table("k")];
    if tables.iter().all(Option::is_none) {
        return Ok([None, None]);
    }
    for (table, name) in tables.iter().zip(["eta", "k"]) {
        if let Some(t) = table {
            if t.values().iter().any(|v| *v < 0.0) {
                return Err(Error::spec(p.at_param(name), format!("`{name}` of `{}`: a table with a value < 0", p.plugin_type())));
            }
        }
    }
    let [eta, k] = &tables;
    #[allow(clippy::cast_precision_loss)]
    for nm in 360..=830_u16 {
        let l = f32::from(nm);
        let value = |t: &Option<PiecewiseLinear>, rgb: Rgb| {
            t.as_ref().map_or(f64::from(unbounded_at(rgb.0, [l; 3])[0]), |t| t.eval_clamped(f64::from(l)))
        };
        if value(eta, eta_rgb) + value(k, k_rgb) <= 0.0 {
            return Err(Error::spec(
                p.at(),
                format!("`{}` needs eta + k > 0 at every wavelength; the tables give 0 at {nm} nm", p.plugin_type()),
            ));
        }
    }
    Ok(tables.map(|t| t.map(Arc::new)))
}

impl crate::bsdf::Examples for Conductor {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "conductor"}"#,
        r#"{"type": "conductor", "material": "Au"}"#,
        r#"{"type": "conductor", "material": "Cu", "specular_reflectance": [0.2, 0.5, 1.0]}"#,
        r#"{"type": "conductor", "eta": [0.001, 1, 40], "k": [0, 0.001, 100]}"#,
    ];
}

impl BsdfModel for Conductor {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DELTA_REFLECTION
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

impl Conductor {
    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// The model in lanes ([`LaneModel`]), which its `sample` runs for one direction: the path tracer's packets
/// run it for the lanes on one conductor.
impl LaneModel for Conductor {
    #[inline(always)]
    fn f_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> [R; 3] {
        [R::splat(0.0); 3]
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> R {
        R::splat(0.0)
    }

    /// The mirror direction 2 (ωo·n) n − ωo, n = +z ([`reflect`](crate::fresnel::reflect)), with
    /// probability 1 and weight F(cos θo) · `specular_reflectance`; none from below the surface.
    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, _uc: R, _ux: R, _uy: R) -> LaneSample<R> {
        let above = !wo.z.le(R::splat(0.0));
        let fresnel = match self.eta_k {
            Some((eta, k)) => fresnel_conductor_rgb_lanes(wo.z, eta, k),
            None => [R::splat(1.0); 3],
        };
        let s = self.specular_reflectance.0;
        let value = channels!(|c| fresnel[c] * s[c]);
        let wi = reflect_lanes(wo, V3::splat(Vec3::Z));
        LaneSample::delta(wi, value, R::splat(1.0), flag_lanes(BsdfFlags::DELTA_REFLECTION | BsdfFlags::DELTA), R::splat(1.0), above)
    }
}
