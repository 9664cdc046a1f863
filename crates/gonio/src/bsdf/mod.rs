//! Reflection models. Every model is a small value type implementing [`BsdfModel`]
//! (`flags`, `f`, `sample`, `pdf`), collected in the closed enum [`Bsdf`].
//!
//! # Conventions
//! - `wo` (towards the viewer) and `wi` (towards the light) point *away* from the surface, are unit
//!   length and are expressed in the local shading frame, normal = +z.
//! - `f(wo, wi)` is the BSDF value in sr⁻¹ **without** the cosine. Mitsuba's `eval` includes it:
//!   `mitsuba.eval(si.wi = a, wo = b) == gonio f(a, b) · |cos θ(b)|`.
//! - `sample` returns `wi`, the solid-angle `pdf` (for a delta lobe: the discrete probability of choosing
//!   it, with [`BsdfFlags::DELTA`] set), and `weight = f · |cos θi| / pdf`.
//! - Transport is radiance transport: refraction scales `f` by (ηᵢ/ηₜ)², where ηᵢ is the index on the
//!   side of `wo` and ηₜ the index on the side of `wi` (the path's incident and transmitted media;
//!   [`BsdfSample::eta`] is ηₜ/ηᵢ). Radiance is η²-denser in the denser medium; importance (adjoint)
//!   transport omits the factor. gonio traces radiance only for now.
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::{Vec2, Vec3};
//! let bsdf = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.5}"#).unwrap();
//! let wo = Vec3::new(0.0, 0.6, 0.8);
//! let s = bsdf.sample(wo, 0.3, Vec2::new(0.2, 0.7)).unwrap();
//! // Lambertian: f = ρ/π and the cosine-weighted sample has weight ρ.
//! assert!((s.weight.r() - 0.5).abs() < 1e-5);
//! assert!((bsdf.f(wo, s.wi).g() - 0.5 / std::f32::consts::PI).abs() < 1e-6);
//! ```

/// Implements [`BsdfModel`] for a type that is one model under another name (a plugin over a shared core)
/// by forwarding all four methods to the field given: `forward_bsdf_model!(RoughConductor => 0);`.
macro_rules! forward_bsdf_model {
    ($ty:ty => $field:tt) => {
        impl $crate::bsdf::BsdfModel for $ty {
            #[inline]
            fn flags(&self) -> $crate::bsdf::BsdfFlags {
                self.$field.flags()
            }
            #[inline]
            fn f(&self, wo: $crate::math::Vec3, wi: $crate::math::Vec3) -> $crate::spectrum::Rgb {
                self.$field.f(wo, wi)
            }
            #[inline]
            fn sample(&self, wo: $crate::math::Vec3, uc: f32, u: $crate::math::Vec2) -> Option<$crate::bsdf::BsdfSample> {
                self.$field.sample(wo, uc, u)
            }
            #[inline]
            fn pdf(&self, wo: $crate::math::Vec3, wi: $crate::math::Vec3) -> f32 {
                self.$field.pdf(wo, wi)
            }
            #[inline(always)]
            fn f_batch(&self, wo: &[$crate::math::Vec3], wi: &[$crate::math::Vec3], out: &mut [$crate::spectrum::Rgb]) {
                self.$field.f_batch(wo, wi, out)
            }
            #[inline(always)]
            fn pdf_batch(&self, wo: &[$crate::math::Vec3], wi: &[$crate::math::Vec3], out: &mut [f32]) {
                self.$field.pdf_batch(wo, wi, out)
            }
            #[inline(always)]
            fn sample_batch(
                &self,
                wo: &[$crate::math::Vec3],
                uc: &[f32],
                u: &[$crate::math::Vec2],
                out: &mut $crate::bsdf::SampleColumns<'_>,
            ) {
                self.$field.sample_batch(wo, uc, u, out)
            }
            #[inline(always)]
            fn f_batch_checked(
                &self,
                wo: &[$crate::math::Vec3],
                wi: &[$crate::math::Vec3],
                out: &mut [$crate::spectrum::Rgb],
                check: $crate::bsdf::RowCheck,
            ) -> bool {
                self.$field.f_batch_checked(wo, wi, out, check)
            }
            #[inline(always)]
            fn pdf_batch_checked(
                &self,
                wo: &[$crate::math::Vec3],
                wi: &[$crate::math::Vec3],
                out: &mut [f32],
                check: $crate::bsdf::RowCheck,
            ) -> bool {
                self.$field.pdf_batch_checked(wo, wi, out, check)
            }
            #[inline(always)]
            fn sample_batch_checked(
                &self,
                wo: &[$crate::math::Vec3],
                uc: &[f32],
                u: &[$crate::math::Vec2],
                out: &mut $crate::bsdf::SampleColumns<'_>,
                check: $crate::bsdf::RowCheck,
            ) -> bool {
                self.$field.sample_batch_checked(wo, uc, u, out, check)
            }
        }
    };
}

/// `impl LaneModel` for a model whose lane code takes a mask of active lanes (`f_lanes_where`,
/// `pdf_lanes_where`, `sample_lanes_where`: [`Bsdf`] and the composites): the same with every lane active.
macro_rules! lane_model_where {
    ($ty:ty) => {
        impl $crate::bsdf::lanes::LaneModel for $ty {
            #[inline(always)]
            fn f_lanes<R: $crate::math::lanes::Real>(&self, wo: $crate::math::lanes::V3<R>, wi: $crate::math::lanes::V3<R>) -> [R; 3] {
                self.f_lanes_where(wo, wi, $crate::bsdf::lanes::all::<R>())
            }

            #[inline(always)]
            fn pdf_lanes<R: $crate::math::lanes::Real>(&self, wo: $crate::math::lanes::V3<R>, wi: $crate::math::lanes::V3<R>) -> R {
                self.pdf_lanes_where(wo, wi, $crate::bsdf::lanes::all::<R>())
            }

            #[inline(always)]
            fn sample_lanes<R: $crate::math::lanes::Real>(
                &self,
                wo: $crate::math::lanes::V3<R>,
                uc: R,
                ux: R,
                uy: R,
            ) -> $crate::bsdf::lanes::LaneSample<R> {
                self.sample_lanes_where(wo, uc, ux, uy, $crate::bsdf::lanes::all::<R>())
            }
        }
    };
}

/// The batch methods (plain and `_checked`) of a model with a SIMD kernel ([`lanes::LaneModel`]) for some configurations:
/// `lane_batch_methods!(kernel);` inside its `impl BsdfModel`, where `self.kernel()` returns `Some(k)` for a
/// configuration `k` runs (`Option<impl LaneModel>`) and `None` for the others, which take the per-pair loops
/// ([`f_each`] and friends). A model that is its own lane code in every configuration (the composites, the
/// smooth conductor and dielectric) returns `Some(self)`.
macro_rules! lane_batch_methods {
    ($kernel:ident) => {
        #[inline(always)]
        fn f_batch(&self, wo: &[$crate::math::Vec3], wi: &[$crate::math::Vec3], out: &mut [$crate::spectrum::Rgb]) {
            match self.$kernel() {
                Some(k) => $crate::bsdf::lanes::f_rows(&k, wo, wi, out),
                None => $crate::bsdf::f_each(self, wo, wi, out),
            }
        }
        #[inline(always)]
        fn pdf_batch(&self, wo: &[$crate::math::Vec3], wi: &[$crate::math::Vec3], out: &mut [f32]) {
            match self.$kernel() {
                Some(k) => $crate::bsdf::lanes::pdf_rows(&k, wo, wi, out),
                None => $crate::bsdf::pdf_each(self, wo, wi, out),
            }
        }
        #[inline(always)]
        fn sample_batch(&self, wo: &[$crate::math::Vec3], uc: &[f32], u: &[$crate::math::Vec2], out: &mut $crate::bsdf::SampleColumns<'_>) {
            match self.$kernel() {
                Some(k) => $crate::bsdf::lanes::sample_rows(&k, wo, uc, u, out),
                None => $crate::bsdf::sample_each(self, wo, uc, u, out),
            }
        }
        #[inline(always)]
        fn f_batch_checked(
            &self,
            wo: &[$crate::math::Vec3],
            wi: &[$crate::math::Vec3],
            out: &mut [$crate::spectrum::Rgb],
            check: $crate::bsdf::RowCheck,
        ) -> bool {
            match self.$kernel() {
                Some(k) => $crate::bsdf::lanes::f_rows_checked(&k, wo, wi, out, check),
                None => {
                    $crate::bsdf::f_each(self, wo, wi, out);
                    check.directions(wo) & check.directions(wi)
                }
            }
        }
        #[inline(always)]
        fn pdf_batch_checked(
            &self,
            wo: &[$crate::math::Vec3],
            wi: &[$crate::math::Vec3],
            out: &mut [f32],
            check: $crate::bsdf::RowCheck,
        ) -> bool {
            match self.$kernel() {
                Some(k) => $crate::bsdf::lanes::pdf_rows_checked(&k, wo, wi, out, check),
                None => {
                    $crate::bsdf::pdf_each(self, wo, wi, out);
                    check.directions(wo) & check.directions(wi)
                }
            }
        }
        #[inline(always)]
        fn sample_batch_checked(
            &self,
            wo: &[$crate::math::Vec3],
            uc: &[f32],
            u: &[$crate::math::Vec2],
            out: &mut $crate::bsdf::SampleColumns<'_>,
            check: $crate::bsdf::RowCheck,
        ) -> bool {
            match self.$kernel() {
                Some(k) => $crate::bsdf::lanes::sample_rows_checked(&k, wo, uc, u, out, check),
                None => {
                    $crate::bsdf::sample_each(self, wo, uc, u, out);
                    check.directions(wo) & $crate::bsdf::RowCheck::unit_numbers(uc) & $crate::bsdf::RowCheck::unit_pairs(u)
                }
            }
        }
    };
}

