//! RGB → spectrum: the sigmoid-polynomial upsampling of W. Jakob and J. Hanika, "A Low-Dimensional
//! Function Space for Efficient Spectral Upsampling", Computer Graphics Forum 38(2) (Eurographics 2019).
//!
//! A colour becomes the smooth spectrum (the paper's quadratic polynomial through its algebraic sigmoid)
//!
//! ```text
//! s(λ) = S(c₀ λ² + c₁ λ + c₂),   S(x) = 1/2 + x / (2 √(1 + x²)),   λ in nm,
//! ```
//!
//! which lies in (0, 1) for any coefficients — a valid reflectance — and needs three numbers per colour.
//! The coefficients of a colour are those that make the round trip exact: the spectrum, lit by the
//! colour space's white (D65 for sRGB, [`super::illuminant::d65`], luminance 1) and seen by the CIE 1931
//! observer, has the colour's XYZ:
//!
//! ```text
//! XYZ(c) = ∫ s(λ) d65(λ) (x̄, ȳ, z̄)(λ) dλ · CIE_Y_NORMALIZATION = M⁻¹ rgb      (over [360, 830] nm)
//! ```
//!
//! with M the XYZ → linear sRGB matrix of [`super::named::xyz_to_linear_srgb`]. The integral is a
//! Gauss–Legendre rule, 3 nodes on each 5 nm interval of the CIE and D65 tables (282 nodes; exact where
//! s is a cubic across 5 nm, the product of the two tables being quadratic there).
//!
//! **gonio's table** ([`RgbToSpectrumTable`]) is built by gonio's own solver, following the paper's
//! scheme for its coefficient tables:
//!
//! * *parametrisation*: the colour's largest channel l ∈ {r, g, b} picks one of three blocks; its value
//!   z ∈ [0, 1] and the two others' ratios x = c_{l+1}/z, y = c_{l+2}/z ∈ [0, 1] index a res³ grid, x and
//!   y uniform, z at `smoothstep(smoothstep(k/(res−1)))` (the paper's spacing, dense near black and near 1
//!   where the coefficients change fast);
//! * *solve*: damped Gauss–Newton (Levenberg–Marquardt with Marquardt's diagonal scaling) on the XYZ
//!   difference, in the centred variable t = (λ − 595)/235 ∈ [−1, 1] for conditioning;
//! * *continuation*: grey 1/2 is c = 0 (S(0) = 1/2 everywhere); from there the middle slice (z ≈ 1/2) of
//!   each block, from its grey corner outwards to saturation; then every (x, y) column from the middle
//!   slice along z to white and to black — each cell starting from its solved neighbour, and halving the
//!   step towards a target the solver does not reach. (Continuing along z, as the paper's code does,
//!   keeps the path away from white, which no reflectance below 1 reaches, until the last cell.)
//!
//! [`RgbToSpectrumTable::fetch`] interpolates the table trilinearly (the paper's lookup);
//! [`RgbToSpectrumTable::fit`] then polishes the coefficients with a few solver iterations, which makes the
//! round trip exact to the quadrature. Measured numbers (build time, table-only and polished round-trip
//! errors) are in `docs/spectral.md`.
//!
//! Emission is unbounded: [`RgbIlluminantSpectrum`] is Mitsuba 3's scheme (`srgb_d65`, and pbrt-v4's
//! `RGBIlluminantSpectrum`): scale = 2 · max(rgb), the spectrum of rgb / scale (largest channel 1/2, in the
//! middle of the sigmoid's range), times scale, times D65. [`RgbUnboundedSpectrum`] is the same without
//! D65, for unbounded non-emissive values.
//!
//! ```
//! use gonio::spectrum::upsample::RgbReflectanceSpectrum;
//! use gonio::spectrum::Rgb;
//! let red = RgbReflectanceSpectrum::new(Rgb::new(0.8, 0.1, 0.1));
//! assert!(red.eval(650.0) > 0.7 && red.eval(450.0) < 0.2);
//! ```

use std::io::{Read, Write};
use std::path::Path;
use std::sync::OnceLock;

