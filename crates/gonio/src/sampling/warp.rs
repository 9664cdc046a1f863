//! Warps from the unit square to disks, hemispheres, spheres and spherical caps.
//!
//! Every warp is a triplet: `sample_*` maps `u ∈ [0,1)²` to the domain, `*_pdf` is the density of the result
//! with respect to area (disk) or solid angle (directions), and `invert_*` maps a point back to the `u`
//! that produces it. The round-trip and chi-square tests beside them (and in `verify::chi2`) hold the
//! three together.

use crate::math::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

const INV_2PI: f32 = 0.5 * FRAC_1_PI;
const INV_4PI: f32 = 0.25 * FRAC_1_PI;

/// Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square": concentric square → unit disk.
#[inline]
#[must_use]
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // Map each of the four wedges of the square to a wedge of the disk.
    let (r, theta) = if o.x.abs() > o.y.abs() { (o.x, FRAC_PI_4 * (o.y / o.x)) } else { (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y)) };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Density of [`sample_uniform_disk_concentric`] per unit area: 1/π inside the disk.
#[inline]
#[must_use]
pub fn uniform_disk_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// The inverse of [`sample_uniform_disk_concentric`].
#[must_use]
pub fn invert_uniform_disk_concentric(p: Vec2) -> Vec2 {
    let r = p.length();
    if r == 0.0 {
        return Vec2::splat(0.5);
    }
    let mut theta = p.y.atan2(p.x);
    // Bring θ into [−π/4, 7π/4) so that each wedge is one interval.
    if theta < -FRAC_PI_4 {
        theta += 2.0 * PI;
    }
    let o = if theta < FRAC_PI_4 {
        Vec2::new(r, r * theta / FRAC_PI_4)
    } else if theta < 3.0 * FRAC_PI_4 {
        Vec2::new(r * (FRAC_PI_2 - theta) / FRAC_PI_4, r)
    } else if theta < 5.0 * FRAC_PI_4 {
        Vec2::new(-r, -r * (theta - PI) / FRAC_PI_4)
    } else {
        Vec2::new(-r * (3.0 * FRAC_PI_2 - theta) / FRAC_PI_4, -r)
    };
    ((o + Vec2::ONE) * 0.5).clamp(Vec2::ZERO, Vec2::ONE)
}

/// Malley's method: the concentric disk projected up to the hemisphere gives density cos θ / π.
#[inline]
#[must_use]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_uniform_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of [`sample_cosine_hemisphere`]: cos θ / π above the horizon, 0 below.
#[inline]
#[must_use]
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    if w.z > 0.0 {
        w.z * FRAC_1_PI
    } else {
        0.0
    }
}

/// The inverse of [`sample_cosine_hemisphere`].
#[inline]
#[must_use]
pub fn invert_cosine_hemisphere_sample(w: Vec3) -> Vec2 {
    invert_uniform_disk_concentric(Vec2::new(w.x, w.y))
}

/// Uniform directions on the upper hemisphere: z = u₀, φ = 2π u₁.
#[inline]
#[must_use]
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_hemisphere`]: 1/(2π) above the horizon.
#[inline]
#[must_use]
pub fn uniform_hemisphere_pdf(w: Vec3) -> f32 {
    if w.z >= 0.0 {
        INV_2PI
    } else {
        0.0
    }
}

/// The inverse of [`sample_uniform_hemisphere`].
#[inline]
#[must_use]
pub fn invert_uniform_hemisphere_sample(w: Vec3) -> Vec2 {
    Vec2::new(w.z, phi_fraction(w))
}

/// Uniform directions on the sphere: z = 1 − 2u₀, φ = 2π u₁.
#[inline]
#[must_use]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_sphere`]: 1/(4π).
#[inline]
#[must_use]
pub fn uniform_sphere_pdf(_w: Vec3) -> f32 {
    INV_4PI
}

/// The inverse of [`sample_uniform_sphere`].
#[inline]
#[must_use]
pub fn invert_uniform_sphere_sample(w: Vec3) -> Vec2 {
    Vec2::new((1.0 - w.z) * 0.5, phi_fraction(w))
}

