//! The chi-square goodness-of-fit test of a sampler against its density: does `sample` draw directions
//! (or points) with exactly the density `pdf` claims? (Pearson 1900; the test as used for BSDFs by
//! Jakob's Mitsuba and by pbrt-v4's `bsdfs_test.cpp`, written anew here.)
//!
//! The domain is cut into a grid of cells: for directions, equal-area cells in (cos θ ∈ [−1, 1],
//! φ ∈ [0, 2π)) over the full sphere, where dω = d(cos θ) dφ; for planar warps, a rectangle in (x, y).
//! N samples are drawn and counted per cell (observed); the expected count of a cell is N ∫_cell pdf,
//! integrated numerically (never by sampling). Delta lobes of a BSDF, which
//! `pdf` cannot see, get one bin per lobe direction whose expected count is N × the lobe's discrete
//! probability; samples that were not produced (`None`, or outside a planar domain) fall into a "no
//! sample" bin expected to hold the missing probability N (1 − ∫pdf − Σ delta probabilities).
//!
//! # The cell integrals
//! A peaked lobe defeats any fixed quadrature: a microfacet lobe of α = 0.01 is narrower than a cell, so
//! a fixed 6 × 6 Gauss–Legendre rule per cell sees it at a few nodes or not at all (it made correct
//! models "integrate to 1.27–3.8"). Each cell is therefore integrated adaptively: the tensor Gauss–
//! Legendre rule of order 2n on the part is compared with the rule of order n on the part and on four
//! unequal parts of it (split at 0.4 of each side), and where either differs by more than 10⁻⁴ of the
//! part's expected count (or 10⁻⁴ counts shared by area) the part is split into 4 and each quarter
//! integrated the same way, down to 10 splits; the value kept is the order-2n one. Parts still
//! disagreeing at the limit are named in the result's message. (Until 2026-12-06 only the two rules on
//! the whole part were compared: both symmetric about its centre, so a pdf with a step between their
//! central nodes — a GGX `roughdielectric`'s transmission cutting off at cos θi ≈ −0.027 at cos θo = 0.05
//! for η ≈ 1.75–1.88 — gave both the same half-way answer, 11 % above the integral, and the sampler
//! failed at p = 10⁻³³. Comparing with the unequal parts alone was tried and lost 9·10⁻⁵ of an α = 10⁻³
//! lobe: the order-2n rule must also be checked against the order-n rule on the same part.)
//!
//! A lobe much narrower than the nodes' spacing can fall between the nodes of both rules, which then
//! agree on the wrong answer. The samples say where to look: a cell that holds samples but expects
//! almost none (< 10⁻³), or whose observed count is more than 5σ from its expected one, is integrated
//! again, split regardless of the rules' agreement down to the depth limit around the first samples
//! that landed in it (up to 64 positions, kept while counting), and every part overlapping the region
//! around those samples (their bounding box widened twofold on each side) is split while it is wider
//! than that region, so that the lobe's tails, which hold no sample, are resolved too. The expected
//! counts remain integrals of `pdf` alone — the samples only choose where the quadrature looks harder —
//! so a wrong pdf still fails: refinement makes its integral accurate, not closer to the histogram.
//!
//! # The statistic
//! Cells expected to hold fewer than 5 samples are pooled; Pearson's statistic Σ (O − E)² / E over the
//! remaining cells follows a χ² law with (cells − 1) degrees of freedom when the sampler is right. The
//! test fails when its p-value is below the per-test significance α' = 1 − (1 − α)^(1/m) (Šidák 1967,
//! for m tests run together), or at once when a sample lands where the pdf is zero, reports a pdf that
//! disagrees with `pdf`, or is not a unit direction. On failure [`Chi2Result::write_histograms`] writes
//! both histograms to a text file for plotting.
//!
//! ```
//! use gonio::bsdf::Bsdf;
//! use gonio::math::Vec3;
//! use gonio::verify::chi2::{chi2_bsdf, Chi2Config};
//! let bsdf = Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap();
//! let cfg = Chi2Config { samples: 100_000, ..Chi2Config::default() };
//! let r = chi2_bsdf(&bsdf, Vec3::new(0.6, 0.0, 0.8), &cfg);
//! assert!(r.passed, "{r}");
//! ```

use crate::bsdf::{BsdfFlags, BsdfModel};
use crate::math::{Vec2, Vec3};
use crate::sampling::Pcg32;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};
use std::fmt;
use std::io::Write;
use std::path::Path;

/// Cells expected to hold fewer samples than this are pooled (Cochran 1954's rule of five).
const MIN_EXPECTED: f64 = 5.0;
/// Samples per parallel chunk; each chunk draws from its own PCG32 stream, so results do not depend
/// on the number of threads.
const CHUNK: usize = 1 << 14;
/// Tolerance on |‖wi‖ − 1| (2026-11: `f32` directions built from sin/cos carry ~1e-7 error; 1e-3 flags
/// real normalisation bugs only).
const UNIT_TOLERANCE: f32 = 1e-3;
/// Relative tolerance between a sample's reported pdf and `pdf(wo, wi)` (2026-11: the two are computed
/// along different `f32` paths, e.g. mixture sums in a different order).
const PDF_TOLERANCE: f32 = 1e-3;
/// Relative spread allowed between the pdfs reported by samples of one delta lobe (2026-11: `f32`
/// Fresnel factors computed from the same `wo` agree to ~1e-7).
const DELTA_PDF_TOLERANCE: f32 = 1e-4;
/// Delta directions are grouped after rounding each coordinate to this step (2026-11: a delta lobe's
/// direction is a deterministic function of `wo`, so any step far above `f32` noise works).
const DELTA_QUANTUM: f32 = 1e-4;
/// How far ∫pdf + Σ delta probabilities may exceed 1 before the test fails (2026-11: quadrature error
/// of smooth pdfs is far below this; a real excess is a normalisation bug).
const EXCESS_TOLERANCE: f64 = 1e-3;

/// Settings of a chi-square test.
#[derive(Clone, Debug, PartialEq)]
pub struct Chi2Config {
    /// Number of samples N (the project's floor for a verdict is 10⁶).
    pub samples: usize,
    /// Cells along cos θ ∈ [−1, 1] (sphere domain). Even, so that the horizon is a cell edge.
    pub theta_res: usize,
    /// Cells along φ ∈ [0, 2π) (sphere domain).
    pub phi_res: usize,
    /// Family-wise significance α.
    pub significance: f64,
    /// Number of tests m run together, for the Šidák correction.
    pub tests: usize,
    /// Seed of the random streams.
    pub seed: u64,
    /// Gauss–Legendre points per cell and axis for the expected counts.
    pub integration_res: usize,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Chi2Config { samples: 1_000_000, theta_res: 40, phi_res: 80, significance: 0.01, tests: 1, seed: 0, integration_res: 6 }
    }
}

impl Chi2Config {
    /// The Šidák-corrected per-test threshold α' = 1 − (1 − α)^(1/m).
    #[must_use]
    pub fn alpha(&self) -> f64 {
        sidak_alpha(self.significance, self.tests)
    }
}

/// Šidák 1967: the per-test significance that keeps the family-wise error rate of `tests` independent
/// tests at `significance`: 1 − (1 − α)^(1/m).
#[must_use]
pub fn sidak_alpha(significance: f64, tests: usize) -> f64 {
    // ln1p / exp_m1 keep precision for small α and many tests.
    -(((-significance).ln_1p()) / tests.max(1) as f64).exp_m1()
}

/// One bin of a delta lobe: the samples that went in direction `wi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaBin {
    pub wi: Vec3,
    pub observed: f64,
    pub expected: f64,
}

/// The outcome of a chi-square test, with both histograms.
#[derive(Clone, Debug, PartialEq)]
pub struct Chi2Result {
    /// Pearson's statistic over the pooled cells.
    pub statistic: f64,
    /// Degrees of freedom: pooled cells − 1.
    pub dof: usize,
    /// P(χ²_dof ≥ statistic).
    pub p_value: f64,
    /// The Šidák-corrected per-test threshold the p-value was compared with.
    pub alpha: f64,
    pub passed: bool,
    /// Empty, or why the test failed (or a note, such as "no scattering from this wo").
    pub message: String,
    /// Observed counts per grid cell, row-major over `res` (first coordinate major: cos θ rows for the
    /// sphere, x rows for the plane).
    pub observed: Vec<f64>,
    /// Expected counts per grid cell, same layout.
    pub expected: Vec<f64>,
    /// Grid shape (rows, columns).
    pub res: (usize, usize),
    /// One bin per delta lobe direction, sorted by direction.
    pub delta_bins: Vec<DeltaBin>,
    /// Samples that were not produced (`None`) or fell outside a planar domain.
    pub no_sample_observed: f64,
    /// N (1 − ∫pdf − Σ delta probabilities), clamped at 0.
    pub no_sample_expected: f64,
    /// Smooth samples whose reported pdf disagreed with `pdf(wo, wi)`.
    pub pdf_mismatches: usize,
    /// The grid in words, e.g. "sphere: rows = 40 bins of cos θ over [-1, 1], …".
    pub domain: String,
}

impl fmt::Display for Chi2Result {
    /// A one-line summary (the histograms are left out; see [`Chi2Result::write_histograms`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "chi2 {}: statistic {:.2}, dof {}, p = {:.3e} (threshold {:.3e}), {} delta bins, no-sample {}/{:.1}, {} pdf mismatches{}{}",
            if self.passed { "passed" } else { "FAILED" },
            self.statistic,
            self.dof,
            self.p_value,
            self.alpha,
            self.delta_bins.len(),
            self.no_sample_observed,
            self.no_sample_expected,
            self.pdf_mismatches,
            if self.message.is_empty() { "" } else { ": " },
            self.message
        )
    }
}

