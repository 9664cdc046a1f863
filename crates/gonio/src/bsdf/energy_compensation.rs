//! Energy compensation for `roughconductor`, `roughdielectric` and `roughplastic`: the light a
//! single-scattering microfacet model loses between microfacets, added back as smooth lobes (Kulla & Conty
//! 2017, "Revisiting Physically Based Shading at Imageworks", SIGGRAPH course "Physically Based Shading in
//! Theory and Practice", §"Energy compensation" — conductors, and its dielectric part: tables for both
//! sides of the interface, the lost energy split between reflection and transmission by the average
//! Fresnel term, the split tied across the interface by reciprocity).
//!
//! | quantity   | meaning                                                                          |
//! |------------|----------------------------------------------------------------------------------|
//! | E(μ)       | directional albedo of the single-scattering lobe with F = 1 at cos θo = μ (dielectric: reflected + transmitted energy, F and 1 − F at each microfacet) |
//! | E_avg      | its cosine-weighted hemispherical average 2∫₀¹ E(μ) μ dμ                          |
//! | F_avg      | the same average of the Fresnel reflectance (times `specular_reflectance`)        |
//!
//! # Conductors
//! f_ms(ωo, ωi) = F_ms · (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg)), F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)).
//! For F = 1, ∫ f_ms cos θi dωi = 1 − E(μo) exactly, so single + multiple scattering reflect all the light
//! (the white furnace); F_ms sums the series of further bounces, each reflecting F_avg and escaping with
//! probability E_avg (the colour of rough gold deepens). f_ms is symmetric in ωo, ωi (reciprocal).
//!
//! # Dielectrics
//! Write Eₒ, Eᵢ for the energy tables seen from outside (relative index η = int_ior/ext_ior) and from
//! inside (1/η), Lₒ = π(1 − E_avg,o), Lᵢ = π(1 − E_avg,i), and τₒ, τᵢ for the shares of the lost energy
//! that cross the interface. The added lobes are, with ηₒ = 1 outside and μ = |cos θ|,
//! - reflection outside: (1 − τₒ) (1 − Eₒ(μo))(1 − Eₒ(μi)) / Lₒ; inside: (1 − τᵢ) (1 − Eᵢ(μo))(1 − Eᵢ(μi)) / Lᵢ;
//! - transmission: f_t(ω_out, ω_in) = k (1 − Eₒ(μ_out))(1 − Eᵢ(μ_in)) with ω_out = ωo outside, and
//!   f_t(ω_in, ω_out) = η² f_t(ω_out, ω_in): the reciprocity of [`crate::verify::reciprocity`]
//!   (f(ωo, ωi)/ηo² = f(ωi, ωo)/ηi²) holds by construction.
//!
//! Energy (transmitted radiance counted times (ηₜ/ηᵢ)², as in [`crate::verify::energy`]): from outside the
//! lobes carry (1 − Eₒ(μo)) [(1 − τₒ) + η² k Lᵢ], from inside (1 − Eᵢ(μo)) [(1 − τᵢ) + k Lₒ]; both are
//! 1 − E(μo), the white furnace at every μo, if η² k Lᵢ = τₒ and k Lₒ = τᵢ, i.e.
//! τᵢ = τₒ Lₒ / (η² Lᵢ) (the same light crosses either way). One share is free: on the less dense side
//! (where light enters the denser medium, relative index η' > 1) τ = 1 − F_avg(η'), the smooth
//! interface's hemispherical transmittance, as Kulla & Conty choose; the other side's τ follows, and
//! where it would exceed 1 it is set to 1 and the first follows instead. `specular_reflectance` and
//! `specular_transmittance` scale the added reflection and transmission as they scale the single lobes.
//!
//! # Coated diffuse (`roughplastic`)
//! The coating is the compensated interface: its reflection gains the lobe above, the light it lets in
//! at μ becomes T'(μ) = T(μ) + τₒ (1 − Eₒ(μ)) and its underside reflects R̄ᵢ' = R̄ᵢ + (1 − τᵢ)(1 − E_avg,i).
//! Since the single-scattering transmission is reciprocal, 2∫T μ dμ = η² T̄ᵢ, and with the τ above the
//! same holds for the added parts, so 2∫T' μ dμ = η² (1 − R̄ᵢ'): a white base (ρ = 1) returns everything
//! that enters, and the albedo is E(μo) + (1 − E(μo)) = 1 at every μo.
//!
//! **Exact**: the energy balance for F = 1 (conductors) and for white dielectrics, up to the tables'
//! accuracy (E by a 64 × 64 Gauss–Legendre rule over the model's own visible-normal sampler, i.e. the
//! model itself — any distribution and shadowing — on 64 nodes in √μ, interpolated linearly in √μ; E_avg
//! integrated from that same interpolant in closed form, so the balance holds for the table as used).
//! **Approximate**: the shape of the multiply scattered light (the product form spreads it like a diffuse
//! lobe, where real second bounces lean towards the backward and forward directions), F_ms for coloured
//! metals (the average-Fresnel series) and the dielectric's split τ; compare Heitz et al. 2016's random
//! walk, which `gonio` does not implement.
//!
//! Tables are computed at first use per (distribution, α, shadowing) for conductors and per
//! (distribution, α, η) for each side of a dielectric — tens to hundreds of milliseconds — and shared
//! through a process-wide cache. The tables are isotropic: an anisotropic roughness is refused.

