//! `gonio albedo BSDF`: the directional albedo against θo, and the white-furnace average.

use crate::spec::load_bsdf;
use crate::stdout::outln;
use gonio::verify::energy::{albedo_curve, white_furnace};
use gonio::verify::scatters_from_below;
use gonio::Error;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct Args {
    /// A JSON object in Mitsuba's dictionary form or a path to an XML file with one <bsdf> element.
    bsdf: String,
    /// Number of θo values over (0°, 90°).
    #[arg(long, default_value_t = 18)]
    angles: usize,
    /// Samples per albedo estimate.
    #[arg(long, default_value_t = 65_536)]
    samples: usize,
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let bsdf = load_bsdf(&args.bsdf)?;
    let sides: &[f32] = if scatters_from_below(&bsdf) { &[1.0, -1.0] } else { &[1.0] };
    for &sign in sides {
        let curve = albedo_curve(&bsdf, args.angles, sign, args.samples, 0);
        outln!("{:>8} {:>9} {:>9} {:>9} {:>9}", "θo(deg)", "cosθo", "R", "G", "B");
        for (mu, a) in &curve {
            outln!("{:>8.2} {:>+9.4} {:>9.5} {:>9.5} {:>9.5}", mu.acos().to_degrees(), mu, a.r(), a.g(), a.b());
        }
        let w = white_furnace(&curve);
        outln!("white furnace ({}): [{:.5}, {:.5}, {:.5}]\n", if sign > 0.0 { "above" } else { "below" }, w.r(), w.g(), w.b());
    }
    Ok(ExitCode::SUCCESS)
}