impl Chi2Result {
    /// Write the observed and expected histograms to a text file, atomically (`path.tmp`, then renamed).
    ///
    /// The header lines start with `#` and give the grid, the verdict, the delta and no-sample bins.
    /// Then come the observed matrix and the expected matrix, one line per row of the grid (cos θ bins
    /// for the sphere), so that NumPy reads both at once:
    ///
    /// ```python
    /// import numpy as np, matplotlib.pyplot as plt
    /// a = np.loadtxt("chi2.txt"); rows = a.shape[0] // 2
    /// observed, expected = a[:rows], a[rows:]
    /// fig, ax = plt.subplots(1, 3)
    /// ax[0].imshow(observed); ax[1].imshow(expected); ax[2].imshow(observed - expected)
    /// plt.show()
    /// ```
    pub fn write_histograms(&self, path: &Path) -> std::io::Result<()> {
        // Written in memory, then atomically (gonio::image::write_atomically).
        let mut out = Vec::new();
        {
            writeln!(out, "# gonio chi-square histograms: observed and expected sample counts per cell")?;
            writeln!(out, "# domain: {}", self.domain)?;
            writeln!(out, "# {self}")?;
            writeln!(out, "# no_sample observed {} expected {:.3}", self.no_sample_observed, self.no_sample_expected)?;
            for d in &self.delta_bins {
                writeln!(
                    out,
                    "# delta wi ({:.6}, {:.6}, {:.6}) observed {} expected {:.3}",
                    d.wi.x, d.wi.y, d.wi.z, d.observed, d.expected
                )?;
            }
            writeln!(out, "# load: a = numpy.loadtxt(path); observed, expected = a[:{0}], a[{0}:]", self.res.0)?;
            for (name, m) in [("observed", &self.observed), ("expected", &self.expected)] {
                writeln!(out, "# {name}: {} rows x {} columns", self.res.0, self.res.1)?;
                for row in m.chunks(self.res.1.max(1)) {
                    let line: Vec<String> = row.iter().map(|v| format!("{v:.3}")).collect();
                    writeln!(out, "{}", line.join(" "))?;
                }
            }
        }
        crate::image::write_atomically(path, &out).map_err(|e| match e {
            crate::Error::Io { source, .. } => source,
            other => std::io::Error::other(other.to_string()),
        })
    }
}

// ---------------------------------------------------------------------------------------------------
// Statistics
// ---------------------------------------------------------------------------------------------------

/// ln Γ(x) for x > 0 by the Lanczos approximation (Lanczos 1964; g = 7, 9 terms, relative error ~1e-15).
#[must_use]
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection Γ(x) Γ(1 − x) = π / sin(πx).
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let z = x - 1.0;
    let series = C[0] + C.iter().enumerate().skip(1).map(|(i, c)| c / (z + i as f64)).sum::<f64>();
    let t = z + G + 0.5;
    0.5 * (2.0 * PI).ln() + (z + 0.5) * t.ln() - t + series.ln()
}

/// The regularized upper incomplete gamma function Q(a, x) = Γ(a, x) / Γ(a), for a > 0, x ≥ 0.
///
/// Numerical Recipes (3rd ed.) §6.2: the series of P = 1 − Q (Eq. 6.2.5) for x < a + 1, the continued
/// fraction of Q (Eq. 6.2.7, evaluated by the modified Lentz method, §5.2) otherwise. Both converge in
/// O(√a) terms, so large degrees of freedom need no approximation.
#[must_use]
pub fn gamma_q(a: f64, x: f64) -> f64 {
    debug_assert!(a > 0.0, "gamma_q: a = {a} must be positive");
    if x.is_nan() || a.is_nan() {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 1.0;
    }
    if x == f64::INFINITY {
        return 0.0;
    }
    // e^{−x} x^a / Γ(a), the common prefactor.
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    const EPS: f64 = 1e-15;
    const MAX_ITER: usize = 100_000;
    if x < a + 1.0 {
        // P(a, x) = e^{−x} x^a / Γ(a) · Σₙ xⁿ / (a (a+1) … (a+n)).
        let (mut ap, mut term) = (a, 1.0 / a);
        let mut sum = term;
        for _ in 0..MAX_ITER {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * EPS {
                break;
            }
        }
        (1.0 - sum * prefactor).clamp(0.0, 1.0)
    } else {
        // Q(a, x) = e^{−x} x^a / Γ(a) · 1/(x+1−a− 1·(1−a)/(x+3−a− 2·(2−a)/(x+5−a− …))).
        // Lentz's guard against division by zero (2026-11: NR's value, far below any term's magnitude).
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..MAX_ITER {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < EPS {
                break;
            }
        }
        (prefactor * h).clamp(0.0, 1.0)
    }
}

/// The survival function of the χ² law: P(χ²_dof ≥ statistic) = Q(dof/2, statistic/2).
/// With 0 degrees of freedom the law is a point mass at 0.
#[must_use]
pub fn chi2_survival(statistic: f64, dof: usize) -> f64 {
    if statistic.is_nan() {
        return 0.0;
    }
    if dof == 0 {
        return if statistic <= 0.0 { 1.0 } else { 0.0 };
    }
    gamma_q(0.5 * dof as f64, 0.5 * statistic)
}

// ---------------------------------------------------------------------------------------------------
// Pooling and the statistic
// ---------------------------------------------------------------------------------------------------

/// Observed and expected counts of one cell of the test.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Bin {
    observed: f64,
    expected: f64,
}

impl std::ops::AddAssign for Bin {
    fn add_assign(&mut self, o: Bin) {
        self.observed += o.observed;
        self.expected += o.expected;
    }
}

/// Pool cells with expected count below `min_expected` into one cell; if that cell is still below the
/// threshold, merge it into the smallest regular cell. Cells that are empty in both counts are dropped.
/// The result is sorted by expected count (pooled cell wherever it lands).
fn pool(bins: &[Bin], min_expected: f64) -> Vec<Bin> {
    let mut sorted: Vec<Bin> = bins.iter().copied().filter(|b| b.expected > 0.0 || b.observed > 0.0).collect();
    sorted.sort_by(|a, b| a.expected.total_cmp(&b.expected));
    let mut low = Bin::default();
    let mut out = Vec::with_capacity(sorted.len());
    for b in sorted {
        if b.expected < min_expected {
            low += b;
        } else {
            out.push(b);
        }
    }
    if low.expected > 0.0 || low.observed > 0.0 {
        if low.expected >= min_expected || out.is_empty() {
            out.push(low);
        } else {
            // `out` is sorted ascending: its first cell is the smallest regular one.
            out[0] += low;
        }
    }
    out
}

