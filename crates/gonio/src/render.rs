//! The render loop: passes of a few samples per pixel over 16×16 tiles on rayon's threads.
//!
//! Deterministic for a seed whatever the number of threads: sample `k` of pixel `i` draws from its own PCG32
//! stream ([`integrator::start`]), every tile sums its samples in order, and the tiles' sums are added to
//! the film in tile order.
//!
//! With a reconstruction filter wider than the box ([`crate::film::Filter`]), a tile splats its samples into
//! its pixels and a border of [`crate::film::Filter::border`] pixels around them, which overlaps the
//! neighbouring tiles and is added with them. Cancellation (the
//! `cancel` flag, e.g. set by Ctrl-C) is checked between tiles; the pass in flight is dropped, so the image
//! holds exactly `spp_done` samples in every pixel.

use crate::film::Film;
use crate::image::Channels;
use crate::integrator::{self, CameraSample};
use crate::scene::Scene;
use crate::spectrum::Rgb;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

const TILE: u32 = 16;

/// What a render produced.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major, top row first (the layout of `image::Image`).
    pub data: Vec<f32>,
    /// The integrator's channels after the RGB (an `aov` integrator's, [`IntegratorKind::channels`]
    /// after `R`, `G`, `B`; none for the others), filtered as the RGB is.
    ///
    /// [`IntegratorKind::channels`]: crate::scene::IntegratorKind::channels
    pub aovs: Channels,
    /// Samples per pixel in `data` (less than requested when cancelled).
    pub spp_done: u32,
    pub spp_requested: u32,
    /// Samples that were NaN or infinite, dropped (counted as black).
    pub nonfinite: u64,
    pub cancelled: bool,
    pub seconds: f64,
}

/// Sample `i`'s values for the film, in `buffer` (R, G, B and the further channels): its radiance `rgb`,
/// then its values in `aovs` (`buffer.len() − 3` per sample).
#[inline(always)]
fn sample_values<'a>(buffer: &'a mut [f32], rgb: Rgb, aovs: &[f32], i: usize) -> &'a [f32] {
    let extra = buffer.len() - 3;
    buffer[..3].copy_from_slice(&rgb.0);
    buffer[3..].copy_from_slice(&aovs[extra * i..extra * (i + 1)]);
    buffer
}

/// Pixel values of all channels (`names`, `R`, `G`, `B` first) as the RGB and the further channels.
fn split_rgb(values: Vec<f32>, names: Vec<String>) -> (Vec<f32>, Channels) {
    let k = names.len();
    if k == 3 {
        return (values, Channels::none());
    }
    let rgb = values.chunks_exact(k).flat_map(|p| p[..3].iter().copied()).collect();
    let data = values.chunks_exact(k).flat_map(|p| p[3..].iter().copied()).collect();
    (rgb, Channels { names: names[3..].to_vec(), data })
}

/// The unnormalised sums of the samples with indices in a range: one part of a render. Parts of disjoint
/// ranges add up ([`Film::add_tile`] at (0, 0)) to the sums of their union, so a render can be split over
/// processes or machines (`gonio.distributed`) and developed once with [`Film::mean`].
#[derive(Clone, Debug, PartialEq)]
pub struct SampleSums {
    /// Per-pixel sums (and, for filters other than the box, summed weights).
    pub film: Film,
    /// The first sample index of the range.
    pub first: u32,
    /// Samples per pixel summed: the indices `first .. first + spp_done` (fewer than asked when cancelled).
    pub spp_done: u32,
    /// Samples that were NaN or infinite, dropped (counted as black).
    pub nonfinite: u64,
    pub cancelled: bool,
    pub seconds: f64,
}

/// Render `spp` samples per pixel with `seed`. `progress(samples_done)` is called after every tile
/// (samples = pixel samples over the whole image); `cancel` stops the render between tiles.
/// The image is [`render_samples`] of `0..spp`, developed.
pub fn render(scene: &Scene, spp: u32, seed: u64, cancel: &AtomicBool, progress: &(dyn Fn(u64) + Sync)) -> RenderOutput {
    let part = render_samples(scene, seed, 0..spp, cancel, progress);
    let (data, aovs) = split_rgb(part.film.mean(part.spp_done), scene.integrator.channels());
    RenderOutput {
        width: part.film.width,
        height: part.film.height,
        data,
        aovs,
        spp_done: part.spp_done,
        spp_requested: spp,
        nonfinite: part.nonfinite,
        cancelled: part.cancelled,
        seconds: part.seconds,
    }
}

