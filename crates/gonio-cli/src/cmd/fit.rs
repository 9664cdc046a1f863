//! `gonio fit MEASURED --model MODEL -o fit.xml`: fit an analytic model to a measured (or any) BSDF by
//! Levenberg–Marquardt on the cosine-weighted error metric of Ngan, Durand & Matusik 2005
//! (see `gonio::fit`), and write the fitted `<bsdf>` as Mitsuba XML.

use crate::spec::load_bsdf;
use crate::stdout::outln;
use gonio::fit::{fit, fit_file, model, pairs, MODELS};
use gonio::Error;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct Args {
    /// The BSDF to fit to: a MERL .binary, an RGL .bsdf file, JSON, or an XML file with one <bsdf>
    /// (several files with --ray).
    #[arg(required_unless_present = "list")]
    measured: Vec<String>,
    /// The analytic model (repeat to fit several; the best goes to --output): see --list.
    #[arg(long = "model", required_unless_present = "list")]
    models: Vec<String>,
    /// The Mitsuba XML file to write the best fit to (written atomically); with --ray a folder, where the
    /// best fit of each file goes to <file stem>.xml.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Strata per axis of the direction set (θh, θd; 2× for φd): more pairs, slower and finer.
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(2..=64))]
    strata: u32,
    /// List the models and exit.
    #[arg(long)]
    list: bool,
    /// Fit on a Ray cluster, one task per file and model: `auto`, `local` or its address (see
    /// `gonio render --ray`; docs/distributed.md).
    #[arg(long, value_name = "ADDRESS")]
    ray: Option<String>,
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
    if let Some(address) = &args.ray {
        let mut a: Vec<std::ffi::OsString> = vec!["fit".into()];
        a.extend(args.measured.iter().map(Into::into));
        for m in &args.models {
            a.extend(["--model".into(), m.into()]);
        }
        a.extend(["--strata".into(), args.strata.to_string().into()]);
        if let Some(out) = &args.output {
            a.extend(["-o".into(), out.clone().into_os_string()]);
        }
        return crate::ray::delegate(address, a);
    }
    let [measured] = <[String; 1]>::try_from(args.measured).map_err(|files| Error::Spec {
        at: "command line".into(),
        message: format!("fit one measured file at a time (got {}), or several with --ray", files.len()),
    })?;
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
        gonio::image::write_atomically(path, fit_file(best, &measured, set.len()).as_bytes())?;
        outln!("wrote the best fit ({}) to {}", best.model, path.display());
    }
    Ok(ExitCode::SUCCESS)
}
