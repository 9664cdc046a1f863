//! The explorer's views of one model, from the functions `gonio plot` and `gonio preview` draw from:
//! [`crate::plot`] (with its defaults, so the numbers are those of `gonio plot`) and [`crate::preview`].

use super::number;
use crate::bsdf::{Bsdf, BsdfFlags, BsdfModel};
use crate::error::{Error, Result};
use crate::plot::{self, albedo_data, lobe_data, slice_data, Channel};
use crate::preview::{render_preview, Lighting, AMBIENT};
use crate::scene::Material;
use crate::spectrum::Rgb;
use crate::verify::energy::{albedo_curve, white_furnace};
use glam::Vec3;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::atomic::AtomicBool;

/// The white furnace's budget: viewing angles (uniform in cos θo) and samples per angle, 65 536 samples in
/// all, an eighth of the albedo curve's. Against 64 angles × 262 144 samples (2026-12-04, `gonio albedo`):
/// within 4e-4 for GGX α = 0.2, Beckmann α = 0.8, rough plastic and Oren–Nayar; 0.7 % low for the
/// unnormalised Phong counter-example (1.263 against 1.272: still far above 1).
const FURNACE_ANGLES: usize = 16;
const FURNACE_SAMPLES: usize = 4096;

/// Which plot's numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotKind {
    Polar,
    Lobe,
    Slice,
    Albedo,
}

/// What `/api/plot` computes: the arguments of `gonio plot`.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotRequest {
    pub kind: PlotKind,
    pub theta_o: f64,
    pub phi_d: f64,
    pub channel: Channel,
    pub angles: usize,
    pub samples: usize,
}

impl PlotRequest {
    /// From the query: `kind` (polar, lobe, slice, albedo), `theta_o` (30), `phi_d` (90), `channel`
    /// (lum), `angles` and `samples` of the albedo curve (`gonio plot`'s defaults).
    pub fn from_query(q: &HashMap<String, String>) -> Result<Self> {
        let kind = match q.get("kind").map_or("polar", String::as_str) {
            "polar" => PlotKind::Polar,
            "lobe" | "3d" => PlotKind::Lobe,
            "slice" => PlotKind::Slice,
            "albedo" => PlotKind::Albedo,
            other => return Err(Error::spec("kind", format!("unknown plot `{other}`; expected polar, lobe, slice or albedo"))),
        };
        let channel_name = q.get("channel").map_or("lum", String::as_str);
        let channel = Channel::parse(channel_name)
            .ok_or_else(|| Error::spec("channel", format!("unknown channel `{channel_name}`; expected r, g, b or lum")))?;
        let count = |name: &str, default: usize, max: f64| -> Result<usize> {
            let v = number(q, name, default as f64)?;
            if !(1.0..=max).contains(&v) || v.fract() != 0.0 {
                return Err(Error::spec(name, format!("must be a whole number in [1, {max}], got {v}")));
            }
            Ok(v as usize)
        };
        Ok(PlotRequest {
            kind,
            theta_o: number(q, "theta_o", 30.0)?,
            phi_d: number(q, "phi_d", 90.0)?,
            channel,
            angles: count("angles", plot::ALBEDO_ANGLES, 180.0)?,
            samples: count("samples", plot::ALBEDO_SAMPLES, 1_048_576.0)?,
        })
    }
}

/// An `f32` as JSON in its shortest form that reads back as the same `f32` (NaN and ±∞ as null).
fn number_json(v: f32) -> Value {
    if v.is_finite() {
        v.to_string().parse::<f64>().map_or(Value::Null, |x| json!(x))
    } else {
        Value::Null
    }
}

fn channel_json(channel: Channel, values: &[Rgb]) -> Value {
    Value::Array(values.iter().map(|&v| number_json(channel.of(v))).collect())
}

fn rgb_json(v: Rgb) -> Value {
    Value::Array(v.0.iter().map(|&c| number_json(c)).collect())
}

/// The numbers of one plot, as `gonio plot` computes them for the same arguments.
pub fn plot(bsdf: &Bsdf, r: &PlotRequest) -> Result<Value> {
    let c = r.channel;
    Ok(match r.kind {
        PlotKind::Polar => {
            let l = lobe_data(bsdf, r.theta_o, plot::POLAR_SAMPLES, 0, 0)?;
            json!({
                "kind": "polar", "theta_o": l.theta_o, "angles": l.angles,
                "incidence": channel_json(c, &l.incidence), "perpendicular": channel_json(c, &l.perpendicular),
                "transmission": bsdf.flags().intersects(BsdfFlags::TRANSMISSION),
            })
        }
        PlotKind::Lobe => {
            let l = lobe_data(bsdf, r.theta_o, 2, plot::GRID_THETA, plot::GRID_PHI)?;
            json!({"kind": "lobe", "theta_o": l.theta_o, "theta": l.grid.theta, "phi": l.grid.phi, "values": channel_json(c, &l.grid.values)})
        }
        PlotKind::Slice => {
            let s = slice_data(bsdf, r.phi_d, plot::SLICE_RES, plot::SLICE_RES)?;
            json!({"kind": "slice", "phi_d": s.phi_d, "theta_h": s.theta_h, "theta_d": s.theta_d, "values": channel_json(c, &s.values)})
        }
        PlotKind::Albedo => {
            let a = albedo_data(bsdf, r.angles, r.samples, 0)?;
            // The white furnace as `gonio albedo` computes it (the cosine-weighted mean of the albedo), on
            // a lighter budget than the curve's: it is one number, and the curve is what takes the time.
            let furnace = white_furnace(&albedo_curve(bsdf, FURNACE_ANGLES, 1.0, FURNACE_SAMPLES, 0));
            json!({
                "kind": "albedo", "theta_o": a.theta_o, "albedo": channel_json(c, &a.albedo),
                "furnace": rgb_json(furnace), "furnace_channel": number_json(c.of(furnace)),
            })
        }
    })
}