/// `enum $kernel { Ggx($lobe<Ggx>), Beckmann($lobe<Beckmann>), Blinn($lobe<Blinn>) }`: a model's lobe,
/// written once over the distribution, for the distribution a model has — the kind matched once per
/// call (`on_distribution!(d, |d| Lobe { .. }.into())` builds it), the lobe's code monomorphised per kind.
/// The microfacet models' kernels are these (`ConductorKernel`, `DielectricKernel`, `PlasticKernel`).
macro_rules! distribution_kernel {
    ($(#[$doc:meta])* $kernel:ident $(<$lt:lifetime>)?, $lobe:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug)]
        pub enum $kernel$(<$lt>)? {
            Ggx($lobe<$($lt,)? $crate::microfacet::Ggx>),
            Beckmann($lobe<$($lt,)? $crate::microfacet::Beckmann>),
            Blinn($lobe<$($lt,)? $crate::microfacet::Blinn>),
        }

        impl$(<$lt>)? From<$lobe<$($lt,)? $crate::microfacet::Ggx>> for $kernel$(<$lt>)? {
            #[inline(always)]
            fn from(k: $lobe<$($lt,)? $crate::microfacet::Ggx>) -> Self {
                $kernel::Ggx(k)
            }
        }

        impl$(<$lt>)? From<$lobe<$($lt,)? $crate::microfacet::Beckmann>> for $kernel$(<$lt>)? {
            #[inline(always)]
            fn from(k: $lobe<$($lt,)? $crate::microfacet::Beckmann>) -> Self {
                $kernel::Beckmann(k)
            }
        }

        impl$(<$lt>)? From<$lobe<$($lt,)? $crate::microfacet::Blinn>> for $kernel$(<$lt>)? {
            #[inline(always)]
            fn from(k: $lobe<$($lt,)? $crate::microfacet::Blinn>) -> Self {
                $kernel::Blinn(k)
            }
        }

        impl$(<$lt>)? $crate::bsdf::lanes::LaneModel for $kernel$(<$lt>)? {
            #[inline(always)]
            fn f_lanes<R: $crate::math::lanes::Real>(&self, wo: $crate::math::lanes::V3<R>, wi: $crate::math::lanes::V3<R>) -> [R; 3] {
                match self {
                    $kernel::Ggx(k) => k.f_lanes(wo, wi),
                    $kernel::Beckmann(k) => k.f_lanes(wo, wi),
                    $kernel::Blinn(k) => k.f_lanes(wo, wi),
                }
            }

            #[inline(always)]
            fn pdf_lanes<R: $crate::math::lanes::Real>(&self, wo: $crate::math::lanes::V3<R>, wi: $crate::math::lanes::V3<R>) -> R {
                match self {
                    $kernel::Ggx(k) => k.pdf_lanes(wo, wi),
                    $kernel::Beckmann(k) => k.pdf_lanes(wo, wi),
                    $kernel::Blinn(k) => k.pdf_lanes(wo, wi),
                }
            }

            #[inline(always)]
            fn sample_lanes<R: $crate::math::lanes::Real>(
                &self,
                wo: $crate::math::lanes::V3<R>,
                uc: R,
                ux: R,
                uy: R,
            ) -> $crate::bsdf::lanes::LaneSample<R> {
                match self {
                    $kernel::Ggx(k) => k.sample_lanes(wo, uc, ux, uy),
                    $kernel::Beckmann(k) => k.sample_lanes(wo, uc, ux, uy),
                    $kernel::Blinn(k) => k.sample_lanes(wo, uc, ux, uy),
                }
            }
        }
    };
}

pub mod ashikhmin_shirley;
pub mod blend;
pub mod blinn_phong;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod energy_compensation;
pub mod glossy_mix;
pub mod lanes;
pub mod layered;
pub mod mask;
pub mod measured;
pub mod merl;
pub mod normal_map;
pub mod oren_nayar;
pub mod phong;
pub mod plastic;
pub mod polarizer;
pub mod principled;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod rough_plastic;
pub mod sum;
pub mod thin_dielectric;
pub mod torrance_sparrow;
pub mod twosided;

use crate::error::{Error, Result};
use crate::math::param::{PerLane, PER_LANE};
use crate::math::{Vec2, Vec3};
use crate::microfacet::MicrofacetDistribution;
use crate::props::Props;
use crate::spectrum::Rgb;
use rough_conductor::textured_roughness;

pub use ashikhmin_shirley::AshikhminShirley;
pub use blend::BlendBsdf;
pub use blinn_phong::BlinnPhong;
pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use lanes::{PerLaneKernel, RowCheck};
pub use layered::Layered;
pub use mask::Mask;
pub use measured::Measured;
pub use merl::Merl;
pub use normal_map::NormalMap;
pub use oren_nayar::OrenNayar;
pub use phong::Phong;
pub use plastic::Plastic;
pub use polarizer::Polarizer;
pub use principled::Principled;
pub use rough_conductor::{MicrofacetConductor, RoughConductor};
pub use rough_dielectric::RoughDielectric;
pub use rough_plastic::RoughPlastic;
pub use sum::Sum;
pub use thin_dielectric::ThinDielectric;
pub use torrance_sparrow::TorranceSparrow;
pub use twosided::TwoSided;

/// What kind of scattering a model (or one sampled lobe) does. A small bit set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BsdfFlags(pub u32);

impl BsdfFlags {
    pub const NONE: BsdfFlags = BsdfFlags(0);
    /// Scatters into the hemisphere of `wo`.
    pub const REFLECTION: BsdfFlags = BsdfFlags(1);
    /// Scatters into the opposite hemisphere.
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(2);
    /// A smooth lobe spread over the hemisphere.
    pub const DIFFUSE: BsdfFlags = BsdfFlags(4);
    /// A peaked but finite lobe.
    pub const GLOSSY: BsdfFlags = BsdfFlags(8);
    /// A Dirac delta: `f` and `pdf` are zero for every pair of directions; only `sample` finds it.
    pub const DELTA: BsdfFlags = BsdfFlags(16);

    pub const DIFFUSE_REFLECTION: BsdfFlags = BsdfFlags(1 | 4);
    pub const GLOSSY_REFLECTION: BsdfFlags = BsdfFlags(1 | 8);
    pub const DELTA_REFLECTION: BsdfFlags = BsdfFlags(1 | 16);
    pub const DELTA_TRANSMISSION: BsdfFlags = BsdfFlags(2 | 16);

    #[inline]
    #[must_use]
    pub const fn contains(self, other: BsdfFlags) -> bool {
        self.0 & other.0 == other.0
    }

    #[inline]
    #[must_use]
    pub const fn intersects(self, other: BsdfFlags) -> bool {
        self.0 & other.0 != 0
    }

    #[inline]
    #[must_use]
    pub const fn union(self, other: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | other.0)
    }

    /// Whether the model has any delta lobe.
    #[inline]
    #[must_use]
    pub const fn has_delta(self) -> bool {
        self.intersects(BsdfFlags::DELTA)
    }

    /// Whether the model has any lobe that `f` and `pdf` can see.
    #[inline]
    #[must_use]
    pub const fn has_smooth(self) -> bool {
        self.intersects(BsdfFlags(4 | 8))
    }

    /// Names of the set bits, e.g. `"reflection|delta"`.
    #[must_use]
    pub fn describe(self) -> String {
        let names = ["reflection", "transmission", "diffuse", "glossy", "delta"];
        let parts: Vec<&str> = names.iter().enumerate().filter(|(i, _)| self.0 & (1 << i) != 0).map(|(_, n)| *n).collect();
        if parts.is_empty() {
            "none".into()
        } else {
            parts.join("|")
        }
    }
}

impl std::ops::BitOr for BsdfFlags {
    type Output = BsdfFlags;
    fn bitor(self, o: BsdfFlags) -> BsdfFlags {
        self.union(o)
    }
}

/// One sampled scattering direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction towards the light, local frame, unit length.
    pub wi: Vec3,
    /// `f(wo, wi)`; for a delta lobe the coefficient of the Dirac delta (weight · pdf / |cos θi|).
    pub f: Rgb,
    /// Solid-angle density of `wi`; for a delta lobe the discrete probability of having chosen it.
    pub pdf: f32,
    /// `f · |cos θi| / pdf`: the Monte Carlo weight of this sample.
    pub weight: Rgb,
    /// The lobe that was sampled (reflection or transmission; diffuse, glossy or delta).
    pub flags: BsdfFlags,
    /// Relative index of refraction ηₜ/ηᵢ along the sampled path (1 for reflection).
    pub eta: f32,
}

impl BsdfSample {
    /// A sample of a smooth lobe: `weight` is derived from `f` and `pdf`.
    #[inline(always)]
    #[must_use]
    pub fn smooth(wi: Vec3, f: Rgb, pdf: f32, flags: BsdfFlags, eta: f32) -> Option<Self> {
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample { wi, f, pdf, weight: f * (wi.z.abs() / pdf), flags, eta })
    }

    /// A sample of a delta lobe chosen with probability `prob`, carrying total energy `value`
    /// (the weight is `value / prob`, and `f` is the delta's coefficient `value / |cos θi|`).
    #[inline]
    #[must_use]
    pub fn delta(wi: Vec3, value: Rgb, prob: f32, flags: BsdfFlags, eta: f32) -> Option<Self> {
        if !(prob > 0.0) {
            return None;
        }
        let cos = wi.z.abs();
        // On (or within f32 overflow of) the horizon the delta's coefficient is unbounded; report 0 rather
        // than Inf (2026-11: f is informational for delta lobes, the weight is what integrators use).
        let f = value.map(|v| if cos > 0.0 && (v / cos).is_finite() { v / cos } else { 0.0 });
        Some(BsdfSample { wi, f, pdf: prob, weight: value / prob, flags: flags.union(BsdfFlags::DELTA), eta })
    }
}

