//! Reflection, refraction (Snell's law in vector form) and the exact Fresnel equations for dielectric and
//! conducting interfaces.
//!
//! Convention: `eta` is the *relative* index η_inside / η_outside of the interface, the normal is +z
//! (outside is z > 0), and `cos_theta_i` is signed: negative means the direction lies inside. References:
//! Born & Wolf, *Principles of Optics*, §1.5.2 (eqs. 20–21: the amplitude coefficients rₛ, rₚ) and
//! pbrt-v4 §9.3 (the complex-index form for conductors).

use crate::math::lanes::{channels, Real, V3};
use crate::math::param::{Param, PerLane, PER_LANE};
use crate::math::Vec3;
use crate::spectrum::Rgb;

/// Mirror `w` about the normal `n`: 2 (w·n) n − w. Both point away from the surface.
#[inline(always)]
#[must_use]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

/// [`reflect`] in lanes ([`Real`]).
#[inline(always)]
#[must_use]
pub fn reflect_lanes<R: Real>(w: V3<R>, n: V3<R>) -> V3<R> {
    n.scale(w.dot(n) * 2.0).sub(w)
}

/// The outcome of refracting a direction through an interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refraction {
    /// The transmitted direction, pointing away from the surface on the other side.
    pub wt: Vec3,
    /// Relative index ηₜ/ηᵢ along this path (η when entering, 1/η when leaving).
    pub eta: f32,
}

/// Snell's law in vector form for the local frame (normal +z): the direction transmitted from `wi`
/// through an interface of relative index `eta` (η_inside/η_outside). `None` on total internal reflection.
///
/// With η' = ηₜ/ηᵢ and n on the side of `wi`: wₜ = −wᵢ/η' + (cos θᵢ/η' − cos θₜ) n, where
/// cos²θₜ = 1 − sin²θᵢ/η'² (pbrt-v4 eq. 9.4).
#[inline]
#[must_use]
pub fn refract(wi: Vec3, eta: f32) -> Option<Refraction> {
    refract_about(wi, Vec3::Z, eta)
}

/// [`refract`] through an interface with unit normal `n` (a microfacet normal ωm; "outside" is the side
/// `n` points to, `eta` = η_inside/η_outside as before). `refract(w, η) == refract_about(w, +z, η)`.
#[inline]
#[must_use]
pub fn refract_about(wi: Vec3, n: Vec3, eta: f32) -> Option<Refraction> {
    let cos = wi.dot(n);
    let (eta, n, cos_i) = if cos < 0.0 { (1.0 / eta, -n, -cos) } else { (eta, n, cos) };
    let cos2_t = cos2_transmitted(cos_i, eta);
    if cos2_t <= 0.0 {
        return None;
    }
    let cos_t = cos2_t.sqrt();
    let wt = -wi / eta + (cos_i / eta - cos_t) * n;
    Some(Refraction { wt, eta })
}

/// [`refract_about`] in lanes for a direction on the side `n` points to: `cos` = w·n > 0 and `eta` = ηₜ/ηᵢ,
/// the relative index along the path. Returns the transmitted direction (normalised; pbrt-v4 eq. 9.4 with
/// the normal `n`) and cos²θₜ ([`cos2_transmitted`]), which is ≤ 0 where there is total internal
/// reflection (the direction is then meaningless).
#[inline(always)]
#[must_use]
pub fn refract_lanes<R: Real>(w: V3<R>, n: V3<R>, cos: R, eta: R) -> (V3<R>, R) {
    let cos2_t = cos2_transmitted(cos, eta);
    let wt = w.div(eta).neg().add(n.scale(cos / eta - cos2_t.sqrt())).normalize();
    (wt, cos2_t)
}