use rayon::prelude::*;

use super::cie::{cie1931_xyz, CIE_MAX, CIE_MIN, CIE_SAMPLES, CIE_Y_NORMALIZATION};
use super::illuminant::{d65, d65_at};
use super::named::xyz_to_linear_srgb;
use super::Rgb;
use crate::math::lanes::Real;

/// Jakob & Hanika's sigmoid, S(x) = 1/2 + x / (2 √(1 + x²)): (0, 1) for finite x,
/// 0 and 1 at ∓∞ (and for |x| ≥ 10¹⁸, where x² would overflow); NaN stays NaN. [`sigmoid_lanes`] at one lane.
#[inline]
#[must_use]
pub fn sigmoid(x: f32) -> f32 {
    sigmoid_lanes(x)
}

/// [`sigmoid`] in lanes.
#[inline(always)]
#[must_use]
pub fn sigmoid_lanes<R: Real>(x: R) -> R {
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let inner = R::splat(0.5) + x / (x.mul_add(x, one).sqrt() * 2.0);
    let outside = R::select(x.is_nan(), x, R::select(x.gt(zero), one, zero));
    R::select(x.abs().lt(R::splat(1e18)), inner, outside)
}

/// s(λ) = S(c₀ λ² + c₁ λ + c₂) per lane (the coefficients `c` of [`SigmoidPolynomial`], one set per lane),
/// `lambda` in nm: [`SigmoidPolynomial::eval`] in lanes.
#[inline(always)]
#[must_use]
pub fn sigmoid_polynomial_lanes<R: Real>(c: [R; 3], lambda: R) -> R {
    sigmoid_lanes(c[0].mul_add(lambda, c[1]).mul_add(lambda, c[2]))
}

/// Centre of the solver's variable t = (λ − [`T_CENTER`]) / [`T_HALF_WIDTH`], nm.
const T_CENTER: f64 = 0.5 * (CIE_MIN + CIE_MAX);
/// Half-width of the CIE range, nm.
const T_HALF_WIDTH: f64 = 0.5 * (CIE_MAX - CIE_MIN);

/// A spectrum S(c₀ λ² + c₁ λ + c₂), λ in nm (Jakob & Hanika 2019).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmoidPolynomial {
    c: [f32; 3],
}

impl SigmoidPolynomial {
    /// 0 everywhere (c₂ = −∞), the spectrum of black.
    pub const BLACK: SigmoidPolynomial = SigmoidPolynomial { c: [0.0, 0.0, f32::NEG_INFINITY] };

    /// The spectrum with coefficients (c₀, c₁, c₂) of λ², λ, 1, λ in nm (the layout of Mitsuba 3's
    /// `srgb_model_fetch` and pbrt-v4's `RGBSigmoidPolynomial`).
    #[must_use]
    pub const fn new(c: [f32; 3]) -> Self {
        SigmoidPolynomial { c }
    }

    /// From coefficients (a₀, a₁, a₂) of t², t, 1 in the solver's variable t = (λ − 595)/235:
    /// expanding a₀ (λ − m)²/h² + a₁ (λ − m)/h + a₂ in f64, then rounding.
    #[allow(clippy::cast_possible_truncation)]
    fn from_centered(a: [f64; 3]) -> Self {
        let (m, h) = (T_CENTER, T_HALF_WIDTH);
        let c0 = a[0] / (h * h);
        let c1 = a[1] / h - 2.0 * a[0] * m / (h * h);
        let c2 = a[0] * m * m / (h * h) - a[1] * m / h + a[2];
        SigmoidPolynomial { c: [c0 as f32, c1 as f32, c2 as f32] }
    }

    /// The coefficients (c₀, c₁, c₂), λ in nm.
    #[must_use]
    pub fn coefficients(&self) -> [f32; 3] {
        self.c
    }

    /// s(λ) at `lambda` nm, in [0, 1].
    #[inline]
    #[must_use]
    pub fn eval(&self, lambda: f32) -> f32 {
        self.eval_lanes(lambda)
    }

