//! The `gonio` binary end to end: good input passes, bad input gets one clear line and exit code 2.

mod common;

use common::{assert_one_line_error, gonio, gonio_command, ok, Scratch};
use std::path::Path;
use std::process::{Command, Stdio};

fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn check_passes_a_good_model_with_a_table() {
    let out = gonio(&["check", r#"{"type": "diffuse", "reflectance": [0.2, 0.4, 0.6]}"#, "--samples", "200000", "--sweep", "100000"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    for row in ["chi2", "reciprocity", "albedo max", "white furnace", "NaN/Inf sweep", "sample weight/pdf"] {
        assert!(stdout.contains(row), "missing row {row}:\n{stdout}");
    }
}

#[test]
fn check_reads_an_xml_file_and_prints_json() {
    let out = gonio(&["check", &data("rough_gold_plate.xml"), "--json", "--samples", "200000", "--sweep", "100000"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(v["passed"], true);
    assert!(v["checks"].as_array().unwrap().len() >= 8);
}

#[test]
fn check_at_wavelengths_runs_the_harness_on_the_model_at_each() {
    // `--wavelengths` (issue 30): the model as spectral mode renders it at each wavelength, one report each:
    // a dispersive glass (refracting at the index of that wavelength) and gold (η and k of that wavelength).
    for model in [
        r#"{"type": "roughdielectric", "distribution": "ggx", "alpha": 0.5, "int_ior": "bk7", "dispersive": true}"#,
        r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Au"}"#,
    ] {
        let out = gonio(&["check", model, "--wavelengths", "450,650", "--json", "--samples", "200000", "--sweep", "100000"]);
        assert_eq!(out.status.code(), Some(0), "{model}: {}", String::from_utf8_lossy(&out.stdout));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
        let reports = v.as_array().expect("a report per wavelength");
        assert_eq!(reports.len(), 2);
        for (r, nm) in reports.iter().zip(["450", "650"]) {
            assert_eq!(r["passed"], true, "{model} at {nm} nm");
            assert!(r["name"].as_str().is_some_and(|n| n.ends_with(&format!("@ {nm} nm"))), "{r}");
        }
    }
}

#[test]
fn bad_input_is_one_line_and_exit_code_two() {
    let bad_xml = data("bad_param.xml");
    let cases: &[(&[&str], &str)] = &[
        (&["check", r#"{"type": "glass"}"#], "unknown BSDF type `glass`"),
        (&["check", r#"{"type": "diffuse", "albedo": 0.5}"#], "unknown parameter `albedo`"),
        (&["check", r#"{"type": "diffuse", "reflectance": 1.5}"#], "[0, 1]"),
        (&["check", r#"{"type": "dielectric", "int_ior": -1}"#], "`int_ior`"),
        (&["check", r#"{"type": "dielectric", "int_ior": 0}"#], "(0, 10000)"),
        (&["check", r#"{"type": "conductor", "material": "Unobtainium"}"#], "unknown conductor material"),
        (&["check", r#"{"type": "blendbsdf", "weight": 2, "a": {"type": "diffuse"}, "b": {"type": "diffuse"}}"#], "`weight`"),
        (&["check", r#"{"type": "diffuse", "reflectance": "#], "not valid JSON"),
        (&["check", "<bsdf type=\"diffuse\">"], "not valid XML"),
        (&["check", &bad_xml], "bad_param.xml:3:5: unknown parameter `roughness`"),
        (&["check", "/no/such/file.xml"], "/no/such/file.xml"),
        (&["check", r#"{"type": "diffuse"}"#, "--wavelengths", "300"], "300 nm is outside [360, 830] nm"),
        (
            &["check", r#"{"type": "phong", "diffuse_reflectance": [0.8, 0.2, 0.1]}"#, "--wavelengths", "500"],
            "`diffuse_reflectance` of `phong`",
        ),
    ];
    for (args, expect) in cases {
        assert_one_line_error(args, expect);
    }
}

#[test]
fn nan_parameters_are_rejected() {
    // JSON has no NaN literal; XML does.
    let out = gonio(&["check", "<bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"nan\"/></bsdf>"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`reflectance`"));
}

/// Every built-in model at default and extreme parameters, at the project's standard (10⁶ samples per
/// chi-square test, 10⁶ sweep queries): the same run as `gonio check --all`.
#[test]
fn check_all_passes_at_the_full_standard() {
    let out = gonio(&["check", "--all", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let reports = v["examples"].as_array().unwrap();
    let failed: Vec<_> = reports.iter().filter(|r| r["passed"] != true).map(|r| r.to_string()).collect();
    assert!(failed.is_empty(), "{failed:#?}");
    assert_eq!(out.status.code(), Some(0));
    assert!(reports.len() >= 20);
    for r in reports {
        let checks = r["checks"].as_array().unwrap();
        for kind in ["chi2", "reciprocity", "albedo max", "white furnace", "NaN/Inf sweep", "sample weight/pdf"] {
            assert!(checks.iter().any(|c| c["check"].as_str().unwrap().starts_with(kind)), "{kind} missing in {}", r["name"]);
        }
        let reciprocity = checks.iter().find(|c| c["check"] == "reciprocity").unwrap();
        assert!(reciprocity["measured"].as_f64().unwrap() < 1e-5);
    }
    // Every non-physical model kept for teaching fails the row it is known to break, and only that.
    let violations = v["violations"].as_array().unwrap();
    assert!(violations.len() >= 5, "{violations:#?}");
    for r in violations {
        assert_eq!(r["detected"], true, "{r}");
        assert_eq!(r["passed"], false, "{r}");
        let kind = r["expected_violation"].as_str().unwrap();
        let checks = r["checks"].as_array().unwrap();
        assert!(checks.iter().any(|c| c["check"].as_str().unwrap().starts_with(kind) && c["passed"] == false), "{r}");
    }
}

/// The virtual gonioreflectometer end to end: measure a model into a MERL file, load the file back
/// (by its `.binary` extension) and compare directional albedos with the model's.
#[test]
fn measure_then_load_round_trips() {
    let dir = Scratch::new("measure");
    let out = dir.join("plastic.binary");
    let spec = r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": [0.5, 0.3, 0.1]}"#;
    ok(&gonio(&["measure", spec, "-o", out.to_str().unwrap(), "--supersample", "1"]));
    assert_eq!(std::fs::metadata(&out).unwrap().len(), 34_992_012);
    let albedos = |arg: &str| -> Vec<[f64; 3]> {
        let o = gonio(&["albedo", arg, "--angles", "4", "--samples", "40000"]);
        ok(&o);
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter_map(|l| {
                let v: Vec<f64> = l.split_whitespace().filter_map(|t| t.parse().ok()).collect();
                (v.len() == 5).then(|| [v[2], v[3], v[4]])
            })
            .collect()
    };
    let (table, model) = (albedos(out.to_str().unwrap()), albedos(spec));
    assert_eq!(table.len(), 4);
    for (t, m) in table.iter().zip(&model) {
        for c in 0..3 {
            assert!((t[c] - m[c]).abs() < 0.02 * m[c] + 2e-3, "table {t:?} vs model {m:?}");
        }
    }
    for (args, expect) in [
        (vec!["measure", spec, "-o", "/no/such/dir/x.binary"], "/no/such/dir/x.binary"),
        (vec!["check", "/no/such.binary"], "/no/such.binary"),
    ] {
        let o = gonio(&args);
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains(expect));
    }
}

/// `gonio fit` recovers the parameters of a known model and writes XML that loads as the fitted model;
/// a misspelt model name is a one-line error before any work.
#[test]
fn fit_recovers_a_known_model_and_writes_loadable_xml() {
    let dir = Scratch::new("fit");
    let out_path = dir.join("fit.xml");
    let target = r#"{"type": "sum", "weights": [1, 1], "a": {"type": "diffuse", "reflectance": [0.3, 0.2, 0.1]},
        "b": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.25, "material": "Au"}}"#;
    let out = gonio(&["fit", target, "--model", "ggx+diffuse", "--strata", "8", "-o", out_path.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let xml = std::fs::read_to_string(&out_path).unwrap();
    let alpha: f64 = xml
        .lines()
        .find(|l| l.contains("name=\"alpha\""))
        .and_then(|l| l.split("value=\"").nth(1))
        .and_then(|v| v.split('"').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no alpha in {xml}"));
    assert!((alpha - 0.25).abs() < 0.02 * 0.25, "α = {alpha}\n{stdout}");
    // The written file is a <bsdf> that `gonio check` reads.
    ok(&gonio(&["albedo", out_path.to_str().unwrap()]));
    let bad = gonio(&["fit", target, "--model", "gxx"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown model `gxx`"));
    // `gonio fit --list` needs no measured BSDF (bench/fit_rgl_table.sh reads the model names from it).
    let list = gonio(&["fit", "--list"]);
    ok(&list);
    let names: Vec<String> =
        String::from_utf8_lossy(&list.stdout).lines().filter_map(|l| l.split_whitespace().next().map(str::to_string)).collect();
    assert_eq!(names, gonio::fit::MODELS.iter().map(|m| m.name).collect::<Vec<_>>());
}

/// The exit code of a gonio whose reader closed standard output (128 + SIGPIPE).
const CLOSED_STDOUT: i32 = 141;

/// `gonio check --all | head -1`: the reader takes one line and closes the pipe while gonio still has
/// models to check (the sweep alone, to keep the test short; the tables go through the same writer). gonio must end quietly (exit code 141, nothing on stderr), never with a panic about a
/// broken pipe.
#[test]
fn a_reader_that_stops_after_one_line_ends_gonio_quietly() {
    use std::io::BufRead;
    let mut child = gonio_command()
        .args(["check", "--all", "--sweep-only", "--sweep", "200000"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run gonio");
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap()).read_line(&mut first).unwrap();
    assert!(!first.is_empty(), "no first line");
    // The reader is dropped here: the pipe is closed while the second model is being swept.
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr, "", "a closed pipe is not an error worth a message");
    assert_eq!(out.status.code(), Some(CLOSED_STDOUT));
}

/// Standard output a pipe whose reader has already gone (deterministic: the reader, `true`, has exited
/// before gonio starts), for every command that prints to stdout; and a full device (`> /dev/full`) is
/// one line of error, not a panic. (`--all`, which loads every example model first, is the test above.)
#[test]
fn every_command_ends_quietly_when_stdout_is_closed() {
    let diffuse = r#"{"type": "diffuse"}"#;
    let commands: &[&[&str]] = &[
        &["check", diffuse, "--sweep-only", "--sweep", "20000"],
        &["check", diffuse, "--samples", "20000", "--sweep", "1000"],
        &["check", diffuse, "--json", "--samples", "20000", "--sweep", "1000"],
        &["albedo", diffuse, "--angles", "4", "--samples", "64"],
        &["fit", "--list"],
    ];
    for args in commands {
        let mut reader = Command::new("true").stdin(Stdio::piped()).spawn().expect("run true");
        let closed = reader.stdin.take().unwrap();
        reader.wait().unwrap();
        let out = gonio_command().args(*args).stdout(closed).output().expect("run gonio");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(stderr, "", "{args:?}");
        assert_eq!(out.status.code(), Some(CLOSED_STDOUT), "{args:?}");

        if Path::new("/dev/full").exists() {
            let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
            let out = gonio_command().args(*args).stdout(full).output().expect("run gonio");
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(
                stderr.trim_end(),
                "gonio: error: cannot write to standard output: No space left on device (os error 28)",
                "{args:?}"
            );
            assert_eq!(out.status.code(), Some(2), "{args:?}");
        }
    }
}
