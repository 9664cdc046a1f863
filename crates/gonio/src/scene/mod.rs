//! The in-memory scene: shapes with their BSDFs and area lights, other lights, the BVH over every
//! primitive, the camera, film, sampler and integrator settings. [`mitsuba_xml`] reads the file format,
//! [`mitsuba_dict`] Mitsuba's scene dictionaries;
//! [`Scene::build`] (in `build.rs`) turns its plugins into these types.

pub mod build;
pub mod material;
pub mod mesh_files;
pub mod mitsuba_dict;
pub mod mitsuba_xml;
pub mod spectral;
pub mod surfaces;

pub use material::{LaneMaterial, Material};
pub use spectral::{Mode, SpectralScene};

use crate::bsdf::Bsdf;
use crate::camera::Camera;
use crate::error::Result;
use crate::film::FilmSpec;
use crate::geometry::bvh::{bits, PacketLeaves, PacketRays, LANES};
pub use crate::geometry::bvh::{Hits8, EMPTY_SLOT};
use crate::geometry::mesh::{parallelogram_barycentrics, FlatTriangles8, Triangle8, UvMap};
use crate::geometry::ray::{ray_point, RayLanes};
use crate::geometry::sphere::Sphere8;
use crate::geometry::{Bvh, PrimHit, Ray, Shape, SurfaceInteraction};
use crate::light::{Light, LightSelection};
use crate::math::simd::{Float8, Mask8};
use crate::math::Vec2;
use rayon::prelude::*;
use std::borrow::Cow;
use std::path::Path;

/// Which integrator renders the scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Mitsuba's `path`: `max_depth` (−1 = unbounded; 1 = emitters only, 2 = direct lighting),
    /// Russian roulette from depth `rr_depth`.
    Path { max_depth: i32, rr_depth: i32, hide_emitters: bool },
    /// Mitsuba's `direct`: one bounce, `emitter_samples` light samples and `bsdf_samples` BSDF samples
    /// combined with the power heuristic.
    Direct { emitter_samples: u32, bsdf_samples: u32, hide_emitters: bool },
    /// Mitsuba's `aov` ([`crate::integrator::aov`]): the nested integrators (name, kind; each `path` or
    /// `direct`), the first of which gives the image's RGB (black when there is none), and the values of
    /// the camera rays' first hits in `outputs`, all as further channels of the film.
    Aov { integrators: Vec<(String, IntegratorKind)>, outputs: Vec<Aov> },
}

/// One output of the `aov` integrator: channels `name.X`, … of a value at the camera ray's first hit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Aov {
    pub name: String,
    pub kind: AovKind,
}

/// What an [`Aov`] holds (Mitsuba 3's `aovs` types); zero where the camera ray hits nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AovKind {
    /// `depth` (`.T`): the ray's distance to the hit, from its origin on the camera's near plane.
    Depth,
    /// `position` (`.X`, `.Y`, `.Z`): the hit point in world space.
    Position,
    /// `uv` (`.U`, `.V`): the texture coordinates.
    Uv,
    /// `geo_normal` (`.X`, `.Y`, `.Z`): the geometric normal (the shape's outward side).
    GeoNormal,
    /// `sh_normal` (`.X`, `.Y`, `.Z`): the shading normal.
    ShNormal,
    /// `prim_index` (`.I`): the triangle's index in its mesh (0 for other shapes).
    PrimIndex,
    /// `shape_index` (`.I`): the shape's position in the file, counted from 1.
    ShapeIndex,
}

