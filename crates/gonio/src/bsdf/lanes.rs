//! SIMD kernels: a model's `f`, `pdf` and `sample` written once over [`Real`] lanes, run a register of
//! rows at a time by the batch methods and one row at a time by the single calls — so a batch equals the
//! single calls bit for bit by construction (test `bsdf::tests::batches_equal_single_calls`).
//!
//! A model (or one configuration of it, e.g. GGX with visible-normal sampling) that has a kernel implements
//! [`LaneModel`]; its `BsdfModel` methods call [`f_one`], [`pdf_one`], [`sample_one`] for that
//! configuration. Every [`Bsdf`] runs in lanes through one dispatch (`Bsdf::f_lanes_where` and friends,
//! below): its kernel, its components' lanes for the composites, or its single calls lane by lane
//! ([`each_lane`]). The path tracer calls that dispatch for the lanes of a packet that share a model. The
//! batch methods of a model with a kernel call the drivers [`f_rows`], [`pdf_rows`], [`sample_rows`] and
//! their `_checked` forms (`Bsdf`'s batches choose the model once and call its batch methods: running every
//! batch through the dispatch made models without a kernel up to 6× slower from Python, 2026-12-04, as
//! its single calls lane by lane cannot be inlined and vectorised the way a per-pair loop over one model
//! type is). A driver loads the rows into
//! structure-of-arrays lanes ([`V3`] of the widest lane type the CPU runs: `Twice<Twice<Avx16>>` with AVX-512, `Avx8`
//! with AVX2, else [`F32x8`]), runs the kernel and stores the lanes back; the last rows (fewer than a
//! register) run on single `f32`s. The `_checked` forms also test the rows against a [`RowCheck`] on the
//! lanes already loaded, so that checking a batch's inputs costs no pass of its own. Measured with callgrind
//! (instructions per row): see the table in the `batch_rows` example's doc.

use super::conductor::Conductor;
use super::dielectric::Dielectric;
use super::plastic::CoatedMirror;
use super::polarizer::Polarizer;
use super::principled::PrincipledLobes;
use super::rough_conductor::{ConductorKernel, ConductorLobe};
use super::rough_dielectric::{DielectricKernel, DielectricLobe};
use super::rough_plastic::{PlasticKernel, PlasticLobe};
use super::thin_dielectric::ThinDielectric;
use super::{Bsdf, BsdfFlags, BsdfSample, SampleColumns};
use crate::math::lanes::{channels, F32x8, Real, Rows, V3};
use crate::math::param::PerLane;
use crate::math::{Vec2, Vec3};
use crate::microfacet::{Beckmann, Ggx};
use crate::spectrum::Rgb;

/// One sampled row per lane: the fields of [`BsdfSample`] as lanes, and which lanes hold a sample.
#[derive(Clone, Copy, Debug)]
pub struct LaneSample<R: Real> {
    pub wi: V3<R>,
    pub f: [R; 3],
    pub pdf: R,
    pub weight: [R; 3],
    /// The bits of [`BsdfFlags`] as numbers (small integers, exact in `f32`).
    pub flags: R,
    pub eta: R,
    /// Lanes where `sample` returns `Some`.
    pub valid: R::Mask,
}

impl<R: Real> LaneSample<R> {
    /// A sample of a smooth lobe, as [`BsdfSample::smooth`] (valid only where 0 < pdf < ∞) with the weight
    /// f |cos θi| / pdf, which must be finite too: far out in the tails of a glossy lobe f and pdf are both
    /// subnormal and the quotient overflows; such a direction carries no measurable energy (2026-11).
    #[inline(always)]
    pub fn smooth(wi: V3<R>, f: [R; 3], pdf: R, flags: R, valid: R::Mask) -> Self {
        let ratio = wi.z.abs() / pdf;
        let weight = channels!(|c| f[c] * ratio);
        let finite = weight[0].is_finite() & weight[1].is_finite() & weight[2].is_finite();
        let valid = valid & pdf.gt(R::splat(0.0)) & pdf.is_finite() & finite;
        LaneSample { wi, f, pdf, weight, flags, eta: R::splat(1.0), valid }
    }

    /// A sample of a delta lobe, as [`BsdfSample::delta`] (valid only where `prob` > 0): `value` the
    /// multiplier, chosen with probability `prob`, and f = value / |cos θi| where that is finite (else 0).
    #[inline(always)]
    pub fn delta(wi: V3<R>, value: [R; 3], prob: R, flags: R, eta: R, valid: R::Mask) -> Self {
        let zero = R::splat(0.0);
        let cos = wi.z.abs();
        let f = channels!(|c| {
            let q = value[c] / cos;
            R::select(cos.gt(zero) & q.is_finite(), q, zero)
        });
        let weight = channels!(|c| value[c] / prob);
        LaneSample { wi, f, pdf: prob, weight, flags, eta, valid: valid & prob.gt(zero) }
    }

    /// No sample in any lane.
    #[inline(always)]
    pub fn none(valid: R::Mask) -> Self {
        let zero = R::splat(0.0);
        LaneSample { wi: V3::new(zero, zero, zero), f: [zero; 3], pdf: zero, weight: [zero; 3], flags: zero, eta: zero, valid }
    }
}

