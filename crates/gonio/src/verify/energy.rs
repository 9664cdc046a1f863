//! Energy conservation: the directional albedo a(ωo) = ∫ f(ωo, ωi) |cos θi| dωi, and the white furnace.
//!
//! The albedo is estimated with the model's own sampling (E[weight]) on stratified samples, so a model
//! whose weights are constant — white Lambertian, a perfect mirror — gives its exact albedo. For
//! transmission the radiance factor (ηᵢ/ηₜ)² is undone (the weight is multiplied by `eta²`): energy, not
//! radiance, is what must be conserved (Veach 1997, §5.2). The white furnace is the hemispherical
//! average (1/π)∫ a(ωo) |cos θo| dωo: the fraction of uniform incident light that a surface reflects or
//! transmits.

use crate::bsdf::{BsdfFlags, BsdfModel};
use crate::math::{Vec2, Vec3};
use crate::sampling::Pcg32;
use crate::spectrum::Rgb;

/// Directional albedo ∫ f cos dωi at `wo`, from `n` samples (rounded up to a square) of the model's own
/// sampling, stratified in `u` and jittered in `uc`. Transmission counts energy (see the module doc).
/// The samples go to the model in batches (its lanes), which give each sample as a single call would.
#[must_use]
pub fn albedo<M: BsdfModel + ?Sized>(bsdf: &M, wo: Vec3, n: usize, seed: u64) -> Rgb {
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let mut rng = Pcg32::new(seed, 0x0a1b);
    let mut sum = [0f64; 3];
    let count = side * side;
    let draw = |k: usize| {
        let (i, j) = (k % side, k / side);
        let u = Vec2::new((i as f32 + rng.next_f32()) / side as f32, (j as f32 + rng.next_f32()) / side as f32);
        // A Latin-hypercube permutation of the lobe-selection strata.
        let uc = ((k * 7919 + 13) % count) as f32 / count as f32 + rng.next_f32() / count as f32;
        (uc.min(1.0 - f32::EPSILON), u)
    };
    super::sample_batches(bsdf, wo, count, draw, |rows, m| {
        for r in 0..m {
            if rows.valid[r] {
                let transmits = BsdfFlags(rows.flags[r]).intersects(BsdfFlags::TRANSMISSION);
                let scale = if transmits { rows.eta[r] * rows.eta[r] } else { 1.0 };
                for (acc, w) in sum.iter_mut().zip(rows.weight[r].0) {
                    *acc += (w * scale) as f64;
                }
            }
        }
    });
    Rgb::new((sum[0] / count as f64) as f32, (sum[1] / count as f64) as f32, (sum[2] / count as f64) as f32)
}

/// The albedo at the polar angle whose cosine is `cos_theta_o` (negative: from below), azimuth φ = 0.3.
#[must_use]
pub fn albedo_at<M: BsdfModel + ?Sized>(bsdf: &M, cos_theta_o: f32, n: usize, seed: u64) -> Rgb {
    albedo(bsdf, direction(cos_theta_o, 0.3), n, seed)
}

/// A unit direction with the given cos θ and azimuth φ.
#[must_use]
pub fn direction(cos_theta: f32, phi: f32) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Albedo for `count` values of cos θo spread over (0, 1] (midpoints, so the horizon itself is never hit),
/// on the side given by `sign` (+1 above, −1 below).
#[must_use]
pub fn albedo_curve<M: BsdfModel + ?Sized>(bsdf: &M, count: usize, sign: f32, n: usize, seed: u64) -> Vec<(f32, Rgb)> {
    (0..count)
        .map(|k| {
            let mu = (k as f32 + 0.5) / count as f32;
            (sign * mu, albedo_at(bsdf, sign * mu, n, seed + k as u64))
        })
        .collect()
}

