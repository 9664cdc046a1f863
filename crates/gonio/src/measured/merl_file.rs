//! The MERL BRDF file (Matusik, Pfister, Brand & McMillan 2003, "A Data-Driven Reflectance Model",
//! SIGGRAPH; the 100 isotropic materials of the MERL database): reading, writing, and the table lookups.
//!
//! # The layout (checked against MERL's published reader `BRDFRead.cpp`)
//! | bytes                      | what                                                               |
//! |----------------------------|--------------------------------------------------------------------|
//! | 0..12                      | three little-endian `int32`: the dimensions 90, 90, 180             |
//! | 12..12 + 8n                | red: n = 90·90·180 = 1,458,000 little-endian `float64`             |
//! | then 8n, then 8n           | green, blue                                                        |
//!
//! 34,992,012 bytes in all. Entry `i = iφd + 180 (iθd + 90 iθh)` of a block holds f/scale, with the
//! channel scales (1/1500, 1.15/1500, 1.66/1500) for red, green, blue: f = entry · scale in sr⁻¹.
//! The indices are those of Rusinkiewicz's half/difference angles (1998): for a pair of directions with
//! half vector ωh = (θh, φh) and the incident direction expressed in the frame of ωh as (θd, φd),
//! - iθh = ⌊√(θh / (π/2)) · 90⌋ — the non-linear mapping that spends the resolution near the specular
//!   peak (the first cell covers θh < 0.011°);
//! - iθd = ⌊θd / (π/2) · 90⌋;
//! - iφd = ⌊φd / π · 180⌋ with φd brought into [0, π) by adding π to negative angles: reciprocity
//!   f(ωo, ωi) = f(ωi, ωo) exchanges the two directions, which turns φd into φd + π, so half the circle
//!   is stored;
//! - φh is ignored: the materials are isotropic.
//!
//! every index clamped to its range. Negative entries mark configurations that were not measured (the
//! reader's comment says "below horizon").
//!
//! # Reading
//! [`MerlTable::read`] streams the file through a 1 MiB buffer into one `f32` array (17.5 MB, half the
//! file; the three channels of a cell side by side so that a lookup touches one cache line per cell).
//! Any NaN or infinite entry is an error naming its byte offset and cell; a file whose every cell is
//! negative is an error. Cells that were not measured (any channel negative) are filled, so that no
//! negative value reaches a lookup: breadth-first from the measured cells, each unmeasured cell takes the
//! mean of its already-known neighbours (±1 along each axis, φd wrapping around). Near the horizon this
//! continues the measured values outwards rather than dropping to black, so interpolation next to an
//! unmeasured region stays accurate. The writer writes −1 to the cells that were filled.
//!
//! Cost (2026-11, a 34,992,012-byte file written by `gonio measure`, warm page cache, loaded through
//! `gonio.load_bsdf` as the `merl` BSDF, i.e. read + fill + the sampling tables): 60–62 ms of CPU time
//! over all threads (10 loads; wall time 316–360 ms on the shared 2-core machine at load average 18),
//! and the process's peak resident memory grows by 24 MiB (the 17.5 MB table plus the sampling tables).
//!
//! # Lookups
//! - **nearest** (`interpolation = "nearest"`) is the reference reader's: the floor of each index.
//! - **trilinear** (the default) reads each entry as the value at the centre of its cell in the index
//!   coordinates (xθh = √(θh/(π/2))·90, xθd = θd/(π/2)·90, xφd = φd/π·180; cell i spans [i, i + 1)) and
//!   interpolates between the eight surrounding centres, clamped at the ends of θh and θd and wrapping
//!   around in φd (period π). A table made by [`crate::measured::gonioreflectometer`] stores cell
//!   averages, whose centre value they equal up to second order.
//!
//! Both are reciprocal bit for bit: θh and θd are computed symmetrically in ωo and ωi, and φd from the
//! difference ωi − ωo, which the exchange negates exactly; negation is undone by the folding into [0, π).

use crate::error::{Error, Result};
use crate::math::Vec3;
use crate::spectrum::Rgb;
use std::f64::consts::{FRAC_PI_2, PI};
use std::io::Read;
use std::path::Path;

