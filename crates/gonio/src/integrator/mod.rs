//! Integrators: [`direct`] (the reflection equation, one bounce) and [`path`] (unidirectional path tracing),
//! both with next-event estimation combined with BSDF sampling by the power heuristic (Veach & Guibas 1995,
//! "Optimally Combining Sampling Techniques for Monte Carlo Rendering", eq. 8 with β = 2).
//!
//! [`aov`] adds Mitsuba 3's arbitrary output variables (values at the camera rays' first hits) beside the
//! image of a nested integrator.
//!
//! The two techniques below are shared: [`sample_emitter`] (a light sample and its weight) and
//! [`emitter_hit`] (radiance found by a BSDF-sampled ray and its weight).

pub mod aov;
pub mod direct;
pub mod path;

use crate::bsdf::{Bsdf, BsdfModel};
use crate::geometry::ray::RayLanes;
use crate::geometry::{Ray, SurfaceInteraction};
use crate::light::selection::SelectionSums;
use crate::math::lanes::Real;
use crate::math::simd::Float8;
use crate::sampling::mis::power_heuristic;
use crate::sampling::{Pcg32, Pcg32x8};
use crate::scene::{IntegratorKind, Scene};
use crate::spectrum::Rgb;
use glam::Vec3;

/// One camera sample: sample number `k` of pixel (`x`, `y`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CameraSample {
    pub x: u32,
    pub y: u32,
    pub k: u32,
}

