//! `gonio` — the command line of the gonio reflectance toolkit.
//!
//! Exit codes: 0 success, 1 a check failed, 2 bad input (the message names the file or parameter),
//! 141 standard output was closed by its reader (`gonio check --all | head -1`; see [`stdout`]).

// Every command writes through `stdout::out!`/`outln!`, which end gonio quietly on a closed pipe.
#![deny(clippy::print_stdout)]

mod cmd;
mod figure;
mod ray;
mod spec;
mod stdout;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "gonio", version, about = "A physically based reflectance toolkit: verify, measure and render BSDFs")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Verify a BSDF: chi-square of sample vs pdf, sample weights, reciprocity, energy, NaN/Inf sweep.
    Check(cmd::check::Args),
    /// Print the directional albedo ∫ f cos dωi of a BSDF against θo.
    Albedo(cmd::albedo::Args),
    /// Render a Mitsuba 3 XML scene to an EXR or PNG image.
    Render(cmd::render::Args),
    /// Tabulate a BSDF into a MERL table (the virtual gonioreflectometer).
    Measure(cmd::measure::Args),
    /// Fit an analytic model to a measured BSDF and write it as a Mitsuba <bsdf>.
    Fit(cmd::fit::Args),
    /// Plot BSDFs: polar lobes, 3-D lobes, θh × θd slices or albedo curves, overlaid, to PNG, SVG or CSV.
    Plot(cmd::plot::Args),
    /// Render lit spheres of BSDFs with the path tracer (side by side, or a sweep of one parameter).
    Preview(cmd::preview::Args),
    /// Look at BSDFs interactively in the browser: a local web page with live plots, a lit sphere and checks.
    Explore(cmd::explore::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Check(args) => cmd::check::run(args),
        Command::Albedo(args) => cmd::albedo::run(args),
        Command::Render(args) => cmd::render::run(args),
        Command::Measure(args) => cmd::measure::run(args),
        Command::Fit(args) => cmd::fit::run(args),
        Command::Plot(args) => cmd::plot::run(args),
        Command::Preview(args) => cmd::preview::run(args),
        Command::Explore(args) => cmd::explore::run(args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("gonio: error: {e}");
            ExitCode::from(2)
        }
    }
}
