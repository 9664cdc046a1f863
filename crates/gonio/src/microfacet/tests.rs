//! The identities of microfacet theory checked on every distribution: normalisation, the projected-area
//! identity, the visible-normal densities, and the samplers against their densities (chi-square).
use super::*;
use crate::sampling::Pcg32;
use std::f64::consts::PI as PI64;

/// The distributions the identities are checked on: several α incl. 0.05, and 20:1 anisotropy.
fn distributions() -> Vec<MicrofacetDistribution> {
    let mut all = Vec::new();
    for kind in MicrofacetKind::ALL {
        for (ax, ay) in [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.02, 0.4)] {
            if kind == MicrofacetKind::Blinn && ax != ay {
                continue;
            }
            all.push(MicrofacetDistribution::new(kind, ax, ay));
        }
    }
    all
}

fn dir(theta_deg: f64, phi: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new((t.sin() * phi.cos()) as f32, (t.sin() * phi.sin()) as f32, t.cos() as f32)
}

/// Midpoints and widths of `n` cells over (−π/2, π/2), with a cell boundary at `split` if given
/// (the kink of max(0, ωo·ωm) lies on a grid line, which keeps the midpoint rule second order).
fn cells(n: usize, split: Option<f64>) -> Vec<(f64, f64)> {
    let half = std::f64::consts::FRAC_PI_2;
    let bounds = match split {
        Some(s) => vec![-half, s, half],
        None => vec![-half, half],
    };
    let mut out = Vec::new();
    for w in bounds.windows(2) {
        let m = ((n as f64 * (w[1] - w[0]) / (2.0 * half)).round() as usize).max(1);
        let h = (w[1] - w[0]) / m as f64;
        out.extend((0..m).map(|i| (w[0] + (i as f64 + 0.5) * h, h)));
    }
    out
}

/// The slope p = α tan³a and dp/da.
fn slope(a: f64, alpha: f64) -> (f64, f64) {
    let t = a.tan();
    (alpha * t * t * t, 3.0 * alpha * t * t / (a.cos() * a.cos()))
}

/// ∫ over the upper hemisphere of g(ωm) dωm in f64, through the slope plane: ωm = (−p, −q, 1)/√(1+p²+q²),
/// dωm = dp dq / (1+p²+q²)^{3/2}, with p = αx tan³a, q = αy tan³b and the midpoint rule in (a, b).
/// `kink`: a direction ωo in the xz or yz plane whose max(0, ωo·ωm) the integrand contains.
///
/// The map p = α tan³a (not α tan a) makes the slope-space corners (p, q → ∞ together) carry a bounded
/// integrand even for GGX's r⁻³ tail times the linear factor ωo·ωm, so the rule stays second order.
fn integrate_hemisphere(d: &MicrofacetDistribution, n: usize, kink: Option<Vec3>, g: impl Fn(Vec3) -> f64) -> f64 {
    let (ax, ay) = (d.alpha_x as f64, d.alpha_y as f64);
    // ωm = (−p, −q, 1)/r: ωo·ωm = 0 at p = z/x (ωo in the xz plane) or q = z/y (yz plane).
    let split = |along: f32, other: f32, alpha: f64| {
        kink.filter(|w| w.z.abs() > 0.0 && other.abs() < 1e-7 && along != 0.0).map(|w| (w.z as f64 / along as f64 / alpha).cbrt().atan())
    };
    let (sa, sb) = match kink {
        Some(w) => (split(w.x, w.y, ax), split(w.y, w.x, ay)),
        None => (None, None),
    };
    let (ca, cb) = (cells(n, sa), cells(n, sb));
    let mut sum = 0.0;
    for &(a, ha) in &ca {
        let (p, dp) = slope(a, ax);
        for &(b, hb) in &cb {
            let (q, dq) = slope(b, ay);
            let r2 = 1.0 + p * p + q * q;
            let r = r2.sqrt();
            let wm = Vec3::new((-p / r) as f32, (-q / r) as f32, (1.0 / r) as f32);
            sum += g(wm) * dp * dq / (r2 * r) * ha * hb;
        }
    }
    sum
}

#[test]
fn projected_area_of_microfacets_is_one() {
    // ∫ D(ωm) cos θm dωm = 1 (Heitz 2014's normalisation of D).
    for d in distributions() {
        let total = integrate_hemisphere(&d, 800, None, |wm| d.d(wm) as f64 * wm.z as f64);
        assert!((total - 1.0).abs() < 1e-5, "{d:?}: {total}");
    }
}

