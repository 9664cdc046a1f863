//! Sampling a bilinear interpolant on [0, 1]² by the inversion method, conditioned on extra parameters:
//! the warp Dupuy & Jakob 2018 ("An Adaptive Parameterization for Efficient Material Acquisition and
//! Rendering", §5) store their material tables for, and the structure Mitsuba 3 calls
//! `Marginal2D<Float, Dimension, Continuous = true>` (the numerics here follow it step for step, so that
//! gonio's `measured` BSDF agrees with Mitsuba's to float32 round-off).
//!
//! The density is the bilinear interpolant of a `w × h` grid of values at the points
//! (x, y) = (i/(w−1), j/(h−1)). Integrating it over x gives, for each grid row, the row integral
//! rⱼ = Σᵢ (vᵢ + vᵢ₊₁) / (2(w−1)); the marginal density in y is then *linear* between rows, and the
//! conditional density in x at a given y is the interpolant of two rows, linear between columns.
//! Sampling inverts both CDFs exactly (a quadratic per segment, [`Marginal2D::sample`]);
//! [`Marginal2D::invert`] maps a point back to the unit square. Both return the density at the point.
//!
//! With `D` parameters (e.g. φᵢ, θᵢ of a measured BRDF), the file holds one grid per combination of
//! tabulated parameter values; each query interpolates the grids, CDFs and values multilinearly between
//! the two nearest values of each parameter (clamped to the tabulated range). A parameter with a single
//! tabulated value is constant.
//!
//! ```
//! use gonio::sampling::marginal2d::Marginal2D;
//! use gonio::math::Vec2;
//! // Density 2x on [0, 1]² (a 2 × 2 grid: 0 on the left, 2 on the right, normalised).
//! let m = Marginal2D::<0>::new(&[0.0, 1.0, 0.0, 1.0], [2, 2], [], true, true).unwrap();
//! let (p, pdf) = m.sample(Vec2::new(0.25, 0.5), []);
//! assert!((p.x - 0.5).abs() < 1e-6 && (pdf - 1.0).abs() < 1e-6); // x = √u
//! let (u, _) = m.invert(p, []);
//! assert!((u - Vec2::new(0.25, 0.5)).length() < 1e-6);
//! ```

use crate::math::Vec2;

/// The largest `f32` below 1, and the smallest sample kept away from 0 (Mitsuba clamps samples into
/// [ε, 1 − ε] to keep them off the domain boundary, where the quadratic inversion degenerates).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;
const EPSILON: f32 = f32::EPSILON / 2.0;

/// A bilinear interpolant on [0, 1]² with `D` interpolated parameters, ready to be sampled and inverted.
#[derive(Clone, Debug, PartialEq)]
pub struct Marginal2D<const D: usize> {
    /// Grid resolution (w, h): w values along x per row, h rows.
    size: [usize; 2],
    /// 1/(w−1), 1/(h−1) and their inverses.
    patch_size: [f32; 2],
    inv_patch_size: [f32; 2],
    /// The tabulated values of each parameter, ascending.
    param_values: [Vec<f32>; D],
    /// Slice stride of each parameter (0 for a parameter with one value).
    param_strides: [usize; D],
    /// Values (normalised when `normalized`), one w·h slice per parameter combination.
    data: Vec<f32>,
    /// Marginal CDF: per slice, the h−1 cumulative integrals up to the end of each row segment.
    marg_cdf: Vec<f32>,
    /// Conditional CDFs: per slice and row, the w−1 cumulative integrals along x.
    cond_cdf: Vec<f32>,
    normalized: bool,
}

/// The most parameter corners of a lookup (2ᴰ, D ≤ 3).
const MAX_CORNERS: usize = 8;

/// The parameter corners of a lookup ([`Marginal2D::lookup`]): the weights (w₀, w₁) per parameter, and
/// for corner c (bit k set: parameter k's upper value) its offset from the lower corner, in slices.
struct Corners<const D: usize> {
    step: [usize; MAX_CORNERS],
    weights: [[f32; 2]; D],
}

