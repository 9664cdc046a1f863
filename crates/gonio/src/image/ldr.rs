//! PNG, JPEG and Radiance HDR through the `image` crate (JPEG read only; PNG and HDR both ways).
//! Integer samples are sRGB-decoded to linear; HDR samples are linear already.

use std::io::Cursor;
use std::path::Path;

use ::image::{DynamicImage, ImageFormat};

use super::{linear_to_srgb, srgb_to_linear, Bytes8, Format, Image, Stored};
use crate::error::{Error, Result};

/// The file as the `image` crate decodes it.
fn decode_dynamic(path: &Path, bytes: &[u8], format: Format) -> Result<DynamicImage> {
    let image_format = match format {
        Format::Hdr => ImageFormat::Hdr,
        Format::Png => ImageFormat::Png,
        Format::Jpeg => ImageFormat::Jpeg,
        Format::Bmp => ImageFormat::Bmp,
        Format::Exr => unreachable!("EXR is decoded by the exr module"),
    };
    ::image::load_from_memory_with_format(bytes, image_format)
        .map_err(|e| Error::format(path, format!("{image_format:?} data"), e.to_string()))
}

/// The file's pixels: 8-bit files as their samples, others as linear floats (integer samples sRGB-decoded).
pub(super) fn decode_stored(path: &Path, bytes: &[u8], format: Format) -> Result<Stored> {
    let decoded = decode_dynamic(path, bytes, format)?;
    let (width, height) = (decoded.width() as usize, decoded.height() as usize);
    let stored = match decoded {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            Stored::Linear(Image { width, height, data: decoded.into_rgb32f().into_raw() })
        }
        DynamicImage::ImageLuma16(_) | DynamicImage::ImageLumaA16(_) | DynamicImage::ImageRgb16(_) | DynamicImage::ImageRgba16(_) => {
            // A table would be 64 K entries; the curve is cheap enough per sample.
            let data = decoded.into_rgb16().into_raw().into_iter().map(|v| srgb_to_linear(f32::from(v) / 65535.0)).collect();
            Stored::Linear(Image { width, height, data })
        }
        DynamicImage::ImageLuma8(_) | DynamicImage::ImageLumaA8(_) => {
            Stored::Bytes(Bytes8 { width, height, channels: 1, data: decoded.into_luma8().into_raw() })
        }
        _ => Stored::Bytes(Bytes8 { width, height, channels: 3, data: decoded.into_rgb8().into_raw() }),
    };
    if !stored.samples_fit() {
        return Err(Error::format(path, "pixels", "decoder returned the wrong number of samples"));
    }
    Ok(stored)
}

pub(super) fn encode_png(path: &Path, img: &Image) -> Result<Vec<u8>> {
    let too_large = || Error::format(path, "image", "too large for PNG (at most 2³²−1 pixels a side)");
    let width = u32::try_from(img.width).map_err(|_| too_large())?;
    let height = u32::try_from(img.height).map_err(|_| too_large())?;
    let bytes: Vec<u8> = img
        .data
        .iter()
        .map(|&v| {
            // NaN maps to 0 (`clamp` keeps NaN, so treat it first).
            let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
            (linear_to_srgb(v) * 255.0).round() as u8
        })
        .collect();
    let buffer = ::image::RgbImage::from_raw(width, height, bytes).ok_or_else(too_large)?;
    let mut out = Cursor::new(Vec::new());
    buffer.write_to(&mut out, ImageFormat::Png).map_err(|e| Error::format(path, "PNG encoding", e.to_string()))?;
    Ok(out.into_inner())
}

/// Radiance RGBE (run-length encoded), linear. RGBE has no sign and no NaN: negative and NaN samples
/// are written as 0, values above its range (≈ 1.7·10³⁸) as its largest value.
pub(super) fn encode_hdr(path: &Path, img: &Image) -> Result<Vec<u8>> {
    let pixels: Vec<::image::Rgb<f32>> = img
        .data
        .chunks_exact(3)
        .map(|p| ::image::Rgb(std::array::from_fn(|c| if p[c] > 0.0 { p[c].min(f32::MAX) } else { 0.0 })))
        .collect();
    let mut out = Vec::new();
    ::image::codecs::hdr::HdrEncoder::new(&mut out)
        .encode(&pixels, img.width, img.height)
        .map_err(|e| Error::format(path, "HDR encoding", e.to_string()))?;
    Ok(out)
}
