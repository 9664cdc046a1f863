//! `gonio render SCENE.xml`: render a Mitsuba 3 XML scene with gonio's path tracer.
//!
//! The image goes to `-o FILE` (`.exr`: float32 linear RGB, and an `aov` integrator's further channels
//! under Mitsuba 3's names, e.g. `image.R`, `dd.y.T`; `.png`: 8-bit sRGB, the RGB only), by default next to the
//! scene with the extension replaced by `.exr` (as Mitsuba's `mitsuba scene.xml` does), atomically: a
//! failure never leaves a partial file, and a file already there survives any error. The output path is
//! checked before the scene is loaded, so an unwritable one fails at once.
//!
//! Ctrl-C, SIGTERM or SIGHUP stop the render after the current pass; the image so far is written (every
//! pixel with the same number of samples), stderr says how many, and the exit code is 130. A second signal
//! exits at once, writing nothing. If no pass had finished, nothing is written (an older file stays).
//! EXR output carries the notes `gonio.spp` (samples per pixel written), `gonio.spp_requested`,
//! `gonio.interrupted`, `gonio.nonfinite_samples` and `gonio.seed` as header attributes.
//!
//! Non-finite samples (NaN or Inf radiance, e.g. from overflow) are dropped and counted as black; when
//! there are any, stderr says "N non-finite samples dropped".

use gonio::image::{check_writable, write_image_with_channels, Image};
use gonio::render::render;
use gonio::scene::{Mode, Scene};
use gonio::Error;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

