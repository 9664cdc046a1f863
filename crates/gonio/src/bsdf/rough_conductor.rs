//! `roughconductor` — a rough metal: Mitsuba's microfacet conductor (Walter et al. 2007, "Microfacet
//! Models for Refraction through Rough Surfaces", eq. 20) with Smith's separable masking–shadowing.
//!
//! | parameter              | type            | default      | meaning                                          |
//! |------------------------|-----------------|--------------|--------------------------------------------------|
//! | `distribution`         | `beckmann` \| `ggx` | `beckmann` | the microfacet distribution (as in Mitsuba)   |
//! | `alpha`                | float [1e-4, 10]| 0.1          | roughness (RMS slope for Beckmann); isotropic     |
//! | `alpha_u`, `alpha_v`   | float [1e-4, 10]| `alpha`      | roughness along the tangent and bitangent (anisotropic; instead of `alpha`) |
//! | `material`             | string          | `"none"`     | named metal (`Au`, `Cu`, …); `none` reflects 100 % |
//! | `eta`, `k`             | rgb ≥ 0         | preset       | complex index η + i k (instead of `material`)     |
//! | `specular_reflectance` | rgb [0,1]       | 1            | multiplier (not physical)                          |
//! | `sample_visible`       | bool            | true         | sample the visible normals (Heitz & d'Eon 2014) rather than D·cos |
//! | `energy_compensation`  | bool            | false        | add the multiple-scattering lobe of Kulla & Conty 2017 (isotropic `alpha` only; see [`super::energy_compensation`]) |
//!
//! Without compensation a white rough conductor loses the light that bounces between microfacets: white
//! furnace 0.99 (GGX α = 0.05), 0.88 (0.25), 0.69 (0.5), 0.38 (1.0); Beckmann 0.97 (0.25), 0.66 (1.0).
//! With it, 1.000 ± 0.003 at every α ≤ 1 (2026-11, `energy_compensation` tests); `gonio albedo` shows both.
//!
//! f(ωo, ωi) = F(ωo·ωh) D(ωh) G1(ωo, ωh) G1(ωi, ωh) / (4 cos θo cos θi), ωh = (ωo + ωi)/|ωo + ωi|
//! (Walter 2007 eq. 20 with the separable Smith G of eq. 23 — what Mitsuba 3 uses). Λ is exact for both
//! distributions (gonio uses the erf form for Beckmann where Mitsuba uses Walter's rational approximation,
//! eq. 27: compared with Mitsuba 3 they differ by up to 0.6 % in f and 0.3 % in the visible-normal pdf,
//! and agree to 1e-5 once that approximation is undone). One-sided: light from below is absorbed. The `material`,
//! `eta`, `k` and `specular_reflectance` parameters are those of [`Conductor`].
//!
//! Sampling draws ωh from the distribution (visible normals or D·cos) and reflects ωo about it;
//! pdf(ωi) = pdf(ωh) / (4 ωo·ωh) (Walter 2007 eq. 14). `f` and `pdf` of a sample are evaluated from the
//! returned ωi, so `sample`, `f` and `pdf` agree to the last bit. The lobe is written once over the lanes
//! and the distribution ([`ConductorLobe`], [`ReflectionLobe`]): single calls run it at `f32`, batches and
//! the renderer's packets in SIMD lanes, for GGX and Beckmann alike (the energy-compensated configuration
//! adds its tabulated lobe in single calls).
//!
//! Roughness range: below α = 1e-4 the lobe is narrower than f32 can place a half vector reliably
//! (round-off in ωo + ωi is ~1e-7 rad, 0.1 % of the lobe at 1e-4); use `conductor`. Above 10 the model
//! is a grey, strongly shadowed surface and nothing new is learnt.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let gold = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, "material": "Au"}"#).unwrap();
//! let wo = Vec3::new(0.3, 0.0, 0.954).normalize();
//! let s = gold.sample(wo, 0.5, Vec2::new(0.4, 0.6)).unwrap();
//! assert!((s.pdf - gold.pdf(wo, s.wi)).abs() <= 1e-6 * s.pdf);
//! // Gold reflects red more than blue.
//! assert!(s.weight.r() > s.weight.b());
//! ```