/// Pearson's statistic Σ (O − E)² / E; infinite when a cell expects nothing but holds samples.
fn pearson(bins: &[Bin]) -> f64 {
    bins.iter()
        .map(|b| {
            let d = b.observed - b.expected;
            if b.expected > 0.0 {
                d * d / b.expected
            } else if b.observed > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .sum()
}

// ---------------------------------------------------------------------------------------------------
// The grid and the quadrature
// ---------------------------------------------------------------------------------------------------

/// Gauss–Legendre nodes and weights on [−1, 1]: the n roots of Pₙ by Newton's method from the
/// Tricomi-style initial guess cos(π (i + 3/4) / (n + 1/2)), weights 2 / ((1 − x²) Pₙ′(x)²)
/// (Abramowitz & Stegun 25.4.29).
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let n = n.max(1);
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // Pₙ(x) by the three-term recurrence (k+1) P_{k+1} = (2k+1) x P_k − k P_{k−1}.
            let (mut p0, mut p1) = (1.0, x);
            for k in 1..n {
                let p2 = ((2 * k + 1) as f64 * x * p1 - k as f64 * p0) / (k + 1) as f64;
                p0 = p1;
                p1 = p2;
            }
            let (p, pm1) = if n == 1 { (x, 1.0) } else { (p1, p0) };
            // Pₙ′(x) = n (x Pₙ − Pₙ₋₁) / (x² − 1).
            dp = n as f64 * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    (nodes, weights)
}

/// A rectangle [lo, hi] of a 2-D parameter space cut into `res.0 × res.1` cells, first coordinate major.
/// The sphere is the rectangle (cos θ, φ) ∈ [−1, 1] × [0, 2π), whose area element is dω.
#[derive(Clone, Copy, Debug)]
struct Grid {
    lo: [f64; 2],
    hi: [f64; 2],
    res: (usize, usize),
}

impl Grid {
    fn sphere(cfg: &Chi2Config) -> Grid {
        Grid { lo: [-1.0, 0.0], hi: [1.0, TAU], res: (cfg.theta_res.max(1), cfg.phi_res.max(1)) }
    }

    fn len(&self) -> usize {
        self.res.0 * self.res.1
    }

    /// The cell holding (a, b); `None` outside the rectangle (or NaN). The upper edges belong to the
    /// last cells.
    fn cell(&self, a: f64, b: f64) -> Option<usize> {
        if !(a >= self.lo[0] && a <= self.hi[0] && b >= self.lo[1] && b <= self.hi[1]) {
            return None;
        }
        let i = (((a - self.lo[0]) / (self.hi[0] - self.lo[0]) * self.res.0 as f64) as usize).min(self.res.0 - 1);
        let j = (((b - self.lo[1]) / (self.hi[1] - self.lo[1]) * self.res.1 as f64) as usize).min(self.res.1 - 1);
        Some(i * self.res.1 + j)
    }

    fn describe_cell(&self, index: usize, names: [&str; 2]) -> String {
        let (i, j) = (index / self.res.1, index % self.res.1);
        let da = (self.hi[0] - self.lo[0]) / self.res.0 as f64;
        let db = (self.hi[1] - self.lo[1]) / self.res.1 as f64;
        let (a0, b0) = (self.lo[0] + i as f64 * da, self.lo[1] + j as f64 * db);
        format!("{} ∈ [{:.4}, {:.4}], {} ∈ [{:.4}, {:.4}]", names[0], a0, a0 + da, names[1], b0, b0 + db)
    }
}

// ---------------------------------------------------------------------------------------------------
// Adaptive cell integrals
// ---------------------------------------------------------------------------------------------------

/// Most 4-way splits of a grid cell (2026-11: 2¹⁰ per axis takes a 0.05-wide band of cos θ down to
/// 5·10⁻⁵, a third of the width in cos θ of a Phong lobe of exponent 10⁴ at the pole, and φ cells of
/// 4.5° down to 0.004°, well below an α = 10⁻³ microfacet lobe).
const MAX_DEPTH: u32 = 10;
/// Accept a (sub)cell when the Gauss–Legendre rules of order n and 2n agree to this fraction of its
/// expected count, or to this fraction of a count spread over the cell by area, whichever is larger
/// (2026-11: the cells' errors add up in the "no sample" bin, whose expected count is 0 for a sampler
/// that always succeeds; at 10⁻³ a power-cosine lobe of exponent 10⁴ lost 1.2·10⁻⁴ of its mass there,
/// 122 counts where 0 were expected, and failed. Per cell, Σ δ²/E ≤ 10⁻⁸ N is negligible. `f32` pdfs
/// bound it from below: that lobe evaluated at `f32` directions carries ~10⁻⁴ relative noise per node,
/// ~10⁻⁵ per rule, and at 10⁻⁵ every part of it ran to the depth limit, taking a minute per test).
const QUADRATURE_TOLERANCE: f64 = 1e-4;
/// Where the low rule's parts split a (sub)cell, as a fraction of each side (2026-12-06: any fraction but
/// 1/2, which would keep the comparison symmetric; the pdf of a step at 0.46 is then integrated right).
const UNEQUAL_SPLIT: f64 = 0.4;
/// A cell whose observed count is this many standard deviations √max(E, 1) from its expected count is
/// integrated again, refined to the depth limit along its samples (2026-11: a correct sampler puts a
/// cell beyond 5σ with probability ~6·10⁻⁷, so correct models rarely pay for it).
const GUIDE_SIGMAS: f64 = 5.0;
/// A cell that holds samples but expects fewer than this is integrated again likewise: the pdf may have
/// a lobe that both rules stepped over (2026-11: far below the pooling threshold of 5, so a real empty
/// tail costs a refinement, never a verdict).
const GUIDE_TINY_EXPECTED: f64 = 1e-3;
/// Sample positions kept per cell and chunk of samples, and per cell in all, to guide the refinement
/// (2026-11: a narrow lobe's bulk is found by a few dozen of its samples; the cost of the guided
/// refinement is proportional to this number times the depth).
const GUIDE_POINTS_PER_CHUNK: u8 = 4;
const GUIDE_POINTS: usize = 64;
/// The guide points' bounding box is widened by this multiple of its own extent on every side to give
/// the region whose parts are split while they are larger than it (2026-11: 64 points of a Gaussian
/// lobe span about ±2.4σ, so the region reaches about ±12σ, and 4 points (a single chunk) still about
/// ±5σ; the mass of a 2-D Gaussian beyond is below 10⁻⁶. Without it a roughdielectric Beckmann α = 10⁻³
/// transmission lobe, 4·10⁻⁵ wide in cos θ, lost its 2σ tail across a φ split (1.2·10⁻³ of its mass)
/// into a part whose nodes all lay 10σ from it in cos θ, where both rules agreed on 10⁻¹⁴).
const GUIDE_WIDEN: f64 = 2.0;
/// At most this many cells get the guided refinement, those farthest off first (2026-11: beyond a few
/// dozen cells the sampler, not the quadrature, is wrong; refining thousands of cells of a wrong
/// sampler to the depth limit would take minutes).
const GUIDED_CELLS_MAX: usize = 64;

/// A Gauss–Legendre rule on [−1, 1].
struct Rule {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl Rule {
    fn new(n: usize) -> Rule {
        let (nodes, weights) = gauss_legendre(n);
        Rule { nodes, weights }
    }
}

/// The integral of one (sub)cell and whether it met the tolerance.
#[derive(Clone, Copy, Debug, Default)]
struct CellIntegral {
    value: f64,
    /// Some part reached [`MAX_DEPTH`] with its two rules still disagreeing.
    at_depth_limit: bool,
}

/// A density evaluated at many points at once: `out[k]` = the density at `points[k]`.
type Density<'a> = &'a (dyn Fn(&[(f64, f64)], &mut [f64]) + Sync);

/// A density of one point as a [`Density`].
fn pointwise(density: impl Fn(f64, f64) -> f64 + Sync) -> impl Fn(&[(f64, f64)], &mut [f64]) + Sync {
    move |points, out| {
        for (o, &(a, b)) in out.iter_mut().zip(points) {
            *o = density(a, b);
        }
    }
}

/// Adaptive tensor-product Gauss–Legendre quadrature of a density over rectangles: rule 2n against rule n,
/// on the part and on four unequal parts of it, split into 4 where they disagree, optionally forced down
/// along sample positions.
struct Quadrature<'a> {
    density: Density<'a>,
    low: Rule,
    high: Rule,
    /// N, to turn probabilities into expected counts for the tolerance.
    samples: f64,
}

impl Quadrature<'_> {
    fn rule(&self, rule: &Rule, a: [f64; 2], b: [f64; 2]) -> f64 {
        let (ha, hb) = (0.5 * (a[1] - a[0]), 0.5 * (b[1] - b[0]));
        // Every node's density in one call (the model's batches), then the sum in the nodes' order.
        let points: Vec<(f64, f64)> =
            rule.nodes.iter().flat_map(|xa| rule.nodes.iter().map(move |xb| (a[0] + ha * (xa + 1.0), b[0] + hb * (xb + 1.0)))).collect();
        let mut values = vec![0.0; points.len()];
        (self.density)(&points, &mut values);
        let mut sum = 0.0;
        let mut value = values.iter();
        for wa in &rule.weights {
            for wb in &rule.weights {
                sum += wa * wb * value.next().expect("a value per node");
            }
        }
        sum * ha * hb
    }

    /// ∫ over [a₀, a₁] × [b₀, b₁] at `depth` splits below a grid cell. While `guide` holds sample
    /// positions inside the rectangle, it is split regardless of the rules' agreement, down to the limit;
    /// so is a part that overlaps `focus` (the region around the cell's guide points, see
    /// [`GUIDE_WIDEN`]) while it is wider than `focus` along either axis: the lobe the samples came from
    /// may be narrower than the spacing of both rules' nodes along one axis, and its tails then lie in
    /// parts without samples where both rules see nothing and agree.
    fn integrate(&self, a: [f64; 2], b: [f64; 2], depth: u32, guide: &[(f64, f64)], focus: Option<&Focus>) -> CellIntegral {
        let coarse = self.rule(&self.low, a, b);
        let fine = self.rule(&self.high, a, b);
        if !fine.is_finite() || !coarse.is_finite() {
            // NaN or Inf: refining cannot help; the verdict reports the cell.
            return CellIntegral { value: coarse + fine, at_depth_limit: false };
        }
        // Tolerance in probability: a fraction of this part's own expected count, with a floor of
        // QUADRATURE_TOLERANCE counts shared among the parts of a cell by area.
        let floor = 0.25f64.powi(depth as i32) / self.samples;
        let tolerance = QUADRATURE_TOLERANCE * fine.abs().max(floor);
        // Where the two rules agree, the low rule on four unequal parts too: not symmetric about the
        // centre as both rules are.
        let converged = (fine - coarse).abs() <= tolerance && {
            let (sa, sb) = (a[0] + UNEQUAL_SPLIT * (a[1] - a[0]), b[0] + UNEQUAL_SPLIT * (b[1] - b[0]));
            let unequal = [([a[0], sa], [b[0], sb]), ([a[0], sa], [sb, b[1]]), ([sa, a[1]], [b[0], sb]), ([sa, a[1]], [sb, b[1]])]
                .iter()
                .map(|&(qa, qb)| self.rule(&self.low, qa, qb))
                .sum::<f64>();
            (fine - unequal).abs() <= tolerance
        };
        if depth >= MAX_DEPTH {
            return CellIntegral { value: fine, at_depth_limit: !converged };
        }
        let unresolved = focus.is_some_and(|f| f.overlaps(a, b) && (a[1] - a[0] > f.a[1] - f.a[0] || b[1] - b[0] > f.b[1] - f.b[0]));
        if converged && guide.is_empty() && !unresolved {
            return CellIntegral { value: fine, at_depth_limit: false };
        }
        let (am, bm) = (0.5 * (a[0] + a[1]), 0.5 * (b[0] + b[1]));
        let mut total = CellIntegral::default();
        for (qa, qb) in [([a[0], am], [b[0], bm]), ([a[0], am], [bm, b[1]]), ([am, a[1]], [b[0], bm]), ([am, a[1]], [bm, b[1]])] {
            // A point on a split line goes to the upper part, as in `Grid::cell`.
            let inside: Vec<(f64, f64)> = guide
                .iter()
                .copied()
                .filter(|&(u, v)| {
                    (u >= qa[0] || qa[0] == a[0])
                        && (u < qa[1] || qa[1] == a[1])
                        && (v >= qb[0] || qb[0] == b[0])
                        && (v < qb[1] || qb[1] == b[1])
                })
                .collect();
            let part = self.integrate(qa, qb, depth + 1, &inside, focus);
            total.value += part.value;
            total.at_depth_limit |= part.at_depth_limit;
        }
        total
    }
}