    /// [`SigmoidPolynomial::eval`] in lanes (which is this at one lane).
    #[inline(always)]
    #[must_use]
    pub fn eval_lanes<R: Real>(&self, lambda: R) -> R {
        sigmoid_polynomial_lanes(self.c.map(R::splat), lambda)
    }

    /// The linear sRGB of this reflectance under D65 (the round trip of the module docs, by its 282-node
    /// rule, with the f32 coefficients evaluated in f64).
    #[must_use]
    pub fn linear_srgb(&self) -> [f64; 3] {
        let k = kernel();
        let c = self.c.map(f64::from);
        let mut xyz = [0.0; 3];
        for (lambda, w) in k.lambda.iter().zip(&k.xyz) {
            let x = c[0].mul_add(*lambda, c[1]).mul_add(*lambda, c[2]);
            let s = if x.is_infinite() { f64::from(u8::from(x > 0.0)) } else { 0.5 + 0.5 * x / x.mul_add(x, 1.0).sqrt() };
            for i in 0..3 {
                xyz[i] += s * w[i];
            }
        }
        xyz_to_linear_srgb(xyz)
    }
}

/// The quadrature of the round trip: nodes (λ nm and t) and weights wᵢ · d65(λᵢ) · (x̄, ȳ, z̄)(λᵢ) ·
/// `CIE_Y_NORMALIZATION`, so that XYZ = Σᵢ s(λᵢ) xyzᵢ.
struct Kernel {
    lambda: Vec<f64>,
    t: Vec<f64>,
    xyz: Vec<[f64; 3]>,
}

fn kernel() -> &'static Kernel {
    static KERNEL: OnceLock<Kernel> = OnceLock::new();
    KERNEL.get_or_init(|| {
        // 3-point Gauss–Legendre on [−1, 1]: nodes 0, ±√(3/5), weights 8/9, 5/9.
        let gl = [(-(0.6_f64.sqrt()), 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.6_f64.sqrt(), 5.0 / 9.0)];
        let h = (CIE_MAX - CIE_MIN) / (CIE_SAMPLES - 1) as f64;
        let mut k = Kernel { lambda: Vec::new(), t: Vec::new(), xyz: Vec::new() };
        for i in 0..CIE_SAMPLES - 1 {
            let mid = CIE_MIN + h * (i as f64 + 0.5);
            for (node, weight) in gl {
                let lambda = mid + 0.5 * h * node;
                let scale = 0.5 * h * weight * d65(lambda) * CIE_Y_NORMALIZATION;
                k.lambda.push(lambda);
                k.t.push((lambda - T_CENTER) / T_HALF_WIDTH);
                k.xyz.push(cie1931_xyz(lambda).map(|v| v * scale));
            }
        }
        k
    })
}

/// Linear sRGB → XYZ: the inverse of [`xyz_to_linear_srgb`]'s matrix (computed, so the two round-trip).
fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    static INVERSE: OnceLock<[[f64; 3]; 3]> = OnceLock::new();
    let m = INVERSE.get_or_init(|| {
        let columns = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(xyz_to_linear_srgb);
        let forward = [0, 1, 2].map(|r| [0, 1, 2].map(|c| columns[c][r]));
        invert3(forward)
    });
    [0, 1, 2].map(|r| m[r][0] * rgb[0] + m[r][1] * rgb[1] + m[r][2] * rgb[2])
}

