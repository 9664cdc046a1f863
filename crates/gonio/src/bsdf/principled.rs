//! `principled` — Mitsuba 3's principled BSDF: the Disney model (Burley 2012, "Physically Based Shading at
//! Disney"; Burley 2015, "Extending the Disney BRDF to a BSDF with Integrated Subsurface Scattering") as
//! Mitsuba 3 computes it, so that a Mitsuba file means the same thing.
//!
//! | parameter                           | type        | default          | meaning                                           |
//! |-------------------------------------|-------------|------------------|---------------------------------------------------|
//! | `base_color`                        | rgb [0, 1]  | 0.5              | colour of the diffuse, metallic and transmitted light |
//! | `roughness`                         | float [0, 1] | 0.5             | roughness of the main specular lobes (α = roughness²) |
//! | `anisotropic`                       | float [0, 1] | 0               | anisotropy of the main specular lobes (0: isotropic) |
//! | `metallic`                          | float [0, 1] | 0               | blend towards a metal: Schlick Fresnel of `base_color`, no diffuse |
//! | `spec_trans`                        | float [0, 1] | 0               | share of the dielectric that transmits (a rough glass) rather than diffuses |
//! | `eta`                               | float [0.01, 10] | from `specular` | relative index inside/outside (instead of `specular`) |
//! | `specular`                          | float [0, 1] | 0.5             | the index as reflectance: η = 2/(1 − √(0.08 specular)) − 1 (instead of `eta`) |
//! | `spec_tint`                         | float [0, 1] | 0               | share of the dielectric reflection tinted towards `base_color` |
//! | `sheen`                             | float [0, 1] | 0               | strength of the grazing sheen lobe                |
//! | `sheen_tint`                        | float [0, 1] | 0               | tint of the sheen towards `base_color`            |
//! | `flatness`                          | float [0, 1] | 0               | blend of the diffuse towards Burley's fake subsurface (Hanrahan–Krueger-like) |
//! | `clearcoat`                         | float [0, 1] | 0               | strength of the clearcoat lobe                    |
//! | `clearcoat_gloss`                   | float [0, 1] | 0               | gloss of the clearcoat: GTR1 α from 0.1 to 0.001  |
//! | `main_specular_sampling_rate`       | float ≥ 0   | 1                | sampling weight of the main specular lobes        |
//! | `clearcoat_sampling_rate`           | float ≥ 0   | 1                | sampling weight of the clearcoat                  |
//! | `diffuse_reflectance_sampling_rate` | float ≥ 0   | 1                | sampling weight of the diffuse lobe               |
//!
//! Every float in [0, 1] and `base_color` may be a texture (float textures are read with the scalar lookup).
//! `eta` and `specular` are one parameter in two forms: giving both is an error. `flatness` is a parameter
//! of Mitsuba 3.9.1's `principled` too (not only of `principledthin`); it is read and used as there.
//!
//! # Model (f without the cosine; ωo towards the viewer, directions in the shading frame)
//! With m = `metallic`, t = `spec_trans`, the weights of the dielectric's diffusing and transmitting parts
//! are w_d = (1 − m)(1 − t) and w_t = (1 − m) t. Seen from above (cos θo > 0):
//! - **Main specular reflection**: anisotropic GGX with Smith's separable masking (Walter et al. 2007
//!   eq. 20), f = F_p D G / (4 cos θo cos θi), α_x = max(0.001, r²/a), α_y = max(0.001, r² a),
//!   a = √(1 − 0.9 `anisotropic`) (Burley 2012, Appendix B.2). F_p blends (1 − m)(1 − `spec_tint`) times the
//!   *exact* dielectric Fresnel F(ωo·ωh) with Schlick terms m·S(`base_color`) and (1 − m) `spec_tint` ·
//!   S(c_tint R₀(η)), c_tint = `base_color`/luminance (Mitsuba's blend; Burley uses Schlick throughout).
//!   S(R₀) = R₀ + (1 − R₀)(1 − cos)⁵ with cos = ωo·ωh where η > 1, else the refracted cosine.
//! - **Transmission** (t > 0): √`base_color` · w_t times Walter 2007 eq. 21 for radiance (that of
//!   [`RoughDielectric`](super::RoughDielectric), GGX, index η).
//! - **Diffuse** (Burley 2015, §5.3): w_d `base_color`/π · [(1 − F_L/2)(1 − F_V/2) + R_R (F_L + F_V +
//!   F_L F_V (R_R − 1))], F = (1 − |cos θ|)⁵, R_R = 2 `roughness` cos²θd, cos θd = ωi·ωh; blended by
//!   `flatness` towards 1.25 (F_ss (1/(cos θo + cos θi) − ½) + ½), F_ss = (1 + (R_R/2 − 1) F_L)(1 + (R_R/2 − 1) F_V)
//!   (Burley 2012 §5.3's subsurface approximation with Mitsuba's R_R/2 for F_ss90).
//! - **Sheen** (Burley 2012 §5.3): `sheen` (1 − m) (1 − cos θd)⁵ · mix(1, c_tint, `sheen_tint`), without
//!   1/π, as in Disney's reference code.
//! - **Clearcoat**: ¼ `clearcoat` · F_cc D_GTR1(ωh) G, F_cc = S(0.04), GTR1 α = mix(0.1, 0.001,
//!   `clearcoat_gloss`) ([`Gtr1`]), G separable Smith GGX at α = 0.25 (Burley 2012 §5.5, Appendix B.2).
//!   **Mitsuba's form, not Burley's**: it omits the 1/(4 cos θo cos θi) of a microfacet lobe; gonio matches
//!   Mitsuba (the lobe reflects about cos θo times what Burley's would).
//!
//! Seen from below (cos θo < 0) only the interface acts: reflection w_t F D G/(4|cos θo||cos θi|) with F of
//! 1/η (no tint, no metal) and the transmission; no diffuse, sheen or clearcoat. With w_t = 0 nothing
//! scatters from below (wrap it in `twosided` for a two-sided surface, as Blender's exporter does).
//!
//! # Sampling (Mitsuba's lobe probabilities)
//! A microfacet normal ωm is drawn from GGX's visible normals of ωo (turned upwards) first. From above, the
//! lobes are chosen with weights (normalised to sum 1): diffuse w_d · `diffuse_reflectance_sampling_rate`,
//! clearcoat ¼ `clearcoat` · `clearcoat_sampling_rate`, transmission s w_t (1 − F(ωo·ωm)), specular
//! reflection s (1 − w_t (1 − F)), s = `main_specular_sampling_rate`; from below F and 1 − F. The diffuse
//! lobe samples the cosine, the clearcoat GTR1's D·cos, the others reflect or refract ωo about ωm. pdf is
//! the same mixture with F at the half vector of (ωo, ωi), which is ωm for the specular lobes, and the
//! sum of the two specular weights does not depend on F: `pdf` is the exact density of `sample`.
//!
//! # Where gonio differs from Mitsuba 3 (3.9.1)
//! - `pdf` from below is 0 when nothing transmits (w_t = 0): Mitsuba's is the specular lobe's density there,
//!   for a lobe whose value is 0 and which `sample` never draws. No image changes.
//! - Sheen is added wherever its own conditions hold, as Mitsuba's vectorised variants (`llvm_*`, `cuda_*`,
//!   which rendered the reference images) do; the `scalar_*` variants also require w_d > 0, so they drop the
//!   sheen of a fully transmissive (t = 1) surface.
//! - Mitsuba sets η = 1 to 1.001 (and `specular` = 0 to 0.001) when `spec_trans` is given, as gonio does;
//!   a `spec_trans` texture counts as given, as in Mitsuba.
//!
//! # Compared with Mitsuba 3 (3.9.1, `scalar_rgb`)
//! `tests::matches_mitsuba` checks f·|cos θi| and pdf against `eval` and `pdf` of Mitsuba at 1120 pairs of
//! directions over 14 parameter sets (80 each, from above and below, reflected and transmitted, half of
//! them drawn by Mitsuba's `sample`; the numbers in `tests/data/principled_mitsuba.json`, made by
//! `tools/principled_reference.py`): 4480 values agree within 4.4e-5 relative (2026-12-05; floor 1e-6 of a
//! set's largest value), the differences of f32 rounding (GTR1's D is written as sin²θ + α² cos²θ where
//! Mitsuba's 1 + (α² − 1) cos²θ cancels at the pole, Schlick's blend and cos θd taken as |ωo + ωi|/2).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let b = Bsdf::from_json(r#"{"type": "principled", "base_color": [0.8, 0.3, 0.1], "metallic": 0.5, "clearcoat": 1.0}"#).unwrap();
//! let wo = Vec3::new(0.0, 0.6, 0.8);
//! let s = b.sample(wo, 0.3, Vec2::new(0.2, 0.7)).unwrap();
//! assert!(s.wi.z > 0.0 && (s.pdf - b.pdf(wo, s.wi)).abs() <= 1e-5 * s.pdf);
//! ```