impl<R: Real> LaneSample<R> {
    /// `a` in the lanes of `m`, else `b`, field by field.
    #[inline(always)]
    pub fn select(m: R::Mask, a: Self, b: Self) -> Self {
        LaneSample {
            wi: V3::select(m, a.wi, b.wi),
            f: channels!(|c| R::select(m, a.f[c], b.f[c])),
            pdf: R::select(m, a.pdf, b.pdf),
            weight: channels!(|c| R::select(m, a.weight[c], b.weight[c])),
            flags: R::select(m, a.flags, b.flags),
            eta: R::select(m, a.eta, b.eta),
            valid: (m & a.valid) | (!m & b.valid),
        }
    }

    /// Where the sampled lobe is a Dirac delta: flag bits are below 32, so the delta bit (16) is set
    /// exactly where the number is at least 16.
    #[inline(always)]
    pub fn is_delta(&self) -> R::Mask {
        self.flags.ge(R::splat(BsdfFlags::DELTA.0 as f32))
    }
}

/// Every lane set.
#[inline(always)]
#[must_use]
pub fn all<R: Real>() -> R::Mask {
    R::splat(0.0).eq(R::splat(0.0))
}

/// The flag bits of `flags` as a lane number.
#[inline(always)]
#[must_use]
pub fn flag_lanes<R: Real>(flags: BsdfFlags) -> R {
    R::splat(flags.0 as f32)
}

/// A model (or configuration) whose `f`, `pdf` and `sample` are written over [`Real`] lanes. Each must give
/// what the model's `BsdfModel` method gives, and does, because those call these (see the module doc).
pub trait LaneModel {
    /// f(ωo, ωi) per channel.
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3];
    /// pdf(ωo, ωi).
    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R;
    /// sample(ωo, uc, (ux, uy)).
    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R) -> LaneSample<R>;
}

/// A model's lane code through a reference (the batch methods' kernel of a model that is its own).
impl<K: LaneModel> LaneModel for &K {
    #[inline(always)]
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3] {
        (**self).f_lanes(wo, wi)
    }

    #[inline(always)]
    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        (**self).pdf_lanes(wo, wi)
    }

    #[inline(always)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R) -> LaneSample<R> {
        (**self).sample_lanes(wo, uc, ux, uy)
    }
}

/// The kernel of a model whose configuration has one: the models the `Bsdf` lane dispatch runs in lanes
/// besides `diffuse` and the composites.
#[derive(Clone, Copy, Debug)]
pub enum LaneKernel<'a> {
    Conductor(ConductorKernel),
    RoughPlastic(PlasticKernel<'a>),
    RoughDielectric(DielectricKernel),
    SmoothConductor(&'a Conductor),
    Dielectric(&'a Dielectric),
    ThinDielectric(&'a ThinDielectric),
    Plastic(CoatedMirror<f32>),
    Polarizer(&'a Polarizer),
    Principled(PrincipledLobes),
}

/// The kernel of a model with a parameter given per lane ([`Bsdf::per_lane_kernel`]): a textured roughness
/// (of the rough conductors and dielectric) or base colour (of the plastics and `principled`) in the path tracer's
/// packets runs one kernel call for all the lanes on it, each lane with its own value, instead of a model
/// and a call per lane. The same lobes as the models' own kernels, over a [`PerLane`] parameter. Read in at
/// most [`crate::math::param::PER_LANE`] lanes.
#[derive(Clone, Debug)]
pub enum PerLaneKernel<'a> {
    ConductorGgx(ConductorLobe<Ggx<PerLane>>),
    ConductorBeckmann(ConductorLobe<Beckmann<PerLane>>),
    DielectricGgx(DielectricLobe<Ggx<PerLane>>),
    DielectricBeckmann(DielectricLobe<Beckmann<PerLane>>),
    RoughPlasticGgx(PlasticLobe<'a, Ggx, PerLane>),
    RoughPlasticBeckmann(PlasticLobe<'a, Beckmann, PerLane>),
    Plastic(CoatedMirror<PerLane>),
    /// Boxed: its constants per lane (~0.7 KB) would make every kernel that size, and the path tracer keeps
    /// one per group of lanes in each packet's shading.
    Principled(Box<PrincipledLobes<PerLane>>),
    /// A rough conductor with its roughness and its Fresnel term per lane ([`Bsdf::kernel_of_lanes`]:
    /// spectral mode's copies of one model at each lane's wavelengths). Boxed, as `Principled`.
    ConductorLanesGgx(Box<ConductorLobe<Ggx<PerLane>, PerLane>>),
    ConductorLanesBeckmann(Box<ConductorLobe<Beckmann<PerLane>, PerLane>>),
}

/// Each kernel of [`PerLaneKernel`], bound to `$k` in `$body`.
macro_rules! on_per_lane {
    ($kernel:expr, |$k:ident| $body:expr) => {
        match $kernel {
            PerLaneKernel::ConductorGgx($k) => $body,
            PerLaneKernel::ConductorBeckmann($k) => $body,
            PerLaneKernel::DielectricGgx($k) => $body,
            PerLaneKernel::DielectricBeckmann($k) => $body,
            PerLaneKernel::RoughPlasticGgx($k) => $body,
            PerLaneKernel::RoughPlasticBeckmann($k) => $body,
            PerLaneKernel::Plastic($k) => $body,
            PerLaneKernel::Principled($k) => $body,
            PerLaneKernel::ConductorLanesGgx($k) => $body,
            PerLaneKernel::ConductorLanesBeckmann($k) => $body,
        }
    };
}

/// Not inlined, as [`LaneKernel`]'s (one copy for the packets' lane type).
impl LaneModel for PerLaneKernel<'_> {
    #[inline(never)]
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3] {
        on_per_lane!(self, |k| k.f_lanes(wo, wi))
    }

    #[inline(never)]
    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        on_per_lane!(self, |k| k.pdf_lanes(wo, wi))
    }

    #[inline(never)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R) -> LaneSample<R> {
        on_per_lane!(self, |k| k.sample_lanes(wo, uc, ux, uy))
    }
}

impl Bsdf {
    /// This model's [`LaneKernel`], `None` for models and configurations without one (`diffuse` and the
    /// composites have their own arms in the lane dispatch).
    #[inline]
    #[must_use]
    pub fn lane_kernel(&self) -> Option<LaneKernel<'_>> {
        match self {
            Bsdf::RoughConductor(m) => m.0.lanes().map(LaneKernel::Conductor),
            Bsdf::TorranceSparrow(m) => m.0.lanes().map(LaneKernel::Conductor),
            Bsdf::RoughPlastic(m) => m.lanes().map(LaneKernel::RoughPlastic),
            Bsdf::RoughDielectric(m) => m.lanes().map(LaneKernel::RoughDielectric),
            Bsdf::Conductor(m) => Some(LaneKernel::SmoothConductor(m)),
            Bsdf::Dielectric(m) => Some(LaneKernel::Dielectric(m)),
            Bsdf::ThinDielectric(m) => Some(LaneKernel::ThinDielectric(m)),
            Bsdf::Plastic(m) => m.lanes().map(LaneKernel::Plastic),
            Bsdf::Polarizer(m) => Some(LaneKernel::Polarizer(m)),
            Bsdf::Principled(m) => m.lanes().map(LaneKernel::Principled),
            _ => None,
        }
    }
}

