//! `path` — unidirectional path tracing with next-event estimation and MIS (Veach 1997, ch. 9 and 10),
//! with Mitsuba 3's depth conventions:
//!
//! | parameter       | type    | default | meaning                                                                   |
//! |-----------------|---------|---------|---------------------------------------------------------------------------|
//! | `max_depth`     | integer | −1      | longest path in segments (−1: unbounded; 1: emitters only; 2: direct light) |
//! | `rr_depth`      | integer | 5       | Russian roulette from this depth on                                       |
//! | `hide_emitters` | boolean | false   | emitters seen directly by the camera are black                            |
//!
//! Russian roulette as Mitsuba: continue with probability q = min(max(β) · η², 0.95), β the throughput
//! and η the accumulated relative index of refraction, and divide β by q.
//!
//! # Eight paths at a time
//! Paths are traced in packets of eight, one per lane ([`W`]), bounce by bounce: every phase of a bounce
//! (trace, emission found, next-event estimation, BSDF sampling, Russian roulette) runs for all the packet's
//! paths before the next phase, so that the arithmetic of the phases can run in SIMD lanes. A lane whose
//! path ends takes the next camera sample (path regeneration, Novák et al. 2010, "GPU Computing: Path
//! Regeneration"), so the lanes stay busy until the samples run out: at the top of the next bounce, and
//! also right after the trace where paths escaped there (their lanes' new camera rays are traced before the
//! packet shades; see `MIN_READY`). Each path
//! draws from its own random stream in the order a path traced alone would, so the packet changes nothing
//! but the speed.

use super::{emitter_hit, mix, start_lanes, wavelength_stratum, BsdfSampled, CameraSample};
use crate::bsdf::diffuse::{diffuse_f, diffuse_pdf, diffuse_sample};
use crate::bsdf::lanes::{LaneModel, LaneSample};
use crate::bsdf::{Bsdf, BsdfModel, PerLaneKernel};
use crate::geometry::bvh::{bits, groups};
use crate::geometry::mesh::uniform_triangle_point;
use crate::geometry::ray::{offset_origin_lanes, spawn_ray_to_lanes, RayLanes};
use crate::geometry::shape::solid_angle_density;
use crate::geometry::sphere::sample_sphere_from;
use crate::geometry::{Ray, Shape};
use crate::light::area::towards;
use crate::light::point::point_source_lanes;
use crate::light::selection::SelectionSums;
use crate::light::{Light, LightSample};
use crate::math::lanes::{Real, V3};
use crate::math::simd::{Float8, Mask8};
use crate::math::{Vec2, Vec3};
use crate::sampling::mis::power_heuristic_lanes;
use crate::sampling::warp::uniform_sphere;
use crate::sampling::Pcg32x8;
use crate::scene::spectral::{reflectances_at, Dependence, GivenSpectra};
use crate::scene::surfaces::{Rows3, Surfaces8};
use crate::scene::Scene;
use crate::spectrum::sampled::{path_to_linear_srgb, sample_path_wavelengths, PATH_WAVELENGTHS};
use crate::spectrum::Rgb;
use std::borrow::Cow;

/// Paths per packet.
pub const W: usize = 8;

/// The parameters of the table above.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    pub max_depth: i32,
    pub rr_depth: i32,
    pub hide_emitters: bool,
    /// Light and BSDF samples at a vertex, combined by the power heuristic with these counts (Veach &
    /// Guibas 1995, eq. 8): the `direct` integrator's `emitter_samples` and `bsdf_samples`; the path tracer
    /// takes one of each. Other than one BSDF sample needs `max_depth` 2: the path cannot go on along several.
    pub light_samples: u32,
    pub bsdf_samples: u32,
}

impl Settings {
    /// The path tracer's: one light and one BSDF sample per vertex.
    #[must_use]
    pub fn path(max_depth: i32, rr_depth: i32, hide_emitters: bool) -> Self {
        Settings { max_depth, rr_depth, hide_emitters, light_samples: 1, bsdf_samples: 1 }
    }
}

/// Rays as rows of lanes.
#[derive(Clone, Copy, Debug, Default)]
struct RayRows {
    o: Rows3,
    d: Rows3,
    tmax: [f32; W],
}

impl RayRows {
    #[inline(always)]
    fn set(&mut self, lane: usize, r: &Ray) {
        self.o.set(lane, r.o);
        self.d.set(lane, r.d);
        self.tmax[lane] = r.tmax;
    }

    /// The lanes of `r` where `m` is set.
    #[inline(always)]
    fn merge(&mut self, m: Mask8, r: &RayLanes<Float8>) {
        let (o, d) = (V3::select(m, r.o, self.o.lanes()), V3::select(m, r.d, self.d.lanes()));
        self.o.store(o);
        self.d.store(d);
        self.tmax = Float8::select(m, r.tmax, Float8::load(&self.tmax)).to_array();
    }
}

/// Eight paths in flight.
struct Packet {
    /// Lanes holding a path (bit `i` for lane `i`).
    live: u32,
    /// The camera sample (index into the caller's slice) of each lane.
    sample: [usize; W],
    rng: Pcg32x8,
    /// Segments traced so far.
    depth: [i32; W],
    /// The ray to trace next (`tmax` the camera's far clip for camera rays, else infinite).
    o: Rows3,
    d: Rows3,
    tmax: [f32; W],
    /// Throughput and radiance gathered.
    beta: Rows3,
    l: Rows3,
    /// Accumulated relative index of refraction.
    eta: [f32; W],
    /// How the ray was sampled at the vertex it leaves (for weighting an emitter it finds): the vertex,
    /// the BSDF sample's density, and whether it came from a delta lobe (bit per lane).
    from: Rows3,
    pdf: [f32; W],
    delta: u32,
    /// The light choice's sums at that vertex (`LightSelection::sample`'s), in the lanes of `sums_at`:
    /// the lanes that sampled a light there.
    sums: [SelectionSums; W],
    sums_at: u32,
    /// In spectral mode ([`Mode::Spectral`]), each lane's wavelengths (channel `c` of lane `l` in row `c`)
    /// and their densities ([`sample_path_wavelengths`]); unused in RGB mode.
    spectral: bool,
    lambda: Rows3,
    lambda_pdf: Rows3,
    /// The lanes that follow their hero wavelength alone ([`Packet::terminate_secondary`]).
    terminated: u32,
}

impl Packet {
    fn new() -> Self {
        Packet {
            live: 0,
            sample: [0; W],
            rng: Pcg32x8::default(),
            depth: [0; W],
            o: Rows3::default(),
            d: Rows3::default(),
            tmax: [f32::INFINITY; W],
            beta: Rows3::default(),
            l: Rows3::default(),
            eta: [1.0; W],
            from: Rows3::default(),
            pdf: [0.0; W],
            delta: 0,
            sums: [SelectionSums::UNIFORM; W],
            sums_at: 0,
            spectral: false,
            lambda: Rows3::default(),
            lambda_pdf: Rows3::default(),
            terminated: 0,
        }
    }