/// The inverse of a 3 × 3 matrix by cofactors (the callers' matrices are well conditioned).
fn invert3(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let cof = |r: usize, c: usize| {
        let (r0, r1, c0, c1) = ((r + 1) % 3, (r + 2) % 3, (c + 1) % 3, (c + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det = m[0][0] * cof(0, 0) + m[0][1] * cof(0, 1) + m[0][2] * cof(0, 2);
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| cof(c, r) / det))
}

/// Solves A x = b for a symmetric positive (semi-)definite 3 × 3 A by Gaussian elimination with partial
/// pivoting; `None` if A is singular to working precision.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if !(a[pivot][col].abs() > 1e-300) {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let tail: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The residual XYZ(a) − target and its Jacobian ∂XYZ/∂a for centred coefficients a (t², t, 1).
fn residual(a: &[f64; 3], target: &[f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let k = kernel();
    let mut r = target.map(|v| -v);
    let mut jac = [[0.0; 3]; 3];
    for (t, w) in k.t.iter().zip(&k.xyz) {
        let x = a[0].mul_add(*t, a[1]).mul_add(*t, a[2]);
        let inv = 1.0 / x.mul_add(x, 1.0).sqrt();
        let s = 0.5 * x.mul_add(inv, 1.0);
        // S'(x) = 1 / (2 (1 + x²)^{3/2}).
        let ds = 0.5 * inv * inv * inv;
        let basis = [t * t * ds, t * ds, ds];
        for i in 0..3 {
            r[i] += s * w[i];
            for j in 0..3 {
                jac[i][j] += basis[j] * w[i];
            }
        }
    }
    (r, jac)
}

fn norm(r: &[f64; 3]) -> f64 {
    (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt()
}

/// The solver stops when ‖XYZ(a) − target‖₂ is below this: a thousandth of the 1e-3 the round trip is
/// held to, and about f32 rounding of the stored coefficients' effect.
const SOLVE_TOLERANCE: f64 = 1e-7;

/// Levenberg–Marquardt from `start` towards the centred coefficients whose XYZ is `target`. Returns the
/// best coefficients found and their residual norm.
fn solve(target: &[f64; 3], start: [f64; 3], max_iterations: usize) -> ([f64; 3], f64) {
    let mut a = start;
    let (mut r, mut jac) = residual(&a, target);
    let mut error = norm(&r);
    // The damping μ, relative to diag(JᵀJ) (Marquardt's scaling); small first: near a solution the
    // Gauss–Newton step is right.
    let mut mu = 1e-6;
    for _ in 0..max_iterations {
        if error < SOLVE_TOLERANCE {
            break;
        }
        let jtj = [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| jac[k][i] * jac[k][j]).sum::<f64>()));
        let jtr = [0, 1, 2].map(|i| -(0..3).map(|k| jac[k][i] * r[k]).sum::<f64>());
        let mut improved = false;
        while mu < 1e12 {
            let mut damped = jtj;
            for i in 0..3 {
                // The 1e-30 keeps a vanished column (a flat sigmoid) from making the system singular.
                damped[i][i] += mu * jtj[i][i] + 1e-30;
            }
            if let Some(step) = solve3(damped, jtr) {
                let trial = [a[0] + step[0], a[1] + step[1], a[2] + step[2]];
                let (r_trial, jac_trial) = residual(&trial, target);
                let e = norm(&r_trial);
                if e < error {
                    (a, r, jac, error) = (trial, r_trial, jac_trial, e);
                    mu = (mu * 0.1).max(1e-12);
                    improved = true;
                    break;
                }
            }
            mu *= 10.0;
        }
        if !improved {
            break; // no step reduces the residual: a target the sigmoid cannot reach (white, the edges)
        }
    }
    (a, error)
}

/// [`solve`] from a neighbour's solution, halving the step towards `target` (continuation) when the
/// solver stalls, at most `depth` times.
fn solve_continued(target_rgb: [f64; 3], from_rgb: [f64; 3], from: [f64; 3], depth: u32) -> [f64; 3] {
    let (a, error) = solve(&linear_srgb_to_xyz(target_rgb), from, 50);
    if error < SOLVE_TOLERANCE || depth == 0 {
        return a;
    }
    let mid_rgb = [0, 1, 2].map(|i| 0.5 * (target_rgb[i] + from_rgb[i]));
    let mid = solve_continued(mid_rgb, from_rgb, from, depth - 1);
    let (b, error_b) = solve(&linear_srgb_to_xyz(target_rgb), mid, 50);
    if error_b < error {
        b
    } else {
        a
    }
}

/// `smoothstep(x) = 3x² − 2x³`.
fn smoothstep(x: f64) -> f64 {
    x * x * (3.0 - 2.0 * x)
}

/// The table's resolution per axis for [`srgb_table`].
pub const SRGB_TABLE_RESOLUTION: usize = 32;

/// Jakob & Hanika's coefficient table for linear sRGB, built by gonio's solver (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct RgbToSpectrumTable {
    res: usize,
    /// The z nodes, ascending from 0 to 1.
    z: Vec<f64>,
    /// Centred coefficients at [block][k (z)][j (y)][i (x)], flattened.
    coefficients: Vec<[f32; 3]>,
}

