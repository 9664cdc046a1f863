//! The in-memory scene: shapes with their BSDFs and area lights, other lights, the BVH over every
//! primitive, the camera, film, sampler and integrator settings. [`mitsuba_xml`] reads the file format,
//! [`mitsuba_dict`] Mitsuba's scene dictionaries;
//! [`Scene::build`] (in `build.rs`) turns its plugins into these types.

pub mod build;
pub mod material;
pub mod mesh_files;
pub mod mitsuba_dict;
pub mod mitsuba_xml;

pub use material::Material;

use crate::camera::PerspectiveCamera;
use crate::error::Result;
use crate::film::FilmSpec;
use crate::geometry::bvh::{EMPTY_SLOT, LANES};
use crate::geometry::mesh::Triangle4;
use crate::geometry::{Bvh, PrimHit, Ray, Shape, SurfaceInteraction};
use crate::light::Light;
use glam::Vec2;
use std::path::Path;

/// Which integrator renders the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Mitsuba's `path`: `max_depth` (−1 = unbounded; 1 = emitters only, 2 = direct lighting),
    /// Russian roulette from depth `rr_depth`.
    Path { max_depth: i32, rr_depth: i32, hide_emitters: bool },
    /// Mitsuba's `direct`: one bounce, `emitter_samples` light samples and `bsdf_samples` BSDF samples
    /// combined with the power heuristic.
    Direct { emitter_samples: u32, bsdf_samples: u32, hide_emitters: bool },
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
    pub camera: PerspectiveCamera,
    pub film: FilmSpec,
    pub sampler: SamplerSpec,
    pub integrator: IntegratorKind,
    /// Things accepted but approximated (e.g. a Gaussian filter rendered as a box).
    pub warnings: Vec<String>,
    /// Seconds spent building the BVH and its primitive packets (for benchmarks).
    pub bvh_seconds: f64,
    bvh: Bvh,
    /// The primitives in BVH leaf order.
    prims: Primitives,
}

/// The shape and primitive at one BVH slot ([`EMPTY_SLOT`] as the shape for padding).
#[derive(Clone, Copy, Debug)]
struct SlotRef {
    shape: u32,
    prim: u32,
}

/// The primitives in BVH leaf order, in packets of four slots: triangles inline as a [`Triangle4`] (no
/// index lookups in the inner loop), other shapes (spheres, disks) flagged in `others` and intersected
/// one by one.
#[derive(Clone, Debug, Default)]
struct Primitives {
    triangles: Vec<Triangle4>,
    /// Bit `i` of `others[k]`: slot `4k + i` holds a shape that is not a triangle.
    others: Vec<u8>,
    /// Some bit of `others` is set (else the leaf loops skip reading them: meshes only).
    has_others: bool,
    slots: Vec<SlotRef>,
}

impl Primitives {
    fn new(shapes: &[Shape], refs: &[SlotRef], order: &[u32]) -> Self {
        let packets = order.len() / LANES;
        let mut p = Primitives {
            triangles: vec![Triangle4::default(); packets],
            others: vec![0; packets],
            has_others: false,
            slots: Vec::with_capacity(order.len()),
        };
        for (slot, &i) in order.iter().enumerate() {
            let (packet, lane) = (slot / LANES, slot % LANES);
            if i == EMPTY_SLOT {
                p.slots.push(SlotRef { shape: EMPTY_SLOT, prim: 0 });
                continue;
            }
            let r = refs[i as usize];
            match &shapes[r.shape as usize] {
                Shape::Mesh(m) => p.triangles[packet].set(lane, m.triangle_edges(r.prim)),
                _ => p.others[packet] |= 1 << lane,
            }
            p.slots.push(r);
        }
        p.has_others = p.others.iter().any(|&bits| bits != 0);
        p
    }

