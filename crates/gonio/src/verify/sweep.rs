//! NaN/Inf sweep: query `f`, `pdf` and `sample` with random and degenerate inputs — directions on the
//! horizon, exactly on the poles, wi = −wo, wi = wo, denormal components, lengths off by 1e-6, sample
//! coordinates at 0 and just below 1 — and demand finite, non-negative answers everywhere.

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
    ];
    let mirrored: Vec<Vec3> = v.iter().map(|w| Vec3::new(-w.x, -w.y, w.z)).collect();
    v.extend(mirrored);
    v
}

fn degenerate_samples() -> [f32; 4] {
    [0.0, 0.5, 1.0 - f32::EPSILON, f32::MIN_POSITIVE]
}

/// Check one query; `None` if every output is finite and non-negative, otherwise what went wrong.
fn probe<M: BsdfModel + ?Sized>(bsdf: &M, wo: Vec3, wi: Vec3, uc: f32, u: Vec2) -> Option<String> {
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
            && s.eta > 0.0;
        if !ok {
            return Some(format!("sample(wo={wo}, uc={uc}, u={u}) = {s:?}"));
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
                let (wo, wi, uc, u) = if k % 4 == 0 {
                    // Degenerate: wo from the list, wi one of −wo, wo, mirror, another listed or random one.
                    let wo = dirs[rng.next_u32() as usize % dirs.len()];
                    let wi = match rng.next_u32() % 5 {
                        0 => -wo,
                        1 => wo,
                        2 => Vec3::new(-wo.x, -wo.y, wo.z),
                        3 => dirs[rng.next_u32() as usize % dirs.len()],
                        _ => random_direction(&mut rng),
                    };
                    let pick = |rng: &mut Pcg32| us[rng.next_u32() as usize % us.len()];
                    (wo, wi, pick(&mut rng), Vec2::new(pick(&mut rng), pick(&mut rng)))
                } else {
                    (random_direction(&mut rng), random_direction(&mut rng), rng.next_f32(), rng.next_vec2())
                };
                r.queries += 1;
                if let Some(msg) = probe(bsdf, wo, wi, uc, u) {
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

    #[test]
    fn a_division_by_cos_theta_is_caught() {
        let r = sweep(&Careless, 20_000, 1);
        assert!(r.bad > 0);
        assert!(r.first_bad.unwrap().contains("inf"));
    }
}