use super::rough_conductor::MicrofacetConductor;
use super::{Conductor, RoughDielectric};
use crate::math::{Vec2, Vec3};
use crate::microfacet::{MicrofacetDistribution, MicrofacetKind, Shadowing};
use crate::sampling::distribution::PiecewiseLinear1D;
use crate::spectrum::Rgb;
use crate::verify::energy::direction;
use rayon::prelude::*;
use std::collections::HashMap;
use std::f32::consts::PI;
use std::hash::Hash;
use std::sync::{Arc, Mutex, OnceLock};

/// Table nodes, evenly spaced in t = √μ (dense near grazing, where E changes fastest).
const NODES: usize = 64;
/// Gauss–Legendre points per axis of the unit square of a visible-normal sampler, for conductors and
/// dielectrics alike (the dielectric's integrand has kinks where total internal reflection begins).
const QUADRATURE: usize = 64;

/// A directional albedo E(μ) tabulated on μ = t², t = k/(N−1), with its hemispherical average.
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoTable {
    /// E at the nodes, clamped to [0, 1].
    values: Vec<f32>,
    /// 2∫₀¹ E(μ) μ dμ of the interpolant.
    average: f64,
    /// A density in s = μ² proportional to 1 − E(√s) (plus 1 % of its mean, so that it is positive
    /// wherever the interpolant's loss may be): directions distributed like the loss (1 − E(μ)) cos θ.
    /// Piecewise linear, so continuous: the chi-square harness integrates this density adaptively, and
    /// each jump of a piecewise-constant one was refined to its depth limit (2026-12: 256 cells made a
    /// full `gonio check` of a compensated roughdielectric take 695 CPU seconds instead of 12).
    loss: PiecewiseLinear1D,
}

impl AlbedoTable {
    /// Tabulate `albedo(μ)` (μ > 0; the horizon node is evaluated at μ = 10⁻⁶). The nodes are independent
    /// integrals: they are evaluated on the thread pool, and the table is the same bit for bit as one
    /// built in order.
    #[must_use]
    pub fn from_fn(albedo: impl Fn(f32) -> f64 + Sync) -> Self {
        AlbedoTable::from_nodes(
            (0..NODES)
                .into_par_iter()
                .map(|k| {
                    let t = k as f64 / (NODES - 1) as f64;
                    albedo(((t * t) as f32).max(1e-6))
                })
                .collect(),
        )
    }

    /// The table of the values E at N ≥ 2 nodes μ = t², t = k/(N−1), k = 0..N.
    #[must_use]
    pub fn from_nodes(nodes: Vec<f64>) -> Self {
        debug_assert!(nodes.len() >= 2);
        let n = nodes.len();
        let values: Vec<f32> = nodes.iter().map(|e| e.clamp(0.0, 1.0) as f32).collect();
        // E is linear in t on each segment, E = a + b t, and μ dμ = 2t³ dt: 2∫ E μ dμ = Σ ∫ 4(a + b t) t³ dt.
        let mut average = 0.0;
        for k in 0..n - 1 {
            let (t0, t1) = (k as f64 / (n - 1) as f64, (k + 1) as f64 / (n - 1) as f64);
            let (e0, e1) = (values[k] as f64, values[k + 1] as f64);
            let b = (e1 - e0) / (t1 - t0);
            let a = e0 - b * t0;
            average += a * (t1.powi(4) - t0.powi(4)) + 0.8 * b * (t1.powi(5) - t0.powi(5));
        }
        let mut table = AlbedoTable { values, average, loss: PiecewiseLinear1D::new(&[1.0, 1.0]) };
        let segments = 256;
        let floor = 0.01 * (1.0 - average) as f32;
        let loss: Vec<f32> = (0..=segments).map(|i| 1.0 - table.albedo((i as f32 / segments as f32).sqrt()) + floor).collect();
        table.loss = PiecewiseLinear1D::new(&loss);
        table
    }

