//! `hdrfilm` and its reconstruction filters (`rfilter`), as Mitsuba 3 develops an image: each sample is
//! splatted into every pixel within the filter's radius with weight w(Δx) · w(Δy) (Δ = the pixel centre
//! minus the sample position, in pixels), and a pixel is its weighted sum over its summed weights; sums in f64.
//! With the `box` filter (radius ½) that is the mean of the samples in the pixel.
//!
//! | parameter          | type    | default | meaning                                           |
//! |--------------------|---------|---------|---------------------------------------------------|
//! | `width`, `height`  | integer | 768, 576| resolution: each in [1, 65536], at most 2²⁶ pixels |
//! | `file_format`      | string  | openexr | `openexr`, `exr`, `rgbe` or `pfm`: accepted (the output format follows the file name) |
//! | `pixel_format`     | string  | rgb     | one of Mitsuba's (`rgb`, `rgba`, `luminance`, `xyz`, …): accepted (gonio writes RGB, and an `aov` integrator's channels) |
//! | `component_format` | string  | float16 | `float16`, `float32` or `uint32`: accepted (the output format follows the file name) |
//! | `crop_offset_x`, `crop_offset_y`, `crop_width`, `crop_height` | integer | 0, 0, width, height | a crop window: only the whole film (gonio renders no partial films yet; anything else is an error) |
//! | `sample_border`    | boolean | false   | only `false` (samples in the film's pixels; `true` is an error) |
//! | `compensate`       | boolean | false   | accepted: gonio always sums in f64 (what Mitsuba's Kahan summation is for) |
//! | nested `rfilter`   | plugin  | gaussian | `box`, `tent`, `gaussian` ([`Filter`]); others are rendered with a box and a warning |
//!
//! A non-finite sample is dropped and counted: it adds nothing to the sum but still counts in the
//! denominator (the pixel stays an unbiased estimate if such samples are rare; 2026-11).

use crate::error::{Error, Result};
use crate::props::Props;

/// A separable reconstruction filter, Mitsuba 3's `rfilter` plugins:
///
/// | plugin     | parameter | default | w(x)                                                    | radius r |
/// |------------|-----------|---------|---------------------------------------------------------|----------|
/// | `box`      | —         |         | 1 for \|x\| ≤ ½                                          | ½        |
/// | `tent`     | `radius`  | 1       | max(0, 1 − \|x\| / r)                                    | `radius` |
/// | `gaussian` | `stddev`  | 0.5     | max(0, exp(−x² / 2σ²) − exp(−r² / 2σ²)), cut off at 4σ   | 4σ       |
///
/// (Mitsuba 3's `gaussian.cpp` and `tent.cpp` define these; the Gaussian is Mitsuba's default for
/// `hdrfilm`, so it is gonio's when a film names no filter. Mitsuba 3.9.1 evaluates its Gaussian with an
/// exponential that differs from exp by up to 4·10⁻⁴ at these arguments, e.g. w(0) = 0.99925 against
/// 0.99966 here; a pixel's value is a ratio of weighted sums, so that changes it by far less.)
///
/// Weights are read from a table of w over [0, r] at [`FILTER_TABLE`] points, interpolated linearly:
/// for the Gaussian the error is at most h² max|w''| / 8 = (4σ / 127)² / (8σ²) = 1.2·10⁻⁴ (h the spacing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filter {
    /// `box`, `tent` or `gaussian`.
    name: &'static str,
    radius: f32,
    /// (FILTER_TABLE − 1) / r: table entries per pixel.
    scale: f32,
    /// w(i · r / (FILTER_TABLE − 1)); the last entry is w(r) = 0.
    table: [f32; FILTER_TABLE],
}

/// Points in a filter's weight table (see [`Filter`]).
pub const FILTER_TABLE: usize = 128;

impl Filter {
    /// The box filter: each sample counts in its own pixel only, with weight 1.
    pub const BOX: Filter = Filter { name: "box", radius: 0.5, scale: (FILTER_TABLE - 1) as f32 / 0.5, table: [1.0; FILTER_TABLE] };

