//! Spherical coordinates: direction from (θ, φ) and back, solid-angle helpers.

use glam::Vec3;
use std::f32::consts::PI;

/// The unit direction with the given sin θ, cos θ and azimuth φ (frame: normal along +z).
#[inline]
#[must_use]
pub fn spherical_direction(sin_theta: f32, cos_theta: f32, phi: f32) -> Vec3 {
    let (sin_phi, cos_phi) = phi.sin_cos();
    Vec3::new(sin_theta.clamp(-1.0, 1.0) * cos_phi, sin_theta.clamp(-1.0, 1.0) * sin_phi, cos_theta.clamp(-1.0, 1.0))
}

/// Polar angle θ ∈ [0, π] of a unit direction (clamped so that |z| a hair above 1 gives a finite angle).
#[inline]
#[must_use]
pub fn spherical_theta(w: Vec3) -> f32 {
    w.z.clamp(-1.0, 1.0).acos()
}

/// Azimuth φ ∈ [0, 2π) of a direction.
#[inline]
#[must_use]
pub fn spherical_phi(w: Vec3) -> f32 {
    let p = w.y.atan2(w.x);
    if p < 0.0 {
        p + 2.0 * PI
    } else {
        p
    }
}

/// Solid angle of a spherical cap with half-angle θ: 2π (1 − cos θ).
#[inline]
#[must_use]
pub fn cap_solid_angle(cos_theta_max: f32) -> f32 {
    2.0 * PI * (1.0 - cos_theta_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_theta_phi() {
        for &(t, p) in &[(0.1f32, 0.2f32), (1.2, 3.0), (2.9, 5.9), (std::f32::consts::FRAC_PI_2 - 1e-4, 0.0)] {
            let w = spherical_direction(t.sin(), t.cos(), p);
            assert!((w.length() - 1.0).abs() < 1e-6);
            assert!((spherical_theta(w) - t).abs() < 1e-4);
            assert!((spherical_phi(w) - p).abs() < 1e-4);
        }
    }

    #[test]
    fn cap_of_hemisphere_is_two_pi() {
        assert!((cap_solid_angle(0.0) - 2.0 * PI).abs() < 1e-6);
        assert!((cap_solid_angle(-1.0) - 4.0 * PI).abs() < 1e-5);
    }
}