    /// A direction above the surface with density [`loss_pdf`](Self::loss_pdf) ∝ (1 − E(μ)) cos θ: s = μ²
    /// from the tabulated loss, φ uniform.
    #[must_use]
    pub fn sample_loss(&self, u: Vec2) -> Vec3 {
        let mu = self.loss.sample(u.x).clamp(0.0, 1.0).sqrt();
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        Vec3::new(sin * phi.cos(), sin * phi.sin(), mu)
    }

    /// The solid-angle density of [`sample_loss`](Self::sample_loss): p(s) |ds/dω| = p(s) cos θ / π.
    #[must_use]
    pub fn loss_pdf(&self, w: Vec3) -> f32 {
        if w.z <= 0.0 {
            return 0.0;
        }
        self.loss.pdf((w.z * w.z).min(1.0)) * w.z / PI
    }

    /// E(μ), interpolated linearly in √μ.
    #[must_use]
    pub fn albedo(&self, mu: f32) -> f32 {
        let n = self.values.len();
        let x = mu.clamp(0.0, 1.0).sqrt() * (n - 1) as f32;
        let k = (x as usize).min(n - 2);
        let t = x - k as f32;
        (1.0 - t) * self.values[k] + t * self.values[k + 1]
    }

    /// E_avg = 2∫₀¹ E(μ) μ dμ.
    #[must_use]
    pub fn average(&self) -> f64 {
        self.average
    }
}

/// The energy of the single-scattering lobe at cos θo = `mu`, F = 1: ∫ weight du over the unit square of
/// the visible-normal sampler, by Gauss–Legendre, in f64.
fn single_scattering_albedo(white: &MicrofacetConductor, mu: f32, nodes: &[f64], weights: &[f64]) -> f64 {
    let wo = direction(mu, 0.0);
    let mut sum = 0.0;
    for (x, wx) in nodes.iter().zip(weights) {
        for (y, wy) in nodes.iter().zip(weights) {
            let u = Vec2::new((0.5 * x + 0.5) as f32, (0.5 * y + 0.5) as f32);
            if let Some(s) = white.sample_lobe(wo, u) {
                sum += 0.25 * wx * wy * s.weight.r() as f64;
            }
        }
    }
    sum
}

/// A process-wide cache of energy tables.
type TableCache<K> = OnceLock<Mutex<HashMap<K, Arc<AlbedoTable>>>>;

/// The one builder of the conductor and dielectric tables: the table of `energy(μ, nodes, weights)` — a
/// single-scattering energy at cos θo = μ by the Gauss–Legendre rule of order [`QUADRATURE`] on [−1, 1]
/// given to it (computed once per table) — looked up in, or added to, `cache` under `key`.
fn cached_table<K: Eq + Hash>(cache: &TableCache<K>, key: K, energy: impl Fn(f32, &[f64], &[f64]) -> f64 + Sync) -> Arc<AlbedoTable> {
    let cache = cache.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(t) = cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return t;
    }
    let (nodes, weights) = crate::verify::chi2::gauss_legendre(QUADRATURE);
    let table = Arc::new(AlbedoTable::from_fn(|mu| energy(mu, &nodes, &weights)));
    if let Ok(mut c) = cache.lock() {
        c.insert(key, table.clone());
    }
    table
}

/// E(μ) of a white (F = 1) microfacet conductor with `core`'s distribution and shadowing, cached.
fn conductor_table(core: &MicrofacetConductor) -> Arc<AlbedoTable> {
    static CACHE: TableCache<(MicrofacetKind, u32, u32, Shadowing)> = OnceLock::new();
    let d = core.distribution;
    let white = MicrofacetConductor::new(d, core.shadowing, true, Conductor::mirror());
    cached_table(&CACHE, (d.kind, d.alpha_x.to_bits(), d.alpha_y.to_bits(), core.shadowing), |mu, nodes, weights| {
        single_scattering_albedo(&white, mu, nodes, weights)
    })
}