impl AovKind {
    /// Every kind with its name in `aovs` and its channels' suffixes.
    pub const ALL: [(AovKind, &'static str, &'static [&'static str]); 7] = [
        (AovKind::Depth, "depth", &["T"]),
        (AovKind::Position, "position", &["X", "Y", "Z"]),
        (AovKind::Uv, "uv", &["U", "V"]),
        (AovKind::GeoNormal, "geo_normal", &["X", "Y", "Z"]),
        (AovKind::ShNormal, "sh_normal", &["X", "Y", "Z"]),
        (AovKind::PrimIndex, "prim_index", &["I"]),
        (AovKind::ShapeIndex, "shape_index", &["I"]),
    ];

    /// The channels' suffixes (`T`; `X`, `Y`, `Z`; `U`, `V`; `I`).
    #[must_use]
    pub fn suffixes(self) -> &'static [&'static str] {
        AovKind::ALL.iter().find(|(k, _, _)| *k == self).map_or(&[], |(_, _, s)| s)
    }
}

impl IntegratorKind {
    /// The names of the film's channels: `R`, `G`, `B`, then for `aov` each nested integrator's `name.R`,
    /// `name.G`, `name.B`, `name.A` and each output's `name.X`, … (Mitsuba 3.9.1's order).
    #[must_use]
    pub fn channels(&self) -> Vec<String> {
        let mut names: Vec<String> = ["R", "G", "B"].map(String::from).to_vec();
        if let IntegratorKind::Aov { integrators, outputs } = self {
            for (name, _) in integrators {
                names.extend(["R", "G", "B", "A"].map(|c| format!("{name}.{c}")));
            }
            for aov in outputs {
                names.extend(aov.kind.suffixes().iter().map(|c| format!("{}.{c}", aov.name)));
            }
        }
        names
    }

    /// The integrator whose radiance is the image's RGB: this one, or an `aov`'s first nested integrator
    /// (`None` when it has none: the RGB is black).
    #[must_use]
    pub fn rgb(&self) -> Option<&IntegratorKind> {
        match self {
            IntegratorKind::Aov { integrators, .. } => integrators.first().and_then(|(_, k)| k.rgb()),
            _ => Some(self),
        }
    }

    /// Whether an `aov` output of this kind is asked for.
    #[must_use]
    pub fn outputs(&self, kind: AovKind) -> bool {
        matches!(self, IntegratorKind::Aov { outputs, .. } if outputs.iter().any(|a| a.kind == kind))
    }
}

/// Sampler settings (`independent`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerSpec {
    pub sample_count: u32,
    pub seed: u64,
}

/// A renderable scene.
#[derive(Debug)]
pub struct Scene {
    pub shapes: Vec<Shape>,
    /// The material (BSDF, possibly textured) of each shape.
    pub materials: Vec<Material>,
    /// The area light of each shape (index into `lights`), if it emits.
    pub shape_lights: Vec<Option<u32>>,
    pub lights: Vec<Light>,
    /// Index of the environment light (`constant` or `envmap`), seen by rays that escape.
    pub environment: Option<u32>,
    /// Per light: an area light that emits on a mesh of at most eight flat-shaded triangles, as lanes
    /// ([`Mesh::flat_triangles8`](crate::geometry::mesh::Mesh::flat_triangles8)), for the path tracer's
    /// next-event estimation.
    pub light_triangles: Vec<Option<FlatTriangles8>>,
    /// Which light next-event estimation samples at a point ([`LightSelection`]).
    pub light_selection: LightSelection,
    pub camera: Camera,
    pub film: FilmSpec,
    pub sampler: SamplerSpec,
    pub integrator: IntegratorKind,
    /// Things accepted but approximated (e.g. a Gaussian filter rendered as a box).
    pub warnings: Vec<String>,
    /// Seconds spent building the BVH and its primitive packets (for benchmarks).
    pub bvh_seconds: f64,
    /// What spectral mode keeps of the scene; `None` in RGB mode ([`Scene::build_in`], [`Scene::mode`]).
    pub spectral: Option<SpectralScene>,
    /// Whether each shape's material reads textures (only then are texture coordinates computed at hits).
    textured: Vec<bool>,
    /// Per shape, the first shape with the same constant `diffuse` reflectance (shapes that share a
    /// `<ref>`'d `bsdf`, or equal ones), else the shape itself: the path tracer finds the reflectance of
    /// the lanes of one class together.
    pub material_class: Vec<u32>,
    bvh: Bvh,
    /// The primitives in BVH leaf order.
    prims: Primitives,
}

