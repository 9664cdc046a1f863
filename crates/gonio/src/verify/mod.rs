//! The verification harness: proofs of a model's physics that anyone can run on any [`BsdfModel`].
//! The same functions back `cargo test`, the `gonio check` command and (later) `gonio.verify` in Python.
//!
//! | check        | what it proves                                                       | limit            |
//! |--------------|----------------------------------------------------------------------|------------------|
//! | chi2         | `sample` draws directions with the density `pdf` claims               | p > α (Šidák, α = 0.01) |
//! | consistency  | `weight == f·cos/pdf`, and `f`, `pdf` agree with their sampled values | 1e-4 relative    |
//! | reciprocity  | f(ωo, ωi) = f(ωi, ωo) (η-scaled across an interface)                  | 1e-5 relative    |
//! | energy       | directional albedo ≤ 1 at every θo; the white furnace ≤ 1            | 1 + 1e-3         |
//! | sweep        | no NaN, Inf or negative value for random and degenerate inputs       | 0 bad queries    |
//!
//! ```
//! use gonio::verify::{check, CheckConfig};
//! let bsdf = gonio::Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap();
//! let report = check(&bsdf, &CheckConfig::quick());
//! assert!(report.passed(), "{}", report.to_table());
//! ```

pub mod chi2;
pub mod consistency;
pub mod energy;
pub mod reciprocity;
pub mod sweep;

use crate::bsdf::{BsdfFlags, BsdfModel, SampleBuffers};
use crate::math::{Vec2, Vec3};
use crate::sampling::warp::sample_uniform_sphere;
use crate::sampling::Pcg32;
use std::path::PathBuf;

/// A uniformly distributed unit direction.
#[inline]
pub(crate) fn random_direction(rng: &mut Pcg32) -> Vec3 {
    sample_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()))
}

/// How hard to check.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckConfig {
    /// Samples per chi-square test (the project's standard: at least 10⁶).
    pub chi2_samples: usize,
    /// Significance of the whole family of chi-square tests, before the Šidák correction.
    pub significance: f64,
    /// Number of chi-square tests in the family; `None` = those of this one model.
    pub sidak_family: Option<usize>,
    /// Queries in the NaN/Inf sweep (standard: at least 10⁶).
    pub sweep_queries: usize,
    /// Direction pairs for reciprocity.
    pub reciprocity_pairs: usize,
    /// Samples per albedo estimate, and how many θo.
    pub albedo_samples: usize,
    pub albedo_angles: usize,
    /// Samples per direction for the consistency check.
    pub consistency_samples: usize,
    pub seed: u64,
    /// Where to write chi-square histograms of failed tests (None: not written).
    pub histogram_dir: Option<PathBuf>,
}

impl Default for CheckConfig {
    fn default() -> Self {
        CheckConfig {
            chi2_samples: 1_000_000,
            significance: 0.01,
            sidak_family: None,
            sweep_queries: 1_000_000,
            reciprocity_pairs: 100_000,
            albedo_samples: 65_536,
            albedo_angles: 32,
            consistency_samples: 100_000,
            seed: 0,
            histogram_dir: None,
        }
    }
}

impl CheckConfig {
    /// A lighter configuration for doctests and quick looks (not the standard of `gonio check`).
    #[must_use]
    pub fn quick() -> Self {
        CheckConfig {
            chi2_samples: 100_000,
            sweep_queries: 100_000,
            reciprocity_pairs: 10_000,
            albedo_samples: 4096,
            albedo_angles: 8,
            consistency_samples: 10_000,
            ..CheckConfig::default()
        }
    }
}

/// One line of a report.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckRow {
    /// What was checked, e.g. `chi2 cosθo=+0.30`.
    pub check: String,
    /// The measured figure.
    pub measured: f64,
    /// The limit it is held to, as text (`< 1e-5`, `> 0.000125`).
    pub limit: String,
    pub passed: bool,
    /// Context: the worst case, a file written, a reason.
    pub detail: String,
}

/// The result of [`check`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    pub name: String,
    pub rows: Vec<CheckRow>,
}

impl Report {
    #[must_use]
    pub fn passed(&self) -> bool {
        self.rows.iter().all(|r| r.passed)
    }

    /// A plain-text table: check, measured value, limit, pass/fail.
    #[must_use]
    pub fn to_table(&self) -> String {
        let mut out = format!("{}\n", self.name);
        out += &format!("  {:<34} {:>12} {:>12}  {}\n", "check", "measured", "limit", "result");
        for r in &self.rows {
            out +=
                &format!("  {:<34} {:>12} {:>12}  {}", r.check, format_value(r.measured), r.limit, if r.passed { "pass" } else { "FAIL" });
            if !r.detail.is_empty() && !r.passed {
                out += &format!("  ({})", r.detail);
            }
            out.push('\n');
        }
        out
    }