/// The lit sphere as PNG: `light` = env (`environment`: the explorer's environment map, else the built-in sky), sky,
/// furnace (uniform radiance 1) or dir (from `dir=x,y,z`, +x right, +y up, +z towards the viewer, with
/// the CLI's ambient); `size` (128) pixels a side, `spp` (1) samples per pixel, `seed` (0).
pub fn sphere(bsdf: &Bsdf, q: &HashMap<String, String>, environment: Lighting, cancel: &AtomicBool) -> Result<Vec<u8>> {
    let lighting = match q.get("light").map_or("env", String::as_str) {
        "env" => environment,
        "sky" => Lighting::GradientSky,
        "furnace" => Lighting::Constant(Rgb::ONE),
        "dir" => {
            let text = q.get("dir").map_or("1,1,1", String::as_str);
            let parts: Vec<f32> = text.split(',').filter_map(|s| s.trim().parse().ok()).collect();
            let d = match parts.as_slice() {
                [x, y, z] => Vec3::new(*x, *y, *z),
                _ => return Err(Error::spec("dir", format!("expected a direction x,y,z of three numbers, got `{text}`"))),
            };
            Lighting::Directional { towards_light: d, ambient: AMBIENT }
        }
        other => return Err(Error::spec("light", format!("unknown lighting `{other}`; expected env, sky, furnace or dir"))),
    };
    let size = number(q, "size", 128.0)?;
    let spp = number(q, "spp", 1.0)?;
    let seed = number(q, "seed", 0.0)?;
    if !(8.0..=512.0).contains(&size) {
        return Err(Error::spec("size", format!("must be in [8, 512] pixels, got {size}")));
    }
    if !(1.0..=1024.0).contains(&spp) {
        return Err(Error::spec("spp", format!("must be in [1, 1024] samples per pixel, got {spp}")));
    }
    if !(0.0..=1e9).contains(&seed) {
        return Err(Error::spec("seed", format!("must be in [0, 10⁹], got {seed}")));
    }
    let material = || Ok(Material::Fixed(bsdf.clone()));
    let out = render_preview(&material, &lighting, size as u32, spp as u32, seed as u64, None, cancel)?;
    crate::image::encode_png(&out.image)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(kind: PlotKind) -> PlotRequest {
        PlotRequest { kind, theta_o: 30.0, phi_d: 90.0, channel: Channel::Lum, angles: 4, samples: 256 }
    }

    #[test]
    fn plot_numbers_are_those_of_the_plot_module() {
        let b = Bsdf::from_json(r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3}"#).unwrap();
        let v = plot(&b, &request(PlotKind::Polar)).unwrap();
        let l = lobe_data(&b, 30.0, plot::POLAR_SAMPLES, 0, 0).unwrap();
        let got: Vec<f32> = v["incidence"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect();
        assert_eq!(got, Channel::Lum.of_all(&l.incidence));
        let a = plot(&b, &request(PlotKind::Albedo)).unwrap();
        let furnace = a["furnace_channel"].as_f64().unwrap();
        assert!(furnace > 0.5 && furnace < 1.0, "{furnace}");
        // At φd = 0 part of the θh × θd grid has a direction below the horizon.
        let s = plot(&b, &PlotRequest { phi_d: 0.0, ..request(PlotKind::Slice) }).unwrap();
        assert_eq!(s["values"].as_array().unwrap().len(), plot::SLICE_RES * plot::SLICE_RES);
        assert!(s["values"].as_array().unwrap().iter().any(Value::is_null), "unreachable cells are null");
    }

    #[test]
    fn sphere_is_a_png() {
        let b = Bsdf::from_json(r#"{"type": "diffuse"}"#).unwrap();
        let q: HashMap<String, String> =
            [("light", "furnace"), ("size", "16")].iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        let png = sphere(&b, &q, Lighting::GradientSky, &AtomicBool::new(false)).unwrap();
        assert!(png.starts_with(&[0x89, b'P', b'N', b'G']));
        let mut bad = q.clone();
        bad.insert("size".into(), "4".into());
        assert!(sphere(&b, &bad, Lighting::GradientSky, &AtomicBool::new(false)).unwrap_err().to_string().starts_with("size:"));
    }
}
