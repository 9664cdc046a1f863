//! `gonio measure BSDF -o out.binary`: the virtual gonioreflectometer. Tabulates any BSDF into a MERL
//! table, averaging f over k³ stratified points per cell (see `gonio::measured::gonioreflectometer`).

use crate::spec::load_bsdf;
use crate::stdout::outln;
use gonio::measured::gonioreflectometer::measure;
use gonio::Error;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct Args {
    /// The BSDF to measure: JSON, an XML file with one <bsdf>, a MERL .binary or an RGL .bsdf file.
    bsdf: String,
    /// The MERL file to write (34,992,012 bytes, written atomically).
    #[arg(short, long)]
    output: PathBuf,
    /// Points per cell and axis (k; k³ points per cell).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=8))]
    supersample: u32,
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let bsdf = load_bsdf(&args.bsdf)?;
    let start = std::time::Instant::now();
    let table = measure(&bsdf, args.supersample as usize, &args.bsdf)?;
    table.write(&args.output)?;
    outln!(
        "measured {} into {} ({}³ points per cell, {} of {} cells below the horizon written as not measured) in {:.1} s",
        bsdf.plugin_name(),
        args.output.display(),
        args.supersample,
        table.unmeasured_cells(),
        gonio::measured::merl_file::CELLS,
        start.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}