use super::energy_compensation::ConductorCompensation;
use super::lanes::{f_one, flag_lanes, pdf_one, sample_one, LaneModel, LaneSample, PerLaneKernel};
use super::{BsdfFlags, BsdfModel, BsdfSample, Conductor};
use crate::error::{Error, Result};
use crate::fresnel::{fresnel_conductor_at, ConductorIndex};
use crate::math::lanes::{channels, Real, V3};
use crate::math::param::{Param, PerLane, PER_LANE};
use crate::math::{Vec2, Vec3};
use crate::microfacet::reflection::ReflectionLobe;
use crate::microfacet::{alpha_from_blinn_exponent, on_distribution, Distribution, MicrofacetDistribution, MicrofacetKind, Shadowing};
use crate::props::Props;
use crate::spectrum::Rgb;

/// Roughness limits of every microfacet conductor (see the module doc for the reasons).
pub const ALPHA_MIN: f32 = 1e-4;
pub const ALPHA_MAX: f32 = 10.0;

/// A texture's value on a roughness parameter as the microfacet models take it: clamped to
/// [[`ALPHA_MIN`], [`ALPHA_MAX`]] (Mitsuba's distributions clamp α to 10⁻⁴ the same way).
#[inline]
#[must_use]
pub fn textured_roughness(value: f32) -> f32 {
    value.clamp(ALPHA_MIN, ALPHA_MAX)
}

/// The shared core of `roughconductor` and `torrance_sparrow`: a microfacet distribution, a
/// masking–shadowing form, a sampling strategy and a conductor's Fresnel term.
#[derive(Clone, Debug, PartialEq)]
pub struct MicrofacetConductor {
    pub distribution: MicrofacetDistribution,
    pub shadowing: Shadowing,
    pub sample_visible: bool,
    /// The smooth conductor whose reflectance F(cos) weights each microfacet.
    pub fresnel: Conductor,
    /// The multiple-scattering lobe added by `energy_compensation` ([`ConductorCompensation`]).
    pub compensation: Option<ConductorCompensation>,
}

/// What a plugin accepts and defaults to; the plugins differ only in these.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MicrofacetParams {
    /// Accepted `distribution` values.
    pub kinds: &'static [MicrofacetKind],
    pub default_kind: MicrofacetKind,
    pub default_alpha: f32,
    /// `Some(default)`: a `shadowing` parameter is read; `None`: Smith, fixed.
    pub shadowing: Option<Shadowing>,
    /// Whether the Blinn `exponent` is accepted (instead of `alpha`).
    pub exponent: bool,
}

impl MicrofacetParams {
    /// Mitsuba's microfacet plugins (`roughconductor`, `roughdielectric`, `roughplastic`): Beckmann (the
    /// default) or GGX, α = 0.1 by default, Smith shadowing, no Blinn exponent.
    pub const MITSUBA: MicrofacetParams = MicrofacetParams {
        kinds: &[MicrofacetKind::Beckmann, MicrofacetKind::Ggx],
        default_kind: MicrofacetKind::Beckmann,
        default_alpha: 0.1,
        shadowing: None,
        exponent: false,
    };
}

impl MicrofacetConductor {
    /// A microfacet conductor with `distribution`, `shadowing` and the Fresnel term of `fresnel`.
    #[must_use]
    pub fn new(distribution: MicrofacetDistribution, shadowing: Shadowing, sample_visible: bool, fresnel: Conductor) -> Self {
        MicrofacetConductor { distribution, shadowing, sample_visible, fresnel, compensation: None }
    }