    /// Lane `lane`'s wavelengths.
    #[inline(always)]
    fn lambda(&self, lane: usize) -> [f32; 3] {
        self.lambda.get(lane).to_array()
    }

    /// The lanes' wavelengths, per channel.
    #[inline(always)]
    fn lambda_lanes(&self) -> [Float8; 3] {
        let l = self.lambda.lanes();
        [l.x, l.y, l.z]
    }

    /// Lanes `lanes` (new paths) take their wavelengths, in spectral mode: the hero at each one's camera
    /// sample's stratum (`strata`, [`wavelength_stratum`]).
    #[inline(always)]
    fn sample_wavelengths(&mut self, lanes: u32, strata: &[f32; W]) {
        let (lambda, pdf) = sample_path_wavelengths(Float8::load(strata));
        let m = Mask8::from_bitmask(lanes);
        self.lambda.store(V3::select(m, V3::new(lambda[0], lambda[1], lambda[2]), self.lambda.lanes()));
        self.lambda_pdf.store(V3::select(m, V3::new(pdf[0], pdf[1], pdf[2]), self.lambda_pdf.lanes()));
    }

    /// In spectral mode, the live lanes on a dispersive material ([`Dependence::Dispersion`]) follow their
    /// hero wavelength alone from here: its model refracts each wavelength its own way, and the lane's copy
    /// runs at the hero's ([`reflectances_at`]). The other wavelengths' throughput becomes 0 and the hero's
    /// is multiplied by their number, so that the film's average over the wavelengths
    /// ([`path_to_linear_srgb`]) counts the hero for all of them: the estimate of one wavelength drawn with
    /// the same density, unbiased (pbrt-v4's `TerminateSecondary`, Wilkie et al. 2014 §4). Once per path.
    #[inline(always)]
    fn terminate_secondary(&mut self, scene: &Scene, hit: &Surfaces8) {
        let Some(spectral) = &scene.spectral else { return };
        for lane in bits(self.live & !self.terminated) {
            if spectral.dependence.get(hit.shape[lane] as usize) == Some(&Dependence::Dispersion) {
                let beta = self.beta.get(lane);
                #[allow(clippy::cast_precision_loss)]
                self.beta.set(lane, Vec3::new(beta.x * PATH_WAVELENGTHS as f32, 0.0, 0.0));
                self.terminated |= 1 << lane;
            }
        }
    }

    /// Emission `le` (linear RGB) found by lanes `lanes`, each from light `light(lane)`, as the path carries
    /// it: unchanged in RGB mode, and at each lane's wavelengths in spectral mode
    /// ([`SpectralScene::emission`](crate::scene::SpectralScene::emission)).
    ///
    /// The lanes of one light whose spectrum is fitted from its colour are evaluated together
    /// ([`SpectralScene::fitted_emission`](crate::scene::SpectralScene::fitted_emission), which
    /// `SpectralScene::emission` is at one lane), the others lane by lane.
    #[inline(always)]
    fn emission(&self, scene: &Scene, le: [Float8; 3], lanes: u32, light: impl Fn(usize) -> Option<usize>) -> [Float8; 3] {
        let Some(spectral) = &scene.spectral else { return le };
        let lights: [Option<usize>; W] = std::array::from_fn(|lane| if lanes >> lane & 1 != 0 { light(lane) } else { None });
        let same = |lane: usize| (0..W).filter(|&l| lights[l] == lights[lane]).fold(0u32, |m, l| m | 1 << l);
        let (mut out, mut alone) = (le, 0u32);
        for (lane, group) in groups(lanes, same) {
            let Some(values) = spectral.fitted_emission(lights[lane], le, self.lambda_lanes()) else {
                alone |= group;
                continue;
            };
            let m = Mask8::from_bitmask(group);
            for c in 0..3 {
                out[c] = Float8::select(m, values[c], out[c]);
            }
        }
        map_lanes(out, alone, |lane, rgb| spectral.emission(lights[lane], rgb, self.lambda(lane)))
    }

    /// The probability of choosing light `index` at the vertex lane `lane`'s ray left
    /// (`LightSelection::pmf`; from the light choice's sums there where that vertex sampled a light).
    #[inline]
    fn pmf(&self, scene: &Scene, lane: usize, index: usize) -> f32 {
        let (selection, x) = (&scene.light_selection, self.from.get(lane));
        match self.sums(lane) {
            Some(sums) => selection.pmf_with(&scene.lights, x, index, sums),
            None => selection.pmf(&scene.lights, x, index),
        }
    }

    /// The light choice's sums at the vertex lane `lane`'s ray left, where that vertex sampled a light.
    #[inline(always)]
    fn sums(&self, lane: usize) -> Option<SelectionSums> {
        (self.sums_at & (1 << lane) != 0).then_some(self.sums[lane])
    }

    #[inline(always)]
    fn ray(&self, lane: usize) -> Ray {
        Ray::new(self.o.get(lane), self.d.get(lane), self.tmax[lane])
    }

    /// Lanes `lanes` start paths along `rays` (their camera samples and generators already set).
    #[inline(always)]
    fn start(&mut self, lanes: u32, rays: &RayLanes<Float8>) {
        self.live |= lanes;
        self.terminated &= !lanes;
        let m = Mask8::from_bitmask(lanes);
        self.o.store(V3::select(m, rays.o, self.o.lanes()));
        self.d.store(V3::select(m, rays.d, self.d.lanes()));
        self.tmax = Float8::select(m, rays.tmax, Float8::load(&self.tmax)).to_array();
        self.beta.store(V3::select(m, V3::splat(Vec3::ONE), self.beta.lanes()));
        self.l.store(V3::select(m, V3::splat(Vec3::ZERO), self.l.lanes()));
        self.eta = Float8::select(m, Float8::splat(1.0), Float8::load(&self.eta)).to_array();
        // As bit patterns in float lanes, stored by `to_array`: a loop here became a masked store (slow on
        // AMD's cores: see `Avx8::to_array`).
        let depth = Float8::load(&self.depth.map(|d| f32::from_bits(d as u32)));
        self.depth = Float8::select(m, Float8::splat(0.0), depth).to_array().map(|d| d.to_bits() as i32);
    }

    /// The live paths' rays leave their vertices: one more segment each.
    #[inline(always)]
    fn deepen(&mut self) {
        for (i, depth) in self.depth.iter_mut().enumerate() {
            *depth += (self.live >> i & 1) as i32;
        }
    }

    /// Diffuse reflectances `rho` (linear RGB) of lanes `lanes`, each on shape `shape(lane)`, at each lane's
    /// wavelengths (spectral mode; [`SpectralScene::reflectance`](crate::scene::SpectralScene::reflectance)).
    #[inline(always)]
    fn reflectance(&self, scene: &Scene, rho: [Float8; 3], lanes: u32, shape: impl Fn(usize) -> usize) -> [Float8; 3] {
        let Some(spectral) = &scene.spectral else { return rho };
        map_lanes(rho, lanes, |lane, rgb| spectral.reflectance(shape(lane), rgb, self.lambda(lane)))
    }