/// The interface every reflection model implements.
pub trait BsdfModel {
    /// The lobes this model has.
    fn flags(&self) -> BsdfFlags;

    /// The BSDF value f(wo, wi) in sr⁻¹, without the cosine. Zero for delta lobes.
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb;

    /// Sample `wi` given `wo`, a 1-D sample `uc` (lobe selection) and a 2-D sample `u` (direction).
    /// `None` when the model does not scatter from `wo`.
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample>;

    /// Solid-angle density with which `sample` produces `wi`, counting smooth lobes only.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// [`f`](Self::f) over many pairs: `out[k] = f(wo[k], wi[k])`, bit for bit, for `k` below the shortest
    /// length. [`Bsdf`] calls this once per batch (the model is chosen once, not per pair) from a loop compiled
    /// for the CPU's SIMD units (see [`Bsdf::f_batch`]); a model overrides it when its parameters select
    /// between code paths, so that each path's loop is straight-line arithmetic the compiler can vectorise.
    #[inline(always)]
    fn f_batch(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb]) {
        f_each(self, wo, wi, out);
    }

    /// [`pdf`](Self::pdf) over many pairs, bit for bit (see [`f_batch`](Self::f_batch)).
    #[inline(always)]
    fn pdf_batch(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [f32]) {
        pdf_each(self, wo, wi, out);
    }

    /// [`sample`](Self::sample) over many rows, bit for bit (see [`f_batch`](Self::f_batch)), into columns.
    #[inline(always)]
    fn sample_batch(&self, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>) {
        sample_each(self, wo, uc, u, out);
    }

    /// [`f_batch`](Self::f_batch), and whether every row passes `check` ([`RowCheck`]). Models with SIMD
    /// kernels test the rows on the lanes they load anyway, so that a batch's inputs are read once; the
    /// rows are computed either way.
    #[inline(always)]
    fn f_batch_checked(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb], check: RowCheck) -> bool {
        self.f_batch(wo, wi, out);
        check.directions(wo) & check.directions(wi)
    }

    /// [`pdf_batch`](Self::pdf_batch), and whether every row passes `check` (see
    /// [`f_batch_checked`](Self::f_batch_checked)).
    #[inline(always)]
    fn pdf_batch_checked(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [f32], check: RowCheck) -> bool {
        self.pdf_batch(wo, wi, out);
        check.directions(wo) & check.directions(wi)
    }

    /// [`sample_batch`](Self::sample_batch), and whether every row passes `check`: `wo` its direction
    /// test, `uc` and `u` within [0, 1] (see [`f_batch_checked`](Self::f_batch_checked)).
    #[inline(always)]
    fn sample_batch_checked(&self, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>, check: RowCheck) -> bool {
        self.sample_batch(wo, uc, u, out);
        check.directions(wo) & RowCheck::unit_numbers(uc) & RowCheck::unit_pairs(u)
    }
}

/// The loop of [`BsdfModel::f_batch`]: `out[k] = m.f(wo[k], wi[k])`. Models that override `f_batch` call it
/// on a copy of themselves whose code-path choices are constants.
#[inline(always)]
pub fn f_each<M: BsdfModel + ?Sized>(m: &M, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb]) {
    for ((r, &o), &i) in out.iter_mut().zip(wo).zip(wi) {
        *r = m.f(o, i);
    }
}

/// The loop of [`BsdfModel::pdf_batch`] (see [`f_each`]).
#[inline(always)]
pub fn pdf_each<M: BsdfModel + ?Sized>(m: &M, wo: &[Vec3], wi: &[Vec3], out: &mut [f32]) {
    for ((r, &o), &i) in out.iter_mut().zip(wo).zip(wi) {
        *r = m.pdf(o, i);
    }
}

/// The results of [`BsdfModel::sample_batch`], one slice per field of [`BsdfSample`] (structure of
/// arrays: the loop stores each field with plain vector stores, and these are numpy's arrays). Row `k`
/// holds `sample(wo[k], uc[k], u[k])`; where that is `None`, `valid[k]` is false and the other fields are 0.
#[derive(Debug)]
pub struct SampleColumns<'a> {
    pub wi: &'a mut [Vec3],
    pub f: &'a mut [Rgb],
    pub pdf: &'a mut [f32],
    pub weight: &'a mut [Rgb],
    /// The bits of [`BsdfSample::flags`].
    pub flags: &'a mut [u32],
    pub eta: &'a mut [f32],
    pub valid: &'a mut [bool],
}

impl SampleColumns<'_> {
    /// The number of rows a batch of `sample` over `wo`, `uc`, `u` into these columns computes: the
    /// shortest length of all ten slices.
    #[must_use]
    pub fn rows(&self, wo: &[Vec3], uc: &[f32], u: &[Vec2]) -> usize {
        [
            wo.len(),
            uc.len(),
            u.len(),
            self.wi.len(),
            self.f.len(),
            self.pdf.len(),
            self.weight.len(),
            self.flags.len(),
            self.eta.len(),
            self.valid.len(),
        ]
        .into_iter()
        .min()
        .unwrap_or(0)
    }

    /// Row `k` = `s`, or zeros and `valid = false` for `None`.
    #[inline(always)]
    pub fn set(&mut self, k: usize, s: Option<BsdfSample>) {
        self.valid[k] = s.is_some();
        let s = s.unwrap_or(BsdfSample { wi: Vec3::ZERO, f: Rgb::ZERO, pdf: 0.0, weight: Rgb::ZERO, flags: BsdfFlags::NONE, eta: 0.0 });
        (self.wi[k], self.f[k], self.pdf[k], self.weight[k], self.flags[k], self.eta[k]) = (s.wi, s.f, s.pdf, s.weight, s.flags.0, s.eta);
    }
}

/// Owned rows for [`BsdfModel::sample_batch`], lent as [`SampleColumns`] by [`columns`](Self::columns): for
/// callers that keep the results in vectors (tests, benchmarks; the Python package writes into numpy's
/// arrays instead). Every row starts as a value the batch overwrites (ones, flags 7, not valid), so that a
/// row left unwritten shows.
#[derive(Clone, Debug)]
pub struct SampleBuffers {
    pub wi: Vec<Vec3>,
    pub f: Vec<Rgb>,
    pub pdf: Vec<f32>,
    pub weight: Vec<Rgb>,
    pub flags: Vec<u32>,
    pub eta: Vec<f32>,
    pub valid: Vec<bool>,
}

impl SampleBuffers {
    /// `n` rows.
    #[must_use]
    pub fn new(n: usize) -> Self {
        SampleBuffers {
            wi: vec![Vec3::ONE; n],
            f: vec![Rgb::ONE; n],
            pdf: vec![1.0; n],
            weight: vec![Rgb::ONE; n],
            flags: vec![7; n],
            eta: vec![1.0; n],
            valid: vec![false; n],
        }
    }

    /// All the rows, as the columns a batch writes.
    pub fn columns(&mut self) -> SampleColumns<'_> {
        SampleColumns {
            wi: &mut self.wi,
            f: &mut self.f,
            pdf: &mut self.pdf,
            weight: &mut self.weight,
            flags: &mut self.flags,
            eta: &mut self.eta,
            valid: &mut self.valid,
        }
    }
}

/// The loop of [`BsdfModel::sample_batch`] (see [`f_each`]), for `k` below the shortest length.
#[inline(always)]
pub fn sample_each<M: BsdfModel + ?Sized>(m: &M, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>) {
    for k in 0..out.rows(wo, uc, u) {
        out.set(k, m.sample(wo[k], uc[k], u[k]));
    }
}

/// The specs every model is checked with by `cargo test` and `gonio check --all`: examples (defaults and
/// extreme parameters) that must pass every check, and violations — non-physical forms kept for
/// teaching — each with the kind of check row that must catch it (e.g. "reciprocity", "albedo max"; see
/// [`crate::verify::expect_violation`]).
pub trait Examples {
    const EXAMPLES: &'static [&'static str];
    const VIOLATIONS: &'static [(&'static str, &'static str)] = &[];
}

/// Runs `$call` (one model's batch loop, the model chosen by one `match`) compiled twice: for the baseline
/// target and, on x86-64 CPUs that have them (detected at run time, so one wheel runs everywhere), with AVX2
/// and FMA, whose 8-wide registers the kernels' lanes fill ([`lanes`]). Each is a function generic over the
/// model, so every model's loop is its own function, compiled with those features (`$arg: $ty` are its
/// parameters, named as in `$call`): a closure would not do, as it is compiled once, for the baseline, and
/// merely called from the feature function (2026-11: that was the case before, and the AVX2 build held no
/// 256-bit instruction). They are kept out of line: one function holding every model's loops (the `match`
/// inside the feature function, as this was until 2026-12-04) kept LLVM's loop passes on it for 40
/// CPU-minutes in the test build. Both builds round alike: Rust never fuses a multiply and an add on its
/// own, and `mul_add` is the same exact operation in hardware and in libm, so the results are the same bit
/// for bit on every path (test `batches_equal_single_calls`).
macro_rules! simd_batch {
    ($self:ident, $m:ident => $call:expr; $($arg:ident: $ty:ty),* => $ret:ty) => {{
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        #[inline(never)]
        unsafe fn with_avx2<M: BsdfModel>($m: &M, $($arg: $ty),*) -> $ret {
            $call
        }
        #[inline(never)]
        fn baseline<M: BsdfModel>($m: &M, $($arg: $ty),*) -> $ret {
            $call
        }
        dispatch!($self, $m => {
            #[cfg(target_arch = "x86_64")]
            {
                if crate::math::avx2::detected() {
                    // SAFETY: the CPU has the features the function is compiled for (checked just above).
                    return unsafe { with_avx2($m, $($arg),*) };
                }
            }
            baseline($m, $($arg),*)
        })
    }};
}