    /// The same model with Kulla & Conty's multiple-scattering lobe added (isotropic roughness only;
    /// see [`super::energy_compensation`]).
    #[must_use]
    pub fn with_energy_compensation(mut self) -> Self {
        self.compensation = Some(ConductorCompensation::new(&self));
        self
    }

    pub(crate) fn from_props(p: &Props, rules: &MicrofacetParams) -> Result<Self> {
        let plugin = p.plugin_type().to_string();
        let distribution = read_distribution(p, rules)?;
        // Read `shadowing` only where it is a parameter, so that `finish` rejects it elsewhere.
        let shadowing = match rules.shadowing {
            None => Shadowing::Smith,
            Some(default) => match p.string("shadowing")? {
                None => default,
                Some(name) => Shadowing::parse(&name).ok_or_else(|| {
                    let names: Vec<&str> = Shadowing::ALL.iter().map(|s| s.name()).collect();
                    Error::spec(p.at(), format!("parameter `shadowing` of `{plugin}` must be one of {}, got `{name}`", names.join(", ")))
                })?,
            },
        };
        let sample_visible = p.bool("sample_visible", true)?;
        let fresnel = Conductor::from_props(p)?;
        Ok(MicrofacetConductor::new(distribution, shadowing, sample_visible, fresnel))
    }

    /// f = F(ωo·ωh) D(ωh) G(ωo, ωi, ωh) / (4 cos θo cos θi) for both directions above the surface: the
    /// lobe's kernel ([`ConductorKernel`]) at one pair.
    #[must_use]
    #[inline(always)]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        f_one(&self.kernel(), wo, wi)
    }

    /// The solid-angle density of [`sample_lobe`](Self::sample_lobe): pdf(ωh) / (4 ωo·ωh).
    #[must_use]
    #[inline(always)]
    pub fn pdf_lobe(&self, wo: Vec3, wi: Vec3) -> f32 {
        pdf_one(&self.kernel(), wo, wi)
    }

    /// Sample ωh, reflect ωo about it; `f` and `pdf` are those of the returned ωi.
    #[must_use]
    #[inline(always)]
    pub fn sample_lobe(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        sample_one(&self.kernel(), wo, 0.0, u)
    }

    /// The glossy lobe of this model as a lane kernel, for its distribution (matched here, once per call).
    #[inline(always)]
    pub(crate) fn kernel(&self) -> ConductorKernel {
        on_distribution!(self.distribution, |d| ConductorKernel::from(self.lobe(d)))
    }

    /// The glossy lobe with the distribution `d`: this model's own, or its kind with a roughness per lane.
    #[inline(always)]
    fn lobe<D>(&self, d: D) -> ConductorLobe<D> {
        self.lobe_with(d, ConductorFresnel::of(&self.fresnel))
    }

    /// The glossy lobe with the distribution `d` and the Fresnel term `fresnel` (this model's, or one per lane).
    #[inline(always)]
    fn lobe_with<D, P>(&self, d: D, fresnel: ConductorFresnel<P>) -> ConductorLobe<D, P> {
        ConductorLobe { lobe: ReflectionLobe { distribution: d, shadowing: self.shadowing, visible: self.sample_visible }, fresnel }
    }

    /// The kernel of the lanes `models` (lane → its model; lanes without a model take the first's), each a
    /// copy of this model that may differ from it in its roughness and its Fresnel term only — as spectral
    /// mode's copies at each lane's wavelengths do ([`Bsdf::kernel_of_lanes`](super::Bsdf::kernel_of_lanes)):
    /// one kernel call for the lanes instead of one per lane. `None` with energy compensation, for Blinn,
    /// or where the lanes differ in anything else (a mirror beside a metal, another distribution).
    pub(crate) fn kernel_of_lanes(&self, models: &[Option<&MicrofacetConductor>; PER_LANE]) -> Option<PerLaneKernel<'static>> {
        if self.compensation.is_some() {
            return None;
        }
        let model = |l: usize| models[l].unwrap_or(self);
        let alike = (0..PER_LANE).all(|l| {
            let m = model(l);
            m.compensation.is_none()
                && m.distribution.kind == self.distribution.kind
                && m.shadowing == self.shadowing
                && m.sample_visible == self.sample_visible
                && m.fresnel.eta_k.is_some() == self.fresnel.eta_k.is_some()
        });
        if !alike {
            return None;
        }
        let alphas = (
            PerLane(std::array::from_fn(|l| model(l).distribution.alpha_x)),
            PerLane(std::array::from_fn(|l| model(l).distribution.alpha_y)),
        );
        let fresnel = ConductorFresnel::per_lane(std::array::from_fn(|l| ConductorFresnel::of(&model(l).fresnel)));
        self.distribution.per_lane(
            alphas,
            |d| PerLaneKernel::ConductorLanesGgx(Box::new(self.lobe_with(d, fresnel))),
            |d| PerLaneKernel::ConductorLanesBeckmann(Box::new(self.lobe_with(d, fresnel))),
        )
    }

    /// The kernel of this model with the roughness (`ax`, `ay`) of each lane instead of its own (GGX and
    /// Beckmann without energy compensation; `None` otherwise): [`Bsdf::per_lane_kernel`](super::Bsdf::per_lane_kernel).
    pub(crate) fn per_lane(&self, alphas: (PerLane, PerLane)) -> Option<PerLaneKernel<'static>> {
        if self.compensation.is_some() {
            return None;
        }
        self.distribution.per_lane(
            alphas,
            |d| PerLaneKernel::ConductorGgx(self.lobe(d)),
            |d| PerLaneKernel::ConductorBeckmann(self.lobe(d)),
        )
    }

    /// The kernel of this model when the glossy lobe is all of it (no energy compensation, whose lobe
    /// looks its tables up per lane and stays on the single calls).
    #[inline(always)]
    pub(crate) fn lanes(&self) -> Option<ConductorKernel> {
        self.compensation.is_none().then(|| self.kernel())
    }
}

