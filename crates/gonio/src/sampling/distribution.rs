//! Piecewise-constant 1-D and 2-D distributions (pbrt-v4 §A.4.2 and §A.5.2, "Sampling 1D functions"
//! and "Piecewise-Constant 2D Distributions") and a continuous piecewise-linear 1-D one: tabulated
//! functions sampled by inverting their CDF.
//!
//! Each is a triplet like the warps in [`super::warp`]: `sample` maps a uniform number to a point,
//! `pdf` is the density of that point, `invert` maps the point back to the uniform number. The CDF is
//! built in `f64` (table building, see the precision convention in `ARCHITECTURE.md`), so that tables
//! with many small entries keep their tail.
//!
//! ```
//! use gonio::sampling::distribution::Distribution1D;
//! // Twice as likely to land in the second half of [0, 1).
//! let d = Distribution1D::new(&[1.0, 2.0]);
//! let s = d.sample(0.5);
//! assert_eq!(s.index, 1);
//! assert!((s.pdf - 4.0 / 3.0).abs() < 1e-6);
//! assert!((d.invert(s.x) - 0.5).abs() < 1e-6);
//! ```

use crate::math::Vec2;

/// The largest `f32` below 1: sampled coordinates stay in the half-open interval [0, 1) even when
/// `(i + du) / n` rounds up (2026-11: `f32` rounding of the last cell's upper end).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// One continuous sample of a [`Distribution1D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample1D {
    /// The sampled point in [0, 1).
    pub x: f32,
    /// Its density with respect to length on [0, 1].
    pub pdf: f32,
    /// The cell it lies in.
    pub index: usize,
}

/// One discrete sample of a [`Distribution1D`]: a cell chosen with probability proportional to its value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteSample {
    /// The chosen cell.
    pub index: usize,
    /// The probability of having chosen it.
    pub pmf: f32,
    /// The uniform number rescaled to [0, 1) within the chosen cell, ready for reuse.
    pub u_remapped: f32,
}

/// One sample of a [`Distribution2D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample2D {
    /// The sampled point in [0, 1)².
    pub p: Vec2,
    /// Its density with respect to area on [0, 1]².
    pub pdf: f32,
}

/// A piecewise-constant density on [0, 1] with `len()` equal cells, proportional to a tabulated function.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// The tabulated function, negative and non-finite entries replaced by 0.
    func: Vec<f32>,
    /// cdf[i] = ∫₀^{i/n} p(x) dx, n + 1 entries from 0 to 1.
    cdf: Vec<f64>,
    /// ∫₀¹ func(x) dx = Σ func / n, of the function as given (0 when all entries are 0).
    integral: f64,
    /// All entries were 0: sampling falls back to the uniform density.
    uniform: bool,
}

impl Distribution1D {
    /// A distribution proportional to `func` (one value per equal cell of [0, 1]).
    ///
    /// Entries must be finite and non-negative; others are treated as 0 (a debug assertion flags them).
    /// When every entry is 0 (or `func` is empty) the distribution is uniform, and [`Self::integral`] is 0.
    #[must_use]
    pub fn new(func: &[f32]) -> Self {
        debug_assert!(func.iter().all(|v| v.is_finite() && *v >= 0.0), "Distribution1D: entries must be finite and ≥ 0");
        // Release builds never panic on user data: clamp invalid entries to 0 (2026-11: e.g. NaN texels).
        let mut func: Vec<f32> = func.iter().map(|v| if v.is_finite() && *v > 0.0 { *v } else { 0.0 }).collect();
        if func.is_empty() {
            func.push(0.0);
        }
        let n = func.len();
        let total: f64 = func.iter().map(|v| f64::from(*v)).sum();
        let uniform = total <= 0.0; // entries are finite and ≥ 0 by now, so the sum is too
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut acc = 0.0;
        for v in &func {
            acc += if uniform { 1.0 } else { f64::from(*v) };
            cdf.push(acc);
        }
        let sum = acc;
        for c in &mut cdf {
            *c /= sum;
        }
        // Exactly 1 at the end, so that every u < 1 finds a cell.
        cdf[n] = 1.0;
        Distribution1D { func, cdf, integral: total / n as f64, uniform }
    }

