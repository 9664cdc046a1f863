//! `gonio fit MEASURED --model MODEL -o fit.xml`: fit an analytic model to a measured (or any) BSDF by
//! Levenberg–Marquardt on the cosine-weighted error metric of Ngan, Durand & Matusik 2005
//! (see `gonio::fit`), and write the fitted `<bsdf>` as Mitsuba XML.

use crate::spec::load_bsdf;
use crate::stdout::outln;
use gonio::fit::{fit, model, pairs, spec_to_xml, MODELS};
use gonio::Error;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct Args {
    /// The BSDF to fit to: a MERL .binary, an RGL .bsdf file, JSON, or an XML file with one <bsdf>.
    #[arg(required_unless_present = "list")]
    measured: Option<String>,
    /// The analytic model (repeat to fit several; the best goes to --output): see --list.
    #[arg(long = "model", required_unless_present = "list")]
    models: Vec<String>,
    /// The Mitsuba XML file to write the best fit to (written atomically).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Strata per axis of the direction set (θh, θd; 2× for φd): more pairs, slower and finer.
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(2..=64))]
    strata: u32,
    /// List the models and exit.
    #[arg(long)]
    list: bool,
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    if args.list {
        for m in MODELS {
            outln!("{:<26} {}", m.name, m.about);
        }
        return Ok(ExitCode::SUCCESS);
    }
    // Resolve every model name before the (slow) fits, so a typo fails at once.
    let models = args.models.iter().map(|name| model(name)).collect::<Result<Vec<_>, _>>()?;
    let measured = args.measured.unwrap_or_default();
    let target = load_bsdf(&measured)?;
    let set = pairs(&target, args.strata as usize);
    let mut best: Option<gonio::fit::Fit> = None;
    for m in models {
        let start = std::time::Instant::now();
        let result = fit(m, &set)?;
        outln!(
            "{}: relative error {:.4} (E = {:.4e}) in {:.1} s",
            m.name,
            result.relative_error,
            result.error,
            start.elapsed().as_secs_f64()
        );
        for (name, value) in &result.values {
            outln!("  {name:<10} {value:.6}");
        }
        let bands: Vec<String> = result.per_angle.iter().map(|(deg, e)| format!("{deg:.0}°: {e:.3}")).collect();
        outln!("  error by θi band (RMS error / RMS signal): {}", bands.join(", "));
        let better = match &best {
            Some(b) => result.error < b.error,
            None => true,
        };
        if better {
            best = Some(result);
        }
    }
    if let (Some(path), Some(best)) = (&args.output, &best) {
        // XML comments may not contain "--": hyphens in the source's name become U+2010.
        let comment = format!(
            "<!-- fitted by gonio to {}: model {}, relative error {:.4} (Ngan et al. 2005 metric, {} direction pairs) -->\n",
            measured.replace('-', "\u{2010}"),
            best.model,
            best.relative_error,
            set.len()
        );
        gonio::image::write_atomically(path, (comment + &spec_to_xml(&best.spec, None, 0)).as_bytes())?;
        outln!("wrote the best fit ({}) to {}", best.model, path.display());
    }
    Ok(ExitCode::SUCCESS)
}