#[test]
fn smith_masking_conserves_projected_area() {
    // ∫ G1(ωo, ωm) max(0, ωo·ωm) D(ωm) dωm = cos θo (Heitz 2014's projected-area identity) — exact for Beckmann and GGX.
    for d in distributions() {
        let mut worst = 0.0f64;
        for theta in [0.0, 30.0, 60.0, 80.0, 85.0] {
            for phi in [0.0, std::f64::consts::FRAC_PI_2] {
                let wo = dir(theta, phi);
                let lhs = integrate_hemisphere(&d, 800, Some(wo), |wm| d.g1(wo, wm) as f64 * (wo.dot(wm).max(0.0) as f64) * d.d(wm) as f64);
                let rel = (lhs / wo.z as f64 - 1.0).abs();
                worst = worst.max(rel);
                if d.kind != MicrofacetKind::Blinn {
                    assert!(rel < 1e-5, "{d:?} θo={theta} φ={phi}: {lhs} vs {}", wo.z);
                }
            }
        }
        // Blinn with the Beckmann Λ of the equivalent α is an approximation that improves as e grows.
        if d.kind == MicrofacetKind::Blinn {
            eprintln!("Blinn alpha={} worst relative violation {worst:.3e}", d.alpha_x);
            let bound = if d.alpha_x <= 0.05 {
                BLINN_005
            } else if d.alpha_x <= 0.3 {
                BLINN_03
            } else {
                BLINN_1
            };
            assert!(worst < bound, "Blinn α={}: {worst}", d.alpha_x);
        }
    }
}

#[test]
fn identities_hold_at_alpha_one_thousandth() {
    // The narrowest roughness the BSDFs accept in their examples: D's normalisation, the
    // projected-area identity and the visible-normal pdf, in f64 quadrature over D evaluated in f32
    // (2026-11: asked because roughdielectric Beckmann α = 10⁻³ failed the chi-square; these hold to
    // 10⁻⁶, the failure was the harness's quadrature).
    for kind in [MicrofacetKind::Beckmann, MicrofacetKind::Ggx] {
        let d = MicrofacetDistribution::new(kind, 1e-3, 1e-3);
        let total = integrate_hemisphere(&d, 800, None, |wm| d.d(wm) as f64 * wm.z as f64);
        assert!((total - 1.0).abs() < 1e-5, "{kind:?}: ∫D cos = {total}");
        for theta in [0.0, 11.48, 45.0, 85.0] {
            let wo = dir(theta, 0.0);
            let lhs = integrate_hemisphere(&d, 800, Some(wo), |wm| d.g1(wo, wm) as f64 * wo.dot(wm).max(0.0) as f64 * d.d(wm) as f64);
            assert!((lhs / wo.z as f64 - 1.0).abs() < 1e-5, "{kind:?} θo={theta}: {lhs} vs {}", wo.z);
            let visible = integrate_hemisphere(&d, 800, Some(wo), |wm| d.pdf_wm(wo, wm, true) as f64);
            assert!((visible - 1.0).abs() < 1e-5, "{kind:?} θo={theta}: ∫ D_ωo = {visible}");
        }
    }
}

#[test]
fn narrow_blinn_is_evaluated_without_rounding_noise() {
    // e = 2·10⁴: D at f32 half vectors against D at the same directions in f64. z^e amplified the
    // rounding of z to ~10⁻³ relative (2026-11); the sin² form keeps it near 10⁻⁶.
    let e = 2e4f32;
    let d = MicrofacetDistribution::blinn(e);
    let mut rng = Pcg32::new(17, 3);
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        let wo = crate::sampling::warp::sample_uniform_hemisphere(rng.next_vec2());
        let wm = d.sample_wm(wo, rng.next_vec2(), false);
        let wi = (2.0 * wo.dot(wm) * wm - wo).normalize();
        if wi.z <= 0.0 {
            continue;
        }
        let h = (wo + wi).normalize();
        let (x, y, z) = (h.x as f64, h.y as f64, h.z as f64);
        let cos = z / (x * x + y * y + z * z).sqrt();
        let exact = (e as f64 + 2.0) / (2.0 * PI64) * cos.powf(e as f64);
        if exact > 1e-3 * (e as f64 + 2.0) / (2.0 * PI64) {
            worst = worst.max((d.d(h) as f64 / exact - 1.0).abs());
        }
    }
    eprintln!("Blinn e = 2e4: worst relative error of D over 20 000 sampled half vectors {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
}

