//! `merl` — a measured isotropic BRDF from the MERL database (Matusik et al. 2003, "A Data-Driven
//! Reflectance Model", SIGGRAPH), or any model tabulated into the same layout by gonio's virtual
//! gonioreflectometer. The file format, the half/difference angles and the lookups are described in
//! [`crate::measured::merl_file`].
//!
//! | parameter       | type    | default       | meaning                                               |
//! |-----------------|---------|---------------|-------------------------------------------------------|
//! | `filename`      | string  | —             | a MERL `.binary` file (34,992,012 bytes)               |
//! | `interpolation` | `trilinear` \| `nearest` | `trilinear` | between cell centres, or the nearest cell (MERL's reader) |
//! | (nested bsdf)   | bsdf    | —             | instead of `filename`: tabulate this model in memory (one point per cell, at its centre) |
//!
//! f is read from the table; it is reciprocal bit for bit and never negative (cells that were not
//! measured are filled from their neighbours when the table is loaded). One-sided: zero below the surface.
//!
//! # Sampling
//! Per-θo tabulated distributions of the half vector (in the spirit of the warped half-vector tables of
//! Dupuy & Jakob 2018, "An Adaptive Parameterization for Efficient Material Acquisition and Rendering",
//! §5, built here from the table itself). For 32 angles θo,j = (j + ½)/32 · π/2, with ωo in the xz-plane,
//! the half vector ωh is parameterised by a point (a, b) ∈ [0,1]²:
//! 1. Shirley & Chiu's concentric map takes (a, b) to a point e of the unit disk (area × π);
//! 2. a radial warp r = g(|e|) = (e^{c|e|} − 1)/(e^c − 1), c = 3, moves it to d = e·r/|e|: cells near the
//!    centre shrink 6.4-fold, and g′(0) > 0 keeps the density finite there (a polar grid would not);
//! 3. ωh = (d.x, d.y, √(1 − r²)) (Nusselt's projection: dA = cos θh dωh);
//! 4. ωi reflects ωo about ωh: dωi = 4 (ωo·ωh) dωh (Torrance & Sparrow 1967).
//!
//! A continuous density over (a, b) — the bilinear interpolant of the channel sum of
//! f(ωo,j, ωi) cos θi |dωi/d(a, b)| at the 65 × 65 nodes (i/64, j/64), sampled by inverting its marginal
//! and conditional CDFs ([`Marginal2D`], the warp Dupuy & Jakob store their tables for) — so that its
//! samples are distributed like f cos θi. Being continuous (a piecewise-constant table is not), it lets
//! the chi-square test's adaptive quadrature converge quickly. At run time ωo is rotated into the
//! xz-plane; the tables of the two nearest θo,j are mixed with weights linear in θo, and a
//! cosine-weighted lobe is mixed in with probability 0.1 so that every direction where f > 0 can be
//! drawn. The pdf is the exact density of this mixture:
//! pdf = 0.1 cos θi/π + 0.9 Σⱼ wⱼ p_j(a, b)/|dωi/d(a, b)|, evaluated from the returned ωi.
//!
//! ```no_run
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! let brdf = Bsdf::from_json(r#"{"type": "merl", "filename": "gold-metallic-paint.binary"}"#).unwrap();
//! let f = brdf.f(Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.0, -0.6, 0.8));
//! ```

use super::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
use crate::error::{Error, Result};
use crate::math::{Vec2, Vec3};
use crate::measured::{gonioreflectometer, Interpolation, MerlTable};
use crate::props::Props;
use crate::sampling::marginal2d::Marginal2D;
use crate::sampling::warp::{
    cosine_hemisphere_pdf, invert_uniform_disk_concentric, sample_cosine_hemisphere, sample_uniform_disk_concentric,
};
use crate::spectrum::Rgb;
use std::f32::consts::{FRAC_PI_2, PI};
use std::path::Path;
use std::sync::Arc;

/// Number of θo tables.
const THETA_O_TABLES: usize = 32;
/// Cells per side of each half-vector table (GRID + 1 nodes).
const GRID: usize = 64;
/// The radial warp's constant c (see the module docs).
const WARP_C: f32 = 3.0;
/// Probability of the cosine-weighted lobe.
const COSINE_WEIGHT: f32 = 0.1;

/// A measured BRDF: the table and its sampling distributions, shared.
#[derive(Clone, Debug, PartialEq)]
pub struct Merl {
    data: Arc<MerlData>,
    pub interpolation: Interpolation,
}

#[derive(Debug, PartialEq)]
struct MerlData {
    table: MerlTable,
    sampler: HalfVectorSampler,
}

impl Merl {
    /// A model reading `table` with `interpolation`; builds the sampling tables.
    #[must_use]
    pub fn new(table: MerlTable, interpolation: Interpolation) -> Self {
        let sampler = HalfVectorSampler::build(&table);
        Merl { data: Arc::new(MerlData { table, sampler }), interpolation }
    }

    /// Load a MERL file.
    pub fn open(path: &Path, interpolation: Interpolation) -> Result<Self> {
        Ok(Merl::new(MerlTable::read(path)?, interpolation))
    }

    /// The table.
    #[must_use]
    pub fn table(&self) -> &MerlTable {
        &self.data.table
    }

    pub fn from_props(p: &Props) -> Result<Self> {
        let interpolation = match p.string("interpolation")? {
            None => Interpolation::Trilinear,
            Some(name) => Interpolation::parse(&name).ok_or_else(|| {
                Error::spec(
                    p.at_param("interpolation"),
                    format!("parameter `interpolation` of `merl` must be `trilinear` or `nearest`, got `{name}`"),
                )
            })?,
        };
        let filename = p.string("filename")?;
        let nested = p.nested();
        let table = match (filename, nested.as_slice()) {
            (Some(f), []) => MerlTable::read(Path::new(&f))?,
            (None, [source]) => {
                let bsdf = Bsdf::from_props(source)?;
                gonioreflectometer::measure(&bsdf, 1, &format!("{} tabulated", source.at()))?
            }
            (None, []) => return Err(Error::spec(p.at(), "`merl` needs a `filename` (a MERL .binary file) or a nested BSDF to tabulate")),
            _ => return Err(Error::spec(p.at(), "`merl` takes either a `filename` or one nested BSDF, not both or several")),
        };
        Ok(Merl::new(table, interpolation))
    }
}

/// Tables made in memory from analytic models (a real MERL file cannot ship with gonio): a shiny
/// aluminium GGX lobe, a rough Beckmann copper read with `nearest`, and a rough plastic. The nested model
/// is tabulated when the spec is loaded, so no file is needed. With the continuous half-vector density the
/// whole harness takes 10–40 s per spec on 2 cores (2026-11): the first (shiny) spec is the
/// [`crate::bsdf::Examples`] of `merl` (so in `gonio check --all`); the `#[ignore]`d test
/// `harness_on_tables` runs all three, `chi2_on_the_shiny_table` two directions in every `cargo test`.
pub const HARNESS_SPECS: &[&str] = &[
    r#"{"type": "merl", "bsdf": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.05, "material": "Al"}}"#,
    r#"{"type": "merl", "interpolation": "nearest", "bsdf": {"type": "roughconductor", "alpha": 0.4, "material": "Cu"}}"#,
    r#"{"type": "merl", "bsdf": {"type": "roughplastic", "distribution": "ggx", "alpha": 0.2, "diffuse_reflectance": [0.6, 0.3, 0.1]}}"#,
];

impl crate::bsdf::Examples for Merl {
    /// The shiny table of [`HARNESS_SPECS`].
    const EXAMPLES: &'static [&'static str] = &[HARNESS_SPECS[0]];
}

