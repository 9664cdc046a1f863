//! `gonio check BSDF` and `gonio check --all`.

use crate::spec::{in_json_file, load_props};
use crate::stdout::{out, outln};
use gonio::scene::spectral::{check_bsdf, given_spectra, reflectances_at};
use gonio::spectrum::wavelengths::{LAMBDA_MAX, LAMBDA_MIN};
use gonio::verify::{check_named, expect_violation, sweep::sweep, test_directions, CheckConfig, Report};
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
    /// Run only the NaN/Inf sweep (e.g. `gonio check --all --sweep-only --sweep 10000000`); with --all it
    /// also covers the non-physical models, which must be finite too.
    #[arg(long)]
    sweep_only: bool,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// With --all: check on a Ray cluster, one task per model: `auto`, `local` or its address (see
    /// `gonio render --ray`; docs/distributed.md). Histograms of failed tests are not written.
    #[arg(long, value_name = "ADDRESS", requires = "all", conflicts_with = "sweep_only")]
    ray: Option<String>,
    /// Folder for the observed/expected histograms of failed chi-square tests.
    #[arg(long, default_value = "gonio-check-histograms")]
    histograms: PathBuf,
    /// Check the model at each of these wavelengths (nm, comma-separated, in [360, 830]) as spectral mode
    /// renders it (its colours' spectra, a metal's η and k, a dispersive glass's index there), instead of
    /// in RGB: one report per wavelength.
    #[arg(long, value_name = "NM,NM,...", value_delimiter = ',', conflicts_with = "all")]
    wavelengths: Vec<f32>,
}

/// The model of `arg` at each of `wavelengths` (named `arg @ λ nm`), as spectral mode sets a path's
/// (`gonio::scene::spectral::reflectances_at`); refused where spectral mode does not take the model.
fn at_wavelengths(arg: &str, wavelengths: &[f32]) -> Result<Vec<(String, Bsdf)>, Error> {
    let props = load_props(arg)?;
    let bsdf = Bsdf::from_props(&props).map_err(|e| in_json_file(arg, e))?;
    if wavelengths.is_empty() {
        return Ok(vec![(arg.to_string(), bsdf)]);
    }
    check_bsdf(&props).map_err(|e| in_json_file(arg, e))?;
    let given = given_spectra(&props);
    wavelengths
        .iter()
        .map(|&l| {
            if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&l) {
                return Err(Error::Spec {
                    at: "command line".into(),
                    message: format!("--wavelengths: {l} nm is outside [{LAMBDA_MIN}, {LAMBDA_MAX}] nm"),
                });
            }
            let mut model = bsdf.clone();
            reflectances_at(&mut model, [l; 3], &given);
            Ok((format!("{arg} @ {l} nm"), model))
        })
        .collect()
}