    fn tabulated(name: &'static str, radius: f32, w: impl Fn(f64) -> f64) -> Filter {
        let table = std::array::from_fn(|i| w(f64::from(radius) * i as f64 / (FILTER_TABLE - 1) as f64) as f32);
        Filter { name, radius, scale: (FILTER_TABLE - 1) as f32 / radius, table }
    }

    /// Mitsuba's `tent` of the given radius (> 0).
    #[must_use]
    pub fn tent(radius: f32) -> Filter {
        let r = f64::from(radius);
        Filter::tabulated("tent", radius, |x| (1.0 - x / r).max(0.0))
    }

    /// Mitsuba's `gaussian` of standard deviation `stddev` (> 0), cut off at 4σ.
    #[must_use]
    pub fn gaussian(stddev: f32) -> Filter {
        let s = f64::from(stddev);
        let alpha = -1.0 / (2.0 * s * s);
        let bias = (alpha * (4.0 * s).powi(2)).exp();
        Filter::tabulated("gaussian", 4.0 * stddev, |x| ((alpha * x * x).exp() - bias).max(0.0))
    }

    /// Read a nested `<rfilter>`; a filter gonio does not have yet is a box, with a warning.
    pub fn from_props(p: &Props, warnings: &mut Vec<String>) -> Result<Filter> {
        let f = match p.plugin_type() {
            "box" => Filter::BOX,
            "tent" => Filter::tent(p.float_in("radius", 1.0, 1e-3, 64.0)?),
            "gaussian" => Filter::gaussian(p.float_in("stddev", 0.5, 1e-3, 16.0)?),
            other => {
                warnings.push(format!("{}: rfilter `{other}` is rendered as a box filter (gonio has box, tent, gaussian)", p.at()));
                return Ok(Filter::BOX);
            }
        };
        p.finish()?;
        Ok(f)
    }

    /// The plugin name (`box`, `tent`, `gaussian`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        self.name
    }

    #[must_use]
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Whether this is the box filter (every sample in its own pixel, weight 1).
    #[must_use]
    pub fn is_box(&self) -> bool {
        self.name == "box"
    }

    /// How many pixels beyond its own a sample may reach on each side: ⌈r − ½⌉ (0 for the box).
    #[must_use]
    pub fn border(&self) -> u32 {
        (self.radius - 0.5).max(0.0).ceil() as u32
    }

    /// w(x) from the table, linearly interpolated; 0 from the radius on.
    #[inline]
    #[must_use]
    pub fn eval(&self, x: f32) -> f32 {
        let t = x.abs() * self.scale;
        let i = t as usize; // t ≥ 0: truncation is floor
        if i >= FILTER_TABLE - 1 {
            return if i == FILTER_TABLE - 1 && t == i as f32 { self.table[i] } else { 0.0 };
        }
        let f = t - i as f32;
        self.table[i] + f * (self.table[i + 1] - self.table[i])
    }

    /// The weights along one axis of a sample at offset `u` ∈ [0, 1) in its pixel, for the pixels
    /// −b ..= b from it (b = [`Self::border`]): `out[k]` = w(k − b + ½ − u). `out` has 2b + 1 entries.
    #[inline]
    pub fn weights(&self, u: f32, out: &mut [f32]) {
        let b = self.border() as f32;
        for (k, w) in out.iter_mut().enumerate() {
            *w = self.eval(k as f32 - b + 0.5 - u);
        }
    }
}

/// Channels [`Film::splat`] weights together per row.
const SPLAT_GROUP: usize = 4;

/// The taps from the first to the last of non-zero weight (empty if all are 0).
#[inline]
fn nonzero_span(w: &[f32]) -> std::ops::Range<usize> {
    let first = w.iter().position(|w| *w != 0.0).unwrap_or(w.len());
    let last = w.iter().rposition(|w| *w != 0.0).map_or(first, |l| l + 1);
    first..last
}