/// Uniform directions in the cap of half-angle θmax around +z: z = 1 − u₀ (1 − cos θmax).
#[inline]
#[must_use]
pub fn sample_uniform_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let z = 1.0 - u.x * (1.0 - cos_theta_max);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_cone`]: 1 / (2π (1 − cos θmax)) inside the cap.
#[inline]
#[must_use]
pub fn uniform_cone_pdf(w: Vec3, cos_theta_max: f32) -> f32 {
    if w.z >= cos_theta_max && cos_theta_max < 1.0 {
        1.0 / (2.0 * PI * (1.0 - cos_theta_max))
    } else {
        0.0
    }
}

/// The inverse of [`sample_uniform_cone`].
#[inline]
#[must_use]
pub fn invert_uniform_cone_sample(w: Vec3, cos_theta_max: f32) -> Vec2 {
    Vec2::new(((1.0 - w.z) / (1.0 - cos_theta_max)).clamp(0.0, 1.0), phi_fraction(w))
}

/// φ / 2π ∈ [0, 1).
#[inline]
fn phi_fraction(w: Vec3) -> f32 {
    let f = w.y.atan2(w.x) * INV_2PI;
    if f < 0.0 {
        f + 1.0
    } else {
        f
    }
}

/// Power-cosine lobe around +z: density (n+1)/(2π) cosⁿθ on the upper hemisphere, sampled by inverting its
/// polar CDF, cos θ = u₀^(1/(n+1)), φ = 2π u₁ (Phong 1975's lobe as a density; Lafortune & Willems 1994,
/// "Using the modified Phong reflectance model for physically based rendering", §4). `n ≥ 0`.
#[inline]
#[must_use]
pub fn sample_power_cosine_hemisphere(u: Vec2, n: f32) -> Vec3 {
    debug_assert!(n >= 0.0, "power-cosine exponent must be ≥ 0, got {n}");
    let z = u.x.powf(1.0 / (n + 1.0));
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_power_cosine_hemisphere`]: (n+1)/(2π) cosⁿθ above the horizon, 0 below.
#[inline]
#[must_use]
pub fn power_cosine_hemisphere_pdf(w: Vec3, n: f32) -> f32 {
    if w.z > 0.0 {
        (n + 1.0) * INV_2PI * w.z.powf(n)
    } else {
        0.0
    }
}

/// The inverse of [`sample_power_cosine_hemisphere`].
#[inline]
#[must_use]
pub fn invert_power_cosine_hemisphere_sample(w: Vec3, n: f32) -> Vec2 {
    Vec2::new(w.z.max(0.0).powf(n + 1.0).min(1.0), phi_fraction(w))
}

#[cfg(test)]
mod power_cosine_tests {
    use super::*;

    #[test]
    fn round_trip() {
        for n in [0.0f32, 1.0, 10.0, 300.0] {
            for (i, j) in (1..20).flat_map(|i| (1..20).map(move |j| (i, j))) {
                let u = Vec2::new(i as f32 / 20.0, j as f32 / 20.0);
                let w = sample_power_cosine_hemisphere(u, n);
                assert!((w.length() - 1.0).abs() < 1e-5);
                let back = invert_power_cosine_hemisphere_sample(w, n);
                assert!((back - u).abs().max_element() < 2e-3, "n={n} u={u} back={back}");
            }
        }
    }

    #[test]
    fn pdf_integrates_to_one() {
        // Midpoint rule over (θ, φ) in f64-accumulated f32 evaluations.
        for n in [0.0f32, 1.0, 30.0, 1000.0] {
            let steps = 20_000;
            let dtheta = std::f64::consts::FRAC_PI_2 / steps as f64;
            let total: f64 = (0..steps)
                .map(|k| {
                    let theta = (k as f64 + 0.5) * dtheta;
                    let w = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
                    power_cosine_hemisphere_pdf(w, n) as f64 * 2.0 * std::f64::consts::PI * theta.sin() * dtheta
                })
                .sum();
            assert!((total - 1.0).abs() < 1e-3, "n={n}: {total}");
        }
    }
}