use super::lanes::{f_one, flag_lanes, pdf_one, sample_one, LaneModel, LaneSample};
use super::rough_dielectric::{unit_upper, DielectricLobe, GLOSSY_TRANSMISSION};
use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::fresnel::{fresnel_dielectric_lanes, reflect_lanes, refract_lanes};
use crate::math::lanes::{channels, Real, V3};
use crate::math::param::{Param, PerLane, PER_LANE};
use crate::math::{Vec2, Vec3};
use crate::microfacet::reflection::ReflectionLobe;
use crate::microfacet::{Distribution, Ggx, Gtr1, Shadowing};
use crate::props::Props;
use crate::sampling::warp::{cosine_hemisphere, cosine_hemisphere_density};
use crate::spectrum::Rgb;
use std::f32::consts::FRAC_1_PI;

/// The index of refraction, as given: `eta` itself or the `specular` reflectance it is derived from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpecularIndex {
    Eta(f32),
    Specular(f32),
}

/// Mitsuba's principled BSDF (see the module doc). Holds the parameters as given; everything derived from
/// them is computed per call ([`Principled::lobes`]), so that a texture can set any of them at a hit.
#[derive(Clone, Debug, PartialEq)]
pub struct Principled {
    pub base_color: Rgb,
    pub roughness: f32,
    pub anisotropic: f32,
    pub metallic: f32,
    pub spec_trans: f32,
    pub spec_tint: f32,
    pub sheen: f32,
    pub sheen_tint: f32,
    pub flatness: f32,
    pub clearcoat: f32,
    pub clearcoat_gloss: f32,
    pub index: SpecularIndex,
    /// Mitsuba's "has spec_trans": `spec_trans` was given as a texture or a number ≠ 0. Without it the
    /// transmission lobe is off (whatever `spec_trans` holds) and η is taken as given.
    pub transmissive: bool,
    pub main_specular_sampling_rate: f32,
    pub clearcoat_sampling_rate: f32,
    pub diffuse_reflectance_sampling_rate: f32,
}

