//! Warps from the unit square to disks, hemispheres, spheres and spherical caps.
//!
//! Every warp is a triplet: `sample_*` maps `u ∈ [0,1)²` to the domain, `*_pdf` is the density of the result
//! with respect to area (disk) or solid angle (directions), and `invert_*` maps a point back to the `u`
//! that produces it. The round-trip and chi-square tests beside them (and in `verify::chi2`) hold the
//! three together.

use crate::math::lanes::{Real, V3};
use crate::math::trig::{sin_cos_quarter, sin_cos_turn};
use crate::math::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

const INV_2PI: f32 = 0.5 * FRAC_1_PI;
const INV_4PI: f32 = 0.25 * FRAC_1_PI;

/// Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square": concentric square → unit disk.
#[inline(always)]
#[must_use]
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = concentric_disk(u.x, u.y);
    Vec2::new(x, y)
}

/// [`sample_uniform_disk_concentric`] in lanes ([`Real`]): the point (x, y) for `(ux, uy)`.
#[inline(always)]
#[must_use]
pub fn concentric_disk<R: Real>(ux: R, uy: R) -> (R, R) {
    let (ox, oy) = (ux * 2.0 - 1.0, uy * 2.0 - 1.0);
    // Map each of the four wedges of the square to a wedge of the disk: θ = π/4 · (y/x) about the x axis,
    // or π/2 − π/4 · (x/y) about the y axis, whose cosine and sine are the sine and cosine of π/4 · (x/y).
    // Either way the angle to evaluate is in [−π/4, π/4], where a short polynomial is exact to f32.
    let x_major = ox.abs().gt(oy.abs());
    // (One division of the selected operands: the same quotient in each lane as selecting between two.)
    let (r, t) = (R::select(x_major, ox, oy), R::select(x_major, oy, ox) / R::select(x_major, ox, oy));
    let (s, c) = sin_cos_quarter(t * FRAC_PI_4);
    let (x, y) = (r * R::select(x_major, c, s), r * R::select(x_major, s, c));
    // The centre (where t is 0/0).
    let centre = ox.eq(R::splat(0.0)) & oy.eq(R::splat(0.0));
    (R::select(centre, R::splat(0.0), x), R::select(centre, R::splat(0.0), y))
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
#[inline(always)]
#[must_use]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    cosine_hemisphere(u.x, u.y).into()
}

/// [`sample_cosine_hemisphere`] in lanes ([`Real`]).
#[inline(always)]
#[must_use]
pub fn cosine_hemisphere<R: Real>(ux: R, uy: R) -> V3<R> {
    let (x, y) = concentric_disk(ux, uy);
    let z = (R::splat(1.0) - (x * x + y * y)).max(R::splat(0.0)).sqrt();
    V3::new(x, y, z)
}

/// Density of [`sample_cosine_hemisphere`]: cos θ / π above the horizon, 0 below.
#[inline(always)]
#[must_use]
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    cosine_hemisphere_density(w.z)
}

/// [`cosine_hemisphere_pdf`] in lanes, from cos θ.
#[inline(always)]
#[must_use]
pub fn cosine_hemisphere_density<R: Real>(cos_theta: R) -> R {
    R::select(cos_theta.gt(R::splat(0.0)), cos_theta * FRAC_1_PI, R::splat(0.0))
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
    uniform_sphere(u.x, u.y).into()
}