impl<const D: usize> Marginal2D<D> {
    /// Build from `data`: one `size = [w, h]` grid (row-major, x fastest) per combination of the
    /// parameter values `param_values` (the last parameter varying fastest, as in C order).
    ///
    /// `normalize`: scale each slice to integrate to 1 (then `eval` is a density); otherwise values are
    /// kept and sampling is still proportional. `enable_sampling = false` skips the CDFs (`eval` only).
    /// `Err` says what is inconsistent (callers add the file and field).
    pub fn new(
        data: &[f32],
        size: [usize; 2],
        param_values: [Vec<f32>; D],
        normalize: bool,
        enable_sampling: bool,
    ) -> Result<Self, String> {
        let [w, h] = size;
        if w < 2 || h < 2 {
            return Err(format!("a 2-D table needs at least 2 × 2 values, got {w} × {h}"));
        }
        let mut strides = [0usize; D];
        let mut slices = 1usize;
        for i in (0..D).rev() {
            let n = param_values[i].len();
            if n < 1 {
                return Err(format!("parameter {i} has no tabulated values"));
            }
            if param_values[i].windows(2).any(|p| !(p[1] > p[0])) {
                return Err(format!("the values of parameter {i} are not strictly increasing: {:?}", param_values[i]));
            }
            strides[i] = if n > 1 { slices } else { 0 };
            slices *= n;
        }
        let n_data = w * h;
        if data.len() != slices * n_data {
            return Err(format!("expected {slices} slices of {w} × {h} values ({} in all), got {}", slices * n_data, data.len()));
        }
        if let Some(v) = data.iter().find(|v| !(v.is_finite())) {
            return Err(format!("the table holds a non-finite value ({v})"));
        }
        let (n_marg, n_cond) = (h - 1, (w - 1) * h);
        let (scale_x, scale_y) = (0.5 / (w - 1) as f64, 0.5 / (h - 1) as f64);
        let mut data_out = Vec::with_capacity(data.len());
        let (mut marg_cdf, mut cond_cdf) = (Vec::new(), Vec::new());
        let mut row_sums = vec![0.0f64; h];
        for slice in data.chunks_exact(n_data) {
            let mut norm = 1.0f32;
            if enable_sampling {
                // Conditional CDFs: trapezoidal integrals along each row (exact for the linear interpolant).
                let cond_start = cond_cdf.len();
                for (y, row) in slice.chunks_exact(w).enumerate() {
                    let mut acc = 0.0f64;
                    for x in 0..w - 1 {
                        acc += scale_x * (f64::from(row[x]) + f64::from(row[x + 1]));
                        cond_cdf.push(acc as f32);
                    }
                    row_sums[y] = acc;
                }
                // Marginal CDF: trapezoidal integrals of the row integrals along y.
                let marg_start = marg_cdf.len();
                let mut acc = 0.0f64;
                for y in 0..h - 1 {
                    acc += scale_y * (row_sums[y] + row_sums[y + 1]);
                    marg_cdf.push(acc as f32);
                }
                if normalize {
                    // An all-zero slice has no density to normalise; it is never sampled with weight
                    // (its pdf is 0) and stays zero rather than becoming NaN (2026-11).
                    norm = if acc > 0.0 { (1.0 / acc) as f32 } else { 0.0 };
                }
                cond_cdf[cond_start..].iter_mut().for_each(|c| *c *= norm);
                marg_cdf[marg_start..].iter_mut().for_each(|c| *c *= norm);
            } else if normalize {
                let mut sum = 0.0f64;
                for y in 0..h - 1 {
                    for x in 0..w - 1 {
                        let i = y * w + x;
                        sum += f64::from(slice[i]) + f64::from(slice[i + 1]) + f64::from(slice[i + w]) + f64::from(slice[i + w + 1]);
                    }
                }
                let integral = scale_x * scale_y * sum;
                norm = if integral > 0.0 { (1.0 / integral) as f32 } else { 0.0 };
            }
            data_out.extend(slice.iter().map(|v| v * norm));
        }
        debug_assert!(!enable_sampling || (marg_cdf.len() == slices * n_marg && cond_cdf.len() == slices * n_cond));
        Ok(Marginal2D {
            size,
            patch_size: [1.0 / (w - 1) as f32, 1.0 / (h - 1) as f32],
            inv_patch_size: [(w - 1) as f32, (h - 1) as f32],
            param_values,
            param_strides: strides,
            data: data_out,
            marg_cdf,
            cond_cdf,
            normalized: normalize,
        })
    }