    /// The number of cells.
    #[inline]
    #[must_use]
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// Whether there are no cells (never: an empty table becomes one zero cell).
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// ∫₀¹ of the tabulated function (piecewise constant): Σ func / n. Zero when every entry was zero.
    #[inline]
    #[must_use]
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The tabulated function, after clamping invalid entries to 0.
    #[inline]
    #[must_use]
    pub fn func(&self) -> &[f32] {
        &self.func
    }

    /// Density of cell `i` with respect to length on [0, 1].
    #[inline]
    fn cell_pdf(&self, i: usize) -> f64 {
        if self.uniform {
            1.0
        } else {
            f64::from(self.func[i]) / self.integral
        }
    }

    /// The cell holding `u` in the CDF: the largest i with cdf[i] ≤ u, so zero-width cells are skipped.
    /// Short tables count the entries ≤ u without branches, which is the same index as the binary search
    /// on a non-decreasing CDF (2026-12: choosing one of the Cornell box light's two triangles, with the
    /// triangle's vertices loaded, went from 6.2 % to 3.8 % of the render's profile samples).
    #[inline]
    fn find_cell(&self, u: f64) -> usize {
        let n = self.len();
        let i = if self.cdf.len() <= SHORT_CDF {
            self.cdf.iter().map(|&c| usize::from(c <= u)).sum()
        } else {
            self.cdf.partition_point(|c| *c <= u)
        };
        i.saturating_sub(1).min(n - 1)
    }

    /// The cell holding `x ∈ [0, 1]`.
    #[inline]
    fn cell_of(&self, x: f32) -> usize {
        let n = self.len();
        // Points outside [0, 1] are clamped to the first or last cell (2026-11: callers feeding x = 1.0).
        ((f64::from(x) * n as f64).max(0.0) as usize).min(n - 1)
    }

