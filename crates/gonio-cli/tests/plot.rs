//! `gonio plot` end to end: figures that decode and are not blank, legends, the numbers behind them,
//! measured files through the shared loader, and bad input with exit code 2.

mod common;

use common::{assert_bad_input, gonio, Scratch};
use std::path::Path;

fn ok(args: &[&str]) {
    common::ok(&gonio(args));
}

const DIFFUSE: &str = r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#;
const GGX: &str = r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, "material": "Au"}"#;

/// Decoded PNG: size, and checks that it is a drawing (many colours, text in the title band, the first
/// model's blue curve, or the colours of a heat map).
fn assert_png_is_a_figure(path: &Path, width: usize, curve: bool) {
    let img = gonio::image::read_image(path).expect("a PNG gonio can decode");
    assert_eq!(img.width, width, "{}", path.display());
    assert!(img.height > 300, "{}", img.height);
    let px = |x: usize, y: usize| img.get(x, y);
    // Text in the title band: dark pixels in the top 50 rows (the embedded font was used).
    let dark_title = (0..50).flat_map(|y| (0..img.width).map(move |x| (x, y))).filter(|&(x, y)| px(x, y).max_component() < 0.2).count();
    assert!(dark_title > 200, "{}: no title text ({dark_title} dark pixels)", path.display());
    // A heat map: many distinct colours.
    if !curve {
        let mut colours: Vec<[u8; 3]> = img.data.chunks_exact(3).map(|p| [0, 1, 2].map(|c| (p[c] * 255.0) as u8)).collect();
        colours.sort_unstable();
        colours.dedup();
        assert!(colours.len() > 100, "{}: {} colours", path.display(), colours.len());
        return;
    }
    // The first curve's colour, #1f77b4: blue clearly above red.
    let blue =
        (0..img.height).flat_map(|y| (0..img.width).map(move |x| (x, y))).filter(|&(x, y)| px(x, y).b() > px(x, y).r() + 0.2).count();
    assert!(blue > 200, "{}: no curve ({blue} blue pixels)", path.display());
}

#[test]
fn polar_png_and_svg_with_two_models() {
    let dir = Scratch::new("plot");
    let png = dir.join("polar.png");
    ok(&["plot", DIFFUSE, GGX, "--theta-o", "30", "--kind", "polar", "-o", png.to_str().unwrap()]);
    assert_png_is_a_figure(&png, 1360, true);
    let svg = dir.join("polar.svg");
    ok(&["plot", DIFFUSE, GGX, "--theta-o", "30", "-o", svg.to_str().unwrap(), "--log"]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<?xml") && text.trim_end().ends_with("</svg>"));
    for entry in [">diffuse</text>", ">roughconductor</text>", "θo = 30°", "log scale", "10⁻¹"] {
        assert!(text.contains(entry), "{entry} missing from the SVG");
    }
    // --label names the models; the same type twice is numbered.
    ok(&["plot", DIFFUSE, GGX, "--theta-o", "0", "--label", "paint", "--label", "gold & co", "-o", svg.to_str().unwrap()]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(">paint</text>") && text.contains(">gold &amp; co</text>"));
    ok(&["plot", DIFFUSE, DIFFUSE, "--theta-o", "0", "-o", svg.to_str().unwrap()]);
    assert!(std::fs::read_to_string(&svg).unwrap().contains(">diffuse #2</text>"));
}

#[test]
fn every_kind_draws() {
    let dir = Scratch::new("plot");
    for (kind, width) in [("3d", 960), ("slice", 1030), ("albedo", 1000)] {
        let png = dir.join(format!("{kind}.png"));
        ok(&["plot", GGX, DIFFUSE, "--theta-o", "45", "--kind", kind, "-o", png.to_str().unwrap(), "--samples", "1024"]);
        assert_png_is_a_figure(&png, width, kind != "slice");
    }
}

#[test]
fn csv_holds_the_plotted_numbers() {
    let dir = Scratch::new("plot");
    let csv = dir.join("polar.csv");
    ok(&["plot", DIFFUSE, "--theta-o", "30", "--channel", "b", "-o", csv.to_str().unwrap()]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(r#"angle_deg,"diffuse incidence","diffuse perpendicular""#));
    let mut rows = 0;
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        let cos = v[0].to_radians().cos();
        // The Lambertian polar curve: 0.8/π · cos θi above the surface, 0 below.
        let expect = if cos > 0.0 { 0.8 / std::f64::consts::PI * cos } else { 0.0 };
        assert!((v[1] - expect).abs() < 1e-6, "{line}");
        rows += 1;
    }
    assert_eq!(rows, 721);
    // The albedo of a Lambertian surface is flat at ρ.
    ok(&["plot", DIFFUSE, "--kind", "albedo", "--channel", "g", "--samples", "256", "-o", csv.to_str().unwrap()]);
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().count(), 31);
    for line in text.lines().skip(1) {
        let a: f64 = line.split(',').nth(1).unwrap().parse().unwrap();
        assert!((a - 0.5).abs() < 1e-5, "{line}");
    }
}

#[test]
fn measured_files_use_the_shared_loader() {
    let dir = Scratch::new("plot");
    let rgl = "/work/shared/data/rgl/paper_white_rgb.bsdf";
    if !Path::new(rgl).exists() {
        eprintln!("skipped: {rgl} not present");
        return;
    }
    let svg = dir.join("measured.svg");
    ok(&["plot", rgl, "--kind", "slice", "-o", svg.to_str().unwrap()]);
    assert!(std::fs::read_to_string(&svg).unwrap().contains(">measured</text>"));
}

#[test]
fn bad_input_is_exit_code_two() {
    let dir = Scratch::new("plot");
    let out = dir.join("bad.png");
    let out = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["plot", DIFFUSE, "--theta-o", "95", "-o", out], "--theta-o"),
        (&["plot", DIFFUSE, "--theta-o", "-5", "-o", out], "[0°, 90°)"),
        (&["plot", DIFFUSE, "-o", out], "needs the viewing angle"),
        (&["plot", DIFFUSE, "--theta-o", "10", "--kind", "bar", "-o", out], "bar"),
        (&["plot", DIFFUSE, "--theta-o", "10", "--channel", "x", "-o", out], "unknown channel"),
        (&["plot", "/no/such/model.xml", "--theta-o", "10", "-o", out], "/no/such/model.xml"),
        (&["plot", r#"{"type": "diffuse", "reflectance": 2}"#, "--theta-o", "10", "-o", out], "reflectance"),
        (&["plot", DIFFUSE, "--theta-o", "10", "-o", "figure.txt"], "accepted: .png, .svg, .csv"),
        (&["plot", DIFFUSE, GGX, "--theta-o", "10", "--label", "one", "-o", out], "2 models"),
        (&["plot", DIFFUSE, "--kind", "slice", "--phi-d", "400", "-o", out], "--phi-d"),
        (&["plot", DIFFUSE, "--theta-o", "10", "-o", "/no/such/dir/x.png"], "/no/such/dir/x.png"),
    ];
    for (args, expect) in cases {
        assert_bad_input(args, expect);
    }
    assert!(!Path::new(out).exists(), "a failed plot left a file");
}