/// Declares the closed set of models: the enum, its `BsdfModel` forwarding, `From` conversions and the
/// plugin-name table. Adding a model is one line here.
macro_rules! bsdf_models {
    ($( $variant:ident($ty:ty) = $plugin:literal ),* $(,)?) => {
        /// Any gonio reflection model. Nested models (blend, sum, twosided) hold boxed `Bsdf`s.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Bsdf { $( $variant($ty) ),* }

        $( impl From<$ty> for Bsdf {
            #[inline]
            fn from(m: $ty) -> Bsdf { Bsdf::$variant(m) }
        } )*

        macro_rules! dispatch {
            ($self:ident, $m:ident => $call:expr) => { match $self { $( Bsdf::$variant($m) => $call ),* } };
        }

        impl BsdfModel for Bsdf {
            #[inline]
            fn flags(&self) -> BsdfFlags { dispatch!(self, m => m.flags()) }
            #[inline]
            fn f(&self, wo: Vec3, wi: Vec3) -> Rgb { dispatch!(self, m => m.f(wo, wi)) }
            #[inline]
            fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> { dispatch!(self, m => m.sample(wo, uc, u)) }
            #[inline]
            fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 { dispatch!(self, m => m.pdf(wo, wi)) }
            fn f_batch(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb]) {
                simd_batch!(self, m => m.f_batch(wo, wi, out); wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb] => ())
            }
            fn pdf_batch(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [f32]) {
                simd_batch!(self, m => m.pdf_batch(wo, wi, out); wo: &[Vec3], wi: &[Vec3], out: &mut [f32] => ())
            }
            fn sample_batch(&self, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>) {
                simd_batch!(self, m => m.sample_batch(wo, uc, u, out); wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_> => ())
            }
            fn f_batch_checked(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb], check: RowCheck) -> bool {
                simd_batch!(self, m => m.f_batch_checked(wo, wi, out, check); wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb], check: RowCheck => bool)
            }
            fn pdf_batch_checked(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [f32], check: RowCheck) -> bool {
                simd_batch!(self, m => m.pdf_batch_checked(wo, wi, out, check); wo: &[Vec3], wi: &[Vec3], out: &mut [f32], check: RowCheck => bool)
            }
            fn sample_batch_checked(&self, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>, check: RowCheck) -> bool {
                simd_batch!(self, m => m.sample_batch_checked(wo, uc, u, out, check);
                    wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>, check: RowCheck => bool)
            }
        }

        /// The plugin names gonio understands, as in Mitsuba's `type = "…"`.
        pub const PLUGINS: &[&str] = &[ $( $plugin ),* ];

        impl Bsdf {
            /// Build a model from a plugin description (JSON or XML, see [`Props`]).
            pub fn from_props(props: &Props) -> Result<Bsdf> {
                let bsdf = match props.plugin_type() {
                    $( $plugin => <$ty>::from_props(props)?.into(), )*
                    // A normal map whose normal a scene's material sets from a height field at each hit.
                    "bumpmap" => NormalMap::from_props(props)?.into(),
                    other => return Err(Error::spec(props.at(), format!(
                        "unknown BSDF type `{other}`; expected one of: {}, bumpmap", PLUGINS.join(", ")))),
                };
                props.finish()?;
                Ok(bsdf)
            }

            /// The plugin name of this model.
            #[must_use]
            pub fn plugin_name(&self) -> &'static str {
                match self { $( Bsdf::$variant(_) => $plugin ),* }
            }

            /// Example specs per plugin (defaults and extreme parameters), used by `gonio check --all`.
            #[must_use]
            pub fn examples() -> Vec<&'static str> {
                let mut all = Vec::new();
                $( all.extend_from_slice(<$ty as Examples>::EXAMPLES); )*
                all
            }

            /// Non-physical specs per plugin with the check row that must fail for each, used by
            /// `gonio check --all`.
            #[must_use]
            pub fn violations() -> Vec<(&'static str, &'static str)> {
                let mut all = Vec::new();
                $( all.extend_from_slice(<$ty as Examples>::VIOLATIONS); )*
                all
            }
        }
    };
}

bsdf_models! {
    Diffuse(Diffuse) = "diffuse",
    Conductor(Conductor) = "conductor",
    RoughConductor(RoughConductor) = "roughconductor",
    TorranceSparrow(TorranceSparrow) = "torrance_sparrow",
    Dielectric(Dielectric) = "dielectric",
    RoughDielectric(RoughDielectric) = "roughdielectric",
    Plastic(Plastic) = "plastic",
    RoughPlastic(RoughPlastic) = "roughplastic",
    ThinDielectric(ThinDielectric) = "thindielectric",
    Blend(BlendBsdf) = "blendbsdf",
    Sum(Sum) = "sum",
    TwoSided(TwoSided) = "twosided",
    Mask(Mask) = "mask",
    Phong(Phong) = "phong",
    BlinnPhong(BlinnPhong) = "blinn_phong",
    OrenNayar(OrenNayar) = "oren_nayar",
    Measured(Measured) = "measured",
    Layered(Layered) = "layered",
    AshikhminShirley(AshikhminShirley) = "ashikhmin_shirley",
    Merl(Merl) = "merl",
    Principled(Principled) = "principled",
    Polarizer(Polarizer) = "polarizer",
    NormalMap(NormalMap) = "normalmap",
}

/// The lobe a colour parameter tints ([`Bsdf::tint`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tint {
    /// Directions on ωo's side of the surface (ωo·n and ωi·n of one sign).
    Reflection,
    /// Directions through the surface.
    Transmission,
}

impl Bsdf {
    /// Build a model from a JSON object in Mitsuba's dictionary form, e.g.
    /// `{"type": "conductor", "material": "Au"}`.
    pub fn from_json(text: &str) -> Result<Bsdf> {
        Bsdf::from_props(&Props::from_json(text)?)
    }

    /// Build a model from an XML document whose root (or only `<bsdf>` child) is a `<bsdf>` element.
    /// `source` names the file in error messages.
    pub fn from_xml(text: &str, source: &str) -> Result<Bsdf> {
        Bsdf::from_props(&Props::from_xml_bsdf(text, source)?)
    }

    /// Set this model's float parameter `name` to a texture's value at a hit without building the model
    /// again, where the model has such a parameter: the blend `weight` and `principled`'s floats (clamped
    /// to [0, 1]), and the roughness `alpha`, `alpha_u`, `alpha_v` of the microfacet conductors and of
    /// `roughdielectric` without energy compensation (whose tables are built for one roughness), clamped
    /// to [10⁻⁴, 10] — the values the model built again from a description holding `value` would take
    /// (`Props::set_texture_value`). `false` (the model unchanged) otherwise. The float counterpart of
    /// [`Self::reflectance_slot`].
    pub fn set_float(&mut self, name: &str, value: f32) -> bool {
        match (self, name) {
            (Bsdf::Blend(b), "weight") => {
                b.set_weight(value.clamp(0.0, 1.0));
                true
            }
            (Bsdf::Principled(p), name) => p.set_unit_float(name, value.clamp(0.0, 1.0)),
            (Bsdf::RoughConductor(RoughConductor(c)) | Bsdf::TorranceSparrow(TorranceSparrow(c)), name) if c.compensation.is_none() => {
                c.distribution.set_roughness(name, textured_roughness(value))
            }
            (Bsdf::RoughDielectric(d), name) if d.compensation.is_none() => d.distribution.set_roughness(name, textured_roughness(value)),
            _ => false,
        }
    }