/// The most pixels a film may have: 2²⁶ (8192 × 8192), whose sums take 1.5 GiB and the image 0.75 GiB.
/// Larger films are refused when the scene is read, before anything is allocated for them, rather than
/// aborting on a failed allocation midway (2026-11).
pub const MAX_PIXELS: u64 = 1 << 26;

/// The film's size and reconstruction filter, read from an `hdrfilm` description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmSpec {
    pub width: u32,
    pub height: u32,
    pub filter: Filter,
}

impl FilmSpec {
    /// Mitsuba's film when a sensor names none: 768 × 576 with its default (Gaussian) filter.
    #[must_use]
    pub fn mitsuba_default() -> FilmSpec {
        FilmSpec { width: 768, height: 576, filter: Filter::gaussian(0.5) }
    }
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
        let filter = match p.nested_of("rfilter").as_slice() {
            [] => Filter::gaussian(0.5),
            [f] => Filter::from_props(f, warnings)?,
            [_, second, ..] => return Err(Error::spec(second.at(), "a film takes one <rfilter>")),
        };
        p.finish()?;
        Ok(FilmSpec { width, height, filter })
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

/// Per-pixel sums of samples, `channels` values each (RGB, then an `aov` integrator's further channels):
/// with the box filter plain sums (divided by the sample count), otherwise weighted sums and the sums of
/// their weights. Every channel is filtered alike, as Mitsuba 3's film splats its AOVs with the colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    channels: usize,
    /// `channels` sums per pixel, row-major.
    sum: Vec<f64>,
    /// Summed filter weights per pixel; empty for the box filter.
    weight: Vec<f64>,
}

impl Film {
    /// A film of `channels` values per pixel for the box filter.
    #[must_use]
    pub fn new(width: u32, height: u32, channels: usize) -> Self {
        Film { width, height, channels, sum: vec![0.0; channels * width as usize * height as usize], weight: Vec::new() }
    }

    /// A film of `channels` values per pixel for a filter with weights (see [`Film::splat`]).
    #[must_use]
    pub fn weighted(width: u32, height: u32, channels: usize) -> Self {
        let n = width as usize * height as usize;
        Film { width, height, channels, sum: vec![0.0; channels * n], weight: vec![0.0; n] }
    }

    /// A film from sums read back (e.g. a part of a render sent between processes): `sum` has `channels`
    /// values per pixel, row-major; `weight` one per pixel for a weighted film, `None` for the box filter.
    ///
    /// # Errors
    /// When a length does not match the size.
    pub fn from_sums(width: u32, height: u32, channels: usize, sum: &[f64], weight: Option<&[f64]>) -> Result<Film> {
        let n = width as usize * height as usize;
        if channels == 0 || sum.len() != channels * n || weight.is_some_and(|w| w.len() != n) {
            return Err(Error::spec(
                "film",
                format!(
                    "a {width}×{height} film of {channels} channels needs {} sums and {n} weights (or none), got {} and {}",
                    channels * n,
                    sum.len(),
                    weight.map_or_else(|| "none".to_string(), |w| w.len().to_string())
                ),
            ));
        }
        Ok(Film { width, height, channels, sum: sum.to_vec(), weight: weight.map(<[f64]>::to_vec).unwrap_or_default() })
    }

    /// Values per pixel.
    #[must_use]
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// The per-pixel sums, row-major, [`Film::channels`] per pixel (see [`Film::from_sums`]).
    #[must_use]
    pub fn sums(&self) -> &[f64] {
        &self.sum
    }

    /// The summed filter weights per pixel; `None` for the box filter.
    #[must_use]
    pub fn weights(&self) -> Option<&[f64]> {
        (!self.weight.is_empty()).then_some(self.weight.as_slice())
    }

    /// Add one sample (its [`Film::channels`] values) to pixel `index` (box filter); returns false (and adds
    /// nothing) when a value is not finite.
    #[inline]
    pub fn add(&mut self, index: usize, v: &[f32]) -> bool {
        debug_assert_eq!(v.len(), self.channels);
        if !v.iter().all(|c| c.is_finite()) {
            return false;
        }
        for (s, &c) in self.sum[index * self.channels..].iter_mut().zip(v) {
            *s += f64::from(c);
        }
        true
    }