/// A conductor's Fresnel term per channel: the complex index, as the Fresnel term reads it (`None`: a
/// perfect mirror), and the multiplier; one value each (`f32`: a model's) or one per lane ([`PerLane`]:
/// the lanes of [`MicrofacetConductor::kernel_of_lanes`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConductorFresnel<P = f32> {
    pub index: Option<[ConductorIndex<P>; 3]>,
    pub specular_reflectance: [P; 3],
}

impl ConductorFresnel {
    /// The Fresnel term of the smooth conductor `c`.
    #[inline(always)]
    #[must_use]
    pub fn of(c: &Conductor) -> Self {
        let index = c.eta_k.map(|(eta, k)| std::array::from_fn(|i| ConductorIndex::new(eta.0[i], k.0[i])));
        ConductorFresnel { index, specular_reflectance: c.specular_reflectance.0 }
    }
}

impl ConductorFresnel<PerLane> {
    /// The lanes' terms, one per lane; a lane that is a mirror (no index) where the first is not, or the
    /// reverse, reads the first's index (the caller checks that they agree).
    #[must_use]
    pub fn per_lane(lanes: [ConductorFresnel; PER_LANE]) -> Self {
        let index = lanes[0].index.map(|first| {
            std::array::from_fn(|c| ConductorIndex::per_lane(std::array::from_fn(|l| lanes[l].index.map_or(first[c], |i| i[c]))))
        });
        ConductorFresnel {
            index,
            specular_reflectance: std::array::from_fn(|c| PerLane(lanes.each_ref().map(|l| l.specular_reflectance[c]))),
        }
    }
}

/// The microfacet conductor's glossy lobe for the distribution `D` in lanes ([`LaneModel`]): the Walter
/// 2007 reflection lobe ([`ReflectionLobe`]) times the conductor's Fresnel term (one, or one per lane: `P`).
/// `f`, `pdf` and `sample` of [`MicrofacetConductor`] are these, for single calls and batches alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConductorLobe<D, P = f32> {
    pub lobe: ReflectionLobe<D>,
    pub fresnel: ConductorFresnel<P>,
}