    /// Grid resolution [w, h].
    #[must_use]
    pub fn size(&self) -> [usize; 2] {
        self.size
    }

    /// Whether the CDFs were built (sampling and inversion are available).
    #[must_use]
    pub fn can_sample(&self) -> bool {
        !self.marg_cdf.is_empty()
    }

    /// The slice offset of the lower corner and the parameters' corners: the interpolation weights
    /// (w₀, w₁) per parameter and each corner's slice offset from the lower one.
    fn interpolate_weights(&self, param: [f32; D]) -> (usize, Corners<D>) {
        const { assert!(D <= 3, "at most 2³ = MAX_CORNERS corners") };
        let mut weights = [[1.0, 0.0]; D];
        let (mut offset, mut upper) = (0, [0; D]);
        for dim in 0..D {
            let values = &self.param_values[dim];
            if values.len() == 1 {
                // No upper value: its corners read the lower one (with weight 0).
                continue;
            }
            upper[dim] = self.param_strides[dim];
            // The interval [values[i], values[i+1]] holding the parameter, clamped to the first and last.
            let i = find_interval(values.len(), |k| values[k] < param[dim]);
            let (p0, p1) = (values[i], values[i + 1]);
            let w1 = ((param[dim] - p0) / (p1 - p0)).clamp(0.0, 1.0);
            // NaN parameters clamp to NaN: treat as the lower value (2026-11: never index with NaN).
            let w1 = if w1.is_nan() { 0.0 } else { w1 };
            weights[dim] = [1.0 - w1, w1];
            offset += self.param_strides[dim] * i;
        }
        // Corner c takes the upper value of parameter k where bit k of c is set.
        let mut step = [0; MAX_CORNERS];
        for (c, s) in step.iter_mut().enumerate().take(1 << D) {
            *s = (0..D).filter(|k| c & (1 << k) != 0).map(|k| upper[k]).sum();
        }
        (offset, Corners { step, weights })
    }

    /// Multilinear interpolation over the parameters of `table[i0 + offset]`, where slices of `table` are
    /// `size` long: Mitsuba's recursive `lookup` (the last parameter the outermost level, a level whose
    /// upper weight is 0 taking its lower value alone), evaluated level by level from the first parameter
    /// up, with the same operations in the same order.
    #[inline]
    fn lookup(&self, table: &[f32], offset: usize, i0: usize, size: usize, corners: &Corners<D>) -> f32 {
        let mut v = [0.0f32; MAX_CORNERS];
        for (c, v) in v.iter_mut().enumerate().take(1 << D) {
            *v = table[i0 + offset + corners.step[c] * size];
        }
        let mut n = 1 << D;
        for [w0, w1] in corners.weights {
            n /= 2;
            for j in 0..n {
                v[j] = if w1 == 0.0 { v[2 * j] * w0 } else { v[2 * j].mul_add(w0, v[2 * j + 1] * w1) };
            }
        }
        v[0]
    }

    /// The (interpolated) value at `pos` ∈ [0, 1]²: a density when normalised.
    #[must_use]
    pub fn eval(&self, pos: Vec2, param: [f32; D]) -> f32 {
        let (slice, corners) = self.interpolate_weights(param);
        let [w, h] = self.size;
        let (cell, t) = self.cell(pos);
        let n_data = w * h;
        let index = cell[0] + cell[1] * w + slice * n_data;
        let v00 = self.lookup(&self.data, 0, index, n_data, &corners);
        let v10 = self.lookup(&self.data, 1, index, n_data, &corners);
        let v01 = self.lookup(&self.data, w, index, n_data, &corners);
        let v11 = self.lookup(&self.data, w + 1, index, n_data, &corners);
        lerp(lerp(v00, v10, t.x), lerp(v01, v11, t.x), t.y)
    }

