//! Helmholtz reciprocity: f(ωo, ωi) = f(ωi, ωo) for reflection. For transmission through an interface of
//! relative index η the radiance factor breaks plain symmetry; the reciprocal quantity is
//! f(ωo, ωi) / η_o² = f(ωi, ωo) / η_i², η_o and η_i being the indices on the sides of ωo and ωi
//! (Veach 1997, eq. 5.14).

use super::random_direction;
use crate::bsdf::{BsdfFlags, BsdfModel};
use crate::math::{Vec2, Vec3};
use crate::sampling::Pcg32;

/// Values below this (in sr⁻¹) on both sides are not compared: relative error is meaningless at f32
/// underflow scale (2026-11: the smallest f that matters for rendering is far above it).
const NEGLIGIBLE: f32 = 1e-12;

/// The outcome of a reciprocity test.
#[derive(Clone, Debug, PartialEq)]
pub struct ReciprocityResult {
    /// Largest relative error |a − b| / max(a, b) over all pairs and channels.
    pub max_rel_error: f64,
    /// The pair where it occurred.
    pub worst: Option<(Vec3, Vec3)>,
    /// How many pairs had a non-negligible value.
    pub compared: usize,
}

/// The relative index η_inside/η_outside a transmissive model reports when sampled from above, or 1.
fn relative_eta<M: BsdfModel + ?Sized>(bsdf: &M) -> f32 {
    if !bsdf.flags().intersects(BsdfFlags::TRANSMISSION) {
        return 1.0;
    }
    let wo = Vec3::new(0.0, 0.0, 1.0);
    (0..64).filter_map(|k| bsdf.sample(wo, (k as f32 + 0.5) / 64.0, Vec2::new(0.37, 0.61))).find(|s| s.wi.z < 0.0).map_or(1.0, |s| s.eta)
}

/// Compare f(wo, wi) with f(wi, wo) at `pairs` random direction pairs over the whole sphere.
#[must_use]
pub fn reciprocity<M: BsdfModel + ?Sized>(bsdf: &M, pairs: usize, seed: u64) -> ReciprocityResult {
    let eta = relative_eta(bsdf);
    let mut rng = Pcg32::new(seed, 0x5ec1);
    let mut result = ReciprocityResult { max_rel_error: 0.0, worst: None, compared: 0 };
    for _ in 0..pairs {
        let wo = random_direction(&mut rng);
        let wi = random_direction(&mut rng);
        let (a, b) = (bsdf.f(wo, wi), bsdf.f(wi, wo));
        // Scale transmission by 1/η² of the side of the first argument (outside: η = 1, inside: η).
        let side_eta2 = |w: Vec3| if w.z < 0.0 { (eta * eta) as f64 } else { 1.0 };
        let (sa, sb) = if wo.z * wi.z < 0.0 { (1.0 / side_eta2(wo), 1.0 / side_eta2(wi)) } else { (1.0, 1.0) };
        let mut counted = false;
        for c in 0..3 {
            let (x, y) = (a.0[c] as f64 * sa, b.0[c] as f64 * sb);
            let m = x.abs().max(y.abs());
            if m <= NEGLIGIBLE as f64 {
                continue;
            }
            counted = true;
            let e = (x - y).abs() / m;
            if !(e <= result.max_rel_error) {
                result.max_rel_error = if e.is_nan() { f64::INFINITY } else { e };
                result.worst = Some((wo, wi));
            }
        }
        result.compared += counted as usize;
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    #[test]
    fn lambertian_is_exactly_reciprocal() {
        let b = Bsdf::from_json(r#"{"type": "twosided", "a": {"type": "diffuse", "reflectance": [0.3, 0.6, 0.9]}}"#).unwrap();
        let r = reciprocity(&b, 10_000, 1);
        assert_eq!(r.max_rel_error, 0.0);
        assert!(r.compared > 4000);
    }

    /// f = (1 + cos θi)/(2π): not symmetric in its arguments.
    struct Skewed;
    impl BsdfModel for Skewed {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::GLOSSY_REFLECTION
        }
        fn f(&self, wo: Vec3, wi: Vec3) -> crate::Rgb {
            if wo.z > 0.0 && wi.z > 0.0 {
                crate::Rgb::splat((1.0 + wi.z) / (2.0 * std::f32::consts::PI))
            } else {
                crate::Rgb::ZERO
            }
        }
        fn sample(&self, _wo: Vec3, _uc: f32, _u: Vec2) -> Option<crate::BsdfSample> {
            None
        }
        fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
            0.0
        }
    }

    #[test]
    fn a_non_reciprocal_model_is_caught() {
        let r = reciprocity(&Skewed, 1000, 2);
        assert!(r.max_rel_error > 0.1, "{r:?}");
        let (wo, wi) = r.worst.unwrap();
        assert!(wo.z > 0.0 && wi.z > 0.0);
    }

    #[test]
    fn transmission_eta_is_found_by_sampling() {
        let d = Bsdf::from_json(r#"{"type": "dielectric"}"#).unwrap();
        assert!((relative_eta(&d) - 1.5046 / 1.000_277).abs() < 1e-5);
        assert_eq!(relative_eta(&Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap()), 1.0);
    }
}