/// Why a table file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TableFileError {
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("not a gonio sigmoid-polynomial table of version {version} (wrong header, size or checksum)", version = TABLE_FILE_VERSION)]
    Format,
}

/// The file header; the version changes whenever the solver or the quadrature does (an old cache is then
/// rebuilt, not used).
const TABLE_FILE_MAGIC: &[u8; 16] = b"gonio-rgb2spec\0\0";
const TABLE_FILE_VERSION: u32 = 1;

impl RgbToSpectrumTable {
    /// Builds the table at `res` nodes per axis (res ≥ 3) by the continuation of the module docs, in
    /// parallel over the blocks and then over the (block, x, y) columns. `docs/spectral.md` has the time.
    #[must_use]
    pub fn build(res: usize) -> Self {
        let res = res.max(3);
        let z: Vec<f64> = (0..res).map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64))).collect();
        // The middle slice, z ≈ 1/2, is far from the gamut's surface everywhere: solve it first, from grey
        // (c = 0 there) outwards in x and y.
        let mid = z.partition_point(|&v| v < 0.5).clamp(1, res - 1);
        let middle: Vec<Vec<[f64; 3]>> = (0..3).into_par_iter().map(|l| Self::build_slice(l, z[mid], res)).collect();
        // Then every (block, x, y) column along z, from the middle slice to white and to black.
        let columns: Vec<Vec<[f64; 3]>> = (0..3 * res * res)
            .into_par_iter()
            .map(|lji| {
                let (l, ji) = (lji / (res * res), lji % (res * res));
                let (j, i) = (ji / res, ji % res);
                let rgb_at = |k: usize| Self::cell_rgb(l, z[k], i, j, res);
                let mut column = vec![[0.0; 3]; res];
                column[mid] = middle[l][ji];
                for k in mid + 1..res {
                    column[k] = solve_continued(rgb_at(k), rgb_at(k - 1), column[k - 1], 6);
                }
                for k in (1..mid).rev() {
                    column[k] = solve_continued(rgb_at(k), rgb_at(k + 1), column[k + 1], 6);
                }
                // z = 0 is black for every x, y: repeat k = 1 there (its colours are below 3e-5 anyway).
                column[0] = column[1];
                column
            })
            .collect();
        // Scatter the columns into the [block][z][y][x] layout.
        let mut coefficients = vec![[0.0_f32; 3]; 3 * res * res * res];
        for (lji, column) in columns.iter().enumerate() {
            let (l, ji) = (lji / (res * res), lji % (res * res));
            for (k, a) in column.iter().enumerate() {
                #[allow(clippy::cast_possible_truncation)]
                let a = a.map(|v| v as f32);
                coefficients[(l * res + k) * res * res + ji] = a;
            }
        }
        RgbToSpectrumTable { res, z, coefficients }
    }

    /// The colour of cell (x = i/(res−1), y = j/(res−1)) of block `l` at `z`.
    fn cell_rgb(l: usize, z: f64, i: usize, j: usize, res: usize) -> [f64; 3] {
        let mut rgb = [0.0; 3];
        rgb[l] = z;
        rgb[(l + 1) % 3] = z * i as f64 / (res - 1) as f64;
        rgb[(l + 2) % 3] = z * j as f64 / (res - 1) as f64;
        rgb
    }

    /// One (block, z) slice, [y][x] flattened: from grey (x = y = 1) down to saturation (x, y = 0).
    fn build_slice(l: usize, z: f64, res: usize) -> Vec<[f64; 3]> {
        let rgb_at = |i: usize, j: usize| Self::cell_rgb(l, z, i, j, res);
        let mut cells = vec![[0.0_f64; 3]; res * res];
        let last = res - 1;
        // Grey z from grey 1/2, whose spectrum is S(0) = 1/2.
        cells[last * res + last] = solve_continued(rgb_at(last, last), [0.5; 3], [0.0; 3], 6);
        // The row y = 1, then each column from y = 1 down.
        for i in (0..last).rev() {
            cells[last * res + i] = solve_continued(rgb_at(i, last), rgb_at(i + 1, last), cells[last * res + i + 1], 6);
        }
        for i in 0..res {
            for j in (0..last).rev() {
                cells[j * res + i] = solve_continued(rgb_at(i, j), rgb_at(i, j + 1), cells[(j + 1) * res + i], 6);
            }
        }
        cells
    }

    /// Nodes per axis.
    #[must_use]
    pub fn resolution(&self) -> usize {
        self.res
    }

    /// The table's coefficients for `rgb` (components clamped to [0, 1]) by trilinear interpolation, the
    /// paper's lookup; black gives [`SigmoidPolynomial::BLACK`].
    #[must_use]
    pub fn fetch(&self, rgb: Rgb) -> SigmoidPolynomial {
        self.fetch_centered(rgb).map_or(SigmoidPolynomial::BLACK, SigmoidPolynomial::from_centered)
    }

    /// [`Self::fetch`], then up to 20 solver iterations on the exact target: the round trip to the
    /// quadrature's precision (module docs). Deterministic; a few microseconds.
    #[must_use]
    pub fn fit(&self, rgb: Rgb) -> SigmoidPolynomial {
        let Some(start) = self.fetch_centered(rgb) else {
            return SigmoidPolynomial::BLACK;
        };
        let target = linear_srgb_to_xyz(rgb.map(|v| v.clamp(0.0, 1.0)).to_f64());
        SigmoidPolynomial::from_centered(solve(&target, start, 20).0)
    }

    fn fetch_centered(&self, rgb: Rgb) -> Option<[f64; 3]> {
        let rgb = rgb.map(|v| if v > 0.0 { v.min(1.0) } else { 0.0 }).to_f64(); // NaN → 0
                                                                                // The block: the largest channel (the first of equal ones; the blocks agree on their borders).
        let l = if rgb[0] >= rgb[1] && rgb[0] >= rgb[2] {
            0
        } else if rgb[1] >= rgb[2] {
            1
        } else {
            2
        };
        let z = rgb[l];
        if z <= 0.0 {
            return None;
        }
        let (x, y) = (rgb[(l + 1) % 3] / z, rgb[(l + 2) % 3] / z);
        let res = self.res;
        let last = (res - 1) as f64;
        let k = self.z.partition_point(|&v| v <= z).saturating_sub(1).min(res - 2);
        let tz = ((z - self.z[k]) / (self.z[k + 1] - self.z[k])).clamp(0.0, 1.0);
        let cell = |v: f64| {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // v ∈ [0, 1]
            let i = ((v * last) as usize).min(res - 2);
            (i, v * last - i as f64)
        };
        let ((i, tx), (j, ty)) = (cell(x), cell(y));
        let mut a = [0.0; 3];
        for (dk, wk) in [(0, 1.0 - tz), (1, tz)] {
            for (dj, wj) in [(0, 1.0 - ty), (1, ty)] {
                for (di, wi) in [(0, 1.0 - tx), (1, tx)] {
                    let c = self.coefficients[((l * res + k + dk) * res + j + dj) * res + i + di];
                    for n in 0..3 {
                        a[n] += wk * wj * wi * f64::from(c[n]);
                    }
                }
            }
        }
        Some(a)
    }

    /// Writes the table (header, resolution, little-endian f32 coefficients, FNV-1a checksum).
    ///
    /// # Errors
    /// Any I/O error.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let mut bytes = Vec::with_capacity(32 + self.coefficients.len() * 12);
        bytes.extend_from_slice(TABLE_FILE_MAGIC);
        bytes.extend_from_slice(&TABLE_FILE_VERSION.to_le_bytes());
        #[allow(clippy::cast_possible_truncation)]
        bytes.extend_from_slice(&(self.res as u32).to_le_bytes());
        for c in &self.coefficients {
            for v in c {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        bytes.extend_from_slice(&fnv1a(&bytes).to_le_bytes());
        // Write to a temporary name and rename, so a concurrent reader never sees half a file.
        let temporary = path.with_extension(format!("tmp{}", std::process::id()));
        std::fs::File::create(&temporary)?.write_all(&bytes)?;
        std::fs::rename(&temporary, path)
    }

    /// Reads a table written by [`Self::save`].
    ///
    /// # Errors
    /// [`TableFileError::Io`], or [`TableFileError::Format`] for another version, a wrong size or checksum.
    pub fn load(path: &Path) -> Result<Self, TableFileError> {
        let mut bytes = Vec::new();
        std::fs::File::open(path)?.read_to_end(&mut bytes)?;
        let header = TABLE_FILE_MAGIC.len() + 8;
        if bytes.len() < header + 8 || &bytes[..16] != TABLE_FILE_MAGIC {
            return Err(TableFileError::Format);
        }
        let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
        let (version, res) = (word(16), word(20) as usize);
        let count = 3 * res * res * res;
        if version != TABLE_FILE_VERSION || !(3..=1024).contains(&res) || bytes.len() != header + count * 12 + 8 {
            return Err(TableFileError::Format);
        }
        let (body, sum) = bytes.split_at(bytes.len() - 8);
        if fnv1a(body).to_le_bytes() != sum {
            return Err(TableFileError::Format);
        }
        let value = |n: usize| {
            f32::from_le_bytes([body[header + 4 * n], body[header + 4 * n + 1], body[header + 4 * n + 2], body[header + 4 * n + 3]])
        };
        let coefficients = (0..count).map(|c| [value(3 * c), value(3 * c + 1), value(3 * c + 2)]).collect();
        let z = (0..res).map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64))).collect();
        Ok(RgbToSpectrumTable { res, z, coefficients })
    }

    /// [`Self::load`] from `path` if it holds a valid table of resolution `res`; otherwise
    /// [`Self::build`] and try to [`Self::save`] it there (a failure to write is ignored: the cache is an
    /// optimisation).
    #[must_use]
    pub fn load_or_build(path: &Path, res: usize) -> Self {
        if let Ok(table) = Self::load(path) {
            if table.res == res {
                return table;
            }
        }
        let table = Self::build(res);
        let _ = table.save(path);
        table
    }
}