    /// Lane `lane`'s path ends: its radiance goes to `out`.
    #[inline(always)]
    fn finish(&mut self, lane: usize, out: &mut [Rgb]) {
        out[self.sample[lane]] = if self.spectral {
            path_to_linear_srgb(self.lambda(lane), self.lambda_pdf.get(lane).to_array(), self.l.get(lane).to_array())
        } else {
            self.l.rgb(lane)
        };
        self.live &= !(1 << lane);
    }
}

/// `values` with each lane of `lanes` replaced by `f(lane, its three values)`.
#[inline(always)]
fn map_lanes(values: [Float8; 3], lanes: u32, f: impl Fn(usize, [f32; 3]) -> [f32; 3]) -> [Float8; 3] {
    let mut rows = values.map(|c| c.to_array());
    for lane in bits(lanes) {
        let v = f(lane, [rows[0][lane], rows[1][lane], rows[2][lane]]);
        for (row, v) in rows.iter_mut().zip(v) {
            row[lane] = v;
        }
    }
    rows.map(|r| Float8::load(&r))
}

#[inline(always)]
fn load_rgb(r: &Rows3) -> [Float8; 3] {
    let v = r.lanes();
    [v.x, v.y, v.z]
}

#[inline(always)]
fn store_rgb(r: &mut Rows3, v: [Float8; 3]) {
    r.store(V3::new(v[0], v[1], v[2]));
}

/// `v` in the frame (s, t, n), as [`crate::math::Frame::to_local`].
#[inline(always)]
fn to_local(s: V3<Float8>, t: V3<Float8>, n: V3<Float8>, v: V3<Float8>) -> V3<Float8> {
    V3::new(v.dot(s), v.dot(t), v.dot(n))
}

/// `v` from the frame (s, t, n) to world space, as [`crate::math::Frame::to_world`].
#[inline(always)]
fn to_world(s: V3<Float8>, t: V3<Float8>, n: V3<Float8>, v: V3<Float8>) -> V3<Float8> {
    s.scale(v.x).add(t.scale(v.y)).add(n.scale(v.z))
}

/// The mask of the lanes `i` (all [`W`] of them, live or not) where `f(i)` holds: a fixed loop, which
/// compiles to comparisons without branches, where a loop over a mask's set lanes mispredicts its exit.
#[inline(always)]
fn lanes_where(f: impl Fn(usize) -> bool) -> u32 {
    (0..W).fold(0, |m, i| m | u32::from(f(i)) << i)
}

/// The packet shades once at least this many of its lanes hold a surface: while fewer do (paths escaped
/// or ended at the trace), the free lanes take camera samples and their rays are traced first. The
/// shading phases cost about the same for a few lanes as for eight, a trace of a few rays less than one of
/// eight (a lone ray traverses alone). 2026-12: on the material spheres 45 % of the rays traced escape to
/// the sky (a floor bounce, mostly), and with shading at once the packets shaded 4.4 lanes on average;
/// with 6 here the render took 14.2 % fewer instructions and 0.79–0.82 × the time (two alternations
/// with the build before), with 5, 7 and 8 within a percent of that in instructions (8 the most); the Cornell box
/// (16 % escape) the same within 0.3 %. Images are the same: each path draws from its own stream.
const MIN_READY: u32 = 6;

/// A model's lane dispatch ([`Bsdf::f_lanes_where`] and friends), out of line: inlined, every model's kernel
/// (and each composite's copy of them) became part of [`radiance`], and LLVM's SROA pass spent 3.5 minutes
/// on that one function in every build (2026-12-04). One call per group of lanes per bounce costs nothing
/// measurable. `Float8` is the build's base lane type, so these compile with the features its code needs.
#[inline(never)]
fn f_where(model: &Bsdf, wo: V3<Float8>, wi: V3<Float8>, m: Mask8) -> [Float8; 3] {
    model.f_lanes_where(wo, wi, m)
}

/// See [`f_where`].
#[inline(never)]
fn pdf_where(model: &Bsdf, wo: V3<Float8>, wi: V3<Float8>, m: Mask8) -> Float8 {
    model.pdf_lanes_where(wo, wi, m)
}

/// See [`f_where`].
#[inline(never)]
fn sample_where(model: &Bsdf, wo: V3<Float8>, uc: Float8, ux: Float8, uy: Float8, m: Mask8) -> LaneSample<Float8> {
    model.sample_lanes_where(wo, uc, ux, uy, m)
}