    /// This model's kernel with the parameters in `values` given per lane of a packet (name and each
    /// lane's value, as [`Self::set_float`] and [`Self::reflectance_slot`] take them and clamped as they
    /// are clamped; the others the model's own): what each lane's model with those values written into it
    /// computes, in one kernel call for all lanes. The parameters: the roughness of the models whose
    /// roughness [`Self::set_float`] sets (except Blinn's, whose exponent is one number), and the base
    /// reflectance of `plastic` and of `roughplastic` without energy compensation, and `principled`'s
    /// `base_color`; `None` for other models and parameters. A kernel is returned only after every value
    /// has been read ([`Material::lanes_at`](crate::scene::material::Material::lanes_at) evaluates its
    /// textures as they are read, and checks them for finite numbers after).
    pub fn per_lane_kernel<'n>(&self, values: impl IntoIterator<Item = (&'n str, LaneValue)>) -> Option<PerLaneKernel<'_>> {
        match self {
            Bsdf::RoughConductor(RoughConductor(c)) | Bsdf::TorranceSparrow(TorranceSparrow(c)) => {
                c.per_lane(roughness_lanes(&c.distribution, values)?)
            }
            Bsdf::RoughDielectric(d) => d.per_lane(roughness_lanes(&d.distribution, values)?),
            Bsdf::RoughPlastic(p) => p.per_lane(colour_lanes("diffuse_reflectance", p.diffuse_reflectance, values)?),
            Bsdf::Plastic(p) => {
                Some(PerLaneKernel::Plastic(p.per_lane(colour_lanes("diffuse_reflectance", p.diffuse_reflectance, values)?)))
            }
            Bsdf::Principled(p) => Some(PerLaneKernel::Principled(Box::new(p.per_lane(colour_lanes("base_color", p.base_color, values)?)))),
            _ => None,
        }
    }

    /// One kernel for the lanes of a packet whose models are copies of this one that differ from it where
    /// spectral mode sets each lane's copy at its wavelengths ([`crate::scene::spectral::reflectances_at`]),
    /// or where a texture sets a parameter the kernel takes per lane: `models[lane]`, `None` for lanes not
    /// in the group. The rough conductors (`roughconductor`, `torrance_sparrow` with GGX or Beckmann, without
    /// energy compensation: their roughness and Fresnel term per lane), `plastic` and `roughplastic` (their
    /// `diffuse_reflectance` per lane) and `principled` (its `base_color`), as [`Self::per_lane_kernel`]
    /// takes them; `None` for other models, and where a copy differs from this model in anything else —
    /// those lanes then run one at a time. Each lane's values are its own model's, bit for bit (test
    /// `kernels_of_lanes_are_each_lanes_model`).
    #[must_use]
    pub fn kernel_of_lanes(&self, models: &[Option<&Bsdf>; PER_LANE]) -> Option<PerLaneKernel<'_>> {
        fn conductor(b: &Bsdf) -> Option<&MicrofacetConductor> {
            match b {
                Bsdf::RoughConductor(RoughConductor(c)) | Bsdf::TorranceSparrow(TorranceSparrow(c)) => Some(c),
                _ => None,
            }
        }
        if models.iter().flatten().any(|m| std::mem::discriminant(*m) != std::mem::discriminant(self)) {
            return None;
        }
        if let Some(own) = conductor(self) {
            let lanes = models.map(|m| m.and_then(conductor));
            return own.kernel_of_lanes(&lanes);
        }
        // A colour per lane: each copy must be this model with its colour written into it.
        fn colour_of(b: &Bsdf) -> Option<(&'static str, Rgb)> {
            match b {
                Bsdf::Plastic(p) => Some(("diffuse_reflectance", p.diffuse_reflectance)),
                Bsdf::RoughPlastic(p) => Some(("diffuse_reflectance", p.diffuse_reflectance)),
                Bsdf::Principled(p) => Some(("base_color", p.base_color)),
                _ => None,
            }
        }
        let (name, own) = colour_of(self)?;
        let mut colour = own.0.map(|c| [c; PER_LANE]);
        let mut probe = self.clone();
        for (lane, model) in models.iter().enumerate() {
            let Some(model) = model else { continue };
            let (_, value) = colour_of(model)?;
            *probe.reflectance_slot(name)? = value;
            // (A value the kernel would clamp differently, or NaN, is not taken.)
            if probe != **model || value.0.iter().any(|&v| textured_reflectance(v) != v) {
                return None;
            }
            for (channel, v) in colour.iter_mut().zip(value.0) {
                channel[lane] = v;
            }
        }
        self.per_lane_kernel([(name, LaneValue::Colour(colour))])
    }

    /// The models this one built from the k-th of its `count` nested descriptions (`Props::nested`'s
    /// order) and holds as they are, where a texture on a parameter of that description can be set at a
    /// hit ([`Self::reflectance_slot`], [`Self::set_float`]) without building this model again:
    /// `twosided` (a single nested model is both sides) and `blendbsdf`; none for other models.
    /// Calls `f` on each of them; returns how many there were.
    pub fn for_nested_models(&mut self, k: usize, count: usize, f: &mut dyn FnMut(&mut Bsdf)) -> usize {
        match self {
            Bsdf::TwoSided(t) => t.for_sides(k, count, f),
            Bsdf::Blend(b) if count == 2 => b.model_mut(k).map(f).map_or(0, |()| 1),
            _ => 0,
        }
    }

    /// Call `f` on every model this one holds as it is (one level down): a `twosided`'s sides, a blend's or
    /// a sum's components, the model of a `mask` or a normal or bump map.
    pub fn for_each_nested(&mut self, f: &mut dyn FnMut(&mut Bsdf)) {
        match self {
            Bsdf::TwoSided(t) => {
                t.for_sides(0, 1, f);
            }
            Bsdf::Blend(b) => b.mix_mut().components_mut().iter_mut().for_each(f),
            Bsdf::Sum(s) => s.components_mut().iter_mut().for_each(f),
            Bsdf::Mask(m) => f(m.nested_mut()),
            Bsdf::NormalMap(n) => f(n.nested_mut()),
            _ => {}
        }
    }

    /// Which lobe colour parameter `name` tints, where it is a pure tint of this model: it scales `f` (and
    /// a sample's `f` and weight) channel by channel for the directions on ωo's side of the surface
    /// ([`Tint::Reflection`]) or through it ([`Tint::Transmission`]), and changes neither `pdf` nor the
    /// sampled directions. A texture on such a parameter can then be applied after the model (the
    /// renderer's packets run one model for the lanes of a textured material and scale each lane's values
    /// by its texels). The conductors' `specular_reflectance` and the dielectrics' `specular_reflectance`
    /// and `specular_transmittance` (Mitsuba's meaning: "a factor that modulates the component"; both
    /// renderers choose the dielectric's lobe by the Fresnel term alone), where [`Self::reflectance_slot`]
    /// holds them; `None` for every other parameter (test `tints_only_scale_their_lobe`).
    #[must_use]
    pub fn tint(&mut self, name: &str) -> Option<Tint> {
        self.reflectance_slot(name)?;
        match (self, name) {
            (Bsdf::Conductor(_) | Bsdf::RoughConductor(_), "specular_reflectance") => Some(Tint::Reflection),
            (Bsdf::Dielectric(_) | Bsdf::ThinDielectric(_) | Bsdf::RoughDielectric(_), "specular_reflectance") => Some(Tint::Reflection),
            (Bsdf::Dielectric(_) | Bsdf::ThinDielectric(_) | Bsdf::RoughDielectric(_), "specular_transmittance") => {
                Some(Tint::Transmission)
            }
            _ => None,
        }
    }

    /// The model a `twosided` with one nested model runs on both sides (`None` for other models).
    #[must_use]
    pub fn both_sides(&mut self) -> Option<&mut Bsdf> {
        match self {
            Bsdf::TwoSided(t) => t.both_sides(),
            _ => None,
        }
    }

    /// A dispersive dielectric interface's law and its relative index η, to set at a path's hero
    /// wavelength in spectral mode (`dielectric`, and `roughdielectric` without energy compensation, whose
    /// lobes are built from η; [`Self::is_dispersive`] tells those apart). A `thindielectric` takes every
    /// wavelength instead ([`Self::set_wavelengths`]).
    pub fn dispersion_mut(&mut self) -> Option<(&dielectric::Dispersion, &mut f32)> {
        match self {
            Bsdf::Dielectric(d) => Some((d.dispersion.as_deref()?, &mut d.eta)),
            Bsdf::RoughDielectric(d) if d.compensation.is_none() => Some((d.dispersion.as_deref()?, &mut d.eta)),
            _ => None,
        }
    }

    /// Set what this model (not the models it holds) reads of a path's wavelengths `lambda` (nm, one per
    /// channel) itself: a conductor's index ([`Conductor::set_wavelengths`], where
    /// [`Self::conductor_fresnel`] gives it), a dispersive interface's index at the hero wavelength
    /// `lambda[0]` ([`Self::dispersion_mut`]), a dispersive `thindielectric`'s index per channel
    /// ([`ThinDielectric::set_wavelengths`]) and a `measured` file's spectra ([`Measured::set_wavelengths`]);
    /// other models are unchanged.
    pub fn set_wavelengths(&mut self, lambda: [f32; 3]) {
        if let Some(c) = self.conductor_fresnel() {
            c.set_wavelengths(lambda);
        }
        if let Some((law, eta)) = self.dispersion_mut() {
            *eta = law.eta(lambda[0]);
        }
        match self {
            Bsdf::Measured(m) => m.set_wavelengths(lambda),
            Bsdf::ThinDielectric(t) => t.set_wavelengths(lambda),
            _ => {}
        }
    }

    /// Whether this model (not the models it holds) has an index that varies with wavelength.
    #[must_use]
    pub fn is_dispersive(&self) -> bool {
        match self {
            Bsdf::Dielectric(d) => d.dispersion.is_some(),
            Bsdf::ThinDielectric(d) => d.dispersion.is_some(),
            Bsdf::RoughDielectric(d) => d.dispersion.is_some(),
            _ => false,
        }
    }

    /// The Fresnel term of a `conductor` or `roughconductor` (not of an energy-compensated one, whose lobe is
    /// built from it): its index of refraction, to set at a path's wavelengths in spectral mode.
    pub fn conductor_fresnel(&mut self) -> Option<&mut Conductor> {
        match self {
            Bsdf::Conductor(c) => Some(c),
            Bsdf::RoughConductor(RoughConductor(c)) if c.compensation.is_none() => Some(&mut c.fresnel),
            _ => None,
        }
    }

    /// The field that holds this model's colour parameter `name`, where a texture can set it at a hit
    /// without building the model again: a reflectance in [0, 1] per channel (`Props::reflectance`) that
    /// the model reads as it is, deriving nothing from it when built. `None` where the model must be
    /// built again from its parameters (for models with energy-compensation lobes too, which are built
    /// from the model).
    pub fn reflectance_slot(&mut self, name: &str) -> Option<&mut Rgb> {
        let compensated = match self {
            Bsdf::RoughConductor(RoughConductor(c)) => c.compensation.is_some(),
            Bsdf::RoughDielectric(d) => d.compensation.is_some(),
            Bsdf::RoughPlastic(p) => p.coating.compensation.is_some(),
            _ => false,
        };
        if compensated {
            return None;
        }
        match (self, name) {
            (Bsdf::Diffuse(d), "reflectance") => Some(&mut d.reflectance),
            (Bsdf::OrenNayar(o), "reflectance") => Some(&mut o.reflectance),
            (Bsdf::Conductor(c), "specular_reflectance") => Some(&mut c.specular_reflectance),
            (Bsdf::RoughConductor(RoughConductor(c)), "specular_reflectance") => Some(&mut c.fresnel.specular_reflectance),
            (Bsdf::Dielectric(d), "specular_reflectance") => Some(&mut d.specular_reflectance),
            (Bsdf::Dielectric(d), "specular_transmittance") => Some(&mut d.specular_transmittance),
            (Bsdf::ThinDielectric(d), "specular_reflectance") => Some(&mut d.specular_reflectance),
            (Bsdf::ThinDielectric(d), "specular_transmittance") => Some(&mut d.specular_transmittance),
            (Bsdf::RoughDielectric(d), "specular_reflectance") => Some(&mut d.specular_reflectance),
            (Bsdf::RoughDielectric(d), "specular_transmittance") => Some(&mut d.specular_transmittance),
            (Bsdf::Plastic(p), "diffuse_reflectance") => Some(&mut p.diffuse_reflectance),
            (Bsdf::Plastic(p), "specular_reflectance") => Some(&mut p.specular_reflectance),
            (Bsdf::RoughPlastic(p), "diffuse_reflectance") => Some(&mut p.diffuse_reflectance),
            (Bsdf::RoughPlastic(p), "specular_reflectance") => Some(&mut p.coating.specular_reflectance),
            (Bsdf::Principled(p), "base_color") => Some(&mut p.base_color),
            (Bsdf::Polarizer(p), "transmittance") => Some(&mut p.transmittance),
            (Bsdf::NormalMap(m), "normalmap") => Some(&mut m.normalmap),
            _ => None,
        }
    }
}