impl Default for Principled {
    fn default() -> Self {
        Principled {
            base_color: Rgb::splat(0.5),
            roughness: 0.5,
            anisotropic: 0.0,
            metallic: 0.0,
            spec_trans: 0.0,
            spec_tint: 0.0,
            sheen: 0.0,
            sheen_tint: 0.0,
            flatness: 0.0,
            clearcoat: 0.0,
            clearcoat_gloss: 0.0,
            index: SpecularIndex::Specular(0.5),
            transmissive: false,
            main_specular_sampling_rate: 1.0,
            clearcoat_sampling_rate: 1.0,
            diffuse_reflectance_sampling_rate: 1.0,
        }
    }
}

impl Principled {
    pub fn from_props(p: &Props) -> Result<Self> {
        let unit = |name: &'static str, default: f32| p.float_in(name, default, 0.0, 1.0);
        let rate = |name: &'static str| p.float_in(name, 1.0, 0.0, f32::MAX);
        if p.has("eta") && p.has("specular") {
            return Err(Error::spec(p.at(), "give one of `eta` or `specular` to `principled` (both set the index of refraction)"));
        }
        let index = if p.has("eta") {
            SpecularIndex::Eta(p.float_in("eta", 1.5, 0.01, 10.0)?)
        } else {
            SpecularIndex::Specular(unit("specular", 0.5)?)
        };
        let spec_trans = unit("spec_trans", 0.0)?;
        Ok(Principled {
            base_color: p.reflectance("base_color", Rgb::splat(0.5))?,
            roughness: unit("roughness", 0.5)?,
            anisotropic: unit("anisotropic", 0.0)?,
            metallic: unit("metallic", 0.0)?,
            spec_trans,
            spec_tint: unit("spec_tint", 0.0)?,
            sheen: unit("sheen", 0.0)?,
            sheen_tint: unit("sheen_tint", 0.0)?,
            flatness: unit("flatness", 0.0)?,
            clearcoat: unit("clearcoat", 0.0)?,
            clearcoat_gloss: unit("clearcoat_gloss", 0.0)?,
            index,
            // Mitsuba's rule: a parameter given as the number 0 is off.
            transmissive: p.has("spec_trans") && spec_trans != 0.0,
            main_specular_sampling_rate: rate("main_specular_sampling_rate")?,
            clearcoat_sampling_rate: rate("clearcoat_sampling_rate")?,
            diffuse_reflectance_sampling_rate: rate("diffuse_reflectance_sampling_rate")?,
        })
    }

    /// The float parameter `name` in [0, 1] (a texture's value at a hit), if it is one of this model's.
    pub(crate) fn set_unit_float(&mut self, name: &str, value: f32) -> bool {
        let slot = match name {
            "roughness" => &mut self.roughness,
            "anisotropic" => &mut self.anisotropic,
            "metallic" => &mut self.metallic,
            "spec_trans" => {
                // A texture: Mitsuba's flag is set whatever its values.
                self.transmissive = true;
                &mut self.spec_trans
            }
            "spec_tint" => &mut self.spec_tint,
            "sheen" => &mut self.sheen,
            "sheen_tint" => &mut self.sheen_tint,
            "flatness" => &mut self.flatness,
            "clearcoat" => &mut self.clearcoat,
            "clearcoat_gloss" => &mut self.clearcoat_gloss,
            _ => return false,
        };
        *slot = value;
        true
    }