    /// Sample a point with density proportional to the function: invert the CDF, linearly inside a cell.
    #[must_use]
    pub fn sample(&self, u: f32) -> Sample1D {
        debug_assert!((0.0..=1.0).contains(&u), "Distribution1D::sample: u = {u} outside [0, 1]");
        let u = f64::from(u);
        let index = self.find_cell(u);
        let (c0, c1) = (self.cdf[index], self.cdf[index + 1]);
        // Position inside the cell; c1 > c0 because find_cell skips empty cells.
        let du = if c1 > c0 { ((u - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.0 };
        let x = (((index as f64 + du) / self.len() as f64) as f32).min(ONE_MINUS_EPSILON);
        Sample1D { x, pdf: self.cell_pdf(index) as f32, index }
    }

    /// The density of [`Self::sample`] at `x ∈ [0, 1]` with respect to length.
    #[must_use]
    pub fn pdf(&self, x: f32) -> f32 {
        if !(0.0..=1.0).contains(&x) {
            return 0.0;
        }
        self.cell_pdf(self.cell_of(x)) as f32
    }

    /// The inverse of [`Self::sample`]: the `u` whose sample is `x`, i.e. the CDF at `x`.
    #[must_use]
    pub fn invert(&self, x: f32) -> f32 {
        let n = self.len();
        let i = self.cell_of(x);
        let t = (f64::from(x) * n as f64 - i as f64).clamp(0.0, 1.0);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        (c0 + t * (c1 - c0)) as f32
    }

    /// Choose a cell with probability proportional to its value, and hand back `u` rescaled for reuse.
    #[inline]
    #[must_use]
    pub fn sample_discrete(&self, u: f32) -> DiscreteSample {
        debug_assert!((0.0..=1.0).contains(&u), "Distribution1D::sample_discrete: u = {u} outside [0, 1]");
        let u = f64::from(u);
        let index = self.find_cell(u);
        let (c0, c1) = (self.cdf[index], self.cdf[index + 1]);
        let pmf = c1 - c0;
        let u_remapped = if pmf > 0.0 { (((u - c0) / pmf) as f32).clamp(0.0, ONE_MINUS_EPSILON) } else { 0.0 };
        DiscreteSample { index, pmf: pmf as f32, u_remapped }
    }

    /// The cell [`Self::sample_discrete`] chooses for `u`, alone.
    #[inline]
    #[must_use]
    pub fn sample_index(&self, u: f32) -> usize {
        debug_assert!((0.0..=1.0).contains(&u), "Distribution1D::sample_index: u = {u} outside [0, 1]");
        self.find_cell(f64::from(u))
    }

    /// Thresholds t₁ … t_{n−1} for choosing a cell in lanes: for every `f32` u in [0, 1),
    /// [`Self::sample_index`]`(u)` is the number of them at or below u. t_k is the smallest `f32` at or
    /// above cdf[k], so that u ≥ t_k exactly when cdf[k] ≤ u in `f64`, as [`Self::find_cell`] compares.
    #[must_use]
    pub fn index_thresholds(&self) -> Vec<f32> {
        self.cdf[1..self.len()]
            .iter()
            .map(|&c| {
                let f = c as f32;
                // c ∈ [0, 1]: the next f32 up is the next bit pattern.
                if f64::from(f) < c {
                    f32::from_bits(f.to_bits() + 1)
                } else {
                    f
                }
            })
            .collect()
    }

    /// The probability with which [`Self::sample_discrete`] chooses cell `index`.
    #[must_use]
    pub fn pmf(&self, index: usize) -> f32 {
        if index >= self.len() {
            return 0.0;
        }
        (self.cdf[index + 1] - self.cdf[index]) as f32
    }
}

/// CDFs of at most this many entries are searched by counting ([`Distribution1D::find_cell`]).
const SHORT_CDF: usize = 16;

/// A continuous, piecewise-linear density on [0, 1] through `n + 1` equally spaced nodes x_k = k/n,
/// proportional to the linear interpolant of the tabulated node values (pbrt-v4 §A.4.3 "Sampling a linear
/// function", per segment). Unlike [`Distribution1D`] its density has no jumps, only kinks, which matters
/// where a density is integrated numerically: the chi-square harness's adaptive quadrature refines every
/// jump of a piecewise-constant density to its depth limit (2026-12: the energy-compensation lobes of
/// `roughdielectric`, sampled from a 256-cell piecewise-constant table, made one `gonio check` take
/// 695 CPU seconds instead of 12).
///
/// ```
/// use gonio::sampling::distribution::PiecewiseLinear1D;
/// // Density 2x on [0, 1].
/// let d = PiecewiseLinear1D::new(&[0.0, 1.0]);
/// let x = d.sample(0.25);
/// assert!((x - 0.5).abs() < 1e-6);
/// assert!((d.pdf(x) - 1.0).abs() < 1e-6);
/// assert!((d.invert(x) - 0.25).abs() < 1e-6);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear1D {
    /// The node values, negative and non-finite entries replaced by 0 (all 1 when every entry was 0).
    nodes: Vec<f32>,
    /// cdf[k] = ∫₀^{k/n} p(x) dx, n + 1 entries from 0 to 1.
    cdf: Vec<f64>,
    /// ∫₀¹ of the interpolant of `nodes`.
    integral: f64,
}

impl PiecewiseLinear1D {
    /// A distribution proportional to the linear interpolant of `nodes` (at least two values, at equally
    /// spaced points from 0 to 1). Entries must be finite and non-negative; others are treated as 0. When
    /// every entry is 0 (or fewer than two are given) the distribution is uniform.
    #[must_use]
    pub fn new(nodes: &[f32]) -> Self {
        debug_assert!(nodes.iter().all(|v| v.is_finite() && *v >= 0.0), "PiecewiseLinear1D: entries must be finite and ≥ 0");
        let mut nodes: Vec<f32> = nodes.iter().map(|v| if v.is_finite() && *v > 0.0 { *v } else { 0.0 }).collect();
        if nodes.len() < 2 || nodes.iter().all(|v| *v == 0.0) {
            nodes = vec![1.0; nodes.len().max(2)];
        }
        let n = nodes.len() - 1;
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut acc = 0.0;
        for pair in nodes.windows(2) {
            acc += 0.5 * (f64::from(pair[0]) + f64::from(pair[1])) / n as f64;
            cdf.push(acc);
        }
        for c in &mut cdf {
            *c /= acc;
        }
        cdf[n] = 1.0;
        PiecewiseLinear1D { nodes, cdf, integral: acc }
    }