/// Not inlined: one copy per lane type, called by the dispatch below wherever a model or a composite's
/// component runs its kernel. Inlined, every composite's lane code held a copy of every kernel for every
/// lane type (the test build's portable `F32x8` copies most of all: its build took twice as long once the
/// rough dielectric and every distribution of the rough plastic had kernels, 2026-12-05). A call per
/// packet costs nothing next to a kernel; the batch drivers still inline their model's own kernel.
impl LaneModel for LaneKernel<'_> {
    #[inline(never)]
    fn f_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> [R; 3] {
        match self {
            LaneKernel::Conductor(k) => k.f_lanes(wo, wi),
            LaneKernel::RoughPlastic(k) => k.f_lanes(wo, wi),
            LaneKernel::RoughDielectric(k) => k.f_lanes(wo, wi),
            LaneKernel::SmoothConductor(k) => k.f_lanes(wo, wi),
            LaneKernel::Dielectric(k) => k.f_lanes(wo, wi),
            LaneKernel::ThinDielectric(k) => k.f_lanes(wo, wi),
            LaneKernel::Plastic(k) => k.f_lanes(wo, wi),
            LaneKernel::Polarizer(k) => k.f_lanes(wo, wi),
            LaneKernel::Principled(k) => k.f_lanes(wo, wi),
        }
    }

    #[inline(never)]
    fn pdf_lanes<R: Real>(&self, wo: V3<R>, wi: V3<R>) -> R {
        match self {
            LaneKernel::Conductor(k) => k.pdf_lanes(wo, wi),
            LaneKernel::RoughPlastic(k) => k.pdf_lanes(wo, wi),
            LaneKernel::RoughDielectric(k) => k.pdf_lanes(wo, wi),
            LaneKernel::SmoothConductor(k) => k.pdf_lanes(wo, wi),
            LaneKernel::Dielectric(k) => k.pdf_lanes(wo, wi),
            LaneKernel::ThinDielectric(k) => k.pdf_lanes(wo, wi),
            LaneKernel::Plastic(k) => k.pdf_lanes(wo, wi),
            LaneKernel::Polarizer(k) => k.pdf_lanes(wo, wi),
            LaneKernel::Principled(k) => k.pdf_lanes(wo, wi),
        }
    }

    #[inline(never)]
    fn sample_lanes<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R) -> LaneSample<R> {
        match self {
            LaneKernel::Conductor(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::RoughPlastic(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::RoughDielectric(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::SmoothConductor(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::Dielectric(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::ThinDielectric(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::Plastic(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::Polarizer(k) => k.sample_lanes(wo, uc, ux, uy),
            LaneKernel::Principled(k) => k.sample_lanes(wo, uc, ux, uy),
        }
    }
}

/// Any model in lanes, for the lanes of a mask (the others' results are unspecified): the path tracer
/// calls it once for the lanes of a packet that share a model, and the batch drivers (through
/// `impl LaneModel for Bsdf`) for every model. Models with a kernel run it in lanes; the composites
/// (`twosided`, `mask`, `normalmap`, `sum`, `blendbsdf`) combine their components' lanes; a model that cannot vectorise
/// (a random walk, a table lookup per lane, a composite inside a composite) runs its single calls lane by
/// lane, inside this dispatch ([`each_lane`]) rather than in its callers.
impl Bsdf {
    /// f(ωo, ωi) in the lanes of `active`.
    #[inline(always)]
    pub fn f_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        if let Some(sum) = self.as_sum() {
            return sum.f_lanes_where(wo, wi, active);
        }
        match self {
            Bsdf::TwoSided(m) => m.f_lanes_where(wo, wi, active),
            Bsdf::Mask(m) => m.f_lanes_where(wo, wi, active),
            Bsdf::NormalMap(m) => m.f_lanes_where(wo, wi, active),
            _ => self.leaf_f(wo, wi, active),
        }
    }

    /// pdf(ωo, ωi) in the lanes of `active`.
    #[inline(always)]
    pub fn pdf_lanes_where<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        if let Some(sum) = self.as_sum() {
            return sum.pdf_lanes_where(wo, wi, active);
        }
        match self {
            Bsdf::TwoSided(m) => m.pdf_lanes_where(wo, wi, active),
            Bsdf::Mask(m) => m.pdf_lanes_where(wo, wi, active),
            Bsdf::NormalMap(m) => m.pdf_lanes_where(wo, wi, active),
            _ => self.leaf_pdf(wo, wi, active),
        }
    }

    /// sample(ωo, uc, (ux, uy)) in the lanes of `active` (no sample in the others).
    #[inline(always)]
    pub fn sample_lanes_where<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        if let Some(sum) = self.as_sum() {
            return sum.sample_lanes_where(wo, uc, ux, uy, active);
        }
        match self {
            Bsdf::TwoSided(m) => m.sample_lanes_where(wo, uc, ux, uy, active),
            Bsdf::Mask(m) => m.sample_lanes_where(wo, uc, ux, uy, active),
            Bsdf::NormalMap(m) => m.sample_lanes_where(wo, uc, ux, uy, active),
            _ => self.leaf_sample(wo, uc, ux, uy, active),
        }
    }

    /// The sum a `sum` or `blendbsdf` is (so that both run one copy of its lane code).
    #[inline(always)]
    fn as_sum(&self) -> Option<&super::Sum> {
        match self {
            Bsdf::Blend(m) => Some(m.mix()),
            Bsdf::Sum(m) => Some(m),
            _ => None,
        }
    }

    /// [`Self::f_lanes_where`] for a component of a composite: its kernel, or lane by lane (a composite
    /// nested in another composite runs lane by lane, so that the dispatch is not recursive and every
    /// kernel it reaches is inlined into the caller's lane code).
    #[inline(always)]
    pub(crate) fn leaf_f<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        match (self, self.lane_kernel()) {
            (Bsdf::Diffuse(m), _) => m.f_lanes(wo, wi),
            (_, Some(k)) => k.f_lanes(wo, wi),
            (_, None) => each_lane::f(self, wo, wi, active),
        }
    }

    /// [`Self::pdf_lanes_where`] for a component (see [`Self::leaf_f`]).
    #[inline(always)]
    pub(crate) fn leaf_pdf<R: Real>(&self, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        match (self, self.lane_kernel()) {
            (Bsdf::Diffuse(m), _) => m.pdf_lanes(wo, wi),
            (_, Some(k)) => k.pdf_lanes(wo, wi),
            (_, None) => each_lane::pdf(self, wo, wi, active),
        }
    }

    /// [`Self::sample_lanes_where`] for a component (see [`Self::leaf_f`]).
    #[inline(always)]
    pub(crate) fn leaf_sample<R: Real>(&self, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        let s = match (self, self.lane_kernel()) {
            (Bsdf::Diffuse(m), _) => m.sample_lanes(wo, uc, ux, uy),
            (_, Some(k)) => k.sample_lanes(wo, uc, ux, uy),
            (_, None) => return each_lane::sample(self, wo, uc, ux, uy, active),
        };
        LaneSample { valid: s.valid & active, ..s }
    }
}

// Every lane active (the drivers can run any model this way).
lane_model_where!(Bsdf);

/// A model's single calls, lane by lane, for the lanes of a mask (zeros and no sample in the others): how a
/// model that cannot vectorise runs in lanes. Up to [`each_lane::MAX_LANES`] lanes (the widest lane type).
pub mod each_lane {
    use super::{BsdfSample, LaneSample};
    use crate::bsdf::{Bsdf, BsdfModel};
    use crate::math::lanes::{channels, Real, V3};
    use crate::math::{Vec2, Vec3};
    use crate::spectrum::Rgb;

    /// The most lanes of any lane type (`Twice<Twice<Avx16>>`).
    pub const MAX_LANES: usize = 64;

    /// Lane `i` of `w`.
    #[inline(always)]
    fn row<R: Real>(w: V3<R>, i: usize) -> Vec3 {
        Vec3::new(w.x.lane(i), w.y.lane(i), w.z.lane(i))
    }

    /// The lanes set in `active`, in order.
    #[inline(always)]
    fn lanes<R: Real>(active: R::Mask) -> impl Iterator<Item = usize> {
        let mut bits = R::bitmask(active);
        std::iter::from_fn(move || {
            (bits != 0).then(|| {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                i
            })
        })
    }

    /// `m.f` in the lanes of `active`.
    #[inline(never)]
    pub fn f<R: Real>(m: &Bsdf, wo: V3<R>, wi: V3<R>, active: R::Mask) -> [R; 3] {
        debug_assert!(R::LANES <= MAX_LANES);
        let mut rows = [Rgb::ZERO; MAX_LANES];
        for i in lanes::<R>(active) {
            rows[i] = m.f(row(wo, i), row(wi, i));
        }
        channels!(|c| R::from_fn(|i| rows[i].0[c]))
    }

    /// `m.pdf` in the lanes of `active`.
    #[inline(never)]
    pub fn pdf<R: Real>(m: &Bsdf, wo: V3<R>, wi: V3<R>, active: R::Mask) -> R {
        debug_assert!(R::LANES <= MAX_LANES);
        let mut rows = [0.0f32; MAX_LANES];
        for i in lanes::<R>(active) {
            rows[i] = m.pdf(row(wo, i), row(wi, i));
        }
        R::from_fn(|i| rows[i])
    }

    /// `m.sample` in the lanes of `active`.
    #[inline(never)]
    pub fn sample<R: Real>(m: &Bsdf, wo: V3<R>, uc: R, ux: R, uy: R, active: R::Mask) -> LaneSample<R> {
        debug_assert!(R::LANES <= MAX_LANES);
        let mut rows: [Option<BsdfSample>; MAX_LANES] = [None; MAX_LANES];
        for i in lanes::<R>(active) {
            rows[i] = m.sample(row(wo, i), uc.lane(i), Vec2::new(ux.lane(i), uy.lane(i)));
        }
        let get = |f: &dyn Fn(&BsdfSample) -> f32| R::from_fn(|i| rows[i].as_ref().map_or(0.0, f));
        LaneSample {
            wi: V3::new(get(&|s| s.wi.x), get(&|s| s.wi.y), get(&|s| s.wi.z)),
            f: channels!(|c| get(&|s| s.f.0[c])),
            pdf: get(&|s| s.pdf),
            weight: channels!(|c| get(&|s| s.weight.0[c])),
            flags: get(&|s| s.flags.0 as f32),
            eta: get(&|s| s.eta),
            valid: R::from_fn(|i| if rows[i].is_some() { 1.0 } else { 0.0 }).gt(R::splat(0.5)),
        }
    }
}

/// [`LaneModel::f_lanes`] for one pair.
#[inline(always)]
pub fn f_one<K: LaneModel>(k: &K, wo: Vec3, wi: Vec3) -> Rgb {
    Rgb(k.f_lanes::<f32>(wo.into(), wi.into()))
}

/// [`LaneModel::pdf_lanes`] for one pair.
#[inline(always)]
pub fn pdf_one<K: LaneModel>(k: &K, wo: Vec3, wi: Vec3) -> f32 {
    k.pdf_lanes::<f32>(wo.into(), wi.into())
}

/// [`LaneModel::sample_lanes`] for one row.
#[inline(always)]
pub fn sample_one<K: LaneModel>(k: &K, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
    let s = k.sample_lanes::<f32>(wo.into(), uc, u.x, u.y);
    s.valid.then(|| BsdfSample {
        wi: s.wi.into(),
        f: Rgb(s.f),
        pdf: s.pdf,
        weight: Rgb(s.weight),
        flags: BsdfFlags(s.flags as u32),
        eta: s.eta,
    })
}

/// A check of a batch's rows made in the batch's own pass over them (the `_checked` batch methods of
/// [`BsdfModel`](super::BsdfModel)): every direction's squared length x² + y² + z², computed in `f32`, within
/// [`lo`, `hi`]; for `sample` also every number of `uc` and `u` within [0, 1]. NaN fails every test.
/// A caller that must reject rows by another measure (gonio's Python bindings: |w| within 10⁻³ of 1,
/// in f64) sets the band a little inside it, so that a batch that passes needs no closer look, and looks
/// row by row at a batch that fails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowCheck {
    pub lo: f32,
    pub hi: f32,
}

impl RowCheck {
    /// Where the direction `w` passes.
    #[inline(always)]
    #[must_use]
    pub fn direction<R: Real>(self, w: V3<R>) -> R::Mask {
        let l2 = w.dot(w);
        l2.ge(R::splat(self.lo)) & l2.le(R::splat(self.hi))
    }

    /// Where `v` is within [0, 1].
    #[inline(always)]
    #[must_use]
    pub fn unit<R: Real>(v: R) -> R::Mask {
        v.ge(R::splat(0.0)) & v.le(R::splat(1.0))
    }

    /// Whether every direction of `w` passes.
    #[must_use]
    pub fn directions(self, w: &[Vec3]) -> bool {
        w.iter().fold(true, |ok, &w| ok & self.direction(V3::from(w)))
    }

    /// Whether every number of `v` is within [0, 1].
    #[must_use]
    pub fn unit_numbers(v: &[f32]) -> bool {
        v.iter().fold(true, |ok, &v| ok & Self::unit(v))
    }

    /// Whether both numbers of every pair of `v` are within [0, 1].
    #[must_use]
    pub fn unit_pairs(v: &[Vec2]) -> bool {
        v.iter().fold(true, |ok, &v| ok & Self::unit(v.x) & Self::unit(v.y))
    }
}

/// No lane set.
#[inline(always)]
fn none<R: Real>() -> R::Mask {
    R::splat(1.0).lt(R::splat(0.0))
}

/// Rows of three numbers (`Vec3`, `Rgb`) as `[f32; 3]`s, to be overwritten.
#[inline(always)]
fn triples<T: Triple>(rows: &mut [T]) -> &mut [[f32; 3]] {
    // SAFETY: `Triple` types are three `f32`s laid out as `[f32; 3]` (size 12, alignment 4).
    unsafe { std::slice::from_raw_parts_mut(rows.as_mut_ptr().cast::<[f32; 3]>(), rows.len()) }
}

/// # Safety
/// Implementors are laid out exactly as `[f32; 3]`.
unsafe trait Triple {}
// SAFETY: `glam::Vec3` is `#[repr(C)]` of x, y, z; `Rgb` is `#[repr(transparent)]` over `[f32; 3]`.
unsafe impl Triple for Vec3 {}
unsafe impl Triple for Rgb {}
const _: () = assert!(std::mem::size_of::<Vec3>() == 12 && std::mem::align_of::<Vec3>() == 4);
const _: () = assert!(std::mem::size_of::<Rgb>() == 12 && std::mem::align_of::<Rgb>() == 4);

/// Defines `$name`, which runs `$generic` on the widest lanes the CPU has: 64 (four `Avx16` registers
/// whose operations alternate, `Twice<Twice<Avx16>>`: see `math::twice` for why, AVX-512F), 8 (`Avx8`,
/// AVX2 + FMA), each inside a
/// function compiled for those features (so that every lane operation is inlined as its instruction,
/// whoever calls the driver), else [`F32x8`]. `CHECK` selects whether the rows are tested against the
/// [`RowCheck`] (the result: whether all passed; true when not checked).
macro_rules! driver {
    ($name:ident => $generic:ident($($arg:ident: $ty:ty),*)) => {
        #[inline(always)]
        fn $name<K: LaneModel, const CHECK: bool>(k: &K, $($arg: $ty),*) -> bool {
            #[cfg(all(target_arch = "x86_64", gonio_avx512))]
            {
                #[target_feature(enable = "avx512f,avx2,fma")]
                unsafe fn with_avx512<K: LaneModel, const CHECK: bool>(k: &K, $($arg: $ty),*) -> bool {
                    $generic::<crate::math::twice::Twice<crate::math::twice::Twice<crate::math::avx512::Avx16>>, K, CHECK>(k, $($arg),*)
                }
                if crate::math::avx512::detected() {
                    // SAFETY: the CPU has the features `with_avx512` is compiled for (checked just above);
                    // `Avx16` values exist only inside it (see `math::avx512`).
                    return unsafe { with_avx512::<K, CHECK>(k, $($arg),*) };
                }
            }
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                unsafe fn with_avx2<K: LaneModel, const CHECK: bool>(k: &K, $($arg: $ty),*) -> bool {
                    $generic::<crate::math::avx2::Avx8, K, CHECK>(k, $($arg),*)
                }
                if crate::math::avx2::detected() {
                    // SAFETY: as above, for AVX2 + FMA and `Avx8`.
                    return unsafe { with_avx2::<K, CHECK>(k, $($arg),*) };
                }
            }
            $generic::<F32x8, K, CHECK>(k, $($arg),*)
        }
    };
}