    /// Splat a sample (its [`Film::channels`] values) into the pixels (x0 + i, y0 + j) with weight
    /// `wx[i] · wy[j]` (a filter's weights around the sample, [`Filter::weights`]; the pixels must lie in
    /// the film). A sample with a non-finite value adds its weights but no value (it counts as black) and
    /// returns false.
    #[inline]
    pub fn splat(&mut self, x0: u32, y0: u32, wx: &[f32], wy: &[f32], v: &[f32]) -> bool {
        // The body once, its channel count a constant for the films nearly every render makes (RGB, and
        // RGB with alpha), so that the per-tap loops over the channels unroll; any count otherwise.
        match self.channels {
            3 => self.splat_channels(3, x0, y0, wx, wy, v),
            4 => self.splat_channels(4, x0, y0, wx, wy, v),
            k => self.splat_channels(k, x0, y0, wx, wy, v),
        }
    }

    /// [`Self::splat`] for `k` = [`Film::channels`].
    #[inline(always)]
    fn splat_channels(&mut self, k: usize, x0: u32, y0: u32, wx: &[f32], wy: &[f32], v: &[f32]) -> bool {
        debug_assert_eq!((v.len(), k), (self.channels, self.channels));
        let finite = v.iter().all(|c| c.is_finite());
        let width = self.width as usize;
        // Only the taps from the first to the last of non-zero weight (the Gaussian has one of weight 0 at
        // one end of each axis); each row's values times its weight once, in groups of up to
        // `SPLAT_GROUP` channels, then one multiply and one add per tap and channel. (2026-12: with a
        // conversion and two multiplies per tap and channel, and a test per tap, the loop that splats took
        // 15 % of a render of Mitsuba's matpreview with its default Gaussian; now 10 %.) The same products
        // as before, bit for bit.
        let (xs, ys) = (nonzero_span(wx), nonzero_span(wy));
        let wx = &wx[xs.clone()];
        for (j, &wy) in wy[ys.clone()].iter().enumerate() {
            let first = (y0 as usize + ys.start + j) * width + x0 as usize + xs.start;
            let wy = f64::from(wy);
            for (w, &wx) in self.weight[first..first + wx.len()].iter_mut().zip(wx) {
                *w += f64::from(wx) * wy;
            }
            if !finite {
                continue;
            }
            let sums = &mut self.sum[first * k..(first + wx.len()) * k];
            for c0 in (0..k).step_by(SPLAT_GROUP) {
                let n = (k - c0).min(SPLAT_GROUP);
                let mut row = [0.0f64; SPLAT_GROUP];
                for (r, &c) in row.iter_mut().zip(&v[c0..c0 + n]) {
                    *r = f64::from(c) * wy;
                }
                for (pixel, &wx) in sums.chunks_exact_mut(k).zip(wx) {
                    let wx = f64::from(wx);
                    for (s, &r) in pixel[c0..c0 + n].iter_mut().zip(&row) {
                        *s += wx * r;
                    }
                }
            }
        }
        finite
    }

    /// Add a tile's sums (of as many channels), its top-left pixel at (x0, y0) of this film (negative, or
    /// reaching past the right or bottom edge, for a tile with a filter's border: what falls outside is
    /// dropped, as Mitsuba drops the border of its image blocks).
    pub fn add_tile(&mut self, x0: i64, y0: i64, tile: &Film) {
        debug_assert_eq!(tile.channels, self.channels);
        let (weighted, k) = (!self.weight.is_empty(), self.channels);
        for ty in 0..i64::from(tile.height) {
            let y = y0 + ty;
            if y < 0 || y >= i64::from(self.height) {
                continue;
            }
            for tx in 0..i64::from(tile.width) {
                let x = x0 + tx;
                if x < 0 || x >= i64::from(self.width) {
                    continue;
                }
                let (dst, src) = ((y * i64::from(self.width) + x) as usize, (ty * i64::from(tile.width) + tx) as usize);
                for (d, s) in self.sum[dst * k..(dst + 1) * k].iter_mut().zip(&tile.sum[src * k..(src + 1) * k]) {
                    *d += s;
                }
                if weighted {
                    self.weight[dst] += tile.weight[src];
                }
            }
        }
    }