    /// The number of segments (nodes − 1).
    #[inline]
    #[must_use]
    pub fn segments(&self) -> usize {
        self.nodes.len() - 1
    }

    /// The segment holding `x ∈ [0, 1]` and the position t ∈ [0, 1] inside it.
    #[inline]
    fn segment_of(&self, x: f64) -> (usize, f64) {
        let n = self.segments();
        let s = x.clamp(0.0, 1.0) * n as f64;
        let k = (s as usize).min(n - 1);
        (k, (s - k as f64).clamp(0.0, 1.0))
    }

    /// Sample a point: choose a segment by its area, then invert the segment's quadratic CDF.
    #[must_use]
    pub fn sample(&self, u: f32) -> f32 {
        debug_assert!((0.0..=1.0).contains(&u), "PiecewiseLinear1D::sample: u = {u} outside [0, 1]");
        let u = f64::from(u);
        let n = self.segments();
        // The largest k with cdf[k] ≤ u: segments of zero area are skipped.
        let k = self.cdf.partition_point(|c| *c <= u).saturating_sub(1).min(n - 1);
        let (c0, c1) = (self.cdf[k], self.cdf[k + 1]);
        let v = if c1 > c0 { ((u - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.0 };
        // Inside the segment the density is ∝ a + (b − a) t, its CDF (a t + (b − a) t²/2) / ((a + b)/2) = v;
        // the root written as v (a + b) / (a + √(a² + (b² − a²) v)) has no cancellation when a ≈ b.
        let (a, b) = (f64::from(self.nodes[k]), f64::from(self.nodes[k + 1]));
        let denominator = a + (a * a + (b * b - a * a) * v).max(0.0).sqrt();
        let t = if denominator > 0.0 { (v * (a + b) / denominator).clamp(0.0, 1.0) } else { 0.0 };
        (((k as f64 + t) / n as f64) as f32).min(ONE_MINUS_EPSILON)
    }

    /// The density of [`Self::sample`] at `x` with respect to length (0 outside [0, 1]).
    #[must_use]
    pub fn pdf(&self, x: f32) -> f32 {
        if !(0.0..=1.0).contains(&x) {
            return 0.0;
        }
        let (k, t) = self.segment_of(f64::from(x));
        let value = (1.0 - t) * f64::from(self.nodes[k]) + t * f64::from(self.nodes[k + 1]);
        (value / self.integral) as f32
    }

    /// The inverse of [`Self::sample`]: the CDF at `x`.
    #[must_use]
    pub fn invert(&self, x: f32) -> f32 {
        let (k, t) = self.segment_of(f64::from(x));
        let (a, b) = (f64::from(self.nodes[k]), f64::from(self.nodes[k + 1]));
        let area = (a * t + 0.5 * (b - a) * t * t) / self.segments() as f64;
        (self.cdf[k] + area / self.integral).min(1.0) as f32
    }
}

/// A piecewise-constant density on [0, 1]² over an `nu × nv` grid: a marginal distribution over rows (v)
/// and one conditional distribution over u per row.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    conditionals: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// A distribution proportional to `func`, stored row-major: `nv` rows of `nu` values, the value of
    /// cell (iu, iv) at `func[iv * nu + iu]`. Same rules for invalid and all-zero entries as
    /// [`Distribution1D::new`].
    ///
    /// # Panics
    /// When `func.len() != nu * nv` or either size is 0.
    #[must_use]
    pub fn new(func: &[f32], nu: usize, nv: usize) -> Self {
        assert!(nu > 0 && nv > 0, "Distribution2D::new: empty grid {nu} × {nv}");
        assert_eq!(func.len(), nu * nv, "Distribution2D::new: {} values for a {nu} × {nv} grid", func.len());
        let conditionals: Vec<Distribution1D> = func.chunks_exact(nu).map(Distribution1D::new).collect();
        // The marginal density of a row is proportional to the integral of its conditional.
        let row_integrals: Vec<f32> = conditionals.iter().map(|c| c.integral() as f32).collect();
        let marginal = Distribution1D::new(&row_integrals);
        Distribution2D { conditionals, marginal }
    }

    /// Cells along u (columns).
    #[inline]
    #[must_use]
    pub fn nu(&self) -> usize {
        self.conditionals[0].len()
    }

    /// Cells along v (rows).
    #[inline]
    #[must_use]
    pub fn nv(&self) -> usize {
        self.conditionals.len()
    }

    /// ∫∫ of the tabulated function over [0, 1]².
    #[inline]
    #[must_use]
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// Sample a point: the row from the marginal with `u.y`, then the column from its conditional with `u.x`.
    /// The density is the product p(v) p(u | v).
    #[must_use]
    pub fn sample(&self, u: Vec2) -> Sample2D {
        let v = self.marginal.sample(u.y);
        let c = self.conditionals[v.index].sample(u.x);
        Sample2D { p: Vec2::new(c.x, v.x), pdf: v.pdf * c.pdf }
    }

    /// The density of [`Self::sample`] at `p ∈ [0, 1]²` with respect to area.
    #[must_use]
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !(0.0..=1.0).contains(&p.x) || !(0.0..=1.0).contains(&p.y) {
            return 0.0;
        }
        let iv = self.marginal.cell_of(p.y);
        self.marginal.pdf(p.y) * self.conditionals[iv].pdf(p.x)
    }