/// 64-bit FNV-1a, the table file's checksum.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// The process-wide sRGB table at [`SRGB_TABLE_RESOLUTION`], built on first use (0.4–0.9 s) and kept in
/// [`cache_dir`] as `rgb2spec_srgb_v{version}_{res}.bin` (1.2 MB, checksummed, written atomically), which
/// later processes load instead of building it again. A file that does not load (missing, corrupt, another
/// version) is rebuilt; one that cannot be written is not an error (the table is then built per process).
pub fn srgb_table() -> &'static RgbToSpectrumTable {
    static TABLE: OnceLock<RgbToSpectrumTable> = OnceLock::new();
    TABLE.get_or_init(|| match cache_dir() {
        Some(dir) => {
            let name = format!("rgb2spec_srgb_v{TABLE_FILE_VERSION}_{SRGB_TABLE_RESOLUTION}.bin");
            RgbToSpectrumTable::load_or_build(&dir.join(name), SRGB_TABLE_RESOLUTION)
        }
        None => RgbToSpectrumTable::build(SRGB_TABLE_RESOLUTION),
    })
}

/// Where gonio keeps tables it computes once: `$GONIO_CACHE_DIR` (set but empty: nowhere), else
/// `$XDG_CACHE_HOME/gonio`, else `$HOME/.cache/gonio` (the XDG base directory convention).
#[must_use]
pub fn cache_dir() -> Option<std::path::PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty()).map(std::path::PathBuf::from);
    if let Some(dir) = std::env::var_os("GONIO_CACHE_DIR") {
        return (!dir.is_empty()).then(|| dir.into());
    }
    var("XDG_CACHE_HOME").or_else(|| var("HOME").map(|h| h.join(".cache"))).map(|d| d.join("gonio"))
}

