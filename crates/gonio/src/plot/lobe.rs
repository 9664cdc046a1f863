//! Lobe data: f·cos θi for one viewing direction ωo, along two planes (polar plots) and over the sphere
//! of incident directions (3-D lobes). See the [module docs](super) for the conventions.
//!
//! # The two planes (angles `a` in degrees, `a ∈ [−180°, 180°]`)
//! - **Plane of incidence** (the xz-plane, which holds ωo and the normal): ωi(a) = (sin a, 0, cos a).
//!   a is the signed polar angle of ωi: a > 0 on the viewer's side, the mirror direction ωr at a = −θo,
//!   |a| > 90° below the surface (transmission).
//! - **Perpendicular plane**: the plane through the mirror direction ωr perpendicular to the plane of
//!   incidence, ωi(a) = cos a · ωr + sin a · ŷ, so a is the angle from ωr (a > 0 towards +y). At θo = 0
//!   it is the yz-plane. Here cos θi = cos a · cos θo.
//!
//! The value plotted is f(ωo, ωi)·|cos θi| in sr⁻¹ (per channel), the integrand of the reflection
//! equation: a Lambertian surface of albedo ρ gives ρ/π · cos a in the plane of incidence, a circle
//! through the origin in a polar plot. Delta lobes (mirrors, smooth glass) have no finite f and plot as 0.
//!
//! # The grid
//! ωi = (sin θ cos φ, sin θ sin φ, cos θ) with θ from 0° to 90° (to 180° when the model transmits
//! light) and φ ∈ [0°, 360°) — `grid_theta` × `grid_phi` values of f·|cos θi|, row-major in θ.

use super::{direction, linspace, outgoing};
use crate::bsdf::{BsdfFlags, BsdfModel};
use crate::error::{Error, Result};
use crate::math::Vec3;
use crate::spectrum::Rgb;
use rayon::prelude::*;

/// f·|cos θi| over the hemisphere (or sphere) of ωi, for the 3-D lobe.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LobeGrid {
    /// Polar angles θ of ωi in degrees, from 0 to 90 (or 180) inclusive.
    pub theta: Vec<f64>,
    /// Azimuths φ of ωi in degrees, `k · 360 / grid_phi` (the end point 360° is the start again).
    pub phi: Vec<f64>,
    /// f·|cos θi| (sr⁻¹) at (θ[i], φ[j]), at index `i · phi.len() + j`.
    pub values: Vec<Rgb>,
}

/// The lobe of a model for one viewing direction (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct LobeData {
    /// θo in degrees; ωo = (sin θo, 0, cos θo).
    pub theta_o: f64,
    /// The angles `a` of both planes, in degrees, evenly spaced over [−180°, 180°].
    pub angles: Vec<f64>,
    /// f·|cos θi| (sr⁻¹) in the plane of incidence at each angle.
    pub incidence: Vec<Rgb>,
    /// f·|cos θi| (sr⁻¹) in the perpendicular plane at each angle.
    pub perpendicular: Vec<Rgb>,
    /// The 3-D lobe (empty when `grid_theta` or `grid_phi` was 0).
    pub grid: LobeGrid,
}

/// An error unless `theta_o` (degrees) is a viewing angle above the surface: in [0°, 90°).
pub fn check_theta_o(theta_o: f64) -> Result<()> {
    if !(0.0..90.0).contains(&theta_o) {
        return Err(Error::spec("theta_o", format!("θo = {theta_o}° is outside [0°, 90°): the viewer must be above the surface")));
    }
    Ok(())
}

/// ωi in the plane of incidence at angle `a` (degrees).
#[must_use]
pub fn incidence_direction(a: f64) -> Vec3 {
    direction(a.to_radians(), 0.0)
}

/// ωi in the perpendicular plane at angle `a` (degrees) from the mirror direction of θo (degrees).
#[must_use]
pub fn perpendicular_direction(theta_o: f64, a: f64) -> Vec3 {
    let (sa, ca) = a.to_radians().sin_cos();
    let (so, co) = theta_o.to_radians().sin_cos();
    // ωr = (−sin θo, 0, cos θo) and ŷ are orthonormal, so this is a unit vector.
    Vec3::new((-ca * so) as f32, sa as f32, (ca * co) as f32)
}

/// f(ωo, ωi)·|cos θi|.
#[inline]
fn integrand<M: BsdfModel + ?Sized>(bsdf: &M, wo: Vec3, wi: Vec3) -> Rgb {
    bsdf.f(wo, wi) * wi.z.abs()
}