    /// The cell holding `pos` (clamped to [0, 1]²) and the position inside it.
    #[inline]
    fn cell(&self, pos: Vec2) -> ([usize; 2], Vec2) {
        let p = Vec2::new(clamp01(pos.x) * self.inv_patch_size[0], clamp01(pos.y) * self.inv_patch_size[1]);
        let cx = (p.x as usize).min(self.size[0] - 2);
        let cy = (p.y as usize).min(self.size[1] - 2);
        ([cx, cy], Vec2::new(p.x - cx as f32, p.y - cy as f32))
    }

    /// Warp a uniform `u` ∈ [0, 1]² to a point distributed like the interpolant; returns the point and
    /// its density (the interpolated value there). Needs the CDFs (`enable_sampling`).
    #[must_use]
    pub fn sample(&self, u: Vec2, param: [f32; D]) -> (Vec2, f32) {
        debug_assert!(self.can_sample(), "Marginal2D::sample: built without sampling");
        let [w, h] = self.size;
        let (n_cond, n_marg, n_data) = (h * (w - 1), h - 1, w * h);
        let (slice, corners) = self.interpolate_weights(param);
        let clamp = |v: f32| if v.is_nan() { 0.5 } else { v.clamp(EPSILON, ONE_MINUS_EPSILON) };
        let mut s = Vec2::new(clamp(u.x), clamp(u.y));

        // Row: search the marginal CDF.
        let offset_marg = slice * n_marg;
        let fetch_marginal = |i: usize| self.lookup(&self.marg_cdf, 0, offset_marg + i, n_marg, &corners);
        if !self.normalized {
            s.y *= fetch_marginal(n_marg - 1);
        }
        let row = binary_search(0, n_marg - 1, |i| fetch_marginal(i) < s.y);
        if row > 0 {
            s.y -= fetch_marginal(row - 1);
        }
        let offset_cond = slice * n_cond + row * (w - 1);
        // Row integrals at both ends of the segment: the marginal density is linear between them.
        let r0 = self.lookup(&self.cond_cdf, w - 2, offset_cond, n_cond, &corners);
        let r1 = self.lookup(&self.cond_cdf, 2 * (w - 1) - 1, offset_cond, n_cond, &corners);
        s.y = sample_segment(s.y, self.inv_patch_size[1], r0, r1);

        // Column: search the conditional CDF of the interpolated row.
        s.x *= lerp(r0, r1, s.y);
        let fetch_conditional = |i: usize| {
            let v0 = self.lookup(&self.cond_cdf, 0, offset_cond + i, n_cond, &corners);
            let v1 = self.lookup(&self.cond_cdf, w - 1, offset_cond + i, n_cond, &corners);
            lerp(v0, v1, s.y)
        };
        let col = binary_search(0, w - 2, |i| fetch_conditional(i) < s.x);
        if col > 0 {
            s.x -= fetch_conditional(col - 1);
        }
        let offset_data = slice * n_data + row * w + col;
        let v00 = self.lookup(&self.data, 0, offset_data, n_data, &corners);
        let v10 = self.lookup(&self.data, 1, offset_data, n_data, &corners);
        let v01 = self.lookup(&self.data, w, offset_data, n_data, &corners);
        let v11 = self.lookup(&self.data, w + 1, offset_data, n_data, &corners);
        let (c0, c1) = (lerp(v00, v01, s.y), lerp(v10, v11, s.y));
        s.x = sample_segment(s.x, self.inv_patch_size[0], c0, c1);
        let p = Vec2::new((col as f32 + s.x) * self.patch_size[0], (row as f32 + s.y) * self.patch_size[1]);
        (p, lerp(c0, c1, s.x))
    }