/// An unused check (the unchecked drivers).
const UNCHECKED: RowCheck = RowCheck { lo: 0.0, hi: 0.0 };

/// `out[k] = f(wo[k], wi[k])` for `k` below the shortest length, a register of rows at a time.
#[inline(always)]
pub fn f_rows<K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb]) {
    f_rows_on::<K, false>(k, wo, wi, out, UNCHECKED);
}

/// [`f_rows`], and whether every direction passes `check`.
#[inline(always)]
pub fn f_rows_checked<K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb], check: RowCheck) -> bool {
    f_rows_on::<K, true>(k, wo, wi, out, check)
}

driver!(f_rows_on => f_rows_in(wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb], check: RowCheck));

#[inline(always)]
fn f_rows_in<R: Rows, K: LaneModel, const CHECK: bool>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb], check: RowCheck) -> bool {
    let n = wo.len().min(wi.len()).min(out.len());
    let full = n - n % R::LANES;
    let mut bad = none::<R>();
    for ((o, i), r) in
        wo[..full].chunks_exact(R::LANES).zip(wi[..full].chunks_exact(R::LANES)).zip(triples(&mut out[..full]).chunks_exact_mut(R::LANES))
    {
        let (o, i) = (R::load3(o), R::load3(i));
        if CHECK {
            bad = bad | !(check.direction(o) & check.direction(i));
        }
        let [r0, r1, r2] = k.f_lanes(o, i);
        R::store3(r0, r1, r2, r);
    }
    let mut ok = !R::any(bad);
    for j in full..n {
        if CHECK {
            ok &= check.direction(V3::from(wo[j])) & check.direction(V3::from(wi[j]));
        }
        out[j] = f_one(k, wo[j], wi[j]);
    }
    ok
}