pub fn run(args: Args) -> Result<ExitCode, Error> {
    if let Some(address) = &args.ray {
        let mut a: Vec<std::ffi::OsString> = vec!["check".into(), "--all".into()];
        for (name, value) in
            [("--samples", args.samples.to_string()), ("--sweep", args.sweep.to_string()), ("--seed", args.seed.to_string())]
        {
            a.extend([name.into(), value.into()]);
        }
        if args.json {
            a.push("--json".into());
        }
        return crate::ray::delegate(address, a);
    }
    let load = |s: &'static str| Bsdf::from_json(s).map(|b| (s.to_string(), b));
    let models: Vec<(String, Bsdf)> = if args.all {
        Bsdf::examples().into_iter().map(load).collect::<Result<_, _>>()?
    } else {
        let arg = args.bsdf.expect("clap requires BSDF unless --all");
        at_wavelengths(&arg, &args.wavelengths)?
    };
    // With --all, the non-physical models kept for teaching must fail the row they are known to break.
    let violations: Vec<(String, Bsdf, &'static str)> = if args.all {
        Bsdf::violations().into_iter().map(|(s, kind)| load(s).map(|(name, b)| (name, b, kind))).collect::<Result<_, _>>()?
    } else {
        Vec::new()
    };
    let mut cfg = CheckConfig {
        chi2_samples: args.samples,
        sweep_queries: args.sweep,
        seed: args.seed,
        histogram_dir: Some(args.histograms),
        ..CheckConfig::default()
    };
    // One family for the whole run: the Šidák correction covers every chi-square test of every model.
    cfg.sidak_family = Some(
        models.iter().map(|(_, b)| test_directions(b)).chain(violations.iter().map(|(_, b, _)| test_directions(b))).map(|d| d.len()).sum(),
    );

    if args.sweep_only {
        return Ok(sweep_only(models.iter().map(|(n, b)| (n, b)).chain(violations.iter().map(|(n, b, _)| (n, b))), &cfg, args.json));
    }

    let reports: Vec<Report> = in_order(
        &models,
        |(name, bsdf)| check_named(bsdf, name, &cfg),
        |report| {
            if !args.json {
                out!("{}", report.to_table());
            }
        },
    );
    let failed = reports.iter().filter(|r| !r.passed()).count();

    if !violations.is_empty() && !args.json {
        outln!("\nexpected violations (non-physical models kept for teaching)");
    }
    let detections: Vec<(Report, &str, Result<(), String>)> = in_order(
        &violations,
        |(name, bsdf, kind)| {
            let report = check_named(bsdf, name, &cfg);
            let detected = expect_violation(&report, kind);
            (report, *kind, detected)
        },
        |(report, kind, detected)| {
            if !args.json {
                out!("{}", report.to_table());
                match detected {
                    Ok(()) => outln!("  `{kind}`: violation detected"),
                    Err(e) => outln!("  `{kind}`: NOT DETECTED ({})", e.lines().next().unwrap_or_default()),
                }
            }
        },
    );
    let missed = detections.iter().filter(|d| d.2.is_err()).count();

    if args.json {
        let all: Vec<_> = reports.iter().map(Report::to_json).collect();
        let value = if args.all {
            let violations: Vec<_> = detections
                .iter()
                .map(|(report, kind, detected)| {
                    let mut v = report.to_json();
                    v["expected_violation"] = serde_json::json!(kind);
                    v["detected"] = serde_json::json!(detected.is_ok());
                    v
                })
                .collect();
            serde_json::json!({ "examples": all, "violations": violations })
        } else if all.len() == 1 {
            all.into_iter().next().unwrap_or_default()
        } else {
            // --wavelengths: a report per wavelength.
            serde_json::Value::Array(all)
        };
        outln!("{}", serde_json::to_string_pretty(&value).unwrap_or_default());
    } else {
        outln!("{} of {} BSDFs passed every check", reports.len() - failed, reports.len());
        if !detections.is_empty() {
            outln!("{} of {} expected violations detected", detections.len() - missed, detections.len());
        }
    }
    Ok(if failed == 0 && missed == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// `check` of every item, several models at once (each check is parallel inside, but its energy and
/// reciprocity rows are not: one model at a time left a core idle a quarter of the time), and `show` of
/// each result in the items' order as soon as it and every one before it are done. The results do not
/// depend on the order of evaluation (each test draws from its own seeded streams).
fn in_order<T: Sync, R: Send>(items: &[T], check: impl Fn(&T) -> R + Sync, show: impl Fn(&R) + Sync) -> Vec<R> {
    use rayon::prelude::*;
    use std::sync::Mutex;
    // The results not yet shown, and how many were.
    let done: Mutex<(Vec<Option<R>>, usize)> = Mutex::new(((0..items.len()).map(|_| None).collect(), 0));
    (0..items.len()).into_par_iter().for_each(|k| {
        let r = check(&items[k]);
        let mut guard = done.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let (results, shown) = &mut *guard;
        results[k] = Some(r);
        while let Some(Some(next)) = results.get(*shown) {
            show(next);
            *shown += 1;
        }
    });
    let (results, _) = done.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
    results.into_iter().map(|r| r.expect("every item was checked")).collect()
}

/// `--sweep-only`: the NaN/Inf sweep of every model, one line each, and the totals.
fn sweep_only<'a>(models: impl Iterator<Item = (&'a String, &'a Bsdf)>, cfg: &CheckConfig, json: bool) -> ExitCode {
    let (mut queries, mut bad, mut failed, mut count) = (0usize, 0usize, 0usize, 0usize);
    let mut all = Vec::new();
    for (name, bsdf) in models {
        let start = std::time::Instant::now();
        let r = sweep(bsdf, cfg.sweep_queries, cfg.seed);
        let seconds = start.elapsed().as_secs_f64();
        count += 1;
        queries += r.queries;
        bad += r.bad;
        failed += usize::from(r.bad > 0);
        if json {
            all.push(serde_json::json!({ "name": name, "queries": r.queries, "bad": r.bad, "first_bad": r.first_bad, "seconds": seconds }));
        } else {
            let detail = r.first_bad.map(|d| format!("  ({d})")).unwrap_or_default();
            outln!("{:>10} queries {:>8} bad {seconds:>7.1} s  {name}{detail}", r.queries, r.bad);
        }
    }
    if json {
        let v = serde_json::json!({ "sweeps": all, "models": count, "queries": queries, "bad": bad });
        outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        outln!("NaN/Inf sweep: {count} models, {queries} queries, {bad} non-finite or negative; {failed} models failed");
    }
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
