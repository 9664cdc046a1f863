//! Images in and out: a linear-RGB float buffer ([`Image`]) and the files a renderer meets.
//!
//! | format | read | write |
//! |---|---|---|
//! | OpenEXR (`.exr`) | first layer; R, G, B (A ignored) or a single Y channel; half, float or uint → `f32` | float32 RGB and any further named [`Channels`] (an `aov` integrator's), linear, lossless RLE compression (the `exr` crate's default) |
//! | Radiance (`.hdr`, `.rgbe`, `.pic`) | RGBE, run-length encoded or flat | RGBE, run-length encoded; negative and NaN samples as 0; RGB only |
//! | PNG (`.png`) | 8- or 16-bit, grey or colour, alpha ignored; sRGB-decoded to linear | 8-bit RGB, sRGB-encoded, clamped to [0, 1], rounded; RGB only |
//! | JPEG (`.jpg`, `.jpeg`) | 8-bit, grey or colour; sRGB-decoded to linear | — |
//! | BMP (`.bmp`) | 8-bit grey, colour or palette, alpha ignored; sRGB-decoded to linear | — |
//!
//! The format is taken from the file's magic bytes when they are recognised, else from the extension
//! (case-insensitive). Integer images are taken to be sRGB-encoded, as Mitsuba 3 does for PNG and JPEG
//! bitmaps that carry no other colour information.
//!
//! Writing is atomic: the file is encoded in memory first, written to a temporary file beside the target
//! (`.name.tmp-<pid>`) and renamed over it, so a failure never leaves a half-written file, and an existing
//! file at the target survives any error.
//!
//! ```
//! use gonio::image::Image;
//! use gonio::Rgb;
//! let mut img = Image::new(2, 1);
//! img.set(1, 0, Rgb::new(0.5, 0.25, 1.0));
//! assert_eq!(img.get(1, 0), Rgb::new(0.5, 0.25, 1.0));
//! ```

mod exr;
mod ldr;

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::spectrum::Rgb;

pub use crate::spectrum::rgb::{linear_to_srgb, srgb_to_linear};

/// A linear RGB image: row-major, top row first, three `f32` per pixel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    /// `3 · width · height` floats: pixel (x, y) starts at `3 · (y · width + x)`.
    pub data: Vec<f32>,
}

impl Image {
    /// A black image.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        Image { width, height, data: vec![0.0; 3 * width * height] }
    }

    /// The pixel at column `x`, row `y` (row 0 at the top).
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    #[inline]
    #[must_use]
    pub fn get(&self, x: usize, y: usize) -> Rgb {
        debug_assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}×{}", self.width, self.height);
        let i = 3 * (y * self.width + x);
        Rgb([self.data[i], self.data[i + 1], self.data[i + 2]])
    }

    /// Sets the pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    #[inline]
    pub fn set(&mut self, x: usize, y: usize, value: Rgb) {
        debug_assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}×{}", self.width, self.height);
        let i = 3 * (y * self.width + x);
        self.data[i..i + 3].copy_from_slice(&value.0);
    }

    /// The mean of all pixels (zero for an empty image); accumulated in `f64`.
    #[must_use]
    pub fn mean(&self) -> Rgb {
        let n = (self.width * self.height).max(1) as f64;
        let mut sum = [0.0f64; 3];
        for px in self.data.chunks_exact(3) {
            for c in 0..3 {
                sum[c] += f64::from(px[c]);
            }
        }
        Rgb([(sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32])
    }

    /// An error if `data` does not hold exactly `3 · width · height` floats.
    fn check_shape(&self, path: &Path) -> Result<()> {
        let expected = self.width.checked_mul(self.height).and_then(|n| n.checked_mul(3));
        if expected != Some(self.data.len()) {
            return Err(Error::format(
                path,
                "image",
                format!("expected 3·{}·{} floats of pixel data, found {}; nothing was written", self.width, self.height, self.data.len()),
            ));
        }
        Ok(())
    }
}

