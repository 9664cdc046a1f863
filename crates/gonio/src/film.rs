//! `hdrfilm` with a box filter: each pixel is the mean of its samples, accumulated in f64.
//!
//! | parameter          | type    | default | meaning                                           |
//! |--------------------|---------|---------|---------------------------------------------------|
//! | `width`, `height`  | integer | 768, 576| resolution                                        |
//! | `pixel_format`     | string  | rgb     | accepted (gonio writes RGB)                       |
//! | `component_format` | string  | float16 | accepted (the output format follows the file name) |
//! | nested `rfilter`   | plugin  | box     | `box`; others are rendered with a box and a warning |
//!
//! A non-finite sample is dropped and counted: it adds nothing to the sum but still counts in the
//! denominator (the pixel stays an unbiased estimate if such samples are rare; 2026-11).

use crate::error::{Error, Result};
use crate::props::Props;
use crate::spectrum::Rgb;

/// The film's size, read from an `hdrfilm` description.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FilmSpec {
    pub width: u32,
    pub height: u32,
}

impl FilmSpec {
    /// At most this many pixels (2026-11, issue 8): the film holds three `f64` sums per pixel, so a
    /// 65536² film (each side within range) would need 100 GB; 2²⁶ pixels need 1.6 GB.
    pub const MAX_PIXELS: u64 = 1 << 26;

    /// Read `hdrfilm`; warnings (e.g. a filter rendered as a box) are appended to `warnings`.
    pub fn from_props(p: &Props, warnings: &mut Vec<String>) -> Result<FilmSpec> {
        if p.plugin_type() != "hdrfilm" {
            return Err(Error::spec(p.at(), format!("unsupported film `{}` (gonio has: hdrfilm)", p.plugin_type())));
        }
        let width = p.integer_in("width", 768, 1, 1 << 16)? as u32;
        let height = p.integer_in("height", 576, 1, 1 << 16)? as u32;
        if u64::from(width) * u64::from(height) > Self::MAX_PIXELS {
            return Err(Error::spec(
                p.at_param("width"),
                format!("a {width}×{height} film has more than the {} pixels gonio renders (8192×8192; 24 bytes each)", Self::MAX_PIXELS),
            ));
        }
        let _ = p.string("pixel_format")?;
        let _ = p.string("component_format")?;
        for f in p.nested_of("rfilter") {
            if f.plugin_type() != "box" {
                warnings.push(format!("{}: rfilter `{}` is rendered as a box filter", f.at(), f.plugin_type()));
            }
        }
        p.finish()?;
        Ok(FilmSpec { width, height })
    }
}

/// Per-pixel sums of samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    sum: Vec<[f64; 3]>,
}

impl Film {
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Film { width, height, sum: vec![[0.0; 3]; width as usize * height as usize] }
    }

    /// Add one sample to pixel `index`; returns false (and adds nothing) when it is not finite.
    #[inline]
    pub fn add(&mut self, index: usize, v: Rgb) -> bool {
        if !v.is_finite() {
            return false;
        }
        for (s, c) in self.sum[index].iter_mut().zip(v.0) {
            *s += f64::from(c);
        }
        true
    }

    /// Add the sums of a tile `tile_width` pixels wide whose top-left pixel is (x0, y0).
    pub fn add_tile(&mut self, x0: u32, y0: u32, tile_width: u32, sums: &[[f64; 3]]) {
        for (row, chunk) in sums.chunks(tile_width as usize).enumerate() {
            let start = (y0 as usize + row) * self.width as usize + x0 as usize;
            for (dst, src) in self.sum[start..start + chunk.len()].iter_mut().zip(chunk) {
                for c in 0..3 {
                    dst[c] += src[c];
                }
            }
        }
    }

    /// The per-pixel sums, row-major.
    #[must_use]
    pub fn into_sums(self) -> Vec<[f64; 3]> {
        self.sum
    }

    /// The pixel means for `spp` samples per pixel: RGB, row-major, top row first.
    #[must_use]
    pub fn mean(&self, spp: u32) -> Vec<f32> {
        let inv = if spp > 0 { 1.0 / f64::from(spp) } else { 0.0 };
        self.sum.iter().flat_map(|s| s.map(|v| (v * inv) as f32)).collect()
    }
}