/// The shape and primitive at one BVH slot ([`EMPTY_SLOT`] as the shape for padding).
#[derive(Clone, Copy, Debug)]
struct SlotRef {
    shape: u32,
    prim: u32,
    /// For the parallelogram of a mesh's triangles `prim` and `prim + 1` ([`Mesh::parallelogram`]): the
    /// corner of triangle `prim` its edges start from. `None` for a triangle and other shapes.
    corner: Option<u8>,
    /// For a flat mesh's slot whose material reads texture coordinates: its index in
    /// [`Primitives::uv_maps`] ([`NO_UV_MAP`] for others).
    uv_map: u32,
    /// A mesh triangle shaded by its vertex normals (no [`Mesh::flat_frame`](crate::geometry::mesh::Mesh::flat_frame)):
    /// told here, so that a hit on it reads no per-triangle record but its vertices' (2026-12: reading
    /// the mesh's flat frames, its geometric normals and its positions for each hit on a smooth mesh of
    /// 10⁶ triangles missed the caches about as often as the normals themselves).
    smooth: bool,
}

/// [`SlotRef::uv_map`] of slots without one.
const NO_UV_MAP: u32 = u32::MAX;

impl SlotRef {
    /// The barycentrics in triangle `prim` of a hit at (b₁, b₂) of the slot's test (the coordinates along
    /// the parallelogram's edges for a parallelogram).
    #[inline]
    fn barycentrics(&self, b: Vec2) -> Vec2 {
        match self.corner {
            Some(k) => parallelogram_barycentrics(k, b),
            None => b,
        }
    }
}

/// The primitives in BVH leaf order, in packets of eight slots: triangles (and the parallelograms of two
/// triangles, [`crate::geometry::Mesh::parallelogram`]) inline as a [`Triangle8`] (no index lookups in the
/// inner loop), spheres as a [`Sphere8`] beside it where the packet has any, other shapes (disks) flagged
/// in `others` and intersected one by one.
#[derive(Clone, Debug, Default)]
struct Primitives {
    triangles: Vec<Triangle8>,
    /// Bit `i` of `tri_lanes[k]`: slot `8k + i` holds a (non-degenerate) triangle.
    tri_lanes: Vec<u8>,
    /// Bit `i` of `others[k]`: slot `8k + i` holds a shape that is neither a triangle nor a sphere.
    others: Vec<u8>,
    /// Index into `spheres` of packet `k`'s spheres, [`NO_SPHERES`] where it has none.
    sphere_packet: Vec<u32>,
    spheres: Vec<Sphere8>,
    /// Some packet holds a sphere or another shape (else the leaf loops skip looking: meshes only).
    has_others: bool,
    slots: Vec<SlotRef>,
    /// The texture coordinates of the flat mesh slots that need them, as functions of the point.
    uv_maps: Vec<UvMap>,
}

/// [`Primitives::sphere_packet`] of a packet without spheres.
const NO_SPHERES: u32 = u32::MAX;

