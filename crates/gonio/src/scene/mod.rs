//! The in-memory scene: shapes with their BSDFs and area lights, other lights, the BVH over every
//! primitive, the camera, film, sampler and integrator settings. [`mitsuba_xml`] reads the file format;
//! [`Scene::build`] (in `build.rs`) turns its plugins into these types.

pub mod build;
pub mod material;
pub mod mesh_files;
pub mod mitsuba_xml;

pub use material::Material;

use crate::camera::PerspectiveCamera;
use crate::error::Result;
use crate::film::FilmSpec;
use crate::geometry::{Bvh, Ray, Shape, SurfaceInteraction};
use crate::light::Light;
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
    /// Index of the environment light (`constant`), seen by rays that escape.
    pub environment: Option<u32>,
    pub camera: PerspectiveCamera,
    pub film: FilmSpec,
    pub sampler: SamplerSpec,
    pub integrator: IntegratorKind,
    /// Things accepted but approximated (e.g. a Gaussian filter rendered as a box).
    pub warnings: Vec<String>,
    bvh: Bvh,
    /// (shape, primitive) of each BVH primitive.
    prims: Vec<(u32, u32)>,
}

impl Scene {
    /// Load a Mitsuba XML scene file with `-D name=value` overrides.
    pub fn load(path: &Path, overrides: &[(String, String)]) -> Result<Scene> {
        Scene::build(mitsuba_xml::load_file(path, overrides)?)
    }

    /// Assemble a scene and build its BVH.
    #[must_use]
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
        let mut prims = Vec::new();
        let mut bounds = Vec::new();
        for (s, shape) in shapes.iter().enumerate() {
            for p in 0..shape.primitive_count() as u32 {
                prims.push((s as u32, p));
                bounds.push(shape.primitive_bounds(p));
            }
        }
        let bvh = Bvh::build(&bounds);
        let environment = lights.iter().position(|l| matches!(l, Light::Constant(_))).map(|i| i as u32);
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
        let (_, (shape, prim, hit)) = self.bvh.closest(ray, |i, tmax| {
            let (shape, prim) = self.prims[i as usize];
            let r = Ray { tmax, ..*ray };
            self.shapes[shape as usize].intersect(prim, &r).map(|h| (h.t, (shape, prim, h)))
        })?;
        Some(self.shapes[shape as usize].interaction(shape, prim, ray, &hit))
    }

    /// Whether anything blocks `ray` before its `tmax`.
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.any(ray, |i| {
            let (shape, prim) = self.prims[i as usize];
            self.shapes[shape as usize].intersect(prim, ray).is_some()
        })
    }
}