/// Named channels beside an image's RGB (an `aov` integrator's outputs, named as Mitsuba 3 names them,
/// e.g. `depth.T`): `names.len()` values per pixel, row-major, top row first. Written to EXR files only.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Channels {
    pub names: Vec<String>,
    /// `names.len() · width · height` floats: pixel i's values start at `names.len() · i`.
    pub data: Vec<f32>,
}

impl Channels {
    /// No channels.
    #[must_use]
    pub fn none() -> Self {
        Channels::default()
    }

    /// The values of channel `c` (an index into `names`), pixel by pixel.
    pub fn plane(&self, c: usize) -> impl Iterator<Item = f32> + '_ {
        self.data.iter().skip(c).step_by(self.names.len().max(1)).copied()
    }
}

/// The file formats gonio reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Exr,
    Hdr,
    Png,
    Jpeg,
    Bmp,
}

const READ_EXTENSIONS: &str = ".exr, .hdr (also .rgbe, .pic), .png, .jpg, .jpeg, .bmp";
const WRITE_EXTENSIONS: &str = ".exr, .png, .hdr";

fn format_from_extension(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "exr" => Some(Format::Exr),
        "hdr" | "rgbe" | "pic" => Some(Format::Hdr),
        "png" => Some(Format::Png),
        "jpg" | "jpeg" => Some(Format::Jpeg),
        "bmp" => Some(Format::Bmp),
        _ => None,
    }
}

fn format_from_magic(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        Some(Format::Exr)
    } else if bytes.starts_with(b"#?RADIANCE") || bytes.starts_with(b"#?RGBE") {
        Some(Format::Hdr)
    } else if bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]) {
        Some(Format::Png)
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        Some(Format::Jpeg)
    } else if bytes.starts_with(b"BM") {
        Some(Format::Bmp)
    } else {
        None
    }
}

/// An 8-bit image as its samples: row-major, top row first, `channels` bytes per pixel — one (grey, the
/// same in R, G and B) or three (R, G, B) —, sRGB-encoded unless the reader says otherwise. A grey file
/// stays one byte a pixel: roughness and mask maps are, and lookups of a 2048² one missed the caches three
/// times as often as three bytes (2026-12: a fifth of a render with such a map).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bytes8 {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    pub data: Vec<u8>,
}

impl Bytes8 {
    /// Pixel `p`'s (row-major index `y · width + x`) three samples (a grey pixel's one, three times).
    #[inline(always)]
    #[must_use]
    pub fn rgb(&self, p: usize) -> [u8; 3] {
        if self.channels == 1 {
            [self.data[p]; 3]
        } else {
            let i = 3 * p;
            [self.data[i], self.data[i + 1], self.data[i + 2]]
        }
    }
}

/// An image as a texture keeps it ([`read_stored_image`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Stored {
    /// Linear RGB floats (EXR, HDR, 16-bit PNG).
    Linear(Image),
    /// 8-bit PNG and JPEG: a quarter of the memory of linear floats, decoded at each lookup through a
    /// table of 256 ([`srgb8_table`]), which gives the floats [`read_image`] gives, bit for bit.
    Bytes(Bytes8),
}

/// The linear value of each 8-bit sRGB sample: `srgb_to_linear(v / 255)`.
#[must_use]
pub fn srgb8_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|v| srgb_to_linear(v as f32 / 255.0)))
}

impl Stored {
    /// Width and height in pixels.
    fn size(&self) -> (usize, usize) {
        match self {
            Stored::Linear(image) => (image.width, image.height),
            Stored::Bytes(b) => (b.width, b.height),
        }
    }

    /// Whether it holds the samples of its size: three per pixel, or an 8-bit grey image's one.
    fn samples_fit(&self) -> bool {
        let (width, height) = self.size();
        match self {
            Stored::Linear(image) => image.data.len() == 3 * width * height,
            Stored::Bytes(b) => matches!(b.channels, 1 | 3) && b.data.len() == b.channels * width * height,
        }
    }