impl Primitives {
    fn new(shapes: &[Shape], textured: &[bool], refs: &[SlotRef], order: &[u32]) -> Self {
        let packets = order.len() / LANES;
        let mut p = Primitives {
            triangles: vec![Triangle8::default(); packets],
            tri_lanes: vec![0; packets],
            others: vec![0; packets],
            sphere_packet: vec![NO_SPHERES; packets],
            spheres: Vec::new(),
            has_others: false,
            slots: Vec::new(),
            uv_maps: Vec::new(),
        };
        // The slots and the triangles' packets in parallel: each reads its triangles' vertices and
        // records, in leaf order scattered over the meshes (2026-12: 0.13 s of the load of a mesh of 10⁶
        // triangles, on one thread).
        let empty = SlotRef { shape: EMPTY_SLOT, prim: 0, corner: None, uv_map: NO_UV_MAP, smooth: false };
        p.slots = order
            .par_iter()
            .map(|&i| {
                let Some(&r) = refs.get(i as usize) else { return empty };
                match &shapes[r.shape as usize] {
                    Shape::Mesh(m) => SlotRef { smooth: m.flat_frame(r.prim).is_none() && m.vertex_normals(r.prim).is_some(), ..r },
                    _ => r,
                }
            })
            .collect();
        p.triangles.par_iter_mut().zip(p.slots.par_chunks(LANES)).for_each(|(packet, slots)| {
            for (lane, r) in slots.iter().enumerate() {
                if let Some(Shape::Mesh(m)) = shapes.get(r.shape as usize) {
                    packet.set(lane, m.corner_edges(r.prim, r.corner.unwrap_or(0)), r.corner.is_some());
                }
            }
        });
        // What is numbered in order: the texture coordinates of textured flat triangles, the spheres.
        for (slot, r) in p.slots.iter_mut().enumerate() {
            let (packet, lane) = (slot / LANES, slot % LANES);
            match shapes.get(r.shape as usize) {
                Some(Shape::Mesh(m)) if textured[r.shape as usize] && m.flat_frame(r.prim).is_some() => {
                    r.uv_map = p.uv_maps.len() as u32;
                    p.uv_maps.push(m.uv_map(r.prim, r.corner.unwrap_or(0)));
                }
                None | Some(Shape::Mesh(_)) => {}
                Some(Shape::Sphere(s)) => {
                    if p.sphere_packet[packet] == NO_SPHERES {
                        p.sphere_packet[packet] = p.spheres.len() as u32;
                        p.spheres.push(Sphere8::default());
                    }
                    p.spheres[p.sphere_packet[packet] as usize].set(lane, s);
                }
                Some(Shape::Disk(_) | Shape::Cylinder(_) | Shape::SdfGrid(_)) => p.others[packet] |= 1 << lane,
            }
        }
        p.has_others = !p.spheres.is_empty() || p.others.iter().any(|&bits| bits != 0);
        for (lanes, tri) in p.tri_lanes.iter_mut().zip(&p.triangles) {
            *lanes = (0..LANES).fold(0, |m, lane| m | (u8::from(tri.has(lane)) << lane));
        }
        p
    }

    /// The closest hit among slots `first..first + count` (a BVH leaf) below `tmax`: its distance and slot.
    #[inline(always)]
    fn closest(&self, shapes: &[Shape], ray: &Ray, first: u32, count: u32, mut tmax: f32) -> Option<(f32, u32)> {
        let mut best = None;
        for packet in (first as usize / LANES)..(first + count) as usize / LANES {
            if let Some((t, lane)) = self.triangles[packet].nearest(ray, tmax) {
                tmax = t;
                best = Some((t, (packet * LANES) as u32 + lane));
            }
            if !self.has_others {
                continue;
            }
            if let Some(spheres) = self.spheres.get(self.sphere_packet[packet] as usize) {
                let (mask, t) = spheres.intersect(ray, tmax);
                // The smallest t, the first lane among equals.
                for lane in bits(mask) {
                    if t[lane] < tmax {
                        tmax = t[lane];
                        best = Some((tmax, (packet * LANES + lane) as u32));
                    }
                }
            }
            for lane in bits(u32::from(self.others[packet])) {
                let slot = packet * LANES + lane;
                let r = self.slots[slot];
                let clipped = Ray { tmax, ..*ray };
                if let Some(hit) = shapes[r.shape as usize].intersect(r.prim, &clipped) {
                    tmax = hit.t;
                    best = Some((hit.t, slot as u32));
                }
            }
        }
        best
    }

    /// Whether any of slots `first..first + count` blocks `ray`.
    #[inline(always)]
    fn any(&self, shapes: &[Shape], ray: &Ray, first: u32, count: u32) -> bool {
        for packet in (first as usize / LANES)..(first + count) as usize / LANES {
            if self.triangles[packet].any(ray, ray.tmax) {
                return true;
            }
            if !self.has_others {
                continue;
            }
            if let Some(spheres) = self.spheres.get(self.sphere_packet[packet] as usize) {
                if spheres.intersect(ray, ray.tmax).0 != 0 {
                    return true;
                }
            }
            for lane in bits(u32::from(self.others[packet])) {
                let r = self.slots[packet * LANES + lane];
                if shapes[r.shape as usize].intersect(r.prim, ray).is_some() {
                    return true;
                }
            }
        }
        false
    }
}