#[derive(clap::Args)]
pub struct Args {
    /// A scene in Mitsuba 3's XML format.
    scene: PathBuf,
    /// Output image (.exr or .png); default: the scene's name with .exr, next to the scene.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Samples per pixel (overrides the scene's sampler).
    #[arg(long)]
    spp: Option<u32>,
    /// Set a scene parameter, as Mitsuba's -D: overrides <default name="NAME" value="…"/>.
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    define: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Random seed (overrides the sampler's `seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// No progress bar or summary.
    #[arg(short, long)]
    quiet: bool,
    /// Render on a Ray cluster: `auto` (an existing one, e.g. started by `ray start --head`), `local` (start
    /// one here) or its address. Runs gonio's Python package (`pip install "gonio[ray]"`); --threads is then
    /// the CPUs of each task. See docs/distributed.md.
    #[arg(long, value_name = "ADDRESS")]
    ray: Option<String>,
    /// With --ray: samples per pixel in each task (default: about four tasks per CPU of the cluster).
    #[arg(long, requires = "ray")]
    chunk_spp: Option<u32>,
    /// How light is carried: `rgb`, or `spectral` (three sampled wavelengths per path, the film's colour
    /// through the CIE 1931 observer; docs/spectral.md says which materials it takes yet).
    #[arg(long, default_value = "rgb", value_parser = ["rgb", "spectral"])]
    mode: String,
}

/// `gonio render --ray`: the same arguments for `python -m gonio.distributed render`.
fn on_ray(address: &str, args: &Args) -> Result<ExitCode, Error> {
    let mut a: Vec<std::ffi::OsString> = vec!["render".into(), args.scene.clone().into()];
    let mut opt = |name: &str, value: Option<String>| {
        if let Some(v) = value {
            a.push(name.into());
            a.push(v.into());
        }
    };
    opt("-o", args.output.as_ref().map(|p| p.display().to_string()));
    opt("--spp", args.spp.map(|v| v.to_string()));
    opt("--seed", args.seed.map(|v| v.to_string()));
    opt("--chunk-spp", args.chunk_spp.map(|v| v.to_string()));
    opt("--cpus-per-task", args.threads.map(|v| v.to_string()));
    opt("--mode", (args.mode != "rgb").then(|| args.mode.clone()));
    for d in &args.define {
        a.push("-D".into());
        a.push(d.into());
    }
    if args.quiet {
        a.push("-q".into());
    }
    crate::ray::delegate(address, a)
}

fn arg_error(message: String) -> Error {
    Error::Spec { at: "command line".into(), message }
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let mode = Mode::parse(&args.mode)?;
    if let Some(address) = &args.ray {
        return on_ray(address, &args);
    }
    let overrides = args
        .define
        .iter()
        .map(|d| match d.split_once('=') {
            Some((k, v)) if !k.is_empty() => Ok((k.to_string(), v.to_string())),
            _ => Err(arg_error(format!("-D expects NAME=VALUE, got `{d}`"))),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let output = args.output.clone().unwrap_or_else(|| args.scene.with_extension("exr"));
    check_writable(&output)?;
    let load_start = std::time::Instant::now();
    let scene = Scene::load_in(&args.scene, &overrides, mode)?;
    for w in &scene.warnings {
        eprintln!("gonio: warning: {w}");
    }
    let spp = args.spp.unwrap_or(scene.sampler.sample_count);
    if spp == 0 {
        return Err(arg_error("--spp must be at least 1".into()));
    }
    let seed = args.seed.unwrap_or(scene.sampler.seed);
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        pool = pool.num_threads(n);
    }
    let pool = pool.build().map_err(|e| arg_error(format!("--threads: {e}")))?;

    let cancel = Arc::new(AtomicBool::new(false));
    {
        let cancel = cancel.clone();
        // SIGINT, SIGTERM and SIGHUP (ctrlc's `termination` feature); a second one exits at once.
        let _ = ctrlc::set_handler(move || {
            if cancel.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
    }
    let (w, h) = (scene.film.width, scene.film.height);
    let total = u64::from(w) * u64::from(h) * u64::from(spp);
    let bar = if args.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{bar:40} {percent:>3}%  {human_pos}/{human_len} samples  {per_sec}  ETA {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    };
    let load_seconds = load_start.elapsed().as_secs_f64();
    let out = pool.install(|| render(&scene, spp, seed, &cancel, &|done| bar.set_position(done)));
    bar.finish_and_clear();

    if out.nonfinite > 0 {
        eprintln!("gonio: warning: {} non-finite samples dropped (counted as black)", out.nonfinite);
    }
    if out.spp_done == 0 {
        let kept = if output.exists() { format!("; {} is unchanged", output.display()) } else { String::new() };
        eprintln!("gonio: interrupted before the first pass finished: nothing written{kept}");
        return Ok(ExitCode::from(130));
    }
    let notes = [
        ("gonio.spp", out.spp_done.to_string()),
        ("gonio.spp_requested", out.spp_requested.to_string()),
        ("gonio.interrupted", out.cancelled.to_string()),
        ("gonio.nonfinite_samples", out.nonfinite.to_string()),
        ("gonio.seed", seed.to_string()),
    ];
    let image = Image { width: out.width as usize, height: out.height as usize, data: out.data };
    write_image_with_channels(&output, &image, &out.aovs, &notes)?;
    let exr = output.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !out.aovs.names.is_empty() && !exr {
        eprintln!(
            "gonio: note: {} holds the RGB only; the aov channels ({}) are written to .exr files",
            output.display(),
            out.aovs.names.join(", ")
        );
    }
    if !args.quiet {
        let rate = f64::from(out.spp_done) * f64::from(w) * f64::from(h) / out.seconds.max(1e-9);
        eprintln!(
            "gonio: {w}×{h}, {} spp, {} primitives: loaded in {load_seconds:.3} s, BVH built in {:.4} s, rendered in {:.3} s ({:.2} Msamples/s) → {}",
            out.spp_done,
            scene.primitive_count(),
            scene.bvh_seconds,
            out.seconds,
            rate / 1e6,
            output.display()
        );
    }
    if out.cancelled {
        eprintln!("gonio: interrupted: wrote {} of {} spp to {}", out.spp_done, out.spp_requested, output.display());
        return Ok(ExitCode::from(130));
    }
    Ok(ExitCode::SUCCESS)
}
