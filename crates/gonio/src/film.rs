//! `hdrfilm` with a box filter: each pixel is the mean of its samples, accumulated in f64.
//!
//! | parameter          | type    | default | meaning                                           |
//! |--------------------|---------|---------|---------------------------------------------------|
//! | `width`, `height`  | integer | 768, 576| resolution: each in [1, 65536], at most 2²⁶ pixels |
//! | `file_format`      | string  | openexr | `openexr`, `exr`, `rgbe` or `pfm`: accepted (the output format follows the file name) |
//! | `pixel_format`     | string  | rgb     | one of Mitsuba's (`rgb`, `rgba`, `luminance`, `xyz`, …): accepted (gonio writes RGB) |
//! | `component_format` | string  | float16 | `float16`, `float32` or `uint32`: accepted (the output format follows the file name) |
//! | `crop_offset_x`, `crop_offset_y`, `crop_width`, `crop_height` | integer | 0, 0, width, height | a crop window: only the whole film (gonio renders no partial films yet; anything else is an error) |
//! | `sample_border`    | boolean | false   | only `false` (samples in the film's pixels; `true` is an error) |
//! | `compensate`       | boolean | false   | accepted: gonio always sums in f64 (what Mitsuba's Kahan summation is for) |
//! | nested `rfilter`   | plugin  | box     | `box`; others are rendered with a box and a warning |
//!
//! A non-finite sample is dropped and counted: it adds nothing to the sum but still counts in the
//! denominator (the pixel stays an unbiased estimate if such samples are rare; 2026-11).

use crate::error::{Error, Result};
use crate::props::Props;
use crate::spectrum::Rgb;

/// The most pixels a film may have: 2²⁶ (8192 × 8192), whose sums take 1.5 GiB and the image 0.75 GiB.
/// Larger films are refused when the scene is read, before anything is allocated for them, rather than
/// aborting on a failed allocation midway (2026-11).
pub const MAX_PIXELS: u64 = 1 << 26;

/// The film's size, read from an `hdrfilm` description.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FilmSpec {
    pub width: u32,
    pub height: u32,
}

impl FilmSpec {
    /// Read `hdrfilm`; warnings (e.g. a filter rendered as a box) are appended to `warnings`.
    pub fn from_props(p: &Props, warnings: &mut Vec<String>) -> Result<FilmSpec> {
        if p.plugin_type() != "hdrfilm" {
            return Err(Error::spec(p.at(), format!("unsupported film `{}` (gonio has: hdrfilm)", p.plugin_type())));
        }
        let width = p.integer_in("width", 768, 1, 1 << 16)? as u32;
        let height = p.integer_in("height", 576, 1, 1 << 16)? as u32;
        if u64::from(width) * u64::from(height) > MAX_PIXELS {
            return Err(Error::spec(
                p.at(),
                format!("a {width}×{height} film has more than {MAX_PIXELS} pixels (e.g. 8192×8192), the most gonio renders"),
            ));
        }
        one_of(p, "file_format", &["openexr", "exr", "rgbe", "pfm"])?;
        one_of(p, "pixel_format", &["luminance", "luminance_alpha", "rgb", "rgba", "xyz", "xyza"])?;
        one_of(p, "component_format", &["float16", "float32", "uint32"])?;
        let _ = p.bool("compensate", false)?;
        if p.bool("sample_border", false)? {
            return Err(Error::spec(p.at_param("sample_border"), "`sample_border` = true is not supported by gonio yet (only false)"));
        }
        let crop = [
            ("crop_offset_x", 0, p.integer_in("crop_offset_x", 0, 0, i64::from(width))?),
            ("crop_offset_y", 0, p.integer_in("crop_offset_y", 0, 0, i64::from(height))?),
            ("crop_width", i64::from(width), p.integer_in("crop_width", i64::from(width), 1, i64::from(width))?),
            ("crop_height", i64::from(height), p.integer_in("crop_height", i64::from(height), 1, i64::from(height))?),
        ];
        if let Some((name, whole, _)) = crop.iter().find(|(_, whole, got)| got != whole) {
            return Err(Error::spec(
                p.at_param(name),
                format!("crop windows are not supported by gonio yet: `{name}` must be {whole} (the whole {width}×{height} film)"),
            ));
        }
        for f in p.nested_of("rfilter") {
            if f.plugin_type() != "box" {
                warnings.push(format!("{}: rfilter `{}` is rendered as a box filter", f.at(), f.plugin_type()));
            }
        }
        p.finish()?;
        Ok(FilmSpec { width, height })
    }
}

/// A string parameter that, when given, must be one of `allowed`.
fn one_of(p: &Props, name: &'static str, allowed: &[&str]) -> Result<()> {
    match p.string(name)? {
        Some(v) if !allowed.contains(&v.as_str()) => {
            Err(Error::spec(p.at_param(name), format!("`{name}` must be one of {}, got \"{v}\"", allowed.join(", "))))
        }
        _ => Ok(()),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn film(json: &str) -> Result<FilmSpec> {
        let p = Props::from_json(json).unwrap();
        FilmSpec::from_props(&p, &mut Vec::new())
    }

    /// The `hdrfilm` parameters Mitsuba 3 accepts are accepted; values gonio cannot honour are errors
    /// that name the parameter.
    #[test]
    fn mitsubas_hdrfilm_parameters_are_accepted() {
        let all = r#"{"type": "hdrfilm", "width": 8, "height": 4, "file_format": "openexr", "pixel_format": "rgba",
            "component_format": "float32", "crop_offset_x": 0, "crop_offset_y": 0, "crop_width": 8, "crop_height": 4,
            "sample_border": false, "compensate": true}"#;
        assert_eq!(film(all).unwrap(), FilmSpec { width: 8, height: 4 });
        for (json, want) in [
            (r#"{"type": "hdrfilm", "file_format": "png"}"#, "`file_format` must be one of openexr"),
            (r#"{"type": "hdrfilm", "pixel_format": "bgr"}"#, "`pixel_format` must be one of"),
            (r#"{"type": "hdrfilm", "width": 8, "height": 4, "crop_width": 4}"#, "crop windows are not supported by gonio yet: `crop_width` must be 8"),
            (r#"{"type": "hdrfilm", "crop_offset_y": 2}"#, "`crop_offset_y` must be 0"),
            (r#"{"type": "hdrfilm", "sample_border": true}"#, "`sample_border` = true is not supported"),
        ] {
            let e = film(json).unwrap_err().to_string();
            assert!(e.contains(want), "{json}: {e}");
        }
    }
}