/// A bounded RGB reflectance as a spectrum in [0, 1] (components clamped to [0, 1] first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbReflectanceSpectrum {
    polynomial: SigmoidPolynomial,
}

impl RgbReflectanceSpectrum {
    /// The spectrum of `rgb` by [`srgb_table`]'s [`RgbToSpectrumTable::fit`].
    #[must_use]
    pub fn new(rgb: Rgb) -> Self {
        RgbReflectanceSpectrum { polynomial: srgb_table().fit(rgb) }
    }

    /// The sigmoid polynomial.
    #[must_use]
    pub fn polynomial(&self) -> SigmoidPolynomial {
        self.polynomial
    }

    /// The reflectance at `lambda` nm.
    #[inline]
    #[must_use]
    pub fn eval(&self, lambda: f32) -> f32 {
        self.polynomial.eval(lambda)
    }
}

/// scale = 2 · max(rgb) and the sigmoid polynomial of rgb / scale (Mitsuba 3, pbrt-v4); negative
/// components count as 0.
fn scaled_fit(rgb: Rgb) -> (f32, SigmoidPolynomial) {
    let rgb = rgb.map(|v| v.max(0.0));
    let scale = 2.0 * rgb.max_component();
    if !(scale > 0.0) || !scale.is_finite() {
        return (0.0, SigmoidPolynomial::BLACK);
    }
    (scale, srgb_table().fit(rgb / scale))
}

