//! OpenEXR through the pure-Rust `exr` crate: the first valid layer, largest resolution level, any flat
//! channels. Channel names match on their last `.`-separated part, so `R` and `diffuse.R` both count; R, G
//! and B make colour, a lone Y (luminance) is copied to all three, alpha and any other channel are ignored.

use std::io::Cursor;
use std::path::Path;

use ::exr::prelude as x;
use ::exr::prelude::{ReadChannels as _, ReadLayers as _, WritableImage as _};

use super::{Channels, Image};
use crate::error::{Error, Result};

/// More pixels than this in one layer is taken as a hostile or corrupt header: refused before the
/// decoder allocates for it (2²⁸ pixels = a 16384² image, 3 GiB as f32 RGB).
const MAX_PIXELS: usize = 1 << 28;
/// Every pixel of every layer holds at least one 2-byte (half) sample, and deflate, the strongest of
/// the compressions the `exr` crate reads, expands by at most about 1032:1 (RFC 1951 §3.2.5: a 258-byte
/// match in 2 bits); so an honest file holds at most 516 pixels per byte. A header claiming more is
/// refused before the decoder allocates for it.
const MAX_PIXELS_PER_BYTE: usize = 1032 / 2;

pub(super) fn decode(path: &Path, bytes: &[u8]) -> Result<Image> {
    let exr_err = |e: ::exr::error::Error| Error::format(path, "OpenEXR data", e.to_string());
    let meta = ::exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(exr_err)?;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        if !matches!(size.width().checked_mul(size.height()), Some(n) if n <= MAX_PIXELS) {
            return Err(Error::format(
                path,
                "header",
                format!("data window {}×{} exceeds the limit of {MAX_PIXELS} pixels", size.width(), size.height()),
            ));
        }
        let pixels = size.width() * size.height();
        if pixels > bytes.len().saturating_mul(MAX_PIXELS_PER_BYTE) {
            return Err(Error::format(
                path,
                "header",
                format!(
                    "data window {}×{} ({pixels} pixels) cannot be stored in a file of {} bytes: truncated or corrupt",
                    size.width(),
                    size.height(),
                    bytes.len()
                ),
            ));
        }
    }
    let image = x::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(exr_err)?;
    let layer = image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let pixels = width.checked_mul(height).ok_or_else(|| Error::format(path, "header", "image too large"))?;

    let find = |wanted: &str| {
        layer.channel_data.list.iter().find(|c| {
            let name = c.name.to_string();
            name.rsplit('.').next().is_some_and(|last| last.eq_ignore_ascii_case(wanted))
        })
    };
    let planes: [&::exr::image::AnyChannel<x::FlatSamples>; 3] = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => [r, g, b],
        (_, _, _, Some(y)) => [y, y, y],
        _ => {
            let names: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
            return Err(Error::format(path, "channels", format!("expected R, G, B or Y channels, found [{}]", names.join(", "))));
        }
    };
    for plane in planes {
        if plane.sample_data.len() != pixels {
            return Err(Error::format(
                path,
                format!("channel {}", plane.name),
                format!(
                    "expected {pixels} samples ({width}×{height}), found {} (subsampled channels are not supported)",
                    plane.sample_data.len()
                ),
            ));
        }
    }

    let mut img = Image { width, height, data: vec![0.0; 3 * pixels] };
    for (c, plane) in planes.iter().enumerate() {
        for (i, v) in plane.sample_data.values_as_f32().enumerate() {
            img.data[3 * i + c] = v;
        }
    }
    Ok(img)
}

/// Encodes `img` as float32 channels R, G, B and `extra`'s under their names (the file lists them sorted
/// by name, as OpenEXR requires), with each note as a string attribute of the layer header (names and
/// values must be representable as EXR text: Latin-1, no longer than the format allows).
pub(super) fn encode(path: &Path, img: &Image, extra: &Channels, notes: &[(&str, String)]) -> Result<Vec<u8>> {
    let text = |name: &str, what: &str| {
        x::Text::new_or_none(name).ok_or_else(|| Error::format(path, "OpenEXR encoding", format!("the {what} `{name}` is not EXR text")))
    };
    let mut list = x::SmallVec::new();
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let plane = img.data.iter().skip(c).step_by(3).copied().collect();
        list.push(x::AnyChannel::new(*name, x::FlatSamples::F32(plane)));
    }
    for (c, name) in extra.names.iter().enumerate() {
        list.push(x::AnyChannel::new(text(name, "channel name")?, x::FlatSamples::F32(extra.plane(c).collect())));
    }
    let channels = x::AnyChannels::sort(list);
    let mut image = x::Image::from_channels((img.width, img.height), channels);
    for (name, value) in notes {
        let (Some(n), Some(v)) = (x::Text::new_or_none(name), x::Text::new_or_none(value)) else {
            return Err(Error::format(path, "OpenEXR encoding", format!("the note `{name}` = `{value}` is not EXR text")));
        };
        image.layer_data.attributes.other.insert(n, ::exr::meta::attribute::AttributeValue::Text(v));
    }
    let mut out = Cursor::new(Vec::new());
    image.write().non_parallel().to_buffered(&mut out).map_err(|e| Error::format(path, "OpenEXR encoding", e.to_string()))?;
    Ok(out.into_inner())
}

/// The string attributes of the first header, other than the ones the format defines.
pub(super) fn notes(path: &Path, bytes: &[u8]) -> Result<Vec<(String, String)>> {
    let meta = ::exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| Error::format(path, "OpenEXR data", e.to_string()))?;
    let mut notes: Vec<(String, String)> = meta
        .headers
        .iter()
        .take(1)
        .flat_map(|h| h.own_attributes.other.iter().chain(h.shared_attributes.other.iter()))
        .filter_map(|(k, v)| match v {
            ::exr::meta::attribute::AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    notes.sort();
    Ok(notes)
}