/// Kulla & Conty's multiple-scattering lobe of a rough conductor (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct ConductorCompensation {
    table: Arc<AlbedoTable>,
    /// F_ms / (π (1 − E_avg)).
    scale: Rgb,
}

impl ConductorCompensation {
    /// The lobe for `core` (isotropic; the caller checks).
    #[must_use]
    pub fn new(core: &MicrofacetConductor) -> Self {
        debug_assert!(!core.distribution.is_anisotropic(), "the tables are isotropic");
        let table = conductor_table(core);
        let e_avg = table.average();
        // A smooth surface loses nothing (1 − E_avg below f32 resolution): no lobe (2026-11: avoids 0/0).
        if 1.0 - e_avg < 1e-6 {
            return ConductorCompensation { table, scale: Rgb::ZERO };
        }
        // F_avg = 2∫ F(μ) μ dμ per channel (F is smooth in μ: 32 Gauss–Legendre points).
        let (nodes, weights) = crate::verify::chi2::gauss_legendre(32);
        let mut f_avg = [0.0f64; 3];
        for (x, w) in nodes.iter().zip(&weights) {
            let mu = 0.5 * x + 0.5;
            let f = core.fresnel.reflectance(mu as f32);
            for (acc, c) in f_avg.iter_mut().zip(f.0) {
                *acc += w * c as f64 * mu;
            }
        }
        let f_ms = |f: f64| f * f * e_avg / (1.0 - f * (1.0 - e_avg));
        let s = |c: usize| (f_ms(f_avg[c]) / (std::f64::consts::PI * (1.0 - e_avg))) as f32;
        ConductorCompensation { table, scale: Rgb::new(s(0), s(1), s(2)) }
    }

    /// f_ms(ωo, ωi) for cos θo = `mu_o`, cos θi = `mu_i` (both > 0).
    #[must_use]
    pub fn f(&self, mu_o: f32, mu_i: f32) -> Rgb {
        self.scale * ((1.0 - self.table.albedo(mu_o)) * (1.0 - self.table.albedo(mu_i)))
    }

    /// The probability with which the compensated model samples this lobe at cos θo = `mu_o`: the share of
    /// the (white) energy it carries, 1 − E(μo).
    #[must_use]
    pub fn probability(&self, mu_o: f32) -> f32 {
        if self.scale.is_black() {
            0.0
        } else {
            1.0 - self.table.albedo(mu_o)
        }
    }

    /// A direction for this lobe (see [`AlbedoTable::sample_loss`]).
    #[must_use]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        self.table.sample_loss(u)
    }

    /// The density of [`sample`](Self::sample).
    #[must_use]
    pub fn pdf(&self, wi: Vec3) -> f32 {
        self.table.loss_pdf(wi)
    }

    /// The tabulated single-scattering albedo.
    #[must_use]
    pub fn table(&self) -> &AlbedoTable {
        &self.table
    }
}

/// E(μ) = R(μ) + T(μ), the single-scattering energy (reflected plus transmitted, F and 1 − F at each
/// microfacet) of a white rough dielectric interface seen from the side where the relative index is
/// `eta_side` = ηᵢ/ηₒ, cached per (distribution, α, `eta_side`). The inside of an interface of index η is
/// the outside of one of index 1/η (see [`RoughDielectric`]'s module doc), so one cache serves both.
fn dielectric_table(distribution: MicrofacetDistribution, eta_side: f32) -> Arc<AlbedoTable> {
    static CACHE: TableCache<(MicrofacetKind, u32, u32)> = OnceLock::new();
    let interface = RoughDielectric::new(distribution, eta_side);
    cached_table(&CACHE, (distribution.kind, distribution.alpha_x.to_bits(), eta_side.to_bits()), |mu, nodes, weights| {
        let split = interface.energy_split_with(direction(mu, 0.0), nodes, weights);
        split.reflected + split.transmitted
    })
}

/// The multiple-scattering lobes of a rough dielectric interface (Kulla & Conty 2017, dielectrics): the
/// energy 1 − E(μo) lost on the side of ωo is partly reflected back to that side and partly transmitted
/// to the other, each spread like the loss of the side it leaves into (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct DielectricCompensation {
    /// E(μ) from outside (relative index η) and from inside (1/η).
    outside: Arc<AlbedoTable>,
    inside: Arc<AlbedoTable>,
    /// τ: the share of the lost energy that crosses the interface, from outside and from inside.
    transmitted_outside: f32,
    transmitted_inside: f32,
    /// (1 − τ)/(π (1 − E_avg)) of each side: the coefficient of the reflected lobe.
    reflection_outside: f32,
    reflection_inside: f32,
    /// τₒ/(η² π (1 − E_avg,i)) = τᵢ/(π (1 − E_avg,o)): the transmitted lobe's coefficient, divided by ηₒ².
    transmission_over_eta2: f32,
}