/// Cells along θh, θd and φd.
pub const RES_THETA_H: usize = 90;
pub const RES_THETA_D: usize = 90;
pub const RES_PHI_D: usize = 180;
/// Cells of one channel block: 1,458,000.
pub const CELLS: usize = RES_THETA_H * RES_THETA_D * RES_PHI_D;
/// The size of every MERL file: 12 header bytes and three blocks of `CELLS` doubles.
pub const FILE_SIZE: u64 = 12 + 3 * 8 * CELLS as u64;
/// f = entry · scale, per channel (red, green, blue), as in MERL's reader.
pub const CHANNEL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// Index of cell (iθh, iθd, iφd) in a channel block.
#[inline]
#[must_use]
pub const fn cell_index(ih: usize, id: usize, ip: usize) -> usize {
    ip + RES_PHI_D * (id + RES_THETA_D * ih)
}

/// How a table is read between its entries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The cell's value (the floor of each index), as MERL's reader does.
    Nearest,
    /// Trilinear between cell centres (see the module docs).
    Trilinear,
}

impl Interpolation {
    #[must_use]
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "nearest" => Some(Interpolation::Nearest),
            "trilinear" => Some(Interpolation::Trilinear),
            _ => None,
        }
    }
}

/// Rusinkiewicz's half/difference angles of a pair of directions (isotropic: φh dropped), with φd
/// folded into [0, π) by reciprocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfDiff {
    pub theta_h: f32,
    pub theta_d: f32,
    pub phi_d: f32,
}

impl HalfDiff {
    /// The half/difference angles of `wo`, `wi` (both above the surface; `None` otherwise). Symmetric in
    /// the two directions bit for bit (see the module docs).
    #[must_use]
    pub fn from_directions(wo: Vec3, wi: Vec3) -> Option<HalfDiff> {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return None;
        }
        // Scaled by its largest component first: for subnormal grazing pairs (ωi ≈ −ωo on the horizon)
        // |ωo + ωi|² underflows to 0 and ωh would be NaN (2026-11, found by the NaN sweep).
        let sum = wo + wi;
        let sum = sum / sum.abs().max_element();
        let wh = sum / sum.length();
        // Angles by atan2 rather than acos: acos loses half the digits near 0, where the specular peak is
        // (2026-11: acos(f32) put θh = 0.01 off by 3e-3 of a cell).
        let rho = (wh.x * wh.x + wh.y * wh.y).sqrt();
        let theta_h = rho.atan2(wh.z);
        // cos θd = ωo·ωh = ωi·ωh (averaged so that the order does not matter); sin θd = |ωi − ωo|/2.
        let cos_d = 0.5 * (wo.dot(wh) + wi.dot(wh));
        let d = wi - wo;
        let theta_d = (0.5 * d.length()).atan2(cos_d);
        // The frame of ωh: t = ∂ωh/∂θh, b = ∂ωh/∂φh / sin θh (φh = 0 at the pole, as atan2(0, 0) = 0).
        let (cos_phi_h, sin_phi_h) = if rho > 0.0 { (wh.x / rho, wh.y / rho) } else { (1.0, 0.0) };
        let t = Vec3::new(wh.z * cos_phi_h, wh.z * sin_phi_h, -rho);
        let b = Vec3::new(-sin_phi_h, cos_phi_h, 0.0);
        // The difference vector of ωi is the mirror image of ωo's about ωh: (ωi − ωo)/2 is its tangential part.
        let (mut x, mut y) = (d.dot(t), d.dot(b));
        // Reciprocity: φd and φd + π are one configuration; fold by negation (exact) into [0, π).
        if y < 0.0 || (y == 0.0 && x < 0.0) {
            x = -x;
            y = -y;
        }
        let mut phi_d = y.atan2(x);
        if phi_d >= std::f32::consts::PI {
            phi_d = 0.0;
        }
        Some(HalfDiff { theta_h, theta_d, phi_d })
    }

    /// The continuous index coordinates (xθh, xθd, xφd); cell i spans [i, i + 1).
    #[inline]
    #[must_use]
    pub fn coordinates(self) -> [f32; 3] {
        [
            (self.theta_h.max(0.0) / std::f32::consts::FRAC_PI_2).sqrt() * RES_THETA_H as f32,
            self.theta_d / std::f32::consts::FRAC_PI_2 * RES_THETA_D as f32,
            self.phi_d / std::f32::consts::PI * RES_PHI_D as f32,
        ]
    }
}