impl BsdfModel for Merl {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY_REFLECTION
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.data.table.eval(wo, wi, self.interpolation)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let wi = if uc < COSINE_WEIGHT {
            sample_cosine_hemisphere(u)
        } else {
            let uc = ((uc - COSINE_WEIGHT) / (1.0 - COSINE_WEIGHT)).min(1.0);
            self.data.sampler.sample(wo, uc, u)?
        };
        if !(wi.z > 0.0) {
            return None;
        }
        let s = BsdfSample::smooth(wi, self.f(wo, wi), self.pdf(wo, wi), BsdfFlags::GLOSSY_REFLECTION, 1.0)?;
        s.weight.is_finite().then_some(s)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        COSINE_WEIGHT * cosine_hemisphere_pdf(wi) + (1.0 - COSINE_WEIGHT) * self.data.sampler.pdf(wo, wi)
    }
}

/// The per-θo half-vector distributions (see the module docs).
#[derive(Debug, PartialEq)]
struct HalfVectorSampler {
    /// One normalised density per θo,j; `None` where f cos θi is zero over the whole table.
    tables: Vec<Option<Marginal2D<0>>>,
}

/// The radial warp g and its derivative.
fn warp_g(s: f32) -> f32 {
    (WARP_C * s).exp_m1() / WARP_C.exp_m1()
}

