//! `gonio preview BSDF... -o sphere.png`: lit spheres rendered by the path tracer (see `gonio::preview`).
//!
//! Several BSDFs are laid out side by side; `--grid name=v1,v2,…` renders one sphere per value of a
//! parameter (repeated: per point of the product, `gonio::preview::Sweep`; a row per BSDF and per
//! combination of all but the last parameter). `--ray ADDRESS` renders the sweep on a Ray cluster. Lighting: `--env FILE.hdr|FILE.exr|gradient|constant`, or `--light X,Y,Z`
//! (a directional light from that direction: +x right, +y up, +z towards the viewer, plus a dim ambient).
//! Without either: `../shared/data/envmaps/venice_sunset_1k.hdr` when it exists, else the built-in sky.

use crate::spec::{in_json_file, load_props};
use glam::Vec3;
use gonio::image::write_image;
use gonio::preview::{contact_sheet, GridAxis, Lighting, Sweep};
use gonio::scene::Mode;
use gonio::Error;
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
    /// One sphere per value of a top-level parameter, e.g. `alpha=0.01,0.05,0.1,0.3,0.6`; repeat it to
    /// sweep the product of several (`--grid alpha=0.05,0.3 --grid material=Au,Cu`: a column per value of
    /// the last, a row per combination of the others).
    #[arg(long, value_name = "NAME=V1,V2,...")]
    grid: Vec<String>,
    /// Scale the image by 2^EV before writing (e.g. -1 shows a furnace's energy gain below white).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// How light is carried: `rgb`, or `spectral` (as `gonio render --mode`; docs/spectral.md).
    #[arg(long, default_value = "rgb", value_parser = ["rgb", "spectral"])]
    mode: String,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No summary line.
    #[arg(short, long)]
    quiet: bool,
    /// Render on a Ray cluster, one task per sphere of the grid: `auto`, `local` or its address (see
    /// `gonio render --ray`; docs/distributed.md); --threads is then the CPUs of each task.
    #[arg(long, value_name = "ADDRESS")]
    ray: Option<String>,
}

fn arg_error(message: String) -> Error {
    Error::Spec { at: "command line".into(), message }
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

/// The environment `--env` names, or the default; a file that does not exist is an error here.
fn environment(args: &Args) -> Result<Lighting, Error> {
    let name = match args.env.as_deref() {
        Some(name) => name,
        None if Path::new(DEFAULT_ENV).is_file() => DEFAULT_ENV,
        None => "gradient",
    };
    let lighting = Lighting::environment(name);
    if let Lighting::Environment(path) = &lighting {
        if !path.is_file() {
            return Err(Error::Io {
                path: path.clone(),
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such environment map (or give `gradient` or `constant`)"),
            });
        }
    }
    Ok(lighting)
}

fn lighting(args: &Args) -> Result<Lighting, Error> {
    match &args.light {
        Some(l) => Ok(Lighting::sun(parse_direction(l)?)),
        None => environment(args),
    }
}

/// The sweep of each BSDF argument over the grid, each point built once here, so that every error shows
/// before the first render.
fn sweeps(args: &Args) -> Result<Vec<(&str, Sweep)>, Error> {
    let axes = args.grid.iter().map(|g| GridAxis::parse(g)).collect::<Result<Vec<_>, _>>()?;
    args.bsdfs
        .iter()
        .map(|arg| {
            let sweep = Sweep::new(load_props(arg)?, axes.clone())?;
            sweep.check().map_err(|e| in_json_file(arg, e))?;
            Ok((arg.as_str(), sweep))
        })
        .collect()
}

/// `gonio preview --ray`: the same sweep by `python -m gonio.distributed preview`, one task per sphere.
fn on_ray(address: &str, args: &Args) -> Result<ExitCode, Error> {
    let [bsdf] = args.bsdfs.as_slice() else {
        return Err(arg_error(format!("--ray sweeps one BSDF over --grid (got {} BSDFs)", args.bsdfs.len())));
    };
    let mut a: Vec<std::ffi::OsString> = vec!["preview".into(), bsdf.into(), "-o".into(), args.output.clone().into()];
    for g in &args.grid {
        a.extend(["--grid".into(), g.into()]);
    }
    // The default environment is chosen here, where `gonio preview` without --ray chooses it.
    match &args.light {
        Some(l) => a.extend(["--light".into(), l.into()]),
        None => match environment(args)? {
            Lighting::Environment(path) => a.extend(["--env".into(), path.into()]),
            Lighting::Constant(_) => a.extend(["--env".into(), "constant".into()]),
            _ => a.extend(["--env".into(), "gradient".into()]),
        },
    }
    for (name, value) in [("--spp", args.spp.to_string()), ("--size", args.size.to_string()), ("--seed", args.seed.to_string())] {
        a.extend([name.into(), value.into()]);
    }
    a.extend(["--exposure".into(), args.exposure.to_string().into()]);
    if args.mode != "rgb" {
        a.extend(["--mode".into(), args.mode.clone().into()]);
    }
    if let Some(n) = args.threads {
        a.extend(["--cpus-per-task".into(), n.to_string().into()]);
    }
    if args.quiet {
        a.push("-q".into());
    }
    crate::ray::delegate(address, a)
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
    let mode = Mode::parse(&args.mode)?;
    if let Some(address) = &args.ray {
        return on_ray(address, &args);
    }
    let lighting = lighting(&args)?;
    let sweeps = sweeps(&args)?;
    if let Some(n) = args.threads {
        // The global pool: a material description is not `Sync`, so the render cannot be moved into a pool.
        rayon::ThreadPoolBuilder::new().num_threads(n).build_global().map_err(|e| arg_error(format!("--threads: {e}")))?;
    }

    let start = std::time::Instant::now();
    let cancel = AtomicBool::new(false);
    let mut tiles = Vec::new();
    let mut nonfinite = 0;
    for (arg, sweep) in &sweeps {
        for point in 0..sweep.len() {
            let out = sweep.render(point, &lighting, args.size, args.spp, args.seed, mode, &cancel).map_err(|e| in_json_file(arg, e))?;
            nonfinite += out.nonfinite;
            tiles.push(out.image);
        }
    }
    let count = tiles.len();
    // A row per BSDF with a grid (a column per value of its last parameter); the BSDFs side by side without.
    let columns = if args.grid.is_empty() { sweeps.len() } else { sweeps[0].1.columns() };
    let image = contact_sheet(&tiles, columns, args.exposure)?;
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