#[test]
fn lambda_of_the_reversed_direction() {
    // Λ(−ω) = −1 − Λ(ω) (Heitz 2014): |Λ(−ω)| = 1 + Λ(ω) for ω above the surface.
    for d in distributions() {
        for theta in [0.0, 20.0, 60.0, 85.0, 89.9] {
            let w = dir(theta, 0.4);
            let (up, down) = (d.lambda(w), d.lambda(-w));
            assert!(up >= 0.0);
            assert!((down + 1.0 + up).abs() <= 1e-6 * (1.0 + up), "{d:?} θ={theta}: {up} {down}");
        }
    }
    // Also the integral form below the surface: ∫ max(0, ω·ωm) D dωm = cos θ (1 + Λ(ω)) for cos θ < 0.
    for d in distributions().into_iter().filter(|d| d.kind != MicrofacetKind::Blinn) {
        let w = -dir(80.0, 0.0);
        let lhs = integrate_hemisphere(&d, 800, Some(w), |wm| w.dot(wm).max(0.0) as f64 * d.d(wm) as f64);
        // cos θ (1 + Λ(ω)) = |cos θ| Λ(−ω), by the identity asserted above (f32 1 + Λ(ω) cancels).
        let rhs = -w.z as f64 * d.lambda(-w) as f64;
        assert!((lhs - rhs).abs() < 1e-5 * -w.z as f64, "{d:?}: {lhs} vs {rhs}");
    }
}

#[test]
fn ggx_lambda_closed_form() {
    let d = MicrofacetDistribution::new(MicrofacetKind::Ggx, 0.5, 0.5);
    let w = dir(60.0, 0.0);
    let tan2 = 3.0f32;
    assert!((d.lambda(w) - (-1.0 + (1.0 + 0.25 * tan2).sqrt()) / 2.0).abs() < 1e-6);
}

#[test]
fn shadowing_forms_are_symmetric_and_bounded() {
    let mut rng = Pcg32::new(3, 4);
    for d in distributions() {
        for _ in 0..2000 {
            let wo = crate::sampling::warp::sample_uniform_hemisphere(rng.next_vec2());
            let wi = crate::sampling::warp::sample_uniform_hemisphere(rng.next_vec2());
            let wm = (wo + wi).normalize();
            for s in Shadowing::ALL {
                let (a, b) = (d.g(wo, wi, wm, s), d.g(wi, wo, wm, s));
                assert!((0.0..=1.0).contains(&a) && (a - b).abs() <= 1e-6, "{s:?} {a} {b}");
            }
            // Height correlation can only reduce shadowing relative to the separable form.
            assert!(d.g(wo, wi, wm, Shadowing::SmithCorrelated) >= d.g(wo, wi, wm, Shadowing::Smith) - 1e-6);
        }
    }
}

/// Measured worst relative violations of the Smith area identity for Blinn with the equivalent
/// Beckmann Λ over θo ≤ 85° (2026-11): 2.3e-5 at α = 0.05, 2.2e-2 at α = 0.3, 0.66 at α = 1 (e = 0,
/// a uniform D that Beckmann does not resemble). The bounds keep a margin over them.
const BLINN_005: f64 = 1e-4;
const BLINN_03: f64 = 3e-2;
const BLINN_1: f64 = 0.7;