    /// The report as a JSON value, for machines.
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "name": self.name,
            "passed": self.passed(),
            "checks": self.rows.iter().map(|r| serde_json::json!({
                "check": r.check,
                "measured": if r.measured.is_finite() { serde_json::json!(r.measured) } else { serde_json::json!(r.measured.to_string()) },
                "limit": r.limit,
                "passed": r.passed,
                "detail": r.detail,
            })).collect::<Vec<_>>(),
        })
    }
}

/// A file-name-safe version of a report name (a JSON spec, a path).
fn file_stem(name: &str) -> String {
    let stem: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    let stem = stem.split('_').filter(|p| !p.is_empty()).collect::<Vec<_>>().join("_");
    stem.chars().take(80).collect()
}

fn format_value(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        format!("{v:.6}")
    } else {
        format!("{v:.3e}")
    }
}

/// The incident directions chi-square and consistency are tested at: cos θo ∈ {0.98, 0.7, 0.3, 0.05}
/// (the last grazing), azimuth 0.3 rad, and the same below the surface when the model scatters there.
#[must_use]
pub fn test_directions<M: BsdfModel + ?Sized>(bsdf: &M) -> Vec<Vec3> {
    let above: Vec<Vec3> = [0.98f32, 0.7, 0.3, 0.05].iter().map(|&mu| energy::direction(mu, 0.3)).collect();
    let mut dirs = above.clone();
    if scatters_from_below(bsdf) {
        dirs.extend(above.iter().map(|w| Vec3::new(w.x, w.y, -w.z)));
    }
    dirs
}

/// Whether the model does anything for light arriving from below (transmissive or two-sided models).
#[must_use]
pub fn scatters_from_below<M: BsdfModel + ?Sized>(bsdf: &M) -> bool {
    if bsdf.flags().intersects(BsdfFlags::TRANSMISSION) {
        return true;
    }
    let mut rng = Pcg32::new(1, 77);
    (0..64).any(|_| bsdf.sample(energy::direction(-0.6, 0.3), rng.next_f32(), rng.next_vec2()).is_some())
}

/// Run every check on `bsdf`; `name` heads the report.
#[must_use]
pub fn check<M: BsdfModel + Sync + ?Sized>(bsdf: &M, cfg: &CheckConfig) -> Report {
    check_named(bsdf, "bsdf", cfg)
}

/// [`check`] with a name for the report (and for histogram files).
#[must_use]
pub fn check_named<M: BsdfModel + Sync + ?Sized>(bsdf: &M, name: &str, cfg: &CheckConfig) -> Report {
    let mut rows = Vec::new();
    let dirs = test_directions(bsdf);

    // Chi-square of sample() against pdf() at every test direction, one Šidák family.
    let chi2_cfg = chi2::Chi2Config {
        samples: cfg.chi2_samples,
        significance: cfg.significance,
        tests: cfg.sidak_family.unwrap_or(dirs.len()).max(1),
        seed: cfg.seed,
        ..chi2::Chi2Config::default()
    };
    for (k, &wo) in dirs.iter().enumerate() {
        let r = chi2::chi2_bsdf(bsdf, wo, &chi2_cfg);
        let mut detail = r.message.clone();
        if !r.passed {
            if let Some(dir) = &cfg.histogram_dir {
                let file = dir.join(format!("chi2-{}-{k}.txt", file_stem(name)));
                let written = std::fs::create_dir_all(dir).and_then(|()| r.write_histograms(&file));
                detail += &match written {
                    Ok(()) => format!("; histograms in {}", file.display()),
                    Err(e) => format!("; could not write histograms to {}: {e}", file.display()),
                };
            }
        }
        rows.push(CheckRow {
            check: format!("chi2 cosθo={:+.2}", wo.z),
            measured: r.p_value,
            limit: format!("p > {:.2e}", r.alpha),
            passed: r.passed,
            detail,
        });
    }

    // Consistency of sample() with f() and pdf().
    let c = consistency::consistency(bsdf, &dirs, cfg.consistency_samples, cfg.seed);
    rows.push(CheckRow {
        check: "sample weight/pdf".into(),
        measured: c.max_error(),
        limit: "< 1e-4".into(),
        passed: c.max_error() < 1e-4 && c.bad_delta == 0,
        detail: c.worst.unwrap_or_default(),
    });

    // Reciprocity.
    let r = reciprocity::reciprocity(bsdf, cfg.reciprocity_pairs, cfg.seed);
    rows.push(CheckRow {
        check: "reciprocity".into(),
        measured: r.max_rel_error,
        limit: "< 1e-5".into(),
        passed: r.max_rel_error < 1e-5,
        detail: r.worst.map(|(wo, wi)| format!("worst at wo={wo}, wi={wi}")).unwrap_or_default(),
    });

    // Energy: albedo over θo on each side, and the white furnace.
    let limit = 1.0 + 1e-3;
    let sides: &[f32] = if scatters_from_below(bsdf) { &[1.0, -1.0] } else { &[1.0] };
    for &sign in sides {
        let curve = energy::albedo_curve(bsdf, cfg.albedo_angles, sign, cfg.albedo_samples, cfg.seed);
        let (mu, worst) =
            curve.iter().map(|(mu, a)| (*mu, a.max_component())).fold((0.0, f32::MIN), |acc, x| if x.1 > acc.1 { x } else { acc });
        let side = if sign > 0.0 { "above" } else { "below" };
        rows.push(CheckRow {
            check: format!("albedo max ({side})"),
            measured: worst as f64,
            limit: format!("≤ {limit}"),
            passed: worst as f64 <= limit,
            detail: format!("at cosθo={mu:+.3}"),
        });
        let furnace = energy::white_furnace(&curve).max_component();
        rows.push(CheckRow {
            check: format!("white furnace ({side})"),
            measured: furnace as f64,
            limit: format!("≤ {limit}"),
            passed: furnace as f64 <= limit,
            detail: String::new(),
        });
    }

    rows.push(sweep_row(bsdf, cfg));
    Report { name: name.to_string(), rows }
}