/// Rays per packet tested triangle by triangle (each triangle against all rays) rather than ray by ray
/// (each ray against the packet's eight triangles): below this many rays per triangle in the packet, ray by
/// ray. 2026-12 (Zen 3), with the triangle-by-triangle test branch-free ([`Triangle8::intersect_rays`],
/// slots taken by selects): 1 took 0.90–0.95 × the Cornell box's render time of 2 (sequential
/// alternations, 40 renders each), the same instructions and 16 % fewer simulated branch mispredictions;
/// 0 about the same time with 12 % more instructions. (2026-11, with the branching test and a loop over
/// the lanes hit for their slots, 2 had been faster than 0 or 1.)
const RAYS_PER_TRIANGLE: u32 = 1;

/// Lanes `hit` of a leaf's test of one primitive (slot `slot`) against a packet's rays take its distances
/// `t`, and its slot by a select: `slots` holds the lanes' slots as `f32` bit patterns (selects and moves
/// keep bits as they are, NaN patterns included). A loop over the lanes hit, whose exit the branch
/// predictor often misses, is not needed.
#[inline(always)]
fn take_hits(hit: Mask8, t: Float8, slot: usize, hits_t: &mut Float8, slots: &mut Float8) {
    *hits_t = Float8::select(hit, t, *hits_t);
    *slots = Float8::select(hit, Float8::splat(f32::from_bits(slot as u32)), *slots);
}

/// `f(l)` for each lane `l` of `tris` (a packet's triangles): for a full packet by a fixed loop, whose
/// exit the branch predictor does not miss as it does a loop's over the set lanes (2026-12: with the
/// path tracer's lane groups found without branches, a quarter fewer simulated mispredictions on the
/// Cornell box). Partial packets loop over their lanes: all eight lanes, the empty ones masked off, made
/// the material spheres' packets of two triangles 4 % more instructions and about as much slower.
#[inline(always)]
fn for_each_triangle(tris: u32, f: impl FnMut(usize)) {
    if tris == (1 << LANES) - 1 {
        (0..LANES).for_each(f);
    } else {
        bits(tris).for_each(f);
    }
}

/// The scene's primitives as the BVH's packet traversal sees them.
struct Leaves<'a> {
    prims: &'a Primitives,
    shapes: &'a [Shape],
}

impl Leaves<'_> {
    /// The packets of slots `first..first + count`.
    #[inline(always)]
    fn packets(first: u32, count: u32) -> std::ops::Range<usize> {
        first as usize / LANES..(first + count) as usize / LANES
    }
}