fn warp_g_prime(s: f32) -> f32 {
    WARP_C * (WARP_C * s).exp() / WARP_C.exp_m1()
}

fn warp_g_inverse(r: f32) -> f32 {
    (r * WARP_C.exp_m1()).ln_1p() / WARP_C
}

/// ωh for a point of the unit square, and the area ratio dA(disk d)/d(a, b) = π g(s) g′(s)/s.
fn half_vector(ab: Vec2) -> (Vec3, f32) {
    let e = sample_uniform_disk_concentric(ab);
    let s = e.length().min(1.0);
    let r = warp_g(s);
    let ratio = if s > 1e-6 { r / s } else { warp_g_prime(0.0) };
    let d = e * ratio;
    let wh = Vec3::new(d.x, d.y, (1.0 - r * r).max(0.0).sqrt());
    (wh, PI * ratio * warp_g_prime(s))
}

/// The inverse of [`half_vector`]: (a, b) and the same area ratio.
fn invert_half_vector(wh: Vec3) -> (Vec2, f32) {
    let d = Vec2::new(wh.x, wh.y);
    let r = d.length().min(1.0);
    let s = warp_g_inverse(r);
    let ratio = if s > 1e-6 { r / s } else { warp_g_prime(0.0) };
    let e = if r > 0.0 { d * (s / r) } else { Vec2::ZERO };
    (invert_uniform_disk_concentric(e), PI * ratio * warp_g_prime(s))
}

/// ωo rotated into the xz-plane (x ≥ 0), and the rotation (cos φo, sin φo).
fn canonical(wo: Vec3) -> (Vec3, f32, f32) {
    let rho = (wo.x * wo.x + wo.y * wo.y).sqrt();
    let (c, s) = if rho > 0.0 { (wo.x / rho, wo.y / rho) } else { (1.0, 0.0) };
    (Vec3::new(rho, 0.0, wo.z), c, s)
}

/// The two tables around θo and the weight of the upper one.
fn table_pair(cos_theta_o: f32) -> (usize, usize, f32) {
    let t = (cos_theta_o.clamp(-1.0, 1.0).acos() / FRAC_PI_2 * THETA_O_TABLES as f32 - 0.5).clamp(0.0, (THETA_O_TABLES - 1) as f32);
    let j0 = (t as usize).min(THETA_O_TABLES - 2);
    (j0, j0 + 1, t - j0 as f32)
}