/// The region around a cell's guide points that the guided refinement resolves (see [`GUIDE_WIDEN`]).
#[derive(Clone, Copy, Debug)]
struct Focus {
    a: [f64; 2],
    b: [f64; 2],
}

impl Focus {
    /// The bounding box of `points`, widened by [`GUIDE_WIDEN`] times its extent on every side; `None`
    /// without points.
    fn around(points: &[(f64, f64)]) -> Option<Focus> {
        let first = points.first()?;
        let (mut a, mut b) = ([first.0, first.0], [first.1, first.1]);
        for &(u, v) in points {
            a = [a[0].min(u), a[1].max(u)];
            b = [b[0].min(v), b[1].max(v)];
        }
        let (da, db) = (GUIDE_WIDEN * (a[1] - a[0]), GUIDE_WIDEN * (b[1] - b[0]));
        Some(Focus { a: [a[0] - da, a[1] + da], b: [b[0] - db, b[1] + db] })
    }

    fn overlaps(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        a[0] <= self.a[1] && a[1] >= self.a[0] && b[0] <= self.b[1] && b[1] >= self.b[0]
    }
}

/// The cell integrals of the pdf, and what the quadrature has to say about them.
struct CellIntegrals {
    values: Vec<f64>,
    /// Notes for the result's message (cells at the depth limit, cells left unguided).
    notes: Vec<String>,
}

impl Grid {
    fn bounds(&self, index: usize) -> ([f64; 2], [f64; 2]) {
        let (i, j) = (index / self.res.1, index % self.res.1);
        let da = (self.hi[0] - self.lo[0]) / self.res.0 as f64;
        let db = (self.hi[1] - self.lo[1]) / self.res.1 as f64;
        let (a0, b0) = (self.lo[0] + i as f64 * da, self.lo[1] + j as f64 * db);
        // The last cells end exactly on the domain's upper edges.
        let a1 = if i + 1 == self.res.0 { self.hi[0] } else { a0 + da };
        let b1 = if j + 1 == self.res.1 { self.hi[1] } else { b0 + db };
        ([a0, a1], [b0, b1])
    }

    /// ∫ density over each cell, in `f64`, cells in parallel: adaptively (see the module docs), then
    /// again along the samples of cells whose observed count contradicts the first answer.
    fn integrate(&self, density: Density<'_>, n: usize, tally: &Tally, samples: usize, names: [&str; 2]) -> CellIntegrals {
        let n = n.max(1);
        let quad = Quadrature { density, low: Rule::new(n), high: Rule::new(2 * n), samples: samples.max(1) as f64 };
        let mut cells: Vec<CellIntegral> = (0..self.len())
            .into_par_iter()
            .map(|k| {
                let (a, b) = self.bounds(k);
                quad.integrate(a, b, 0, &[], None)
            })
            .collect();

        // Cells the samples contradict, farthest off first.
        let n_samples = samples as f64;
        let mut suspect: Vec<(f64, usize)> = (0..self.len())
            .filter_map(|k| {
                let (o, e) = (tally.cells[k] as f64, n_samples * cells[k].value);
                let z2 = (o - e) * (o - e) / e.max(1.0);
                let contradicted = (o > 0.0 && e < GUIDE_TINY_EXPECTED) || z2 > GUIDE_SIGMAS * GUIDE_SIGMAS;
                (contradicted && e.is_finite()).then_some((z2, k))
            })
            .collect();
        suspect.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let mut notes = Vec::new();
        if suspect.len() > GUIDED_CELLS_MAX {
            notes.push(format!(
                "{} cells contradict their expected counts; only the {GUIDED_CELLS_MAX} farthest off were refined along their samples",
                suspect.len()
            ));
            suspect.truncate(GUIDED_CELLS_MAX);
        }
        let guided: Vec<(usize, CellIntegral)> = suspect
            .par_iter()
            .map(|&(_, k)| {
                let guide: Vec<(f64, f64)> =
                    tally.points.iter().filter(|p| p.0 as usize == k).map(|p| (p.1, p.2)).take(GUIDE_POINTS).collect();
                let (a, b) = self.bounds(k);
                (k, quad.integrate(a, b, 0, &guide, Focus::around(&guide).as_ref()))
            })
            .collect();
        for (k, c) in guided {
            cells[k] = c;
        }

        let limited: Vec<usize> = (0..self.len()).filter(|k| cells[*k].at_depth_limit).collect();
        if let Some(first) = limited.first() {
            notes.push(format!(
                "the quadrature did not converge to {QUADRATURE_TOLERANCE} relative within {MAX_DEPTH} splits in {} cells (first: {})",
                limited.len(),
                self.describe_cell(*first, names)
            ));
        }
        CellIntegrals { values: cells.iter().map(|c| c.value).collect(), notes }
    }
}

/// (cos θ, φ ∈ [0, 2π)) of a direction, in `f64`.
#[inline]
fn sphere_coords(w: Vec3) -> (f64, f64) {
    let phi = f64::from(w.y).atan2(f64::from(w.x));
    (f64::from(w.z).clamp(-1.0, 1.0), if phi < 0.0 { phi + TAU } else { phi })
}

/// The unit direction with cos θ = c and azimuth φ.
#[inline]
fn sphere_direction(c: f64, phi: f64) -> Vec3 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32)
}

// ---------------------------------------------------------------------------------------------------
// Drawing samples
// ---------------------------------------------------------------------------------------------------

/// Samples of one delta lobe.
#[derive(Clone, Copy, Debug)]
struct DeltaTally {
    wi: Vec3,
    count: u64,
    pdf_min: f32,
    pdf_max: f32,
}

/// Counts of one chunk of samples (and, merged, of all of them).
#[derive(Clone, Debug, Default)]
struct Tally {
    cells: Vec<u64>,
    /// `None` samples and samples outside the domain.
    no_sample: u64,
    outside: u64,
    deltas: BTreeMap<[i64; 3], DeltaTally>,
    invalid: u64,
    first_invalid: Option<String>,
    pdf_mismatches: u64,
    first_mismatch: Option<String>,
    /// (cell, a, b) of the first few samples of each cell in each chunk, to guide the quadrature.
    points: Vec<(u32, f64, f64)>,
    /// Points kept per cell in this chunk.
    kept: Vec<u8>,
}

impl Tally {
    fn new(cells: usize) -> Tally {
        Tally { cells: vec![0; cells], kept: vec![0; cells], ..Tally::default() }
    }

    /// Count a sample at (a, b) in cell `i`.
    #[inline]
    fn count(&mut self, i: usize, a: f64, b: f64) {
        self.cells[i] += 1;
        if self.kept[i] < GUIDE_POINTS_PER_CHUNK {
            self.kept[i] += 1;
            self.points.push((i as u32, a, b));
        }
    }

    fn invalid(&mut self, why: String) {
        self.invalid += 1;
        self.first_invalid.get_or_insert(why);
    }

    fn mismatch(&mut self, why: String) {
        self.pdf_mismatches += 1;
        self.first_mismatch.get_or_insert(why);
    }

    fn delta(&mut self, wi: Vec3, pdf: f32) {
        let q = (wi / DELTA_QUANTUM).round();
        let key = [q.x as i64, q.y as i64, q.z as i64];
        let e = self.deltas.entry(key).or_insert(DeltaTally { wi, count: 0, pdf_min: pdf, pdf_max: pdf });
        e.count += 1;
        e.pdf_min = e.pdf_min.min(pdf);
        e.pdf_max = e.pdf_max.max(pdf);
    }

    /// Merge `o` (a later chunk) into `self`, keeping the earliest diagnostic messages.
    fn merge(mut self, o: Tally) -> Tally {
        if self.cells.is_empty() {
            return o;
        }
        for (a, b) in self.cells.iter_mut().zip(&o.cells) {
            *a += b;
        }
        self.no_sample += o.no_sample;
        self.outside += o.outside;
        for (k, d) in o.deltas {
            self.deltas
                .entry(k)
                .and_modify(|e| {
                    e.count += d.count;
                    e.pdf_min = e.pdf_min.min(d.pdf_min);
                    e.pdf_max = e.pdf_max.max(d.pdf_max);
                })
                .or_insert(d);
        }
        self.invalid += o.invalid;
        if self.first_invalid.is_none() {
            self.first_invalid = o.first_invalid;
        }
        self.pdf_mismatches += o.pdf_mismatches;
        if self.first_mismatch.is_none() {
            self.first_mismatch = o.first_mismatch;
        }
        self.points.extend(o.points);
        self
    }
}