/// Trace the rays of lanes `lanes` into `hit` (their lanes of it; the others keep theirs) and add the
/// emission they find, divided by `share` (the number of BSDF samples taken together: 1 but at the `direct`
/// integrator's several). Returns the lanes whose paths end there: escaped, or at the longest length.
#[inline(always)]
fn trace(scene: &Scene, p: &mut Packet, lanes: u32, hit: &mut Surfaces8, settings: Settings, share: f32) -> u32 {
    let Settings { max_depth, hide_emitters, light_samples, bsdf_samples, .. } = settings;
    let rays = RayLanes { o: p.o.lanes(), d: p.d.lanes(), tmax: Float8::load(&p.tmax) };
    let found = scene.intersect_rays(&rays, lanes);
    scene.surfaces_into(&rays, &found, lanes, hit);

    // Emission found by the ray (looked up only where the surface emits or an environment is seen), in
    // lanes L += β Le, Le zero elsewhere (as a path traced alone adds it: a non-finite β spoils the
    // sample either way); paths that escaped or reached the longest length end.
    let mut le = Rows3::default();
    let t = found.t.to_array();
    let first = lanes & lanes_where(|i| p.depth[i] == 0);
    let shown = lanes & !(if hide_emitters { first } else { 0 });
    // An environment seen (constant or a map), in lanes: `emitter_hit`'s Le · w, with w the power heuristic
    // against light sampling (1 after a delta lobe, for camera rays and without light samples).
    let (mut sky, mut sky_le) = (0u32, [Float8::splat(0.0); 3]);
    let environment = scene.environment.map(|i| &scene.lights[i as usize]);
    let seen = match environment {
        Some(Light::Constant(constant)) => Some((constant.radiance.0.map(Float8::splat), Float8::splat(constant.pdf_li(Vec3::Z)))),
        Some(Light::EnvMap(env)) if shown & !hit.found != 0 => {
            // In spectral mode at each lane's wavelengths already (`EnvMap::eval_lanes_at`).
            let lambda = p.lambda_lanes();
            let e = env.eval_lanes_at(p.d.lanes(), shown & !hit.found, p.spectral.then_some(&lambda));
            Some((e.li, e.pdf))
        }
        _ => None,
    };
    if let Some((radiance, pdf)) = seen {
        sky = shown & !hit.found;
        // The probability of choosing the environment at the vertex the ray left, where it is weighted
        // (not for camera rays nor after a delta lobe, whose lanes keep weight 1).
        let env = scene.environment.unwrap_or(0) as usize;
        let unweighted = first | p.delta | if light_samples == 0 { lanes } else { 0 };
        let pmf = Float8::from_fn(|l| if sky & !unweighted & (1 << l) != 0 { p.pmf(scene, l, env) } else { 1.0 });
        let light_pdf = pdf * pmf;
        let unweighted = Mask8::from_bitmask(unweighted);
        let (n_bsdf, n_light) = (Float8::splat(bsdf_samples as f32), Float8::splat(light_samples as f32));
        let w = power_heuristic_lanes(n_bsdf, Float8::load(&p.pdf), n_light, light_pdf);
        let w = Float8::select(unweighted, Float8::splat(1.0), w);
        sky_le = radiance.map(|c| w * c);
    }
    // Other emitters seen, lane by lane: emitting surfaces.
    let escaped = if scene.environment.is_some() { lanes & !hit.found & !sky } else { 0 };
    for lane in bits(shown & (hit.emits | escaped)) {
        let prev = (first & (1 << lane) == 0).then(|| BsdfSampled {
            from: p.from.get(lane),
            pdf: p.pdf[lane],
            delta: p.delta & (1 << lane) != 0,
            n_bsdf: bsdf_samples as f32,
            n_light: light_samples as f32,
            sums: p.sums(lane),
        });
        let si = (hit.found & (1 << lane) != 0).then(|| hit.interaction(lane, t[lane]));
        le.set_rgb(lane, emitter_hit(scene, &p.ray(lane), si.as_ref(), prev.as_ref()));
    }
    let le = load_rgb(&le);
    let le: [Float8; 3] = std::array::from_fn(|c| Float8::select(Mask8::from_bitmask(sky), sky_le[c], le[c]));
    // Each lane's light: an emitting surface's, or the environment where the ray escaped.
    let light_of = |lane: usize| {
        if hit.found & (1 << lane) != 0 {
            scene.shape_lights.get(hit.shape[lane] as usize).copied().flatten().map(|i| i as usize)
        } else {
            scene.environment.map(|i| i as usize)
        }
    };
    let spectral_sky = if matches!(environment, Some(Light::EnvMap(_))) { sky } else { 0 };
    let le = p.emission(scene, le, (sky | (shown & (hit.emits | escaped))) & !spectral_sky, light_of);
    let (mut l, beta) = (load_rgb(&p.l), load_rgb(&p.beta));
    let m = Mask8::from_bitmask(lanes);
    for c in 0..3 {
        let found = beta[c] * le[c];
        let found = if share == 1.0 { found } else { found / Float8::splat(share) };
        l[c] = Float8::select(m, l[c] + found, l[c]);
    }
    store_rgb(&mut p.l, l);
    // A vertex at `depth` can extend the path only if the next one is within max_depth.
    let longest = if max_depth >= 0 { lanes_where(|i| p.depth[i] >= max_depth - 1) } else { 0 };
    lanes & (!hit.found | longest)
}

/// The packet's surfaces as the shading phases see them: the reflectance of the diffuse lanes, the models of
/// the others grouped by instance, the shading frames and ωo in them.
struct Shading<'a> {
    rho: [Float8; 3],
    diffuse: u32,
    /// The lanes whose model has a smooth component.
    smooth: u32,
    models: [Option<Cow<'a, Bsdf>>; W],
    /// The groups of lanes of one model instance (lanes, first lane), `n_groups` of them.
    groups: [(u32, usize); W],
    n_groups: usize,
    /// Each group's kernel with a parameter per lane, if it has one (it runs instead of the model).
    kernels: [Option<PerLaneKernel<'a>>; W],
    /// The shading frames (s, t, n).
    frame: (V3<Float8>, V3<Float8>, V3<Float8>),
    wo: V3<Float8>,
    /// The lanes of tinted materials ([`Material::tinted_lanes`](crate::scene::Material::tinted_lanes)),
    /// whose model's values are scaled by their tints of reflection (`tint[0]`) and transmission (`tint[1]`);
    /// 1 in the other lanes.
    tinted: u32,
    tint: [[Float8; 3]; 2],
}

impl Shading<'_> {
    fn groups(&self) -> &[(u32, usize)] {
        &self.groups[..self.n_groups]
    }

    /// f of group `g`'s model (or its kernel) in lanes `m`.
    fn f(&self, g: usize, wo: V3<Float8>, wi: V3<Float8>, m: Mask8) -> [Float8; 3] {
        match &self.kernels[g] {
            Some(k) => k.f_lanes(wo, wi),
            None => f_where(self.model(self.groups[g].1), wo, wi, m),
        }
    }

    /// pdf of group `g`'s model (or its kernel) in lanes `m`.
    fn pdf(&self, g: usize, wo: V3<Float8>, wi: V3<Float8>, m: Mask8) -> Float8 {
        match &self.kernels[g] {
            Some(k) => k.pdf_lanes(wo, wi),
            None => pdf_where(self.model(self.groups[g].1), wo, wi, m),
        }
    }

    /// A sample of group `g`'s model (or its kernel) in lanes `m`.
    fn sample(&self, g: usize, wo: V3<Float8>, uc: Float8, ux: Float8, uy: Float8, m: Mask8) -> LaneSample<Float8> {
        match &self.kernels[g] {
            Some(k) => {
                let s = k.sample_lanes(wo, uc, ux, uy);
                LaneSample { valid: s.valid & m, ..s }
            }
            None => sample_where(self.model(self.groups[g].1), wo, uc, ux, uy, m),
        }
    }

    fn model(&self, lane: usize) -> &Bsdf {
        self.models[lane].as_deref().expect("a model for every non-diffuse lane")
    }

    fn to_local(&self, v: V3<Float8>) -> V3<Float8> {
        to_local(self.frame.0, self.frame.1, self.frame.2, v)
    }

    fn to_world(&self, v: V3<Float8>) -> V3<Float8> {
        to_world(self.frame.0, self.frame.1, self.frame.2, v)
    }

    /// `values` of the models towards `wi` (local: `f`, or a sample's weight) scaled in tinted lanes by the
    /// tint of the lobe `wi` lies in (transmission where ωo and ωi are on opposite sides).
    #[inline(always)]
    fn tinted(&self, wi: V3<Float8>, values: [Float8; 3]) -> [Float8; 3] {
        if self.tinted == 0 {
            return values;
        }
        let through = (self.wo.z * wi.z).lt(Float8::splat(0.0));
        std::array::from_fn(|c| values[c] * Float8::select(through, self.tint[1][c], self.tint[0][c]))
    }
}