impl<D: Distribution, P: Param> LaneModel for ConductorLobe<D, P> {
    /// F(ωo·ωh) D G / (4 cos θo cos θi), 0 where the lobe is (see [`LobeValue`](crate::microfacet::reflection::LobeValue)).
    #[inline(always)]
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3] {
        let zero = R::splat(0.0);
        let v = self.lobe.eval(wo, wi);
        let fresnel = match &self.fresnel.index {
            Some(index) => channels!(|c| fresnel_conductor_at(v.cos_theta_d, &index[c])),
            None => [R::splat(1.0); 3],
        };
        let s = self.fresnel.specular_reflectance;
        channels!(|c| R::select(v.ok, fresnel[c] * s[c].lanes::<R>() * v.value, zero))
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        self.lobe.pdf(wo, wi)
    }

    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, _uc: R, ux: R, uy: R) -> LaneSample<R> {
        let above = !wo.z.le(R::splat(0.0));
        if !R::any(above) {
            return LaneSample::none(above);
        }
        let s = self.lobe.sample(wo, ux, uy);
        LaneSample::smooth(s.wi, self.f_lanes(wo, s.wi), self.pdf_lanes(wo, s.wi), flag_lanes(BsdfFlags::GLOSSY_REFLECTION), s.valid)
    }
}

distribution_kernel! {
    /// [`ConductorLobe`] for the distribution a model has: the kind matched once per call.
    ConductorKernel, ConductorLobe
}

/// `distribution` (one of `rules.kinds`) and its roughness (see [`read_roughness`]). Shared by every
/// microfacet plugin (`roughconductor`, `torrance_sparrow`, `roughdielectric`, `roughplastic`).
pub(crate) fn read_distribution(p: &Props, rules: &MicrofacetParams) -> Result<MicrofacetDistribution> {
    let plugin = p.plugin_type();
    let kind = match p.string("distribution")? {
        None => rules.default_kind,
        Some(name) => MicrofacetKind::parse(&name).filter(|k| rules.kinds.contains(k)).ok_or_else(|| {
            let names: Vec<&str> = rules.kinds.iter().map(|k| k.name()).collect();
            Error::spec(p.at(), format!("parameter `distribution` of `{plugin}` must be one of {}, got `{name}`", names.join(", ")))
        })?,
    };
    let (alpha_x, alpha_y) = read_roughness(p, rules)?;
    if kind == MicrofacetKind::Blinn && alpha_x != alpha_y {
        return Err(Error::spec(
            p.at(),
            format!("`{plugin}`: `alpha_u` ≠ `alpha_v` needs distribution beckmann or ggx (Blinn is isotropic)"),
        ));
    }
    Ok(MicrofacetDistribution::new(kind, alpha_x, alpha_y))
}

/// `alpha`, or `alpha_u`/`alpha_v`, or (when allowed) the Blinn `exponent`; at most one of the three forms.
fn read_roughness(p: &Props, rules: &MicrofacetParams) -> Result<(f32, f32)> {
    let plugin = p.plugin_type();
    let forms = [p.has("alpha"), p.has("alpha_u") || p.has("alpha_v"), rules.exponent && p.has("exponent")];
    if forms.iter().filter(|f| **f).count() > 1 {
        let names = if rules.exponent { "`alpha`, `alpha_u`/`alpha_v` or `exponent`" } else { "`alpha` or `alpha_u`/`alpha_v`" };
        return Err(Error::spec(p.at(), format!("give one of {names} to `{plugin}`")));
    }
    let alpha = p.float_in("alpha", rules.default_alpha, ALPHA_MIN, ALPHA_MAX)?;
    let alpha_u = p.float_in("alpha_u", alpha, ALPHA_MIN, ALPHA_MAX)?;
    let alpha_v = p.float_in("alpha_v", alpha, ALPHA_MIN, ALPHA_MAX)?;
    if rules.exponent && p.has("exponent") {
        // α ≥ 1e-4 ⇔ e ≤ 2·10⁸ − 2.
        let e = p.float_in("exponent", 0.0, 0.0, 1e8)?;
        let a = alpha_from_blinn_exponent(e);
        return Ok((a, a));
    }
    Ok((alpha_u, alpha_v))
}