/// Draw `cfg.samples` samples in parallel chunks, each chunk on its own PCG32 stream, and count them.
fn draw(cfg: &Chi2Config, cells: usize, one: &(dyn Fn(&mut Pcg32, &mut Tally) + Sync)) -> Tally {
    draw_chunks(cfg, cells, &|rng, n, t| {
        for _ in 0..n {
            one(rng, t);
        }
    })
}

/// [`draw`] with a function that draws and counts `n` samples at once (from `rng`, in order).
fn draw_chunks(cfg: &Chi2Config, cells: usize, chunk: &(dyn Fn(&mut Pcg32, usize, &mut Tally) + Sync)) -> Tally {
    let chunks = cfg.samples.div_ceil(CHUNK);
    (0..chunks)
        .into_par_iter()
        .map(|k| {
            let mut rng = Pcg32::new(cfg.seed, k as u64);
            let mut t = Tally::new(cells);
            chunk(&mut rng, CHUNK.min(cfg.samples - k * CHUNK), &mut t);
            t
        })
        .reduce(|| Tally::new(0), Tally::merge)
}

/// Count a direction into the sphere grid, or record why it is not a valid direction.
#[inline]
fn count_direction(grid: &Grid, wi: Vec3, t: &mut Tally) {
    if !wi.is_finite() || (wi.length() - 1.0).abs() > UNIT_TOLERANCE {
        t.invalid(format!("wi = {wi} is not a unit direction"));
        return;
    }
    let (c, phi) = sphere_coords(wi);
    match grid.cell(c, phi) {
        Some(i) => t.count(i, c, phi),
        None => t.outside += 1,
    }
}

// ---------------------------------------------------------------------------------------------------
// The verdict
// ---------------------------------------------------------------------------------------------------

/// Turn counts and cell integrals of the pdf into the test's result.
fn verdict(tally: Tally, grid: &Grid, integrals: CellIntegrals, cfg: &Chi2Config, names: [&str; 2], domain: String) -> Chi2Result {
    let CellIntegrals { values: integrals, notes } = integrals;
    let n = cfg.samples as f64;
    let alpha = cfg.alpha();
    let mut problems: Vec<String> = Vec::new();

    let observed: Vec<f64> = tally.cells.iter().map(|c| *c as f64).collect();
    let expected: Vec<f64> = integrals.iter().map(|p| n * p).collect();
    let integral: f64 = integrals.iter().sum();

    // Delta lobes: expected N × the lobe's discrete probability; all its samples must agree on it.
    let mut delta_bins = Vec::with_capacity(tally.deltas.len());
    let mut delta_total = 0.0;
    for d in tally.deltas.values() {
        if d.pdf_max - d.pdf_min > DELTA_PDF_TOLERANCE * d.pdf_max {
            problems
                .push(format!("samples of the delta lobe towards {} report different probabilities {} .. {}", d.wi, d.pdf_min, d.pdf_max));
        }
        let p = f64::from(d.pdf_max);
        delta_total += p;
        delta_bins.push(DeltaBin { wi: d.wi, observed: d.count as f64, expected: n * p });
    }

    if tally.invalid > 0 {
        problems.push(format!("{} invalid samples (first: {})", tally.invalid, tally.first_invalid.as_deref().unwrap_or("?")));
    }
    if tally.pdf_mismatches > 0 {
        problems.push(format!(
            "{} samples report a pdf that differs from pdf(wo, wi) by more than {} relative (first: {})",
            tally.pdf_mismatches,
            PDF_TOLERANCE,
            tally.first_mismatch.as_deref().unwrap_or("?")
        ));
    }

    // The probability not accounted for by the pdf and the delta lobes belongs to "no sample".
    let rest = 1.0 - integral - delta_total;
    if rest < -EXCESS_TOLERANCE {
        problems
            .push(format!("the pdf integrates to {integral:.6} and the delta probabilities sum to {delta_total:.6}: together more than 1"));
    }
    let no_sample_observed = (tally.no_sample + tally.outside) as f64;
    let no_sample_expected = n * rest.max(0.0);

    // Samples where the pdf is zero: fail at once, naming the first such cell.
    let bad_pdf: Vec<usize> = (0..expected.len()).filter(|i| !expected[*i].is_finite() || expected[*i] < 0.0).collect();
    if let Some(first) = bad_pdf.first() {
        problems.push(format!(
            "the pdf is negative or not finite in {} cells (first: {})",
            bad_pdf.len(),
            grid.describe_cell(*first, names)
        ));
    }
    let zero_cells: Vec<usize> = (0..observed.len()).filter(|i| observed[*i] > 0.0 && expected[*i] == 0.0).collect();
    if let Some(first) = zero_cells.first() {
        let count: f64 = zero_cells.iter().map(|i| observed[*i]).sum();
        problems.push(format!(
            "{count} samples landed in {} cells where the pdf is 0 (first: {})",
            zero_cells.len(),
            grid.describe_cell(*first, names)
        ));
    }

    let tested = tally.invalid + tally.pdf_mismatches;
    let produced_nothing = tally.no_sample as usize == cfg.samples && tested == 0;
    if produced_nothing && integral <= 0.0 && delta_bins.is_empty() {
        return Chi2Result {
            statistic: 0.0,
            dof: 0,
            p_value: 1.0,
            alpha,
            passed: true,
            message: "no scattering from this wo".into(),
            observed,
            expected,
            res: grid.res,
            delta_bins,
            no_sample_observed,
            no_sample_expected,
            pdf_mismatches: 0,
            domain,
        };
    }

    let bins: Vec<Bin> = observed
        .iter()
        .zip(&expected)
        .map(|(o, e)| Bin { observed: *o, expected: *e })
        .chain(delta_bins.iter().map(|d| Bin { observed: d.observed, expected: d.expected }))
        .chain(std::iter::once(Bin { observed: no_sample_observed, expected: no_sample_expected }))
        .collect();
    let pooled = pool(&bins, MIN_EXPECTED);
    let statistic = pearson(&pooled);
    let dof = pooled.len().saturating_sub(1);
    let p_value = chi2_survival(statistic, dof);
    let passed = problems.is_empty() && p_value >= alpha;
    if !passed && problems.is_empty() {
        problems.push(format!("p-value {p_value:.3e} is below the threshold {alpha:.3e}"));
        // Point at the no-sample bin when it is the obvious culprit.
        let d = no_sample_observed - no_sample_expected;
        if d * d > 25.0 * no_sample_expected.max(1.0) {
            problems.push(format!("{no_sample_observed} samples were not produced or left the domain, {no_sample_expected:.1} expected"));
        }
    }
    // The quadrature's notes come last; they inform, the verdict is the statistic's.
    problems.extend(notes);
    Chi2Result {
        statistic,
        dof,
        p_value,
        alpha,
        passed,
        message: problems.join("; "),
        observed,
        expected,
        res: grid.res,
        delta_bins,
        no_sample_observed,
        no_sample_expected,
        pdf_mismatches: tally.pdf_mismatches as usize,
        domain,
    }
}

fn sphere_domain(grid: &Grid) -> String {
    format!("sphere: rows = {} bins of cos θ over [-1, 1], columns = {} bins of φ over [0, 2π)", grid.res.0, grid.res.1)
}

// ---------------------------------------------------------------------------------------------------
// The three entry points
// ---------------------------------------------------------------------------------------------------

/// Chi-square test of `bsdf.sample(wo, ·, ·)` against `bsdf.pdf(wo, ·)` over the sphere of `wi`, with
/// delta lobes in bins of their own and `None` samples in a "no sample" bin (see the module docs).
///
/// Also fails when a sample has a non-finite or non-positive pdf, a `wi` that is not unit length, or
/// (for smooth lobes) a reported pdf that differs from `bsdf.pdf(wo, wi)` by more than 10⁻³ relative.
/// A `wo` from which the model never scatters and whose pdf is zero everywhere passes with the note
/// "no scattering from this wo".
#[must_use]
pub fn chi2_bsdf<M: BsdfModel + Sync + ?Sized>(bsdf: &M, wo: Vec3, cfg: &Chi2Config) -> Chi2Result {
    let grid = Grid::sphere(cfg);
    let chunk = |rng: &mut Pcg32, n: usize, t: &mut Tally| {
        let (mut wi, mut pdf, wos) = (Vec::new(), Vec::new(), vec![wo; super::SAMPLE_BATCH]);
        let draw = |_| {
            let uc = rng.next_f32();
            (uc, rng.next_vec2())
        };
        super::sample_batches(bsdf, wo, n, draw, |rows, m| {
            // The model's own pdf at every smooth sample's direction, in one batch too.
            let smooth = |r: usize| rows.valid[r] && rows.pdf[r] > 0.0 && rows.pdf[r].is_finite() && !BsdfFlags(rows.flags[r]).has_delta();
            wi.clear();
            wi.extend((0..m).filter(|&r| smooth(r)).map(|r| rows.wi[r]));
            pdf.resize(wi.len(), 0.0);
            bsdf.pdf_batch(&wos[..wi.len()], &wi, &mut pdf);
            let mut pdfs = pdf.iter();
            for r in 0..m {
                let (s_wi, s_pdf) = (rows.wi[r], rows.pdf[r]);
                if !rows.valid[r] {
                    t.no_sample += 1;
                } else if s_pdf <= 0.0 || !s_pdf.is_finite() {
                    t.invalid(format!("pdf = {s_pdf} for wi = {s_wi}"));
                } else if BsdfFlags(rows.flags[r]).has_delta() {
                    if !s_wi.is_finite() || (s_wi.length() - 1.0).abs() > UNIT_TOLERANCE {
                        t.invalid(format!("delta wi = {s_wi} is not a unit direction"));
                    } else {
                        t.delta(s_wi, s_pdf);
                    }
                } else {
                    let pdf = *pdfs.next().expect("a pdf per smooth sample");
                    if (pdf - s_pdf).abs() > PDF_TOLERANCE * s_pdf {
                        t.mismatch(format!("wi = {s_wi}: sample says {s_pdf}, pdf says {pdf}"));
                    }
                    count_direction(&grid, s_wi, t);
                }
            }
        });
    };
    let tally = draw_chunks(cfg, grid.len(), &chunk);
    let density = |points: &[(f64, f64)], out: &mut [f64]| {
        let wi: Vec<Vec3> = points.iter().map(|&(c, phi)| sphere_direction(c, phi)).collect();
        let mut pdf = vec![0.0; wi.len()];
        bsdf.pdf_batch(&vec![wo; wi.len()], &wi, &mut pdf);
        for (o, p) in out.iter_mut().zip(pdf) {
            *o = f64::from(p);
        }
    };
    let integrals = grid.integrate(&density, cfg.integration_res, &tally, cfg.samples, ["cos θ", "φ"]);
    verdict(tally, &grid, integrals, cfg, ["cos θ", "φ"], sphere_domain(&grid))
}