impl HalfVectorSampler {
    fn build(table: &MerlTable) -> Self {
        use rayon::prelude::*;
        const NODES: usize = GRID + 1;
        let tables = (0..THETA_O_TABLES)
            .into_par_iter()
            .map(|j| {
                let theta_o = (j as f32 + 0.5) / THETA_O_TABLES as f32 * FRAC_PI_2;
                let wo = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
                let mut values = vec![0f32; NODES * NODES];
                for (k, v) in values.iter_mut().enumerate() {
                    let ab = Vec2::new((k % NODES) as f32 / GRID as f32, (k / NODES) as f32 / GRID as f32);
                    let (wh, area) = half_vector(ab);
                    let cos_d = wo.dot(wh);
                    if !(cos_d > 0.0 && wh.z > 0.0) {
                        continue;
                    }
                    let wi = (2.0 * cos_d * wh - wo).normalize();
                    if !(wi.z > 0.0) {
                        continue;
                    }
                    let f = table.eval(wo, wi, Interpolation::Trilinear);
                    let jacobian = area / wh.z * 4.0 * cos_d;
                    let value = (f.r() + f.g() + f.b()) * wi.z * jacobian;
                    *v = if value.is_finite() { value.max(0.0) } else { 0.0 };
                }
                if !values.iter().any(|&v| v > 0.0) {
                    return None;
                }
                // Finite, non-negative, not all zero, 65 × 65: `new` cannot fail.
                Some(Marginal2D::new(&values, [NODES, NODES], [], true, true).expect("a valid half-vector table"))
            })
            .collect();
        HalfVectorSampler { tables }
    }

    /// Draw ωi from the θo tables (`uc` picks the table).
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<Vec3> {
        let (wo_c, c, s) = canonical(wo);
        let (j0, j1, t) = table_pair(wo.z);
        let table = self.tables[if uc < 1.0 - t { j0 } else { j1 }].as_ref()?;
        let (wh, _) = half_vector(table.sample(u, []).0);
        let cos_d = wo_c.dot(wh);
        if !(cos_d > 0.0) {
            return None;
        }
        let wi_c = 2.0 * cos_d * wh - wo_c;
        Some(Vec3::new(c * wi_c.x - s * wi_c.y, s * wi_c.x + c * wi_c.y, wi_c.z).normalize())
    }

