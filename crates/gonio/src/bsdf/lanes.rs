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
use crate::math::lanes::{channels, F32x8, Real, Rows8, V3};
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

/// Defines the public driver `$name`, which runs `$generic` on [`Avx8`](crate::math::avx2) lanes inside a
/// function compiled for AVX2 + FMA when the CPU has them (so that each lane operation is inlined as its
/// instruction whoever calls the driver), else on [`F32x8`].
macro_rules! driver {
    ($(#[$doc:meta])* $name:ident => $generic:ident($($arg:ident: $ty:ty),*)) => {
        $(#[$doc])*
        #[inline(always)]
        pub fn $name<K: LaneModel>(k: &K, $($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                unsafe fn with_avx2<K: LaneModel>(k: &K, $($arg: $ty),*) {
                    $generic::<crate::math::avx2::Avx8, K>(k, $($arg),*)
                }
                if crate::math::avx2::detected() {
                    // SAFETY: the CPU has the features `with_avx2` is compiled for (checked just above);
                    // `Avx8` values exist only inside it (see `math::avx2`).
                    return unsafe { with_avx2(k, $($arg),*) };
                }
            }
            $generic::<F32x8, K>(k, $($arg),*)
        }
    };
}

driver!(
    /// `out[k] = f(wo[k], wi[k])` for `k` below the shortest length, eight rows at a time.
    f_rows => f_rows_in(wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb])
);

#[inline(always)]
fn f_rows_in<R: Rows8, K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [Rgb]) {
    let n = wo.len().min(wi.len()).min(out.len());
    let full = n - n % 8;
    for ((o, i), r) in wo[..full].chunks_exact(8).zip(wi[..full].chunks_exact(8)).zip(triples(&mut out[..full]).chunks_exact_mut(8)) {
        let [r0, r1, r2] = k.f_lanes(R::load3(o), R::load3(i));
        R::store3(r0, r1, r2, r);
    }
    for j in full..n {
        out[j] = f_one(k, wo[j], wi[j]);
    }
}

driver!(
    /// `out[k] = pdf(wo[k], wi[k])` for `k` below the shortest length, eight rows at a time.
    pdf_rows => pdf_rows_in(wo: &[Vec3], wi: &[Vec3], out: &mut [f32])
);

#[inline(always)]
fn pdf_rows_in<R: Rows8, K: LaneModel>(k: &K, wo: &[Vec3], wi: &[Vec3], out: &mut [f32]) {
    let n = wo.len().min(wi.len()).min(out.len());
    let full = n - n % 8;
    for ((o, i), r) in wo[..full].chunks_exact(8).zip(wi[..full].chunks_exact(8)).zip(out[..full].chunks_exact_mut(8)) {
        k.pdf_lanes(R::load3(o), R::load3(i)).store(r);
    }
    for j in full..n {
        out[j] = pdf_one(k, wo[j], wi[j]);
    }
}

driver!(
    /// Row `k` of `out` = sample(wo[k], uc[k], u[k]) (zeros and `valid = false` where `None`), for `k` below
    /// the shortest length, eight rows at a time.
    sample_rows => sample_rows_in(wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>)
);

#[inline(always)]
fn sample_rows_in<R: Rows8, K: LaneModel>(k: &K, wo: &[Vec3], uc: &[f32], u: &[Vec2], out: &mut SampleColumns<'_>) {
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
    // Zipped chunks of eight: no bounds checks in the loop.
    let inputs = wo[..full].chunks_exact(8).zip(uc[..full].chunks_exact(8)).zip(u[..full].chunks_exact(8));
    let vectors = triples(&mut out.wi[..full])
        .chunks_exact_mut(8)
        .zip(triples(&mut out.f[..full]).chunks_exact_mut(8))
        .zip(triples(&mut out.weight[..full]).chunks_exact_mut(8));
    let numbers = out.pdf[..full]
        .chunks_exact_mut(8)
        .zip(out.flags[..full].chunks_exact_mut(8))
        .zip(out.eta[..full].chunks_exact_mut(8))
        .zip(out.valid[..full].chunks_exact_mut(8));
    for (((wo, uc), u), (((wi_out, f_out), weight_out), (((pdf_out, flags_out), eta_out), valid_out))) in inputs.zip(vectors.zip(numbers)) {
        let (ux, uy) = R::load2(u);
        let s = k.sample_lanes(R::load3(wo), R::load(uc), ux, uy);
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
    for j in full..n {
        let s = sample_one(k, wo[j], uc[j], u[j]);
        out.valid[j] = s.is_some();
        let s = s.unwrap_or(BsdfSample { wi: Vec3::ZERO, f: Rgb::ZERO, pdf: 0.0, weight: Rgb::ZERO, flags: BsdfFlags::NONE, eta: 0.0 });
        (out.wi[j], out.f[j], out.pdf[j], out.weight[j], out.flags[j], out.eta[j]) = (s.wi, s.f, s.pdf, s.weight, s.flags.0, s.eta);
    }
}