    /// The inverse of [`Self::sample`]: the `u` that maps to `pos`, and the density at `pos`.
    #[must_use]
    pub fn invert(&self, pos: Vec2, param: [f32; D]) -> (Vec2, f32) {
        debug_assert!(self.can_sample(), "Marginal2D::invert: built without sampling");
        let [w, h] = self.size;
        let (n_cond, n_marg, n_data) = (h * (w - 1), h - 1, w * h);
        let (slice, corners) = self.interpolate_weights(param);
        let ([cx, cy], mut s) = self.cell(pos);
        let offset_data = slice * n_data + cy * w + cx;
        let v00 = self.lookup(&self.data, 0, offset_data, n_data, &corners);
        let v10 = self.lookup(&self.data, 1, offset_data, n_data, &corners);
        let v01 = self.lookup(&self.data, w, offset_data, n_data, &corners);
        let v11 = self.lookup(&self.data, w + 1, offset_data, n_data, &corners);
        let (c0, c1) = (lerp(v00, v01, s.y), lerp(v10, v11, s.y));
        let pdf = lerp(c0, c1, s.x);

        // x: the integral of the interpolated row up to pos.x, over the row's total.
        s.x = invert_segment(s.x, self.patch_size[0], c0, c1);
        let offset_cond = slice * n_cond + cy * (w - 1);
        if cx > 0 {
            let v0 = self.lookup(&self.cond_cdf, 0, offset_cond + cx - 1, n_cond, &corners);
            let v1 = self.lookup(&self.cond_cdf, w - 1, offset_cond + cx - 1, n_cond, &corners);
            s.x += lerp(v0, v1, s.y);
        }
        let r0 = self.lookup(&self.cond_cdf, w - 2, offset_cond, n_cond, &corners);
        let r1 = self.lookup(&self.cond_cdf, 2 * (w - 1) - 1, offset_cond, n_cond, &corners);
        s.x /= lerp(r0, r1, s.y);

        // y: the marginal CDF at pos.y.
        s.y = invert_segment(s.y, self.patch_size[1], r0, r1);
        let offset_marg = slice * n_marg;
        if cy > 0 {
            s.y += self.lookup(&self.marg_cdf, 0, offset_marg + cy - 1, n_marg, &corners);
        }
        if !self.normalized {
            s.y /= self.lookup(&self.marg_cdf, 0, offset_marg + n_marg - 1, n_marg, &corners);
        }
        (s, pdf)
    }
}

#[inline]
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    // Mitsuba's lerp: a·(1 − t) + b·t, as fmadd(b, t, fnmadd(a, t, a)).
    b.mul_add(t, (-a).mul_add(t, a))
}

#[inline]
fn clamp01(v: f32) -> f32 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(0.0, 1.0)
    }
}