/// Mix a seed and a sample index into a PCG32 seed (the SplitMix64 finaliser, Steele et al. 2014).
#[inline]
pub(crate) fn mix(seed: u64, sample: u64) -> u64 {
    let mut z = seed.wrapping_add(sample.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The start of a camera sample's path: its own PCG32 stream, `Pcg32::new(mix(seed, k), pixel index)`, and
/// the camera ray through a uniformly jittered point of its pixel, drawn from that stream (the film then
/// weights the sample by its reconstruction filter), and for a thin lens through the lens point drawn next.
#[inline]
#[must_use]
pub fn start(scene: &Scene, seed: u64, s: CameraSample) -> (Ray, Pcg32) {
    let (offset, mut rng) = stream_and_offset(scene, seed, s);
    let (x, y) = film_point(scene, s.x as f32, s.y as f32, offset.x, offset.y);
    // A thin lens takes the next two numbers for its lens point; a pinhole none.
    let lens = if scene.camera.has_lens() { glam::Vec2::new(rng.next_f32(), rng.next_f32()) } else { glam::Vec2::splat(0.5) };
    (scene.camera.ray_through_lens(glam::Vec2::new(x, y), lens), rng)
}

/// Where in its pixel camera sample `s` lies: (ux, uy) ∈ [0, 1)², the first two numbers of its stream
/// (as [`start`] draws them), for the film to splat it with its reconstruction filter.
#[inline]
#[must_use]
pub fn pixel_offset(scene: &Scene, seed: u64, s: CameraSample) -> glam::Vec2 {
    stream_and_offset(scene, seed, s).0
}

/// A camera sample's generator and the pixel offset drawn first from it.
#[inline(always)]
fn stream_and_offset(scene: &Scene, seed: u64, s: CameraSample) -> (glam::Vec2, Pcg32) {
    let mut rng = Pcg32::new(mix(seed, u64::from(s.k)), pixel_index(scene, s));
    let offset = glam::Vec2::new(rng.next_f32(), rng.next_f32());
    (offset, rng)
}

/// Where camera sample `s`'s hero wavelength lies in spectral mode (the `uc` ∈ [0, 1) of
/// [`sample_path_wavelengths`], its other two at +1/3 and +2/3): the base-2 radical inverse of its number
/// `k` (van der Corput), rotated by an offset drawn once per pixel from the seed.
///
/// Any `2ᵐ` consecutive samples of a pixel from a multiple of `2ᵐ` put their heroes one in each `2⁻ᵐ` of
/// [0, 1), and their three wavelengths one in each `1/(3·2ᵐ)`: the run's heroes are the rotation r plus
/// j/2ᵐ (j = 0 … 2ᵐ − 1, wrapped), and a position's place within its third, 3·uc mod 1, is 3r plus 3j/2ᵐ,
/// the same comb permuted (3 and 2ᵐ are coprime). Every prefix of a pixel's samples is spread nearly as evenly,
/// and sample `k` has its position whichever range renders it. So the film's estimate of a pixel's colour
/// (the CIE functions over the density, smooth) keeps almost no variance from the wavelengths, with all
/// three or with the hero alone behind dispersive glass, where drawing `uc` per path independently left
/// three wavelengths far noisier than Mitsuba 3's four (docs/spectral.md). The rotation makes each
/// sample's `uc` uniform on its own, as the estimator needs, and pixels independent; pbrt-v4 gets the same
/// from its samplers' wavelength dimension.
///
/// [`sample_path_wavelengths`]: crate::spectrum::sampled::sample_path_wavelengths
#[inline(always)]
#[must_use]
pub(crate) fn wavelength_stratum(scene: &Scene, seed: u64, s: CameraSample) -> f32 {
    // The pixel's rotation: 32 bits of a hash of the seed (kept apart from the paths' streams, which hash
    // the sample's number) and the pixel.
    #[allow(clippy::cast_possible_truncation)]
    let rotation = (mix(mix(seed, WAVELENGTH_STREAM), pixel_index(scene, s)) >> 32) as u32;
    let bits = rotation.wrapping_add(s.k.reverse_bits());
    // The top 24 bits: exact in f32, below 1.
    #[allow(clippy::cast_precision_loss)]
    let stratum = (bits >> 8) as f32 * (1.0 / 16_777_216.0);
    stratum
}

/// What [`wavelength_stratum`] mixes into the seed (any constant other than the samples' numbers' range).
const WAVELENGTH_STREAM: u64 = 0x7761_7665_6c65_6e67;

/// The stream of a camera sample's generator: its pixel's row-major index.
#[inline(always)]
fn pixel_index(scene: &Scene, s: CameraSample) -> u64 {
    u64::from(s.y) * u64::from(scene.film.width) + u64::from(s.x)
}

/// The point of pixel (`x`, `y`) offset by (`ux`, `uy`), in film coordinates [0, 1]².
#[inline(always)]
fn film_point<R: Real>(scene: &Scene, x: R, y: R, ux: R, uy: R) -> (R, R) {
    ((x + ux) / R::splat(scene.film.width as f32), (y + uy) / R::splat(scene.film.height as f32))
}

/// [`start`] for eight camera samples at once, in the lanes of `lanes` (lane `i` for `samples[i]`, whose
/// seed `mixed[i]` is [`mix`]`(seed, k)`, computed by the caller for the starting lanes alone): each lane's
/// generator in `rng` is started as `start` starts it and its ray is the one `start` returns, by the same
/// operations in lanes. The other lanes of `rng` are left as they were; their rays mean nothing.
#[inline(always)]
pub fn start_lanes(scene: &Scene, mixed: &[u64; 8], samples: &[CameraSample; 8], lanes: u32, rng: &mut Pcg32x8) -> RayLanes<Float8> {
    rng.seed(lanes, mixed, &samples.map(|s| pixel_index(scene, s)));
    let (ux, uy) = (rng.next_f32(lanes), rng.next_f32(lanes));
    let (x, y) = (Float8::from_fn(|i| samples[i].x as f32), Float8::from_fn(|i| samples[i].y as f32));
    let (x, y) = film_point(scene, x, y, ux, uy);
    if scene.camera.has_lens() {
        let (lx, ly) = (rng.next_f32(lanes), rng.next_f32(lanes));
        return scene.camera.rays_through_lens(x, y, lx, ly);
    }
    scene.camera.rays(x, y)
}

/// The radiance of each camera sample (`out[i]` for `samples[i]`), by the scene's integrator (for `aov`, by
/// its first nested integrator, [`IntegratorKind::rgb`]: black when it has none).
pub fn radiance(scene: &Scene, seed: u64, samples: &[CameraSample], out: &mut [Rgb]) {
    radiance_by(&scene.integrator, scene, seed, samples, out);
}

/// [`radiance`] by integrator `kind` (a `path` or `direct`; an `aov` renders its first nested one).
pub(crate) fn radiance_by(kind: &IntegratorKind, scene: &Scene, seed: u64, samples: &[CameraSample], out: &mut [Rgb]) {
    match *kind {
        IntegratorKind::Path { max_depth, rr_depth, hide_emitters } => {
            path::radiance(scene, seed, samples, out, path::Settings::path(max_depth, rr_depth, hide_emitters));
        }
        // The path tracer's estimator at max_depth 2 with the integrator's sample counts, with the random
        // numbers of the scalar `direct::radiance` in the same order: the same image bit for bit (test
        // `direct_is_the_path_tracer_at_depth_two`), rendered in packets (2026-12-05: with one sample of
        // each 2.3× faster than the scalar loop on the benchmark's area-lights-shapes; with 4 light
        // samples and none of the BSDF, Mitsuba's `scenes/hello.xml`, 2.49 -> 1.25 s CPU).
        IntegratorKind::Direct { emitter_samples, bsdf_samples, hide_emitters } => {
            let settings = path::Settings { max_depth: 2, rr_depth: i32::MAX, hide_emitters, light_samples: emitter_samples, bsdf_samples };
            path::radiance(scene, seed, samples, out, settings);
        }
        IntegratorKind::Aov { .. } => match kind.rgb() {
            Some(inner) => radiance_by(inner, scene, seed, samples, out),
            None => out.fill(Rgb::ZERO),
        },
    }
}

/// The `direct` integrator one camera sample at a time ([`direct::radiance`]): the scalar reference the
/// packets are tested against.
pub fn direct_each(
    scene: &Scene,
    seed: u64,
    samples: &[CameraSample],
    out: &mut [Rgb],
    emitter_samples: u32,
    bsdf_samples: u32,
    hide_emitters: bool,
) {
    for (s, l) in samples.iter().zip(out) {
        let (ray, mut rng) = start(scene, seed, *s);
        *l = direct::radiance(scene, &ray, &mut rng, emitter_samples, bsdf_samples, hide_emitters);
    }
}

/// How a direction was sampled at the previous vertex, for weighting an emitter it hits.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSampled {
    /// The vertex the ray left from.
    pub from: Vec3,
    /// Solid-angle density of the BSDF sample.
    pub pdf: f32,
    /// The sample came from a delta lobe (light sampling could not have produced it).
    pub delta: bool,
    /// Number of BSDF samples taken there (`n_b` of the power heuristic), and of light samples (`n_l`).
    pub n_bsdf: f32,
    pub n_light: f32,
    /// The light choice's sums at `from`, where a light was sampled there (`LightSelection::pmf_with`).
    pub sums: Option<SelectionSums>,
}

/// Next-event estimation at `si`: choose a light ([`LightSelection`](crate::light::LightSelection)), sample it, and return
/// f · |cos θi| · Lᵢ · w / p_light, with w the power-heuristic weight against `n_bsdf` BSDF samples.
/// `wo` is local; the caller divides by its number of light samples.
pub fn sample_emitter(scene: &Scene, si: &SurfaceInteraction, wo: Vec3, bsdf: &Bsdf, rng: &mut Pcg32, n_light: f32, n_bsdf: f32) -> Rgb {
    let n = scene.lights.len();
    if n == 0 {
        return Rgb::ZERO;
    }
    let (index, pmf, _) = scene.light_selection.sample(&scene.lights, si.p, rng.next_f32());
    let (uc, u) = (rng.next_f32(), rng.next_vec2());
    let Some(ls) = scene.lights[index].sample_li(&scene.shapes, si.p, si.n, uc, u) else { return Rgb::ZERO };
    if !(ls.pdf > 0.0) || ls.li.is_black() {
        return Rgb::ZERO;
    }
    let wi = si.shading.to_local(ls.wi);
    let f = bsdf.f(wo, wi);
    if f.is_black() || scene.occluded(&ls.shadow) {
        return Rgb::ZERO;
    }
    let light_pdf = ls.pdf * pmf;
    let w = if ls.delta || n_bsdf == 0.0 { 1.0 } else { power_heuristic(n_light, light_pdf, n_bsdf, bsdf.pdf(wo, wi)) };
    f * ls.li * (wi.z.abs() * w / light_pdf)
}

/// Radiance reaching the previous vertex along a BSDF-sampled ray that found `hit` (or escaped when
/// `None`), weighted against light sampling.
pub fn emitter_hit(scene: &Scene, ray: &Ray, hit: Option<&SurfaceInteraction>, prev: Option<&BsdfSampled>) -> Rgb {
    // The previous vertex where light sampling could also have found this emitter (not after a delta lobe,
    // nor for camera rays): only there is Le weighted, and only there are the light's densities needed.
    let weighted = prev.filter(|p| !p.delta && p.n_light > 0.0);
    // The probability of choosing light `index` at that vertex.
    let pmf = |p: &BsdfSampled, index: usize| match p.sums {
        Some(sums) => scene.light_selection.pmf_with(&scene.lights, p.from, index, sums),
        None => scene.light_selection.pmf(&scene.lights, p.from, index),
    };
    let (le, light_pdf) = match hit {
        Some(si) => {
            let Some(index) = scene.shape_lights[si.shape as usize] else { return Rgb::ZERO };
            let crate::light::Light::Area(area) = &scene.lights[index as usize] else { return Rgb::ZERO };
            let le = area.radiance_towards(si.shading.n, -ray.d);
            if le.is_black() {
                return Rgb::ZERO;
            }
            let shape = &scene.shapes[si.shape as usize];
            (le, weighted.map_or(0.0, |p| area.pdf_li(shape, p.from, si) * pmf(p, index as usize)))
        }
        None => {
            let Some(index) = scene.environment else { return Rgb::ZERO };
            let Some((le, pdf)) = scene.lights[index as usize].environment(ray.d) else { return Rgb::ZERO };
            (le, weighted.map_or(0.0, |p| pdf * pmf(p, index as usize)))
        }
    };
    match weighted {
        Some(p) => le * power_heuristic(p.n_bsdf, p.pdf, p.n_light, light_pdf),
        None => le,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mitsuba_xml;
    use std::path::Path;

    /// A pixel's heroes: every aligned run of 2ᵐ samples puts one in each 2⁻ᵐ of [0, 1) (the 16 of 0..16,
    /// the 32 of 32..64), and one of its three wavelengths in each 2⁻ᵐ of every third; one sample's is
    /// uniform over pixels, and pixels are rotated apart.
    #[test]
    fn wavelength_strata_spread_over_a_pixels_samples() {
        let xml = r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm">
            <integer name="width" value="8"/><integer name="height" value="4"/></film></sensor></scene>"#;
        let scene = Scene::build(mitsuba_xml::load_str(xml, "strata.xml", Path::new("."), &[]).unwrap()).unwrap();
        let strata = |x: u32, y: u32, ks: std::ops::Range<u32>| -> Vec<f32> {
            ks.map(|k| wavelength_stratum(&scene, 7, CameraSample { x, y, k })).collect()
        };
        for (x, y) in [(0, 0), (5, 3)] {
            for (ks, n) in [(0..16, 16usize), (32..64, 32)] {
                let s = strata(x, y, ks.clone());
                // The heroes, and the places within their thirds of all three wavelengths (3·uc mod 1).
                for thirds in [false, true] {
                    let mut seen = vec![false; n];
                    for &w in &s {
                        assert!((0.0..1.0).contains(&w), "{w}");
                        let v = if thirds { (f64::from(w) * 3.0).fract() } else { f64::from(w) };
                        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
                        let bin = (v * n as f64) as usize;
                        assert!(!seen[bin], "pixel ({x}, {y}), samples {ks:?} (thirds {thirds}): two in bin {bin}: {s:?}");
                        seen[bin] = true;
                    }
                }
            }
        }
        assert_ne!(strata(0, 0, 0..1), strata(5, 3, 0..1));
        assert_ne!(strata(0, 0, 0..1), strata(1, 0, 0..1));
        // Over pixels, one sample's position is uniform: 20 bins of 20 000 pixels each within 5 standard
        // deviations.
        let mut bins = [0u32; 20];
        for i in 0..400_000 {
            let w = wavelength_stratum(&scene, 7, CameraSample { x: i % 8, y: i / 8, k: 5 });
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let bin = (w * 20.0) as usize;
            bins[bin] += 1;
        }
        for n in bins {
            assert!((f64::from(n) - 20_000.0).abs() < 5.0 * 20_000f64.sqrt(), "{bins:?}");
        }
        // Another seed rotates the pixel elsewhere.
        assert_ne!(
            wavelength_stratum(&scene, 7, CameraSample { x: 0, y: 0, k: 0 }),
            wavelength_stratum(&scene, 8, CameraSample { x: 0, y: 0, k: 0 })
        );
    }
}
