//! `dielectric` — a smooth interface between two dielectrics (glass, water): mirror reflection and
//! refraction by Snell's law, weighted by the exact unpolarised Fresnel equations, with total internal
//! reflection beyond the critical angle (Born & Wolf §1.5; pbrt-v4 §9.5).
//!
//! | parameter                | type            | default | meaning                                         |
//! |--------------------------|-----------------|---------|-------------------------------------------------|
//! | `int_ior`                | float, name, law or table | `bk7` (1.5046) | index of the inside (below the surface, z < 0) |
//! | `ext_ior`                | float, name, law or table | `air` (1.000277) | index of the outside (z > 0)     |
//! | `dispersive`             | bool            | false   | read `int_ior`/`ext_ior` names as gonio's dispersive glasses ([`Dispersion`]) |
//! | `abbe`                   | float > 0       | —       | Abbe number V_d: `int_ior` (a number or name) becomes its value at 587.56 nm of a dispersive Cauchy law |
//! | `specular_reflectance`   | rgb [0,1]       | 1       | multiplier on reflection (not physical)         |
//! | `specular_transmittance` | rgb [0,1]       | 1       | multiplier on transmission (not physical)       |
//! | `fresnel`                | bool            | true    | gonio's teaching switch: `false` replaces F(θ) by the constant F(0) = ((η−1)/(η+1))² (total internal reflection stays) |
//!
//! Both sides scatter: `wo` below the surface sees the interface from the inside. Names are those of
//! Mitsuba's IOR table (`vacuum`, `air`, `water`, `bk7`, `diamond`, …). An index may also vary with
//! wavelength ([`Dispersion`], shared with `roughdielectric` and `thindielectric`).
//!
//! Sampling picks reflection with probability F and refraction with 1 − F, so both weights are 1 times
//! the multipliers, and refraction carries the radiance factor (ηᵢ/ηₜ)² (see [`crate::bsdf`]).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let glass = Bsdf::from_json(r#"{"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}"#).unwrap();
//! // At normal incidence 4 % is reflected: uc = 0.5 chooses refraction, straight through.
//! let s = glass.sample(Vec3::Z, 0.5, Vec2::ZERO).unwrap();
//! assert!((s.wi + Vec3::Z).length() < 1e-6);
//! assert!((s.pdf - 0.96).abs() < 1e-6);
//! assert!((s.weight.r() - 1.0 / 2.25).abs() < 1e-6); // (1/1.5)² entering glass
//! ```