/// The live lanes' materials at their surfaces in `hit`: diffuse ones are evaluated in lanes, the others by
/// their model.
#[inline(always)]
fn shading<'a>(scene: &'a Scene, p: &Packet, hit: &Surfaces8) -> Shading<'a> {
    // The lanes on one shape, or on shapes of one constant reflectance (`Scene::material_class`), share
    // their material: a constant, checkerboard or bitmap reflectance is found for them together, other
    // materials lane by lane.
    let (mut rho, mut rho_rows, mut diffuse, mut diffuse_rows) = ([Float8::splat(0.0); 3], Rows3::default(), 0u32, 0u32);
    let (mut tint, mut tinted) = ([[Float8::splat(1.0); 3]; 2], 0u32);
    let mut models: [Option<Cow<'_, Bsdf>>; W] = Default::default();
    // Groups of lanes running a kernel with a parameter per lane: one per material, found here.
    let (mut groups_of, mut n_groups, mut kernels, mut grouped) = ([(0u32, 0usize); W], 0usize, std::array::from_fn(|_| None), 0u32);
    let (u, v) = (Float8::load(&hit.uv[0]), Float8::load(&hit.uv[1]));
    // Without a branch per lane (a lane without a hit holds shape 0 or the shape of an earlier hit in it
    // (`Scene::surfaces_into`): a valid index either way, and an out-of-range one would read as no class).
    let class: [u32; W] = std::array::from_fn(|l| {
        let c = scene.material_class.get(hit.shape[l] as usize).copied().unwrap_or(u32::MAX);
        if p.live & (1 << l) != 0 {
            c
        } else {
            u32::MAX
        }
    });
    for (first, same) in groups(p.live, |l| p.live & lanes_where(|k| class[k] == class[l])) {
        let material = &scene.materials[hit.shape[first] as usize];
        // In spectral mode, a material with colours runs a copy of its model per lane, at the lane's
        // wavelengths (`spectral::reflectances_at`); diffuse ones are converted in `rho` below.
        let chromatic =
            scene.spectral.as_ref().is_some_and(|s| s.dependence.get(hit.shape[first] as usize).is_some_and(|d| *d != Dependence::None));
        if let Some(r) = material.diffuse_reflectance_lanes(u, v, same) {
            let r = p.reflectance(scene, r, same, |_| hit.shape[first] as usize);
            let m = Mask8::from_bitmask(same);
            rho = std::array::from_fn(|c| Float8::select(m, r[c], rho[c]));
            diffuse |= same;
            continue;
        }
        // A textured material whose textures only tint its model or set parameters it takes per lane: that
        // one model (or its kernel with each lane's values) for all its lanes, each lane's values scaled by
        // its tints (`Shading::tinted`).
        if let Some(lm) = material.lanes_at(u, v, same).filter(|_| !chromatic) {
            if lm.tinted {
                let m = Mask8::from_bitmask(same);
                for (lobe, t) in tint.iter_mut().zip(lm.tints) {
                    *lobe = std::array::from_fn(|c| Float8::select(m, t[c], lobe[c]));
                }
                tinted |= same;
            }
            for lane in bits(same) {
                models[lane] = Some(Cow::Borrowed(lm.model));
            }
            if lm.kernel.is_some() {
                (groups_of[n_groups], kernels[n_groups]) = ((same, first), lm.kernel);
                n_groups += 1;
                grouped |= same;
            }
            continue;
        }
        for lane in bits(same) {
            let uv = Vec2::new(hit.uv[0][lane], hit.uv[1][lane]);
            match material.diffuse_reflectance(uv) {
                Some(r) => {
                    rho_rows.set_rgb(lane, r);
                    diffuse_rows |= 1 << lane;
                }
                None => {
                    let model = if material.reads_surface() { scene.bsdf_at(&hit.interaction(lane, 0.0)) } else { material.at(uv) };
                    models[lane] = Some(if chromatic {
                        let mut model = model.into_owned();
                        let given = scene.spectral.as_ref().and_then(|s| s.given.get(hit.shape[lane] as usize));
                        reflectances_at(&mut model, p.lambda(lane), given.unwrap_or(&GivenSpectra::NONE));
                        Cow::Owned(model)
                    } else {
                        model
                    });
                }
            }
        }
        // Spectral mode's copies of one model at each lane's wavelengths: one kernel call for them where the
        // model has such a kernel (`Bsdf::kernel_of_lanes`), instead of one call per lane.
        let modelled = if chromatic { bits(same).filter(|&l| models[l].is_some()).fold(0u32, |m, l| m | 1 << l) } else { 0 };
        if modelled.count_ones() > 1 {
            let lanes: [Option<&Bsdf>; W] = std::array::from_fn(|l| if modelled & (1 << l) != 0 { models[l].as_deref() } else { None });
            let first = modelled.trailing_zeros() as usize;
            if let Some(kernel) = material.model().and_then(|m| m.kernel_of_lanes(&lanes)) {
                (groups_of[n_groups], kernels[n_groups]) = ((modelled, first), Some(kernel));
                n_groups += 1;
                grouped |= modelled;
            }
        }
    }
    if diffuse_rows != 0 {
        let r = load_rgb(&rho_rows);
        let r = p.reflectance(scene, r, diffuse_rows, |l| hit.shape[l] as usize);
        let m = Mask8::from_bitmask(diffuse_rows);
        rho = std::array::from_fn(|c| Float8::select(m, r[c], rho[c]));
        diffuse |= diffuse_rows;
    }
    // The other lanes grouped by model instance (lanes on one shape share their material's model; a
    // textured material's model is its own lane's): each group calls its model once, in lanes
    // (`Bsdf::f_lanes_where` and friends: the model's kernel, or its single calls lane by lane).
    for lane in bits(p.live & !diffuse) {
        if grouped & (1 << lane) != 0 {
            continue;
        }
        let same = match models[lane] {
            Some(Cow::Borrowed(model)) => bits(p.live & !diffuse & !grouped)
                .filter(|&l| matches!(models[l], Some(Cow::Borrowed(m)) if std::ptr::eq(m, model)))
                .fold(0u32, |m, l| m | 1 << l),
            _ => 1 << lane,
        };
        groups_of[n_groups] = (same, lane);
        n_groups += 1;
        grouped |= same;
    }
    let frame = (hit.s.lanes(), hit.t.lanes(), hit.ns.lanes());
    let wo = to_local(frame.0, frame.1, frame.2, p.d.lanes().neg());
    // The lanes whose model has a smooth component: next-event estimation serves them.
    let smooth = diffuse
        | bits(p.live & !diffuse).fold(0, |m, lane| m | (u32::from(models[lane].as_ref().is_some_and(|b| b.flags().has_smooth())) << lane));
    Shading { rho, diffuse, smooth, models, groups: groups_of, n_groups, kernels, frame, wo, tinted, tint }
}