/// cos²θₜ = 1 − (1 − cos²θᵢ)/η² written as (cos²θᵢ + η² − 1)/η², which keeps its precision when η ≈ 1
/// and θᵢ is grazing (2026-11: the first form rounded to total internal reflection at η = 1 for
/// |cos θᵢ| < 1.7e-4, found by the Mitsuba cross-check). ≤ 0 means total internal reflection.
#[inline(always)]
pub(crate) fn cos2_transmitted<R: Real>(cos_i: R, eta: R) -> R {
    cos_i.mul_add(cos_i, eta.mul_add(eta, R::splat(-1.0))) / (eta * eta)
}

/// Fresnel reflectances (Rₛ, Rₚ) of s- and p-polarised light at a dielectric interface.
/// `cos_theta_i` is signed (negative: arriving from inside). Both are 1 under total internal reflection.
#[inline(always)]
#[must_use]
pub fn fresnel_dielectric_sp(cos_theta_i: f32, eta: f32) -> (f32, f32) {
    fresnel_dielectric_sp_lanes(cos_theta_i, eta)
}

/// [`fresnel_dielectric_sp`] in lanes ([`Real`]).
#[inline(always)]
#[must_use]
pub fn fresnel_dielectric_sp_lanes<R: Real>(cos_theta_i: R, eta: f32) -> (R, R) {
    let inside = cos_theta_i.lt(R::splat(0.0));
    let (eta, cos_i) = (R::select(inside, R::splat(1.0 / eta), R::splat(eta)), R::select(inside, -cos_theta_i, cos_theta_i));
    let cos_i = cos_i.min(R::splat(1.0));
    let cos2_t = cos2_transmitted(cos_i, eta);
    let cos_t = cos2_t.sqrt();
    // Born & Wolf eq. 1.5.21 with n₁ = 1, n₂ = η.
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    // Total internal reflection reflects all; no interface at all (η = 1) nothing, even at grazing incidence.
    let total = cos2_t.le(R::splat(0.0));
    let none = eta.eq(R::splat(1.0));
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    (R::select(none, zero, R::select(total, one, rs * rs)), R::select(none, zero, R::select(total, one, rp * rp)))
}

/// Unpolarised Fresnel reflectance (Rₛ + Rₚ)/2 of a dielectric interface.
#[inline(always)]
#[must_use]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    fresnel_dielectric_lanes(cos_theta_i, eta)
}

/// [`fresnel_dielectric`] in lanes ([`Real`]).
#[inline(always)]
#[must_use]
pub fn fresnel_dielectric_lanes<R: Real>(cos_theta_i: R, eta: f32) -> R {
    let (rs, rp) = fresnel_dielectric_sp_lanes(cos_theta_i, eta);
    (rs + rp) * 0.5
}

/// The hemispherical average of the Fresnel reflectance, F̄ = 2 ∫₀¹ F(μ) μ dμ, for light arriving from the
/// outside of an interface of relative index `eta` (η_inside/η_outside; pass 1/η for light arriving from
/// inside, the internal reflectance of a coating). Computed by Gauss–Legendre quadrature in f64: beyond
/// the critical angle (η < 1) F = 1 and that part is integrated exactly (μc²), the smooth rest with 64
/// nodes. Mitsuba 3 uses polynomial fits instead (Egan & Hilgeman 1973 for η < 1, d'Eon & Irving 2011
/// for η ≥ 1; accurate to 0.1–0.6 %); the exact value keeps energy conservation exact for `plastic`
/// (1 − F̄(η) = η² (1 − F̄(1/η))).
#[must_use]
pub fn fresnel_diffuse_reflectance(eta: f32) -> f64 {
    // Below μc = √(1 − η²) light is totally reflected (only when η < 1).
    let mu_c = if eta < 1.0 { (1.0 - (eta as f64) * (eta as f64)).sqrt() } else { 0.0 };
    let (nodes, weights) = crate::verify::chi2::gauss_legendre(64);
    let half = 0.5 * (1.0 - mu_c);
    let smooth: f64 = nodes
        .iter()
        .zip(&weights)
        .map(|(x, w)| {
            let mu = mu_c + half * (x + 1.0);
            w * half * 2.0 * fresnel_dielectric(mu as f32, eta) as f64 * mu
        })
        .sum();
    mu_c * mu_c + smooth
}

