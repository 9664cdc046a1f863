//! `gonio preview` end to end: the image has the right size, the sphere is lit and the background is the
//! environment; a white Lambertian sphere in the white furnace renders as the furnace; bad input exits 2.

mod common;

use common::{assert_one_line_error, gonio, ok, Scratch};
use gonio::image::read_image;
use gonio::Rgb;

/// The mean over the central half of a square image (all on the sphere, which fills 90 % of the width).
fn centre_mean(img: &gonio::image::Image) -> Rgb {
    let (lo, hi) = (img.width / 4, 3 * img.width / 4);
    let mut sum = Rgb::ZERO;
    for y in lo..hi {
        for x in lo..hi {
            sum += img.get(x, y);
        }
    }
    sum / ((hi - lo) * (hi - lo)) as f32
}

#[test]
fn diffuse_sphere_png_has_the_size_a_lit_sphere_and_the_sky_behind() {
    let dir = Scratch::new("preview-png");
    let png = dir.join("ball.png");
    let p = png.to_str().unwrap();
    ok(&gonio(&[
        "preview",
        r#"{"type": "diffuse", "reflectance": [0.2, 0.4, 0.8]}"#,
        "--env",
        "gradient",
        "--size",
        "48",
        "--spp",
        "8",
        "-o",
        p,
    ]));
    let img = read_image(&png).unwrap();
    assert_eq!((img.width, img.height), (48, 48));
    let c = centre_mean(&img);
    assert!(c.min_component() > 0.02 && c.b() > c.r(), "the blue sphere is lit and blue: {c}");
    // The corners show the built-in sky: blue-grey above the horizon (row 0), brown ground below.
    let (top, bottom) = (img.get(0, 0), img.get(0, 47));
    assert!(top.b() > top.r() && top.min_component() > 0.2, "sky {top}");
    assert!(bottom.r() > bottom.b() && bottom.max_component() < 0.6, "ground {bottom}");
    // A directional light from the right: the right half of the sphere is brighter than the left.
    ok(&gonio(&["preview", r#"{"type": "diffuse"}"#, "--light", "1,0,0.2", "--size", "32", "--spp", "4", "-o", p, "--quiet"]));
    let img = read_image(&png).unwrap();
    assert!(img.get(24, 16).r() > 4.0 * img.get(7, 16).r(), "{} vs {}", img.get(24, 16), img.get(7, 16));
}

#[test]
fn white_diffuse_sphere_in_the_white_furnace_is_white() {
    // A convex white Lambertian sphere under uniform radiance 1 reflects radiance 1 everywhere. The mean
    // over 32² pixels × 16 spp has a standard error of a few tenths of a percent.
    let dir = Scratch::new("preview-furnace");
    let exr = dir.join("furnace.exr");
    let e = exr.to_str().unwrap();
    ok(&gonio(&["preview", r#"{"type": "diffuse", "reflectance": 1}"#, "--env", "constant", "--size", "64", "--spp", "16", "-o", e]));
    let img = read_image(&exr).unwrap();
    let c = centre_mean(&img);
    for v in c.0 {
        assert!((v - 1.0).abs() < 0.02, "furnace sphere {c}");
    }
    assert_eq!(img.get(0, 0), Rgb::ONE, "the background is the environment");
    // --exposure −1 halves everything.
    ok(&gonio(&[
        "preview",
        r#"{"type": "diffuse", "reflectance": 1}"#,
        "--env",
        "constant",
        "--size",
        "8",
        "--spp",
        "1",
        "--exposure",
        "-1",
        "-o",
        e,
    ]));
    assert_eq!(read_image(&exr).unwrap().get(0, 0), Rgb::splat(0.5));
}

#[test]
fn grid_and_several_bsdfs_are_laid_out_in_rows_and_columns() {
    let dir = Scratch::new("preview-grid");
    let exr = dir.join("grid.exr");
    let e = exr.to_str().unwrap();
    let a = r#"{"type": "roughconductor", "distribution": "ggx"}"#;
    let b = r#"{"type": "roughconductor", "distribution": "beckmann"}"#;
    ok(&gonio(&["preview", a, b, "--grid", "alpha=0.05,0.2,0.6", "--env", "constant", "--size", "16", "--spp", "1", "-o", e]));
    let img = read_image(&exr).unwrap();
    // 3 columns and 2 rows of 16 px with 1 px gaps.
    assert_eq!((img.width, img.height), (50, 33));
    assert_eq!(img.get(16, 5), Rgb::splat(0.02), "the gap");
    ok(&gonio(&["preview", a, b, "--env", "constant", "--size", "16", "--spp", "1", "-o", e]));
    assert_eq!(read_image(&exr).unwrap().width, 33);
    // Two parameters: their product, a column per value of the last and a row per value of the first.
    let grid = ["--grid", "alpha=0.05,0.2,0.6", "--grid", "distribution=ggx,beckmann"];
    ok(&gonio(&[&["preview", a][..], &grid, &["--env", "constant", "--size", "16", "--spp", "1", "-o", e]].concat()));
    let img = read_image(&exr).unwrap();
    assert_eq!((img.width, img.height), (33, 50));
}

#[test]
fn spectral_mode_previews_dispersive_glass_in_the_white_furnace_as_white() {
    // Spectral mode (issue 30): a dispersive diamond sphere (each path following its hero wavelength through
    // it) and a coloured diffuse one, in the white furnace. The diamond sphere is the furnace's white within
    // noise; the diffuse sphere's colour is its reflectance, as in RGB mode, within the upsampling's 1 %.
    let dir = Scratch::new("preview-spectral");
    let exr = dir.join("spectral.exr");
    let e = exr.to_str().unwrap();
    let diamond = r#"{"type": "dielectric", "int_ior": "diamond", "dispersive": true}"#;
    ok(&gonio(&["preview", diamond, "--env", "constant", "--mode", "spectral", "--size", "32", "--spp", "64", "-o", e, "--quiet"]));
    let c = centre_mean(&read_image(&exr).unwrap());
    for v in c.0 {
        assert!((v - 1.0).abs() < 0.03, "the diamond sphere in the furnace: {c}");
    }
    let paper = r#"{"type": "diffuse", "reflectance": [0.2, 0.4, 0.8]}"#;
    ok(&gonio(&["preview", paper, "--env", "constant", "--mode", "spectral", "--size", "32", "--spp", "64", "-o", e, "--quiet"]));
    let c = centre_mean(&read_image(&exr).unwrap());
    for (v, want) in c.0.iter().zip([0.2f32, 0.4, 0.8]) {
        assert!((v / want - 1.0).abs() < 0.03, "the blue paper in the furnace: {c}");
    }
}

#[test]
fn bad_input_is_one_line_and_exit_code_two() {
    let dir = Scratch::new("preview-bad");
    let png = dir.join("x.png");
    let p = png.to_str().unwrap();
    let d = r#"{"type": "diffuse"}"#;
    let cases: &[(&[&str], &str)] = &[
        (&["preview", r#"{"type": "glass"}"#, "-o", p], "unknown BSDF type `glass`"),
        (&["preview", d, "--grid", "alpha=0.1,0.2", "-o", p], "unknown parameter `alpha`"),
        (&["preview", d, "--grid", "reflectance", "-o", p], "NAME=V1,V2"),
        (&["preview", d, "--grid", "reflectance=0.1,,0.2", "-o", p], "empty value"),
        (&["preview", d, "--grid", "reflectance=0.5,2", "-o", p], "[0, 1]"),
        (&["preview", d, "--grid", "reflectance=0.5", "--grid", "reflectance=0.2", "-o", p], "`reflectance` is given twice"),
        (&["preview", d, d, "--grid", "reflectance=0.5", "--ray", "auto", "-o", p], "--ray sweeps one BSDF"),
        (&["preview", d, "--light", "1,2", "-o", p], "X,Y,Z"),
        (&["preview", d, "--light", "0,0,0", "-o", p], "non-zero"),
        (&["preview", d, "--env", "/no/such/sky.hdr", "-o", p], "/no/such/sky.hdr"),
        (&["preview", d, "-o", "/tmp/sphere.jpg"], ".png, .exr or .hdr"),
        (&["preview", d, "--spp", "0", "-o", p], "--spp"),
        (&["preview", "/no/such/material.xml", "-o", p], "/no/such/material.xml"),
        (
            &["preview", r#"{"type": "phong", "diffuse_reflectance": [0.8, 0.2, 0.1]}"#, "--mode", "spectral", "-o", p],
            "`diffuse_reflectance` of `phong`",
        ),
    ];
    for (args, expect) in cases {
        assert_one_line_error(args, expect);
        assert!(!png.exists(), "{args:?} wrote an image");
    }
}