/// The sweep's row of a report: `cfg.sweep_queries` queries, passing with zero bad ones.
fn sweep_row<M: BsdfModel + Sync + ?Sized>(bsdf: &M, cfg: &CheckConfig) -> CheckRow {
    let s = sweep::sweep(bsdf, cfg.sweep_queries, cfg.seed);
    CheckRow {
        check: format!("NaN/Inf sweep ({} queries)", s.queries),
        measured: s.bad as f64,
        limit: "= 0".into(),
        passed: s.bad == 0,
        detail: s.first_bad.unwrap_or_default(),
    }
}

/// Whether `report` shows the violation `row_kind` a non-physical model is kept to teach: some row whose
/// check starts with `row_kind` (e.g. "reciprocity", "albedo max") fails, and every other row passes.
/// For "albedo max" the white-furnace rows belong to the same energy violation and may fail with it.
/// `Err` says what went wrong.
pub fn expect_violation(report: &Report, row_kind: &str) -> Result<(), String> {
    let related = |check: &str| check.starts_with(row_kind) || (row_kind == "albedo max" && check.starts_with("white furnace"));
    if !report.rows.iter().any(|r| r.check.starts_with(row_kind) && !r.passed) {
        return Err(format!("expected a `{row_kind}` violation:\n{}", report.to_table()));
    }
    let others: Vec<&str> = report.rows.iter().filter(|r| !related(&r.check) && !r.passed).map(|r| r.check.as_str()).collect();
    if !others.is_empty() {
        return Err(format!("only `{row_kind}` may fail, but so did {}:\n{}", others.join(", "), report.to_table()));
    }
    Ok(())
}

/// Samples per call of a model's `sample_batch` in the checks.
const SAMPLE_BATCH: usize = 256;

