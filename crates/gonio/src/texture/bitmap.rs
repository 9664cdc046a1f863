//! `bitmap` — an image texture, looked up as Mitsuba 3's `bitmap` does.
//!
//! | parameter     | type      | default    | meaning                                                     |
//! |---------------|-----------|------------|-------------------------------------------------------------|
//! | `filename`    | string    | —          | EXR, HDR, PNG or JPEG (LDR files are sRGB-decoded to linear) |
//! | `raw`         | boolean   | false      | keep LDR values as stored (no sRGB decoding)                |
//! | `filter_type` | string    | `bilinear` | `bilinear` or `nearest`                                     |
//! | `wrap_mode`   | string    | `repeat`   | `repeat`, `mirror` or `clamp`                               |
//! | `to_uv`       | transform | identity   | applied to (u, v, 0) before the lookup                      |
//!
//! Texel (x, y) covers [x, x + 1)/W × [y, y + 1)/H of uv space with row 0 at the *top* of the image
//! (v = 0 is the first row); bilinear lookups blend the four texels around (u W − ½, v H − ½).

use crate::error::{Error, Result};
use crate::geometry::bvh::bits;
use crate::image::{linear_to_srgb, read_stored_image, srgb8_table, Bytes8, Image, Stored};
use crate::math::lanes::V3;
use crate::math::simd::Float8;
use crate::math::Transform;
use crate::props::Props;
use crate::spectrum::Rgb;
use glam::{Vec2, Vec3};
use std::path::Path;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

impl Wrap {
    /// Map an integer texel coordinate into [0, n).
    #[inline]
    fn apply(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        if (0..n).contains(&i) {
            // Every mode leaves [0, n) as it is (most lookups: no integer division).
            return i as usize;
        }
        let r = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n {
                    m
                } else {
                    2 * n - 1 - m
                }
            }
        };
        r as usize
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    texels: Texels,
    bilinear: bool,
    wrap: Wrap,
    to_uv: Transform,
}