impl crate::bsdf::Examples for RoughConductor {
    /// Examples for `gonio check --all`: defaults and extremes (α down to 0.001, 20:1 anisotropy). All
    /// pass the full standard since the chi-square cell integrals became adaptive (2026-11; p-values at
    /// cos θo = 0.98/0.7/0.3/0.05 for the default: 0.0063/0.25/0.19/0.088, for GGX α = 0.001:
    /// 0.36/0.65/0.50/0.36).
    const EXAMPLES: &'static [&'static str] = &[
        r#"{"type": "roughconductor"}"#,
        r#"{"type": "roughconductor", "alpha": 0.3}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Cu"}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha": 1.0}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 1.0, "sample_visible": false}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.05, "alpha_v": 1.0, "material": "Al"}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.01, "material": "Au"}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha": 0.01, "sample_visible": false}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.02, "alpha_v": 0.4, "material": "Al"}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha_u": 0.4, "alpha_v": 0.02, "sample_visible": false}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha_u": 1.0, "alpha_v": 0.05, "sample_visible": false}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.001, "material": "Au"}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha": 0.001}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha": 0.001, "sample_visible": false}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.5, "energy_compensation": true}"#,
        r#"{"type": "roughconductor", "distribution": "beckmann", "alpha": 1.0, "material": "Au", "energy_compensation": true}"#,
    ];
}

impl BsdfModel for MicrofacetConductor {
    fn flags(&self) -> BsdfFlags {
        if self.compensation.is_some() {
            BsdfFlags::GLOSSY_REFLECTION | BsdfFlags::DIFFUSE_REFLECTION
        } else {
            BsdfFlags::GLOSSY_REFLECTION
        }
    }

    #[inline(always)]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if let Some(k) = self.lanes() {
            return f_one(&k, wo, wi);
        }
        let single = self.eval(wo, wi);
        match &self.compensation {
            Some(ms) if wo.z > 0.0 && wi.z > 0.0 => single + ms.f(wo.z, wi.z),
            _ => single,
        }
    }

    /// The glossy lobe; with compensation, a direction of the multiple-scattering lobe with probability
    /// 1 − E(μo) instead.
    #[inline(always)]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if let Some(k) = self.lanes() {
            return sample_one(&k, wo, uc, u);
        }
        let Some(ms) = &self.compensation else { return self.sample_lobe(wo, u) };
        if !(wo.z > 0.0) {
            return None;
        }
        let (wi, flags) = if uc < ms.probability(wo.z) {
            (ms.sample(u), BsdfFlags::DIFFUSE_REFLECTION)
        } else {
            (self.sample_lobe(wo, u)?.wi, BsdfFlags::GLOSSY_REFLECTION)
        };
        if !(wi.z > 0.0) {
            return None;
        }
        let s = BsdfSample::smooth(wi, self.f(wo, wi), self.pdf(wo, wi), flags, 1.0)?;
        s.weight.is_finite().then_some(s)
    }

    #[inline(always)]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if let Some(k) = self.lanes() {
            return pdf_one(&k, wo, wi);
        }
        let lobe = self.pdf_lobe(wo, wi);
        match &self.compensation {
            Some(ms) if wo.z > 0.0 && wi.z > 0.0 => {
                let p = ms.probability(wo.z);
                (1.0 - p) * lobe + p * ms.pdf(wi)
            }
            _ => lobe,
        }
    }

    lane_batch_methods!(lanes);
}