/// The directions (ωo, ωi) of the configuration at index coordinates (xθh, xθd, xφd), with φh = 0; the
/// inverse of [`HalfDiff::from_directions`] followed by [`HalfDiff::coordinates`]. In f64 (table building).
#[must_use]
pub fn directions_at(x_h: f64, x_d: f64, x_p: f64) -> (glam::DVec3, glam::DVec3) {
    let theta_h = FRAC_PI_2 * (x_h / RES_THETA_H as f64).powi(2);
    let theta_d = FRAC_PI_2 * x_d / RES_THETA_D as f64;
    let phi_d = PI * x_p / RES_PHI_D as f64;
    let (sd, cd) = theta_d.sin_cos();
    let (sp, cp) = phi_d.sin_cos();
    // ωi in the frame of ωh, and ωo its mirror image about ωh.
    let di = glam::DVec3::new(sd * cp, sd * sp, cd);
    let d_o = glam::DVec3::new(-di.x, -di.y, di.z);
    // Rotate the frame of ωh back about the y axis by θh.
    let (sh, ch) = theta_h.sin_cos();
    let rot = |v: glam::DVec3| glam::DVec3::new(ch * v.x + sh * v.z, v.y, -sh * v.x + ch * v.z);
    (rot(d_o), rot(di))
}

/// A MERL table in memory: f in sr⁻¹ as `f32`, the three channels of a cell side by side, every cell
/// measured or filled (see the module docs).
#[derive(Clone, PartialEq)]
pub struct MerlTable {
    /// 3 · `CELLS` values, `values[3 · cell_index(..) + channel]`.
    values: Vec<f32>,
    /// Cells that were not measured (filled from their neighbours), ascending.
    unmeasured: Vec<u32>,
    /// Where the table came from, for messages.
    source: String,
}

impl std::fmt::Debug for MerlTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MerlTable({}, {} of {CELLS} cells not measured)", self.source, self.unmeasured.len())
    }
}

impl MerlTable {
    /// A table from `3 · CELLS` interleaved values of f (sr⁻¹); a cell with any negative channel is
    /// "not measured" and is filled. `source` names the table in errors. Fails on NaN/Inf, on the wrong
    /// length, and when no cell is measured.
    pub fn from_values(mut values: Vec<f32>, source: &str) -> Result<MerlTable> {
        let bad = |msg: String| Error::Format { path: source.into(), at: "table".into(), message: msg };
        if values.len() != 3 * CELLS {
            return Err(bad(format!("{} values, expected 3 × {CELLS}", values.len())));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            let (ih, id, ip) = cell_of(i / 3);
            return Err(bad(format!("value {} at cell (θh {ih}, θd {id}, φd {ip}) channel {} is not finite", values[i], i % 3)));
        }
        let unmeasured = fill_unmeasured(&mut values).map_err(bad)?;
        Ok(MerlTable { values, unmeasured, source: source.into() })
    }

    /// Read a MERL `.binary` file (see the module docs for the layout and the checks).
    pub fn read(path: &Path) -> Result<MerlTable> {
        let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        MerlTable::from_reader(path, std::io::BufReader::with_capacity(1 << 20, file), len)
    }