/// The image as the lookups read it.
#[derive(Clone, Debug, PartialEq)]
enum Texels {
    /// Linear RGB floats (EXR, HDR, 16-bit PNG).
    Linear(Arc<Image>),
    /// 8-bit samples (PNG and JPEG), each turned into a float through `table` where a lookup reads it: a
    /// quarter of the memory of floats, where lookups miss the caches (2026-12: a 2048 × 1571 JPEG took
    /// 38 MB as floats, and its lookups 15 % of a render).
    Bytes { image: Arc<Bytes8>, table: &'static [f32; 256] },
}

impl Texels {
    /// Pixel `p` (row-major, `y · width + x`) as linear RGB.
    #[inline(always)]
    fn texel(&self, p: usize) -> [f32; 3] {
        match self {
            Texels::Linear(image) => {
                let i = 3 * p;
                [image.data[i], image.data[i + 1], image.data[i + 2]]
            }
            Texels::Bytes { image, table } => image.rgb(p).map(|v| table[usize::from(v)]),
        }
    }
}

/// A decoded image as bitmaps share it.
#[derive(Clone)]
enum SharedImage {
    Linear(Arc<Image>),
    Bytes(Arc<Bytes8>),
}

/// The image of the file `path`, decoded once for every bitmap that reads it while any of them lives: the
/// shapes of a scene that share a textured material (by `ref`) each build their own bitmap, and decoding
/// a 2048 × 1571 JPEG for each of 15 such shapes took 1.1 s and 15 copies of its memory (2026-12-06).
/// Keyed by the canonical path, the file's length and its modification time, so that a file changed on
/// disk is read again; held weakly, so that an image no bitmap uses is freed.
fn shared_image(path: &Path) -> Result<SharedImage> {
    type Key = (std::path::PathBuf, u64, Option<std::time::SystemTime>);
    enum Held {
        Linear(std::sync::Weak<Image>),
        Bytes(std::sync::Weak<Bytes8>),
    }
    static CACHE: std::sync::Mutex<Vec<(Key, Held)>> = std::sync::Mutex::new(Vec::new());
    let key = std::fs::canonicalize(path).ok().zip(std::fs::metadata(path).ok()).map(|(p, m)| (p, m.len(), m.modified().ok()));
    let held = |cache: &[(Key, Held)], key: &Key| {
        cache.iter().find(|(k, _)| k == key).and_then(|(_, h)| match h {
            Held::Linear(w) => w.upgrade().map(SharedImage::Linear),
            Held::Bytes(w) => w.upgrade().map(SharedImage::Bytes),
        })
    };
    if let (Some(key), Ok(cache)) = (&key, CACHE.lock()) {
        if let Some(image) = held(&cache, key) {
            return Ok(image);
        }
    }
    // Decoded outside the lock: other threads' files decode meanwhile.
    let image = match read_stored_image(path)? {
        Stored::Linear(image) => SharedImage::Linear(Arc::new(image)),
        Stored::Bytes(image) => SharedImage::Bytes(Arc::new(image)),
    };
    if let (Some(key), Ok(mut cache)) = (key, CACHE.lock()) {
        cache.retain(|(_, h)| match h {
            Held::Linear(w) => w.strong_count() > 0,
            Held::Bytes(w) => w.strong_count() > 0,
        });
        let weak = match &image {
            SharedImage::Linear(a) => Held::Linear(Arc::downgrade(a)),
            SharedImage::Bytes(a) => Held::Bytes(Arc::downgrade(a)),
        };
        cache.push((key, weak));
    }
    Ok(image)
}

/// Decode the image files `paths` at once, in parallel (a file that fails is left to its bitmap, which
/// reports the error where it is read): while the returned images are held, the bitmaps built from those
/// files find them decoded ([`shared_image`]). A scene's materials are built one shape after another;
/// its textures are decoded together before that.
#[must_use]
pub fn decode_images(paths: &[String]) -> DecodedImages {
    use rayon::prelude::*;
    let mut unique: Vec<&String> = paths.iter().collect();
    unique.sort();
    unique.dedup();
    DecodedImages { _held: unique.par_iter().filter_map(|p| shared_image(Path::new(p.as_str())).ok()).collect() }
}

/// Images decoded ahead of their bitmaps ([`decode_images`]), kept while this lives.
pub struct DecodedImages {
    _held: Vec<SharedImage>,
}

impl Bitmap {
    pub fn from_props(p: &Props) -> Result<Self> {
        let filename = p.string("filename")?.ok_or_else(|| Error::spec(p.at(), "`bitmap` needs a `filename`"))?;
        let raw = p.bool("raw", false)?;
        let texels = match shared_image(Path::new(&filename))? {
            // `raw`: the samples as stored, v / 255.
            SharedImage::Bytes(image) => Texels::Bytes { image, table: if raw { raw8_table() } else { srgb8_table() } },
            SharedImage::Linear(mut image) => {
                let is_ldr = matches!(
                    Path::new(&filename).extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
                    Some("png" | "jpg" | "jpeg")
                );
                // A 16-bit PNG was decoded from sRGB: encode it again (in a copy of its own).
                if raw && is_ldr {
                    let mut own = Image::clone(&image);
                    own.data.iter_mut().for_each(|v| *v = linear_to_srgb(*v));
                    image = Arc::new(own);
                }
                Texels::Linear(image)
            }
        };
        let bilinear = match p.string("filter_type")?.as_deref() {
            None | Some("bilinear") => true,
            Some("nearest") => false,
            Some(other) => {
                return Err(Error::spec(p.at_param("filter_type"), format!("`filter_type` must be bilinear or nearest, got `{other}`")))
            }
        };
        let wrap = match p.string("wrap_mode")?.as_deref() {
            None | Some("repeat") => Wrap::Repeat,
            Some("mirror") => Wrap::Mirror,
            Some("clamp") => Wrap::Clamp,
            Some(other) => {
                return Err(Error::spec(p.at_param("wrap_mode"), format!("`wrap_mode` must be repeat, mirror or clamp, got `{other}`")))
            }
        };
        // `read_stored_image` refuses an image without pixels.
        Ok(Bitmap { texels, bilinear, wrap, to_uv: p.transform("to_uv")? })
    }