    /// The relative index η: `eta`, or from `specular` (R₀ = 0.08 `specular` = ((η − 1)/(η + 1))²). With
    /// transmission Mitsuba keeps η off 1 (1.001, or `specular` 0.001), where the interface would vanish.
    #[must_use]
    pub fn eta(&self) -> f32 {
        match self.index {
            SpecularIndex::Eta(e) if self.transmissive && e == 1.0 => 1.001,
            SpecularIndex::Eta(e) => e,
            SpecularIndex::Specular(s) => {
                let s = if self.transmissive && s == 0.0 { 1e-3 } else { s };
                2.0 / (1.0 - (0.08 * s).sqrt()) - 1.0
            }
        }
    }

    /// The lobes' constants for these parameters (computed once per call; the lane code reads them).
    #[must_use]
    pub fn lobes(&self) -> PrincipledLobes {
        let eta = self.eta();
        let m = self.metallic;
        let t = if self.transmissive { self.spec_trans } else { 0.0 };
        let (w_diffuse, w_transmit) = ((1.0 - m) * (1.0 - t), (1.0 - m) * t);
        // Burley 2012, Appendix B.2: α = roughness², stretched by the aspect √(1 − 0.9 anisotropic).
        let r2 = self.roughness * self.roughness;
        let aspect = (1.0 - 0.9 * self.anisotropic).sqrt();
        let ggx = Ggx { alpha_x: (r2 / aspect).max(1e-3), alpha_y: (r2 * aspect).max(1e-3) };
        let spec = ReflectionLobe { distribution: ggx, shadowing: Shadowing::Smith, visible: true };
        let glass = DielectricLobe { lobe: spec, eta, specular_reflectance: Rgb::ONE, specular_transmittance: Rgb::ONE };
        let base = self.base_color.0;
        let lum = self.base_color.luminance();
        let tint = if lum > 0.0 { base.map(|c| c / lum) } else { [1.0; 3] };
        // F_p = k F + S-terms; every Schlick term is R₀ + (1 − R₀) w with the same w, so they sum to
        // a + b w per channel.
        let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        let tinted = (1.0 - m) * self.spec_tint;
        let r0_tint = tint.map(|c| c * r0);
        let fresnel_a = channels!(|c| m * base[c] + tinted * r0_tint[c]);
        let fresnel_b = channels!(|c| m * (1.0 - base[c]) + tinted * (1.0 - r0_tint[c]));
        let sheen = self.sheen * (1.0 - m);
        PrincipledLobes {
            spec,
            glass,
            eta,
            fresnel_dielectric: (1.0 - m) * (1.0 - self.spec_tint),
            fresnel_a,
            fresnel_b,
            w_transmit,
            diffuse: base.map(|c| w_diffuse * c * FRAC_1_PI),
            two_roughness: 2.0 * self.roughness,
            flatness: self.flatness,
            sheen: tint.map(|c| sheen * (1.0 + self.sheen_tint * (c - 1.0))),
            clearcoat: 0.25 * self.clearcoat,
            gtr1: Gtr1::new(0.1 * (1.0 - self.clearcoat_gloss) + 0.001 * self.clearcoat_gloss),
            coat_masking: Ggx { alpha_x: 0.25, alpha_y: 0.25 },
            transmitted: base.map(|c| c.sqrt() * w_transmit),
            spec_rate: self.main_specular_sampling_rate,
            clearcoat_weight: 0.25 * self.clearcoat * self.clearcoat_sampling_rate,
            diffuse_weight: w_diffuse * self.diffuse_reflectance_sampling_rate,
        }
    }

    /// The kernel: every configuration runs in lanes.
    #[inline(always)]
    pub(crate) fn lanes(&self) -> Option<PrincipledLobes> {
        Some(self.lobes())
    }

    /// The kernel with the `base_color` `base` (per channel, one per lane, clamped to [0, 1] as a
    /// texture's) instead of its own: each lane's constants are its model's ([`Self::lobes`]), the ones
    /// the colour sets gathered per lane. [`Bsdf::per_lane_kernel`](super::Bsdf::per_lane_kernel).
    pub(crate) fn per_lane(&self, base: [[f32; PER_LANE]; 3]) -> PrincipledLobes<PerLane> {
        let lanes: [PrincipledLobes; PER_LANE] =
            std::array::from_fn(|l| Principled { base_color: Rgb::new(base[0][l], base[1][l], base[2][l]), ..self.clone() }.lobes());
        let gather = |field: fn(&PrincipledLobes) -> [f32; 3]| -> [PerLane; 3] {
            std::array::from_fn(|c| PerLane(std::array::from_fn(|l| field(&lanes[l])[c])))
        };
        let k = &lanes[0];
        PrincipledLobes {
            spec: k.spec,
            glass: k.glass,
            eta: k.eta,
            fresnel_dielectric: k.fresnel_dielectric,
            fresnel_a: gather(|k| k.fresnel_a),
            fresnel_b: gather(|k| k.fresnel_b),
            w_transmit: k.w_transmit,
            diffuse: gather(|k| k.diffuse),
            two_roughness: k.two_roughness,
            flatness: k.flatness,
            sheen: gather(|k| k.sheen),
            clearcoat: k.clearcoat,
            gtr1: k.gtr1,
            coat_masking: k.coat_masking,
            transmitted: gather(|k| k.transmitted),
            spec_rate: k.spec_rate,
            clearcoat_weight: k.clearcoat_weight,
            diffuse_weight: k.diffuse_weight,
        }
    }
}