    /// As linear RGB floats: 8-bit samples through [`srgb8_table`].
    #[must_use]
    pub fn into_linear(self) -> Image {
        match self {
            Stored::Linear(image) => image,
            Stored::Bytes(b) => {
                let table = srgb8_table();
                let data = (0..b.width * b.height).flat_map(|p| b.rgb(p)).map(|v| table[usize::from(v)]).collect();
                Image { width: b.width, height: b.height, data }
            }
        }
    }
}

/// Reads an image file as a texture keeps it: 8-bit files as their samples, others as [`read_image`]
/// does.
pub fn read_stored_image(path: &Path) -> Result<Stored> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    decode_stored_image(path, &bytes)
}

/// [`decode_image`], but an 8-bit file as its samples.
fn decode_stored_image(path: &Path, bytes: &[u8]) -> Result<Stored> {
    let format = format_of(path, bytes)?;
    let stored = guard(path, || match format {
        Format::Exr => exr::decode(path, bytes).map(Stored::Linear),
        Format::Hdr | Format::Png | Format::Jpeg | Format::Bmp => ldr::decode_stored(path, bytes, format),
    })?;
    let (width, height) = stored.size();
    if width == 0 || height == 0 {
        return Err(Error::format(path, "header", "image has no pixels"));
    }
    debug_assert!(stored.samples_fit());
    Ok(stored)
}

/// The format of the file `path` holding `bytes`: by its magic bytes, else by its extension.
fn format_of(path: &Path, bytes: &[u8]) -> Result<Format> {
    format_from_magic(bytes)
        .or_else(|| format_from_extension(path))
        .ok_or_else(|| Error::format(path, "header", format!("not a recognised image file; accepted: {READ_EXTENSIONS}")))
}

/// Reads an image file into linear RGB. See the module docs for the formats.
pub fn read_image(path: &Path) -> Result<Image> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    decode_image(path, &bytes)
}

/// Decodes the content of an image file into linear RGB; `path` names it in errors and, when the magic
/// bytes are not recognised, gives the format by its extension.
pub fn decode_image(path: &Path, bytes: &[u8]) -> Result<Image> {
    decode_stored_image(path, bytes).map(Stored::into_linear)
}

/// Writes `img` to `path`, atomically (see the module docs): `.exr` as float32 linear RGB, `.png` as
/// 8-bit sRGB, `.hdr` as RGBE.
pub fn write_image(path: &Path, img: &Image) -> Result<()> {
    write_image_with_notes(path, img, &[])
}

/// [`write_image`] with text notes (name, value) kept where the format has room for them: string
/// attributes in an EXR header (read back with [`read_notes`]); other formats drop them. `gonio render`
/// notes the samples per pixel written, those requested and whether the render was interrupted.
pub fn write_image_with_notes(path: &Path, img: &Image, notes: &[(&str, String)]) -> Result<()> {
    write_image_with_channels(path, img, &Channels::none(), notes)
}

/// [`write_image_with_notes`] with further channels beside the RGB, written to an EXR file under their
/// names; PNG and Radiance files hold the RGB only (the caller says so where it matters).
pub fn write_image_with_channels(path: &Path, img: &Image, extra: &Channels, notes: &[(&str, String)]) -> Result<()> {
    let format = writable_format(path)?;
    img.check_shape(path)?;
    if img.width == 0 || img.height == 0 {
        return Err(Error::format(path, "image", "cannot write an image with no pixels"));
    }
    if extra.data.len() != extra.names.len() * img.width * img.height {
        return Err(Error::format(
            path,
            "image",
            format!("expected {}·{}·{} floats of further channels, found {}", extra.names.len(), img.width, img.height, extra.data.len()),
        ));
    }
    let bytes = guard(path, || match format {
        Format::Exr => exr::encode(path, img, extra, notes),
        Format::Png => ldr::encode_png(path, img),
        Format::Hdr => ldr::encode_hdr(path, img),
        Format::Jpeg | Format::Bmp => {
            Err(Error::format(path, "file name", format!("cannot write this extension; accepted: {WRITE_EXTENSIONS}")))
        }
    })?;
    write_atomically(path, &bytes)
}

