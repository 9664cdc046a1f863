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
use crate::geometry::mesh::intersect_triangle;
use crate::geometry::{Bvh, PrimHit, Ray, Shape, SurfaceInteraction};
use crate::light::Light;
use glam::Vec3;
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
    bvh: Bvh,
    /// The primitives in BVH leaf order.
    prims: Vec<Primitive>,
}

/// One primitive as the BVH's leaves need it: triangles inline (no index lookups in the inner loop),
/// other shapes by reference.
#[derive(Clone, Copy, Debug)]
enum Primitive {
    Triangle { p0: Vec3, e1: Vec3, e2: Vec3, shape: u32, prim: u32 },
    Other { shape: u32, prim: u32 },
}

impl Primitive {
    #[inline]
    fn intersect(&self, shapes: &[Shape], ray: &Ray) -> Option<(u32, u32, PrimHit)> {
        match *self {
            Primitive::Triangle { p0, e1, e2, shape, prim } => intersect_triangle(p0, e1, e2, ray).map(|h| (shape, prim, h)),
            Primitive::Other { shape, prim } => shapes[shape as usize].intersect(prim, ray).map(|h| (shape, prim, h)),
        }
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
                refs.push((s as u32, p));
                bounds.push(shape.primitive_bounds(p));
            }
        }
        let bvh = Bvh::build(&bounds);
        let prims = bvh
            .order()
            .iter()
            .map(|&i| {
                let (shape, prim) = refs[i as usize];
                match &shapes[shape as usize] {
                    Shape::Mesh(m) => {
                        let [p0, e1, e2] = m.triangle_edges(prim);
                        Primitive::Triangle { p0, e1, e2, shape, prim }
                    }
                    _ => Primitive::Other { shape, prim },
                }
            })
            .collect();
        let environment = lights.iter().position(Light::is_environment).map(|i| i as u32);
        Scene { shapes, materials, shape_lights, lights, environment, camera, film, sampler, integrator, warnings, bvh, prims }
    }

    /// Number of primitives in the BVH.
    #[must_use]
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// The closest surface along `ray`.
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let mut r = *ray;
        let (_, (shape, prim, hit)) = self.bvh.closest(ray, |slot, tmax| {
            r.tmax = tmax;
            self.prims[slot as usize].intersect(&self.shapes, &r).map(|h| (h.2.t, h))
        })?;
        Some(self.shapes[shape as usize].interaction(shape, prim, ray, &hit))
    }

    /// Whether anything blocks `ray` before its `tmax`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.any(ray, |slot| self.prims[slot as usize].intersect(&self.shapes, ray).is_some())
    }
}