    /// Width and height in pixels.
    #[must_use]
    pub fn resolution(&self) -> (usize, usize) {
        match &self.texels {
            Texels::Linear(image) => (image.width, image.height),
            Texels::Bytes { image, .. } => (image.width, image.height),
        }
    }

    #[must_use]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        let (iw, ih) = self.resolution();
        let texel = |p: usize| Rgb(self.texels.texel(p));
        let q = self.to_uv.point(Vec3::new(uv.x, uv.y, 0.0));
        let (w, h) = (iw as f32, ih as f32);
        if !self.bilinear {
            return texel(self.nearest_texel(q.x * w, q.y * h, iw, ih));
        }
        let (x, y) = (q.x * w - 0.5, q.y * h - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let [t00, t10, t01, t11] = self.corner_texels(x0, y0, iw, ih).map(texel);
        let top = t00 * (1.0 - fx) + t10 * fx;
        let bottom = t01 * (1.0 - fx) + t11 * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The gradient ∂/∂(u, v) of the scalar lookup (the luminance of [`Self::eval`]), as Mitsuba 3's
    /// `eval_1_grad`: the derivative of the bilinear interpolant over the texel grid, taken through `to_uv`'s
    /// linear part (its transpose applied to the texel-space gradient; Mitsuba scales by the resolution
    /// after that transpose, the same unless `to_uv` rotates); 0 for `nearest` lookups, which are
    /// piecewise constant.
    #[must_use]
    pub fn eval_1_grad(&self, uv: Vec2) -> Vec2 {
        if !self.bilinear {
            return Vec2::ZERO;
        }
        let (iw, ih) = self.resolution();
        let q = self.to_uv.point(Vec3::new(uv.x, uv.y, 0.0));
        let (w, h) = (iw as f32, ih as f32);
        let (x, y) = (q.x * w - 0.5, q.y * h - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |p: usize| Rgb(self.texels.texel(p)).luminance();
        let [f00, f10, f01, f11] = self.corner_texels(x0, y0, iw, ih).map(texel);
        // ∂f/∂x and ∂f/∂y in texels, then per unit of the transformed coordinates (× resolution).
        let (dx, dy) = (((f10 - f00) * (1.0 - fy) + (f11 - f01) * fy) * w, ((f01 - f00) * (1.0 - fx) + (f11 - f10) * fx) * h);
        let (du, dv) = (self.to_uv.vector(Vec3::X), self.to_uv.vector(Vec3::Y));
        Vec2::new(du.x * dx + du.y * dy, dv.x * dx + dv.y * dy)
    }

    /// The colour lookup ([`Self::eval`]) at eight points (`u`, `v`) in lanes, by the same operations in
    /// each lane of `lanes` (the same value bit for bit; the other lanes are unspecified). The texels are
    /// read lane by lane; the coordinates and the blend are in lanes.
    #[must_use]
    pub fn eval_lanes(&self, u: Float8, v: Float8, lanes: u32) -> [Float8; 3] {
        let (iw, ih) = self.resolution();
        let texel = |p: usize| self.texels.texel(p);
        let q = self.to_uv.point_lanes(V3::new(u, v, Float8::splat(0.0)));
        let (w, h) = (Float8::splat(iw as f32), Float8::splat(ih as f32));
        // Each corner's channels as rows of lanes.
        let gather = |corners: &mut [[[f32; 8]; 3]], at: &dyn Fn(usize) -> [usize; 4]| {
            for lane in bits(lanes) {
                for (k, i) in at(lane).into_iter().take(corners.len()).enumerate() {
                    let t = texel(i);
                    for c in 0..3 {
                        corners[k][c][lane] = t[c];
                    }
                }
            }
        };
        if !self.bilinear {
            let (x, y) = ((q.x * w).to_array(), (q.y * h).to_array());
            let mut one = [[[0.0; 8]; 3]; 1];
            gather(&mut one, &|l| [self.nearest_texel(x[l], y[l], iw, ih); 4]);
            return one[0].map(|row| Float8::load(&row));
        }
        let half = Float8::splat(0.5);
        let (x, y) = (q.x * w - half, q.y * h - half);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0s, y0s) = (x0.to_array(), y0.to_array());
        let mut t = [[[0.0; 8]; 3]; 4];
        gather(&mut t, &|l| self.corner_texels(x0s[l], y0s[l], iw, ih));
        let one = Float8::splat(1.0);
        std::array::from_fn(|c| {
            let [t00, t10, t01, t11] = [0, 1, 2, 3].map(|k| Float8::load(&t[k][c]));
            let top = t00 * (one - fx) + t10 * fx;
            let bottom = t01 * (one - fx) + t11 * fx;
            top * (one - fy) + bottom * fy
        })
    }

    /// The pixel (row-major index) a `nearest` lookup at texel coordinates (`x`, `y`) reads.
    #[inline(always)]
    fn nearest_texel(&self, x: f32, y: f32, iw: usize, ih: usize) -> usize {
        self.wrap.apply(y.floor() as i64, ih) * iw + self.wrap.apply(x.floor() as i64, iw)
    }

    /// The pixels (row-major indices) of the four texels a bilinear lookup blends, whose lower corner is (`x0`, `y0`):
    /// (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1), each column and row wrapped once.
    #[inline(always)]
    fn corner_texels(&self, x0: f32, y0: f32, iw: usize, ih: usize) -> [usize; 4] {
        let (x0, y0) = (x0 as i64, y0 as i64);
        let (c0, c1) = (self.wrap.apply(x0, iw), self.wrap.apply(x0 + 1, iw));
        let (r0, r1) = (self.wrap.apply(y0, ih), self.wrap.apply(y0 + 1, ih));
        [(c0, r0), (c1, r0), (c0, r1), (c1, r1)].map(|(x, y)| y * iw + x)
    }
}

/// 8-bit samples as stored, v / 255 (`raw`).
fn raw8_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|v| v as f32 / 255.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes() {
        assert_eq!(Wrap::Repeat.apply(-1, 4), 3);
        assert_eq!(Wrap::Clamp.apply(7, 4), 3);
        assert_eq!(Wrap::Mirror.apply(4, 4), 3);
        assert_eq!(Wrap::Mirror.apply(-1, 4), 0);
    }