/// Next-event estimation on the lanes whose model has a smooth component: `light_samples` times, a light
/// chosen (`LightSelection::sample`) and sampled, its contribution weighted against the BSDF samples by the
/// power heuristic.
#[inline(always)]
fn next_event(scene: &Scene, p: &mut Packet, hit: &Surfaces8, sh: &Shading<'_>, settings: Settings) {
    let (smooth, n, n_lights) = (sh.smooth, settings.light_samples, scene.lights.len());
    // The lanes whose light choice at this vertex (the `from` of the rays sampled next) is kept.
    p.sums_at = if n_lights > 0 && n > 0 { smooth } else { 0 };
    if smooth == 0 || n == 0 {
        return;
    }
    let beta = load_rgb(&p.beta);
    if n_lights == 0 {
        // No light: L += β · 0, as a path traced alone does.
        let (mut l, smooth) = (load_rgb(&p.l), Mask8::from_bitmask(smooth));
        for c in 0..3 {
            l[c] = Float8::select(smooth, l[c] + beta[c] * Float8::splat(0.0), l[c]);
        }
        store_rgb(&mut p.l, l);
        return;
    }
    for _ in 0..n {
        light_sample(scene, p, hit, sh, settings, beta);
    }
}

/// The light samples of a packet's lanes as the lights draw them: direction, radiance arriving (before
/// the samples' scale, such as a point light's 1/d²), solid-angle density and shadow ray, in the lanes of
/// `sampled` (`delta` those from a delta light).
#[derive(Default)]
struct LightSamples {
    wi: Rows3,
    li: Rows3,
    pdf: [f32; W],
    shadow: RayRows,
    sampled: u32,
    delta: u32,
}

impl LightSamples {
    /// Lanes `m` receive radiance `li`.
    #[inline(always)]
    fn set_li(&mut self, m: Mask8, li: V3<Float8>) {
        self.li.store(V3::select(m, li, self.li.lanes()));
    }

    /// Lanes `ok` have a sample: direction `wi` of density `pdf`, tested along `shadow`.
    #[inline(always)]
    fn accept(&mut self, ok: Mask8, wi: V3<Float8>, pdf: Float8, shadow: &RayLanes<Float8>) {
        self.wi.store(V3::select(ok, wi, self.wi.lanes()));
        self.pdf = Float8::select(ok, pdf, Float8::load(&self.pdf)).to_array();
        self.shadow.merge(ok, shadow);
        self.sampled |= ok.bitmask();
    }

    /// Lane `lane` has the sample `ls`, drawn by its light alone.
    #[inline(always)]
    fn set(&mut self, lane: usize, ls: &LightSample) {
        self.wi.set(lane, ls.wi);
        self.li.set_rgb(lane, ls.li);
        self.pdf[lane] = ls.pdf;
        self.delta |= u32::from(ls.delta) << lane;
        self.shadow.set(lane, &ls.shadow);
        self.sampled |= 1 << lane;
    }
}