impl PacketLeaves for Leaves<'_> {
    #[inline(always)]
    fn closest_rays(&self, rays: &RayLanes<Float8>, each: &PacketRays, first: u32, count: u32, lanes: u32, hits: &mut Hits8) {
        let live = Mask8::from_bitmask(lanes);
        for packet in Self::packets(first, count) {
            let tri = &self.prims.triangles[packet];
            let tris = u32::from(self.prims.tri_lanes[packet]);
            if tris != 0 {
                if lanes.count_ones() < RAYS_PER_TRIANGLE * tris.count_ones() {
                    let t = hits.t.to_array();
                    for lane in bits(lanes) {
                        if let Some((tl, l)) = tri.nearest(&each.ray(lane), t[lane]) {
                            hits.t = hits.t.with_lane(lane, tl);
                            hits.slot[lane] = (packet * LANES) as u32 + l;
                        }
                    }
                } else {
                    let mut slots = Float8::new(hits.slot.map(f32::from_bits));
                    for_each_triangle(tris, |l| {
                        let (hit, t) = tri.intersect_rays(l, rays.o, rays.d, hits.t);
                        take_hits(hit & live, t, packet * LANES + l, &mut hits.t, &mut slots);
                    });
                    hits.slot = slots.to_array().map(f32::to_bits);
                }
            }
            if !self.prims.has_others {
                continue;
            }
            if let Some(spheres) = self.prims.spheres.get(self.prims.sphere_packet[packet] as usize) {
                let mut slots = Float8::new(hits.slot.map(f32::from_bits));
                for l in bits(spheres.lanes()) {
                    let (hit, t) = spheres.intersect_rays(l, rays.o, rays.d, hits.t);
                    take_hits(hit & live, t, packet * LANES + l, &mut hits.t, &mut slots);
                }
                hits.slot = slots.to_array().map(f32::to_bits);
            }
            let others = u32::from(self.prims.others[packet]);
            if others != 0 {
                let mut t = hits.t.to_array();
                for lane in bits(lanes) {
                    for l in bits(others) {
                        let r = self.prims.slots[packet * LANES + l];
                        let ray = Ray { tmax: t[lane], ..each.ray(lane) };
                        if let Some(hit) = self.shapes[r.shape as usize].intersect(r.prim, &ray) {
                            t[lane] = hit.t;
                            hits.slot[lane] = (packet * LANES + l) as u32;
                        }
                    }
                }
                hits.t = Float8::load(&t);
            }
        }
    }

    #[inline(always)]
    fn closest_ray(&self, ray: &Ray, first: u32, count: u32, tmax: f32) -> Option<(f32, u32)> {
        self.prims.closest(self.shapes, ray, first, count, tmax)
    }

    #[inline(always)]
    fn any_rays(&self, rays: &RayLanes<Float8>, each: &PacketRays, first: u32, count: u32, lanes: u32) -> u32 {
        let mut blocked = 0u32;
        for packet in Self::packets(first, count) {
            let open = lanes & !blocked;
            if open == 0 {
                break;
            }
            let tri = &self.prims.triangles[packet];
            let tris = u32::from(self.prims.tri_lanes[packet]);
            if tris != 0 {
                if open.count_ones() < RAYS_PER_TRIANGLE * tris.count_ones() {
                    for lane in bits(open) {
                        let ray = each.ray(lane);
                        if tri.any(&ray, ray.tmax) {
                            blocked |= 1 << lane;
                        }
                    }
                } else {
                    for_each_triangle(tris, |l| blocked |= tri.intersect_rays(l, rays.o, rays.d, rays.tmax).0.bitmask() & open);
                }
            }
            if !self.prims.has_others {
                continue;
            }
            if let Some(spheres) = self.prims.spheres.get(self.prims.sphere_packet[packet] as usize) {
                for l in bits(spheres.lanes()) {
                    blocked |= spheres.intersect_rays(l, rays.o, rays.d, rays.tmax).0.bitmask() & lanes;
                }
            }
            let others = u32::from(self.prims.others[packet]);
            if others != 0 {
                for lane in bits(lanes & !blocked) {
                    if bits(others).any(|l| {
                        let r = self.prims.slots[packet * LANES + l];
                        self.shapes[r.shape as usize].intersect(r.prim, &each.ray(lane)).is_some()
                    }) {
                        blocked |= 1 << lane;
                    }
                }
            }
        }
        blocked
    }

    #[inline(always)]
    fn any_ray(&self, ray: &Ray, first: u32, count: u32) -> bool {
        self.prims.any(self.shapes, ray, first, count)
    }
}

impl Scene {
    /// Load a Mitsuba XML scene file with `-D name=value` overrides.
    pub fn load(path: &Path, overrides: &[(String, String)]) -> Result<Scene> {
        Scene::build(mitsuba_xml::load_file(path, overrides)?)
    }

    /// How light is carried: RGB, or sampled wavelengths (where [`Self::spectral`] is kept).
    #[must_use]
    pub fn mode(&self) -> Mode {
        if self.spectral.is_some() {
            Mode::Spectral
        } else {
            Mode::Rgb
        }
    }

    /// [`Scene::load`] for rendering in `mode`.
    pub fn load_in(path: &Path, overrides: &[(String, String)], mode: Mode) -> Result<Scene> {
        Scene::build_in(mitsuba_xml::load_file(path, overrides)?, mode)
    }