/// Wilson–Hilferty approximation of the upper tail of a χ² distribution with `dof` degrees of freedom.
fn chi2_upper_tail(stat: f64, dof: f64) -> f64 {
    let k = 2.0 / (9.0 * dof);
    let z = ((stat / dof).powf(1.0 / 3.0) - (1.0 - k)) / k.sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// Pearson χ² of `n` samples of ωm against `pdf_wm`, on a grid in (t, φ) with tan θ = s t/(1 − t)
/// (s the geometric-mean roughness) so that the bins follow the lobe; expected counts by 6×6 midpoint
/// sub-quadrature per bin; bins expecting fewer than 5 pooled. Returns the p-value.
fn chi2_wm(d: &MicrofacetDistribution, wo: Vec3, visible: bool, n: usize, seed: u64) -> f64 {
    let (nt, np, sub) = (24usize, 36usize, 6usize);
    let scale = (d.alpha_x as f64 * d.alpha_y as f64).sqrt();
    let to_t = |wm: Vec3| {
        let tan = (wm.x as f64).hypot(wm.y as f64) / wm.z as f64;
        tan / (tan + scale)
    };
    let mut observed = vec![0f64; nt * np];
    let mut rng = Pcg32::new(seed, 99);
    for _ in 0..n {
        let wm = d.sample_wm(wo, rng.next_vec2(), visible);
        assert!(wm.is_finite() && (wm.length() - 1.0).abs() < 1e-4, "{wm}");
        if wm.z <= 0.0 {
            continue;
        }
        let t = to_t(wm);
        let phi = (wm.y as f64).atan2(wm.x as f64).rem_euclid(2.0 * PI64);
        let (i, j) = (((t * nt as f64) as usize).min(nt - 1), ((phi / (2.0 * PI64) * np as f64) as usize).min(np - 1));
        observed[i * np + j] += 1.0;
    }
    let mut expected = vec![0f64; nt * np];
    let (ht, hp) = (1.0 / (nt * sub) as f64, 2.0 * PI64 / (np * sub) as f64);
    for i in 0..nt * sub {
        let t = (i as f64 + 0.5) * ht;
        let tan = scale * t / (1.0 - t);
        let theta = tan.atan();
        let dtheta_dt = scale / ((1.0 - t) * (1.0 - t)) / (1.0 + tan * tan);
        for j in 0..np * sub {
            let phi = (j as f64 + 0.5) * hp;
            let wm = Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
            let p = d.pdf_wm(wo, wm, visible) as f64 * theta.sin() * dtheta_dt * ht * hp;
            expected[(i / sub) * np + j / sub] += p * n as f64;
        }
    }
    // Pool the small cells.
    let (mut stat, mut dof, mut pool_o, mut pool_e) = (0.0, 0.0, 0.0, 0.0);
    for (o, e) in observed.iter().zip(&expected) {
        if *e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            stat += (o - e) * (o - e) / e;
            dof += 1.0;
        }
    }
    if pool_e >= 5.0 {
        stat += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof += 1.0;
    } else {
        assert!(pool_o < 5.0 + 5.0 * pool_e.sqrt().max(1.0), "{pool_o} samples where {pool_e} expected");
    }
    chi2_upper_tail(stat, dof - 1.0)
}

#[test]
fn sampled_normals_follow_their_pdf_chi_square() {
    let mut cases = Vec::new();
    // The narrow lobes the BSDF harness's grid cannot resolve: this grid follows the lobe.
    let narrow = [MicrofacetKind::Beckmann, MicrofacetKind::Ggx]
        .into_iter()
        .flat_map(|k| [MicrofacetDistribution::new(k, 0.01, 0.01), MicrofacetDistribution::new(k, 0.001, 0.001)]);
    for d in distributions().into_iter().chain(narrow) {
        cases.push((d, Vec3::Z, false));
        for theta in [30.0, 85.0] {
            cases.push((d, dir(theta, 0.3), true));
        }
    }
    // Šidák correction of α = 0.01 over the family.
    let alpha = 1.0 - 0.99f64.powf(1.0 / cases.len() as f64);
    for (k, (d, wo, visible)) in cases.iter().enumerate() {
        let p = chi2_wm(d, *wo, *visible, 400_000, k as u64);
        assert!(p > alpha, "{d:?} wo={wo} visible={visible}: p = {p:.3e}");
    }
}

#[test]
fn visible_normals_face_the_viewer_and_pdf_integrates_to_one() {
    for d in distributions() {
        for theta in [0.0, 45.0, 85.0] {
            let wo = dir(theta, 0.0);
            let total = integrate_hemisphere(&d, 800, Some(wo), |wm| d.pdf_wm(wo, wm, true) as f64);
            assert!((total - 1.0).abs() < 1e-5, "{d:?} θo={theta}: {total}");
            if d.kind == MicrofacetKind::Blinn {
                continue; // D·cos: normals facing away from ωo are part of it.
            }
            let mut rng = Pcg32::new(7, 1);
            for _ in 0..1000 {
                let wm = d.sample_wm(wo, rng.next_vec2(), true);
                assert!(wm.dot(wo) >= -1e-6 && wm.z >= 0.0);
            }
        }
    }
}