/// An unbounded RGB value as scale × a sigmoid polynomial (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbUnboundedSpectrum {
    scale: f32,
    polynomial: SigmoidPolynomial,
}

impl RgbUnboundedSpectrum {
    /// The spectrum of `rgb` (any non-negative values).
    #[must_use]
    pub fn new(rgb: Rgb) -> Self {
        let (scale, polynomial) = scaled_fit(rgb);
        RgbUnboundedSpectrum { scale, polynomial }
    }

    /// 2 · max(rgb).
    #[must_use]
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// The sigmoid polynomial of rgb / scale.
    #[must_use]
    pub fn polynomial(&self) -> SigmoidPolynomial {
        self.polynomial
    }

    /// The value at `lambda` nm.
    #[inline]
    #[must_use]
    pub fn eval(&self, lambda: f32) -> f32 {
        self.eval_lanes(lambda)
    }

    /// [`RgbUnboundedSpectrum::eval`] in lanes (which is this at one lane).
    #[inline(always)]
    #[must_use]
    pub fn eval_lanes<R: Real>(&self, lambda: R) -> R {
        self.polynomial.eval_lanes(lambda) * self.scale
    }
}

/// An RGB emission as scale × a sigmoid polynomial × D65 (module docs): Mitsuba 3's spectrum of an RGB
/// `radiance` — [`RgbUnboundedSpectrum`] times D65.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbIlluminantSpectrum(RgbUnboundedSpectrum);

impl RgbIlluminantSpectrum {
    /// The spectrum of the emission `rgb` (any non-negative values).
    #[must_use]
    pub fn new(rgb: Rgb) -> Self {
        RgbIlluminantSpectrum(RgbUnboundedSpectrum::new(rgb))
    }

    /// The scaled sigmoid polynomial that D65 multiplies.
    #[must_use]
    pub fn unbounded(&self) -> RgbUnboundedSpectrum {
        self.0
    }

    /// The radiance at `lambda` nm.
    #[inline]
    #[must_use]
    pub fn eval(&self, lambda: f32) -> f32 {
        self.eval_lanes(lambda)
    }

    /// [`RgbIlluminantSpectrum::eval`] in lanes (which is this at one lane).
    #[inline(always)]
    #[must_use]
    pub fn eval_lanes<R: Real>(&self, lambda: R) -> R {
        self.0.eval_lanes(lambda) * d65_at(lambda)
    }
}