impl DielectricCompensation {
    /// The lobes for a rough interface of `distribution` (isotropic; the caller checks) and relative
    /// index `eta` = int_ior/ext_ior. `None` when neither side loses energy measurably.
    #[must_use]
    pub fn new(distribution: MicrofacetDistribution, eta: f32) -> Option<Self> {
        debug_assert!(!distribution.is_anisotropic(), "the tables are isotropic");
        let (outside, inside) = (dielectric_table(distribution, eta), dielectric_table(distribution, 1.0 / eta));
        let split = transmitted_shares(eta, outside.average(), inside.average())?;
        let pi = std::f64::consts::PI;
        let (lost_o, lost_i) = (pi * (1.0 - outside.average()), pi * (1.0 - inside.average()));
        // A side that loses (next to) nothing gets no reflected lobe (2026-11: avoids 0/0).
        let reflection = |tau: f64, lost: f64| if lost > 1e-6 { ((1.0 - tau) / lost) as f32 } else { 0.0 };
        Some(DielectricCompensation {
            reflection_outside: reflection(split.outside, lost_o),
            reflection_inside: reflection(split.inside, lost_i),
            transmitted_outside: split.outside as f32,
            transmitted_inside: split.inside as f32,
            transmission_over_eta2: split.transmission_over_eta2 as f32,
            outside,
            inside,
        })
    }

    /// The tables (E, E_avg) of the side of ωo (`inside`: below the surface) and of the other side.
    fn tables(&self, inside: bool) -> (&AlbedoTable, &AlbedoTable) {
        if inside {
            (&self.inside, &self.outside)
        } else {
            (&self.outside, &self.inside)
        }
    }

    /// The reflected lobe for cos θo = `mu_o`, cos θi = `mu_i` (absolute values) on one side.
    #[must_use]
    pub fn reflection(&self, mu_o: f32, mu_i: f32, inside: bool) -> f32 {
        let (table, scale) = if inside { (&self.inside, self.reflection_inside) } else { (&self.outside, self.reflection_outside) };
        scale * ((1.0 - table.albedo(mu_o)) * (1.0 - table.albedo(mu_i)))
    }

    /// The transmitted lobe divided by ηₒ², for `mu_out` = |cos θ| of the direction outside and `mu_in` of
    /// the one inside: symmetric in the two, like [`RoughDielectric`]'s single-scattering transmission.
    #[must_use]
    pub fn transmission_over_eta2(&self, mu_out: f32, mu_in: f32) -> f32 {
        self.transmission_over_eta2 * ((1.0 - self.outside.albedo(mu_out)) * (1.0 - self.inside.albedo(mu_in)))
    }

    /// The energy from outside at cos θ = `mu` that the lobes carry into the interface: τₒ (1 − Eₒ(μ)).
    #[must_use]
    pub fn entering(&self, mu: f32) -> f32 {
        self.transmitted_outside * (1.0 - self.outside.albedo(mu))
    }

    /// The hemispherical average of the reflected lobe from inside: (1 − τᵢ)(1 − E_avg,i).
    #[must_use]
    pub fn internal_reflectance(&self) -> f32 {
        ((1.0 - self.transmitted_inside as f64) * (1.0 - self.inside.average())) as f32
    }

    /// The probability with which the compensated model samples these lobes at ωo: the share of (white)
    /// energy they carry, 1 − E(|cos θo|) of the side of ωo.
    #[must_use]
    pub fn probability(&self, wo: Vec3) -> f32 {
        1.0 - self.tables(wo.z < 0.0).0.albedo(wo.z.abs())
    }

    /// The share τ of the lost energy that crosses the interface from the side of `wo`.
    fn transmitted_share(&self, wo: Vec3) -> f32 {
        if wo.z < 0.0 {
            self.transmitted_inside
        } else {
            self.transmitted_outside
        }
    }

    /// The energy of the reflected lobe at `wo`: (1 − τ)(1 − E(|cos θo|)) of the side of `wo`.
    #[must_use]
    pub fn reflected(&self, wo: Vec3) -> f32 {
        (1.0 - self.transmitted_share(wo)) * self.probability(wo)
    }

