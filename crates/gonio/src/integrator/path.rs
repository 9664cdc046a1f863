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

use super::{emitter_hit, sample_emitter, BsdfSampled};
use crate::bsdf::{BsdfFlags, BsdfModel};
use crate::geometry::ray::spawn_ray;
use crate::geometry::Ray;
use crate::sampling::Pcg32;
use crate::scene::Scene;
use crate::spectrum::Rgb;

/// The radiance along `ray`.
#[must_use]
pub fn radiance(scene: &Scene, ray: &Ray, rng: &mut Pcg32, max_depth: i32, rr_depth: i32, hide_emitters: bool) -> Rgb {
    if max_depth == 0 {
        return Rgb::ZERO;
    }
    let mut l = Rgb::ZERO;
    let mut beta = Rgb::ONE;
    let mut eta = 1.0f32;
    let mut ray = *ray;
    let mut prev: Option<BsdfSampled> = None;
    let mut depth = 0i32;
    loop {
        let hit = scene.intersect(&ray);
        if !(depth == 0 && hide_emitters) {
            l += beta * emitter_hit(scene, &ray, hit.as_ref(), prev.as_ref());
        }
        let Some(si) = hit else { break };
        // A vertex at `depth` can extend the path only if the next one is within max_depth.
        if max_depth >= 0 && depth + 1 >= max_depth {
            break;
        }
        let material = scene.materials[si.shape as usize].at(si.uv);
        let bsdf = &*material;
        let wo = si.shading.to_local(-ray.d);
        if bsdf.flags().has_smooth() {
            l += beta * sample_emitter(scene, &si, wo, bsdf, rng, 1.0, 1.0);
        }
        let (uc, u) = (rng.next_f32(), rng.next_vec2());
        let Some(s) = bsdf.sample(wo, uc, u) else { break };
        beta *= s.weight;
        eta *= s.eta;
        let wi = si.shading.to_world(s.wi);
        prev = Some(BsdfSampled { from: si.p, pdf: s.pdf, delta: s.flags.contains(BsdfFlags::DELTA), n_bsdf: 1.0, n_light: 1.0 });
        ray = spawn_ray(si.p, si.n, wi);
        depth += 1;
        let beta_max = beta.max_component();
        if !(beta_max > 0.0) {
            break;
        }
        if depth >= rr_depth {
            let q = (beta_max * eta * eta).min(0.95);
            if rng.next_f32() >= q {
                break;
            }
            beta = beta / q;
        }
    }
    l
}