    /// The inverse of [`Self::sample`].
    #[must_use]
    pub fn invert(&self, p: Vec2) -> Vec2 {
        let iv = self.marginal.cell_of(p.y);
        Vec2::new(self.conditionals[iv].invert(p.x), self.marginal.invert(p.y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;
    use crate::verify::chi2::{chi2_plane, Chi2Config};

    fn tables() -> Vec<Vec<f32>> {
        vec![
            vec![1.0, 2.0, 3.0, 4.0],
            vec![0.0, 5.0, 0.0, 0.0, 1.0, 0.0],
            vec![7.0],
            vec![0.0, 0.0, 0.0],
            vec![1e-6, 1.0, 1e3, 0.5, 0.0, 2.0, 0.01],
        ]
    }

    #[test]
    fn one_d_round_trip_and_pdf_agree() {
        let mut rng = Pcg32::new(3, 1);
        for t in tables() {
            let d = Distribution1D::new(&t);
            for _ in 0..10_000 {
                let u = rng.next_f32();
                let s = d.sample(u);
                assert!((0.0..1.0).contains(&s.x));
                assert!((d.invert(s.x) - u).abs() < 1e-4, "{t:?}: u = {u}, x = {}, back {}", s.x, d.invert(s.x));
                assert!((d.pdf(s.x) - s.pdf).abs() <= 1e-6 * s.pdf, "{t:?}");
                assert!(s.pdf > 0.0, "{t:?}: sampled a zero cell");
            }
        }
    }

    #[test]
    fn one_d_pdf_integrates_to_one() {
        for t in tables() {
            let d = Distribution1D::new(&t);
            let m = 100_000;
            let sum: f64 = (0..m).map(|i| f64::from(d.pdf((i as f32 + 0.5) / m as f32))).sum::<f64>() / m as f64;
            assert!((sum - 1.0).abs() < 1e-3, "{t:?}: {sum}");
        }
    }

    #[test]
    fn one_d_degenerate_inputs() {
        // All zero: uniform, integral 0.
        let d = Distribution1D::new(&[0.0, 0.0, 0.0]);
        assert_eq!(d.integral(), 0.0);
        assert!((d.sample(0.5).x - 0.5).abs() < 1e-6);
        assert_eq!(d.pdf(0.9), 1.0);
        // A single cell is uniform with the right integral.
        let d = Distribution1D::new(&[7.0]);
        assert_eq!(d.len(), 1);
        assert!((d.integral() - 7.0).abs() < 1e-12);
        assert!((d.sample(0.25).x - 0.25).abs() < 1e-7);
        // Zeros in the middle are never sampled, not even at their CDF plateau.
        let d = Distribution1D::new(&[1.0, 0.0, 0.0, 1.0]);
        let s = d.sample(0.5);
        assert_eq!(s.index, 3);
        assert_eq!(s.x, 0.75);
        assert_eq!(d.pdf(0.3), 0.0);
        // Empty table: one zero cell, uniform.
        let d = Distribution1D::new(&[]);
        assert_eq!(d.len(), 1);
        assert_eq!(d.pdf(0.4), 1.0);
        // u just below 1 stays in [0, 1).
        let s = Distribution1D::new(&[1.0, 1.0]).sample(ONE_MINUS_EPSILON);
        assert!(s.x < 1.0);
    }

    #[test]
    fn discrete_sampling() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        let a = d.sample_discrete(0.1);
        assert_eq!((a.index, a.pmf), (0, 0.25));
        assert!((a.u_remapped - 0.4).abs() < 1e-6);
        let b = d.sample_discrete(0.25);
        assert_eq!(b.index, 2);
        assert_eq!(b.pmf, 0.75);
        assert!(b.u_remapped.abs() < 1e-6);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.pmf(3), 0.0);
        let total: f32 = (0..d.len()).map(|i| d.pmf(i)).sum();
        assert!((total - 1.0).abs() < 1e-6);
    }

    fn table_2d() -> (Vec<f32>, usize, usize) {
        // 5 × 3 grid with a zero row and zeros inside rows.
        let f = vec![
            1.0, 0.0, 2.0, 3.0, 0.5, //
            0.0, 0.0, 0.0, 0.0, 0.0, //
            4.0, 1.0, 0.0, 0.2, 6.0,
        ];
        (f, 5, 3)
    }

    #[test]
    fn two_d_round_trip_and_pdf_agree() {
        let (f, nu, nv) = table_2d();
        let d = Distribution2D::new(&f, nu, nv);
        let mut rng = Pcg32::new(9, 2);
        for _ in 0..20_000 {
            let u = rng.next_vec2();
            let s = d.sample(u);
            assert!(s.pdf > 0.0);
            assert!((d.pdf(s.p) - s.pdf).abs() <= 1e-5 * s.pdf);
            let back = d.invert(s.p);
            assert!((back - u).abs().max_element() < 1e-4, "u = {u}, back = {back}");
        }
    }

    #[test]
    fn two_d_pdf_integrates_to_one_and_degenerate_inputs() {
        let (f, nu, nv) = table_2d();
        let d = Distribution2D::new(&f, nu, nv);
        let m = 600; // a multiple of both grid sizes: midpoints never sit on a step
        let mut sum = 0.0;
        for i in 0..m {
            for j in 0..m {
                sum += f64::from(d.pdf(Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32)));
            }
        }
        assert!((sum / (m * m) as f64 - 1.0).abs() < 1e-3);
        let sum_f: f64 = f.iter().map(|v| f64::from(*v)).sum();
        assert!((d.integral() - sum_f / 15.0).abs() < 1e-6);
        // All zeros: uniform.
        let z = Distribution2D::new(&[0.0; 6], 3, 2);
        assert_eq!(z.integral(), 0.0);
        assert!((z.pdf(Vec2::new(0.2, 0.7)) - 1.0).abs() < 1e-6);
        let s = z.sample(Vec2::new(0.3, 0.6));
        assert!((s.p - Vec2::new(0.3, 0.6)).abs().max_element() < 1e-6);
        // A single cell.
        let one = Distribution2D::new(&[2.0], 1, 1);
        assert!((one.pdf(Vec2::splat(0.5)) - 1.0).abs() < 1e-6);
        assert_eq!(one.pdf(Vec2::new(1.5, 0.5)), 0.0);
    }