/// `out[k] = pdf(wo[k], wi[k])` for `k` below the shortest length, a register of rows at a time.
#[inline(always)]
pub fn pdf_rows<K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [f32]) {
    pdf_rows_on::<K, false>(k, wo, wi, out, UNCHECKED);
}

/// [`pdf_rows`], and whether every direction passes `check`.
#[inline(always)]
pub fn pdf_rows_checked<K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [f32], check: RowCheck) -> bool {
    pdf_rows_on::<K, true>(k, wo, wi, out, check)
}

driver!(pdf_rows_on => pdf_rows_in(wo: &[Vec3], wi: &[Vec3], out: &mut [f32], check: RowCheck));

#[inline(always)]
fn pdf_rows_in<R: Rows, K: LaneModel, const CHECK: bool>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [f32], check: RowCheck) -> bool {
    let n = wo.len().min(wi.len()).min(out.len());
    let full = n - n % R::LANES;
    let mut bad = none::<R>();
    for ((o, i), r) in wo[..full].chunks_exact(R::LANES).zip(wi[..full].chunks_exact(R::LANES)).zip(out[..full].chunks_exact_mut(R::LANES))
    {
        let (o, i) = (R::load3(o), R::load3(i));
        if CHECK {
            bad = bad | !(check.direction(o) & check.direction(i));
        }
        k.pdf_lanes(o, i).store(r);
    }
    let mut ok = !R::any(bad);
    for j in full..n {
        if CHECK {
            ok &= check.direction(V3::from(wo[j])) & check.direction(V3::from(wi[j]));
        }
        out[j] = pdf_one(k, wo[j], wi[j]);
    }
    ok
}