    /// The pixel values for `spp` samples per pixel: [`Film::channels`] per pixel, row-major, top row
    /// first (the box filter's means, or weighted sums over summed weights; a pixel no sample reached is 0).
    #[must_use]
    pub fn mean(&self, spp: u32) -> Vec<f32> {
        if self.weight.is_empty() {
            let inv = if spp > 0 { 1.0 / f64::from(spp) } else { 0.0 };
            return self.sum.iter().map(|v| (v * inv) as f32).collect();
        }
        self.sum
            .chunks_exact(self.channels)
            .zip(&self.weight)
            .flat_map(|(s, &w)| s.iter().map(move |v| if w != 0.0 { (v / w) as f32 } else { 0.0 }))
            .collect()
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
        assert_eq!(film(all).unwrap(), FilmSpec { width: 8, height: 4, filter: Filter::gaussian(0.5) });
        for (json, want) in [
            (r#"{"type": "hdrfilm", "file_format": "png"}"#, "`file_format` must be one of openexr"),
            (r#"{"type": "hdrfilm", "pixel_format": "bgr"}"#, "`pixel_format` must be one of"),
            (
                r#"{"type": "hdrfilm", "width": 8, "height": 4, "crop_width": 4}"#,
                "crop windows are not supported by gonio yet: `crop_width` must be 8",
            ),
            (r#"{"type": "hdrfilm", "crop_offset_y": 2}"#, "`crop_offset_y` must be 0"),
            (r#"{"type": "hdrfilm", "sample_border": true}"#, "`sample_border` = true is not supported"),
        ] {
            let e = film(json).unwrap_err().to_string();
            assert!(e.contains(want), "{json}: {e}");
        }
    }

    /// A splat adds `wx[i] · (v[c] · wy[j])` to channel c of pixel (x0 + i, y0 + j) and `wx[i] · wy[j]` to
    /// its weight, bit for bit, for any number of channels (several groups of [`SPLAT_GROUP`] and a
    /// partial one) and weights of 0 anywhere (at the ends, inside, everywhere); a non-finite value adds
    /// the weights alone.
    #[test]
    fn splats_add_each_taps_products() {
        let mut rng = crate::sampling::Pcg32::new(3, 9);
        for k in [1, 3, 4, 5, 9] {
            for round in 0..200 {
                let (w, h) = (9u32, 7u32);
                let mut tile = Film::weighted(w, h, k);
                let mut want = (vec![0.0f64; (w * h) as usize * k], vec![0.0f64; (w * h) as usize]);
                let weights = |rng: &mut crate::sampling::Pcg32, n: usize| -> Vec<f32> {
                    (0..n).map(|_| if rng.next_f32() < 0.3 { 0.0 } else { rng.next_f32() }).collect()
                };
                for _ in 0..5 {
                    let (wx, wy) = (weights(&mut rng, 5), weights(&mut rng, 4));
                    let (x0, y0) = ((rng.next_f32() * 5.0) as u32, (rng.next_f32() * 4.0) as u32);
                    let mut v: Vec<f32> = (0..k).map(|_| rng.next_f32() * 10.0 - 2.0).collect();
                    if round % 50 == 7 {
                        v[k - 1] = f32::NAN;
                    }
                    let finite = v.iter().all(|c| c.is_finite());
                    assert_eq!(tile.splat(x0, y0, &wx, &wy, &v), finite);
                    for (j, &wy) in wy.iter().enumerate() {
                        for (i, &wx) in wx.iter().enumerate() {
                            let p = (y0 as usize + j) * w as usize + x0 as usize + i;
                            let (wx, wy) = (f64::from(wx), f64::from(wy));
                            want.1[p] += wx * wy;
                            for (c, &value) in v.iter().enumerate() {
                                if finite {
                                    want.0[p * k + c] += wx * (f64::from(value) * wy);
                                }
                            }
                        }
                    }
                }
                assert_eq!((tile.sums(), tile.weights().unwrap()), (want.0.as_slice(), want.1.as_slice()), "k = {k}");
            }
        }
    }

    /// The filters' weights against Mitsuba 3.9.1's `eval` (tent exactly; the Gaussian to its exp's
    /// accuracy, see [`Filter`]), their radii and borders (`radius()`, `border_size()`).
    #[test]
    fn filters_match_mitsuba() {
        let g = Filter::gaussian(0.5);
        assert_eq!(
            (g.radius(), g.border(), Filter::tent(1.0).border(), Filter::tent(1.5).border(), Filter::BOX.border()),
            (2.0, 2, 1, 1, 0)
        );
        assert_eq!(Filter::gaussian(1.5).border(), 6);
        // (x, Mitsuba's gaussian eval, tent radius 1, tent radius 1.5)
        for (x, gauss, tent1, tent15) in [
            (0.0, 0.999_247, 1.0, 1.0),
            (0.3, 0.835_048, 0.7, 0.8),
            (1.0, 0.134_960, 0.0, 0.333_333),
            (1.9, 0.000_388, 0.0, 0.0),
            (2.0, 0.000_002, 0.0, 0.0),
        ] {
            assert!((g.eval(x) - gauss).abs() < 8e-4 && (g.eval(-x) - g.eval(x)).abs() < 1e-7, "{x}: {}", g.eval(x));
            assert!((Filter::tent(1.0).eval(x) - tent1).abs() < 1e-6, "{x}");
            assert!((Filter::tent(1.5).eval(x) - tent15).abs() < 1e-6, "{x}");
        }
        // The table against the exact Gaussian, densely: the bound in the docs.
        for i in 0..=4000 {
            let x = i as f64 * 0.0005;
            let exact = ((-2.0 * x * x).exp() - (-8.0f64).exp()).max(0.0);
            assert!((f64::from(g.eval(x as f32)) - exact).abs() < 1.3e-4, "{x}");
        }
        for (json, want) in [(r#"{"type": "gaussian", "stddev": -1}"#, "`stddev`"), (r#"{"type": "tent", "radius": 0}"#, "`radius`")] {
            let e = Filter::from_props(&Props::from_json(json).unwrap(), &mut Vec::new()).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
        let mut warnings = Vec::new();
        assert_eq!(Filter::from_props(&Props::from_json(r#"{"type": "mitchell"}"#).unwrap(), &mut warnings).unwrap(), Filter::BOX);
        assert!(warnings[0].contains("rfilter `mitchell` is rendered as a box filter"), "{warnings:?}");
        let mut w = [0.0; 5];
        g.weights(0.25, &mut w);
        let want = [-1.75f32, -0.75, 0.25, 1.25, 2.25].map(|x| g.eval(x));
        assert_eq!(w, want);
    }

    /// A sample splatted with a filter lands in its neighbours by the filter's weights; the developed
    /// pixel is the weighted mean, and a tile's border falls off the film's edges.
    #[test]
    fn splats_develop_to_weighted_means() {
        let f = Filter::tent(1.0);
        let (mut wx, mut wy) = ([0.0; 3], [0.0; 3]);
        f.weights(0.5, &mut wx); // the pixel centre: (0, 1, 0)
        f.weights(0.25, &mut wy); // (0.25, 0.75, 0)
        assert_eq!((wx, wy), ([0.0, 1.0, 0.0], [0.25, 0.75, 0.0]));
        let mut tile = Film::weighted(3, 3, 3);
        assert!(tile.splat(0, 0, &wx, &wy, &[2.0; 3]));
        assert!(!tile.splat(0, 0, &wx, &wy, &[f32::NAN, 1.0, 1.0]));
        let mut film = Film::weighted(2, 2, 3);
        film.add_tile(-1, -1, &tile); // the tile's centre pixel is the film's (0, 0)
        let img = film.mean(2);
        // Pixel (0, 0) has weight 0.75 from each sample, one of them black: a mean of 1.
        assert_eq!(img, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    }
}