/// Sum the samples with indices in `samples` of every pixel, unnormalised (see [`SampleSums`]). Sample `k`
/// of a pixel is the same whichever range it is rendered in; within the range, passes of growing size
/// (1, 2, 4, 8, then 16 samples) are summed per tile from zero and added to the film in order, so
/// `render_samples(0..spp)` is exactly [`render`]'s sums. Sums of other splits of `0..spp` differ from
/// them only in the order their f64 terms are added (docs/distributed.md).
pub fn render_samples(scene: &Scene, seed: u64, samples: Range<u32>, cancel: &AtomicBool, progress: &(dyn Fn(u64) + Sync)) -> SampleSums {
    let start = Instant::now();
    let (w, h) = (scene.film.width, scene.film.height);
    let filter = &scene.film.filter;
    let border = filter.border();
    // R, G, B and the integrator's further channels (an `aov` integrator's), `extra` of them.
    let channels = scene.integrator.channels().len();
    let extra = channels - 3;
    let mut film = if filter.is_box() { Film::new(w, h, channels) } else { Film::weighted(w, h, channels) };
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE))).collect();
    let nonfinite = AtomicU64::new(0);
    let done = AtomicU64::new(0);
    let spp = samples.end.saturating_sub(samples.start);
    let mut spp_done = 0u32;
    // Passes grow so that early ones show a picture quickly and later ones keep the threads busy.
    let mut pass = 1u32;
    while spp_done < spp && !cancel.load(Ordering::Relaxed) {
        let n = pass.min(spp - spp_done);
        let first = samples.start + spp_done;
        let results: Vec<Option<Film>> = tiles
            .par_iter()
            .map(|&(x0, y0)| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let (tw, th) = (TILE.min(w - x0), TILE.min(h - y0));
                let mut tile =
                    if filter.is_box() { Film::new(tw, th, channels) } else { Film::weighted(tw + 2 * border, th + 2 * border, channels) };
                let mut bad = 0;
                // The tile's camera samples, pixel by pixel and sample by sample within a pixel; the integrator
                // may trace them in any order (several at once), and the film sums them in this one.
                // (Built with plain loops into its final size: a nested `flat_map` collected by doubling was
                // a few per cent of a render of small tiles, 2026-12.)
                let mut samples = Vec::with_capacity((tw * th * n) as usize);
                for y in y0..y0 + th {
                    for x in x0..x0 + tw {
                        samples.extend((first..first + n).map(|k| CameraSample { x, y, k }));
                    }
                }
                let mut radiance = vec![Rgb::ZERO; samples.len()];
                integrator::radiance(scene, seed, &samples, &mut radiance);
                let mut aovs = vec![0.0; extra * samples.len()];
                integrator::aov::channels(scene, seed, &samples, &radiance, &mut aovs);
                let mut buffer = vec![0.0; channels];
                // Pixel by pixel, its `n` samples in order (the tile's pixels are row-major, as `samples`).
                if filter.is_box() {
                    for (i, &l) in radiance.iter().enumerate() {
                        if !tile.add(i / n as usize, sample_values(&mut buffer, l, &aovs, i)) {
                            bad += 1;
                        }
                    }
                } else {
                    // Each sample into the (2b + 1)² pixels around its own, b = the border.
                    let taps = 2 * border as usize + 1;
                    let (mut wx, mut wy) = (vec![0.0; taps], vec![0.0; taps]);
                    for (i, (s, &l)) in samples.iter().zip(&radiance).enumerate() {
                        let u = integrator::pixel_offset(scene, seed, *s);
                        filter.weights(u.x, &mut wx);
                        filter.weights(u.y, &mut wy);
                        // The tile's pixel (x − x0, y − y0) sits at (x − x0 + b, y − y0 + b) of its buffer;
                        // the taps start b before it.
                        if !tile.splat(s.x - x0, s.y - y0, &wx, &wy, sample_values(&mut buffer, l, &aovs, i)) {
                            bad += 1;
                        }
                    }
                }
                nonfinite.fetch_add(bad, Ordering::Relaxed);
                let total = done.fetch_add(u64::from(tw * th * n), Ordering::Relaxed) + u64::from(tw * th * n);
                progress(total);
                Some(tile)
            })
            .collect();
        if results.iter().any(Option::is_none) {
            break;
        }
        for (&(x0, y0), tile) in tiles.iter().zip(results.into_iter().flatten()) {
            film.add_tile(i64::from(x0) - i64::from(border), i64::from(y0) - i64::from(border), &tile);
        }
        spp_done += n;
        pass = (pass * 2).min(16);
    }
    SampleSums {
        film,
        first: samples.start,
        spp_done,
        nonfinite: nonfinite.load(Ordering::Relaxed),
        cancelled: spp_done < spp,
        seconds: start.elapsed().as_secs_f64(),
    }
}