    /// The BVH's primitives: each shape's in turn, where two triangles that form a parallelogram are one
    /// (its test costs as much as a triangle's: a `rectangle` is one, a `cube` six) when `pair`.
    fn slot_refs(shapes: &[Shape], textured: &[bool], pair: bool) -> Vec<SlotRef> {
        let mut refs = Vec::with_capacity(shapes.iter().map(Shape::primitive_count).sum());
        for (s, shape) in shapes.iter().enumerate() {
            let slot = |prim: u32, corner: Option<u8>| SlotRef { shape: s as u32, prim, corner, uv_map: NO_UV_MAP, smooth: false };
            match shape {
                Shape::Mesh(m) if pair => {
                    // Whether triangle p and p + 1 form one, for every p in parallel (the test reads both
                    // triangles' vertices and frames); then the pairs in order, each triangle in one.
                    let corners: Vec<Option<u8>> =
                        (0..m.triangle_count() as u32).into_par_iter().map(|p| m.parallelogram(p, textured[s])).collect();
                    let mut p = 0;
                    while p < corners.len() {
                        refs.push(slot(p as u32, corners[p]));
                        p += if corners[p].is_some() { 2 } else { 1 };
                    }
                }
                _ => refs.extend((0..shape.primitive_count() as u32).map(|p| slot(p, None))),
            }
        }
        refs
    }

    /// Assemble a scene and build its BVH.
    #[must_use]
    #[allow(clippy::too_many_arguments)] // one argument per plugin parameter, as in the table above
    pub fn assemble(
        shapes: Vec<Shape>,
        materials: Vec<Material>,
        shape_lights: Vec<Option<u32>>,
        lights: Vec<Light>,
        camera: Camera,
        film: FilmSpec,
        sampler: SamplerSpec,
        integrator: IntegratorKind,
        warnings: Vec<String>,
    ) -> Scene {
        // The `aov` integrator's `uv` output needs texture coordinates at every hit, and its `prim_index`
        // each triangle as its own primitive (not paired into a parallelogram, whose test gives the first).
        let all_uv = integrator.outputs(AovKind::Uv);
        let pair = !integrator.outputs(AovKind::PrimIndex);
        let textured: Vec<bool> = (0..shapes.len()).map(|s| all_uv || materials.get(s).is_some_and(Material::is_textured)).collect();
        let start = std::time::Instant::now();
        let refs = Self::slot_refs(&shapes, &textured, pair);
        // The primitives' boxes, in parallel: each reads its vertices (2026-12: 0.15 s of the load of a
        // mesh of 10⁶ triangles on one thread).
        let bounds: Vec<_> = refs
            .par_iter()
            .map(|r| {
                let shape = &shapes[r.shape as usize];
                let b = shape.primitive_bounds(r.prim);
                if r.corner.is_some() {
                    b.union(shape.primitive_bounds(r.prim + 1))
                } else {
                    b
                }
            })
            .collect();
        // Triangles are tested eight at a time; a leaf's spheres and disks each by its own test.
        let alone: Vec<bool> = refs.iter().map(|r| !matches!(shapes[r.shape as usize], Shape::Mesh(_))).collect();
        let bvh = Bvh::build_costed(&bounds, &alone);
        let prims = Primitives::new(&shapes, &textured, &refs, bvh.order());
        let bvh_seconds = start.elapsed().as_secs_f64();
        let environment = lights.iter().position(Light::is_environment).map(|i| i as u32);
        let mut first_with = std::collections::HashMap::new();
        let material_class = (0..shapes.len() as u32)
            .map(|s| match materials.get(s as usize) {
                Some(Material::Fixed(crate::bsdf::Bsdf::Diffuse(d))) => *first_with.entry(d.reflectance.0.map(f32::to_bits)).or_insert(s),
                _ => s,
            })
            .collect();
        let light_triangles = lights
            .iter()
            .map(|light| match light {
                Light::Area(area) if !area.radiance.is_black() => match &shapes[area.shape as usize] {
                    Shape::Mesh(mesh) => mesh.flat_triangles8(),
                    _ => None,
                },
                _ => None,
            })
            .collect();
        let light_selection = LightSelection::new(&lights, &shapes);
        Scene {
            shapes,
            materials,
            shape_lights,
            lights,
            environment,
            light_triangles,
            light_selection,
            camera,
            film,
            sampler,
            integrator,
            warnings,
            bvh_seconds,
            spectral: None,
            textured,
            material_class,
            bvh,
            prims,
        }
    }

    /// The BVH as text (debugging).
    #[must_use]
    pub fn describe_bvh(&self) -> String {
        self.bvh.describe()
    }

    /// Number of primitives in the BVH.
    #[must_use]
    pub fn primitive_count(&self) -> usize {
        self.prims.slots.iter().filter(|r| r.shape != EMPTY_SLOT).count()
    }