/// The parts a = Re(η̃ cos θₜ), b = Im(η̃ cos θₜ) of η̃ cos θₜ = √(η̃² − sin²θᵢ) for a conductor of complex
/// relative index η̃ = η + i k, given `eta_k2` = η² − k², `eta_k` = ηk and s² = sin²θᵢ, as fractions
/// (a, b) = (x/ℓ, y/ℓ) over one positive denominator ℓ. From (a + ib)² = η² − k² − s² + 2iηk:
/// a² − b² = t and ab = ηk with t = η² − k² − s², so with m = a² + b² = √(t² + 4η²k²): a² = (m + t)/2 and
/// b² = (m − t)/2 (Born & Wolf, *Principles of Optics*, §14.2, eqs. 14.2(21)–(22), the u², v² of an
/// absorbing medium). Whichever of the two would cancel (m ≈ |t|) is taken from ab = ηk instead: with
/// ℓ² = (m + |t|)/2 the larger of a², b², the larger root is ℓ = ℓ²/ℓ and the smaller |ηk|/ℓ, so
/// (x, y) = (ℓ², |ηk|) for t ≥ 0 and (|ηk|, ℓ²) for t < 0 — both in full f32 precision (silver, t ≈ −23,
/// has a² ≈ 0.024: the direct form lost ~10 bits), with two square roots and no division (2026-12: the
/// conductor kernels are bound by divisions and square roots; the callers' ratios are homogeneous in a
/// and b, so ℓ cancels). a = b = 0 (η = sin θᵢ, k = 0) comes back as (0, 0, 1).
#[inline(always)]
fn conductor_cos_t<R: Real, P: Param>(index: &ConductorIndex<P>, sin2_i: R) -> (R, R, R) {
    let t = index.e.lanes::<R>() - sin2_i;
    let m = (t * t + index.four_eta_k2.lanes::<R>()).sqrt();
    let larger2 = (m + t.abs()) * 0.5;
    let zero = R::splat(0.0);
    let ell = R::select(larger2.gt(zero), larger2.sqrt(), R::splat(1.0));
    let smaller = index.abs_eta_k.lanes::<R>();
    let positive = t.ge(zero);
    (R::select(positive, larger2, smaller), R::select(positive, smaller, larger2), ell)
}

/// What the conductor Fresnel term reads of a complex index η + i k, computed once per index (one value,
/// or one per lane: [`Param`]): η̃² = e + i f (e = η² − k², f = 2ηk), 4η²k² and |ηk| for
/// [`conductor_cos_t`], and the scales σₛ = 1/(1 + |η̃|²), σₚ = σₛ/(1 + e² + f²) that keep the Fresnel
/// term's products from overflow ([`fresnel_conductor`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConductorIndex<P> {
    pub e: P,
    pub f: P,
    pub four_eta_k2: P,
    pub abs_eta_k: P,
    pub sigma_s: P,
    pub sigma_p: P,
}

impl ConductorIndex<f32> {
    /// The index η + i k.
    #[inline(always)]
    #[must_use]
    pub fn new(eta: f32, k: f32) -> Self {
        // Products of sums rather than differences of squares: exact to a rounding or two near η = k.
        let (e, f) = ((eta - k) * (eta + k), 2.0 * eta * k);
        let eta_k = eta * k;
        let abs2 = (e * e + f * f).sqrt();
        let (sigma_s, sigma_p) = (1.0 / (1.0 + abs2), 1.0 / ((1.0 + abs2) * (1.0 + e * e + f * f)));
        ConductorIndex { e, f, four_eta_k2: 4.0 * eta_k * eta_k, abs_eta_k: eta_k.abs(), sigma_s, sigma_p }
    }
}