/// The constants of one [`Principled`] that its lane code reads ([`LaneModel`]); those that `base_color`
/// sets are of type `C`: one value, or one per lane ([`Principled::per_lane`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipledLobes<C = f32> {
    /// The main specular reflection: GGX, Smith, visible normals.
    spec: ReflectionLobe<Ggx>,
    /// The same distribution as a rough dielectric of index η: the transmission lobe.
    glass: DielectricLobe<Ggx>,
    eta: f32,
    /// F_p = `fresnel_dielectric` F + `fresnel_a` + `fresnel_b` w (module doc), from above.
    fresnel_dielectric: f32,
    fresnel_a: [C; 3],
    fresnel_b: [C; 3],
    /// w_t = (1 − m) t: the interface's weight from below and the transmission's.
    w_transmit: f32,
    /// w_d `base_color` / π.
    diffuse: [C; 3],
    two_roughness: f32,
    flatness: f32,
    /// `sheen` (1 − m) mix(1, c_tint, `sheen_tint`).
    sheen: [C; 3],
    /// ¼ `clearcoat`.
    clearcoat: f32,
    gtr1: Gtr1,
    coat_masking: Ggx,
    /// √`base_color` w_t.
    transmitted: [C; 3],
    spec_rate: f32,
    clearcoat_weight: f32,
    diffuse_weight: f32,
}