use super::lanes::{flag_lanes, sample_one, LaneModel, LaneSample};
use super::{BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::fresnel::{cos2_transmitted, fresnel_dielectric, fresnel_dielectric_lanes, reflect_lanes};
use crate::math::lanes::{channels, Real, V3};
use crate::math::{Vec2, Vec3};
use crate::props::{NumberOrName, Props};
use crate::spectrum::dispersion::{Cauchy, Ior, Sellmeier, LAMBDA_D, NAMED_GLASSES};
use crate::spectrum::wavelengths::{LAMBDA_MAX, LAMBDA_MIN};
use crate::spectrum::{named, Rgb};
use std::sync::Arc;

/// A smooth dielectric interface.
#[derive(Clone, Debug, PartialEq)]
pub struct Dielectric {
    /// Relative index η = int_ior / ext_ior.
    pub eta: f32,
    pub specular_reflectance: Rgb,
    pub specular_transmittance: Rgb,
    pub fresnel: bool,
    /// How η varies with wavelength, if it does; `eta` is then its value at [`LAMBDA_D`] (or at the
    /// wavelength spectral mode set, [`crate::bsdf::Bsdf::dispersion_mut`]).
    pub dispersion: Option<Arc<Dispersion>>,
}

impl Dielectric {
    #[must_use]
    pub fn new(eta: f32) -> Self {
        Dielectric { eta, specular_reflectance: Rgb::ONE, specular_transmittance: Rgb::ONE, fresnel: true, dispersion: None }
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let (eta, dispersion) = interface_ior(p)?;
        Ok(Dielectric {
            eta,
            dispersion,
            specular_reflectance: p.reflectance("specular_reflectance", Rgb::ONE)?,
            specular_transmittance: p.reflectance("specular_transmittance", Rgb::ONE)?,
            fresnel: p.bool("fresnel", true)?,
        })
    }

    /// The reflected fraction for `cos_theta_o` (signed), honouring the `fresnel` switch (without it, the
    /// normal-incidence value, except under total internal reflection).
    #[must_use]
    pub fn reflected_fraction(&self, cos_theta_o: f32) -> f32 {
        self.reflected_fraction_lanes(cos_theta_o)
    }

    /// [`Self::reflected_fraction`] in lanes ([`Real`]), as the lane kernel samples.
    #[inline(always)]
    fn reflected_fraction_lanes<R: Real>(&self, cos_theta_o: R) -> R {
        let f = fresnel_dielectric_lanes(cos_theta_o, self.eta);
        if self.fresnel {
            f
        } else {
            R::select(f.ge(R::splat(1.0)), f, R::splat(fresnel_dielectric(1.0, self.eta)))
        }
    }
}

/// Read `int_ior` / `ext_ior` (numbers > 0 or names from Mitsuba's table) and return their ratio: the
/// plastics' interface, which does not disperse.
pub(crate) fn relative_ior_with_default(p: &Props, int_default: f32) -> Result<f32> {
    let int_ior = constant_ior(p, "int_ior", int_default)?;
    let ext_ior = constant_ior(p, "ext_ior", 1.000_277)?;
    check_relative(p, int_ior / ext_ior, &format!("int_ior / ext_ior = {int_ior} / {ext_ior}"))
}

/// The relative index η = `int_ior` / `ext_ior` must lie in [1/`MAX_RELATIVE_IOR`, `MAX_RELATIVE_IOR`]
/// (2026-12, issue 8). Each index alone may be anything in (0, 10000), so their ratio could reach 10⁸
/// or underflow f32, and the NaN/Inf sweep found the models breaking inside that range: `plastic` at
/// η = 1000 (f = inf at grazing angles), `roughdielectric` at η = 10⁻²⁰ (pdf = NaN), `dielectric` at
/// η = 1/50 (a refracted direction 0.2 % off unit length from an input 10⁻⁶ off). Real interfaces stay
/// far inside: germanium in air, the densest common dielectric, has η = 4.
pub const MAX_RELATIVE_IOR: f32 = 20.0;

fn check_relative(p: &Props, eta: f32, ratio: &str) -> Result<f32> {
    if (1.0 / MAX_RELATIVE_IOR..=MAX_RELATIVE_IOR).contains(&eta) {
        return Ok(eta);
    }
    Err(Error::spec(
        p.at(),
        format!("`{}`: the relative index {ratio} = {eta} must lie in [1/{MAX_RELATIVE_IOR}, {MAX_RELATIVE_IOR}]", p.plugin_type()),
    ))
}

/// An index of refraction given as a number in (0, 10000) or a name from Mitsuba's table.
fn constant_ior(p: &Props, name: &'static str, default: f32) -> Result<f32> {
    let varies = |at: &str| {
        Error::spec(
            at,
            format!(
                "parameter `{name}` of `{}`: an index that varies with wavelength is taken by `dielectric`, \
                 `roughdielectric` and `thindielectric` only; give a number or one of: {}",
                p.plugin_type(),
                named::DIELECTRICS.join(", ")
            ),
        )
    };
    if let Some(table) = p.spectrum_table(name) {
        return match table.flat_value() {
            Some(v) => number_ior(p, name, v, p.at_param(name)),
            None => Err(varies(p.at_param(name))),
        };
    }
    match p.number_or_name(name)? {
        None => Ok(default),
        Some(NumberOrName::Number(v, at)) => number_ior(p, name, v, &at),
        Some(NumberOrName::Name(n, at)) => named::dielectric_ior(&n).ok_or_else(|| {
            if law_ior(&n, true).is_ok() {
                varies(&at)
            } else {
                Error::spec(
                    at,
                    format!("parameter `{name}`: unknown material `{n}`; expected a number or one of: {}", named::DIELECTRICS.join(", ")),
                )
            }
        }),
    }
}

fn number_ior(p: &Props, name: &str, v: f64, at: &str) -> Result<f32> {
    if v > 0.0 && v.is_finite() && v < 1e4 {
        #[allow(clippy::cast_possible_truncation)]
        Ok(v as f32)
    } else {
        Err(Error::spec(at, format!("parameter `{name}` of `{}` must be an index of refraction in (0, 10000), got {v}", p.plugin_type())))
    }
}

/// The indices of a dielectric interface whose relative index varies with wavelength: dispersion
/// (issue 30; laws and named glasses in [`crate::spectrum::dispersion`]). The models hold η at one
/// wavelength; RGB mode renders them at [`LAMBDA_D`], spectral mode at each path's hero wavelength, and
/// the path tracer then follows that wavelength alone (docs/spectral.md, "Dispersion").
///
/// `int_ior` and `ext_ior` take, besides a number or a Mitsuba name:
///
/// | value | index |
/// |---|---|
/// | `"sellmeier(B1, …, Bn, C1, …, Cn)"` | n² = 1 + Σ Bᵢ λ² / (λ² − Cᵢ), λ in µm, Cᵢ in µm², 1 ≤ n ≤ 4 |
/// | `"cauchy(A, B)"`, `"cauchy(A, B, C)"` | n = A + B / λ² + C / λ⁴, λ in µm |
/// | a name of [`NAMED_GLASSES`] | that glass (`fused silica`, `baf10`, `f2`, `sf11`, pbrt-v4's `glass-*`) |
/// | a table: `<spectrum name="int_ior" value="λ:n, …"/>` or `filename="….spd"` | linear between its nodes, its end values outside |
///
/// Mitsuba's names keep Mitsuba's constants (`bk7` is 1.5046, `water` 1.333, `diamond` 2.419), so that its
/// scenes render as there; with `dispersive` = true a name is read from [`NAMED_GLASSES`] instead
/// (`bk7` is then Schott N-BK7's Sellmeier law, n_d = 1.5168). `abbe` = V_d turns a number or a name
/// `int_ior` into the Cauchy law through that n_d with that Abbe number, as glTF's
/// `KHR_materials_dispersion` defines it.
#[derive(Clone, Debug, PartialEq)]
pub struct Dispersion {
    /// The inside's index.
    pub int_ior: Ior,
    /// The outside's index.
    pub ext_ior: Ior,
}

impl Dispersion {
    /// The relative index int_ior / ext_ior at `lambda` nm.
    #[must_use]
    pub fn eta(&self, lambda: f32) -> f32 {
        let l = f64::from(lambda);
        #[allow(clippy::cast_possible_truncation)]
        let eta = (self.int_ior.eta(l) / self.ext_ior.eta(l)) as f32;
        eta
    }
}

/// The relative index of a dielectric interface at [`LAMBDA_D`] and, where it varies with wavelength, how
/// ([`Dispersion`]). Shared by `dielectric`, `roughdielectric` and `thindielectric`. A dispersive
/// relative index must stay within [1/`MAX_RELATIVE_IOR`, `MAX_RELATIVE_IOR`] at every wavelength spectral
/// mode draws (checked every nanometre).
pub(crate) fn interface_ior(p: &Props) -> Result<(f32, Option<Arc<Dispersion>>)> {
    let dispersive = p.bool("dispersive", false)?;
    let int_ior = index(p, "int_ior", 1.5046, dispersive)?;
    let ext_ior = index(p, "ext_ior", 1.000_277, dispersive)?;
    let int_ior = if p.has("abbe") {
        let abbe = p.float_positive("abbe", 1.0)?;
        let Ior::Constant(n_d) = int_ior else {
            return Err(Error::spec(
                p.at_param("abbe"),
                format!("`{}`: `abbe` makes a constant `int_ior` dispersive; `int_ior` already varies with wavelength", p.plugin_type()),
            ));
        };
        Ior::from_abbe(n_d, f64::from(abbe)).map_err(|e| Error::spec(p.at_param("abbe"), format!("`abbe`: {e}")))?
    } else {
        int_ior
    };
    let d = Dispersion { int_ior, ext_ior };
    let ratio = |l: f64| format!("int_ior / ext_ior at {l} nm = {} / {}", d.int_ior.eta(l), d.ext_ior.eta(l));
    #[allow(clippy::cast_possible_truncation)]
    let eta = check_relative(p, d.eta(LAMBDA_D as f32), &ratio(LAMBDA_D))?;
    if !(d.int_ior.is_dispersive() || d.ext_ior.is_dispersive()) {
        return Ok((eta, None));
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    for nm in LAMBDA_MIN as u32..=LAMBDA_MAX as u32 {
        #[allow(clippy::cast_precision_loss)]
        check_relative(p, d.eta(nm as f32), &ratio(f64::from(nm)))?;
    }
    Ok((eta, Some(Arc::new(d))))
}

/// One index of a dielectric interface (see [`Dispersion`]).
fn index(p: &Props, name: &'static str, default: f32, dispersive: bool) -> Result<Ior> {
    if let Some(table) = p.spectrum_table(name) {
        return match table.flat_value() {
            Some(v) => number_ior(p, name, v, p.at_param(name)).map(|n| Ior::Constant(f64::from(n))),
            None => Ok(Ior::Tabulated(table)),
        };
    }
    match p.number_or_name(name)? {
        None => Ok(Ior::Constant(f64::from(default))),
        Some(NumberOrName::Number(v, at)) => number_ior(p, name, v, &at).map(|n| Ior::Constant(f64::from(n))),
        Some(NumberOrName::Name(n, at)) => match named::dielectric_ior(&n).filter(|_| !dispersive) {
            Some(v) => Ok(Ior::Constant(f64::from(v))),
            None => law_ior(&n, dispersive).map_err(|e| Error::spec(at, format!("parameter `{name}` of `{}`: {e}", p.plugin_type()))),
        },
    }
}

/// An index named or given by its law (see [`Dispersion`]); the message says what was expected.
fn law_ior(text: &str, dispersive: bool) -> std::result::Result<Ior, String> {
    let t = text.trim();
    let call = |law: &str| {
        t.strip_prefix(law)
            .and_then(|r| r.trim_start().strip_prefix('('))
            .and_then(|r| r.trim_end().strip_suffix(')'))
            .map(|args| args.split(',').map(|a| a.trim().parse::<f64>()).collect::<std::result::Result<Vec<f64>, _>>())
    };
    let bad = |e: &dyn std::fmt::Display| format!("`{t}`: {e}");
    if let Some(args) = call("sellmeier") {
        let args = args.map_err(|_| bad(&"expected sellmeier(B1, …, Bn, C1, …, Cn) with numbers"))?;
        if args.len() % 2 != 0 {
            return Err(bad(&format!("expected as many B as C coefficients, got {} numbers", args.len())));
        }
        let (b, c) = args.split_at(args.len() / 2);
        return Sellmeier::new(b, c).map(Ior::Sellmeier).map_err(|e| bad(&e));
    }
    if let Some(args) = call("cauchy") {
        let args = args.map_err(|_| bad(&"expected cauchy(A, B) or cauchy(A, B, C) with numbers"))?;
        let law = match args[..] {
            [a, b] => Cauchy { a, b, c: 0.0 },
            [a, b, c] => Cauchy { a, b, c },
            _ => return Err(bad(&format!("expected cauchy(A, B) or cauchy(A, B, C), got {} numbers", args.len()))),
        };
        if ![law.a, law.b, law.c].iter().all(|v| v.is_finite()) {
            return Err(bad(&"the coefficients must be finite"));
        }
        return Ok(Ior::Cauchy(law));
    }
    Ior::named(t).ok_or_else(|| {
        if dispersive {
            format!("unknown glass `{t}`; with `dispersive`, expected one of: {}", NAMED_GLASSES.join(", "))
        } else {
            format!(
                "unknown material `{t}`; expected a number, sellmeier(…), cauchy(…), one of Mitsuba's names ({}) or a dispersive glass ({})",
                named::DIELECTRICS.join(", "),
                NAMED_GLASSES.join(", ")
            )
        }
    })
}

/// The delta sampling shared by the smooth interfaces (`dielectric`, `thindielectric`), in lanes: mirror
/// `wo` about +z with probability `r` (the reflected fraction), else take the transmitted direction `wt`
/// with relative index `eta` = ηₜ/ηᵢ (valid where `transmits`), with probability 1 − r. Choosing a lobe in
/// proportion to its energy cancels the Fresnel factor from both weights: they are the multipliers, and
/// transmission carries the radiance factor (ηᵢ/ηₜ)² = 1/η² (1 for a slab, whose two refractions cancel).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reflect_or_transmit<R: Real>(
    wo: V3<R>,
    uc: R,
    r: R,
    reflectance: Rgb,
    transmittance: Rgb,
    wt: V3<R>,
    eta: R,
    transmits: R::Mask,
) -> LaneSample<R> {
    let scale = (R::splat(1.0) - r) / (eta * eta);
    let reflected = channels!(|c| r * reflectance.0[c]);
    let transmitted = channels!(|c| scale * transmittance.0[c]);
    split_sample(wo, uc, r, reflected, transmitted, wt, eta, transmits)
}

/// A delta sample that reflects `wo` about the normal with probability `p` (where `uc` < `p`), its value
/// per channel `reflected`, and else goes to `wt` with value `transmitted` and relative index `eta` (valid
/// where `transmits`): [`reflect_or_transmit`] with the values given per channel.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn split_sample<R: Real>(
    wo: V3<R>,
    uc: R,
    p: R,
    reflected: [R; 3],
    transmitted: [R; 3],
    wt: V3<R>,
    eta: R,
    transmits: R::Mask,
) -> LaneSample<R> {
    let one = R::splat(1.0);
    let chosen = uc.lt(p);
    let value = channels!(|c| R::select(chosen, reflected[c], transmitted[c]));
    let wi = V3::select(chosen, reflect_lanes(wo, V3::splat(Vec3::Z)), wt);
    let flags = R::select(
        chosen,
        flag_lanes(BsdfFlags::DELTA_REFLECTION | BsdfFlags::DELTA),
        flag_lanes(BsdfFlags::DELTA_TRANSMISSION | BsdfFlags::DELTA),
    );
    LaneSample::delta(wi, value, R::select(chosen, p, one - p), flags, R::select(chosen, one, eta), chosen | transmits)
}