/// Row `k` of `out` = sample(wo[k], uc[k], u[k]) (zeros and `valid = false` where `None`), for `k` below
/// the shortest length, a register of rows at a time.
#[inline(always)]
pub fn sample_rows<K: LaneModel>(k: &K, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>) {
    sample_rows_on::<K, false>(k, wo, uc, u, out, UNCHECKED);
}

/// [`sample_rows`], and whether every row passes `check` (`wo` a direction, `uc` and `u` in [0, 1]).
#[inline(always)]
pub fn sample_rows_checked<K: LaneModel>(k: &K, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>, check: RowCheck) -> bool {
    sample_rows_on::<K, true>(k, wo, uc, u, out, check)
}

driver!(sample_rows_on => sample_rows_in(wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>, check: RowCheck));

#[inline(always)]
fn sample_rows_in<R: Rows, K: LaneModel, const CHECK: bool>(
    k: &K,
    wo: &[Vec3],
    uc: &[f32],
    u: &[Vec2],
    out: &mut SampleColumns<'_>,
    check: RowCheck,
) -> bool {
    let n = out.rows(wo, uc, u);
    let full = n - n % R::LANES;
    // Zipped chunks of a register each: no bounds checks in the loop.
    let inputs = wo[..full].chunks_exact(R::LANES).zip(uc[..full].chunks_exact(R::LANES)).zip(u[..full].chunks_exact(R::LANES));
    let vectors = triples(&mut out.wi[..full])
        .chunks_exact_mut(R::LANES)
        .zip(triples(&mut out.f[..full]).chunks_exact_mut(R::LANES))
        .zip(triples(&mut out.weight[..full]).chunks_exact_mut(R::LANES));
    let numbers = out.pdf[..full]
        .chunks_exact_mut(R::LANES)
        .zip(out.flags[..full].chunks_exact_mut(R::LANES))
        .zip(out.eta[..full].chunks_exact_mut(R::LANES))
        .zip(out.valid[..full].chunks_exact_mut(R::LANES));
    let mut bad = none::<R>();
    for (((wo, uc), u), (((wi_out, f_out), weight_out), (((pdf_out, flags_out), eta_out), valid_out))) in inputs.zip(vectors.zip(numbers)) {
        let (wo, uc, (ux, uy)) = (R::load3(wo), R::load(uc), R::load2(u));
        if CHECK {
            bad = bad | !(check.direction(wo) & RowCheck::unit(uc) & RowCheck::unit(ux) & RowCheck::unit(uy));
        }
        let s = k.sample_lanes(wo, uc, ux, uy);
        // Invalid lanes are zero in every field.
        let keep = |v: R| R::select(s.valid, v, R::splat(0.0));
        R::store3(keep(s.wi.x), keep(s.wi.y), keep(s.wi.z), wi_out);
        R::store3(keep(s.f[0]), keep(s.f[1]), keep(s.f[2]), f_out);
        R::store3(keep(s.weight[0]), keep(s.weight[1]), keep(s.weight[2]), weight_out);
        keep(s.pdf).store(pdf_out);
        keep(s.flags).store_u32(flags_out);
        keep(s.eta).store(eta_out);
        R::store_mask(s.valid, valid_out);
    }
    let mut ok = !R::any(bad);
    for j in full..n {
        if CHECK {
            ok &= check.direction(V3::from(wo[j])) & RowCheck::unit(uc[j]) & RowCheck::unit(u[j].x) & RowCheck::unit(u[j].y);
        }
        out.set(j, sample_one(k, wo[j], uc[j], u[j]));
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::BsdfModel;
    use crate::math::simd::Float8;
    use crate::sampling::Pcg32;

    /// A model's [`LaneKernel`] on the renderer's eight lanes gives in every lane what the model's single
    /// calls give, bit for bit (rough conductors of every distribution — GGX, Beckmann, Torrance–Sparrow's
    /// Blinn — isotropic and anisotropic, visible and D·cos sampling; rough plastics and rough dielectrics
    /// of both distributions; smooth conductors, dielectrics, thin dielectrics and plastics; from both
    /// sides: the directions cover the sphere); models without a kernel in their configuration have none.
    #[test]
    fn lane_kernels_equal_single_calls() {
        let with = [
            r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, "material": "Au"}"#,
            r#"{"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.05, "alpha_v": 0.4}"#,
            r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.5, "sample_visible": false, "material": "Cu"}"#,
            r#"{"type": "roughconductor"}"#,
            r#"{"type": "roughconductor", "alpha": 0.6, "material": "Au"}"#,
            r#"{"type": "roughconductor", "alpha_u": 0.02, "alpha_v": 0.5, "material": "Al"}"#,
            r#"{"type": "roughconductor", "alpha_u": 0.4, "alpha_v": 0.05, "sample_visible": false}"#,
            r#"{"type": "roughconductor", "alpha": 0.001}"#,
            r#"{"type": "torrance_sparrow"}"#,
            r#"{"type": "torrance_sparrow", "distribution": "beckmann", "alpha": 0.3, "shadowing": "smith_correlated"}"#,
            r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.1, "diffuse_reflectance": [0.7, 0.1, 0.1]}"#,
            r#"{"type": "roughplastic"}"#,
            r#"{"type": "roughplastic", "alpha": 0.4, "sample_visible": false, "nonlinear": true}"#,
            r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "int_ior": 1.0, "ext_ior": 1.5}"#,
            r#"{"type": "roughdielectric"}"#,
            r#"{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3, "int_ior": 1.0, "ext_ior": 1.5}"#,
            r#"{"type": "roughdielectric", "distribution": "ggx", "alpha_u": 0.05, "alpha_v": 0.5, "specular_transmittance": [0.2, 0.7, 0.9]}"#,
            r#"{"type": "roughdielectric", "alpha": 0.6, "sample_visible": false, "int_ior": "diamond"}"#,
            r#"{"type": "conductor", "material": "Al"}"#,
            r#"{"type": "conductor", "specular_reflectance": [0.2, 0.5, 1.0]}"#,
            r#"{"type": "dielectric"}"#,
            r#"{"type": "dielectric", "int_ior": 1.0, "ext_ior": 1.5, "specular_transmittance": [0.2, 0.7, 0.9]}"#,
            r#"{"type": "dielectric", "int_ior": 1.5, "fresnel": false}"#,
            r#"{"type": "thindielectric"}"#,
            r#"{"type": "thindielectric", "int_ior": 2.4, "specular_reflectance": [1, 0.5, 0.2]}"#,
            r#"{"type": "plastic"}"#,
            r#"{"type": "plastic", "diffuse_reflectance": [0.9, 0.4, 0.1], "nonlinear": true, "specular_reflectance": 0.5}"#,
        ];
        let without = [
            r#"{"type": "roughconductor", "alpha": 0.2, "energy_compensation": true}"#,
            r#"{"type": "roughdielectric", "alpha": 0.2, "energy_compensation": true}"#,
            r#"{"type": "roughplastic", "alpha": 0.2, "energy_compensation": true}"#,
            r#"{"type": "diffuse"}"#,
        ];
        for spec in without {
            assert!(Bsdf::from_json(spec).unwrap().lane_kernel().is_none(), "{spec}");
        }
        let mut rng = Pcg32::new(1, 2);
        let dir = |rng: &mut Pcg32| crate::sampling::warp::sample_uniform_sphere(rng.next_vec2());
        for spec in with {
            let b = Bsdf::from_json(spec).unwrap();
            let k = b.lane_kernel().expect("a kernel");
            for _ in 0..64 {
                let (wo, wi): (Vec<Vec3>, Vec<Vec3>) = (0..8).map(|_| (dir(&mut rng), dir(&mut rng))).unzip();
                let (uc, ux, uy) =
                    (Float8::from_fn(|_| rng.next_f32()), Float8::from_fn(|_| rng.next_f32()), Float8::from_fn(|_| rng.next_f32()));
                let lanes = |v: &[Vec3]| V3::new(Float8::from_fn(|i| v[i].x), Float8::from_fn(|i| v[i].y), Float8::from_fn(|i| v[i].z));
                let (wo8, wi8) = (lanes(&wo), lanes(&wi));
                let (f, pdf, s) = (k.f_lanes(wo8, wi8), k.pdf_lanes(wo8, wi8), k.sample_lanes(wo8, uc, ux, uy));
                for i in 0..8 {
                    let want = b.f(wo[i], wi[i]);
                    assert_eq!(f.map(|c| c.lane(i).to_bits()), want.0.map(f32::to_bits), "{spec}: f");
                    assert_eq!(pdf.lane(i).to_bits(), b.pdf(wo[i], wi[i]).to_bits(), "{spec}: pdf");
                    let one = b.sample(wo[i], uc.lane(i), Vec2::new(ux.lane(i), uy.lane(i)));
                    assert_eq!(s.valid.lane(i), one.is_some(), "{spec}: sample");
                    if let Some(one) = one {
                        assert_eq!([s.wi.x.lane(i), s.wi.y.lane(i), s.wi.z.lane(i)].map(f32::to_bits), one.wi.to_array().map(f32::to_bits));
                        assert_eq!(s.weight.map(|c| c.lane(i).to_bits()), one.weight.0.map(f32::to_bits));
                        assert_eq!((s.pdf.lane(i).to_bits(), s.eta.lane(i).to_bits()), (one.pdf.to_bits(), one.eta.to_bits()));
                        assert_eq!(s.flags.lane(i) as u32, one.flags.0);
                    }
                }
            }
        }
    }
}
