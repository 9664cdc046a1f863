//! Energy (to be written).
use crate::bsdf::{Bsdf, BsdfModel};
use crate::math::Vec3;
use crate::sampling::Pcg32;
use crate::spectrum::Rgb;

/// Directional albedo ∫ f cos dωi estimated with the model's own sampling, `n` samples.
pub fn albedo(bsdf: &Bsdf, wo: Vec3, n: usize, seed: u64) -> Rgb {
    let mut rng = Pcg32::new(seed, 0);
    let mut sum = [0f64; 3];
    for _ in 0..n {
        if let Some(s) = bsdf.sample(wo, rng.next_f32(), rng.next_vec2()) {
            for c in 0..3 { sum[c] += s.weight.0[c] as f64; }
        }
    }
    Rgb::new((sum[0] / n as f64) as f32, (sum[1] / n as f64) as f32, (sum[2] / n as f64) as f32)
}