impl crate::bsdf::Examples for Dielectric {
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "dielectric"}"#,
        r#"{"type": "dielectric", "int_ior": "diamond"}"#,
        r#"{"type": "dielectric", "int_ior": 1.0, "ext_ior": 1.5}"#,
        r#"{"type": "dielectric", "int_ior": 1.01}"#,
        r#"{"type": "dielectric", "int_ior": 1.5, "fresnel": false}"#,
        r#"{"type": "dielectric", "specular_transmittance": [0.2, 0.7, 0.9]}"#,
    ];
}

impl BsdfModel for Dielectric {
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

impl Dielectric {
    /// Itself: its lane code runs every configuration (the batch methods' `lane_batch_methods!`).
    #[inline(always)]
    fn lanes(&self) -> Option<&Self> {
        Some(self)
    }
}

/// The model in lanes ([`LaneModel`]), which its `sample` runs for one direction: the path tracer's packets
/// run it for the lanes on one dielectric.
impl LaneModel for Dielectric {
    #[inline(always)]
    fn f_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> [R; 3] {
        [R::splat(0.0); 3]
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, _wo: V3<R>, _wi: V3<R>) -> R {
        R::splat(0.0)
    }

    /// [`reflect_or_transmit`] with r = [`Dielectric::reflected_fraction`]: the mirror direction
    /// 2 (ωo·n) n − ωo, n = +z, where uc < r, else the refracted one ([`refract`](crate::fresnel::refract) about ±z, on the side of ωo), none
    /// under total internal reflection there and for ωo in the plane.
    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, _ux: R, _uy: R) -> LaneSample<R> {
        let (zero, one) = (R::splat(0.0), R::splat(1.0));
        let r = self.reflected_fraction_lanes(wo.z);
        // Refraction from the side of ωo: η' = ηₜ/ηᵢ, n = ±z towards ωo.
        let inside = wo.z.lt(zero);
        let (eta, cos_i, nz) =
            (R::select(inside, R::splat(1.0 / self.eta), R::splat(self.eta)), R::select(inside, -wo.z, wo.z), R::select(inside, -one, one));
        let cos2_t = cos2_transmitted(cos_i, eta);
        let cos_t = cos2_t.sqrt();
        let wt = V3::new(-wo.x / eta, -wo.y / eta, -wo.z / eta + (cos_i / eta - cos_t) * nz);
        let s = reflect_or_transmit(wo, uc, r, self.specular_reflectance, self.specular_transmittance, wt, eta, !cos2_t.le(zero));
        LaneSample { valid: s.valid & !wo.z.eq(zero), ..s }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::fresnel::fresnel_dielectric;

    /// Every model with a dielectric interface is finite at both ends of the allowed relative index
    /// (the NaN/Inf sweep, degenerate directions included), and a ratio beyond them is refused, naming
    /// both indices. Before the limit, `plastic` at int_ior = 1000 returned f = inf, `roughdielectric` at
    /// int_ior = 1e-44 a NaN pdf and `dielectric` at ext_ior = 50 directions 0.2 % off unit length.
    #[test]
    fn relative_index_is_finite_at_the_limits_and_refused_beyond() {
        let models = [
            "\"dielectric\"",
            "\"thindielectric\"",
            "\"roughdielectric\"",
            "\"roughdielectric\", \"distribution\": \"beckmann\", \"alpha\": 1, \"energy_compensation\": true",
            "\"plastic\"",
            "\"roughplastic\", \"energy_compensation\": true",
        ];
        let limit = f64::from(MAX_RELATIVE_IOR);
        for model in models {
            for (int_ior, ext_ior) in [(limit, 1.0), (1.0, limit), (2.0 * limit, 2.0), (1.5, 1.5 * limit)] {
                let spec = format!("{{\"type\": {model}, \"int_ior\": {int_ior}, \"ext_ior\": {ext_ior}}}");
                let b = crate::bsdf::Bsdf::from_json(&spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
                let r = crate::verify::sweep::sweep(&b, 100_000, 3);
                assert_eq!(r.bad, 0, "{spec}: {:?}", r.first_bad);
            }
            for (int_ior, ext_ior) in [(limit * 1.01, 1.0), (1.0, limit * 1.01), (1000.0, 1.0), (1e-44, 1.0), (9999.0, 1e-40)] {
                let spec = format!("{{\"type\": {model}, \"int_ior\": {int_ior}, \"ext_ior\": {ext_ior}}}");
                let e = crate::bsdf::Bsdf::from_json(&spec).map(|_| ()).unwrap_err().to_string();
                assert!(e.contains("the relative index int_ior / ext_ior") && e.contains("must lie in [1/20, 20]"), "{spec}: {e}");
            }
        }
    }

    fn glass() -> Dielectric {
        Dielectric::new(1.5)
    }

    #[test]
    fn lobe_probabilities_are_fresnel_from_both_sides() {
        let d = glass();
        for cos in [0.9f32, 0.5, 0.1, -0.95, -0.8] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let r = fresnel_dielectric(cos, 1.5);
            let refl = d.sample(wo, 0.0, Vec2::ZERO).unwrap();
            assert!((refl.pdf - r).abs() < 1e-6 && refl.wi.z * wo.z > 0.0);
            assert_eq!(refl.weight, Rgb::ONE);
            let tran = d.sample(wo, 0.999_999, Vec2::ZERO).unwrap();
            assert!((tran.pdf - (1.0 - r)).abs() < 1e-6 && tran.wi.z * wo.z < 0.0);
            // Radiance scaling (ηᵢ/ηₜ)² = 1/eta²; eta = 1.5 entering, 1/1.5 leaving.
            let expect_eta = if cos > 0.0 { 1.5 } else { 1.0 / 1.5 };
            assert!((tran.eta - expect_eta).abs() < 1e-6);
            assert!((tran.weight.g() - 1.0 / (expect_eta * expect_eta)).abs() < 1e-5);
        }
    }

    #[test]
    fn total_internal_reflection_beyond_the_critical_angle() {
        let d = glass();
        let theta_c = (1.0f32 / 1.5).asin();
        let theta = theta_c + 0.05;
        let wo = Vec3::new(theta.sin(), 0.0, -theta.cos());
        for uc in [0.0, 0.5, 0.999_99] {
            let s = d.sample(wo, uc, Vec2::ZERO).unwrap();
            assert_eq!(s.pdf, 1.0);
            assert!(s.wi.z < 0.0, "stays inside");
            assert!(s.flags.contains(BsdfFlags::DELTA_REFLECTION));
        }
    }

    #[test]
    fn fresnel_switch_gives_a_constant_split() {
        let d = Dielectric { fresnel: false, ..glass() };
        for cos in [1.0f32, 0.5, 0.05] {
            assert!((d.reflected_fraction(cos) - 0.04).abs() < 1e-6);
        }
        // Total internal reflection is geometry, not Fresnel: it stays.
        assert_eq!(d.reflected_fraction(-0.1), 1.0);
    }

    fn model(spec: &str) -> Result<crate::bsdf::Bsdf> {
        crate::bsdf::Bsdf::from_json(spec)
    }

    fn error(spec: &str) -> String {
        model(spec).err().map(|e| e.to_string()).unwrap_or_else(|| panic!("{spec} should be refused"))
    }

    /// The ways of giving an index that varies with wavelength, and what each means at n_d (RGB mode) and
    /// across the spectrum.
    #[test]
    fn dispersive_indices() {
        use crate::bsdf::Bsdf;
        let dispersion = |spec: &str| -> (f32, Arc<Dispersion>) {
            match model(spec).unwrap() {
                Bsdf::Dielectric(d) => (d.eta, d.dispersion.unwrap_or_else(|| panic!("{spec}: not dispersive"))),
                other => panic!("{other:?}"),
            }
        };
        // Schott N-BK7 by its Sellmeier coefficients: n_d = 1.5168, blue bends more than red.
        let (eta, d) = dispersion(
            r#"{"type": "dielectric", "ext_ior": 1, "int_ior": "sellmeier(1.03961212, 0.231792344, 1.01046945, 0.00600069867, 0.0200179144, 103.560653)"}"#,
        );
        assert!((eta - 1.5168).abs() < 1e-4, "{eta}");
        assert!(d.eta(400.0) > d.eta(550.0) && d.eta(550.0) > d.eta(700.0));
        // The same glass by name with `dispersive`; without it `bk7` is Mitsuba's constant 1.5046.
        let (eta, named) = dispersion(r#"{"type": "dielectric", "ext_ior": 1, "int_ior": "bk7", "dispersive": true}"#);
        assert!((eta - 1.5168).abs() < 1e-4, "{eta}");
        assert_eq!(named.eta(450.0), d.eta(450.0));
        match model(r#"{"type": "dielectric", "ext_ior": 1, "int_ior": "bk7"}"#).unwrap() {
            Bsdf::Dielectric(m) => assert_eq!((m.eta, m.dispersion), (1.5046, None)),
            other => panic!("{other:?}"),
        }
        // A name only gonio's dispersive table has needs no flag; the index is relative to `ext_ior`.
        let (eta, d) = dispersion(r#"{"type": "dielectric", "int_ior": "sf11", "ext_ior": 1.5}"#);
        assert!((eta - 1.784_72 / 1.5).abs() < 1e-4, "{eta}");
        assert!((d.eta(LAMBDA_D as f32) - eta).abs() < 1e-6);
        // An Abbe number turns n_d into glTF's Cauchy law: V_d comes back.
        let (eta, d) = dispersion(r#"{"type": "dielectric", "ext_ior": 1, "int_ior": 1.6, "abbe": 30}"#);
        assert!((eta - 1.6).abs() < 1e-6);
        assert!((d.int_ior.abbe_number() - 30.0).abs() < 1e-9);
        // Cauchy with two or three terms.
        let (_, d) = dispersion(r#"{"type": "dielectric", "ext_ior": 1, "int_ior": "cauchy(1.5, 0.004, 0.0001)"}"#);
        let l = 0.5f64;
        assert!((f64::from(d.eta(500.0)) - (1.5 + 0.004 / (l * l) + 0.0001 / l.powi(4))).abs() < 1e-6);
        // Both other dielectric models take it; `roughdielectric` refuses indices equal at some wavelength.
        assert!(model(r#"{"type": "thindielectric", "int_ior": "f2"}"#).unwrap().is_dispersive());
        assert!(model(r#"{"type": "roughdielectric", "int_ior": "water", "dispersive": true}"#).unwrap().is_dispersive());
        let e = error(r#"{"type": "roughdielectric", "int_ior": "cauchy(1.33, 0.003)", "ext_ior": 1.335}"#);
        assert!(e.contains("must differ at every wavelength") && e.contains("equal near"), "{e}");
    }

    /// Malformed laws, and laws where they are not taken, are refused with the parameter named.
    #[test]
    fn dispersive_indices_refused() {
        for (spec, expect) in [
            (r#"{"type": "dielectric", "int_ior": "sellmeier(1.0, 0.2, 0.01)"}"#, "as many B as C"),
            (r#"{"type": "dielectric", "int_ior": "sellmeier(1, 2, 3, 4, 5, 6, 7, 8, 9, 10)"}"#, "1 to 4"),
            (r#"{"type": "dielectric", "int_ior": "cauchy(1.5)"}"#, "cauchy(A, B) or cauchy(A, B, C)"),
            (r#"{"type": "dielectric", "int_ior": "cauchy(1.5, x)"}"#, "with numbers"),
            (r#"{"type": "dielectric", "int_ior": "crown"}"#, "unknown material `crown`"),
            (r#"{"type": "dielectric", "int_ior": "acetone", "dispersive": true}"#, "unknown glass `acetone`; with `dispersive`"),
            (r#"{"type": "dielectric", "int_ior": "sf11", "abbe": 40}"#, "`abbe` makes a constant `int_ior` dispersive"),
            (r#"{"type": "dielectric", "int_ior": 1.5, "abbe": 0}"#, "abbe"),
            // An absorption band inside the visible range: n² < 0 below 500 nm.
            (r#"{"type": "dielectric", "int_ior": "sellmeier(1.0, 0.25)"}"#, "must lie in"),
            (r#"{"type": "plastic", "int_ior": "sf11"}"#, "taken by `dielectric`, `roughdielectric` and `thindielectric` only"),
            (r#"{"type": "roughplastic", "int_ior": "cauchy(1.5, 0.01)"}"#, "taken by `dielectric`"),
            (r#"{"type": "plastic", "int_ior": 1.5, "abbe": 40}"#, "abbe"),
        ] {
            let e = error(spec);
            assert!(e.contains(expect), "{spec}: {e}");
            assert!(e.contains("int_ior") || e.contains("abbe"), "{spec}: the parameter is named: {e}");
        }
    }

    #[test]
    fn named_and_numeric_indices() {
        let d =
            Dielectric::from_props(&Props::from_json(r#"{"type": "dielectric", "int_ior": "bk7", "ext_ior": "vacuum"}"#).unwrap()).unwrap();
        assert!((d.eta - 1.5046).abs() < 1e-6);
        let d = Dielectric::from_props(&Props::from_json(r#"{"type": "dielectric"}"#).unwrap()).unwrap();
        assert!((d.eta - 1.5046 / 1.000_277).abs() < 1e-6, "Mitsuba's defaults: bk7 in air");
    }
}