impl ConductorIndex<PerLane> {
    /// The indices of the lanes of a packet, one per lane ([`PerLane`]).
    #[must_use]
    pub fn per_lane(lanes: [ConductorIndex<f32>; PER_LANE]) -> Self {
        let field = |get: fn(&ConductorIndex<f32>) -> f32| PerLane(lanes.each_ref().map(get));
        ConductorIndex {
            e: field(|i| i.e),
            f: field(|i| i.f),
            four_eta_k2: field(|i| i.four_eta_k2),
            abs_eta_k: field(|i| i.abs_eta_k),
            sigma_s: field(|i| i.sigma_s),
            sigma_p: field(|i| i.sigma_p),
        }
    }
}

/// Unpolarised Fresnel reflectance of a conductor with complex relative index η + i k, for light arriving
/// at `cos_theta_i` ∈ [0, 1] from the outside (pbrt-v4 §9.3.6: Snell's law with a complex index, then the
/// dielectric amplitude coefficients). Evaluated in real arithmetic: with a + ib = η̃ cos θₜ = (x + iy)/ℓ
/// ([`conductor_cos_t`]), c = cos θᵢ and η̃² = e + i f (e = η² − k², f = 2ηk),
///
/// Rₛ = |c − (a + ib)|² / |c + (a + ib)|² = ((cℓ − x)² + y²) / ((cℓ + x)² + y²),
/// Rₚ = |η̃² c − (a + ib)|² / |η̃² c + (a + ib)|² = ((ecℓ − x)² + (fcℓ − y)²) / ((ecℓ + x)² + (fcℓ + y)²)
///
/// (each ratio multiplied through by ℓ²; Born & Wolf §14.2 eq. 14.2(24) write the same ratios through a²,
/// b²; rₚ here is multiplied through by η̃, which leaves |rₚ| unchanged). Both quotients are of sums of
/// squares, and Rₛ + Rₚ is taken over one denominator: one division per channel. Against an f64 complex
/// evaluation the f32 result is within 1.5e-6 relative over η ∈ [0.05, 50], k ∈ {0} ∪ [1e-3, 100],
/// cos θ ∈ [0, 1] (25 × 26 × 65 grid; worst near η ≈ 1, k ≈ 0 at Brewster's angle, where Rₚ ≈ 0). Test:
/// `conductor_sweep_matches_f64`.
#[inline(always)]
#[must_use]
pub fn fresnel_conductor(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    fresnel_conductor_lanes(cos_theta_i, eta, k)
}

/// [`fresnel_conductor`] in lanes ([`Real`]).
#[inline(always)]
#[must_use]
pub fn fresnel_conductor_lanes<R: Real>(cos_theta_i: R, eta: f32, k: f32) -> R {
    fresnel_conductor_at(cos_theta_i, &ConductorIndex::new(eta, k))
}

/// [`fresnel_conductor_lanes`] of an index computed once ([`ConductorIndex`]: one value, or one per lane).
#[inline(always)]
#[must_use]
pub fn fresnel_conductor_at<R: Real, P: Param>(cos_theta_i: R, index: &ConductorIndex<P>) -> R {
    let c = cos_theta_i.clamp(0.0, 1.0);
    // Products of sums rather than differences of squares: exact to a rounding or two near c = 1.
    // (No `mul_add`: without a target FMA it is a library call per use, which would dominate.)
    let sin2_i = (R::splat(1.0) - c) * (c + 1.0);
    let (x, y, ell) = conductor_cos_t(index, sin2_i);
    let cl = c * ell;
    // Rₛ's terms grow as |η̃|⁴ (ℓ² ~ |η̃|²) and Rₚ's as |η̃|⁶: scaled by σₛ ≈ 1/|η̃|² and σₚ ≈ 1/|η̃|⁶ (each
    // ratio is unchanged) so that the product of the denominators stays far from overflow.
    let (sigma_s, sigma_p) = (index.sigma_s.lanes::<R>(), index.sigma_p.lanes::<R>());
    let (ns, ds) = (sum_of_squares(cl - x, y) * sigma_s, sum_of_squares(cl + x, y) * sigma_s);
    let (ecl, fcl) = (cl * index.e.lanes::<R>(), cl * index.f.lanes::<R>());
    let (np, dp) = (sum_of_squares(ecl - x, fcl - y) * sigma_p, sum_of_squares(ecl + x, fcl + y) * sigma_p);
    // Rₛ + Rₚ over one denominator; the numerator is a sum of non-negative terms.
    (ns * dp + np * ds) / (ds * dp) * 0.5
}