    /// A `w` × `h` image of uniform random texels, green scaled by `green` (above 1: values an 8-bit file
    /// clips and a float file keeps), drawn row by row.
    fn random_image(rng: &mut crate::sampling::Pcg32, w: usize, h: usize, green: f32) -> Image {
        let mut image = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                image.set(x, y, Rgb::new(rng.next_f32(), rng.next_f32() * green, rng.next_f32()));
            }
        }
        image
    }

    /// An 8-bit file kept as its samples gives every lookup the floats decoded at load would give, bit for
    /// bit, in every filter and wrap mode; `raw` gives the samples / 255.
    #[test]
    fn eight_bit_texels_are_the_decoded_floats() {
        use crate::image::{read_image, write_image};
        use crate::sampling::Pcg32;
        let dir = crate::scratch::ScratchDir::new("bitmap8");
        let mut rng = Pcg32::new(3, 1);
        let image = random_image(&mut rng, 13, 7, 1.0);
        let png = dir.join("t.png");
        write_image(&png, &image).unwrap();
        let decoded = Arc::new(read_image(&png).unwrap());
        let stored = read_stored_image(&png).unwrap();
        assert!(matches!(stored, Stored::Bytes(_)), "an 8-bit PNG is kept as bytes");
        for (filter, wrap) in [("bilinear", "repeat"), ("bilinear", "mirror"), ("nearest", "clamp"), ("bilinear", "clamp")] {
            let spec = format!(
                r#"{{"type": "bitmap", "filename": {:?}, "filter_type": "{filter}", "wrap_mode": "{wrap}"}}"#,
                png.to_str().unwrap()
            );
            let bytes = Bitmap::from_props(&Props::from_json(&spec).unwrap()).unwrap();
            assert!(matches!(bytes.texels, Texels::Bytes { .. }));
            let floats = Bitmap { texels: Texels::Linear(decoded.clone()), ..bytes.clone() };
            for _ in 0..2000 {
                let uv = Vec2::new(rng.next_f32() * 3.0 - 1.0, rng.next_f32() * 3.0 - 1.0);
                assert_eq!(bytes.eval(uv).0.map(f32::to_bits), floats.eval(uv).0.map(f32::to_bits), "{filter} {wrap} at {uv}");
            }
        }
        let spec = format!(r#"{{"type": "bitmap", "filename": {:?}, "filter_type": "nearest", "raw": true}}"#, png.to_str().unwrap());
        let raw = Bitmap::from_props(&Props::from_json(&spec).unwrap()).unwrap();
        let Stored::Bytes(samples) = stored else { unreachable!() };
        let v = raw.eval(Vec2::new(4.5 / 13.0, 2.5 / 7.0));
        let i = 3 * (2 * 13 + 4);
        assert_eq!(
            v,
            Rgb::new(f32::from(samples.data[i]) / 255.0, f32::from(samples.data[i + 1]) / 255.0, f32::from(samples.data[i + 2]) / 255.0)
        );
    }

    /// A grey 8-bit file (with or without alpha) is kept at one byte a pixel, and every lookup — one point,
    /// lanes, the gradient — gives what the file expanded to R = G = B gives, bit for bit.
    #[test]
    fn grey_files_keep_one_byte_a_pixel() {
        use crate::image::read_image;
        use crate::sampling::Pcg32;
        let dir = crate::scratch::ScratchDir::new("bitmap-grey");
        let mut rng = Pcg32::new(7, 3);
        let (w, h) = (17u32, 9u32);
        let grey: Vec<u8> = (0..w * h).map(|_| (rng.next_f32() * 256.0) as u8).collect();
        let grey_png = dir.join("grey.png");
        ::image::GrayImage::from_raw(w, h, grey.clone()).unwrap().save(&grey_png).unwrap();
        let grey_alpha_png = dir.join("grey-alpha.png");
        let with_alpha: Vec<u8> = grey.iter().flat_map(|&v| [v, 255 - v]).collect();
        ::image::GrayAlphaImage::from_raw(w, h, with_alpha).unwrap().save(&grey_alpha_png).unwrap();
        let rgb_png = dir.join("rgb.png");
        let rgb: Vec<u8> = grey.iter().flat_map(|&v| [v; 3]).collect();
        ::image::RgbImage::from_raw(w, h, rgb).unwrap().save(&rgb_png).unwrap();
        for path in [&grey_png, &grey_alpha_png] {
            let Stored::Bytes(stored) = read_stored_image(path).unwrap() else { panic!("an 8-bit PNG is kept as bytes") };
            assert_eq!((stored.channels, stored.data), (1, grey.clone()), "{}", path.display());
            assert_eq!(read_image(path).unwrap(), read_image(&rgb_png).unwrap(), "decoded to floats, grey is R = G = B");
        }
        for filter in ["bilinear", "nearest"] {
            let load = |path: &Path| {
                let spec = format!(r#"{{"type": "bitmap", "filename": {:?}, "filter_type": "{filter}"}}"#, path.to_str().unwrap());
                Bitmap::from_props(&Props::from_json(&spec).unwrap()).unwrap()
            };
            let (one, three) = (load(&grey_alpha_png), load(&rgb_png));
            for _ in 0..200 {
                let u: [f32; 8] = std::array::from_fn(|_| rng.next_f32() * 3.0 - 1.0);
                let v: [f32; 8] = std::array::from_fn(|_| rng.next_f32() * 3.0 - 1.0);
                let lanes = |b: &Bitmap| b.eval_lanes(Float8::load(&u), Float8::load(&v), 0xff).map(|c| c.to_array().map(f32::to_bits));
                assert_eq!(lanes(&one), lanes(&three), "{filter}");
                let uv = Vec2::new(u[0], v[0]);
                assert_eq!(one.eval(uv).0.map(f32::to_bits), three.eval(uv).0.map(f32::to_bits), "{filter} at {uv}");
                assert_eq!(one.eval_1_grad(uv), three.eval_1_grad(uv), "{filter} at {uv}");
            }
        }
    }

    /// Bitmaps of one file share its decoded image while one of them lives; a file changed on disk is read
    /// again; a bitmap no longer held frees it.
    #[test]
    fn bitmaps_of_one_file_share_its_image() {
        use crate::image::write_image;
        use crate::sampling::Pcg32;
        let dir = crate::scratch::ScratchDir::new("bitmap-shared");
        let mut rng = Pcg32::new(5, 2);
        let png = dir.join("t.png");
        write_image(&png, &random_image(&mut rng, 9, 5, 1.0)).unwrap();
        let load = |extra: &str| {
            Bitmap::from_props(
                &Props::from_json(&format!(r#"{{"type": "bitmap", "filename": {:?}{extra}}}"#, png.to_str().unwrap())).unwrap(),
            )
            .unwrap()
        };
        let bytes = |b: &Bitmap| match &b.texels {
            Texels::Bytes { image, .. } => image.clone(),
            Texels::Linear(_) => panic!("an 8-bit PNG is kept as bytes"),
        };
        let (a, b) = (load(""), load(r#", "filter_type": "nearest""#));
        assert!(Arc::ptr_eq(&bytes(&a), &bytes(&b)), "one decoded image for both");
        let first = bytes(&a).data.clone();
        // A new file at the same path (another size): read again.
        write_image(&png, &random_image(&mut rng, 11, 6, 1.0)).unwrap();
        let c = load("");
        assert!(!Arc::ptr_eq(&bytes(&a), &bytes(&c)));
        assert_eq!((c.resolution(), bytes(&a).data.clone()), ((11, 6), first));
        // Once no bitmap holds it, the image is freed (the cache holds it weakly).
        let weak = Arc::downgrade(&bytes(&c));
        drop(c);
        assert_eq!(weak.strong_count(), 0);
    }

    /// The lookup in lanes is the single lookup in each lane, bit for bit, for both kinds of texels, every
    /// filter and wrap mode, a `to_uv` transform, and coordinates on and off the image.
    #[test]
    fn lookups_in_lanes_are_the_single_lookups() {
        use crate::image::write_image;
        use crate::sampling::Pcg32;
        let dir = crate::scratch::ScratchDir::new("bitmap_lanes");
        let mut rng = Pcg32::new(5, 2);
        let image = random_image(&mut rng, 11, 6, 4.0);
        // A PNG is kept as bytes, an EXR as floats.
        let (png, exr) = (dir.join("t.png"), dir.join("t.exr"));
        write_image(&png, &image).unwrap();
        write_image(&exr, &image).unwrap();
        for file in [&png, &exr] {
            for (filter, wrap) in
                [("bilinear", "repeat"), ("bilinear", "mirror"), ("bilinear", "clamp"), ("nearest", "repeat"), ("nearest", "mirror")]
            {
                let spec = format!(
                    r#"{{"type": "bitmap", "filename": {:?}, "filter_type": "{filter}", "wrap_mode": "{wrap}",
                        "to_uv": [[1.5, 0.25, 0, 0.1], [-0.3, 2, 0, 0.7], [0, 0, 1, 0], [0, 0, 0, 1]]}}"#,
                    file.to_str().unwrap()
                );
                let b = Bitmap::from_props(&Props::from_json(&spec).unwrap()).unwrap();
                for _ in 0..300 {
                    let (u, v): ([f32; 8], [f32; 8]) =
                        (std::array::from_fn(|_| rng.next_f32() * 4.0 - 2.0), std::array::from_fn(|_| rng.next_f32() * 4.0 - 2.0));
                    let lanes = rng.next_u32() & 0xff;
                    let got = b.eval_lanes(Float8::load(&u), Float8::load(&v), lanes).map(Float8::to_array);
                    for l in bits(lanes) {
                        let want = b.eval(Vec2::new(u[l], v[l]));
                        for (row, want) in got.iter().zip(want.0) {
                            assert_eq!(row[l].to_bits(), want.to_bits(), "{file:?} {filter} {wrap} lane {l} at ({}, {})", u[l], v[l]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn lookups_hit_texel_centres() {
        let mut data = vec![0.0; 3 * 4];
        data[3] = 1.0; // texel (1, 0) red
        let b = Bitmap {
            texels: Texels::Linear(Arc::new(Image { width: 2, height: 2, data })),
            bilinear: true,
            wrap: Wrap::Clamp,
            to_uv: Transform::IDENTITY,
        };
        assert_eq!(b.eval(Vec2::new(0.75, 0.25)).r(), 1.0);
        assert!((b.eval(Vec2::new(0.5, 0.25)).r() - 0.5).abs() < 1e-6);
        assert_eq!(b.eval(Vec2::new(0.75, 0.75)).r(), 0.0);
    }

    /// The gradient is the bilinear interpolant's: it matches central differences of `eval`'s luminance
    /// inside a texel cell, through a scaling and rotating `to_uv`, and is 0 for `nearest`.
    #[test]
    fn gradients_are_the_interpolants() {
        use crate::sampling::Pcg32;
        let mut rng = Pcg32::new(9, 2);
        let data: Vec<f32> = (0..3 * 5 * 4).map(|_| rng.next_f32()).collect();
        let to_uv = Transform::rotate(Vec3::Z, 30.0).unwrap().then_after(Transform::scale(Vec3::new(2.0, 3.0, 1.0)).unwrap());
        let b = Bitmap { texels: Texels::Linear(Arc::new(Image { width: 5, height: 4, data })), bilinear: true, wrap: Wrap::Repeat, to_uv };
        for _ in 0..200 {
            let uv = Vec2::new(rng.next_f32(), rng.next_f32());
            let h = 1e-3;
            let f = |d: Vec2| f64::from(b.eval(uv + d).luminance());
            let numeric = Vec2::new(
                ((f(Vec2::new(h, 0.0)) - f(Vec2::new(-h, 0.0))) / (2.0 * f64::from(h))) as f32,
                ((f(Vec2::new(0.0, h)) - f(Vec2::new(0.0, -h))) / (2.0 * f64::from(h))) as f32,
            );
            let g = b.eval_1_grad(uv);
            // Central differences straddle a texel edge at some points: compare where both sides agree.
            let one_sided = Vec2::new(
                ((f(Vec2::new(h, 0.0)) - f(Vec2::ZERO)) / f64::from(h)) as f32,
                ((f(Vec2::new(0.0, h)) - f(Vec2::ZERO)) / f64::from(h)) as f32,
            );
            if (numeric - one_sided).length() < 1e-2 * numeric.length().max(1.0) {
                assert!((g - numeric).length() < 2e-2 * numeric.length().max(1.0), "at {uv}: {g} against {numeric}");
            }
        }
        let nearest = Bitmap { bilinear: false, ..b };
        assert_eq!(nearest.eval_1_grad(Vec2::new(0.3, 0.6)), Vec2::ZERO);
    }
}
