//! `gonio check BSDF` and `gonio check --all`.

use crate::spec::load_bsdf;
use gonio::verify::{check_named, test_directions, CheckConfig, Report};
use gonio::{Bsdf, Error};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct Args {
    /// A JSON object in Mitsuba's dictionary form ('{"type": "conductor", "material": "Au"}') or a path to
    /// an XML file with one <bsdf> element.
    #[arg(required_unless_present = "all", conflicts_with = "all")]
    bsdf: Option<String>,
    /// Check every built-in model with default and extreme parameters.
    #[arg(long)]
    all: bool,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Samples per chi-square test (at least 10⁶ for the project's standard).
    #[arg(long, default_value_t = 1_000_000)]
    samples: usize,
    /// Queries in the NaN/Inf sweep.
    #[arg(long, default_value_t = 1_000_000)]
    sweep: usize,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Folder for the observed/expected histograms of failed chi-square tests.
    #[arg(long, default_value = "gonio-check-histograms")]
    histograms: PathBuf,
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    let models: Vec<(String, Bsdf)> = if args.all {
        Bsdf::examples().into_iter().map(|s| Bsdf::from_json(s).map(|b| (s.to_string(), b))).collect::<Result<_, _>>()?
    } else {
        let arg = args.bsdf.expect("clap requires BSDF unless --all");
        let bsdf = load_bsdf(&arg)?;
        vec![(arg, bsdf)]
    };
    let mut cfg = CheckConfig {
        chi2_samples: args.samples,
        sweep_queries: args.sweep,
        seed: args.seed,
        histogram_dir: Some(args.histograms),
        ..CheckConfig::default()
    };
    // One family for the whole run: the Šidák correction covers every chi-square test of every model.
    cfg.sidak_family = Some(models.iter().map(|(_, b)| test_directions(b).len()).sum());

    let reports: Vec<Report> = models
        .iter()
        .map(|(name, bsdf)| {
            let report = check_named(bsdf, name, &cfg);
            if !args.json {
                print!("{}", report.to_table());
            }
            report
        })
        .collect();
    let failed = reports.iter().filter(|r| !r.passed()).count();
    if args.json {
        let all: Vec<_> = reports.iter().map(Report::to_json).collect();
        let value = if args.all { serde_json::Value::Array(all) } else { all.into_iter().next().unwrap_or_default() };
        println!("{}", serde_json::to_string_pretty(&value).unwrap_or_default());
    } else {
        println!("{} of {} BSDFs passed every check", reports.len() - failed, reports.len());
    }
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