/// `img` encoded as an 8-bit sRGB PNG file in memory (as [`write_image`] writes `.png`).
pub fn encode_png(img: &Image) -> Result<Vec<u8>> {
    let path = Path::new("<PNG in memory>");
    img.check_shape(path)?;
    guard(path, || ldr::encode_png(path, img))
}

/// The text notes of an EXR file's header (its string attributes other than the required ones), sorted
/// by name; empty for other formats.
pub fn read_notes(path: &Path) -> Result<Vec<(String, String)>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if format_from_magic(&bytes) != Some(Format::Exr) {
        return Ok(Vec::new());
    }
    guard(path, || exr::notes(path, &bytes))
}

/// The format `path`'s extension asks for, or an error listing the extensions gonio writes.
fn writable_format(path: &Path) -> Result<Format> {
    format_from_extension(path)
        .filter(|f| !matches!(f, Format::Jpeg | Format::Bmp))
        .ok_or_else(|| Error::format(path, "file name", format!("cannot write this extension; accepted: {WRITE_EXTENSIONS}")))
}

/// Whether an image can be written to `path`: its extension is one gonio writes and a file can be created
/// in its directory (tried with the temporary name [`write_atomically`] uses, removed at once). Call it
/// before a long computation so that a typo in the output path fails in a second, not after the render.
/// `path` itself is not touched.
pub fn check_writable(path: &Path) -> Result<()> {
    writable_format(path)?;
    let tmp = temporary_path(path);
    std::fs::File::create(&tmp).map_err(|e| Error::io(path, e))?;
    let _ = std::fs::remove_file(&tmp);
    Ok(())
}

/// Runs a third-party decoder or encoder, turning a panic inside it into an error that names the file:
/// user data must never bring the process down (STYLE.md rule 6).
fn guard<T>(path: &Path, op: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(op))
        .unwrap_or_else(|_| Err(Error::format(path, "file", "the decoder failed on malformed data")))
}

/// The temporary file beside `path`: `.name.tmp-<pid>` in the same directory, so the rename stays on one
/// file system.
fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}

