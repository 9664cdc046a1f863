//! Albedo data: the directional albedo a(θo) = ∫ f(ωo, ωi) |cos θi| dωi against the viewing angle,
//! estimated by gonio's energy check ([`crate::verify::energy::albedo`]: the model's own sampling,
//! stratified; transmission counted as energy). A white Lambertian surface gives 1 at every θo, a lossy
//! rough metal falls off towards grazing angles where masking removes energy.
//!
//! θo is sampled at the midpoints θo,k = 90° · (k + ½)/count (the horizon itself is never hit), with ωo
//! = (sin θo, 0, cos θo) and seed `seed + k` for the k-th angle.

use super::outgoing;
use crate::bsdf::BsdfModel;
use crate::error::{Error, Result};
use crate::spectrum::Rgb;
use crate::verify::energy::albedo;
use rayon::prelude::*;

/// The albedo curve of a model (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoData {
    /// θo in degrees.
    pub theta_o: Vec<f64>,
    /// The directional albedo at each θo (dimensionless, per channel).
    pub albedo: Vec<Rgb>,
}

/// The albedo of `bsdf` at `count` viewing angles (≥ 1), each from `samples` samples (≥ 1).
pub fn albedo_data<M: BsdfModel + Sync + ?Sized>(bsdf: &M, count: usize, samples: usize, seed: u64) -> Result<AlbedoData> {
    if count == 0 {
        return Err(Error::spec("angles", "need at least one viewing angle, got 0"));
    }
    if samples == 0 {
        return Err(Error::spec("samples", "need at least one sample per angle, got 0"));
    }
    let theta_o: Vec<f64> = (0..count).map(|k| 90.0 * (k as f64 + 0.5) / count as f64).collect();
    let albedo = theta_o.par_iter().enumerate().map(|(k, &t)| albedo(bsdf, outgoing(t), samples, seed.wrapping_add(k as u64))).collect();
    Ok(AlbedoData { theta_o, albedo })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    #[test]
    fn diffuse_albedo_curve_is_flat_at_rho() {
        let b = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#).unwrap();
        let data = albedo_data(&b, 18, 1024, 7).unwrap();
        assert_eq!((data.theta_o[0], data.theta_o[17]), (2.5, 87.5));
        for (t, a) in data.theta_o.iter().zip(&data.albedo) {
            // Cosine sampling makes every weight ρ: flat to f32 rounding.
            assert!((a.r() - 0.2).abs() < 1e-5 && (a.g() - 0.5).abs() < 1e-5 && (a.b() - 0.8).abs() < 1e-5, "θo = {t}: {a}");
        }
    }

    #[test]
    fn curve_is_the_energy_check_at_documented_angles_and_seeds() {
        let b = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.8, "material": "none"}"#).unwrap();
        let data = albedo_data(&b, 6, 1024, 40).unwrap();
        for (k, (&t, &a)) in data.theta_o.iter().zip(&data.albedo).enumerate() {
            assert_eq!(t, 7.5 + 15.0 * k as f64);
            let w = crate::math::Vec3::new(t.to_radians().sin() as f32, 0.0, t.to_radians().cos() as f32);
            assert_eq!(a, albedo(&b, w, 1024, 40 + k as u64), "θo = {t}");
            // A perfect reflector with single scattering only: energy is lost, never gained.
            assert!(a.r() < 1.0 && a.r() > 0.3, "θo = {t}: {a}");
        }
    }

    #[test]
    fn bad_counts_are_errors() {
        let b = Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap();
        assert!(albedo_data(&b, 0, 10, 0).unwrap_err().to_string().starts_with("angles:"));
        assert!(albedo_data(&b, 3, 0, 0).unwrap_err().to_string().starts_with("samples:"));
    }
}