    /// A direction of the reflected lobe at `wo`, distributed like the loss (1 − E(μ)) cos θ of its side.
    #[must_use]
    pub fn sample_reflection(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let w = self.tables(wo.z < 0.0).0.sample_loss(u);
        if wo.z < 0.0 {
            -w
        } else {
            w
        }
    }

    /// The density of [`sample_reflection`](Self::sample_reflection) (0 on the other side).
    #[must_use]
    pub fn reflection_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let inside = wo.z < 0.0;
        self.tables(inside).0.loss_pdf(if inside { -wi } else { wi })
    }

    /// A direction of the lobes for `wo`: reflected when `uc` < 1 − τ, transmitted otherwise, each
    /// distributed like the loss (1 − E(μ)) cos θ of the side it goes to. The flag says whether it crossed
    /// the interface.
    #[must_use]
    pub fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> (Vec3, bool) {
        if uc < 1.0 - self.transmitted_share(wo) {
            return (self.sample_reflection(wo, u), false);
        }
        let w = self.tables(wo.z < 0.0).1.sample_loss(u);
        (if wo.z < 0.0 { w } else { -w }, true)
    }

    /// The density of [`sample`](Self::sample).
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let tau = self.transmitted_share(wo);
        if wo.z * wi.z > 0.0 {
            return (1.0 - tau) * self.reflection_pdf(wo, wi);
        }
        let other = self.tables(wo.z < 0.0).1;
        tau * other.loss_pdf(if wo.z < 0.0 { wi } else { -wi })
    }
}

/// The shares τ of the lost energy that cross the interface, from outside and from inside, and the
/// transmitted lobe's coefficient (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
struct TransmittedShares {
    outside: f64,
    inside: f64,
    transmission_over_eta2: f64,
}