/// Writes `bytes` to a temporary file beside `path`, flushes it and renames it over `path`. On any error
/// the temporary is removed and `path` is untouched.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let tmp = temporary_path(path);
    let result = (|| -> std::io::Result<()> {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        // The temporary may not exist (creation failed); nothing more to do then.
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const DATA: &str = "/work/shared/data";

    fn scratch_dir(tag: &str) -> crate::scratch::ScratchDir {
        crate::scratch::ScratchDir::new(&format!("image-{tag}"))
    }

    fn test_pattern(width: usize, height: usize) -> Image {
        let mut img = Image::new(width, height);
        for y in 0..height {
            for x in 0..width {
                let v = Rgb::new(x as f32 / width as f32, y as f32 / height as f32, 0.3 + 0.01 * (x * y) as f32);
                img.set(x, y, v);
            }
        }
        img
    }

    fn assert_plausible(img: &Image, width: usize, height: usize, name: &str) -> Rgb {
        assert_eq!((img.width, img.height), (width, height), "{name}");
        assert_eq!(img.data.len(), 3 * width * height);
        assert!(img.data.iter().all(|v| v.is_finite() && *v >= 0.0), "{name}: non-finite or negative pixel");
        let mean = img.mean();
        println!("{name}: {}×{}, mean {mean}", img.width, img.height);
        assert!(mean.luminance() > 1e-4 && mean.luminance() < 1e3, "{name}: implausible mean {mean}");
        mean
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let dir = scratch_dir("exr");
        let mut img = test_pattern(7, 5);
        img.set(3, 2, Rgb::new(1e-7, 12345.678, 0.0));
        let path = dir.join("pattern.EXR");
        write_image(&path, &img).unwrap();
        let back = read_image(&path).unwrap();
        assert_eq!(back, img);
        assert!(std::fs::read_dir(&dir).unwrap().count() == 1, "temporary left behind");
    }

    #[test]
    fn png_round_trip_within_one_step() {
        let dir = scratch_dir("png");
        let img = test_pattern(9, 4);
        let path = dir.join("pattern.png");
        write_image(&path, &img).unwrap();
        let back = read_image(&path).unwrap();
        assert_eq!((back.width, back.height), (9, 4));
        for (a, b) in img.data.iter().zip(&back.data) {
            let (sa, sb) = (linear_to_srgb(a.clamp(0.0, 1.0)), linear_to_srgb(*b));
            assert!((sa - sb).abs() <= 0.5 / 255.0 + 1e-6, "{a} → {b}");
        }
    }

    #[test]
    fn hdr_round_trip_within_rgbe_precision() {
        let dir = scratch_dir("hdr");
        let mut img = test_pattern(6, 5);
        img.set(1, 1, Rgb::new(-1.0, f32::NAN, 3000.5));
        let path = dir.join("pattern.hdr");
        write_image(&path, &img).unwrap();
        let back = read_image(&path).unwrap();
        assert_eq!((back.width, back.height), (6, 5));
        for (a, b) in img.data.chunks_exact(3).zip(back.data.chunks_exact(3)) {
            // RGBE shares one exponent: each channel is kept to 8 bits of the largest one.
            let a: Vec<f32> = a.iter().map(|v| if *v > 0.0 { *v } else { 0.0 }).collect();
            let max = a.iter().fold(0.0f32, |m, v| m.max(*v));
            for (x, y) in a.iter().zip(b) {
                assert!((x - y).abs() <= max / 128.0, "{a:?} → {b:?}");
            }
        }
        assert!(std::fs::read_dir(&dir).unwrap().count() == 1, "temporary left behind");
    }

    #[test]
    fn png_write_clamps_and_reads_grey() {
        let dir = scratch_dir("clamp");
        let mut img = Image::new(2, 1);
        img.set(0, 0, Rgb::new(-1.0, 2.0, f32::NAN));
        img.set(1, 0, Rgb::splat(0.5));
        let path = dir.join("c.png");
        write_image(&path, &img).unwrap();
        let back = read_image(&path).unwrap();
        assert_eq!(back.get(0, 0), Rgb::new(0.0, 1.0, 0.0));
        // A grey 16-bit PNG with alpha, written by the `image` crate directly.
        let grey = ::image::ImageBuffer::<::image::LumaA<u16>, _>::from_raw(2, 1, vec![0u16, 65535, 65535, 0]).unwrap();
        let gpath = dir.join("grey.png");
        grey.save(&gpath).unwrap();
        let g = read_image(&gpath).unwrap();
        assert_eq!(g.get(0, 0), Rgb::ZERO);
        assert_eq!(g.get(1, 0), Rgb::ONE);
    }

    #[test]
    fn reads_jpeg_colour_and_grey() {
        let dir = scratch_dir("jpeg");
        // Flat images survive JPEG compression nearly exactly: sRGB 128 → linear 0.2158.
        let colour = ::image::RgbImage::from_pixel(16, 8, ::image::Rgb([128, 128, 128]));
        let path = dir.join("flat.JPG");
        colour.save_with_format(&path, ::image::ImageFormat::Jpeg).unwrap();
        let grey = ::image::GrayImage::from_pixel(8, 8, ::image::Luma([255]));
        let gpath = dir.join("white.jpeg");
        grey.save_with_format(&gpath, ::image::ImageFormat::Jpeg).unwrap();
        let img = read_image(&path).unwrap();
        assert_eq!((img.width, img.height), (16, 8));
        let want = srgb_to_linear(128.0 / 255.0);
        assert!(img.data.iter().all(|v| (v - want).abs() < 0.01), "{:?}", img.get(0, 0));
        let white = read_image(&gpath).unwrap();
        assert!(white.data.iter().all(|v| (v - 1.0).abs() < 0.01));
    }

    /// BMP (8-bit, as Mitsuba's `flower.bmp`): samples sRGB-decoded, top row first, whatever the file's
    /// row order; never written.
    #[test]
    fn reads_bmp() {
        let dir = scratch_dir("bmp");
        let mut img = ::image::RgbImage::new(3, 2);
        img.put_pixel(0, 0, ::image::Rgb([255, 0, 0]));
        img.put_pixel(2, 1, ::image::Rgb([0, 128, 255]));
        let path = dir.join("two_rows.bmp");
        img.save_with_format(&path, ::image::ImageFormat::Bmp).unwrap();
        let read = read_image(&path).unwrap();
        assert_eq!((read.width, read.height), (3, 2));
        assert_eq!(read.get(0, 0), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(read.get(2, 1), Rgb::new(0.0, srgb_to_linear(128.0 / 255.0), 1.0));
        assert_eq!(read.get(1, 0), Rgb::ZERO);
        let e = write_image(&dir.join("out.bmp"), &Image::new(1, 1)).unwrap_err().to_string();
        assert!(e.contains("cannot write this extension"), "{e}");
    }

    #[test]
    fn reads_flat_radiance_hdr() {
        // A 2×1 flat (not run-length encoded) RGBE file: (128,64,32, e=129) = (1, 0.5, 0.25);
        // (128,128,128, e=128+2) = (2, 2, 2). Value = m · 2^(e − 136) (Radiance's RGBE: (m + 0.5)·2^(e−136)
        // in some readers; both give within 1 %).
        let dir = scratch_dir("hdr");
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
        bytes.extend_from_slice(&[128, 64, 32, 129, 128, 128, 128, 130]);
        let path = dir.join("flat.hdr");
        std::fs::write(&path, &bytes).unwrap();
        let img = read_image(&path).unwrap();
        assert_eq!((img.width, img.height), (2, 1));
        let (a, b) = (img.get(0, 0), img.get(1, 0));
        for (got, want) in [(a.r(), 1.0), (a.g(), 0.5), (a.b(), 0.25), (b.r(), 2.0), (b.b(), 2.0)] {
            assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
        }
    }

    #[test]
    fn reads_real_environment_maps() {
        let museum = read_image(Path::new(&format!("{DATA}/envmaps/museum.exr"))).unwrap();
        assert_plausible(&museum, 512, 256, "museum.exr");
        let venice = read_image(Path::new(&format!("{DATA}/envmaps/venice_sunset_1k.hdr"))).unwrap();
        assert_plausible(&venice, 1024, 512, "venice_sunset_1k.hdr");
    }

    /// Headers claiming absurd sizes in files of a few hundred bytes: a clear error, fast, and no
    /// allocation for the claimed pixels (a 4096² EXR is under the pixel limit, but cannot be held by 300
    /// bytes; a 10⁵ × 10⁵ PNG hits the `image` crate's 512 MiB allocation limit).
    #[test]
    fn absurd_dimensions_are_refused_before_allocating() {
        let dir = scratch_dir("absurd");
        let exr = dir.join("claims.exr");
        write_image(&exr, &test_pattern(3, 2)).unwrap();
        let mut bytes = std::fs::read(&exr).unwrap();
        let at = bytes.windows(11).position(|w| w == b"dataWindow\0").unwrap() + 11 + 6 + 4;
        bytes[at + 8..at + 12].copy_from_slice(&4095i32.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&4095i32.to_le_bytes());
        let start = std::time::Instant::now();
        let err = decode_image(&exr, &bytes).unwrap_err().to_string();
        assert!(err.contains("claims.exr") && err.contains("4096×4096") && err.contains("cannot be stored in a file of"), "{err}");

        // PNG: signature, then an IHDR chunk (length, type, 13 bytes, CRC over type and data).
        let mut png = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];
        let mut ihdr = b"IHDR".to_vec();
        ihdr.extend_from_slice(&100_000u32.to_be_bytes());
        ihdr.extend_from_slice(&100_000u32.to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8-bit RGB, deflate, adaptive filter, no interlace
        let mut crc = flate2::Crc::new();
        crc.update(&ihdr);
        png.extend_from_slice(&13u32.to_be_bytes());
        png.extend_from_slice(&ihdr);
        png.extend_from_slice(&crc.sum().to_be_bytes());
        png.extend_from_slice(&[0, 0, 0, 0, b'I', b'E', b'N', b'D', 0xae, 0x42, 0x60, 0x82]);
        let err = decode_image(Path::new("claims.png"), &png).unwrap_err().to_string();
        assert!(err.contains("claims.png"), "{err}");
        assert!(start.elapsed().as_secs_f64() < 10.0, "took {:?}", start.elapsed());
    }

    #[test]
    fn reads_mitsuba_reference_exr() {
        let path = format!("{DATA}/mitsuba/tests/scenes/bsdf_spheres/refs/test_arealight_ref_rgb.exr");
        let img = read_image(Path::new(&path)).unwrap();
        assert_plausible(&img, 48, 48, "test_arealight_ref_rgb.exr");
    }

    #[test]
    fn truncated_files_are_errors_naming_the_file() {
        let dir = scratch_dir("trunc");
        for name in ["envmaps/museum.exr", "envmaps/venice_sunset_1k.hdr"] {
            let src = std::fs::read(format!("{DATA}/{name}")).unwrap();
            let file = Path::new(name).file_name().unwrap();
            let path = dir.join(file);
            for len in [0, 3, 100, src.len() / 2] {
                std::fs::write(&path, &src[..len]).unwrap();
                let err = read_image(&path).expect_err("truncated file accepted");
                assert!(err.to_string().contains(file.to_str().unwrap()), "{err}");
            }
        }
        // An EXR whose data window claims 10⁶ × 10⁶ pixels: refused before any allocation.
        let exr = dir.join("huge.exr");
        write_image(&exr, &test_pattern(3, 2)).unwrap();
        let mut bytes = std::fs::read(&exr).unwrap();
        let at = bytes.windows(11).position(|w| w == b"dataWindow\0").unwrap() + 11 + 6 + 4;
        bytes[at + 8..at + 12].copy_from_slice(&1_000_000i32.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&1_000_000i32.to_le_bytes());
        std::fs::write(&exr, &bytes).unwrap();
        let err = read_image(&exr).unwrap_err().to_string();
        assert!(err.contains("huge.exr"), "{err}");
        println!("hostile EXR header: {err}");
        // A truncated PNG of our own.
        let png = dir.join("t.png");
        write_image(&png, &test_pattern(40, 40)).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        std::fs::write(&png, &bytes[..100.min(bytes.len() - 1)]).unwrap();
        assert!(read_image(&png).unwrap_err().to_string().contains("t.png"));
        // Unknown content and extension.
        let txt = dir.join("notes.txt");
        std::fs::write(&txt, "hello").unwrap();
        assert!(read_image(&txt).unwrap_err().to_string().contains(".exr"));
        assert!(matches!(read_image(&dir.join("missing.exr")), Err(Error::Io { .. })));
    }

    #[test]
    fn exr_notes_round_trip_and_other_formats_have_none() {
        let dir = scratch_dir("notes");
        let path = dir.join("noted.exr");
        let notes = [("gonio.spp", "12".to_string()), ("gonio.interrupted", "true".to_string())];
        write_image_with_notes(&path, &test_pattern(3, 2), &notes).unwrap();
        assert_eq!(read_image(&path).unwrap(), test_pattern(3, 2));
        let back = read_notes(&path).unwrap();
        assert_eq!(back, [("gonio.interrupted".to_string(), "true".to_string()), ("gonio.spp".to_string(), "12".to_string())]);
        let png = dir.join("noted.png");
        write_image_with_notes(&png, &test_pattern(3, 2), &notes).unwrap();
        assert!(read_notes(&png).unwrap().is_empty());
        let err = write_image_with_notes(&dir.join("bad.exr"), &test_pattern(1, 1), &[("x", "\u{1F600}".to_string())]).unwrap_err();
        assert!(err.to_string().contains("bad.exr"), "{err}");
    }

    /// Further channels are written to EXR files under their names, each the values given for it; the RGB
    /// reads back as before, and a count that does not match the image is refused.
    #[test]
    fn exr_files_carry_further_channels() {
        let dir = scratch_dir("channels");
        let path = dir.join("aov.exr");
        let extra = Channels { names: vec!["dd.y.T".into(), "nn.X".into()], data: (0..12).map(|i| i as f32 * 0.5).collect() };
        write_image_with_channels(&path, &test_pattern(3, 2), &extra, &[]).unwrap();
        assert_eq!(read_image(&path).unwrap(), test_pattern(3, 2));
        let image = ::exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
        let channels = &image.layer_data[0].channel_data.list;
        let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
        assert_eq!(names, ["B", "G", "R", "dd.y.T", "nn.X"]);
        let values = |c: usize| channels[c].sample_data.values_as_f32().collect::<Vec<f32>>();
        assert_eq!((values(3), values(4)), (vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0], vec![0.5, 1.5, 2.5, 3.5, 4.5, 5.5]));
        let short = Channels { names: vec!["d.T".into()], data: vec![0.0; 5] };
        let e = write_image_with_channels(&dir.join("short.exr"), &test_pattern(3, 2), &short, &[]).unwrap_err();
        assert!(e.to_string().contains("expected 1·3·2 floats of further channels, found 5"), "{e}");
    }

    #[test]
    fn check_writable_catches_bad_paths_and_leaves_nothing() {
        let dir = scratch_dir("writable");
        check_writable(&dir.join("ok.exr")).unwrap();
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "the probe file was left behind");
        assert!(check_writable(&dir.join("x.jpg")).unwrap_err().to_string().contains(".exr, .png"));
        assert!(matches!(check_writable(&dir.join("no/such/dir/out.exr")), Err(Error::Io { .. })));
        // A regular file where a directory should be: an error even for root.
        std::fs::write(dir.join("file"), "x").unwrap();
        let err = check_writable(&dir.join("file/out.exr")).unwrap_err();
        assert!(err.to_string().contains("file/out.exr"), "{err}");
    }

    #[test]
    fn writing_into_a_missing_directory_leaves_nothing() {
        let dir = scratch_dir("missing");
        let path = dir.join("no/such/dir/out.exr");
        assert!(matches!(write_image(&path, &test_pattern(2, 2)), Err(Error::Io { .. })));
        assert!(!dir.join("no").exists());
    }

    #[test]
    fn a_failed_write_keeps_the_old_file() {
        let dir = scratch_dir("keep");
        let path = dir.join("keep.png");
        write_image(&path, &test_pattern(4, 4)).unwrap();
        let before = std::fs::read(&path).unwrap();
        let mut bad = test_pattern(4, 4);
        bad.data.pop();
        let err = write_image(&path, &bad).unwrap_err();
        assert!(err.to_string().contains("keep.png"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), before);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "temporary left behind");
        // Unknown extension: an error listing the accepted ones.
        let err = write_image(&dir.join("x.tiff"), &test_pattern(1, 1)).unwrap_err();
        assert!(err.to_string().contains(".exr, .png"), "{err}");
    }

    #[test]
    fn a_read_only_directory_is_an_error_and_leaves_nothing() {
        let dir = scratch_dir("ro");
        let ro = dir.join("ro");
        std::fs::create_dir(&ro).unwrap();
        let mut perms = std::fs::metadata(&ro).unwrap().permissions();
        perms.set_readonly(true);
        std::fs::set_permissions(&ro, perms.clone()).unwrap();
        let result = write_image(&ro.join("out.png"), &test_pattern(2, 2));
        #[allow(clippy::permissions_set_readonly_false)]
        perms.set_readonly(false);
        let listing: Vec<_> = std::fs::read_dir(&ro).unwrap().collect();
        std::fs::set_permissions(&ro, perms).unwrap();
        // Root ignores directory permissions; then the write succeeds, which is also correct.
        match result {
            Err(e) => {
                assert!(e.to_string().contains("out.png"));
                assert!(listing.is_empty(), "left behind: {listing:?}");
            }
            Ok(()) => assert_eq!(listing.len(), 1),
        }
    }
}
