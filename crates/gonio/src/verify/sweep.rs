//! NaN/Inf sweep: query `f`, `pdf` and `sample` with random and degenerate inputs and demand finite,
//! non-negative answers everywhere (in release builds too, where debug assertions are off).
//!
//! A quarter of the queries are degenerate: `wo` from a list of directions that break careless code —
//! exactly on the horizon (z = 0), grazing from above and just below it (|z| = 1e-7 … 1e-3), exactly on the
//! poles (±normal), within f32 precision of the poles (sin θ underflowing), denormal and subnormal-squared
//! components, lengths off by 1e-6 — and `wi` one of −wo, wo, its mirror image about the normal, its
//! image through the surface, another listed direction or a random one; the sample coordinates are 0,
//! ½, the smallest positive float or just below 1. In these queries the sampled `wi` is fed back to `f`
//! and `pdf` in both argument orders, which reaches the exact refraction and half-vector-degenerate
//! directions of each model. A sampled direction must also be of unit length (within 1e-3).

use super::random_direction;
use crate::bsdf::BsdfModel;
use crate::math::{Vec2, Vec3};
use crate::sampling::Pcg32;
use rayon::prelude::*;

/// The outcome of a sweep.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepResult {
    /// Number of (wo, wi, uc, u) queries, each exercising `f`, `pdf` and `sample`.
    pub queries: usize,
    /// Queries with any non-finite or negative output.
    pub bad: usize,
    /// The first bad query, described.
    pub first_bad: Option<String>,
}

/// Directions that break careless code.
fn degenerate_directions() -> Vec<Vec3> {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let mut v = vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::Y,
        -Vec3::X,
        Vec3::new(s, s, 0.0),
        Vec3::new(1.0, 0.0, 1e-7).normalize(),
        Vec3::new(1.0, 0.0, -1e-7).normalize(),
        Vec3::new(1e-40, 0.0, 1.0),
        Vec3::new(1e-40, -1e-40, -1.0),
        Vec3::new(1.0, 1e-40, 1e-40),
        Vec3::new(0.0, 0.0, 1.0 + 1e-6),
        Vec3::new(0.0, 0.0, 1.0 - 1e-6),
        Vec3::new(0.6, 0.0, 0.8) * (1.0 + 1e-6),
        Vec3::new(0.6, 0.0, -0.8) * (1.0 - 1e-6),
        Vec3::new(s, 0.0, s),
        Vec3::new(0.999_999, 0.0, 0.001_414_2),
        // Grazing from above, and just below the horizon.
        Vec3::new(1.0, 0.0, 1e-4).normalize(),
        Vec3::new(1.0, 0.0, 1e-3).normalize(),
        Vec3::new(1.0, 0.0, -1e-4).normalize(),
        Vec3::new(0.6, 0.8, -1e-6).normalize(),
        Vec3::new(0.6, -0.8, 0.0),
        // z a denormal, and z whose square underflows.
        Vec3::new(1.0, 0.0, f32::MIN_POSITIVE),
        Vec3::new(1.0, 0.0, -1e-40),
        Vec3::new(1.0, 0.0, 1e-20),
        Vec3::new(0.0, 1.0, -1e-20),
        // Within f32 precision of the poles: sin θ is 0 or underflows when squared.
        Vec3::new(1e-20, 0.0, 1.0),
        Vec3::new(0.0, 1e-20, -1.0),
        Vec3::new(3e-4, 0.0, 1.0).normalize(),
        Vec3::new(0.0, -3e-4, -1.0).normalize(),
        Vec3::new(1e-40, 1e-40, -1.0),
        -Vec3::Y,
    ];
    let mirrored: Vec<Vec3> = v.iter().map(|w| Vec3::new(-w.x, -w.y, w.z)).collect();
    v.extend(mirrored);
    v
}

fn degenerate_samples() -> [f32; 4] {
    [0.0, 0.5, 1.0 - f32::EPSILON, f32::MIN_POSITIVE]
}

/// Check one query; `None` if every output is finite and non-negative, otherwise what went wrong.
fn probe<M: BsdfModel + ?Sized>(bsdf: &M, wo: Vec3, wi: Vec3, uc: f32, u: Vec2, feed_back: bool) -> Option<String> {
    let f = bsdf.f(wo, wi);
    if !f.is_finite() || f.min_component() < 0.0 {
        return Some(format!("f(wo={wo}, wi={wi}) = {f}"));
    }
    let pdf = bsdf.pdf(wo, wi);
    if !pdf.is_finite() || pdf < 0.0 {
        return Some(format!("pdf(wo={wo}, wi={wi}) = {pdf}"));
    }
    if let Some(s) = bsdf.sample(wo, uc, u) {
        let ok = s.wi.is_finite()
            && s.pdf.is_finite()
            && s.pdf > 0.0
            && s.weight.is_finite()
            && s.weight.min_component() >= 0.0
            && s.f.is_finite()
            && s.f.min_component() >= 0.0
            && s.eta.is_finite()
            && s.eta > 0.0
            && (s.wi.length() - 1.0).abs() < 1e-3;
        if !ok {
            return Some(format!("sample(wo={wo}, uc={uc}, u={u}) = {s:?}"));
        }
        // The sampled direction, fed back: f and pdf there (and with the arguments swapped, as an adjoint
        // or reciprocity check would ask) must be finite too. Delta directions are as good a query as any.
        if feed_back {
            for (a, b) in [(wo, s.wi), (s.wi, wo)] {
                let f = bsdf.f(a, b);
                let pdf = bsdf.pdf(a, b);
                if !f.is_finite() || f.min_component() < 0.0 || !pdf.is_finite() || pdf < 0.0 {
                    return Some(format!("at a sampled direction: f(wo={a}, wi={b}) = {f}, pdf = {pdf}"));
                }
            }
        }
    }
    None
}