/// `count` samples of `bsdf` from `wo`, through the model's batches (its lanes give each sample as a
/// single call would): `draw(k)` gives the k-th sample's (uc, u), called for k in order; `take(rows, m)`
/// sees each batch's first `m` rows, batches in order.
pub(crate) fn sample_batches<M: BsdfModel + ?Sized>(
    bsdf: &M,
    wo: Vec3,
    count: usize,
    mut draw: impl FnMut(usize) -> (f32, Vec2),
    mut take: impl FnMut(&SampleBuffers, usize),
) {
    let wos = [wo; SAMPLE_BATCH];
    let (mut uc, mut u) = (Vec::with_capacity(SAMPLE_BATCH), Vec::with_capacity(SAMPLE_BATCH));
    let mut rows = SampleBuffers::new(SAMPLE_BATCH);
    for start in (0..count).step_by(SAMPLE_BATCH) {
        let m = SAMPLE_BATCH.min(count - start);
        uc.clear();
        u.clear();
        for k in start..start + m {
            let (c, v) = draw(k);
            uc.push(c);
            u.push(v);
        }
        bsdf.sample_batch(&wos[..m], &uc, &u, &mut rows.columns());
        take(&rows, m);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::BsdfSample;
    use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
    use crate::Rgb;

    /// A deliberately broken model: f = gain/π with a cosine sampler, and optionally a pdf that lies.
    struct Broken {
        gain: f32,
        skew: bool,
        pdf_scale: f32,
    }

    impl BsdfModel for Broken {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::DIFFUSE_REFLECTION
        }
        fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
            if wo.z <= 0.0 || wi.z <= 0.0 {
                return Rgb::ZERO;
            }
            let skew = if self.skew { 0.5 + wi.z } else { 1.0 };
            Rgb::splat(self.gain * skew * std::f32::consts::FRAC_1_PI)
        }
        fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
            if wo.z <= 0.0 {
                return None;
            }
            let wi = sample_cosine_hemisphere(u);
            BsdfSample::smooth(wi, self.f(wo, wi), self.pdf(wo, wi), BsdfFlags::DIFFUSE_REFLECTION, 1.0)
        }
        fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
            if wo.z <= 0.0 {
                return 0.0;
            }
            // pdf_scale ≠ 1 makes pdf() disagree with the density sample() actually has.
            let p = cosine_hemisphere_pdf(wi);
            if self.pdf_scale == 1.0 {
                p
            } else {
                p * (self.pdf_scale * wi.z + (1.0 - self.pdf_scale) * 0.5) * 2.0
            }
        }
    }

    fn failed_rows(report: &Report) -> Vec<String> {
        report.rows.iter().filter(|r| !r.passed).map(|r| r.check.clone()).collect()
    }

    #[test]
    fn an_honest_model_passes_everything() {
        let r = check(&Broken { gain: 0.9, skew: false, pdf_scale: 1.0 }, &CheckConfig::quick());
        assert!(r.passed(), "{}", r.to_table());
    }

    #[test]
    fn energy_gain_is_detected() {
        let r = check(&Broken { gain: 1.2, skew: false, pdf_scale: 1.0 }, &CheckConfig::quick());
        assert_eq!(failed_rows(&r), ["albedo max (above)", "white furnace (above)"], "{}", r.to_table());
        assert!((r.rows.iter().find(|x| x.check.starts_with("albedo")).unwrap().measured - 1.2).abs() < 1e-3);
    }

    #[test]
    fn non_reciprocity_is_detected() {
        let r = check(&Broken { gain: 0.5, skew: true, pdf_scale: 1.0 }, &CheckConfig::quick());
        assert_eq!(failed_rows(&r), ["reciprocity"], "{}", r.to_table());
    }

    #[test]
    fn a_lying_pdf_fails_chi2_and_writes_histograms() {
        let dir = crate::scratch::ScratchDir::new("verify");
        let cfg = CheckConfig { histogram_dir: Some(dir.to_path_buf()), ..CheckConfig::quick() };
        let r = check_named(&Broken { gain: 0.5, skew: false, pdf_scale: 0.7 }, "lying pdf", &cfg);
        let failed = failed_rows(&r);
        // sample() reports the lying pdf consistently, so only the chi-square test can see the lie.
        assert!(!failed.is_empty() && failed.iter().all(|c| c.starts_with("chi2")), "{}", r.to_table());
        let files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
        assert!(!files.is_empty());
        let text = std::fs::read_to_string(&files[0]).unwrap();
        let numeric_rows = text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()).count();
        assert_eq!(numeric_rows, 2 * chi2::Chi2Config::default().theta_res, "observed and expected matrices");
    }

    #[test]
    fn expected_violations_are_recognised() {
        let gain = check(&Broken { gain: 1.2, skew: false, pdf_scale: 1.0 }, &CheckConfig::quick());
        assert_eq!(expect_violation(&gain, "albedo max"), Ok(()));
        assert!(expect_violation(&gain, "reciprocity").is_err());
        let skew = check(&Broken { gain: 0.5, skew: true, pdf_scale: 1.0 }, &CheckConfig::quick());
        assert_eq!(expect_violation(&skew, "reciprocity"), Ok(()));
        let honest = check(&Broken { gain: 0.9, skew: false, pdf_scale: 1.0 }, &CheckConfig::quick());
        assert!(expect_violation(&honest, "reciprocity").unwrap_err().contains("expected a `reciprocity` violation"));
    }

    #[test]
    fn report_renders_as_table_and_json() {
        let r = check(&Broken { gain: 1.2, skew: false, pdf_scale: 1.0 }, &CheckConfig::quick());
        let table = r.to_table();
        assert!(table.contains("FAIL") && table.contains("pass"));
        let json = r.to_json();
        assert_eq!(json["passed"], false);
        assert_eq!(json["checks"].as_array().unwrap().len(), r.rows.len());
    }
}