/// The lobe of `bsdf` seen from θo = `theta_o` degrees: `samples` angles (≥ 2) along each plane and a
/// `grid_theta` × `grid_phi` grid (0 for none). Errors name the argument that is out of range.
pub fn lobe_data<M: BsdfModel + Sync + ?Sized>(
    bsdf: &M,
    theta_o: f64,
    samples: usize,
    grid_theta: usize,
    grid_phi: usize,
) -> Result<LobeData> {
    check_theta_o(theta_o)?;
    if samples < 2 {
        return Err(Error::spec("samples", format!("need at least 2 angles per plane, got {samples}")));
    }
    if grid_theta == 1 {
        return Err(Error::spec("grid_theta", "need 0 (no grid) or at least 2 polar angles, got 1"));
    }
    let wo = outgoing(theta_o);
    let angles = linspace(-180.0, 180.0, samples);
    let incidence = angles.iter().map(|&a| integrand(bsdf, wo, incidence_direction(a))).collect();
    let perpendicular = angles.iter().map(|&a| integrand(bsdf, wo, perpendicular_direction(theta_o, a))).collect();
    let grid = if grid_theta == 0 || grid_phi == 0 {
        LobeGrid::default()
    } else {
        let theta_max = if bsdf.flags().intersects(BsdfFlags::TRANSMISSION) { 180.0 } else { 90.0 };
        let theta = linspace(0.0, theta_max, grid_theta);
        let phi: Vec<f64> = (0..grid_phi).map(|j| 360.0 * j as f64 / grid_phi as f64).collect();
        let values = theta
            .par_iter()
            .flat_map_iter(|&t| phi.iter().map(move |&p| integrand(bsdf, wo, direction(t.to_radians(), p.to_radians()))))
            .collect();
        LobeGrid { theta, phi, values }
    };
    Ok(LobeData { theta_o, angles, incidence, perpendicular, grid })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;
    use crate::plot::Channel;
    use std::f32::consts::PI;

    #[test]
    fn lambertian_polar_plot_is_a_circle_through_the_origin() {
        let rho = [0.2f32, 0.5, 0.8];
        let b = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#).unwrap();
        let lobe = lobe_data(&b, 40.0, 361, 0, 0).unwrap();
        assert_eq!(lobe.angles.len(), 361);
        for (&a, v) in lobe.angles.iter().zip(&lobe.incidence) {
            let wi = incidence_direction(a);
            for (&value, &rho_c) in v.0.iter().zip(&rho) {
                // r = ρ/π·cos a above the surface (to f32 rounding), 0 below.
                let expect = if wi.z > 0.0 { rho_c / PI * wi.z } else { 0.0 };
                assert!((value - expect).abs() <= 1e-6 * rho_c, "a = {a}: {value} vs {expect}");
                // The polar point (r sin a, r cos a) lies on the circle of diameter ρ/π centred at (0, ρ/2π).
                let (r, ar) = (f64::from(value), a.to_radians());
                let (x, y, half) = (r * ar.sin(), r * ar.cos(), f64::from(rho_c / PI) / 2.0);
                if wi.z > 0.0 {
                    assert!(((x * x + (y - half).powi(2)).sqrt() - half).abs() < 1e-7, "a = {a}: off the circle");
                }
            }
        }
        // In the perpendicular plane cos θi = cos a · cos θo.
        let at_mirror = lobe.perpendicular[180];
        assert!((at_mirror.g() - 0.5 / PI * 40f32.to_radians().cos()).abs() < 1e-6);
    }

    #[test]
    fn ggx_mirror_lobe_peaks_at_the_specular_direction() {
        let b = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.05}"#).unwrap();
        for theta_o in [0.0, 30.0, 60.0] {
            let lobe = lobe_data(&b, theta_o, 721, 0, 0).unwrap();
            let peak =
                |vals: &[Rgb]| (0..vals.len()).max_by(|&i, &j| Channel::Lum.of(vals[i]).total_cmp(&Channel::Lum.of(vals[j]))).unwrap();
            let i = peak(&lobe.incidence);
            assert!((lobe.angles[i] + theta_o).abs() <= 0.5, "θo = {theta_o}: in-plane peak at {}", lobe.angles[i]);
            let j = peak(&lobe.perpendicular);
            assert!(lobe.angles[j].abs() <= 0.5, "θo = {theta_o}: perpendicular peak at {}", lobe.angles[j]);
            // A sharp lobe: 40° away from the peak it has fallen by three orders of magnitude.
            let away = Channel::Lum.of(lobe.incidence[i + 80]);
            assert!(away < 1e-3 * Channel::Lum.of(lobe.incidence[i]), "θo = {theta_o}: not sharp");
        }
    }

    #[test]
    fn grid_covers_the_hemisphere_and_matches_the_planes() {
        let b = Bsdf::from_json(r#"{"type": "roughplastic", "alpha": 0.3}"#).unwrap();
        let lobe = lobe_data(&b, 30.0, 5, 7, 8).unwrap();
        assert_eq!((lobe.grid.theta.len(), lobe.grid.phi.len(), lobe.grid.values.len()), (7, 8, 56));
        assert_eq!((lobe.grid.theta[0], lobe.grid.theta[6], lobe.grid.phi[4]), (0.0, 90.0, 180.0));
        // The grid point (θ = 45°, φ = 0) is the plane-of-incidence point a = 45°.
        let grid_45 = lobe.grid.values[3 * 8];
        let plane = lobe_data(&b, 30.0, 9, 0, 0).unwrap(); // angles −180, −135, …, 45 at index 5
        assert_eq!(plane.angles[5], 45.0);
        assert_eq!(grid_45, plane.incidence[5]);
        // Rough glass transmits: its grid reaches θ = 180°.
        let glass = Bsdf::from_json(r#"{"type": "roughdielectric", "alpha": 0.2}"#).unwrap();
        assert_eq!(*lobe_data(&glass, 0.0, 3, 3, 4).unwrap().grid.theta.last().unwrap(), 180.0);
    }

    #[test]
    fn bad_arguments_are_errors() {
        let b = Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap();
        for t in [-1.0, 90.0, f64::NAN, f64::INFINITY] {
            let e = lobe_data(&b, t, 10, 0, 0).unwrap_err().to_string();
            assert!(e.starts_with("theta_o:") && e.contains("[0°, 90°)"), "{e}");
        }
        assert!(lobe_data(&b, 10.0, 1, 0, 0).unwrap_err().to_string().contains("samples"));
        assert!(lobe_data(&b, 10.0, 10, 1, 4).unwrap_err().to_string().contains("grid_theta"));
    }
}