/// Mitsuba's rough conductor: Beckmann or GGX with separable Smith shadowing.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughConductor(pub MicrofacetConductor);

impl RoughConductor {
    /// A rough conductor of distribution `kind` (Beckmann or GGX) with Fresnel term `fresnel`.
    #[must_use]
    pub fn new(kind: MicrofacetKind, alpha_x: f32, alpha_y: f32, fresnel: Conductor) -> Self {
        debug_assert!(kind != MicrofacetKind::Blinn, "roughconductor is Beckmann or GGX");
        RoughConductor(MicrofacetConductor::new(MicrofacetDistribution::new(kind, alpha_x, alpha_y), Shadowing::Smith, true, fresnel))
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let core = MicrofacetConductor::from_props(p, &MicrofacetParams::MITSUBA)?;
        if !p.bool("energy_compensation", false)? {
            return Ok(RoughConductor(core));
        }
        super::rough_dielectric::check_isotropic_for_compensation(p, &core.distribution)?;
        Ok(RoughConductor(core.with_energy_compensation()))
    }
}

forward_bsdf_model!(RoughConductor => 0);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;
    #[allow(unused_imports)]
    use crate::bsdf::Examples;
    use crate::fresnel::fresnel_conductor;
    use crate::verify::energy;

    #[test]
    fn small_alpha_albedo_approaches_the_fresnel_reflectance() {
        // As α → 0 the lobe becomes the mirror: a(ωo) → F(cos θo) (G → 1 away from grazing).
        let (eta, k) = (0.2f32, 3.9f32);
        for kind in ["beckmann", "ggx"] {
            let spec = format!(r#"{{"type": "roughconductor", "distribution": "{kind}", "alpha": 0.001, "eta": {eta}, "k": {k}}}"#);
            let b = Bsdf::from_json(&spec).unwrap();
            for mu in [1.0f32, 0.5, 0.1] {
                let a = energy::albedo_at(&b, mu, 65_536, 3).r();
                let expect = fresnel_conductor(mu, eta, k);
                eprintln!("{kind} α=0.001 cosθo={mu}: albedo {a:.6}, F = {expect:.6}");
                assert!((a - expect).abs() < 2e-3, "{kind} μ={mu}: {a} vs {expect}");
            }
        }
    }

    #[test]
    fn rough_white_ggx_loses_energy() {
        // Single scattering of a rough surface misses the light that bounces between microfacets.
        let b = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 1.0}"#).unwrap();
        for mu in [1.0f32, 0.5, 0.1] {
            let a = energy::albedo_at(&b, mu, 1 << 20, 5).r();
            eprintln!("white GGX α=1 cosθo={mu}: albedo {a:.4}");
            assert!(a < 0.95, "μ={mu}: {a}");
        }
    }

    #[test]
    fn parameters_are_checked() {
        for bad in [
            r#"{"type": "roughconductor", "distribution": "blinn"}"#,
            r#"{"type": "roughconductor", "alpha": 0.00001}"#,
            r#"{"type": "roughconductor", "alpha": 0.1, "alpha_u": 0.2}"#,
            r#"{"type": "roughconductor", "shadowing": "vcavity"}"#,
            r#"{"type": "roughconductor", "exponent": 10}"#,
            r#"{"type": "roughconductor", "material": "Au", "eta": 1}"#,
        ] {
            assert!(Bsdf::from_json(bad).is_err(), "{bad}");
        }
        let b = Bsdf::from_json(r#"{"type": "roughconductor"}"#).unwrap();
        let Bsdf::RoughConductor(RoughConductor(m)) = b else { panic!() };
        assert_eq!(m.distribution, MicrofacetDistribution::new(MicrofacetKind::Beckmann, 0.1, 0.1));
        assert!(m.sample_visible && m.shadowing == Shadowing::Smith && m.fresnel.eta_k.is_none());
    }
}
