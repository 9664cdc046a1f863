//! `gonio plot BSDF... --theta-o DEG [--kind polar|3d|slice|albedo] [--log] [--channel r|g|b|lum] -o FILE`:
//! figures of one or more models overlaid, from the numbers of [`gonio::plot`].
//!
//! - `polar`: f·cos θi in the plane of incidence and in the perpendicular plane through the mirror
//!   direction, for the viewing angle θo (`--theta-o`, required);
//! - `3d`: the lobe f·cos θi over all incident directions for that θo (`--theta-o`, required);
//! - `slice`: f on MERL's θh × θd grid at φd = `--phi-d` (default 90°), one panel per model;
//! - `albedo`: the directional albedo against θo (`--angles`, `--samples`); `--theta-o` is marked if given.
//!
//! The output format follows the extension: `.svg`, `.png` (the SVG rasterised, with an embedded font),
//! or `.csv` — the numbers the figure is drawn from, each written in the shortest form that reads back as
//! the same `f32`. Files are written atomically. Legend names are `--label` (one per model) or the
//! models' plugin names.

use crate::figure::{self, raster, svg::Svg};
use crate::spec::load_bsdf;
use gonio::bsdf::{BsdfFlags, BsdfModel};
use gonio::plot::{
    albedo_data, lobe_data, slice_data, Channel, ALBEDO_ANGLES, ALBEDO_SAMPLES, GRID_PHI, GRID_THETA, POLAR_SAMPLES, SLICE_RES,
};
use gonio::{Bsdf, Error};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// f·cos θi in two planes, for one θo.
    Polar,
    /// The lobe f·cos θi in 3-D, for one θo.
    #[value(name = "3d")]
    Lobe3d,
    /// f on the θh × θd grid at one φd.
    Slice,
    /// Directional albedo against θo.
    Albedo,
}

#[derive(clap::Args)]
pub struct Args {
    /// Models: JSON in Mitsuba's dictionary form, an XML file with one <bsdf>, or a measured file (.binary MERL, .bsdf RGL).
    #[arg(required = true, value_name = "BSDF")]
    bsdf: Vec<String>,
    /// Viewing angle θo in degrees, in [0, 90) (needed by polar and 3d).
    #[arg(long = "theta-o", value_name = "DEG", allow_negative_numbers = true)]
    theta_o: Option<f64>,
    /// What to draw.
    #[arg(long, value_enum, default_value_t = Kind::Polar)]
    kind: Kind,
    /// Logarithmic scale (four decades below the maximum).
    #[arg(long)]
    log: bool,
    /// Channel shown: r, g, b or lum (Rec. 709 luminance).
    #[arg(long, default_value = "lum", value_parser = parse_channel)]
    channel: Channel,
    /// Output file: .png, .svg, or .csv (the numbers).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: PathBuf,
    /// Legend name of each model, in order (repeat once per BSDF).
    #[arg(long = "label", value_name = "NAME")]
    labels: Vec<String>,
    /// φd of the slice, in degrees (90 is the classic MERL slice; cell centres of MERL tables at k + 0.5).
    #[arg(long = "phi-d", value_name = "DEG", default_value_t = 90.0, allow_negative_numbers = true)]
    phi_d: f64,
    /// Number of viewing angles of the albedo curve.
    #[arg(long, default_value_t = ALBEDO_ANGLES)]
    angles: usize,
    /// Samples per albedo value.
    #[arg(long, default_value_t = ALBEDO_SAMPLES)]
    samples: usize,
}

fn parse_channel(s: &str) -> Result<Channel, String> {
    Channel::parse(s).ok_or_else(|| format!("unknown channel `{s}`; expected r, g, b or lum"))
}

/// The output formats, from the extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Svg,
    Png,
    Csv,
}

fn format_of(path: &Path) -> Result<Format, Error> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("svg") => Ok(Format::Svg),
        Some("png") => Ok(Format::Png),
        Some("csv") => Ok(Format::Csv),
        _ => Err(Error::Format {
            path: path.to_path_buf(),
            at: "file name".into(),
            message: "cannot write this extension; accepted: .png, .svg, .csv".into(),
        }),
    }
}

fn arg_error(at: &str, message: String) -> Error {
    Error::Spec { at: at.into(), message }
}

/// Legend names: the given labels, or plugin names made unique with "#2", "#3", ….
fn legend_names(models: &[Bsdf], labels: &[String]) -> Result<Vec<String>, Error> {
    if !labels.is_empty() {
        if labels.len() != models.len() {
            return Err(arg_error("--label", format!("{} labels for {} models: give one per BSDF, or none", labels.len(), models.len())));
        }
        return Ok(labels.to_vec());
    }
    let names: Vec<&str> = models.iter().map(Bsdf::plugin_name).collect();
    Ok(names
        .iter()
        .enumerate()
        .map(|(k, &name)| {
            let seen = names[..k].iter().filter(|&&n| n == name).count();
            if seen == 0 {
                name.to_string()
            } else {
                format!("{name} #{}", seen + 1)
            }
        })
        .collect())
}