/// The smallest index in [start, end] for which `pred` is false (`end` if it is true everywhere), for a
/// `pred` that is true up to some index and false after.
fn binary_search(start: usize, end: usize, pred: impl Fn(usize) -> bool) -> usize {
    let (mut lo, mut hi) = (start, end);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if pred(mid) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The index i ∈ [0, n − 2] of the interval [v(i), v(i+1)] holding a value, given `below(k) = v(k) < value`.
fn find_interval(n: usize, below: impl Fn(usize) -> bool) -> usize {
    binary_search(1, n - 1, below) - 1
}

/// Invert the CDF of a density linear from `v0` to `v1` over a segment of width 1/`inv_width`: the
/// position t ∈ [0, 1] in the segment whose integral from 0 is `sample`. Solves
/// (v1 − v0)/2 · t² + v0 · t = sample · inv_width, falling back to the linear form when the density is
/// nearly constant (relative slope below 1e-4, where the quadratic formula cancels).
#[inline]
fn sample_segment(sample: f32, inv_width: f32, v0: f32, v1: f32) -> f32 {
    let non_const = (v0 - v1).abs() > 1e-4 * (v0 + v1);
    let divisor = if non_const { v0 - v1 } else { v0 + v1 };
    let mut s = sample * 2.0 * inv_width;
    if non_const {
        s = v0 - (v0 * v0 + s * (v1 - v0)).max(0.0).sqrt();
    }
    if divisor != 0.0 {
        s /= divisor;
    }
    s
}

/// The integral over [0, t] of a density linear from `v0` to `v1` over a segment of width `width`.
#[inline]
fn invert_segment(t: f32, width: f32, v0: f32, v1: f32) -> f32 {
    t * lerp(v0, v1, 0.5 * t) * width
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// A random positive table with `slices` slices.
    fn table(w: usize, h: usize, slices: usize, seed: u64) -> Vec<f32> {
        let mut rng = Pcg32::new(seed, 3);
        (0..w * h * slices).map(|_| 0.05 + rng.next_f32()).collect()
    }

    #[test]
    fn sample_and_invert_are_inverse_and_pdf_is_eval() {
        let (w, h) = (7, 5);
        let m = Marginal2D::<2>::new(&table(w, h, 6, 1), [w, h], [vec![0.0, 1.0], vec![0.0, 0.5, 2.0]], true, true).unwrap();
        let mut rng = Pcg32::new(9, 9);
        for _ in 0..10_000 {
            let u = rng.next_vec2();
            let param = [rng.next_f32() * 1.2 - 0.1, rng.next_f32() * 2.2];
            let (p, pdf) = m.sample(u, param);
            assert!((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y));
            let e = m.eval(p, param);
            assert!((pdf - e).abs() <= 1e-4 * e.max(1.0), "pdf {pdf} eval {e}");
            let (back, pdf2) = m.invert(p, param);
            assert!((back - u).abs().max_element() < 2e-4, "u {u} back {back}");
            assert!((pdf2 - pdf).abs() <= 1e-4 * pdf.max(1.0));
        }
    }

    #[test]
    fn normalised_density_integrates_to_one_for_any_parameter() {
        let (w, h) = (6, 9);
        let m = Marginal2D::<1>::new(&table(w, h, 3, 2), [w, h], [vec![0.0, 0.3, 1.0]], true, true).unwrap();
        for param in [0.0, 0.1, 0.65, 1.0, 5.0] {
            // Midpoint rule on a fine grid (the interpolant is bilinear per cell).
            let n = 400;
            let mut sum = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let p = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    sum += f64::from(m.eval(p, [param]));
                }
            }
            let integral = sum / (n * n) as f64;
            assert!((integral - 1.0).abs() < 1e-4, "param {param}: ∫ = {integral}");
        }
    }

    #[test]
    fn chi2_of_the_warp() {
        use crate::verify::chi2::{chi2_plane, Chi2Config};
        let (w, h) = (5, 4);
        let m = Marginal2D::<1>::new(&table(w, h, 2, 4), [w, h], [vec![0.0, 1.0]], true, true).unwrap();
        let cfg = Chi2Config { samples: 200_000, ..Chi2Config::default() };
        // A 20 × 15 grid aligned with the 4 × 3 patches of the interpolant.
        let r = chi2_plane(|u| m.sample(u, [0.3]).0, |p| f64::from(m.eval(p, [0.3])), Vec2::ZERO, Vec2::ONE, (20, 15), &cfg);
        assert!(r.passed, "{}", r.message);
    }

    #[test]
    fn unnormalised_eval_interpolates_the_values() {
        let m = Marginal2D::<0>::new(&[1.0, 3.0, 5.0, 7.0], [2, 2], [], false, false).unwrap();
        assert_eq!(m.eval(Vec2::new(0.0, 0.0), []), 1.0);
        assert_eq!(m.eval(Vec2::new(1.0, 1.0), []), 7.0);
        assert!((m.eval(Vec2::new(0.5, 0.5), []) - 4.0).abs() < 1e-6);
        // Out of range and NaN positions clamp instead of indexing out of bounds.
        assert_eq!(m.eval(Vec2::new(-3.0, f32::NAN), []), 1.0);
    }

    #[test]
    fn bad_tables_are_errors() {
        assert!(Marginal2D::<0>::new(&[1.0; 3], [3, 1], [], true, true).is_err());
        assert!(Marginal2D::<0>::new(&[1.0; 5], [2, 2], [], true, true).is_err());
        assert!(Marginal2D::<1>::new(&[1.0; 8], [2, 2], [vec![1.0, 0.0]], true, true).is_err());
        assert!(Marginal2D::<0>::new(&[1.0, f32::NAN, 1.0, 1.0], [2, 2], [], true, true).is_err());
    }
}