    /// Read the content of a MERL file, `len` bytes long, from `reader`; `path` names it in errors.
    pub fn from_reader(path: &Path, mut reader: impl Read, len: u64) -> Result<MerlTable> {
        let mut header = [0u8; 12];
        if len < 12 {
            return Err(Error::format(path, "byte 0", format!("{len} bytes: too short for a MERL BRDF file (expected {FILE_SIZE} bytes)")));
        }
        reader.read_exact(&mut header).map_err(|e| Error::io(path, e))?;
        let dims: Vec<i32> = header.chunks_exact(4).map(|c| i32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        if dims != [RES_THETA_H as i32, RES_THETA_D as i32, RES_PHI_D as i32] {
            return Err(Error::format(
                path,
                "byte 0",
                format!("dimensions ({}, {}, {}), expected (90, 90, 180): not a MERL BRDF file", dims[0], dims[1], dims[2]),
            ));
        }
        if len != FILE_SIZE {
            let what = if len < FILE_SIZE { "truncated" } else { "trailing data" };
            return Err(Error::format(
                path,
                format!("byte {}", len.min(FILE_SIZE)),
                format!("{what}: the file has {len} bytes, expected {FILE_SIZE}"),
            ));
        }
        let mut values = vec![0f32; 3 * CELLS];
        let mut buf = vec![0u8; 1 << 20];
        for (channel, scale) in CHANNEL_SCALE.iter().enumerate() {
            let mut cell = 0;
            while cell < CELLS {
                let count = (CELLS - cell).min(buf.len() / 8);
                let chunk = &mut buf[..count * 8];
                reader.read_exact(chunk).map_err(|e| Error::io(path, e))?;
                for (k, bytes) in chunk.chunks_exact(8).enumerate() {
                    let v = f64::from_le_bytes(bytes.try_into().expect("8 bytes"));
                    let f = (v * scale) as f32;
                    if !f.is_finite() {
                        let i = cell + k;
                        let (ih, id, ip) = cell_of(i);
                        let byte = 12 + 8 * (channel * CELLS + i);
                        return Err(Error::format(
                            path,
                            format!("byte {byte}"),
                            format!(
                                "entry {v} of cell (θh {ih}, θd {id}, φd {ip}), {} channel, is not a finite number",
                                ["red", "green", "blue"][channel]
                            ),
                        ));
                    }
                    values[3 * (cell + k) + channel] = f;
                }
                cell += count;
            }
        }
        let unmeasured = fill_unmeasured(&mut values).map_err(|m| Error::format(path, "data", m))?;
        Ok(MerlTable { values, unmeasured, source: path.display().to_string() })
    }

    /// Write the table as a MERL `.binary` file, atomically; cells that were not measured get −1.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut bytes = Vec::with_capacity(FILE_SIZE as usize);
        for d in [RES_THETA_H, RES_THETA_D, RES_PHI_D] {
            bytes.extend_from_slice(&(d as i32).to_le_bytes());
        }
        let mut unmeasured = vec![false; CELLS];
        for &i in &self.unmeasured {
            unmeasured[i as usize] = true;
        }
        for (channel, scale) in CHANNEL_SCALE.iter().enumerate() {
            for (i, missing) in unmeasured.iter().enumerate() {
                let v = if *missing { -1.0 } else { f64::from(self.values[3 * i + channel]) / scale };
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        crate::image::write_atomically(path, &bytes)
    }

    /// Where the table came from.
    #[must_use]
    pub fn source(&self) -> &str {
        &self.source
    }

    /// How many cells were not measured (and were filled).
    #[must_use]
    pub fn unmeasured_cells(&self) -> usize {
        self.unmeasured.len()
    }

    /// The value of cell (iθh, iθd, iφd).
    #[inline]
    #[must_use]
    pub fn cell(&self, ih: usize, id: usize, ip: usize) -> Rgb {
        let i = 3 * cell_index(ih, id, ip);
        Rgb::new(self.values[i], self.values[i + 1], self.values[i + 2])
    }

    /// f(ωo, ωi) read from the table (zero unless both directions are above the surface).
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3, interpolation: Interpolation) -> Rgb {
        let Some(hd) = HalfDiff::from_directions(wo, wi) else { return Rgb::ZERO };
        let x = hd.coordinates();
        match interpolation {
            Interpolation::Nearest => {
                let ih = (x[0] as usize).min(RES_THETA_H - 1);
                let id = (x[1] as usize).min(RES_THETA_D - 1);
                let ip = (x[2] as usize).min(RES_PHI_D - 1);
                self.cell(ih, id, ip)
            }
            Interpolation::Trilinear => self.trilinear(x),
        }
    }

    /// Trilinear interpolation between cell centres at index coordinates `x` (see the module docs).
    #[must_use]
    pub fn trilinear(&self, x: [f32; 3]) -> Rgb {
        // Clamped axes: the two centres around x − 1/2 and the weight of the upper one.
        let clamped = |x: f32, n: usize| -> (usize, usize, f32) {
            let t = (x - 0.5).clamp(0.0, (n - 1) as f32);
            let i0 = (t as usize).min(n - 2);
            (i0, i0 + 1, t - i0 as f32)
        };
        let (h0, h1, wh) = clamped(x[0], RES_THETA_H);
        let (d0, d1, wd) = clamped(x[1], RES_THETA_D);
        // φd wraps: centres at i + 1/2 modulo 180.
        let t = x[2] - 0.5;
        let fl = t.floor();
        let wp = t - fl;
        let p0 = (fl as i32).rem_euclid(RES_PHI_D as i32) as usize;
        let p1 = (p0 + 1) % RES_PHI_D;
        let mut acc = [0f32; 3];
        for (ih, w_h) in [(h0, 1.0 - wh), (h1, wh)] {
            for (id, w_d) in [(d0, 1.0 - wd), (d1, wd)] {
                for (ip, w_p) in [(p0, 1.0 - wp), (p1, wp)] {
                    let w = w_h * w_d * w_p;
                    let i = 3 * cell_index(ih, id, ip);
                    acc[0] += w * self.values[i];
                    acc[1] += w * self.values[i + 1];
                    acc[2] += w * self.values[i + 2];
                }
            }
        }
        Rgb::new(acc[0], acc[1], acc[2])
    }

    /// The raw interleaved values (3 per cell).
    #[must_use]
    pub fn values(&self) -> &[f32] {
        &self.values
    }
}

/// (iθh, iθd, iφd) of a cell index.
#[must_use]
pub const fn cell_of(i: usize) -> (usize, usize, usize) {
    (i / (RES_PHI_D * RES_THETA_D), (i / RES_PHI_D) % RES_THETA_D, i % RES_PHI_D)
}

/// Fill the cells with a negative channel breadth-first from the measured ones (see the module docs);
/// returns the filled cells. Fails when no cell is measured.
fn fill_unmeasured(values: &mut [f32]) -> std::result::Result<Vec<u32>, String> {
    let missing = |v: &[f32], i: usize| v[3 * i] < 0.0 || v[3 * i + 1] < 0.0 || v[3 * i + 2] < 0.0;
    let unmeasured: Vec<u32> = (0..CELLS).filter(|&i| missing(values, i)).map(|i| i as u32).collect();
    if unmeasured.is_empty() {
        return Ok(unmeasured);
    }
    if unmeasured.len() == CELLS {
        return Err(format!("every one of the {CELLS} cells is negative (not measured): there is no BRDF in this file"));
    }
    // known[i]: measured, or filled in an earlier layer.
    let mut known = vec![true; CELLS];
    for &i in &unmeasured {
        known[i as usize] = false;
    }
    let neighbours = |i: usize| {
        let (ih, id, ip) = cell_of(i);
        let mut n = [usize::MAX; 6];
        if ih > 0 {
            n[0] = cell_index(ih - 1, id, ip);
        }
        if ih + 1 < RES_THETA_H {
            n[1] = cell_index(ih + 1, id, ip);
        }
        if id > 0 {
            n[2] = cell_index(ih, id - 1, ip);
        }
        if id + 1 < RES_THETA_D {
            n[3] = cell_index(ih, id + 1, ip);
        }
        n[4] = cell_index(ih, id, (ip + RES_PHI_D - 1) % RES_PHI_D);
        n[5] = cell_index(ih, id, (ip + 1) % RES_PHI_D);
        n
    };
    let mut frontier: Vec<usize> =
        unmeasured.iter().map(|&i| i as usize).filter(|&i| neighbours(i).iter().any(|&n| n != usize::MAX && known[n])).collect();
    let mut queued = vec![false; CELLS];
    for &i in &frontier {
        queued[i] = true;
    }
    while !frontier.is_empty() {
        // Every cell of a layer takes the mean of neighbours known before the layer began.
        let fills: Vec<[f32; 3]> = frontier
            .iter()
            .map(|&i| {
                let (mut sum, mut count) = ([0f32; 3], 0.0f32);
                for n in neighbours(i).into_iter().filter(|&n| n != usize::MAX && known[n]) {
                    for c in 0..3 {
                        sum[c] += values[3 * n + c];
                    }
                    count += 1.0;
                }
                sum.map(|s| s / count)
            })
            .collect();
        let mut next = Vec::new();
        for (&i, v) in frontier.iter().zip(&fills) {
            values[3 * i..3 * i + 3].copy_from_slice(v);
            known[i] = true;
        }
        for &i in &frontier {
            for n in neighbours(i) {
                if n != usize::MAX && !known[n] && !queued[n] {
                    queued[n] = true;
                    next.push(n);
                }
            }
        }
        frontier = next;
    }
    Ok(unmeasured)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::BsdfModel;
    use crate::measured::fixtures::{scratch_dir, smooth};
    use crate::sampling::Pcg32;

    /// A direction above the surface with θ ≤ `max_deg`, uniform in solid angle.
    fn direction(rng: &mut Pcg32, max_deg: f32) -> Vec3 {
        let cos_max = max_deg.to_radians().cos();
        let z = 1.0 - rng.next_f32() * (1.0 - cos_max);
        let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// MERL's indexing written out independently in f64: ωh and its spherical angles, the incident
    /// direction rotated by −φh about z and by −θh about y, then the three index formulas.
    fn reference_index(wo: Vec3, wi: Vec3) -> (usize, usize, usize) {
        let (o, i) = (wo.as_dvec3(), wi.as_dvec3());
        let h = (o + i).normalize();
        let theta_h = h.z.acos();
        let phi_h = h.y.atan2(h.x);
        let rz = |v: glam::DVec3, a: f64| glam::DVec3::new(v.x * a.cos() - v.y * a.sin(), v.x * a.sin() + v.y * a.cos(), v.z);
        let ry = |v: glam::DVec3, a: f64| glam::DVec3::new(v.x * a.cos() + v.z * a.sin(), v.y, -v.x * a.sin() + v.z * a.cos());
        let d = ry(rz(i, -phi_h), -theta_h);
        let theta_d = d.z.clamp(-1.0, 1.0).acos();
        let mut phi_d = d.y.atan2(d.x);
        if phi_d < 0.0 {
            phi_d += PI;
        }
        let ih = if theta_h <= 0.0 { 0 } else { ((theta_h / FRAC_PI_2 * 90.0 * 90.0).sqrt() as usize).min(89) };
        let id = ((theta_d / FRAC_PI_2 * 90.0) as usize).min(89);
        let ip = ((phi_d / PI * 180.0) as usize).min(179);
        (ih, id, ip)
    }

    /// A table whose cell (iθh, iθd, iφd) holds its own index in every channel.
    fn index_table() -> MerlTable {
        let values: Vec<f32> = (0..CELLS).flat_map(|i| [i as f32; 3]).collect();
        MerlTable::from_values(values, "index table").unwrap()
    }

    #[test]
    fn nearest_lookup_is_the_reference_indexing() {
        let table = index_table();
        let mut rng = Pcg32::new(3, 1);
        let (n, mut off) = (100_000, 0);
        for _ in 0..n {
            let (wo, wi) = (direction(&mut rng, 89.0), direction(&mut rng, 89.0));
            let got = table.eval(wo, wi, Interpolation::Nearest).r() as usize;
            let (ih, id, ip) = reference_index(wo, wi);
            if got != cell_index(ih, id, ip) {
                off += 1;
                // f32 against f64: only a rounding across one cell boundary may differ.
                let (gh, gd, gp) = cell_of(got);
                let dp = (gp as i32 - ip as i32).rem_euclid(180).min((ip as i32 - gp as i32).rem_euclid(180));
                assert!(gh.abs_diff(ih) + gd.abs_diff(id) + dp as usize <= 1, "{wo} {wi}: {:?} vs {:?}", cell_of(got), (ih, id, ip));
            }
        }
        eprintln!("nearest lookup: {off} of {n} pairs differ from the f64 reference by one cell (boundary rounding)");
        assert!(off < n / 1000, "{off}");
    }

    #[test]
    fn half_diff_coordinates_invert_directions_at() {
        let mut rng = Pcg32::new(5, 2);
        for _ in 0..10_000 {
            let x = [1.0 + 88.0 * rng.next_f64(), 1.0 + 88.0 * rng.next_f64(), 180.0 * rng.next_f64()];
            let (wo, wi) = directions_at(x[0], x[1], x[2]);
            if wo.z <= 1e-3 || wi.z <= 1e-3 {
                continue;
            }
            let hd = HalfDiff::from_directions(wo.as_vec3(), wi.as_vec3()).unwrap();
            let c = hd.coordinates();
            let dp = ((c[2] as f64 - x[2]).rem_euclid(180.0)).min((x[2] - c[2] as f64).rem_euclid(180.0));
            // In angles: the f32 rounding of the directions (6e-8) amplified by at most ~1/cos θd ≈ 20.
            let theta_h = FRAC_PI_2 * (x[0] / 90.0).powi(2);
            let theta_d = FRAC_PI_2 * x[1] / 90.0;
            assert!(
                (f64::from(hd.theta_h) - theta_h).abs() < 2e-6 && (f64::from(hd.theta_d) - theta_d).abs() < 2e-6 && dp < 1e-3,
                "{x:?} → {c:?}"
            );
        }
    }

    #[test]
    fn lookups_are_reciprocal_bit_for_bit() {
        let (_, _, table) = smooth();
        let mut rng = Pcg32::new(9, 3);
        for _ in 0..100_000 {
            let (wo, wi) = (direction(&mut rng, 90.0), direction(&mut rng, 90.0));
            for interp in [Interpolation::Nearest, Interpolation::Trilinear] {
                assert_eq!(table.eval(wo, wi, interp), table.eval(wi, wo, interp), "{wo} {wi}");
            }
        }
    }

    /// The reader against the analytic model it was made from, at 2·10⁴ random pairs with θ ≤ 80°.
    ///
    /// The bound: the table holds f at the cell centres (k = 1), so the only error is trilinear
    /// interpolation's, |f − f̃| ≤ Σₖ (1/8) max|∂²f/∂xₖ²| (Taylor, unit spacing in index coordinates), where
    /// the second derivative along each axis is estimated by the table's second differences at the eight
    /// stencil corners, doubled because it varies between them; where an axis is clamped (within half a
    /// cell of θh = 0 or θd = 90°) the error is first order: ½ |first difference|. Plus f32 rounding (1e-5
    /// relative) and the f32 angle arithmetic (2e-4 relative of the slopes).
    #[test]
    fn reader_matches_the_analytic_model_within_the_interpolation_bound() {
        let (model, _, table) = smooth();
        let v = |ih: usize, id: usize, ip: usize| table.cell(ih, id, ip.rem_euclid(RES_PHI_D)).max_component();
        let mut rng = Pcg32::new(11, 4);
        let (mut checked, mut worst_ratio, mut rel_sum) = (0usize, 0f64, 0f64);
        while checked < 20_000 {
            let (wo, wi) = (direction(&mut rng, 80.0), direction(&mut rng, 80.0));
            let x = HalfDiff::from_directions(wo, wi).unwrap().coordinates();
            let exact = model.f(wo, wi).max_component() as f64;
            let got = table.eval(wo, wi, Interpolation::Trilinear).max_component() as f64;
            // The stencil's cells (with φd wrapping).
            let lo = |x: f32, n: usize| ((x - 0.5).floor().clamp(0.0, (n - 2) as f32)) as usize;
            let (h0, d0) = (lo(x[0], RES_THETA_H), lo(x[1], RES_THETA_D));
            let p0 = ((x[2] - 0.5).floor() as i32).rem_euclid(180) as usize;
            let mut bound = 0f64;
            let (mut dh, mut dd, mut dp, mut g) = (0f32, 0f32, 0f32, 0f32);
            for ih in [h0, h0 + 1] {
                for id in [d0, d0 + 1] {
                    for ip in [p0, p0 + 1] {
                        let c = v(ih, id, ip);
                        if ih > 0 && ih + 1 < RES_THETA_H {
                            dh = dh.max((v(ih - 1, id, ip) - 2.0 * c + v(ih + 1, id, ip)).abs());
                        }
                        if id > 0 && id + 1 < RES_THETA_D {
                            dd = dd.max((v(ih, id - 1, ip) - 2.0 * c + v(ih, id + 1, ip)).abs());
                        }
                        dp = dp.max((v(ih, id, ip + 179) - 2.0 * c + v(ih, id, ip + 1)).abs());
                        let slope_h = (v((ih + 1).min(89), id, ip) - c).abs();
                        let slope_d = (v(ih, (id + 1).min(89), ip) - c).abs();
                        g = g.max(slope_h).max(slope_d).max((v(ih, id, ip + 1) - c).abs());
                        if x[0] < 0.5 || x[1] > 89.5 {
                            bound = bound.max(0.5 * slope_h.max(slope_d) as f64);
                        }
                    }
                }
            }
            bound += 2.0 * (dh + dd + dp) as f64 / 8.0 + 1e-5 * exact + 2e-4 * g as f64;
            let err = (got - exact).abs();
            assert!(err <= bound, "wo={wo} wi={wi} x={x:?}: table {got}, analytic {exact}, error {err} > bound {bound}");
            worst_ratio = worst_ratio.max(err / bound);
            rel_sum += err / exact.max(1e-3);
            checked += 1;
        }
        eprintln!(
            "reader vs analytic: {checked} pairs, mean relative error {:.2e}, worst error/bound {worst_ratio:.3}",
            rel_sum / checked as f64
        );
        assert!(rel_sum / (checked as f64) < 5e-3);
    }

    #[test]
    fn written_and_read_tables_agree() {
        let (model, path, read) = smooth();
        assert_eq!(std::fs::metadata(path).unwrap().len(), FILE_SIZE);
        let again = crate::measured::gonioreflectometer::measure(model, 1, "again").unwrap();
        assert_eq!(again.unmeasured_cells(), read.unmeasured_cells());
        // f32 → f64 / scale → f64 · scale → f32 is exact to within one f32 rounding.
        let worst = again.values().iter().zip(read.values()).map(|(a, b)| ((a - b) / a.abs().max(1e-30)).abs()).fold(0f32, f32::max);
        assert!(worst <= f32::EPSILON, "{worst}");
        assert!(read.unmeasured_cells() > 0, "cells below the horizon are written as not measured");
        assert!(read.values().iter().all(|v| *v >= 0.0));
    }

    fn write_raw(name: &str, dims: [i32; 3], blocks: &dyn Fn(usize, usize) -> f64, cells: usize) -> std::path::PathBuf {
        let mut bytes = Vec::new();
        for d in dims {
            bytes.extend_from_slice(&d.to_le_bytes());
        }
        for c in 0..3 {
            for i in 0..cells {
                bytes.extend_from_slice(&blocks(c, i).to_le_bytes());
            }
        }
        let path = scratch_dir().join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn bad_files_are_clear_errors() {
        let dims = [90, 90, 180];
        let cases: Vec<(std::path::PathBuf, &str)> = vec![
            (write_raw("dims.binary", [90, 180, 90], &|_, _| 1.0, CELLS), "dimensions (90, 180, 90), expected (90, 90, 180)"),
            (write_raw("short.binary", dims, &|_, _| 1.0, CELLS - 10), "truncated: the file has 34991772 bytes, expected 34992012"),
            (write_raw("long.binary", dims, &|_, _| 1.0, CELLS + 1), "trailing data"),
            (write_raw("nan.binary", dims, &|c, i| if c == 1 && i == 777 { f64::NAN } else { 1.0 }, CELLS), "byte 11670228"),
            (write_raw("neg.binary", dims, &|_, _| -1.0, CELLS), "every one of the 1458000 cells is negative"),
            (write_raw("tiny.binary", dims, &|_, _| 1.0, 0), "truncated"),
        ];
        for (path, expect) in cases {
            let err = MerlTable::read(&path).unwrap_err().to_string();
            assert!(err.contains(expect) && err.contains(path.to_str().unwrap()), "{}: {err}", path.display());
        }
        let nan = MerlTable::read(&scratch_dir().join("nan.binary")).unwrap_err().to_string();
        assert!(nan.contains("green") && nan.contains("(θh 0, θd 4, φd 57)"), "{nan}");
        let three = scratch_dir().join("three.binary");
        std::fs::write(&three, [0u8; 3]).unwrap();
        assert!(MerlTable::read(&three).unwrap_err().to_string().contains("too short"));
        assert!(MerlTable::read(Path::new("/no/such.binary")).unwrap_err().to_string().contains("/no/such.binary"));
    }

    #[test]
    fn unmeasured_cells_are_filled_from_measured_neighbours() {
        // Measured only for θd < 45 (value = 2 + iθh/100 in scaled units); the rest is −1.
        let path = write_raw(
            "half.binary",
            [90, 90, 180],
            &|c, i| {
                let (ih, id, _) = cell_of(i);
                if id < 45 {
                    (2.0 + ih as f64 / 100.0) / CHANNEL_SCALE[c]
                } else {
                    -1.0
                }
            },
            CELLS,
        );
        let t = MerlTable::read(&path).unwrap();
        assert_eq!(t.unmeasured_cells(), CELLS / 2);
        for (ih, id, ip) in [(0, 60, 3), (50, 89, 179), (89, 45, 0)] {
            let v = t.cell(ih, id, ip);
            let expect = 2.0 + ih as f32 / 100.0;
            assert!((v.r() - expect).abs() < 1e-5 && (v.b() - expect).abs() < 1e-5, "{v:?} vs {expect}");
        }
        // Written back, the filled cells are "not measured" again.
        let out = scratch_dir().join("half-out.binary");
        t.write(&out).unwrap();
        let bytes = std::fs::read(&out).unwrap();
        let entry = |i: usize| f64::from_le_bytes(bytes[12 + 8 * i..20 + 8 * i].try_into().unwrap());
        assert_eq!(entry(cell_index(3, 70, 5)), -1.0);
        assert!((entry(cell_index(3, 10, 5)) * CHANNEL_SCALE[0] - 2.03).abs() < 1e-6);
    }
}