/// White furnace: (1/π) ∫ a(ωo) |cos θo| dωo = 2 ∫₀¹ a(μ) μ dμ over one side, by the midpoint rule on
/// an albedo curve with evenly spaced μ.
#[must_use]
pub fn white_furnace(curve: &[(f32, Rgb)]) -> Rgb {
    let n = curve.len() as f32;
    curve.iter().fold(Rgb::ZERO, |acc, (mu, a)| acc + *a * (2.0 * mu.abs() / n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    #[test]
    fn lossless_models_have_unit_albedo() {
        for spec in [
            r#"{"type": "diffuse", "reflectance": 1}"#,
            r#"{"type": "conductor"}"#,
            r#"{"type": "dielectric", "int_ior": 1.5, "ext_ior": 1}"#,
            r#"{"type": "thindielectric"}"#,
            r#"{"type": "twosided", "a": {"type": "diffuse", "reflectance": 1}}"#,
        ] {
            let b = Bsdf::from_json(spec).unwrap();
            for mu in [1.0, 0.5, 0.05, -0.5] {
                if mu < 0.0 && !crate::verify::scatters_from_below(&b) {
                    continue;
                }
                let a = albedo_at(&b, mu, 4096, 1);
                assert!((a.max_component() - 1.0).abs() < 1e-3 && (a.min_component() - 1.0).abs() < 1e-3, "{spec} at μ={mu}: {a}");
            }
        }
    }

    #[test]
    fn lambertian_albedo_is_rho_and_furnace_is_rho() {
        let b = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#).unwrap();
        let curve = albedo_curve(&b, 16, 1.0, 1024, 3);
        for (_, a) in &curve {
            assert!((a.r() - 0.2).abs() < 1e-5 && (a.b() - 0.8).abs() < 1e-5);
        }
        let w = white_furnace(&curve);
        assert!((w.g() - 0.5).abs() < 1e-3, "{w}");
    }

    #[test]
    fn batched_albedo_is_the_sum_of_single_samples() {
        // The estimator written one `sample` call at a time: the batches must give it bit for bit (same
        // random numbers in the same order, same sum), also over a last, partial batch (27² = 729 samples).
        let single = |b: &Bsdf, wo: Vec3, n: usize, seed: u64| {
            let side = (n as f64).sqrt().ceil() as usize;
            let (count, mut rng, mut sum) = (side * side, Pcg32::new(seed, 0x0a1b), [0f64; 3]);
            for k in 0..count {
                let (i, j) = (k % side, k / side);
                let u = Vec2::new((i as f32 + rng.next_f32()) / side as f32, (j as f32 + rng.next_f32()) / side as f32);
                let uc = ((k * 7919 + 13) % count) as f32 / count as f32 + rng.next_f32() / count as f32;
                if let Some(s) = b.sample(wo, uc.min(1.0 - f32::EPSILON), u) {
                    let scale = if s.flags.intersects(BsdfFlags::TRANSMISSION) { s.eta * s.eta } else { 1.0 };
                    for (acc, w) in sum.iter_mut().zip(s.weight.0) {
                        *acc += (w * scale) as f64;
                    }
                }
            }
            sum.map(|x| (x / count as f64) as f32)
        };
        for spec in [
            r#"{"type": "roughconductor", "alpha_u": 0.1, "alpha_v": 0.4}"#,
            r#"{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3}"#,
            r#"{"type": "blendbsdf", "weight": 0.3, "a": {"type": "diffuse"}, "b": {"type": "dielectric"}}"#,
            r#"{"type": "oren_nayar", "sigma": 0.5}"#,
        ] {
            let b = Bsdf::from_json(spec).unwrap();
            for (mu, n) in [(0.8, 700), (-0.4, 256), (0.05, 1)] {
                let wo = direction(mu, 0.3);
                assert_eq!(albedo(&b, wo, n, 5).0.map(f32::to_bits), single(&b, wo, n, 5).map(f32::to_bits), "{spec} at μ = {mu}, n = {n}");
            }
        }
    }

    #[test]
    fn gold_albedo_is_its_fresnel_reflectance() {
        let b = Bsdf::from_json(r#"{"type": "conductor", "eta": [0.2, 0.4, 1.4], "k": [3.9, 2.4, 1.6]}"#).unwrap();
        let a = albedo(&b, Vec3::Z, 16, 0);
        let expect = crate::fresnel::fresnel_conductor(1.0, 0.2, 3.9);
        assert!((a.r() - expect).abs() < 1e-6);
        assert!(a.r() < 1.0 && a.r() > a.b());
    }
}