    /// The closest hit among slots `first..first + count` (a BVH leaf) below `tmax`.
    #[inline(always)]
    fn closest(&self, shapes: &[Shape], ray: &Ray, first: u32, count: u32, mut tmax: f32) -> Option<(f32, (SlotRef, PrimHit))> {
        let mut best = None;
        for packet in (first as usize / LANES)..(first + count) as usize / LANES {
            let h = self.triangles[packet].intersect(ray, tmax);
            let mut mask = h.mask;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if h.t[lane] < tmax {
                    tmax = h.t[lane];
                    best = Some((packet * LANES + lane, PrimHit { t: h.t[lane], uv: Vec2::new(h.b1[lane], h.b2[lane]) }));
                }
            }
            if !self.has_others {
                continue;
            }
            let mut others = u32::from(self.others[packet]);
            while others != 0 {
                let slot = packet * LANES + others.trailing_zeros() as usize;
                others &= others - 1;
                let r = self.slots[slot];
                let clipped = Ray { tmax, ..*ray };
                if let Some(hit) = shapes[r.shape as usize].intersect(r.prim, &clipped) {
                    tmax = hit.t;
                    best = Some((slot, hit));
                }
            }
        }
        best.map(|(slot, hit)| (hit.t, (self.slots[slot], hit)))
    }

    /// Whether any of slots `first..first + count` blocks `ray`.
    #[inline(always)]
    fn any(&self, shapes: &[Shape], ray: &Ray, first: u32, count: u32) -> bool {
        for packet in (first as usize / LANES)..(first + count) as usize / LANES {
            if self.triangles[packet].intersect(ray, ray.tmax).mask != 0 {
                return true;
            }
            if !self.has_others {
                continue;
            }
            let mut others = u32::from(self.others[packet]);
            while others != 0 {
                let r = self.slots[packet * LANES + others.trailing_zeros() as usize];
                others &= others - 1;
                if shapes[r.shape as usize].intersect(r.prim, ray).is_some() {
                    return true;
                }
            }
        }
        false
    }
}

impl Scene {
    /// Load a Mitsuba XML scene file with `-D name=value` overrides.
    pub fn load(path: &Path, overrides: &[(String, String)]) -> Result<Scene> {
        Scene::build(mitsuba_xml::load_file(path, overrides)?)
    }

    /// Assemble a scene and build its BVH.
    #[must_use]
    #[allow(clippy::too_many_arguments)] // one argument per plugin parameter, as in the table above
    pub fn assemble(
        shapes: Vec<Shape>,
        materials: Vec<Material>,
        shape_lights: Vec<Option<u32>>,
        lights: Vec<Light>,
        camera: PerspectiveCamera,
        film: FilmSpec,
        sampler: SamplerSpec,
        integrator: IntegratorKind,
        warnings: Vec<String>,
    ) -> Scene {
        let mut refs = Vec::new();
        let mut bounds = Vec::new();
        for (s, shape) in shapes.iter().enumerate() {
            for p in 0..shape.primitive_count() as u32 {
                refs.push(SlotRef { shape: s as u32, prim: p });
                bounds.push(shape.primitive_bounds(p));
            }
        }
        let start = std::time::Instant::now();
        let bvh = Bvh::build(&bounds);
        let prims = Primitives::new(&shapes, &refs, bvh.order());
        let bvh_seconds = start.elapsed().as_secs_f64();
        let environment = lights.iter().position(Light::is_environment).map(|i| i as u32);
        Scene { shapes, materials, shape_lights, lights, environment, camera, film, sampler, integrator, warnings, bvh_seconds, bvh, prims }
    }

    /// Number of primitives in the BVH.
    #[must_use]
    pub fn primitive_count(&self) -> usize {
        self.prims.slots.iter().filter(|r| r.shape != EMPTY_SLOT).count()
    }

    /// The closest surface along `ray`.
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let (r, hit) = self.bvh.closest(ray, |first, count, tmax| self.prims.closest(&self.shapes, ray, first, count, tmax))?;
        Some(self.shapes[r.shape as usize].interaction(r.shape, r.prim, ray, &hit))
    }

    /// Whether anything blocks `ray` before its `tmax`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.any(ray, |first, count| self.prims.any(&self.shapes, ray, first, count))
    }
}