/// A parameter's values per lane of a packet ([`Bsdf::per_lane_kernel`]).
#[derive(Clone, Copy, Debug)]
pub enum LaneValue {
    Float([f32; PER_LANE]),
    /// Per channel.
    Colour([[f32; PER_LANE]; 3]),
}

/// A texture's value on a reflectance (a colour parameter of a model) as the models take it: clamped to
/// [0, 1].
#[inline]
#[must_use]
pub fn textured_reflectance(value: f32) -> f32 {
    value.clamp(0.0, 1.0)
}

/// A colour parameter per lane: the colour `name` in `values` (clamped as a texture's,
/// [`textured_reflectance`]), else `own`; `None` for any other parameter.
fn colour_lanes<'n>(name: &str, own: Rgb, values: impl IntoIterator<Item = (&'n str, LaneValue)>) -> Option<[[f32; PER_LANE]; 3]> {
    let mut rho = own.0.map(|c| [c; PER_LANE]);
    for value in values {
        let (n, LaneValue::Colour(c)) = value else { return None };
        if n != name {
            return None;
        }
        rho = c.map(|channel| channel.map(textured_reflectance));
    }
    Some(rho)
}

/// The roughness per lane of `distribution` with the roughness parameters in `values` (clamped as a
/// texture's, [`textured_roughness`]) and its own elsewhere; `None` for any other parameter.
fn roughness_lanes<'n>(
    distribution: &MicrofacetDistribution,
    values: impl IntoIterator<Item = (&'n str, LaneValue)>,
) -> Option<(PerLane, PerLane)> {
    let (mut ax, mut ay) = ([distribution.alpha_x; PER_LANE], [distribution.alpha_y; PER_LANE]);
    for (name, value) in values {
        let ((x, y), LaneValue::Float(v)) = (distribution.roughness_axes(name)?, value) else { return None };
        let v = v.map(textured_roughness);
        if x {
            ax = v;
        }
        if y {
            ay = v;
        }
    }
    Some((PerLane(ax), PerLane(ay)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// The batch methods (one `match` per batch, AVX2-compiled loops, the eight-lane kernels of the models
    /// that have one in `lanes`) give every example model's per-pair results bit for
    /// bit, including directions below the horizon and on it, and the rows after the last full eight.
    /// The `_checked` batch methods compute what the plain ones do, bit for bit, and report a row that fails
    /// the check wherever it is (in a full register of rows or among the last rows), for models with SIMD
    /// kernels and without.
    #[test]
    fn checked_batches_compute_the_same_and_find_bad_rows() {
        for level in [2, 1, 0] {
            crate::math::simd_level::with(level, checked_batches_at_this_level);
        }
    }

    fn checked_batches_at_this_level() {
        let n = 257;
        let mut rng = Pcg32::new(3, 0);
        let mut dir = || Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() + 0.1).normalize();
        let (wo, wi): (Vec<Vec3>, Vec<Vec3>) = (0..n).map(|_| (dir(), dir())).unzip();
        let mut rng = Pcg32::new(4, 0);
        let uc: Vec<f32> = (0..n).map(|_| rng.next_f32()).collect();
        let u: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect();
        let check = RowCheck { lo: 0.998, hi: 1.002 };
        for spec in [
            r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#,
            r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Au"}"#,
            r#"{"type": "roughconductor", "distribution": "beckmann", "alpha": 0.3}"#,
            r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3}"#,
            r#"{"type": "plastic"}"#,
        ] {
            let b = Bsdf::from_json(spec).unwrap();
            let run = |wo: &[Vec3], wi: &[Vec3], uc: &[f32], u: &[Vec2]| {
                let (mut f, mut pdf, mut f_checked, mut pdf_checked) = (vec![Rgb::ZERO; n], vec![0.0; n], vec![Rgb::ONE; n], vec![1.0; n]);
                b.f_batch(wo, wi, &mut f);
                b.pdf_batch(wo, wi, &mut pdf);
                let ok = (b.f_batch_checked(wo, wi, &mut f_checked, check), b.pdf_batch_checked(wo, wi, &mut pdf_checked, check));
                assert!(f.iter().zip(&f_checked).all(|(a, c)| a.0.map(f32::to_bits) == c.0.map(f32::to_bits)), "{spec}: f");
                assert!(pdf.iter().zip(&pdf_checked).all(|(a, c)| a.to_bits() == c.to_bits()), "{spec}: pdf");
                let sample = |checked: bool| {
                    let mut rows = SampleBuffers::new(n);
                    let mut columns = rows.columns();
                    let ok = if checked {
                        b.sample_batch_checked(wo, uc, u, &mut columns, check)
                    } else {
                        b.sample_batch(wo, uc, u, &mut columns);
                        true
                    };
                    let bits: Vec<u32> = rows
                        .wi
                        .iter()
                        .flat_map(|v| v.to_array())
                        .chain(rows.weight.iter().flat_map(|c| c.0))
                        .chain(rows.pdf)
                        .map(f32::to_bits)
                        .collect();
                    (ok, bits, rows.flags, rows.valid)
                };
                let (plain, checked) = (sample(false), sample(true));
                assert_eq!((&plain.1, &plain.2, &plain.3), (&checked.1, &checked.2, &checked.3), "{spec}: sample");
                (ok.0, ok.1, checked.0)
            };
            assert_eq!(run(&wo, &wi, &uc, &u), (true, true, true), "{spec}: unit rows");
            for at in [0, 5, 16, 255, 256] {
                for bad in [1.01, f32::NAN, 0.9] {
                    let mut w = wi.clone();
                    w[at] *= bad;
                    assert_eq!(run(&wo, &w, &uc, &u), (false, false, true), "{spec}: wi[{at}] × {bad}");
                    let mut w = wo.clone();
                    w[at] *= bad;
                    assert_eq!(run(&w, &wi, &uc, &u), (false, false, false), "{spec}: wo[{at}] × {bad}");
                }
                for bad in [-1e-7, 1.000_001, f32::NAN] {
                    let mut v = uc.clone();
                    v[at] = bad;
                    assert!(!run(&wo, &wi, &v, &u).2, "{spec}: uc[{at}] = {bad}");
                    let mut v = u.clone();
                    v[at].y = bad;
                    assert!(!run(&wo, &wi, &uc, &v).2, "{spec}: u[{at}].y = {bad}");
                }
            }
            // The band's edges are inside.
            let mut w = wi.clone();
            (w[3], w[200]) = (Vec3::new(0.0, 0.0, 0.998f32.sqrt() * 1.000_001), Vec3::new(0.0, 0.0, 1.002f32.sqrt() * 0.999_999));
            assert_eq!(run(&wo, &w, &uc, &u), (true, true, true), "{spec}: band edges");
        }
    }

    #[test]
    fn batches_equal_single_calls() {
        // Each lane type the CPU has: AVX-512, AVX2, portable.
        for level in [2, 1, 0] {
            crate::math::simd_level::with(level, batches_equal_single_calls_at_this_level);
        }
    }

    fn batches_equal_single_calls_at_this_level() {
        let mut rng = Pcg32::new(7, 0);
        let n = 257;
        let dir = |rng: &mut Pcg32| {
            let v = Vec3::new(2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0);
            if v.length_squared() < 1e-6 {
                Vec3::Z
            } else {
                v.normalize()
            }
        };
        let mut wo: Vec<Vec3> = (0..n).map(|_| dir(&mut rng)).collect();
        let wi: Vec<Vec3> = (0..n).map(|_| dir(&mut rng)).collect();
        (wo[0], wo[1]) = (Vec3::Z, Vec3::X);
        let uc: Vec<f32> = (0..n).map(|_| rng.next_f32()).collect();
        let u: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect();
        let bits = |c: Rgb| c.0.map(f32::to_bits);
        // Every example but the models whose construction integrates tables (seconds each), and three rough
        // plastics (GGX, which has its own batch loops, once with a coating less dense than the outside, whose
        // tables have graded nodes, and Beckmann, which has no batch loops).
        let cheap = Bsdf::examples().into_iter().filter(|s| !["roughplastic", "layered", "measured", "merl"].iter().any(|p| s.contains(p)));
        let plastics = [
            r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": [0.9, 0.4, 0.1], "nonlinear": true}"#,
            r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.2, "int_ior": 1.0, "ext_ior": 1.5}"#,
            r#"{"type": "roughplastic", "alpha": 0.3}"#,
        ];
        for spec in cheap.chain(plastics) {
            let b = Bsdf::from_json(spec).unwrap();
            let (mut f, mut pdf) = (vec![Rgb::ZERO; n], vec![0.0; n]);
            let mut rows = SampleBuffers::new(n);
            b.f_batch(&wo, &wi, &mut f);
            b.pdf_batch(&wo, &wi, &mut pdf);
            b.sample_batch(&wo, &uc, &u, &mut rows.columns());
            for k in 0..n {
                assert_eq!(bits(f[k]), bits(b.f(wo[k], wi[k])), "{spec}: f at {k}");
                assert_eq!(pdf[k].to_bits(), b.pdf(wo[k], wi[k]).to_bits(), "{spec}: pdf at {k}");
                let one = b.sample(wo[k], uc[k], u[k]);
                assert_eq!(rows.valid[k], one.is_some(), "{spec}: sample at {k}");
                let one = one.unwrap_or(BsdfSample {
                    wi: Vec3::ZERO,
                    f: Rgb::ZERO,
                    pdf: 0.0,
                    weight: Rgb::ZERO,
                    flags: BsdfFlags::NONE,
                    eta: 0.0,
                });
                assert_eq!(
                    (
                        rows.wi[k].to_array().map(f32::to_bits),
                        bits(rows.f[k]),
                        rows.pdf[k].to_bits(),
                        bits(rows.weight[k]),
                        rows.flags[k],
                        rows.eta[k].to_bits()
                    ),
                    (one.wi.to_array().map(f32::to_bits), bits(one.f), one.pdf.to_bits(), bits(one.weight), one.flags.0, one.eta.to_bits()),
                    "{spec}: sample at {k}"
                );
            }
        }
    }

    /// A kernel with a parameter per lane ([`Bsdf::per_lane_kernel`]) gives in each lane what that lane's
    /// model — the value written into it with [`Bsdf::set_float`] or [`Bsdf::reflectance_slot`], clamped
    /// as a texture's — gives in its single calls, bit for bit: `f`, `pdf` and `sample` in the path
    /// tracer's lanes, for GGX and Beckmann, conductors, the dielectric, the plastics and `principled`, each
    /// roughness parameter and the base colours, over roughnesses from 0 (clamped to 10⁻⁴)
    /// to beyond 10 and reflectances beyond [0, 1], every lane a different one. Models and parameters it
    /// does not cover have none.
    /// Run `kernel` in eight lanes on random directions and random numbers, and check that each lane `l`
    /// where `own(l)` is a model gets that model's f, pdf and sample, bit for bit; the samples compared.
    fn assert_lanes_are_models(
        kernel: &lanes::PerLaneKernel<'_>,
        own: &dyn Fn(usize) -> Option<Bsdf>,
        rng: &mut Pcg32,
        label: &str,
    ) -> usize {
        use crate::math::lanes::{Real, V3};
        use crate::math::simd::Float8;
        use lanes::LaneModel;
        let mut dir = || {
            let v = Vec3::new(2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0);
            v.try_normalize().unwrap_or(Vec3::Z)
        };
        let (wo, wi): (Vec<Vec3>, Vec<Vec3>) = (0..PER_LANE).map(|_| (dir(), dir())).unzip();
        let lanes = |v: &[Vec3]| V3::new(Float8::from_fn(|i| v[i].x), Float8::from_fn(|i| v[i].y), Float8::from_fn(|i| v[i].z));
        let (uc, ux, uy) = (Float8::from_fn(|_| rng.next_f32()), Float8::from_fn(|_| rng.next_f32()), Float8::from_fn(|_| rng.next_f32()));
        let f = kernel.f_lanes(lanes(&wo), lanes(&wi));
        let pdf = kernel.pdf_lanes(lanes(&wo), lanes(&wi));
        let s = kernel.sample_lanes(lanes(&wo), uc, ux, uy);
        let valid = Float8::bitmask(s.valid);
        let mut sampled = 0;
        for l in 0..PER_LANE {
            let Some(own) = own(l) else { continue };
            let at = format!("{label}, lane {l}, {} → {}", wo[l], wi[l]);
            let want = own.f(wo[l], wi[l]);
            for (got, want) in f.iter().map(|c| c.lane(l)).zip(want.0) {
                assert_eq!(got.to_bits(), want.to_bits(), "{at}: f {got} against {want}");
            }
            assert_eq!(pdf.lane(l).to_bits(), own.pdf(wo[l], wi[l]).to_bits(), "{at}: pdf");
            match own.sample(wo[l], uc.lane(l), Vec2::new(ux.lane(l), uy.lane(l))) {
                Some(b) => {
                    assert!(valid & (1 << l) != 0, "{at}: a sample in the model only");
                    let a_wi = Vec3::new(s.wi.x.lane(l), s.wi.y.lane(l), s.wi.z.lane(l));
                    assert_eq!((a_wi, s.pdf.lane(l).to_bits()), (b.wi, b.pdf.to_bits()), "{at}: sample");
                    for (got, want) in s.weight.iter().map(|c| c.lane(l)).zip(b.weight.0) {
                        assert_eq!(got.to_bits(), want.to_bits(), "{at}: weight");
                    }
                    sampled += 1;
                }
                None => assert!(valid & (1 << l) == 0, "{at}: a sample in the kernel only"),
            }
        }
        sampled
    }

    /// Spectral mode's copies of a model at each lane's wavelengths (and each lane's roughness, for the
    /// rough conductors) run as one kernel (`Bsdf::kernel_of_lanes`), each lane's f, pdf and sample its own
    /// model's bit for bit; copies that differ otherwise, and models without such a kernel, are refused.
    #[test]
    fn kernels_of_lanes_are_each_lanes_model() {
        use crate::scene::spectral::{reflectances_at, GivenSpectra};
        let cases = [
            r#"{"type": "roughconductor"}"#,
            r#"{"type": "roughconductor", "distribution": "ggx", "material": "Cu", "specular_reflectance": [0.9, 0.6, 0.3]}"#,
            r#"{"type": "roughconductor", "alpha_u": 0.05, "alpha_v": 0.4, "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2]}"#,
            r#"{"type": "roughconductor", "distribution": "ggx", "sample_visible": false, "material": "Ag"}"#,
            r#"{"type": "roughconductor", "material": "none"}"#,
            r#"{"type": "torrance_sparrow", "distribution": "beckmann", "material": "Al"}"#,
            r#"{"type": "plastic", "diffuse_reflectance": [0.8, 0.3, 0.1]}"#,
            r#"{"type": "plastic", "diffuse_reflectance": [0.1, 0.5, 0.9], "nonlinear": true, "int_ior": 1.7}"#,
            r#"{"type": "roughplastic", "diffuse_reflectance": [0.8, 0.3, 0.1]}"#,
            r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": [0.2, 0.6, 0.3], "nonlinear": true}"#,
            r#"{"type": "principled", "base_color": [0.7, 0.2, 0.4], "metallic": 0.3, "roughness": 0.4, "sheen": 0.5, "clearcoat": 0.3, "spec_trans": 0.2}"#,
        ];
        let mut rng = Pcg32::new(23, 0);
        for json in cases {
            let model = Bsdf::from_json(json).unwrap();
            let conductor = json.contains("conductor") || json.contains("torrance");
            let mut sampled = 0;
            for round in 0..200 {
                // Lanes 2 and 5 are not in the group (another material's lanes in a packet).
                let own: Vec<Bsdf> = (0..PER_LANE)
                    .map(|_| {
                        let mut m = model.clone();
                        let lambda = [0, 1, 2].map(|_| 360.0 + 470.0 * rng.next_f32());
                        reflectances_at(&mut m, lambda, &GivenSpectra::NONE);
                        if conductor && round % 2 == 1 {
                            assert!(m.set_float("alpha", 10f32.powf(-3.0 + 3.0 * rng.next_f32())));
                        }
                        m
                    })
                    .collect();
                let lanes: [Option<&Bsdf>; PER_LANE] = std::array::from_fn(|l| (l != 2 && l != 5).then_some(&own[l]));
                let kernel = model.kernel_of_lanes(&lanes).unwrap_or_else(|| panic!("{json}: a kernel"));
                sampled += assert_lanes_are_models(&kernel, &|l| lanes[l].cloned(), &mut rng, json);
            }
            assert!(sampled > 400, "{json}: {sampled} samples compared");
        }
        // Refused: a mirror beside a metal, another model, copies that differ in more than the kernel takes
        // per lane, energy compensation, Blinn, other models.
        let of = |json: &str| Bsdf::from_json(json).unwrap();
        let (gold, mirror) =
            (of(r#"{"type": "roughconductor", "material": "Au"}"#), of(r#"{"type": "roughconductor", "material": "none"}"#));
        let pair = |a: &Bsdf, b: &Bsdf| {
            let lanes: [Option<&Bsdf>; PER_LANE] = std::array::from_fn(|l| Some(if l == 3 { b } else { a }));
            a.kernel_of_lanes(&lanes).is_some()
        };
        assert!(pair(&gold, &gold) && !pair(&gold, &mirror));
        assert!(!pair(&gold, &of(r#"{"type": "roughconductor", "material": "Au", "distribution": "ggx"}"#)));
        assert!(!pair(&gold, &of(r#"{"type": "torrance_sparrow", "material": "Au", "distribution": "beckmann"}"#)));
        let compensated = of(r#"{"type": "roughconductor", "energy_compensation": true}"#);
        assert!(!pair(&compensated, &compensated));
        let blinn = of(r#"{"type": "torrance_sparrow", "distribution": "blinn"}"#);
        assert!(!pair(&blinn, &blinn));
        let plastic = of(r#"{"type": "roughplastic", "diffuse_reflectance": [0.8, 0.3, 0.1]}"#);
        assert!(pair(&plastic, &plastic) && pair(&plastic, &of(r#"{"type": "roughplastic", "diffuse_reflectance": [0.1, 0.3, 0.8]}"#)));
        assert!(!pair(&plastic, &of(r#"{"type": "roughplastic", "diffuse_reflectance": [0.8, 0.3, 0.1], "alpha": 0.2}"#)));
        assert!(!pair(&plastic, &of(r#"{"type": "roughplastic", "diffuse_reflectance": [0.8, 0.3, 0.1], "specular_reflectance": 0.5}"#)));
        assert!(!pair(&plastic, &of(r#"{"type": "plastic", "diffuse_reflectance": [0.8, 0.3, 0.1]}"#)));
        let compensated = of(r#"{"type": "roughplastic", "diffuse_reflectance": [0.8, 0.3, 0.1], "energy_compensation": true}"#);
        assert!(!pair(&compensated, &compensated));
        let principled = of(r#"{"type": "principled", "base_color": [0.7, 0.2, 0.4]}"#);
        assert!(!pair(&principled, &of(r#"{"type": "principled", "base_color": [0.7, 0.2, 0.4], "metallic": 0.5}"#)));
        let dielectric = of(r#"{"type": "roughdielectric"}"#);
        assert!(!pair(&dielectric, &dielectric));
    }

    #[test]
    fn per_lane_parameters_are_each_lanes_model() {
        let cases = [
            (r#"{"type": "roughconductor"}"#, "alpha"),
            (r#"{"type": "roughconductor", "distribution": "ggx", "material": "Cu"}"#, "alpha"),
            (r#"{"type": "roughconductor", "alpha_v": 0.3}"#, "alpha_u"),
            (r#"{"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.05}"#, "alpha_v"),
            (r#"{"type": "roughconductor", "sample_visible": false}"#, "alpha"),
            (r#"{"type": "torrance_sparrow", "distribution": "beckmann"}"#, "alpha"),
            (r#"{"type": "roughdielectric"}"#, "alpha"),
            (r#"{"type": "roughdielectric", "distribution": "ggx", "int_ior": 1.33}"#, "alpha"),
            (r#"{"type": "roughdielectric", "distribution": "ggx", "alpha_v": 0.2}"#, "alpha_u"),
            (r#"{"type": "roughplastic"}"#, "diffuse_reflectance"),
            (r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "nonlinear": true}"#, "diffuse_reflectance"),
            (r#"{"type": "roughplastic", "distribution": "ggx", "int_ior": 1.0, "ext_ior": 1.5}"#, "diffuse_reflectance"),
            (r#"{"type": "plastic"}"#, "diffuse_reflectance"),
            (r#"{"type": "plastic", "nonlinear": true, "specular_reflectance": 0.4}"#, "diffuse_reflectance"),
            (r#"{"type": "principled"}"#, "base_color"),
            (r#"{"type": "principled", "metallic": 0.4, "sheen": 0.5, "clearcoat": 0.6, "flatness": 0.3, "spec_tint": 0.5}"#, "base_color"),
            (r#"{"type": "principled", "spec_trans": 0.7, "roughness": 0.3}"#, "base_color"),
        ];
        let mut rng = Pcg32::new(17, 0);
        for (json, name) in cases {
            let model = Bsdf::from_json(json).unwrap();
            let colour = name == "diffuse_reflectance" || name == "base_color";
            let mut sampled = 0;
            for _ in 0..400 {
                // Roughness from 0 to 10^1.2 (log-uniform), and the ends beyond the range; reflectances in
                // [−0.2, 1.2].
                let value = |rng: &mut Pcg32| match rng.next_f32() {
                    u if colour => 1.4 * u - 0.2,
                    u if u < 0.1 => 0.0,
                    u if u > 0.95 => 20.0,
                    u => 10f32.powf(-4.5 + 5.7 * u),
                };
                let values: [[f32; PER_LANE]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| value(&mut rng)));
                let lane_value = if colour { LaneValue::Colour(values) } else { LaneValue::Float(values[0]) };
                let kernel = model.per_lane_kernel([(name, lane_value)]).unwrap_or_else(|| panic!("{json} {name}: a kernel"));
                let own = |l: usize| {
                    let mut own = model.clone();
                    if colour {
                        *own.reflectance_slot(name).unwrap() = Rgb::new(values[0][l], values[1][l], values[2][l]).map(textured_reflectance);
                    } else {
                        assert!(own.set_float(name, values[0][l]));
                    }
                    Some(own)
                };
                sampled += assert_lanes_are_models(&kernel, &own, &mut rng, &format!("{json} {name}"));
            }
            assert!(sampled > 1000, "{json}: {sampled} samples compared");
        }
        let float = LaneValue::Float([0.3; PER_LANE]);
        let none = [
            (r#"{"type": "roughconductor", "energy_compensation": true}"#, "alpha", float),
            (r#"{"type": "roughdielectric", "energy_compensation": true}"#, "alpha", float),
            (r#"{"type": "torrance_sparrow"}"#, "alpha", float),
            (r#"{"type": "roughplastic"}"#, "alpha", float),
            (r#"{"type": "roughplastic", "energy_compensation": true}"#, "diffuse_reflectance", LaneValue::Colour([[0.3; PER_LANE]; 3])),
            (r#"{"type": "roughplastic"}"#, "specular_reflectance", LaneValue::Colour([[0.3; PER_LANE]; 3])),
            (r#"{"type": "roughconductor"}"#, "specular_reflectance", LaneValue::Colour([[0.3; PER_LANE]; 3])),
            (r#"{"type": "roughconductor"}"#, "alpha", LaneValue::Colour([[0.3; PER_LANE]; 3])),
            (r#"{"type": "diffuse"}"#, "alpha", float),
            (r#"{"type": "principled"}"#, "roughness", float),
            (r#"{"type": "plastic"}"#, "base_color", LaneValue::Colour([[0.3; PER_LANE]; 3])),
        ];
        for (json, name, value) in none {
            assert!(Bsdf::from_json(json).unwrap().per_lane_kernel([(name, value)]).is_none(), "{json} {name}");
        }
    }

    /// Each parameter [`Bsdf::tint`] names scales its lobe and nothing else: with it at c, `f` and a
    /// sample's `f` and weight are c times theirs at 1 in the tinted lobe (to rounding) and the same in the
    /// other; `pdf`, the sampled direction and its pdf are unchanged, bit for bit. Parameters that are not
    /// pure tints (a plastic's, a principled's colour, a compensated conductor's reflectance) have none.
    #[test]
    fn tints_only_scale_their_lobe() {
        let c = Rgb::new(0.7, 0.2, 0.45);
        let cases = [
            (r#"{"type": "conductor", "material": "Au"}"#, "specular_reflectance", Tint::Reflection),
            (r#"{"type": "roughconductor", "alpha_u": 0.1, "alpha_v": 0.3}"#, "specular_reflectance", Tint::Reflection),
            (r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3}"#, "specular_reflectance", Tint::Reflection),
            (r#"{"type": "dielectric"}"#, "specular_reflectance", Tint::Reflection),
            (r#"{"type": "dielectric", "int_ior": 1.33}"#, "specular_transmittance", Tint::Transmission),
            (r#"{"type": "thindielectric"}"#, "specular_reflectance", Tint::Reflection),
            (r#"{"type": "thindielectric"}"#, "specular_transmittance", Tint::Transmission),
            (r#"{"type": "roughdielectric", "alpha": 0.2}"#, "specular_reflectance", Tint::Reflection),
            (r#"{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.4}"#, "specular_transmittance", Tint::Transmission),
        ];
        let mut rng = Pcg32::new(11, 0);
        let dir = |rng: &mut Pcg32| {
            let v = Vec3::new(2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0);
            v.try_normalize().unwrap_or(Vec3::Z)
        };
        let close = |a: Rgb, b: Rgb, what: &str| {
            for k in 0..3 {
                assert!((a.0[k] - b.0[k]).abs() <= 1e-6 * b.0[k].abs().max(1e-30) + 1e-30, "{what}: {a:?} against {b:?}");
            }
        };
        for (json, name, lobe) in cases {
            let mut at_one = Bsdf::from_json(json).unwrap();
            assert_eq!(at_one.tint(name), Some(lobe), "{json} {name}");
            let mut tinted = at_one.clone();
            *tinted.reflectance_slot(name).unwrap() = c;
            let (mut reflected, mut transmitted) = (0, 0);
            for _ in 0..2000 {
                let (wo, wi) = (dir(&mut rng), dir(&mut rng));
                let through = wo.z * wi.z < 0.0;
                let scale = if through == (lobe == Tint::Transmission) { c } else { Rgb::ONE };
                close(tinted.f(wo, wi), at_one.f(wo, wi) * scale, &format!("{json} {name}: f({wo}, {wi})"));
                assert_eq!(tinted.pdf(wo, wi).to_bits(), at_one.pdf(wo, wi).to_bits(), "{json} {name}: pdf");
                let (uc, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
                match (tinted.sample(wo, uc, u), at_one.sample(wo, uc, u)) {
                    (Some(a), Some(b)) => {
                        assert_eq!((a.wi, a.pdf.to_bits(), a.flags), (b.wi, b.pdf.to_bits(), b.flags), "{json} {name}: sample");
                        let through = wo.z * a.wi.z < 0.0;
                        let scale = if through == (lobe == Tint::Transmission) { c } else { Rgb::ONE };
                        close(a.weight, b.weight * scale, &format!("{json} {name}: weight at {wo}"));
                        close(a.f, b.f * scale, &format!("{json} {name}: sampled f at {wo}"));
                        if through {
                            transmitted += 1;
                        } else {
                            reflected += 1;
                        }
                    }
                    (None, None) => {}
                    (a, b) => panic!("{json} {name}: a sample in one model only: {a:?} {b:?}"),
                }
            }
            // Both lobes of the dielectrics were sampled (so both scales were compared).
            assert!(reflected > 100 && (transmitted > 100 || !json.contains("dielectric")), "{json}: {reflected} / {transmitted}");
        }
        for (json, name) in [
            (r#"{"type": "plastic"}"#, "diffuse_reflectance"),
            (r#"{"type": "roughplastic"}"#, "specular_reflectance"),
            (r#"{"type": "principled"}"#, "base_color"),
            (r#"{"type": "diffuse"}"#, "reflectance"),
            (r#"{"type": "roughconductor", "energy_compensation": true}"#, "specular_reflectance"),
            (r#"{"type": "conductor"}"#, "eta"),
        ] {
            assert_eq!(Bsdf::from_json(json).unwrap().tint(name), None, "{json} {name}");
        }
    }
}