    #[test]
    fn one_d_chi2() {
        let t = [0.2_f32, 0.0, 3.0, 1.0, 0.0, 0.0, 2.5, 0.7];
        let d = Distribution1D::new(&t);
        let cfg = Chi2Config::default();
        // The chi-square grid refines the table's cells, so the pdf is smooth inside each grid cell.
        let r = chi2_plane(|u| Vec2::new(d.sample(u.x).x, u.y), |p| f64::from(d.pdf(p.x)), Vec2::ZERO, Vec2::ONE, (8 * t.len(), 4), &cfg);
        assert!(r.passed, "{r}");
    }

    #[test]
    fn linear_round_trip_pdf_and_integral() {
        let mut rng = Pcg32::new(5, 2);
        for t in tables() {
            let d = PiecewiseLinear1D::new(&t);
            for _ in 0..2000 {
                let u = rng.next_f32();
                let x = d.sample(u);
                assert!((0.0..1.0).contains(&x), "{t:?}: x = {x}");
                assert!(d.pdf(x) > 0.0, "{t:?}: sampled x = {x} has pdf 0");
                assert!((d.invert(x) - u).abs() < 2e-5, "{t:?}: invert(sample({u})) = {}", d.invert(x));
            }
            // ∫ pdf = 1 by the trapezoid rule on a fine grid (exact up to the kinks at the nodes).
            let m = 100_000;
            let integral: f64 = (0..m).map(|i| f64::from(d.pdf((i as f32 + 0.5) / m as f32))).sum::<f64>() / m as f64;
            assert!((integral - 1.0).abs() < 1e-4, "{t:?}: ∫pdf = {integral}");
        }
    }