/// [`sample_uniform_sphere`] in lanes ([`Real`]): the direction for `(ux, uy)`, with φ's sine and cosine
/// from [`sin_cos_turn`] so that one `f32` and the lanes compute the same numbers.
#[inline(always)]
#[must_use]
pub fn uniform_sphere<R: Real>(ux: R, uy: R) -> V3<R> {
    let one = R::splat(1.0);
    let z = one - ux * 2.0;
    let r = (one - z * z).max(R::splat(0.0)).sqrt();
    let (sin_phi, cos_phi) = sin_cos_turn(uy);
    V3::new(r * cos_phi, r * sin_phi, z)
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
    fn chi2() {
        use crate::verify::chi2::{chi2_warp, Chi2Config};
        // Sharper lobes fall inside the default grid's polar cell (cos θ ∈ [0.95, 1], 18°) and its 6-point
        // quadrature no longer resolves them.
        let exponents = [0.0f32, 1.0, 20.0, 60.0];
        for (k, n) in exponents.into_iter().enumerate() {
            let cfg = Chi2Config { tests: exponents.len(), seed: k as u64, ..Chi2Config::default() };
            let r = chi2_warp(|u| sample_power_cosine_hemisphere(u, n), |w| f64::from(power_cosine_hemisphere_pdf(w, n)), &cfg);
            eprintln!("power cosine n={n}: {r}");
            assert!(r.passed, "n={n}: {r}");
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;
    use crate::verify::chi2::{chi2_plane, chi2_warp, Chi2Config};

    /// The cone apertures under test: wide, a hemisphere, beyond a hemisphere, and a narrow cap.
    const CONES: [f32; 4] = [0.5, 0.0, -0.5, 0.999];

    /// 32 × 32 grid points (cell centres) and 10 000 random points of [0, 1)².
    fn square_points() -> Vec<Vec2> {
        let mut rng = Pcg32::new(5, 7);
        let grid = (0..32 * 32).map(|i| Vec2::new((i % 32) as f32 + 0.5, (i / 32) as f32 + 0.5) / 32.0);
        grid.chain((0..10_000).map(|_| rng.next_vec2())).collect()
    }

    /// Distance between two `u` on the square where the second coordinate is an azimuth fraction: 0 and 1
    /// are the same φ, so the seam φ = 0 is compared modulo 1.
    fn azimuth_distance(a: Vec2, b: Vec2) -> f32 {
        let dy = (a.y - b.y).abs();
        (a.x - b.x).abs().max(dy.min(1.0 - dy))
    }

    /// Round trip of a direction warp of the (z, φ) kind. At the poles (sin θ < 10⁻³, a set of measure
    /// zero up to f32 rounding) φ is not recoverable and only u₀ is compared.
    fn round_trip_z_phi(sample: impl Fn(Vec2) -> Vec3, invert: impl Fn(Vec3) -> Vec2, name: &str) {
        for u in square_points() {
            let w = sample(u);
            let back = invert(w);
            let sin_theta = (w.x * w.x + w.y * w.y).sqrt();
            let err = if sin_theta < 1e-3 { (u.x - back.x).abs() } else { azimuth_distance(u, back) };
            assert!(err < 1e-4, "{name}: u = {u} → {w} → {back}");
        }
    }

    #[test]
    fn disk_round_trip() {
        for u in square_points() {
            let p = sample_uniform_disk_concentric(u);
            assert!(p.length() <= 1.0 + 1e-6);
            let back = invert_uniform_disk_concentric(p);
            assert!((back - u).abs().max_element() < 1e-4, "u = {u} → {p} → {back}");
        }
        // The centre and the wedge diagonals.
        for u in [Vec2::splat(0.5), Vec2::new(0.9, 0.9), Vec2::new(0.1, 0.9), Vec2::new(0.1, 0.1), Vec2::new(0.9, 0.1)] {
            let back = invert_uniform_disk_concentric(sample_uniform_disk_concentric(u));
            assert!((back - u).abs().max_element() < 1e-5, "u = {u} → {back}");
        }
    }

    #[test]
    fn cosine_hemisphere_round_trip() {
        for u in square_points() {
            let w = sample_cosine_hemisphere(u);
            assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
            let back = invert_cosine_hemisphere_sample(w);
            assert!((back - u).abs().max_element() < 1e-4, "u = {u} → {w} → {back}");
        }
    }

    #[test]
    fn uniform_hemisphere_and_sphere_round_trip() {
        round_trip_z_phi(sample_uniform_hemisphere, invert_uniform_hemisphere_sample, "hemisphere");
        round_trip_z_phi(sample_uniform_sphere, invert_uniform_sphere_sample, "sphere");
    }

    /// The lanes of [`uniform_sphere`] are [`sample_uniform_sphere`]'s directions bit for bit (the path
    /// tracer samples a constant environment in lanes, a single path with the scalar form).
    #[test]
    fn uniform_sphere_lanes_match() {
        for chunk in square_points().chunks(8) {
            let u = |i: usize| chunk.get(i).copied().unwrap_or(Vec2::ZERO);
            let w = uniform_sphere(crate::math::simd::Float8::from_fn(|i| u(i).x), crate::math::simd::Float8::from_fn(|i| u(i).y));
            for i in 0..chunk.len() {
                let want = sample_uniform_sphere(u(i)).to_array().map(f32::to_bits);
                assert_eq!([w.x.lane(i), w.y.lane(i), w.z.lane(i)].map(f32::to_bits), want, "u = {}", u(i));
            }
        }
    }

    #[test]
    fn cone_round_trip() {
        for cos_theta_max in CONES {
            round_trip_z_phi(|u| sample_uniform_cone(u, cos_theta_max), |w| invert_uniform_cone_sample(w, cos_theta_max), "cone");
            for u in square_points() {
                assert!(sample_uniform_cone(u, cos_theta_max).z >= cos_theta_max);
            }
        }
    }

    /// ∫ pdf dω by the midpoint rule on a fine (cos θ, φ) grid; dω = d(cos θ) dφ. The cos θ steps of
    /// 2·10⁻⁵ put every cone's rim used here on a step boundary.
    fn sphere_integral(pdf: impl Fn(Vec3) -> f32) -> f64 {
        let (nz, nphi) = (100_000, 16);
        let (dz, dphi) = (2.0 / nz as f64, std::f64::consts::TAU / nphi as f64);
        let mut sum = 0.0;
        for i in 0..nz {
            let z = -1.0 + (i as f64 + 0.5) * dz;
            let r = (1.0 - z * z).sqrt();
            for j in 0..nphi {
                let phi = (j as f64 + 0.5) * dphi;
                sum += f64::from(pdf(Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)));
            }
        }
        sum * dz * dphi
    }

    #[test]
    fn pdfs_integrate_to_one() {
        let n = 2000;
        let h = 2.0 / n as f64;
        let disk: f64 = (0..n * n)
            .map(|k| {
                let p = Vec2::new((-1.0 + ((k % n) as f64 + 0.5) * h) as f32, (-1.0 + ((k / n) as f64 + 0.5) * h) as f32);
                f64::from(uniform_disk_pdf(p))
            })
            .sum::<f64>()
            * h
            * h;
        assert!((disk - 1.0).abs() < 1e-3, "disk: {disk}");
        for (name, integral) in [
            ("cosine hemisphere", sphere_integral(cosine_hemisphere_pdf)),
            ("uniform hemisphere", sphere_integral(uniform_hemisphere_pdf)),
            ("uniform sphere", sphere_integral(uniform_sphere_pdf)),
        ] {
            assert!((integral - 1.0).abs() < 1e-4, "{name}: {integral}");
        }
        for c in CONES {
            let integral = sphere_integral(|w| uniform_cone_pdf(w, c));
            assert!((integral - 1.0).abs() < 1e-3, "cone {c}: {integral}");
        }
    }

    #[test]
    fn disk_chi2() {
        // The rim cuts grid cells, where the pdf jumps: many quadrature points per cell keep the
        // expected counts accurate there.
        let cfg = Chi2Config { integration_res: 24, ..Chi2Config::default() };
        let r = chi2_plane(sample_uniform_disk_concentric, |p| f64::from(uniform_disk_pdf(p)), Vec2::NEG_ONE, Vec2::ONE, (50, 50), &cfg);
        eprintln!("disk: {r}");
        assert!(r.passed, "{r}");
        // The naive polar map r = u₀ crowds the centre: the same test must catch it.
        let naive = |u: Vec2| u.x * Vec2::new((2.0 * PI * u.y).cos(), (2.0 * PI * u.y).sin());
        let r = chi2_plane(naive, |p| f64::from(uniform_disk_pdf(p)), Vec2::NEG_ONE, Vec2::ONE, (50, 50), &cfg);
        assert!(!r.passed, "{r}");
    }

    #[test]
    fn direction_warps_chi2() {
        let cfg = Chi2Config { tests: 3, ..Chi2Config::default() };
        for (name, r) in [
            ("cosine hemisphere", chi2_warp(sample_cosine_hemisphere, |w| f64::from(cosine_hemisphere_pdf(w)), &cfg)),
            ("uniform hemisphere", chi2_warp(sample_uniform_hemisphere, |w| f64::from(uniform_hemisphere_pdf(w)), &cfg)),
            ("uniform sphere", chi2_warp(sample_uniform_sphere, |w| f64::from(uniform_sphere_pdf(w)), &cfg)),
        ] {
            eprintln!("{name}: {r}");
            assert!(r.passed, "{name}: {r}");
        }
    }

    #[test]
    fn cone_chi2() {
        for (k, c) in CONES.into_iter().enumerate() {
            // The rim must be a cell edge: 40 rows of cos θ put 0.5, 0 and −0.5 on edges; the narrow cap
            // needs rows of 10⁻⁴ (ten rows inside it).
            let theta_res = if c == 0.999 { 20_000 } else { 40 };
            let cfg = Chi2Config { theta_res, phi_res: 40, tests: CONES.len(), seed: k as u64, ..Chi2Config::default() };
            let r = chi2_warp(|u| sample_uniform_cone(u, c), |w| f64::from(uniform_cone_pdf(w, c)), &cfg);
            eprintln!("cone {c}: {r}");
            assert!(r.passed, "cone {c}: {r}");
        }
    }
}