/// x² + y².
#[inline(always)]
fn sum_of_squares<R: Real>(x: R, y: R) -> R {
    x * x + y * y
}

/// [`fresnel_conductor`] per RGB channel: the three channels are independent lanes of the same
/// straight-line arithmetic (no branches besides selects), which the compiler keeps in SIMD registers.
#[inline(always)]
#[must_use]
pub fn fresnel_conductor_rgb(cos_theta_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    Rgb(fresnel_conductor_rgb_lanes(cos_theta_i, eta, k))
}

/// [`fresnel_conductor_rgb`] in lanes ([`Real`]): one lane value per channel.
#[inline(always)]
#[must_use]
pub fn fresnel_conductor_rgb_lanes<R: Real>(cos_theta_i: R, eta: Rgb, k: Rgb) -> [R; 3] {
    channels!(|i| fresnel_conductor_lanes(cos_theta_i, eta.0[i], k.0[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_is_squared_ratio() {
        for eta in [1.33f32, 1.5, 2.4, 0.7] {
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - r0).abs() < 1e-6, "eta {eta}");
            // Same from the other side (1/η gives the same R₀).
            assert!((fresnel_dielectric(-1.0, 1.0 / eta) - r0).abs() < 1e-6);
        }
        // Glass, η = 1.5: R₀ = 0.04 exactly.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-7);
    }

    #[test]
    fn brewster_angle_has_no_p_reflection() {
        let eta = 1.5f32;
        let theta_b = eta.atan();
        let (rs, rp) = fresnel_dielectric_sp(theta_b.cos(), eta);
        assert!(rp < 1e-10, "Rp at Brewster = {rp}");
        // The averaged value is then Rs/2 exactly; Rs at Brewster for η = 1.5 is
        // ((cos θB − η cos θt)/(cos θB + η cos θt))² with θt = π/2 − θB: 0.1479.
        assert!((fresnel_dielectric(theta_b.cos(), eta) - 0.5 * rs).abs() < 1e-7);
        assert!((rs - 0.147_928).abs() < 1e-5, "Rs = {rs}");
    }

    #[test]
    fn critical_angle_starts_total_internal_reflection() {
        let (n1, n2) = (1.5f32, 1.0f32);
        let eta = n1 / n2; // inside is the glass, light arrives from inside
        let theta_c = (n2 / n1).asin();
        let just_below = -(theta_c - 1e-3).cos();
        let just_above = -(theta_c + 1e-3).cos();
        assert!(fresnel_dielectric(just_below, eta) < 1.0);
        assert_eq!(fresnel_dielectric(just_above, eta), 1.0);
        let w_below = Vec3::new((theta_c - 1e-3).sin(), 0.0, -(theta_c - 1e-3).cos());
        let w_above = Vec3::new((theta_c + 1e-3).sin(), 0.0, -(theta_c + 1e-3).cos());
        assert!(refract(w_below, eta).is_some());
        assert!(refract(w_above, eta).is_none());
    }

    #[test]
    fn refraction_obeys_snell() {
        let eta = 1.5f32;
        for theta in [0.0f32, 0.3, 0.9, 1.4] {
            let wi = Vec3::new(theta.sin(), 0.0, theta.cos());
            let r = refract(wi, eta).unwrap();
            assert!((r.wt.length() - 1.0).abs() < 1e-6);
            assert!(r.wt.z < 0.0);
            let sin_t = (r.wt.x * r.wt.x + r.wt.y * r.wt.y).sqrt();
            assert!((theta.sin() - eta * sin_t).abs() < 1e-6, "n1 sinθ1 = n2 sinθ2");
            assert!(r.wt.x <= 0.0, "the transmitted ray continues across the normal");
            // Refracting back out retraces the path.
            let back = refract(r.wt, eta).unwrap();
            assert!((back.wt - wi).length() < 1e-5);
            assert!((back.eta - 1.0 / eta).abs() < 1e-7);
        }
    }

    #[test]
    fn conductor_matches_hand_computed_values() {
        // 1. Normal incidence: R = ((η−1)² + k²)/((η+1)² + k²).
        //    η = 0.2, k = 3.0: (0.64 + 9)/(1.44 + 9) = 9.64/10.44 = 0.923372.
        assert!((fresnel_conductor(1.0, 0.2, 3.0) - 0.923_372).abs() < 1e-5);
        // 2. k = 0 reduces to the dielectric: η = 1.5 at 60°: cos θt = sqrt(1 − 0.75/2.25) = 0.816497;
        //    rs = (0.5 − 1.224745)/(0.5 + 1.224745) = −0.420204, rp = (0.75 − 0.816497)/(0.75 + 0.816497)
        //    = −0.042449; F = (0.176571 + 0.001802)/2 = 0.089187.
        let c60 = 0.5f32;
        assert!((fresnel_conductor(c60, 1.5, 0.0) - 0.089_187).abs() < 1e-5);
        assert!((fresnel_conductor(c60, 1.5, 0.0) - fresnel_dielectric(c60, 1.5)).abs() < 1e-6);
        // 3. Gold-like η = 0.2, k = 3.0 at 60°: η̃² = −8.96 + 1.2i, sin²θt = 0.75/η̃² = −0.082230 − 0.011013i,
        //    cos θt = sqrt(1 − sin²θt) = 1.040316 + 0.005293i, η̃ cos θt = 0.192184 + 3.122008i;
        //    |rs|² = |0.5 − η̃ cos θt|²/|0.5 + η̃ cos θt|² = 9.841685 / 10.226053 = 0.962413;
        //    |rp|² = |η̃/2 − cos θt|²/|η̃/2 + cos θt|² with η̃/2 = 0.1 + 1.5i: 0.874409; F = 0.918411.
        let f = fresnel_conductor(c60, 0.2, 3.0);
        assert!((f - 0.918_411).abs() < 1e-5, "F = {f}");
        // Grazing incidence reflects everything.
        assert!((fresnel_conductor(0.0, 0.2, 3.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn conductor_is_accurate_when_k_is_small_against_eta() {
        // η = 40, k = 100 and silver-like η = 0.155, k = 4.83 at 70°: compare with an f64 evaluation.
        fn exact(c: f64, eta: f64, k: f64) -> f64 {
            // |rs|², |rp|² via the closed form of Born & Wolf for an absorbing medium (a², b² terms).
            let s2 = 1.0 - c * c;
            let t = eta * eta - k * k - s2;
            let a2b2 = (t * t + 4.0 * eta * eta * k * k).sqrt();
            let a = (0.5 * (a2b2 + t)).max(0.0).sqrt();
            let rs = (a2b2 + c * c - 2.0 * a * c) / (a2b2 + c * c + 2.0 * a * c);
            let rp = rs * (a2b2 * c * c + s2 * s2 - 2.0 * a * c * s2) / (a2b2 * c * c + s2 * s2 + 2.0 * a * c * s2);
            0.5 * (rs + rp)
        }
        for (eta, k) in [(40.0f32, 100.0f32), (0.155, 4.83), (1.5, 1e-3), (0.2, 3.0)] {
            for c in [1.0f32, 0.7, 0.34, 0.05] {
                let got = fresnel_conductor(c, eta, k) as f64;
                let want = exact(c as f64, eta as f64, k as f64);
                assert!(((got - want) / want).abs() < 2e-6, "η={eta} k={k} cos={c}: {got} vs {want}");
            }
        }
    }

    /// The conductor Fresnel equations in f64 complex arithmetic, straight from the definitions
    /// (cos θₜ = √(1 − sin²θᵢ/η̃²), rₛ = (c − η̃ cos θₜ)/(c + η̃ cos θₜ), rₚ = (η̃ c − cos θₜ)/(η̃ c + cos θₜ)).
    fn conductor_f64_complex(c: f64, eta: f64, k: f64) -> f64 {
        type C = (f64, f64);
        let mul = |x: C, y: C| (x.0 * y.0 - x.1 * y.1, x.0 * y.1 + x.1 * y.0);
        let div = |x: C, y: C| {
            let d = y.0 * y.0 + y.1 * y.1;
            ((x.0 * y.0 + x.1 * y.1) / d, (x.1 * y.0 - x.0 * y.1) / d)
        };
        let sqrt = |z: C| {
            let r = z.0.hypot(z.1);
            let re = (0.5 * (r + z.0)).max(0.0).sqrt();
            let im = (0.5 * (r - z.0)).max(0.0).sqrt().copysign(z.1);
            (re, im)
        };
        let norm = |z: C| z.0 * z.0 + z.1 * z.1;
        let n = (eta, k);
        let sin2_t = div((1.0 - c * c, 0.0), mul(n, n));
        let cos_t = sqrt((1.0 - sin2_t.0, -sin2_t.1));
        let nct = mul(n, cos_t);
        let rs = div((c - nct.0, -nct.1), (c + nct.0, nct.1));
        let nc = (eta * c, k * c);
        let rp = div((nc.0 - cos_t.0, nc.1 - cos_t.1), (nc.0 + cos_t.0, nc.1 + cos_t.1));
        0.5 * (norm(rs) + norm(rp))
    }

    #[test]
    fn conductor_sweep_matches_f64() {
        // η and k log-spaced over the metals (and beyond), k = 0 included, cos θ over [0, 1].
        let etas: Vec<f32> = (0..=24).map(|i| 0.05 * 1000f32.powf(i as f32 / 24.0)).collect();
        let ks: Vec<f32> = std::iter::once(0.0).chain((0..=24).map(|i| 1e-3 * 1e5f32.powf(i as f32 / 24.0))).collect();
        let mut worst = (0.0f64, 0.0, 0.0, 0.0);
        for &eta in &etas {
            for &k in &ks {
                for j in 0..=64 {
                    let c = j as f32 / 64.0;
                    if (eta - 1.0).abs() < 1e-3 && k == 0.0 {
                        continue; // no interface
                    }
                    let want = conductor_f64_complex(c as f64, eta as f64, k as f64);
                    let got = fresnel_conductor(c, eta, k) as f64;
                    let rel = ((got - want) / want).abs();
                    if !(rel <= worst.0) {
                        worst = (rel, eta, k, c);
                    }
                }
            }
        }
        assert!(worst.0 < 1.5e-6, "max relative error {:e} at η={} k={} cos={}", worst.0, worst.1, worst.2, worst.3);
    }

    #[test]
    fn equal_indices_transmit_everything_even_at_grazing() {
        for c in [1.0f32, 1e-3, 1.7e-4, 6.79e-5, -6.79e-5, -1e-6] {
            assert_eq!(fresnel_dielectric(c, 1.0), 0.0);
            let w = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
            let r = refract(w, 1.0).expect("no total internal reflection at η = 1");
            assert!((r.wt + w).length() < 1e-6);
        }
    }

    #[test]
    fn reflect_is_an_involution() {
        let w = Vec3::new(0.3, -0.4, 0.866).normalize();
        let r = reflect(w, Vec3::Z);
        assert!((r - Vec3::new(-w.x, -w.y, w.z)).length() < 1e-6);
        assert!((reflect(r, Vec3::Z) - w).length() < 1e-6);
    }
}