    /// The reflection model of the surface `si`: its shape's material at its texture coordinates, and, for
    /// a material with a bump map or a mesh attribute, on its surface ([`Shape::uv_partials`], the mesh).
    #[must_use]
    pub fn bsdf_at(&self, si: &SurfaceInteraction) -> Cow<'_, Bsdf> {
        let material = &self.materials[si.shape as usize];
        if !material.reads_surface() {
            return material.at(si.uv);
        }
        let shape = &self.shapes[si.shape as usize];
        let (dp_du, dp_dv) = shape.uv_partials(si.prim, si.p, &si.shading);
        let mesh = if let Shape::Mesh(m) = shape { Some(m) } else { None };
        material
            .at_surface(si.uv, Some(&material::Differentials { n: si.n, shading: si.shading, dp_du, dp_dv, mesh, prim: si.prim, p: si.p }))
    }

    /// The closest surface along `ray`.
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        // The leaf tests inlined into the traversal (2026-11: left as calls, they cost a fifth more
        // instructions per ray).
        let slot = self.bvh.closest(
            ray,
            #[inline(always)]
            |first, count, tmax| self.prims.closest(&self.shapes, ray, first, count, tmax),
        )?;
        self.interaction_at(slot, ray)
    }

    /// The closest hits of eight rays (the lanes of `rays` set in `lanes`): per lane the distance and the
    /// BVH slot of the primitive hit ([`EMPTY_SLOT`] for none), for [`Self::surfaces`] (or [`Self::interaction_at`] one
    /// by one).
    #[must_use]
    pub fn intersect_rays(&self, rays: &RayLanes<Float8>, lanes: u32) -> Hits8 {
        self.bvh.closest_rays(rays, lanes, &Leaves { prims: &self.prims, shapes: &self.shapes })
    }

    /// Which of eight rays (the lanes of `rays` set in `lanes`) something blocks before their `tmax`.
    #[must_use]
    pub fn occluded_rays(&self, rays: &RayLanes<Float8>, lanes: u32) -> u32 {
        self.bvh.any_rays(rays, lanes, &Leaves { prims: &self.prims, shapes: &self.shapes })
    }

    /// The surface where `ray` hits the primitive at BVH slot `slot` (as the traversal found it).
    #[must_use]
    pub fn interaction_at(&self, slot: u32, ray: &Ray) -> Option<SurfaceInteraction> {
        let r = self.prims.slots[slot as usize];
        let shape = &self.shapes[r.shape as usize];
        // The traversal kept only the distance: the primitive's own test gives the hit again, bit for bit
        // (the packet tests run the scalar test's operations), now with its coordinates.
        let textured = self.textured[r.shape as usize];
        if let Shape::Mesh(mesh) = shape {
            let (tris, lane) = (&self.prims.triangles[slot as usize / LANES], slot as usize % LANES);
            let hit = tris.intersect_lane(lane, ray);
            debug_assert!(hit.is_some(), "the closest hit is found again");
            return hit.map(|hit| {
                let mut si = mesh.interaction(r.prim, ray, &PrimHit { uv: r.barycentrics(hit.uv), ..hit }, textured);
                (si.shape, si.prim) = (r.shape, r.prim);
                // On a flat-shaded mesh the point is o + t d and the texture coordinates a function of it,
                // as `surfaces` computes them (see there).
                if mesh.flat_frame(r.prim).is_some() {
                    si.p = ray_point::<f32>(ray.o.into(), ray.d.into(), hit.t).into();
                    if let Some(map) = self.prims.uv_maps.get(r.uv_map as usize) {
                        si.uv = map.at(si.p);
                    }
                }
                si
            });
        }
        let hit = shape.intersect(r.prim, ray);
        debug_assert!(hit.is_some(), "the closest hit is found again");
        hit.map(|hit| shape.interaction(r.shape, r.prim, ray, &hit, textured))
    }

    /// Whether anything blocks `ray` before its `tmax`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.any(
            ray,
            #[inline(always)]
            |first, count| self.prims.any(&self.shapes, ray, first, count),
        )
    }
}