    #[test]
    fn linear_known_values_and_continuity() {
        // Density 2x: sample(u) = √u, pdf(x) = 2x.
        let d = PiecewiseLinear1D::new(&[0.0, 1.0]);
        for u in [0.0f32, 0.01, 0.3, 0.81, 0.999] {
            assert!((d.sample(u) - u.sqrt()).abs() < 1e-6);
            assert!((d.pdf(u) - 2.0 * u).abs() < 1e-6);
        }
        // Uniform when every node is 0; a node of value 0 between positive ones keeps the density continuous.
        let z = PiecewiseLinear1D::new(&[0.0, 0.0, 0.0]);
        assert!((z.pdf(0.7) - 1.0).abs() < 1e-6);
        let v = PiecewiseLinear1D::new(&[1.0, 0.0, 1.0]);
        assert!(v.pdf(0.5) < 1e-6 && (v.pdf(0.5 - 1e-3) - v.pdf(0.5 + 1e-3)).abs() < 1e-5);
        assert!((v.pdf(0.0) - 2.0).abs() < 1e-6, "∫ = 1/2, so the density at a node of value 1 is 2");
    }

    #[test]
    fn linear_chi2() {
        let t = [0.2_f32, 0.0, 3.0, 1.0, 0.0, 0.0, 2.5, 0.7];
        let d = PiecewiseLinear1D::new(&t);
        let r = chi2_plane(
            |u| Vec2::new(d.sample(u.x), u.y),
            |p| f64::from(d.pdf(p.x)),
            Vec2::ZERO,
            Vec2::ONE,
            (8 * t.len(), 4),
            &Chi2Config::default(),
        );
        assert!(r.passed, "{r}");
        // A wrong sampler (the piecewise-constant one over the same values) fails.
        let wrong = Distribution1D::new(&t);
        let r = chi2_plane(
            |u| Vec2::new(wrong.sample(u.x).x, u.y),
            |p| f64::from(d.pdf(p.x)),
            Vec2::ZERO,
            Vec2::ONE,
            (8 * t.len(), 4),
            &Chi2Config::default(),
        );
        assert!(!r.passed, "{r}");
    }

    #[test]
    fn two_d_chi2() {
        let (f, nu, nv) = table_2d();
        let d = Distribution2D::new(&f, nu, nv);
        let cfg = Chi2Config::default();
        let r = chi2_plane(|u| d.sample(u).p, |p| f64::from(d.pdf(p)), Vec2::ZERO, Vec2::ONE, (8 * nu, 8 * nv), &cfg);
        assert!(r.passed, "{r}");
    }
}