/// τ from the less dense side is 1 − F_avg of the smooth interface (Kulla & Conty 2017); reciprocity then
/// fixes the other: τ_dense = τ_less (1 − E_avg,less) / (η² (1 − E_avg,dense)) with η > 1 the relative
/// index of the dense side to the less dense one. If that exceeds 1 (the dense side loses much less than
/// the other), τ_dense = 1 and τ_less follows from the same equation. `None` if neither side loses energy.
fn transmitted_shares(eta: f32, e_avg_outside: f64, e_avg_inside: f64) -> Option<TransmittedShares> {
    let pi = std::f64::consts::PI;
    let (lost_o, lost_i) = (pi * (1.0 - e_avg_outside), pi * (1.0 - e_avg_inside));
    // Below f32 resolution of the energy there is nothing to add (2026-11: avoids 0/0).
    if lost_o.max(lost_i) < 1e-6 {
        return None;
    }
    // Orient so that `less` is the side light enters the denser medium from (relative index η_rel > 1).
    let outside_is_less_dense = eta > 1.0;
    let eta_rel = if outside_is_less_dense { eta as f64 } else { 1.0 / eta as f64 };
    let (lost_less, lost_dense) = if outside_is_less_dense { (lost_o, lost_i) } else { (lost_i, lost_o) };
    let mut tau_less = 1.0 - crate::fresnel::fresnel_diffuse_reflectance(eta_rel as f32);
    // τ_less · lost_less = η_rel² τ_dense · lost_dense: equal transmitted energy both ways (reciprocity).
    let mut tau_dense = if lost_dense > 0.0 { tau_less * lost_less / (eta_rel * eta_rel * lost_dense) } else { f64::INFINITY };
    if tau_dense > 1.0 {
        tau_dense = 1.0;
        tau_less = eta_rel * eta_rel * lost_dense / lost_less;
    }
    let (outside, inside) = if outside_is_less_dense { (tau_less, tau_dense) } else { (tau_dense, tau_less) };
    // The coefficient k of f_t(out, in)/ηₒ² = k (1 − Eₒ(μ_out))(1 − Eᵢ(μ_in)) (ηₒ = 1 outside): energy
    // from outside η² k π(1 − E_avg,i) = τₒ (1 − Eₒ), from inside k π(1 − E_avg,o) = τᵢ (1 − Eᵢ); the two
    // forms agree, take the one whose denominator is larger.
    let eta2 = eta as f64 * eta as f64;
    let k = if eta2 * lost_i >= lost_o { outside / (eta2 * lost_i) } else { inside / lost_o };
    Some(TransmittedShares { outside, inside, transmission_over_eta2: k })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bsdf, BsdfModel};
    use crate::verify::energy;

    fn white(kind: &str, alpha: f32, on: bool) -> Bsdf {
        Bsdf::from_json(&format!(
            r#"{{"type": "roughconductor", "distribution": "{kind}", "alpha": {alpha}, "energy_compensation": {on}}}"#
        ))
        .unwrap()
    }

    #[test]
    fn white_rough_conductor_passes_the_furnace_with_compensation() {
        // The issue's requirement: a white rough conductor at any α ≤ 1 within 1 % of the white furnace
        // with compensation; without it the loss is reported.
        let mut failed = Vec::new();
        for kind in ["ggx", "beckmann"] {
            for alpha in [0.05f32, 0.1, 0.25, 0.5, 0.75, 1.0] {
                let (on, off) = (white(kind, alpha, true), white(kind, alpha, false));
                let curve_on = energy::albedo_curve(&on, 12, 1.0, 8192, 11);
                let furnace_on = energy::white_furnace(&curve_on).r();
                let furnace_off = energy::white_furnace(&energy::albedo_curve(&off, 12, 1.0, 8192, 11)).r();
                let worst = curve_on.iter().map(|(_, a)| (a.r() - 1.0).abs()).fold(0.0f32, f32::max);
                eprintln!("{kind} α={alpha}: furnace {furnace_off:.4} → {furnace_on:.4} with compensation; worst |albedo − 1| {worst:.4}");
                if (furnace_on - 1.0).abs() > 0.01 || worst > 0.01 {
                    failed.push(format!("{kind} α={alpha}: furnace {furnace_on}, worst albedo error {worst}"));
                }
                if alpha >= 0.25 {
                    assert!(furnace_off < 0.98, "{kind} α={alpha}: the uncompensated model loses energy, got {furnace_off}");
                }
            }
        }
        assert!(failed.is_empty(), "{}", failed.join("\n"));
    }

    #[test]
    fn compensation_is_reciprocal_and_colours_gold() {
        let plain = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.8, "material": "Au"}"#).unwrap();
        let gold = Bsdf::from_json(
            r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.8, "material": "Au", "energy_compensation": true}"#,
        )
        .unwrap();
        let (wo, wi) = (energy::direction(0.3, 0.2), energy::direction(0.8, 2.0));
        let (a, b) = (gold.f(wo, wi), gold.f(wi, wo));
        assert!((a.r() - b.r()).abs() <= 1e-6 * a.r(), "{a} vs {b}");
        // Multiple bounces add energy, more in red (F_avg ≈ 0.9) than in blue (≈ 0.4): the added share of
        // energy grows with F_avg (F_ms ∝ F_avg²).
        let (p, g) = (energy::albedo_at(&plain, 0.5, 1 << 16, 3), energy::albedo_at(&gold, 0.5, 1 << 16, 3));
        eprintln!("gold α=0.8 μ=0.5: {p} → {g}");
        assert!(g.r() > p.r() && g.b() > p.b());
        assert!(g.r() / p.r() > g.b() / p.b());
        assert!(Bsdf::from_json(r#"{"type": "roughconductor", "alpha_u": 0.1, "alpha_v": 0.3, "energy_compensation": true}"#).is_err());
    }

    #[test]
    fn table_interpolant_and_average() {
        // E(μ) = μ is tabulated exactly (linear in t² is not linear in t: within the interpolation error),
        // and its average 2∫ μ² dμ = 2/3.
        let t = AlbedoTable::from_fn(|mu| mu as f64);
        assert!((t.average() - 2.0 / 3.0).abs() < 1e-4, "{}", t.average());
        assert!((t.albedo(0.25) - 0.25).abs() < 1e-3 && t.albedo(1.0) == 1.0);
        let c = AlbedoTable::from_fn(|_| 0.7);
        assert!((c.average() - 0.7).abs() < 1e-6 && (c.albedo(0.33) - 0.7).abs() < 1e-7);
    }

    /// The white furnace of `spec` from the side `sign` (+1 outside, −1 inside), by the model's own
    /// sampling with `n` samples at each of 12 cos θo, and the worst |albedo − 1| over them.
    fn furnace(spec: &str, sign: f32, n: usize) -> (f32, f32) {
        let b = Bsdf::from_json(spec).unwrap();
        let curve = energy::albedo_curve(&b, 12, sign, n, 11);
        (energy::white_furnace(&curve).r(), curve.iter().map(|(_, a)| (a.r() - 1.0).abs()).fold(0.0f32, f32::max))
    }

    #[test]
    fn white_rough_dielectric_passes_the_furnace_with_compensation() {
        // Albedo R + T (energy) from either side: within 1 % of 1 with compensation at α ≤ 1, η = 1.33, 1.5, 2.
        let mut failed = Vec::new();
        for kind in ["ggx", "beckmann"] {
            for alpha in [0.05f32, 0.3, 1.0] {
                for eta in [1.33f32, 1.5, 2.0] {
                    for (sign, side) in [(1.0f32, "outside"), (-1.0, "inside")] {
                        let spec = |on: bool| {
                            format!(
                                r#"{{"type": "roughdielectric", "distribution": "{kind}", "alpha": {alpha}, "int_ior": {eta}, "ext_ior": 1.0, "energy_compensation": {on}}}"#
                            )
                        };
                        // 16384 samples: from inside the weights vary most, σ ≈ 0.002 at one cos θo.
                        let ((off, _), (on, worst)) = (furnace(&spec(false), sign, 4096), furnace(&spec(true), sign, 16384));
                        eprintln!("{kind} α={alpha} η={eta} {side}: furnace {off:.4} → {on:.4}; worst |albedo − 1| {worst:.4}");
                        if (on - 1.0).abs() > 0.01 || worst > 0.01 {
                            failed.push(format!("{kind} α={alpha} η={eta} {side}: furnace {on}, worst albedo error {worst}"));
                        }
                        if alpha >= 1.0 {
                            assert!(off < 0.97, "{kind} α={alpha} η={eta} {side}: the uncompensated model loses energy, got {off}");
                        }
                    }
                }
            }
        }
        assert!(failed.is_empty(), "{}", failed.join("\n"));
    }

    #[test]
    fn white_rough_plastic_passes_the_furnace_with_compensation() {
        // ρ = 1 under a lossless coating: every photon leaves again, so the albedo is exactly 1 — with
        // compensation within 1 %; without, the coating's multiple scattering is lost on the way in, out
        // and at every internal bounce.
        let mut failed = Vec::new();
        for kind in ["ggx", "beckmann"] {
            for alpha in [0.05f32, 0.3, 1.0] {
                let spec = |on: bool| {
                    format!(
                        r#"{{"type": "roughplastic", "distribution": "{kind}", "alpha": {alpha}, "diffuse_reflectance": 1.0, "energy_compensation": {on}}}"#
                    )
                };
                let ((off, _), (on, worst)) = (furnace(&spec(false), 1.0, 4096), furnace(&spec(true), 1.0, 16384));
                eprintln!("roughplastic {kind} α={alpha}: furnace {off:.4} → {on:.4}; worst |albedo − 1| {worst:.4}");
                if (on - 1.0).abs() > 0.01 || worst > 0.01 {
                    failed.push(format!("{kind} α={alpha}: furnace {on}, worst albedo error {worst}"));
                }
                if alpha >= 1.0 {
                    assert!(off < 0.97, "{kind} α={alpha}: the uncompensated model loses energy, got {off}");
                }
            }
        }
        assert!(failed.is_empty(), "{}", failed.join("\n"));
    }

    #[test]
    fn dielectric_compensation_is_reciprocal_across_the_interface() {
        // f(ωo, ωi)/ηo² = f(ωi, ωo)/ηi² for every pair, the added lobes included; and they add light.
        for eta in [1.5f32, 1.0 / 1.5] {
            let spec = |on: bool| {
                format!(
                    r#"{{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.7, "int_ior": {eta}, "ext_ior": 1.0, "energy_compensation": {on}}}"#
                )
            };
            let (plain, b) = (Bsdf::from_json(&spec(false)).unwrap(), Bsdf::from_json(&spec(true)).unwrap());
            let r = crate::verify::reciprocity::reciprocity(&b, 20_000, 5);
            assert!(r.max_rel_error < 1e-5 && r.compared > 10_000, "η={eta}: {r:?}");
            let (wo, wi) = (energy::direction(0.6, 0.2), energy::direction(-0.5, 2.5));
            assert!(b.f(wo, wi).r() > plain.f(wo, wi).r() && b.f(wi, wo).r() > plain.f(wi, wo).r());
        }
        assert!(Bsdf::from_json(r#"{"type": "roughdielectric", "alpha_u": 0.1, "alpha_v": 0.3, "energy_compensation": true}"#).is_err());
    }
}
