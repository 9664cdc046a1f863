//! Sample-weight consistency: for every sample of a smooth lobe, `weight == f·|cos θi|/pdf`,
//! `f == bsdf.f(wo, wi)` and `pdf == bsdf.pdf(wo, wi)`; for a delta lobe, a probability in (0, 1].
//! Integrators rely on all three agreeing (MIS combines `pdf` with the light's density).

use crate::bsdf::BsdfModel;
use crate::math::Vec3;
use crate::sampling::Pcg32;
use crate::spectrum::Rgb;

/// Largest relative disagreement found, with where.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConsistencyResult {
    pub samples: usize,
    /// max |weight − f cos/pdf| / max(weight, f cos/pdf)
    pub weight_error: f64,
    /// max relative |s.f − f(wo, s.wi)|
    pub f_error: f64,
    /// max relative |s.pdf − pdf(wo, s.wi)|
    pub pdf_error: f64,
    /// Delta samples whose probability is outside (0, 1].
    pub bad_delta: usize,
    pub worst: Option<String>,
}

impl ConsistencyResult {
    #[must_use]
    pub fn max_error(&self) -> f64 {
        self.weight_error.max(self.f_error).max(self.pdf_error)
    }
}

/// Values with magnitude below this are compared absolutely (2026-11: relative error of two f32
/// values near underflow says nothing).
const FLOOR: f64 = 1e-6;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(FLOOR)
}

fn rel_rgb(a: Rgb, b: Rgb) -> f64 {
    (0..3).map(|c| rel(a.0[c] as f64, b.0[c] as f64)).fold(0.0, f64::max)
}

/// Draw `n` samples at each of the directions `wos` and compare.
#[must_use]
pub fn consistency<M: BsdfModel + ?Sized>(bsdf: &M, wos: &[Vec3], n: usize, seed: u64) -> ConsistencyResult {
    let mut r = ConsistencyResult::default();
    for (i, &wo) in wos.iter().enumerate() {
        let mut rng = Pcg32::new(seed, i as u64);
        for _ in 0..n {
            let Some(s) = bsdf.sample(wo, rng.next_f32(), rng.next_vec2()) else { continue };
            r.samples += 1;
            if s.flags.has_delta() {
                if !(s.pdf > 0.0 && s.pdf <= 1.0 + 1e-6) {
                    r.bad_delta += 1;
                    r.worst.get_or_insert(format!("delta sample with probability {} at wo={wo}", s.pdf));
                }
                continue;
            }
            let expect_weight = s.f * (s.wi.z.abs() / s.pdf);
            let errs = [rel_rgb(s.weight, expect_weight), rel_rgb(s.f, bsdf.f(wo, s.wi)), rel(s.pdf as f64, bsdf.pdf(wo, s.wi) as f64)];
            let worse = errs[0] > r.weight_error || errs[1] > r.f_error || errs[2] > r.pdf_error;
            r.weight_error = r.weight_error.max(errs[0]);
            r.f_error = r.f_error.max(errs[1]);
            r.pdf_error = r.pdf_error.max(errs[2]);
            if worse {
                r.worst = Some(format!(
                    "wo={wo}, wi={}: weight {} vs f·cos/pdf {expect_weight}, pdf {} vs {}",
                    s.wi,
                    s.weight,
                    s.pdf,
                    bsdf.pdf(wo, s.wi)
                ));
            }
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    #[test]
    fn examples_are_consistent() {
        let wos = [Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::new(0.99, 0.0, 0.05).normalize(), Vec3::new(0.2, 0.3, -0.8).normalize()];
        for spec in Bsdf::examples() {
            let b = Bsdf::from_json(spec).unwrap();
            let r = consistency(&b, &wos, 20_000, 5);
            assert!(r.max_error() < 1e-4 && r.bad_delta == 0, "{spec}: {r:?}");
        }
    }
}
