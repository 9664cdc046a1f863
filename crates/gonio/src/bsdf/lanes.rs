//! SIMD kernels: a model's `f`, `pdf` and `sample` written once over [`Real`] lanes, run eight rows at a
//! time by the batch methods and one row at a time by the single calls — so a batch equals the single calls
//! bit for bit by construction (test `bsdf::tests::batches_equal_single_calls`).
//!
//! A model (or one configuration of it, e.g. GGX with visible-normal sampling) that has a kernel implements
//! [`LaneModel`]; its `BsdfModel` methods call [`f_one`], [`pdf_one`], [`sample_one`] for that
//! configuration, and its batch methods [`f_rows`], [`pdf_rows`], [`sample_rows`] (through the
//! `lane_batch_methods!` macro). The drivers load eight rows into structure-of-arrays lanes
//! ([`V3<F32x8>`](V3)), run the kernel and store the lanes back; the last rows (fewer than eight) run on
//! single `f32`s. Compiled inside `simd_batch!`'s AVX2 + FMA function, each lane operation is one 256-bit
//! instruction. Measured with callgrind (instructions per row, 10⁵ rows, one thread, 2026-11; `cargo run
//! --release --example batch_rows`): see the table in that example's doc.

use super::{BsdfFlags, BsdfSample, SampleColumns};
use crate::math::lanes::{channels, F32x8, Real, V3};
use crate::math::{Vec2, Vec3};
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

    /// No sample in any lane.
    #[inline(always)]
    pub fn none(valid: R::Mask) -> Self {
        let zero = R::splat(0.0);
        LaneSample { wi: V3::new(zero, zero, zero), f: [zero; 3], pdf: zero, weight: [zero; 3], flags: zero, eta: zero, valid }
    }
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

/// `out[k] = f(wo[k], wi[k])` for `k` below the shortest length, eight rows at a time.
#[inline(always)]
pub fn f_rows<K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb]) {
    let n = wo.len().min(wi.len()).min(out.len());
    let full = n - n % 8;
    for ((o, i), r) in wo[..full].chunks_exact(8).zip(wi[..full].chunks_exact(8)).zip(out[..full].chunks_exact_mut(8)) {
        let f = k.f_lanes(V3::load(o), V3::load(i));
        for (l, r) in r.iter_mut().enumerate() {
            *r = Rgb([f[0].0[l], f[1].0[l], f[2].0[l]]);
        }
    }
    for j in full..n {
        out[j] = f_one(k, wo[j], wi[j]);
    }
}

/// `out[k] = pdf(wo[k], wi[k])` for `k` below the shortest length, eight rows at a time.
#[inline(always)]
pub fn pdf_rows<K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [f32]) {
    let n = wo.len().min(wi.len()).min(out.len());
    let full = n - n % 8;
    for ((o, i), r) in wo[..full].chunks_exact(8).zip(wi[..full].chunks_exact(8)).zip(out[..full].chunks_exact_mut(8)) {
        r.copy_from_slice(&k.pdf_lanes(V3::load(o), V3::load(i)).0);
    }
    for j in full..n {
        out[j] = pdf_one(k, wo[j], wi[j]);
    }
}

/// Row `k` of `out` = sample(wo[k], uc[k], u[k]) (zeros and `valid = false` where `None`), for `k` below
/// the shortest length, eight rows at a time.
#[inline(always)]
pub fn sample_rows<K: LaneModel>(k: &K, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>) {
    let n = [
        wo.len(),
        uc.len(),
        u.len(),
        out.wi.len(),
        out.f.len(),
        out.pdf.len(),
        out.weight.len(),
        out.flags.len(),
        out.eta.len(),
        out.valid.len(),
    ]
    .into_iter()
    .min()
    .unwrap_or(0);
    let full = n - n % 8;
    for start in (0..full).step_by(8) {
        let rows = start..start + 8;
        let (ux, uy) = F32x8::load2(&u[rows.clone()]);
        let s = k.sample_lanes(V3::load(&wo[rows.clone()]), F32x8::load(&uc[rows.clone()]), ux, uy);
        // Invalid lanes are zero in every field.
        let zero = F32x8::splat(0.0);
        let (wx, wy, wz) =
            (F32x8::select(s.valid, s.wi.x, zero), F32x8::select(s.valid, s.wi.y, zero), F32x8::select(s.valid, s.wi.z, zero));
        let f = channels!(|c| F32x8::select(s.valid, s.f[c], zero));
        let weight = channels!(|c| F32x8::select(s.valid, s.weight[c], zero));
        let (pdf, flags, eta) =
            (F32x8::select(s.valid, s.pdf, zero), F32x8::select(s.valid, s.flags, zero), F32x8::select(s.valid, s.eta, zero));
        for l in 0..8 {
            let j = start + l;
            out.wi[j] = Vec3::new(wx.0[l], wy.0[l], wz.0[l]);
            out.f[j] = Rgb([f[0].0[l], f[1].0[l], f[2].0[l]]);
            out.weight[j] = Rgb([weight[0].0[l], weight[1].0[l], weight[2].0[l]]);
            out.pdf[j] = pdf.0[l];
            out.flags[j] = flags.0[l] as u32;
            out.eta[j] = eta.0[l];
            out.valid[j] = s.valid.get(l);
        }
    }
    for j in full..n {
        let s = sample_one(k, wo[j], uc[j], u[j]);
        out.valid[j] = s.is_some();
        let s = s.unwrap_or(BsdfSample { wi: Vec3::ZERO, f: Rgb::ZERO, pdf: 0.0, weight: Rgb::ZERO, flags: BsdfFlags::NONE, eta: 0.0 });
        (out.wi[j], out.f[j], out.pdf[j], out.weight[j], out.flags[j], out.eta[j]) = (s.wi, s.f, s.pdf, s.weight, s.flags.0, s.eta);
    }
}