/// (1 − cos)⁵ for cos clamped to [0, 1]: Schlick's weight.
#[inline(always)]
fn schlick_weight<R: Real>(cos: R) -> R {
    let m = (R::splat(1.0) - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// The probabilities of the diffuse, clearcoat, transmission and specular reflection lobes.
struct LobeChoice<R: Real> {
    diffuse: R,
    clearcoat: R,
    transmission: R,
    reflection: R,
}

impl<C: Param> PrincipledLobes<C> {
    /// Schlick's weight of the Schlick terms at cos = ωo·ωh > 0 (from above): of cos where η > 1, else
    /// of the refracted cosine √(1 − (1 − cos²)/η²) (Mitsuba's rule; 0 past the critical angle).
    #[inline(always)]
    fn schlick<R: Real>(&self, cos: R) -> R {
        if self.eta > 1.0 {
            schlick_weight(cos)
        } else {
            let cos2_t = R::splat(1.0) - (R::splat(1.0) - cos * cos) * (1.0 / (self.eta * self.eta));
            schlick_weight(cos2_t.max(R::splat(0.0)).sqrt())
        }
    }

    /// The lobe probabilities given F at the specular lobes' microfacet normal (module doc); `front`: ωo
    /// above the surface (from below only the interface's two lobes).
    #[inline(always)]
    fn choice<R: Real>(&self, f: R, front: R::Mask) -> LobeChoice<R> {
        let (zero, one) = (R::splat(0.0), R::splat(1.0));
        let passes = (one - f) * self.w_transmit;
        let reflection = R::select(front, (one - passes) * self.spec_rate, f);
        let transmission = R::select(front, passes * self.spec_rate, one - f);
        let transmission = if self.w_transmit > 0.0 { transmission } else { zero };
        let clearcoat = R::select(front, R::splat(self.clearcoat_weight), zero);
        let diffuse = R::select(front, R::splat(self.diffuse_weight), zero);
        let norm = one / (reflection + transmission + clearcoat + diffuse);
        LobeChoice {
            diffuse: diffuse * norm,
            clearcoat: clearcoat * norm,
            transmission: transmission * norm,
            reflection: reflection * norm,
        }
    }

    /// Where ωo sees anything: above the surface, or below it when the interface transmits.
    #[inline(always)]
    fn scatters<R: Real>(&self, wo: V3<R>) -> R::Mask {
        let zero = R::splat(0.0);
        if self.w_transmit > 0.0 {
            wo.z.gt(zero) | wo.z.lt(zero)
        } else {
            wo.z.gt(zero)
        }
    }

    /// The diffuse lobe's shape (Burley 2015 §5.3, with `flatness`), without w_d `base_color`/π: `fo`, `fi`
    /// Schlick's weights of the two cosines, `cos_d` = ωi·ωh, `cos_sum` = cos θo + cos θi. Symmetric in the
    /// two directions bit for bit.
    #[inline(always)]
    fn diffuse_shape<R: Real>(&self, fo: R, fi: R, cos_d: R, cos_sum: R) -> R {
        let one = R::splat(1.0);
        let lambert = (one - fo * 0.5) * (one - fi * 0.5);
        let rr = cos_d * cos_d * self.two_roughness;
        let retro = rr * (fo + fi + fo * fi * (rr - 1.0));
        if self.flatness == 0.0 {
            return lambert + retro;
        }
        let fss90 = rr * 0.5 - 1.0;
        let fss = (one + fss90 * fo) * (one + fss90 * fi);
        let subsurface = (fss * (one / cos_sum - 0.5) + 0.5) * 1.25;
        (lambert + retro) * (1.0 - self.flatness) + subsurface * self.flatness
    }
}

impl<C: Param> LaneModel for PrincipledLobes<C> {
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3] {
        let zero = R::splat(0.0);
        let inside = wo.z.lt(zero);
        let front = wo.z.gt(zero);
        let reflection = (wo.z * wi.z).gt(zero);
        let mut out = [zero; 3];
        if R::any(reflection) {
            // Both on ωo's side, turned upwards (D and G are even).
            let (wo_u, wi_u) = (V3::select(inside, wo.neg(), wo), V3::select(inside, wi.neg(), wi));
            let v = self.spec.eval(wo_u, wi_u);
            let cos_d = v.cos_theta_d;
            let f = fresnel_dielectric_lanes(R::select(inside, -cos_d, cos_d), self.eta);
            let w = self.schlick(cos_d);
            let spec_ok = v.ok & f.gt(zero);
            // The front-only lobes: diffuse, sheen, clearcoat.
            let diffuse = self.diffuse_shape(schlick_weight(wo_u.z), schlick_weight(wi_u.z), cos_d, wo_u.z + wi_u.z);
            let sheen = schlick_weight(cos_d);
            let mut coat = zero;
            if self.clearcoat > 0.0 {
                let h = wo_u.add(wi_u);
                let wm = h.div(h.length());
                let g = self.coat_masking.g1(wo_u, wm) * self.coat_masking.g1(wi_u, wm);
                coat = (w * 0.96 + 0.04) * self.gtr1.d(wm) * g * self.clearcoat;
            }
            let front = reflection & front;
            out = channels!(|c| {
                let fp = R::select(
                    inside,
                    f * self.w_transmit,
                    f * self.fresnel_dielectric + w * self.fresnel_b[c].lanes::<R>() + self.fresnel_a[c].lanes::<R>(),
                );
                let spec = R::select(spec_ok, v.value * fp, zero);
                let lobes = diffuse * self.diffuse[c].lanes::<R>() + sheen * self.sheen[c].lanes::<R>() + coat;
                R::select(reflection, spec + R::select(front, lobes, zero), zero)
            });
        }
        let refraction = (wo.z * wi.z).lt(zero);
        if self.w_transmit > 0.0 && R::any(refraction) {
            let t = self.glass.transmission(wo, wi, inside);
            out = channels!(|c| R::select(refraction, t * self.transmitted[c].lanes::<R>(), out[c]));
        }
        // Within f32 underflow of the horizon a lobe can overflow: reported as 0, never NaN/Inf (2026-12).
        channels!(|c| R::select(out[c].is_finite(), out[c], zero))
    }

    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        let zero = R::splat(0.0);
        let inside = wo.z.lt(zero);
        let eta = R::select(inside, R::splat(1.0 / self.eta), R::splat(self.eta));
        let (wo_u, wi_u) = (V3::select(inside, wo.neg(), wo), V3::select(inside, wi.neg(), wi));
        let reflection = wi_u.z.gt(zero);
        // The half vector of either lobe (Walter 2007 eqs. 13, 16), on the +z side.
        let wm = unit_upper(V3::select(reflection, wo_u.add(wi_u), wo_u.add(wi_u.scale(eta)).neg()));
        let (o_m, i_m) = (wo_u.dot(wm), wi_u.dot(wm));
        let f = fresnel_dielectric_lanes(R::select(inside, -o_m, o_m), self.eta);
        let p = self.choice(f, !inside);
        let d = &self.spec.distribution;
        let facing = o_m.gt(zero);
        // Reflection: the specular lobe's visible-normal density over 4 ωi·ωm (Walter 2007 eq. 14), the
        // clearcoat's D cos likewise, the diffuse cosine.
        let mut specular = d.pdf_reflected(wo_u, wm, true) * p.reflection;
        if self.clearcoat_weight > 0.0 {
            specular = specular + self.gtr1.pdf(wm) / (i_m * 4.0) * p.clearcoat;
        }
        let reflected = R::select(facing & i_m.gt(zero), specular, zero) + cosine_hemisphere_density(wi_u.z) * p.diffuse;
        let mut pdf = R::select(reflection, reflected, zero);
        let refraction = wi_u.z.lt(zero);
        if self.w_transmit > 0.0 && R::any(refraction) {
            let transmitted = d.pdf_refracted(wo_u, wi_u, wm, eta, true) * p.transmission;
            pdf = R::select(refraction & facing & i_m.lt(zero), transmitted, pdf);
        }
        R::select(self.scatters(wo) & pdf.is_finite() & pdf.gt(zero), pdf, zero)
    }

    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R) -> LaneSample<R> {
        let zero = R::splat(0.0);
        let scatters = self.scatters(wo);
        if !R::any(scatters) {
            return LaneSample::none(scatters);
        }
        let inside = wo.z.lt(zero);
        let eta = R::select(inside, R::splat(1.0 / self.eta), R::splat(self.eta));
        let wo_u = V3::select(inside, wo.neg(), wo);
        // The specular lobes' microfacet normal, drawn first: their probabilities depend on F there.
        let wm = self.spec.distribution.sample_visible(wo_u, ux, uy);
        let o_m = wo_u.dot(wm);
        let p = self.choice(fresnel_dielectric_lanes(R::select(inside, -o_m, o_m), self.eta), !inside);
        let diffuse = uc.lt(p.diffuse);
        let coat = !diffuse & uc.lt(p.diffuse + p.clearcoat);
        let transmit = !diffuse & !coat & uc.lt(p.diffuse + p.clearcoat + p.transmission);
        let specular = !(diffuse | coat | transmit);
        // Specular reflection about ωm.
        let wr = reflect_lanes(wo_u, wm).normalize();
        let mut wi_u = wr;
        let mut valid = specular & o_m.gt(zero) & wr.z.gt(zero);
        if R::any(transmit) {
            let (wt, cos2_t) = refract_lanes(wo_u, wm, o_m, eta);
            wi_u = V3::select(transmit, wt, wi_u);
            valid = valid | (transmit & o_m.gt(zero) & cos2_t.gt(zero) & wt.z.lt(zero));
        }
        if R::any(coat) {
            let mc = self.gtr1.sample(ux, uy);
            let wc = reflect_lanes(wo_u, mc).normalize();
            wi_u = V3::select(coat, wc, wi_u);
            valid = valid | (coat & wo_u.dot(mc).gt(zero) & wc.z.gt(zero));
        }
        if R::any(diffuse) {
            let wd = cosine_hemisphere(ux, uy);
            wi_u = V3::select(diffuse, wd, wi_u);
            valid = valid | (diffuse & wd.z.gt(zero));
        }
        let wi = V3::select(inside, wi_u.neg(), wi_u);
        let flags = R::select(
            diffuse,
            flag_lanes(BsdfFlags::DIFFUSE_REFLECTION),
            R::select(transmit, flag_lanes(GLOSSY_TRANSMISSION), flag_lanes(BsdfFlags::GLOSSY_REFLECTION)),
        );
        let s = LaneSample::smooth(wi, self.f_lanes(wo, wi), self.pdf_lanes(wo, wi), flags, scatters & valid);
        LaneSample { eta: R::select(transmit, eta, R::splat(1.0)), ..s }
    }
}