/// One light sample of [`next_event`] for each lane of `sh.smooth`: L += β · f · Lᵢ · |cos θi| · w /
/// (p_light · light_samples).
#[inline(always)]
fn light_sample(scene: &Scene, p: &mut Packet, hit: &Surfaces8, sh: &Shading<'_>, settings: Settings, beta: [Float8; 3]) {
    let smooth = sh.smooth;
    // The light, chosen per lane. For an area light on a flat mesh (the common case) the triangle, and
    // the point on it in lanes; environments, point lights and spheres in lanes; other lights in full
    // per lane.
    let mut drawn = LightSamples::default();
    // The lanes whose radiance an environment map gave at their wavelengths already (spectral mode).
    let mut spectral_li = 0u32;
    let (mut tri, mut tri_n, mut tri_ns, mut pdf_area) = ([Rows3::default(); 3], Rows3::default(), Rows3::default(), Float8::splat(0.0));
    let mut on_mesh = 0u32;
    let (mut sph_center, mut sph_radius, mut sph_inward, mut on_sphere) = (Rows3::default(), Float8::splat(1.0), 0u32, 0u32);
    let (mut pt_position, mut on_point) = (Rows3::default(), 0u32);
    let u_light = p.rng.next_f32(smooth);
    let (u_c, u_x, u_y) = (p.rng.next_f32(smooth), p.rng.next_f32(smooth), p.rng.next_f32(smooth));
    // The light of each lane and the probability of its choice (`LightSelection::sample_lanes`).
    let (mut chosen, mut pmf) = ([0.0f32; W], [1.0f32; W]);
    let choices = scene.light_selection.sample_lanes(&scene.lights, hit.p.lanes(), u_light, smooth);
    for lane in bits(smooth) {
        let (index, q, sums) = choices[lane];
        (chosen[lane], pmf[lane], p.sums[lane]) = (index as f32, q, sums);
    }
    let chosen_lanes = Float8::load(&chosen);
    // The lanes that chose the same light, in lanes where it is an environment (constant or a map:
    // `ConstantLight::sample_li`, `EnvMap::sample_lanes`; the surfaces' normals are never zero), a
    // point light or a sphere (their positions, centres and radii gathered, then `point_source_lanes`
    // and `sample_sphere_from` for all of them at once) or a small flat mesh (a `rectangle` light, say:
    // its triangles chosen and loaded in lanes).
    let (sp, sn) = (hit.p.lanes(), hit.n.lanes());
    let mut rest = smooth;
    for (first, same) in groups(smooth, |l| chosen_lanes.eq(Float8::splat(chosen[l])).bitmask()) {
        let index = chosen[first] as usize;
        let m = Mask8::from_bitmask(same);
        if let Light::Constant(constant) = &scene.lights[index] {
            if !constant.radiance.is_black() {
                let dir = uniform_sphere(u_x, u_y);
                let ray = RayLanes { o: offset_origin_lanes(sp, sn, dir), d: dir, tmax: Float8::splat(f32::INFINITY) };
                drawn.set_li(m, V3::splat(Vec3::from_array(constant.radiance.0)));
                drawn.accept(m, dir, Float8::splat(constant.pdf_li(Vec3::Z)), &ray);
            }
            rest &= !same;
            continue;
        }
        if let Light::EnvMap(env) = &scene.lights[index] {
            // `EnvMap::sample_li` in lanes (the surfaces' normals are never zero), where the sample
            // carries light.
            let lambda = p.lambda_lanes();
            let s = env.sample_lanes_at(u_c, u_x, u_y, same, p.spectral.then_some(&lambda));
            spectral_li |= same;
            let zero = Float8::splat(0.0);
            let ok = s.valid & m & (s.li[0].ne(zero) | s.li[1].ne(zero) | s.li[2].ne(zero));
            let ray = RayLanes { o: offset_origin_lanes(sp, sn, s.wi), d: s.wi, tmax: Float8::splat(f32::INFINITY) };
            drawn.set_li(ok, V3::new(s.li[0], s.li[1], s.li[2]));
            drawn.accept(ok, s.wi, s.pdf, &ray);
            rest &= !same;
            continue;
        }
        if let Light::Point(point) = &scene.lights[index] {
            if !point.intensity.is_black() {
                pt_position.store(V3::select(m, V3::splat(point.position), pt_position.lanes()));
                drawn.set_li(m, V3::splat(Vec3::from_array(point.intensity.0)));
                on_point |= same;
            }
            rest &= !same;
            continue;
        }
        if let Light::Area(area) = &scene.lights[index] {
            if let Shape::Sphere(sphere) = &scene.shapes[area.shape as usize] {
                if !area.radiance.is_black() {
                    sph_center.store(V3::select(m, V3::splat(sphere.center), sph_center.lanes()));
                    sph_radius = Float8::select(m, Float8::splat(sphere.radius), sph_radius);
                    sph_inward |= if sphere.flip_normals { same } else { 0 };
                    drawn.set_li(m, V3::splat(Vec3::from_array(area.radiance.0)));
                    on_sphere |= same;
                }
                rest &= !same;
                continue;
            }
        }
        let (Light::Area(area), Some(tris)) = (&scene.lights[index], &scene.light_triangles[index]) else {
            continue;
        };
        let (vertices, ng, ns) = tris.sample(u_c);
        for (rows, v) in tri.iter_mut().zip(vertices) {
            rows.store(V3::select(m, v, rows.lanes()));
        }
        tri_n.store(V3::select(m, ng, tri_n.lanes()));
        tri_ns.store(V3::select(m, ns, tri_ns.lanes()));
        pdf_area = Float8::select(m, Float8::splat(tris.density), pdf_area);
        drawn.set_li(m, V3::splat(Vec3::from_array(area.radiance.0)));
        on_mesh |= same;
        rest &= !same;
    }
    let (uc_rows, ux_rows, uy_rows) = (u_c.to_array(), u_x.to_array(), u_y.to_array());
    for lane in bits(rest) {
        let index = chosen[lane] as usize;
        let (uc, u) = (uc_rows[lane], Vec2::new(ux_rows[lane], uy_rows[lane]));
        let light = &scene.lights[index];
        if let Light::Area(area) = light {
            if let Shape::Mesh(mesh) = &scene.shapes[area.shape as usize] {
                if let Some((vertices, ng, ns, density)) = mesh.sample_flat_triangle(uc) {
                    if !area.radiance.is_black() {
                        for (rows, v) in tri.iter_mut().zip(vertices) {
                            rows.set(lane, v);
                        }
                        tri_n.set(lane, ng);
                        tri_ns.set(lane, ns);
                        pdf_area = Float8::select(Mask8::from_bitmask(1 << lane), Float8::splat(density), pdf_area);
                        drawn.li.set_rgb(lane, area.radiance);
                        on_mesh |= 1 << lane;
                    }
                    continue;
                }
            }
        }
        let Some(ls) = light.sample_li(&scene.shapes, hit.p.get(lane), hit.n.get(lane), uc, u) else { continue };
        if !(ls.pdf > 0.0) || ls.li.is_black() {
            continue;
        }
        drawn.set(lane, &ls);
    }
    if on_point != 0 {
        // `PointLight::sample_li` in lanes, each lane with its light: a delta sample.
        let (dir, inv_dist2, valid, ray) = point_source_lanes(pt_position.lanes(), sp, sn);
        let ok = valid & Mask8::from_bitmask(on_point);
        drawn.set_li(ok, drawn.li.lanes().scale(inv_dist2));
        drawn.accept(ok, dir, Float8::splat(1.0), &ray);
        drawn.delta |= ok.bitmask();
    }
    if on_sphere != 0 {
        // `AreaLight::sample_li` on spheres, in lanes, each lane with its sphere.
        let inward = Mask8::from_bitmask(sph_inward);
        let (q, n, pdf, valid) = sample_sphere_from(sph_center.lanes(), sph_radius, inward, sp, u_x, u_y);
        let (dir, facing) = towards(sp, q, n, pdf);
        let ok = valid & facing & Mask8::from_bitmask(on_sphere);
        let ray = spawn_ray_to_lanes(sp, sn, q, n);
        drawn.accept(ok, dir, pdf, &ray);
    }
    if on_mesh != 0 {
        // `AreaLight::sample_li` on a flat mesh, in lanes.
        let q = uniform_triangle_point(tri[0].lanes(), tri[1].lanes(), tri[2].lanes(), u_x, u_y);
        let ng = tri_n.lanes();
        let (pdf, by_area) = solid_angle_density(sp, q, ng, pdf_area);
        // Emission faces the shading normal (a mesh file's flat normals may oppose its winding).
        let (dir, facing) = towards(sp, q, tri_ns.lanes(), pdf);
        let ray = spawn_ray_to_lanes(sp, sn, q, ng);
        let ok = by_area & facing & Mask8::from_bitmask(on_mesh);
        drawn.accept(ok, dir, pdf, &ray);
    }
    let LightSamples { wi, li, pdf: mut light_pdf, shadow, sampled, delta } = drawn;
    for (v, p) in light_pdf.iter_mut().zip(pmf) {
        *v *= p;
    }
    let wi_local = sh.to_local(wi.lanes());
    // f and the BSDF's density: in lanes for diffuse surfaces, by the model for the others.
    let (rho, wo) = (sh.rho, sh.wo);
    let mut f = diffuse_f(rho, wo, wi_local);
    let mut bsdf_pdf = diffuse_pdf(wo, wi_local);
    for (g, &(lanes, _)) in sh.groups().iter().enumerate() {
        let lanes = lanes & sampled;
        if lanes == 0 {
            continue;
        }
        let m = Mask8::from_bitmask(lanes);
        let fk = sh.f(g, wo, wi_local, m);
        for c in 0..3 {
            f[c] = Float8::select(m, fk[c], f[c]);
        }
        let pdf = Float8::select(Mask8::from_bitmask(delta), Float8::splat(0.0), sh.pdf(g, wo, wi_local, m));
        bsdf_pdf = Float8::select(m, pdf, bsdf_pdf);
    }
    let f = sh.tinted(wi_local, f);
    // Shadow rays where the sample carries light.
    let nonzero = (f[0].ne(Float8::splat(0.0)) | f[1].ne(Float8::splat(0.0)) | f[2].ne(Float8::splat(0.0))).bitmask();
    let tested = sampled & nonzero;
    let rays = RayLanes { o: shadow.o.lanes(), d: shadow.d.lanes(), tmax: Float8::load(&shadow.tmax) };
    let visible = tested & !scene.occluded_rays(&rays, tested);
    // L += β · f · Lᵢ · |cos θi| · w / (p_light · n), or β · 0 where the sample carries nothing (as a path
    // traced alone adds it: a non-finite β spoils the sample either way); w is 1 for a delta light and
    // without BSDF samples.
    let light_pdf = Float8::load(&light_pdf);
    let (n_light, n_bsdf) = (settings.light_samples as f32, settings.bsdf_samples as f32);
    let w = power_heuristic_lanes(Float8::splat(n_light), light_pdf, Float8::splat(n_bsdf), bsdf_pdf);
    let unweighted = delta | if n_bsdf == 0.0 { smooth } else { 0 };
    let w = Float8::select(Mask8::from_bitmask(unweighted), Float8::splat(1.0), w);
    let scale = wi_local.z.abs() * w / light_pdf;
    let li = p.emission(scene, load_rgb(&li), visible & !spectral_li, |lane| Some(chosen[lane] as usize));
    let mut l = load_rgb(&p.l);
    let (visible, smooth) = (Mask8::from_bitmask(visible), Mask8::from_bitmask(smooth));
    for c in 0..3 {
        let ne = Float8::select(visible, f[c] * li[c] * scale, Float8::splat(0.0));
        let ne = if n_light == 1.0 { ne } else { ne / Float8::splat(n_light) };
        l[c] = Float8::select(smooth, l[c] + beta[c] * ne, l[c]);
    }
    store_rgb(&mut p.l, l);
}

