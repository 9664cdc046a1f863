//! `gonio preview BSDF... -o sphere.png`: lit spheres rendered by the path tracer (see `gonio::preview`).
//!
//! Several BSDFs are laid out side by side; `--grid name=v1,v2,…` renders one sphere per value of one
//! parameter (a row per BSDF). Lighting: `--env FILE.hdr|FILE.exr|gradient|constant`, or `--light X,Y,Z`
//! (a directional light from that direction: +x right, +y up, +z towards the viewer, plus a dim ambient).
//! Without either: `../shared/data/envmaps/venice_sunset_1k.hdr` when it exists, else the built-in sky.

use crate::spec::{in_json_file, load_props};
use glam::Vec3;
use gonio::image::write_image;
use gonio::preview::{render_preview, tile, Lighting, AMBIENT};
use gonio::props::{Props, Value};
use gonio::scene::Material;
use gonio::{Error, Rgb};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

/// The environment used when neither `--env` nor `--light` is given, if it exists (relative to the
/// working directory: the repository root of this workspace).
pub const DEFAULT_ENV: &str = "../shared/data/envmaps/venice_sunset_1k.hdr";

#[derive(clap::Args)]
pub struct Args {
    /// BSDFs: JSON in Mitsuba's dictionary form, an XML file with one <bsdf> (textures allowed), a MERL
    /// .binary or an RGL .bsdf file. Several are rendered side by side.
    #[arg(required = true)]
    bsdfs: Vec<String>,
    /// Output image (.png: 8-bit sRGB, .exr: float linear RGB, .hdr), written atomically.
    #[arg(short, long)]
    output: PathBuf,
    /// Environment: a lat-long image (.hdr, .exr), `gradient` (the built-in sky) or `constant` (uniform
    /// radiance 1: the white furnace).
    #[arg(long, conflicts_with = "light")]
    env: Option<String>,
    /// A directional light shining from direction X,Y,Z (+x right, +y up, +z towards the viewer), of
    /// irradiance π, plus a dim uniform ambient.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    light: Option<String>,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Width and height of each sphere's image in pixels.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// One sphere per value of a top-level parameter, e.g. `alpha=0.01,0.05,0.1,0.3,0.6`.
    #[arg(long, value_name = "NAME=V1,V2,...")]
    grid: Option<String>,
    /// Scale the image by 2^EV before writing (e.g. -1 shows a furnace's energy gain below white).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
}

fn arg_error(message: String) -> Error {
    Error::Spec { at: "command line".into(), message }
}

/// A `--grid` value: a number, a boolean, or else a string (e.g. a distribution name).
fn grid_value(text: &str) -> Value {
    match text {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => text.parse::<f64>().map_or_else(|_| Value::String(text.to_string()), Value::Number),
    }
}

fn parse_grid(arg: &str) -> Result<(String, Vec<String>), Error> {
    let (name, values) = arg.split_once('=').ok_or_else(|| arg_error(format!("--grid expects NAME=V1,V2,..., got `{arg}`")))?;
    let name = name.trim();
    if name.is_empty() || name.contains('.') {
        return Err(arg_error(format!("--grid takes a top-level parameter name (no nesting), got `{name}`")));
    }
    let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
    if values.iter().any(String::is_empty) {
        return Err(arg_error(format!("--grid `{arg}` has an empty value")));
    }
    Ok((name.to_string(), values))
}

fn parse_direction(arg: &str) -> Result<Vec3, Error> {
    let parts: Vec<f32> = arg
        .split(',')
        .map(|s| s.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| arg_error(format!("--light expects a direction X,Y,Z of three numbers, got `{arg}`")))?;
    match parts.as_slice() {
        [x, y, z] => {
            let d = Vec3::new(*x, *y, *z);
            if !d.is_finite() || d.length_squared() == 0.0 {
                return Err(arg_error(format!("--light direction must be finite and non-zero, got `{arg}`")));
            }
            Ok(d)
        }
        _ => Err(arg_error(format!("--light expects a direction X,Y,Z of three numbers, got `{arg}`"))),
    }
}