/// A CSV field: quoted, with quotes doubled.
fn field(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let format = format_of(&args.output)?;
    let models = args.bsdf.iter().map(|a| load_bsdf(a)).collect::<Result<Vec<_>, _>>()?;
    let labels = legend_names(&models, &args.labels)?;
    let needs_theta = matches!(args.kind, Kind::Polar | Kind::Lobe3d);
    let theta_o = match (args.theta_o, needs_theta) {
        (Some(t), _) => {
            gonio::plot::check_theta_o(t).map_err(|e| arg_error("--theta-o", e.to_string().trim_start_matches("theta_o: ").into()))?;
            Some(t)
        }
        (None, true) => return Err(arg_error("--theta-o", "this kind of plot needs the viewing angle θo in degrees, in [0, 90)".into())),
        (None, false) => None,
    };
    let channel = args.channel;
    let mut csv = String::new();
    let figure: Svg = match args.kind {
        Kind::Polar | Kind::Lobe3d => {
            let t = theta_o.expect("checked above");
            let (samples, gt, gp) = if args.kind == Kind::Polar { (POLAR_SAMPLES, 0, 0) } else { (2, GRID_THETA, GRID_PHI) };
            let lobes = models.iter().map(|m| lobe_data(m, t, samples, gt, gp)).collect::<Result<Vec<_>, _>>()?;
            if args.kind == Kind::Polar {
                let _ = write!(csv, "angle_deg");
                for l in &labels {
                    let _ = write!(csv, ",{},{}", field(&format!("{l} incidence")), field(&format!("{l} perpendicular")));
                }
                for (i, a) in lobes[0].angles.iter().enumerate() {
                    let _ = write!(csv, "\n{a}");
                    for l in &lobes {
                        let _ = write!(csv, ",{},{}", channel.of(l.incidence[i]), channel.of(l.perpendicular[i]));
                    }
                }
                let full = models.iter().any(|m| m.flags().intersects(BsdfFlags::TRANSMISSION));
                figure::polar::draw(&lobes, &labels, channel, args.log, full)
            } else {
                let _ = write!(csv, "theta_deg,phi_deg");
                for l in &labels {
                    let _ = write!(csv, ",{}", field(l));
                }
                // Models that transmit have a grid over the sphere: rows by θ of the first, which all share
                // when none or all transmit; otherwise a model's row is its own θ (listed per model).
                let g0 = &lobes[0].grid;
                if lobes.iter().all(|l| l.grid.theta == g0.theta) {
                    for (i, t) in g0.theta.iter().enumerate() {
                        for (j, p) in g0.phi.iter().enumerate() {
                            let _ = write!(csv, "\n{t},{p}");
                            for l in &lobes {
                                let _ = write!(csv, ",{}", channel.of(l.grid.values[i * g0.phi.len() + j]));
                            }
                        }
                    }
                } else {
                    csv = "label,theta_deg,phi_deg,value".into();
                    for (l, name) in lobes.iter().zip(&labels) {
                        for (i, t) in l.grid.theta.iter().enumerate() {
                            for (j, p) in l.grid.phi.iter().enumerate() {
                                let _ = write!(csv, "\n{},{t},{p},{}", field(name), channel.of(l.grid.values[i * l.grid.phi.len() + j]));
                            }
                        }
                    }
                }
                figure::lobe3d::draw(&lobes, &labels, channel, args.log)
            }
        }
        Kind::Slice => {
            let slices = models
                .iter()
                .map(|m| slice_data(m, args.phi_d, SLICE_RES, SLICE_RES))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| arg_error("--phi-d", e.to_string().trim_start_matches("phi_d: ").into()))?;
            let _ = write!(csv, "theta_h_deg,theta_d_deg");
            for l in &labels {
                let _ = write!(csv, ",{}", field(l));
            }
            let s0 = &slices[0];
            for (j, td) in s0.theta_d.iter().enumerate() {
                for (i, th) in s0.theta_h.iter().enumerate() {
                    let _ = write!(csv, "\n{th},{td}");
                    for s in &slices {
                        let _ = write!(csv, ",{}", channel.of(s.values[j * s0.theta_h.len() + i]));
                    }
                }
            }
            figure::slice::draw(&slices, &labels, channel, args.log).map_err(|m| Error::Format {
                path: args.output.clone(),
                at: "figure".into(),
                message: m,
            })?
        }
        Kind::Albedo => {
            let curves = models.iter().map(|m| albedo_data(m, args.angles, args.samples, 0)).collect::<Result<Vec<_>, _>>().map_err(
                |e| match e {
                    Error::Spec { at, message } => arg_error(&format!("--{at}"), message),
                    other => other,
                },
            )?;
            let _ = write!(csv, "theta_o_deg");
            for l in &labels {
                let _ = write!(csv, ",{}", field(l));
            }
            for (i, t) in curves[0].theta_o.iter().enumerate() {
                let _ = write!(csv, "\n{t}");
                for c in &curves {
                    let _ = write!(csv, ",{}", channel.of(c.albedo[i]));
                }
            }
            figure::albedo::draw(&curves, &labels, channel, args.log, theta_o)
        }
    };
    let bytes = match format {
        Format::Csv => {
            csv.push('\n');
            csv.into_bytes()
        }
        Format::Svg => figure.finish().into_bytes(),
        Format::Png => raster::svg_to_png(&figure.finish()).map_err(|m| Error::Format {
            path: args.output.clone(),
            at: "figure".into(),
            message: m,
        })?,
    };
    gonio::image::write_atomically(&args.output, &bytes)?;
    eprintln!("gonio plot: wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}