/// Run at least `queries` queries (a quarter of them built from degenerate directions and sample values).
#[must_use]
pub fn sweep<M: BsdfModel + Sync + ?Sized>(bsdf: &M, queries: usize, seed: u64) -> SweepResult {
    let dirs = degenerate_directions();
    let us = degenerate_samples();
    const CHUNK: usize = 16_384;
    let chunks = queries.div_ceil(CHUNK);
    let partial: Vec<SweepResult> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut rng = Pcg32::new(seed, c as u64);
            let mut r = SweepResult::default();
            for k in 0..CHUNK {
                let degenerate = k % 4 == 0;
                let (wo, wi, uc, u) = if degenerate {
                    // Degenerate: wo from the list, wi one of −wo, wo, mirror, another listed or random one.
                    let wo = dirs[rng.next_u32() as usize % dirs.len()];
                    let wi = match rng.next_u32() % 6 {
                        0 => -wo,
                        1 => wo,
                        2 => Vec3::new(-wo.x, -wo.y, wo.z),
                        3 => dirs[rng.next_u32() as usize % dirs.len()],
                        4 => Vec3::new(wo.x, wo.y, -wo.z),
                        _ => random_direction(&mut rng),
                    };
                    let pick = |rng: &mut Pcg32| us[rng.next_u32() as usize % us.len()];
                    (wo, wi, pick(&mut rng), Vec2::new(pick(&mut rng), pick(&mut rng)))
                } else {
                    (random_direction(&mut rng), random_direction(&mut rng), rng.next_f32(), rng.next_vec2())
                };
                r.queries += 1;
                if let Some(msg) = probe(bsdf, wo, wi, uc, u, degenerate) {
                    r.bad += 1;
                    r.first_bad.get_or_insert(msg);
                }
            }
            r
        })
        .collect();
    partial.into_iter().fold(SweepResult::default(), |mut acc, r| {
        acc.queries += r.queries;
        acc.bad += r.bad;
        if acc.first_bad.is_none() {
            acc.first_bad = r.first_bad;
        }
        acc
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bsdf, BsdfFlags, BsdfSample};
    use crate::Rgb;

    #[test]
    fn every_example_model_is_finite() {
        for spec in Bsdf::examples() {
            let b = Bsdf::from_json(spec).unwrap();
            let r = sweep(&b, 100_000, 7);
            assert!(r.queries >= 100_000);
            assert_eq!(r.bad, 0, "{spec}: {:?}", r.first_bad);
        }
    }

    /// f = 1/cos θi: infinite on the horizon.
    struct Careless;
    impl BsdfModel for Careless {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::GLOSSY_REFLECTION
        }
        fn f(&self, _wo: Vec3, wi: Vec3) -> Rgb {
            Rgb::splat(1.0 / wi.z.abs())
        }
        fn sample(&self, _wo: Vec3, _uc: f32, _u: Vec2) -> Option<BsdfSample> {
            None
        }
        fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
            0.0
        }
    }

    /// Always samples the direction `AIM` (finite sample), but f and pdf divide by the distance to it.
    struct InfiniteAtItsSample;
    const AIM: Vec3 = Vec3::new(0.48, 0.6, 0.64);
    impl BsdfModel for InfiniteAtItsSample {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::GLOSSY_REFLECTION
        }
        fn f(&self, _wo: Vec3, wi: Vec3) -> Rgb {
            Rgb::splat(1e-3 / (wi - AIM).length_squared())
        }
        fn sample(&self, _wo: Vec3, _uc: f32, _u: Vec2) -> Option<BsdfSample> {
            BsdfSample::smooth(AIM, Rgb::splat(0.1), 1.0, BsdfFlags::GLOSSY_REFLECTION, 1.0)
        }
        fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
            1.0
        }
    }

    #[test]
    fn sampled_directions_are_fed_back_to_f() {
        let r = sweep(&InfiniteAtItsSample, 20_000, 1);
        assert_eq!(4 * r.bad, r.queries, "every degenerate query samples AIM, where f is infinite");
        assert!(r.first_bad.unwrap().contains("at a sampled direction"));
    }

    /// Samples a direction of length 2.
    struct LongSample;
    impl BsdfModel for LongSample {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::GLOSSY_REFLECTION
        }
        fn f(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
            Rgb::splat(0.1)
        }
        fn sample(&self, _wo: Vec3, _uc: f32, _u: Vec2) -> Option<BsdfSample> {
            BsdfSample::smooth(Vec3::new(0.0, 0.0, 2.0), Rgb::splat(0.1), 1.0, BsdfFlags::GLOSSY_REFLECTION, 1.0)
        }
        fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
            1.0
        }
    }

    #[test]
    fn a_sampled_direction_must_be_unit_length() {
        assert_eq!(sweep(&LongSample, 1000, 1).bad, 16_384);
    }

    #[test]
    fn a_division_by_cos_theta_is_caught() {
        let r = sweep(&Careless, 20_000, 1);
        assert!(r.bad > 0);
        assert!(r.first_bad.unwrap().contains("inf"));
    }
}