/// BSDF sampling at the packet's surfaces: in lanes for diffuse surfaces, by the model for the others. Each
/// live lane's next ray is set, with how it was sampled (for weighting the emitter it finds) and the
/// accumulated relative index of refraction η. Returns the lanes with a sample, the samples' weights
/// f · |cos θi| / p and η.
#[inline(always)]
fn sample_bsdf(p: &mut Packet, hit: &Surfaces8, sh: &Shading<'_>) -> (u32, [Float8; 3], Float8) {
    let (uc, ux, uy) = (p.rng.next_f32(p.live), p.rng.next_f32(p.live), p.rng.next_f32(p.live));
    let (diffuse, wo) = (sh.diffuse, sh.wo);
    let ds = diffuse_sample(sh.rho, wo, ux, uy);
    let mut valid = ds.valid.bitmask() & diffuse;
    let (mut s_wi, mut s_pdf, mut s_eta, mut s_weight) = (ds.wi, ds.pdf, ds.eta, ds.weight);
    let mut s_delta = 0u32;
    for (g, &(lanes, _)) in sh.groups().iter().enumerate() {
        let m = Mask8::from_bitmask(lanes);
        let s = sh.sample(g, wo, uc, ux, uy, m);
        s_wi = V3::select(m, s.wi, s_wi);
        for (w, k) in s_weight.iter_mut().zip(s.weight) {
            *w = Float8::select(m, k, *w);
        }
        (s_pdf, s_eta) = (Float8::select(m, s.pdf, s_pdf), Float8::select(m, s.eta, s_eta));
        valid |= (s.valid & m).bitmask();
        s_delta |= (s.is_delta() & m).bitmask();
    }
    let s_weight = sh.tinted(s_wi, s_weight);
    let eta = Float8::load(&p.eta) * s_eta;
    let wi = sh.to_world(s_wi);
    let sp = hit.p.lanes();
    p.o.store(offset_origin_lanes(sp, hit.n.lanes(), wi));
    p.d.store(wi);
    p.tmax = [f32::INFINITY; W];
    p.from.store(sp);
    p.pdf = s_pdf.to_array();
    p.eta = eta.to_array();
    p.delta = s_delta;
    (valid, s_weight, eta)
}

/// The radiance of each camera sample (`out[i]` for `samples[i]`), eight paths at a time.
pub fn radiance(scene: &Scene, seed: u64, samples: &[CameraSample], out: &mut [Rgb], settings: Settings) {
    let Settings { max_depth, rr_depth, bsdf_samples, .. } = settings;
    if max_depth == 0 {
        out.fill(Rgb::ZERO);
        return;
    }
    let mut p = Packet { spectral: scene.spectral.is_some(), ..Packet::new() };
    // The surfaces the packet shades, and those the `direct` integrator's several BSDF samples find.
    let (mut hit, mut found) = (Surfaces8::default(), Surfaces8::default());
    let mut next = 0;
    loop {
        // Trace until enough lanes hold a surface to shade (`MIN_READY`) or the samples run out: lanes
        // without a path take the next camera samples, and the rays of the lanes not traced yet (`pending`:
        // first the paths carried from the last bounce) are traced. A path that escapes or ends here frees
        // its lane for another camera sample at once, so that the shading phases below run on full packets.
        let mut pending = p.live;
        loop {
            let (mut fill, mut chosen, mut mixed) = (0u32, [CameraSample { x: 0, y: 0, k: 0 }; W], [0u64; W]);
            let mut strata = [0.0f32; W];
            for lane in bits(!p.live & ((1 << W) - 1)) {
                if next == samples.len() {
                    break;
                }
                (chosen[lane], p.sample[lane], mixed[lane]) = (samples[next], next, mix(seed, u64::from(samples[next].k)));
                if p.spectral {
                    strata[lane] = wavelength_stratum(scene, seed, samples[next]);
                }
                fill |= 1 << lane;
                next += 1;
            }
            if fill != 0 {
                let rays = start_lanes(scene, &mixed, &chosen, fill, &mut p.rng);
                p.start(fill, &rays);
                if p.spectral {
                    p.sample_wavelengths(fill, &strata);
                }
            }
            pending |= fill;
            if pending == 0 {
                break;
            }
            for lane in bits(trace(scene, &mut p, pending, &mut hit, settings, 1.0)) {
                p.finish(lane, out);
            }
            pending = 0;
            if p.live.count_ones() >= MIN_READY || next == samples.len() {
                break;
            }
        }
        if p.live == 0 {
            return;
        }

        let sh = shading(scene, &p, &hit);
        p.terminate_secondary(scene, &hit);
        next_event(scene, &mut p, &hit, &sh, settings);
        if bsdf_samples != 1 {
            // The `direct` integrator's BSDF samples, other than one: each is traced here for the emission
            // it finds, and the paths end (max_depth 2).
            debug_assert_eq!(max_depth, 2, "several BSDF samples at a vertex end the path there");
            p.deepen();
            let beta = load_rgb(&p.beta);
            for _ in 0..bsdf_samples {
                let (valid, weight, _) = sample_bsdf(&mut p, &hit, &sh);
                store_rgb(&mut p.beta, std::array::from_fn(|c| beta[c] * weight[c]));
                let traced = p.live & valid;
                trace(scene, &mut p, traced, &mut found, settings, bsdf_samples as f32);
            }
            for lane in bits(p.live) {
                p.finish(lane, out);
            }
            continue;
        }
        let (valid, weight, eta) = sample_bsdf(&mut p, &hit, &sh);
        for lane in bits(p.live & !valid) {
            p.finish(lane, out);
        }
        let mut beta = load_rgb(&p.beta);
        for c in 0..3 {
            beta[c] = beta[c] * weight[c];
        }
        // Russian roulette.
        let beta_max = beta[0].max(beta[1]).max(beta[2]);
        let q = (beta_max * eta * eta).min(Float8::splat(0.95));
        let dead = p.live & (!beta_max.gt(Float8::splat(0.0))).bitmask();
        p.deepen();
        for lane in bits(dead) {
            p.finish(lane, out);
        }
        let roulette = p.live & lanes_where(|i| p.depth[i] >= rr_depth);
        let survive_scale = roulette & !p.rng.next_f32(roulette).ge(q).bitmask();
        for lane in bits(roulette & !survive_scale) {
            p.finish(lane, out);
        }
        let scaled = Mask8::from_bitmask(survive_scale);
        for b in &mut beta {
            *b = Float8::select(scaled, *b / q, *b);
        }
        store_rgb(&mut p.beta, beta);
    }
}
