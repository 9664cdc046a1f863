//! `direct` — the reflection equation at the first visible surface: `emitter_samples` light samples and
//! `bsdf_samples` BSDF samples, combined with the power heuristic (Veach & Guibas 1995, eq. 8 with the
//! sample counts as n_i).
//!
//! | parameter         | type    | default | meaning                                   |
//! |-------------------|---------|---------|-------------------------------------------|
//! | `shading_samples` | integer | 1       | default for both counts below             |
//! | `emitter_samples` | integer | 1       | light samples per camera sample           |
//! | `bsdf_samples`    | integer | 1       | BSDF samples per camera sample            |
//! | `hide_emitters`   | boolean | false   | emitters seen directly by the camera are black |
//!
//! This is the path tracer's estimator at `max_depth` 2 with these sample counts at its one vertex, random
//! numbers and all: [`super::radiance`] renders it with the path tracer's packets, and this scalar form is
//! their reference (test `direct_is_the_path_tracer_at_depth_two`).

use super::{emitter_hit, sample_emitter, BsdfSampled};
use crate::bsdf::{BsdfFlags, BsdfModel};
use crate::geometry::ray::spawn_ray;
use crate::geometry::Ray;
use crate::sampling::Pcg32;
use crate::scene::Scene;
use crate::spectrum::Rgb;

/// The radiance along `ray`: emission seen directly plus one bounce of direct lighting.
#[must_use]
pub fn radiance(scene: &Scene, ray: &Ray, rng: &mut Pcg32, emitter_samples: u32, bsdf_samples: u32, hide_emitters: bool) -> Rgb {
    let hit = scene.intersect(ray);
    let mut l = if hide_emitters { Rgb::ZERO } else { emitter_hit(scene, ray, hit.as_ref(), None) };
    let Some(si) = hit else { return l };
    let material = scene.bsdf_at(&si);
    let bsdf = &*material;
    let wo = si.shading.to_local(-ray.d);
    let (ne, nb) = (emitter_samples as f32, bsdf_samples as f32);
    if bsdf.flags().has_smooth() {
        for _ in 0..emitter_samples {
            l += sample_emitter(scene, &si, wo, bsdf, rng, ne, nb) / ne;
        }
    }
    for _ in 0..bsdf_samples {
        let (uc, u) = (rng.next_f32(), rng.next_vec2());
        let Some(s) = bsdf.sample(wo, uc, u) else { continue };
        let next = spawn_ray(si.p, si.n, si.shading.to_world(s.wi));
        let found = scene.intersect(&next);
        let prev = BsdfSampled { from: si.p, pdf: s.pdf, delta: s.flags.contains(BsdfFlags::DELTA), n_bsdf: nb, n_light: ne, sums: None };
        l += s.weight * emitter_hit(scene, &next, found.as_ref(), Some(&prev)) / nb;
    }
    l
}