impl BsdfModel for Principled {
    fn flags(&self) -> BsdfFlags {
        let reflection = BsdfFlags::DIFFUSE_REFLECTION | BsdfFlags::GLOSSY_REFLECTION;
        if self.transmissive {
            reflection | GLOSSY_TRANSMISSION
        } else {
            reflection
        }
    }

    #[inline(always)]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        f_one(&self.lobes(), wo, wi)
    }

    #[inline(always)]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        sample_one(&self.lobes(), wo, uc, u)
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_one(&self.lobes(), wo, wi)
    }

    lane_batch_methods!(lanes);
}

impl crate::bsdf::Examples for Principled {
    /// Examples for `gonio check --all`: the defaults, each lobe strong, anisotropy, transmission from
    /// both sides (η > 1 and < 1), the narrowest lobes (roughness 0: α = 0.001; clearcoat_gloss 1:
    /// GTR1 α = 0.001) and unequal sampling rates. All pass the full standard (2026-12).
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "principled"}"#,
        r#"{"type": "principled", "base_color": [0.9, 0.6, 0.2], "metallic": 0.8, "roughness": 0.3, "anisotropic": 0.7}"#,
        r#"{"type": "principled", "base_color": [0.5, 0.7, 0.9], "spec_trans": 0.9, "roughness": 0.2, "eta": 1.5}"#,
        r#"{"type": "principled", "base_color": [0.2, 0.4, 0.6], "clearcoat": 1.0, "clearcoat_gloss": 0.9, "sheen": 1.0, "sheen_tint": 0.5, "spec_tint": 0.5, "roughness": 0.6}"#,
        r#"{"type": "principled", "base_color": [0.3, 0.5, 0.2], "clearcoat": 1.0, "roughness": 0.4, "spec_trans": 0.3, "flatness": 0.3, "main_specular_sampling_rate": 0.5, "clearcoat_sampling_rate": 2.0, "diffuse_reflectance_sampling_rate": 0.25}"#,
        r#"{"type": "principled", "base_color": 0.7, "roughness": 0.7, "spec_trans": 1.0, "eta": 0.75, "anisotropic": 0.5}"#,
        r#"{"type": "principled", "base_color": [0.95, 0.64, 0.54], "roughness": 0.0, "metallic": 1.0, "clearcoat": 1.0, "clearcoat_gloss": 1.0}"#,
    ];

    /// The Disney model adds its lobes without trading energy between them (Burley 2012 §5: diffuse, sheen
    /// and retro-reflection on top of the specular), so bright, rough or grazing configurations reflect
    /// more than they receive, in Mitsuba as here: a white rough surface with sheen (albedo 1.66 at
    /// cos θo = 0.016), and a smooth half-metal, half-glass with flatness (1.07 there: the specular F → 1 at
    /// grazing plus the diffuse). Every other check passes on them.
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[
        (r#"{"type": "principled", "base_color": 1.0, "roughness": 1.0, "sheen": 1.0}"#, "albedo max"),
        (
            r#"{"type": "principled", "base_color": [0.4, 0.5, 0.6], "roughness": 0.05, "spec_trans": 0.5, "metallic": 0.3, "clearcoat": 0.5, "flatness": 0.5, "eta": 1.33}"#,
            "albedo max",
        ),
    ];
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    #[test]
    fn parameters_are_checked() {
        for bad in [
            r#"{"type": "principled", "roughness": -0.1}"#,
            r#"{"type": "principled", "metallic": 1.5}"#,
            r#"{"type": "principled", "base_color": [0.5, 1.2, 0.5]}"#,
            r#"{"type": "principled", "eta": 1.5, "specular": 0.5}"#,
            r#"{"type": "principled", "eta": 0}"#,
            r#"{"type": "principled", "clearcoat_sampling_rate": -1}"#,
            r#"{"type": "principled", "alpha": 0.1}"#,
        ] {
            assert!(Bsdf::from_json(bad).is_err(), "{bad}");
        }
        let e = Bsdf::from_json(r#"{"type": "principled", "metallic": 1.5}"#).unwrap_err().to_string();
        assert!(e.contains("metallic") && e.contains("[0, 1]"), "{e}");
        let Bsdf::Principled(p) = Bsdf::from_json(r#"{"type": "principled"}"#).unwrap() else { panic!() };
        assert_eq!(p, Principled::default());
        assert!((p.eta() - 1.5).abs() < 1e-6, "specular 0.5 is η = 1.5");
    }

    #[test]
    fn mitsubas_index_rules() {
        let eta = |spec: &str| match Bsdf::from_json(spec).unwrap() {
            Bsdf::Principled(p) => p.eta(),
            _ => unreachable!(),
        };
        assert_eq!(eta(r#"{"type": "principled", "eta": 1.0}"#), 1.0);
        assert_eq!(eta(r#"{"type": "principled", "eta": 1.0, "spec_trans": 0.5}"#), 1.001);
        assert_eq!(eta(r#"{"type": "principled", "eta": 1.0, "spec_trans": 0}"#), 1.0);
        assert_eq!(eta(r#"{"type": "principled", "specular": 0}"#), 1.0);
        assert!(eta(r#"{"type": "principled", "specular": 0, "spec_trans": 1}"#) > 1.0);
    }

    /// Reflection above and below, transmission both ways: f·|cos θi| and pdf against Mitsuba 3.9.1
    /// `scalar_rgb` (`eval`, `pdf`) at the pairs of `tests/data/principled_mitsuba.json`, written by
    /// `tools/principled_reference.py`. Both compute in f32.
    #[test]
    fn matches_mitsuba() {
        let text = include_str!("../../tests/data/principled_mitsuba.json");
        let sets: serde_json::Value = serde_json::from_str(text).unwrap();
        let mut worst = (0.0f64, String::new());
        let mut compared = 0;
        for set in sets.as_array().unwrap() {
            let spec = set["spec"].to_string();
            let b = Bsdf::from_json(&spec).unwrap();
            let scale = set["scale"].as_f64().unwrap();
            for row in set["rows"].as_array().unwrap() {
                let v: Vec<f32> = row.as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect();
                let (wo, wi) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
                let ours = b.f(wo, wi) * wi.z.abs();
                let pairs = [(ours.r(), v[6]), (ours.g(), v[7]), (ours.b(), v[8]), (b.pdf(wo, wi), v[9])];
                for (k, (g, m)) in pairs.into_iter().enumerate() {
                    // Relative to the value, with a floor of 1e-6 of the set's largest value (directions
                    // where a lobe is 1e-6 of its peak carry its rounding).
                    let err = (g as f64 - m as f64).abs() / (m.abs() as f64).max(1e-6 * scale);
                    if err > worst.0 {
                        worst = (err, format!("{spec} wo={wo} wi={wi} {} gonio {g} mitsuba {m}", ["r", "g", "b", "pdf"][k]));
                    }
                    compared += 1;
                }
            }
        }
        eprintln!("{compared} values; worst relative error {:.3e}: {}", worst.0, worst.1);
        assert!(worst.0 < 1e-4, "{}", worst.1);
    }
}