    /// The density of [`Self::sample`] (solid angle).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo_c, c, s) = canonical(wo);
        let wi_c = Vec3::new(c * wi.x + s * wi.y, -s * wi.x + c * wi.y, wi.z);
        let wh = (wo_c + wi_c).normalize();
        let cos_d = wo_c.dot(wh);
        if !(cos_d > 0.0 && wh.z > 0.0) {
            return 0.0;
        }
        let (ab, area) = invert_half_vector(wh);
        let jacobian = area / wh.z * 4.0 * cos_d;
        let (j0, j1, t) = table_pair(wo.z);
        let density = |j: usize| self.tables[j].as_ref().map_or(0.0, |m| m.eval(ab, []));
        let p = ((1.0 - t) * density(j0) + t * density(j1)) / jacobian;
        if p.is_finite() {
            p
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;
    use crate::verify::{check_named, energy::direction, CheckConfig};

    /// About a minute on 2 cores (all three specs, every check): run by hand with `--ignored`.
    #[test]
    #[ignore]
    fn harness_on_tables() {
        let failed: Vec<String> = HARNESS_SPECS
            .iter()
            .map(|spec| {
                let start = std::time::Instant::now();
                let r = check_named(&Bsdf::from_json(spec).unwrap(), spec, &CheckConfig::default());
                eprintln!("{spec}: {:.1} s", start.elapsed().as_secs_f64());
                r
            })
            .inspect(|r| eprintln!("{}", r.to_table()))
            .filter(|r| !r.passed())
            .map(|r| r.to_table())
            .collect();
        assert!(failed.is_empty(), "{}", failed.join("\n"));
    }

    /// Chi-square of the sampling alone, at two directions of the shiny table (a few seconds).
    #[test]
    fn chi2_on_the_shiny_table() {
        use crate::verify::chi2::{chi2_bsdf, Chi2Config};
        let b = Bsdf::from_json(HARNESS_SPECS[0]).unwrap();
        for mu in [0.9f32, 0.3] {
            let start = std::time::Instant::now();
            let r = chi2_bsdf(&b, direction(mu, 0.3), &Chi2Config::default());
            eprintln!("cosθo={mu}: {} ({:.1} s)", r.message, start.elapsed().as_secs_f64());
            assert!(r.passed, "cosθo={mu}: {}", r.message);
        }
    }

    /// Variance of the white-environment estimate f cos θi / pdf (one sample) with the model's sampling
    /// and with cosine-weighted sampling.
    fn variances(b: &Bsdf, wo: Vec3, n: usize) -> (f64, f64, f64) {
        let mut rng = Pcg32::new(17, 5);
        let (mut s1, mut s2, mut c1, mut c2) = (0f64, 0f64, 0f64, 0f64);
        for _ in 0..n {
            let (uc, u) = (rng.next_f32(), rng.next_vec2());
            let w = b.sample(wo, uc, u).map_or(0.0, |s| f64::from(s.weight.luminance()));
            s1 += w;
            s2 += w * w;
            let wi = sample_cosine_hemisphere(u);
            let w = f64::from(b.f(wo, wi).luminance() * PI);
            c1 += w;
            c2 += w * w;
        }
        let n = n as f64;
        (s2 / n - (s1 / n).powi(2), c2 / n - (c1 / n).powi(2), s1 / n)
    }

    #[test]
    fn sampling_beats_cosine_sampling_on_a_shiny_material() {
        let b = Bsdf::from_json(HARNESS_SPECS[0]).unwrap();
        for mu in [0.95f32, 0.7, 0.4] {
            let (var, var_cos, mean) = variances(&b, direction(mu, 0.3), 400_000);
            let factor = var_cos / var;
            eprintln!(
                "shiny Al GGX α=0.05 table, cosθo={mu}: albedo {mean:.4}, variance {var:.3e} vs cosine {var_cos:.3e}: factor {factor:.1}"
            );
            assert!(factor >= 5.0, "cosθo={mu}: variance factor {factor}");
        }
    }

    #[test]
    fn half_vector_warp_round_trips() {
        let mut rng = Pcg32::new(2, 9);
        for _ in 0..10_000 {
            let ab = rng.next_vec2();
            let (wh, area) = half_vector(ab);
            let (back, area2) = invert_half_vector(wh);
            assert!((back - ab).abs().max_element() < 1e-4 && (area - area2).abs() < 1e-3 * area, "{ab} → {wh} → {back}");
            assert!((wh.length() - 1.0).abs() < 1e-5 && area.is_finite() && area > 0.0);
        }
    }

    #[test]
    fn parameters_are_checked() {
        for (bad, expect) in [
            (r#"{"type": "merl"}"#, "needs a `filename`"),
            (r#"{"type": "merl", "filename": "/no/such.binary"}"#, "/no/such.binary"),
            (r#"{"type": "merl", "filename": "x", "bsdf": {"type": "diffuse"}}"#, "not both"),
            (r#"{"type": "merl", "interpolation": "cubic", "bsdf": {"type": "diffuse"}}"#, "`trilinear` or `nearest`"),
        ] {
            let err = Bsdf::from_json(bad).unwrap_err().to_string();
            assert!(err.contains(expect), "{bad}: {err}");
        }
    }

    #[test]
    fn a_file_loads_through_the_registry() {
        let (model, path, _) = crate::measured::fixtures::smooth();
        let spec = format!(r#"{{"type": "merl", "filename": "{}"}}"#, path.display());
        let b = Bsdf::from_json(&spec).unwrap();
        assert_eq!(b.plugin_name(), "merl");
        let (wo, wi) = (Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::new(-0.4, 0.0, 0.8).normalize());
        let (got, want) = (b.f(wo, wi), model.f(wo, wi));
        assert!((got.r() / want.r() - 1.0).abs() < 0.01, "{got:?} vs {want:?}");
    }
}