fn lighting(args: &Args) -> Result<Lighting, Error> {
    if let Some(l) = &args.light {
        return Ok(Lighting::Directional { towards_light: parse_direction(l)?, ambient: AMBIENT });
    }
    Ok(match args.env.as_deref() {
        Some("gradient") => Lighting::GradientSky,
        Some("constant") => Lighting::Constant(Rgb::ONE),
        Some(path) => {
            let path = Path::new(path);
            if !path.is_file() {
                return Err(Error::Io {
                    path: path.to_path_buf(),
                    source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such environment map (or give `gradient` or `constant`)"),
                });
            }
            Lighting::Environment(path.to_path_buf())
        }
        None if Path::new(DEFAULT_ENV).is_file() => Lighting::Environment(PathBuf::from(DEFAULT_ENV)),
        None => Lighting::GradientSky,
    })
}

/// One sphere to render: the BSDF argument it came from (for messages) and its description.
struct Sphere<'a> {
    arg: &'a str,
    props: Props,
}

/// The materials to render, row by row: each BSDF argument, once per grid value, and the number of columns.
/// Each is built once here, so that every error shows before the first render.
fn materials(args: &Args) -> Result<(Vec<Sphere<'_>>, usize), Error> {
    let grid = args.grid.as_deref().map(parse_grid).transpose()?;
    let mut out = Vec::new();
    for arg in &args.bsdfs {
        let props = load_props(arg)?;
        let variants = match &grid {
            None => vec![props],
            Some((name, values)) => values
                .iter()
                .map(|v| {
                    let mut p = props.clone();
                    p.set(name, grid_value(v), &format!("--grid {name}={v}"));
                    p
                })
                .collect(),
        };
        for p in variants {
            Material::from_props(&p).map_err(|e| in_json_file(arg, e))?;
            out.push(Sphere { arg: arg.as_str(), props: p });
        }
    }
    let columns = grid.as_ref().map_or(args.bsdfs.len(), |(_, values)| values.len());
    Ok((out, columns))
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr" | "hdr")) {
        return Err(arg_error(format!("-o {}: the output must end in .png, .exr or .hdr", args.output.display())));
    }
    if args.spp == 0 {
        return Err(arg_error("--spp must be at least 1".into()));
    }
    if args.size == 0 || args.size > 4096 {
        return Err(arg_error(format!("--size must be in [1, 4096], got {}", args.size)));
    }
    if !args.exposure.is_finite() || args.exposure.abs() > 30.0 {
        return Err(arg_error(format!("--exposure must be in [-30, 30], got {}", args.exposure)));
    }
    let lighting = lighting(&args)?;
    let (materials, columns) = materials(&args)?;
    if let Some(n) = args.threads {
        // The global pool: a material description is not `Sync`, so the render cannot be moved into a pool.
        rayon::ThreadPoolBuilder::new().num_threads(n).build_global().map_err(|e| arg_error(format!("--threads: {e}")))?;
    }

    let start = std::time::Instant::now();
    let cancel = AtomicBool::new(false);
    let scale = args.exposure.exp2();
    let mut tiles = Vec::with_capacity(materials.len());
    let mut nonfinite = 0;
    for Sphere { arg, props } in &materials {
        let material = || Material::from_props(props).map_err(|e| in_json_file(arg, e));
        let mut out = render_preview(&material, &lighting, args.size, args.spp, args.seed, &cancel)?;
        nonfinite += out.nonfinite;
        out.image.data.iter_mut().for_each(|v| *v *= scale);
        tiles.push(out.image);
    }
    let count = tiles.len();
    let image = tile(&tiles, columns, (args.size as usize / 64).max(1), Rgb::splat(0.02))?;
    write_image(&args.output, &image)?;
    if nonfinite > 0 {
        eprintln!("gonio: warning: dropped {nonfinite} non-finite samples (counted as black)");
    }
    if !args.quiet {
        let light = match &lighting {
            Lighting::Environment(p) => format!("environment {}", p.display()),
            Lighting::EnvironmentImage { name, .. } => format!("environment {name}"),
            Lighting::GradientSky => "the built-in sky".into(),
            Lighting::Constant(_) => "a uniform white environment".into(),
            Lighting::Directional { towards_light, .. } => format!("a directional light from {towards_light}"),
        };
        eprintln!(
            "gonio: {count} sphere(s), {0}×{0} px, {1} spp, lit by {light}, in {2:.2} s → {3}",
            args.size,
            args.spp,
            start.elapsed().as_secs_f64(),
            args.output.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