/// Chi-square test of a warp from the unit square to the sphere of directions against its density
/// (solid angle), e.g. `sample_cosine_hemisphere` with `cosine_hemisphere_pdf`.
#[must_use]
pub fn chi2_warp(sample: impl Fn(Vec2) -> Vec3 + Sync, pdf: impl Fn(Vec3) -> f64 + Sync, cfg: &Chi2Config) -> Chi2Result {
    let grid = Grid::sphere(cfg);
    let one = |rng: &mut Pcg32, t: &mut Tally| count_direction(&grid, sample(rng.next_vec2()), t);
    let tally = draw(cfg, grid.len(), &one);
    let density = pointwise(|c: f64, phi: f64| pdf(sphere_direction(c, phi)));
    let integrals = grid.integrate(&density, cfg.integration_res, &tally, cfg.samples, ["cos θ", "φ"]);
    verdict(tally, &grid, integrals, cfg, ["cos θ", "φ"], sphere_domain(&grid))
}

/// Chi-square test of a warp from the unit square to the plane against its density (area), over the
/// rectangle [lo, hi] cut into `res.0` cells along x by `res.1` along y (rows are x bins). Samples
/// outside the rectangle count as "no sample".
///
/// The pdf should be smooth inside each cell: align the grid with the steps of a piecewise-constant
/// density, or raise `cfg.integration_res` where an edge (a disk's rim) cuts cells.
#[must_use]
pub fn chi2_plane(
    sample: impl Fn(Vec2) -> Vec2 + Sync,
    pdf: impl Fn(Vec2) -> f64 + Sync,
    lo: Vec2,
    hi: Vec2,
    res: (usize, usize),
    cfg: &Chi2Config,
) -> Chi2Result {
    let grid = Grid { lo: [f64::from(lo.x), f64::from(lo.y)], hi: [f64::from(hi.x), f64::from(hi.y)], res: (res.0.max(1), res.1.max(1)) };
    let one = |rng: &mut Pcg32, t: &mut Tally| {
        let p = sample(rng.next_vec2());
        if !p.is_finite() {
            t.invalid(format!("sample {p} is not finite"));
            return;
        }
        let (x, y) = (f64::from(p.x), f64::from(p.y));
        match grid.cell(x, y) {
            Some(i) => t.count(i, x, y),
            None => t.outside += 1,
        }
    };
    let tally = draw(cfg, grid.len(), &one);
    let density = pointwise(|x: f64, y: f64| pdf(Vec2::new(x as f32, y as f32)));
    let integrals = grid.integrate(&density, cfg.integration_res, &tally, cfg.samples, ["x", "y"]);
    let domain = format!(
        "plane: rows = {} bins of x over [{}, {}], columns = {} bins of y over [{}, {}]",
        grid.res.0, lo.x, hi.x, grid.res.1, lo.y, hi.y
    );
    verdict(tally, &grid, integrals, cfg, ["x", "y"], domain)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;
    use crate::sampling::warp::{cosine_hemisphere_pdf, sample_uniform_hemisphere};
    use std::time::Instant;

    /// The test written one `sample` and one `pdf` call at a time (the draw and the quadrature), as
    /// `chi2_bsdf` was before it took the model's batches: the batched test must give the same result,
    /// field for field (same random numbers in the same order, the same counts, points and cell
    /// integrals), for smooth, delta and mixed models, a model
    /// that rejects samples, and a sample count that ends on a partial batch.
    #[test]
    fn batched_bsdf_test_is_the_single_call_test() {
        let single = |bsdf: &Bsdf, wo: Vec3, cfg: &Chi2Config| {
            let grid = Grid::sphere(cfg);
            let one = |rng: &mut Pcg32, t: &mut Tally| {
                let uc = rng.next_f32();
                let u = rng.next_vec2();
                let Some(s) = bsdf.sample(wo, uc, u) else {
                    t.no_sample += 1;
                    return;
                };
                if s.pdf <= 0.0 || !s.pdf.is_finite() {
                    t.invalid(format!("pdf = {} for wi = {}", s.pdf, s.wi));
                } else if s.flags.has_delta() {
                    t.delta(s.wi, s.pdf);
                } else {
                    let pdf = bsdf.pdf(wo, s.wi);
                    if (pdf - s.pdf).abs() > PDF_TOLERANCE * s.pdf {
                        t.mismatch(format!("wi = {}: sample says {}, pdf says {}", s.wi, s.pdf, pdf));
                    }
                    count_direction(&grid, s.wi, t);
                }
            };
            let tally = draw(cfg, grid.len(), &one);
            let density = pointwise(|c: f64, phi: f64| f64::from(bsdf.pdf(wo, sphere_direction(c, phi))));
            let integrals = grid.integrate(&density, cfg.integration_res, &tally, cfg.samples, ["cos θ", "φ"]);
            verdict(tally, &grid, integrals, cfg, ["cos θ", "φ"], sphere_domain(&grid))
        };
        let cfg = Chi2Config { samples: 3 * CHUNK + 1000, theta_res: 10, phi_res: 20, ..Chi2Config::default() };
        for spec in [
            r#"{"type": "roughconductor", "alpha_u": 0.05, "alpha_v": 0.3}"#,
            r#"{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.2}"#,
            r#"{"type": "blendbsdf", "weight": 0.4, "a": {"type": "diffuse"}, "b": {"type": "dielectric"}}"#,
            r#"{"type": "diffuse"}"#,
        ] {
            let b = Bsdf::from_json(spec).unwrap();
            for wo in [Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.6, -0.8)] {
                assert_eq!(chi2_bsdf(&b, wo, &cfg), single(&b, wo, &cfg), "{spec} from {wo}");
            }
        }
    }

    /// P(χ²_{2k} ≥ x) = e^{−x/2} Σ_{i<k} (x/2)^i / i!, the Poisson tail: exact for even dof, in logs.
    fn survival_even_dof(x: f64, dof: usize) -> f64 {
        let (h, k) = (0.5 * x, dof / 2);
        let mut log_term = -h; // i = 0
        let mut sum = 0.0;
        for i in 0..k {
            if i > 0 {
                log_term += h.ln() - (i as f64).ln();
            }
            sum += log_term.exp();
        }
        sum
    }

    #[test]
    fn survival_matches_tables() {
        // Upper 5 % points of χ² (Abramowitz & Stegun Table 26.8).
        for (x, dof) in [(3.841_459, 1), (5.991_465, 2), (18.307_04, 10), (124.342_1, 100)] {
            let p = chi2_survival(x, dof);
            assert!((p - 0.05).abs() < 1e-5, "dof {dof}: {p}");
        }
        assert!((chi2_survival(6.634_897, 1) - 0.01).abs() < 1e-6);
        assert_eq!(chi2_survival(0.0, 3), 1.0);
        assert_eq!(chi2_survival(0.0, 0), 1.0);
        assert_eq!(chi2_survival(1.0, 0), 0.0);
        assert_eq!(chi2_survival(f64::NAN, 4), 0.0);
        assert_eq!(chi2_survival(f64::INFINITY, 4), 0.0);
    }

    #[test]
    fn survival_large_dof_matches_exact_even_formula() {
        for dof in [2, 10, 100, 1000, 5000] {
            let d = dof as f64;
            for x in [0.5 * d, 0.9 * d, d - 1.0, d, d + 2.0, d + 3.0 * (2.0 * d).sqrt(), 1.5 * d] {
                let (p, exact) = (chi2_survival(x, dof), survival_even_dof(x, dof));
                assert!((p - exact).abs() < 1e-9 + 1e-7 * exact, "dof {dof}, x {x}: {p} vs {exact}");
            }
        }
        // Tail far out is still relative-accurate through the continued fraction.
        let (p, exact) = (chi2_survival(7000.0, 5000), survival_even_dof(7000.0, 5000));
        assert!(exact > 0.0 && ((p - exact) / exact).abs() < 1e-6, "{p} vs {exact}");
    }

    #[test]
    fn ln_gamma_values() {
        assert!(ln_gamma(1.0).abs() < 1e-14);
        assert!((ln_gamma(0.5) - PI.sqrt().ln()).abs() < 1e-14);
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(2500.0) - (1..2500).map(|i| (i as f64).ln()).sum::<f64>()).abs() < 1e-8);
    }

    #[test]
    fn gauss_legendre_is_exact_for_polynomials() {
        for n in 1..10 {
            let (x, w) = gauss_legendre(n);
            // Exact up to degree 2n − 1: ∫_{−1}^{1} t^k dt = 2/(k+1) for even k, 0 for odd.
            for k in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                let exact = if k % 2 == 0 { 2.0 / (k + 1) as f64 } else { 0.0 };
                assert!((q - exact).abs() < 1e-13, "n {n}, k {k}: {q}");
            }
        }
    }

    #[test]
    fn sidak_threshold() {
        assert!((sidak_alpha(0.01, 1) - 0.01).abs() < 1e-15);
        let a = sidak_alpha(0.01, 10);
        assert!((1.0 - (1.0 - a).powi(10) - 0.01).abs() < 1e-14);
        // Slightly above Bonferroni's α/m.
        assert!(a > 0.01 / 10.0 && a < 0.01 / 10.0 * 1.01);
        let cfg = Chi2Config { tests: 100, ..Chi2Config::default() };
        assert!((cfg.alpha() - sidak_alpha(0.01, 100)).abs() < 1e-18);
    }

    #[test]
    fn pooling_merges_small_cells() {
        let b = |observed: f64, expected: f64| Bin { observed, expected };
        // Small cells pool into one regular cell; empty cells vanish.
        let p = pool(&[b(10.0, 12.0), b(1.0, 2.0), b(0.0, 0.0), b(3.0, 4.0), b(9.0, 8.0)], 5.0);
        assert_eq!(p, vec![b(9.0, 8.0), b(10.0, 12.0), b(4.0, 6.0)]);
        // A pool still below 5 joins the smallest regular cell.
        let p = pool(&[b(10.0, 12.0), b(1.0, 2.0), b(20.0, 20.0)], 5.0);
        assert_eq!(p, vec![b(11.0, 14.0), b(20.0, 20.0)]);
        // Only small cells: one cell.
        let p = pool(&[b(1.0, 1.0), b(2.0, 2.0)], 5.0);
        assert_eq!(p, vec![b(3.0, 3.0)]);
        // An observed-only cell is kept (through the pool) so that the statistic sees it.
        let p = pool(&[b(3.0, 0.0), b(10.0, 10.0)], 5.0);
        assert_eq!(p, vec![b(13.0, 10.0)]);
        assert_eq!(pearson(&[b(1.0, 0.0)]), f64::INFINITY);
        assert!((pearson(&[b(12.0, 10.0), b(8.0, 10.0)]) - 0.8).abs() < 1e-12);
    }

    #[test]
    fn diffuse_passes() {
        let bsdf = Bsdf::from_json(r#"{"type":"diffuse"}"#).unwrap();
        let cfg = Chi2Config { tests: 4, ..Chi2Config::default() };
        for (k, cos_theta_o) in [1.0f32, 0.7, 0.2, 0.05].into_iter().enumerate() {
            let wo = Vec3::new((1.0 - cos_theta_o * cos_theta_o).sqrt(), 0.0, cos_theta_o);
            let start = Instant::now();
            let r = chi2_bsdf(&bsdf, wo, &Chi2Config { seed: k as u64, ..cfg.clone() });
            eprintln!("diffuse cosθo = {cos_theta_o}: {r} [{:?}]", start.elapsed());
            assert!(r.passed, "{r}");
            assert!(r.dof > 1000);
            assert_eq!(r.pdf_mismatches, 0);
        }
    }

    #[test]
    fn one_sided_from_below_scatters_nothing() {
        let bsdf = Bsdf::from_json(r#"{"type":"diffuse"}"#).unwrap();
        let cfg = Chi2Config { samples: 10_000, ..Chi2Config::default() };
        let r = chi2_bsdf(&bsdf, Vec3::new(0.0, 0.6, -0.8), &cfg);
        assert!(r.passed, "{r}");
        assert_eq!(r.message, "no scattering from this wo");
    }

    #[test]
    fn wrong_sampler_fails() {
        let start = Instant::now();
        let r = chi2_warp(sample_uniform_hemisphere, |w| f64::from(cosine_hemisphere_pdf(w)), &Chi2Config::default());
        eprintln!("uniform samples vs cosine pdf: {r} [{:?}]", start.elapsed());
        assert!(!r.passed);
        assert!(r.p_value < 1e-12 * r.alpha, "{r}");
    }

    #[test]
    fn samples_where_pdf_is_zero_fail_with_a_message() {
        // Uniform sphere samples against a hemisphere density: half the samples land where pdf = 0.
        let cfg = Chi2Config { samples: 100_000, ..Chi2Config::default() };
        let r = chi2_warp(crate::sampling::warp::sample_uniform_sphere, |w| f64::from(cosine_hemisphere_pdf(w)), &cfg);
        assert!(!r.passed);
        assert!(r.message.contains("where the pdf is 0"), "{r}");
    }

    #[test]
    fn bad_pdfs_fail_with_a_message() {
        let cfg = Chi2Config { samples: 100_000, ..Chi2Config::default() };
        let sample = crate::sampling::warp::sample_cosine_hemisphere;
        // A density that integrates to 2.
        let r = chi2_warp(sample, |w| 2.0 * f64::from(cosine_hemisphere_pdf(w)), &cfg);
        assert!(!r.passed && r.message.contains("more than 1"), "{r}");
        // A density that integrates to 1/2: the missing half is expected in the no-sample bin.
        let r = chi2_warp(sample, |w| 0.5 * f64::from(cosine_hemisphere_pdf(w)), &cfg);
        assert!(!r.passed && r.message.contains("not produced"), "{r}");
        assert!((r.no_sample_expected - 0.5 * cfg.samples as f64).abs() < 1.0);
        // NaN somewhere.
        let r = chi2_warp(sample, |w| if w.x > 0.5 { f64::NAN } else { f64::from(cosine_hemisphere_pdf(w)) }, &cfg);
        assert!(!r.passed && r.message.contains("not finite"), "{r}");
    }

    #[test]
    fn dielectric_delta_bins() {
        let bsdf = Bsdf::from_json(r#"{"type":"dielectric","int_ior":1.5}"#).unwrap();
        let cfg = Chi2Config { tests: 4, ..Chi2Config::default() };
        // From above, from below, and from below beyond the critical angle (total internal reflection).
        for (wo, lobes) in [
            (Vec3::new(0.6, 0.0, 0.8), 2),
            (Vec3::new(0.0, 0.28, 0.96), 2),
            (Vec3::new(0.3, 0.0, -(1.0f32 - 0.09).sqrt()), 2),
            (Vec3::new(0.8, 0.0, -0.6), 1),
        ] {
            let start = Instant::now();
            let r = chi2_bsdf(&bsdf, wo, &cfg);
            eprintln!("dielectric wo = {wo}: {r} [{:?}]", start.elapsed());
            assert!(r.passed, "{r}");
            assert_eq!(r.delta_bins.len(), lobes, "{r}");
            let total: f64 = r.delta_bins.iter().map(|d| d.observed).sum();
            assert_eq!(total, cfg.samples as f64);
            assert!(r.observed.iter().all(|o| *o == 0.0));
        }
    }

    #[test]
    fn blend_of_smooth_and_delta_lobes() {
        let bsdf = Bsdf::from_json(r#"{"type":"blendbsdf","a":{"type":"diffuse"},"b":{"type":"conductor"}}"#).unwrap();
        let cfg = Chi2Config { tests: 2, ..Chi2Config::default() };
        for wo in [Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, -0.99875, 0.05)] {
            let start = Instant::now();
            let r = chi2_bsdf(&bsdf, wo, &cfg);
            eprintln!("blend wo = {wo}: {r} [{:?}]", start.elapsed());
            assert!(r.passed, "{r}");
            assert_eq!(r.delta_bins.len(), 1);
            let d = r.delta_bins[0];
            assert!((d.expected - 0.5 * cfg.samples as f64).abs() < 1.0);
            assert!((d.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-5);
        }
    }

    /// A power-cosine lobe of exponent 10⁴ (cos θ within 10⁻⁴ of the pole, 1/500 of the polar ring of
    /// cells): the fixed 6 × 6 rule put its top node at cos θ = 0.9983, where cos¹⁰⁰⁰⁰θ = 4·10⁻⁸, and
    /// declared the samples to lie where the pdf is 0. The adaptive integral finds the lobe.
    #[test]
    fn very_narrow_correct_lobe_passes() {
        use crate::sampling::warp::{power_cosine_hemisphere_pdf, sample_power_cosine_hemisphere};
        let n = 1e4f32;
        let cfg = Chi2Config { tests: 2, ..Chi2Config::default() };
        let start = Instant::now();
        let r = chi2_warp(|u| sample_power_cosine_hemisphere(u, n), |w| f64::from(power_cosine_hemisphere_pdf(w, n)), &cfg);
        eprintln!("power cosine n = 1e4: {r} [{:?}]", start.elapsed());
        assert!(r.passed, "{r}");
        let total: f64 = r.expected.iter().sum();
        assert!((total - cfg.samples as f64).abs() < 1e-3 * cfg.samples as f64, "∫pdf = {}", total / cfg.samples as f64);
        // A lobe off the pole, narrower than a cell in both cos θ and φ: Phong's lobe around a mirror
        // direction at 60° (sampled about +z and rotated by 60° about y).
        let (s, c) = (60f32.to_radians().sin(), 60f32.to_radians().cos());
        let rotate = move |w: Vec3| Vec3::new(c * w.x + s * w.z, w.y, -s * w.x + c * w.z);
        let unrotate = move |w: Vec3| Vec3::new(c * w.x - s * w.z, w.y, s * w.x + c * w.z);
        let n = 3e4f32;
        let r = chi2_warp(
            |u| rotate(sample_power_cosine_hemisphere(u, n)),
            |w| f64::from(power_cosine_hemisphere_pdf(unrotate(w), n)),
            &Chi2Config { seed: 1, ..cfg.clone() },
        );
        eprintln!("tilted power cosine n = 3e4: {r} [{:?}]", start.elapsed());
        assert!(r.passed, "{r}");
    }

    /// The same narrow lobes with a pdf 2 % too large or small, or 1° off, still fail: the
    /// samples guide the quadrature, they do not enter the expected counts.
    #[test]
    fn very_narrow_wrong_lobe_fails() {
        use crate::sampling::warp::{power_cosine_hemisphere_pdf, sample_power_cosine_hemisphere};
        let n = 1e4f32;
        let cfg = Chi2Config::default();
        let sample = |u| sample_power_cosine_hemisphere(u, n);
        let r = chi2_warp(sample, |w| 1.02 * f64::from(power_cosine_hemisphere_pdf(w, n)), &cfg);
        eprintln!("power cosine n = 1e4, pdf × 1.02: {r}");
        assert!(!r.passed && r.message.contains("more than 1"), "{r}");
        let r = chi2_warp(sample, |w| 0.98 * f64::from(power_cosine_hemisphere_pdf(w, n)), &cfg);
        eprintln!("power cosine n = 1e4, pdf × 0.98: {r}");
        assert!(!r.passed && r.p_value < 1e-12 * r.alpha, "{r}");
        // A lobe of exponent 3·10⁴ sampled around 60° but claimed around 61°.
        let tilt = |deg: f32| {
            let (s, c) = (deg.to_radians().sin(), deg.to_radians().cos());
            (
                move |w: Vec3| Vec3::new(c * w.x + s * w.z, w.y, -s * w.x + c * w.z),
                move |w: Vec3| Vec3::new(c * w.x - s * w.z, w.y, s * w.x + c * w.z),
            )
        };
        let ((rotate, _), (_, unrotate)) = (tilt(60.0), tilt(61.0));
        let n = 3e4f32;
        let r =
            chi2_warp(|u| rotate(sample_power_cosine_hemisphere(u, n)), |w| f64::from(power_cosine_hemisphere_pdf(unrotate(w), n)), &cfg);
        eprintln!("power cosine n = 3e4 sampled at 60°, pdf at 61°: {r}");
        assert!(!r.passed, "{r}");
    }

    #[test]
    fn adaptive_quadrature_integrates_a_peak_between_the_nodes() {
        // A Gaussian bump of σ = 10⁻³ placed between the nodes of both rules on the unit square: the
        // rules see nothing at depth 0; guided by a point at the peak the integral is found.
        let (x0, y0, sigma) = (0.3137, std::f64::consts::FRAC_1_SQRT_2, 1e-3);
        let density = move |x: f64, y: f64| {
            let r2 = (x - x0) * (x - x0) + (y - y0) * (y - y0);
            (-0.5 * r2 / (sigma * sigma)).exp() / (2.0 * PI * sigma * sigma)
        };
        let quad = Quadrature { density: &pointwise(density), low: Rule::new(6), high: Rule::new(12), samples: 1e6 };
        let blind = quad.integrate([0.0, 1.0], [0.0, 1.0], 0, &[], None);
        assert!(blind.value < 1e-3, "{}", blind.value);
        let guide = [(x0 + 1e-4, y0 - 2e-4)];
        let guided = quad.integrate([0.0, 1.0], [0.0, 1.0], 0, &guide, Focus::around(&guide).as_ref());
        assert!((guided.value - 1.0).abs() < 1e-6 && !guided.at_depth_limit, "{guided:?}");
    }

    #[test]
    fn adaptive_quadrature_integrates_a_step_between_the_central_nodes() {
        // A density of 1 left of x = 0.46 and 0 right of it: the step lies between the two central nodes
        // of the order-6 and the order-12 rules on the unit square, which both answer 0.5. The order-6
        // rule on unequal parts does not, and the quadrature splits down to the step (2026-12-06: this is
        // the shape of a roughdielectric's transmission cut-off at grazing angles, integrated 11 % high).
        let step = |x: f64, _y: f64| if x < 0.46 { 1.0 } else { 0.0 };
        let quad = Quadrature { density: &pointwise(step), low: Rule::new(6), high: Rule::new(12), samples: 1e6 };
        let whole = |rule: &Rule| quad.rule(rule, [0.0, 1.0], [0.0, 1.0]);
        assert!((whole(&quad.low) - 0.5).abs() < 1e-12 && (whole(&quad.high) - 0.5).abs() < 1e-12, "both rules alone say 0.5");
        // Polynomial rules never agree across a step: the parts along it reach the depth limit (a note in
        // the result), 1/1024 wide, and the integral is right to their width's share.
        let r = quad.integrate([0.0, 1.0], [0.0, 1.0], 0, &[], None);
        assert!((r.value - 0.46).abs() < 1e-4, "{r:?}");
    }

    #[test]
    fn guided_quadrature_finds_the_tail_of_a_lobe_narrow_along_one_axis() {
        // The shape of a roughdielectric Beckmann α = 10⁻³ transmission lobe in a chi-square cell,
        // scaled to the unit square: narrow along x (between the nodes of both rules until deep splits),
        // wide along y, its centre 2σ above the split at y = 1/2. The guide points all lie in the bulk, so
        // the part below the split holds 2.3 % of the mass and no sample; its nodes lie 10σ away in x and
        // both rules agreed on 10⁻⁴⁹ there (2026-11: the integral was 0.967 before the focus region).
        let (x0, y0, sx, sy) = (0.3137, 0.5 + 2.0 * 0.029, 8e-4, 0.029);
        let density = move |x: f64, y: f64| {
            let (dx, dy) = ((x - x0) / sx, (y - y0) / sy);
            (-0.5 * (dx * dx + dy * dy)).exp() / (2.0 * PI * sx * sy)
        };
        let quad = Quadrature { density: &pointwise(density), low: Rule::new(6), high: Rule::new(12), samples: 1e6 };
        let guide = [(0.3, 0.5), (-0.8, -0.4), (1.1, 0.9), (-0.2, -1.0)].map(|(u, v)| (x0 + u * sx, y0 + v * sy));
        let guided = quad.integrate([0.0, 1.0], [0.0, 1.0], 0, &guide, Focus::around(&guide).as_ref());
        assert!((guided.value - 1.0).abs() < 1e-6, "{guided:?}");
    }

    #[test]
    fn a_transmission_cut_off_between_the_central_nodes_is_integrated_right() {
        // The model behind `adaptive_quadrature_integrates_a_step_between_the_central_nodes`: a GGX
        // roughdielectric of η = 1.8 seen at cos θo = 0.05, whose transmitted pdf steps from 0.75 to 0 at
        // cos θi ≈ −0.027, between the central nodes of both rules on the row cos θi ∈ [−0.05, 0]. Its
        // correct sampler failed at p = 10⁻³³ (the row expected 11 % more than the pdf's integral).
        let bsdf = Bsdf::from_json(r#"{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3, "int_ior": 1.8}"#).unwrap();
        let r = chi2_bsdf(&bsdf, crate::verify::energy::direction(0.05, 0.3), &Chi2Config::default());
        assert!(r.passed, "{r}");
    }

    #[test]
    fn deterministic_across_runs() {
        let bsdf = Bsdf::from_json(r#"{"type":"diffuse"}"#).unwrap();
        let cfg = Chi2Config { samples: 50_000, seed: 11, ..Chi2Config::default() };
        let a = chi2_bsdf(&bsdf, Vec3::Z, &cfg);
        let b = chi2_bsdf(&bsdf, Vec3::Z, &cfg);
        assert_eq!(a, b);
    }

    #[test]
    fn histograms_are_written_and_readable() {
        let cfg = Chi2Config { samples: 20_000, theta_res: 4, phi_res: 6, ..Chi2Config::default() };
        let bsdf = Bsdf::from_json(r#"{"type":"blendbsdf","a":{"type":"diffuse"},"b":{"type":"conductor"}}"#).unwrap();
        let r = chi2_bsdf(&bsdf, Vec3::new(0.6, 0.0, 0.8), &cfg);
        let dir = crate::scratch::ScratchDir::new("chi2");
        let path = dir.join("chi2.txt");
        r.write_histograms(&path).unwrap();
        assert!(!dir.join("chi2.txt.tmp").exists());
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("# delta wi"));
        // What numpy.loadtxt sees: the non-comment lines, 2 × rows of `phi_res` numbers.
        let rows: Vec<Vec<f64>> =
            text.lines().filter(|l| !l.starts_with('#')).map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), 2 * cfg.theta_res);
        assert!(rows.iter().all(|r| r.len() == cfg.phi_res));
        let observed: f64 = rows[..cfg.theta_res].iter().flatten().sum();
        assert_eq!(observed, r.observed.iter().sum::<f64>());
        let expected: f64 = rows[cfg.theta_res..].iter().flatten().sum();
        assert!((expected - r.expected.iter().sum::<f64>()).abs() < 1.0);
    }
}
