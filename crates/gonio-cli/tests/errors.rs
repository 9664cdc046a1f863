//! The bad-input catalogue of docs/errors.md, one test per row (rows already covered elsewhere name their
//! test in the table), and "nothing lost": an interrupted render writes the samples so far, a failed one
//! leaves an existing image untouched.
//!
//! Every bad input must give exit code 2 and one line on stderr with the exact text of the catalogue —
//! never a panic.

mod common;

use common::{gonio, gonio_command, ok, Scratch, SCENE};
use std::path::Path;
use std::process::{Command, Output};

/// Write `SCENE` with `from` replaced by `to` as `dir/name`.
fn scene_with(dir: &Path, name: &str, from: &str, to: &str) -> String {
    assert!(SCENE.contains(from));
    let path = dir.join(name);
    std::fs::write(&path, SCENE.replace(from, to)).unwrap();
    path.to_str().unwrap().to_string()
}

/// Exit code 2, exactly one line on stderr, equal to `expected` after `gonio: error: ` and with the
/// scratch directory written as `DIR`; no panic.
fn assert_error(out: &Output, dir: &Path, expected: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    let line = stderr.trim_end().replace(dir.to_str().unwrap(), "DIR");
    assert_eq!(line, format!("gonio: error: {expected}"));
}

/// Run `gonio render SCENE -o DIR/out.exr --quiet` in `dir` for a scene with `from` replaced by `to`.
fn render_error(dir: &Path, name: &str, from: &str, to: &str, expected: &str) {
    let scene = scene_with(dir, name, from, to);
    let out_path = dir.join("out.exr");
    let out = gonio(&["render", &scene, "-o", out_path.to_str().unwrap(), "--quiet"]);
    assert_error(&out, dir, expected);
    assert!(!out_path.exists(), "{name}: an image was written");
}

/// [`render_error`] for each row (scene name, text to replace, replacement, expected message), in one
/// scratch directory.
fn render_errors(tag: &str, rows: &[(&str, &str, &str, &str)]) {
    let dir = Scratch::new(tag);
    for (name, from, to, expected) in rows {
        render_error(&dir, name, from, to, expected);
    }
}

const SPHERE: &str = r#"<shape type="sphere"/>"#;

#[test]
fn missing_scene_file() {
    let dir = Scratch::new("errors-missing");
    let out = gonio(&["render", dir.join("nope.xml").to_str().unwrap(), "-o", dir.join("o.exr").to_str().unwrap()]);
    assert_error(&out, &dir, "DIR/nope.xml: No such file or directory (os error 2)");
}

/// chmod 000 stops everyone but root; as root the file stays readable and this test says so and skips.
#[test]
fn unreadable_scene_file() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Scratch::new("errors-unreadable");
    let scene = scene_with(&dir, "locked.xml", "", "");
    std::fs::set_permissions(&scene, std::fs::Permissions::from_mode(0o000)).unwrap();
    if std::fs::read(&scene).is_ok() {
        eprintln!("skipped: running as root, chmod 000 does not make {scene} unreadable");
        return;
    }
    let out = gonio(&["render", &scene, "-o", dir.join("o.exr").to_str().unwrap()]);
    assert_error(&out, &dir, "DIR/locked.xml: Permission denied (os error 13)");
}

#[test]
fn not_xml() {
    let dir = Scratch::new("errors-notxml");
    let path = dir.join("hello.xml");
    std::fs::write(&path, "hello").unwrap();
    let out = gonio(&["render", path.to_str().unwrap(), "-o", dir.join("o.exr").to_str().unwrap()]);
    assert_error(&out, &dir, "DIR/hello.xml:1:1: not valid XML: unknown token at 1:1");
}

#[test]
fn unknown_plugin() {
    render_error(
        &Scratch::new("errors-plugin"),
        "blob.xml",
        SPHERE,
        r#"<shape type="blob"/>"#,
        "DIR/blob.xml:9:5: unsupported shape `blob` (gonio has: sphere, rectangle, cube, disk, cylinder, obj, ply, serialized, sdfgrid, shapegroup, instance)",
    );
}

#[test]
fn unknown_parameter() {
    render_error(
        &Scratch::new("errors-param"),
        "typo.xml",
        SPHERE,
        r#"<shape type="sphere"><float name="radiuss" value="1"/></shape>"#,
        "DIR/typo.xml:9:26: unknown parameter `radiuss` for `sphere` (accepted: center, flip_normals, radius, to_world)",
    );
}

#[test]
fn wrong_type() {
    render_error(
        &Scratch::new("errors-type"),
        "type.xml",
        SPHERE,
        r#"<shape type="sphere"><string name="radius" value="big"/></shape>"#,
        "DIR/type.xml:9:26: parameter `radius` of `sphere` must be a number, got a string",
    );
}

#[test]
fn nan_and_negative_values() {
    render_errors(
        "errors-nan",
        &[
            (
                "nan.xml",
                SPHERE,
                r#"<shape type="sphere"><float name="radius" value="nan"/></shape>"#,
                "DIR/nan.xml:9:26: parameter `radius` of `sphere` must be a number in [0, ∞), got NaN",
            ),
            (
                "negative.xml",
                SPHERE,
                r#"<shape type="sphere"><float name="radius" value="-1"/></shape>"#,
                "DIR/negative.xml:9:26: parameter `radius` of `sphere` must be a number in [0, ∞), got -1",
            ),
            (
                "inf.xml",
                "<emitter type=\"constant\"/>",
                r#"<emitter type="constant"><rgb name="radiance" value="inf"/></emitter>"#,
                "DIR/inf.xml:8:30: parameter `radiance` of `constant` must have every channel in [0, ∞), got [inf, inf, inf]",
            ),
        ],
    );
}

#[test]
fn missing_mesh_texture_and_envmap() {
    render_errors(
        "errors-refs",
        &[
            (
                "mesh.xml",
                SPHERE,
                r#"<shape type="ply"><string name="filename" value="missing.ply"/></shape>"#,
                "DIR/mesh.xml:9:23: file `missing.ply` not found (searched: DIR)",
            ),
            (
                "texture.xml",
                SPHERE,
                r#"<shape type="sphere"><bsdf type="diffuse"><texture name="reflectance" type="bitmap"><string name="filename" value="missing.png"/></texture></bsdf></shape>"#,
                "DIR/texture.xml:9:89: file `missing.png` not found (searched: DIR)",
            ),
            (
                "envmap.xml",
                "<emitter type=\"constant\"/>",
                r#"<emitter type="envmap"><string name="filename" value="/no/such/sky.exr"/></emitter>"#,
                "DIR/envmap.xml:8:28: file `/no/such/sky.exr` does not exist",
            ),
        ],
    );
}

const DATA: &str = "/work/shared/data";

/// The first `n` bytes of a shared data file; `None` (and a note) when the data is missing and
/// GONIO_SKIP_MISSING_DATA is set.
fn shared_prefix(source: &str, n: usize) -> Option<Vec<u8>> {
    let Ok(mut bytes) = std::fs::read(format!("{DATA}/{source}")) else {
        assert!(std::env::var_os("GONIO_SKIP_MISSING_DATA").is_some(), "{DATA}/{source} is missing");
        eprintln!("skipped: {DATA}/{source} is missing");
        return None;
    };
    bytes.truncate(n);
    Some(bytes)
}

/// What a truncated file is made from.
enum Content {
    /// The first bytes of a file in the shared data.
    Prefix(&'static str, usize),
    Bytes(Vec<u8>),
}

/// How gonio meets it: a scene whose element (replacing the first string) names the file, rendered as
/// `EXT.xml`, or `gonio check FILE`.
enum Via {
    Scene(&'static str, &'static str),
    Check,
}

/// One row per truncated format: the file, how it is read, the exact message.
#[test]
fn truncated_binary_files() {
    use Content::{Bytes, Prefix};
    let dir = Scratch::new("errors-truncated");
    // A MERL header (90 × 90 × 180) followed by 1000 of the 34,992,000 bytes of data.
    let mut merl: Vec<u8> = [90i32, 90, 180].iter().flat_map(|v| v.to_le_bytes()).collect();
    merl.resize(1012, 0);
    let envmap = "<emitter type=\"constant\"/>";
    let rows = [
        (
            Prefix("mitsuba/common/meshes/sphere.ply", 5000),
            "t.ply",
            Via::Scene(SPHERE, r#"<shape type="ply"><string name="filename" value="t.ply"/></shape>"#),
            "DIR/ply.xml:9:23: cannot load the ply mesh: DIR/t.ply: line 431: element `face` declares 840 records, more than the 176 bytes left can hold",
        ),
        (
            Prefix("mitsuba/common/meshes/matpreview.serialized", 400_000),
            "t.serialized",
            Via::Scene(SPHERE, r#"<shape type="serialized"><string name="filename" value="t.serialized"/></shape>"#),
            "DIR/serialized.xml:9:30: cannot load the serialized mesh: DIR/t.serialized: byte 399996: mesh count 3031104048 does not fit the file of 400000 bytes",
        ),
        (
            Prefix("envmaps/museum.exr", 20_000),
            "t.exr",
            Via::Scene(envmap, r#"<emitter type="envmap"><string name="filename" value="t.exr"/></emitter>"#),
            "DIR/exr.xml:8:28: cannot load the environment map: DIR/t.exr: OpenEXR data: invalid: reference to missing bytes",
        ),
        (
            Prefix("rgl/paper_white_rgb.bsdf", 300_000),
            "t.bsdf",
            Via::Check,
            "DIR/t.bsdf: field `vndf` (byte 198): f32 data of shape [1, 8, 128, 128] (524288 bytes at byte 2536) runs past the end of the file (300000 bytes): truncated?",
        ),
        (Bytes(merl), "t.binary", Via::Check, "DIR/t.binary: byte 1012: truncated: the file has 1012 bytes, expected 34992012"),
    ];
    for (content, name, via, expected) in rows {
        let bytes = match content {
            Prefix(source, n) => match shared_prefix(source, n) {
                Some(bytes) => bytes,
                None => continue,
            },
            Bytes(bytes) => bytes,
        };
        std::fs::write(dir.join(name), bytes).unwrap();
        match via {
            Via::Scene(from, to) => {
                let extension = name.rsplit('.').next().unwrap();
                render_error(&dir, &format!("{extension}.xml"), from, to, expected);
            }
            Via::Check => assert_error(&gonio(&["check", &dir.arg(name)]), &dir, expected),
        }
    }
}

/// Zero-area shapes: a sphere of radius 0 and a scale of 0 are errors; a mesh whose triangles are all
/// degenerate loads and renders (it is invisible, and emits nothing as an area light) without non-finite
/// samples.
#[test]
fn zero_area_shapes() {
    let dir = Scratch::new("errors-zero");
    render_error(
        &dir,
        "sphere.xml",
        SPHERE,
        r#"<shape type="sphere"><float name="radius" value="0"/></shape>"#,
        "DIR/sphere.xml:9:26: parameter `radius` of `sphere` must be a number > 0, got 0",
    );
    render_error(
        &dir,
        "scale.xml",
        SPHERE,
        r#"<shape type="rectangle"><transform name="to_world"><scale x="0" y="1" z="1"/></transform></shape>"#,
        "DIR/scale.xml:9:56: <scale>: a scale factor is zero",
    );
    std::fs::write(dir.join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    let scene = scene_with(
        &dir,
        "mesh.xml",
        SPHERE,
        r#"<shape type="obj"><string name="filename" value="flat.obj"/><emitter type="area"/></shape><shape type="sphere"/>"#,
    );
    let image = dir.join("mesh.exr");
    let out = gonio(&["render", &scene, "-o", image.to_str().unwrap(), "--spp", "16"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("non-finite") && !stderr.contains("panicked"), "{stderr}");
    let img = gonio::image::read_image(&image).unwrap();
    assert!(img.data.iter().all(|v| v.is_finite()));
}

/// A camera inside a closed object renders: one-sided BSDFs are black seen from behind, as in Mitsuba, and
/// a two-sided one is lit by a light inside.
#[test]
fn camera_inside_geometry_renders() {
    let dir = Scratch::new("errors-inside");
    let mut means = Vec::new();
    for (name, bsdf) in [("one", r#"<bsdf type="diffuse"/>"#), ("two", r#"<bsdf type="twosided"><bsdf type="diffuse"/></bsdf>"#)] {
        let scene = scene_with(
            &dir,
            &format!("{name}.xml"),
            SPHERE,
            &format!(
                r#"<shape type="sphere"><float name="radius" value="10"/>{bsdf}</shape>
                <emitter type="point"><point name="position" x="0" y="0" z="3"/><rgb name="intensity" value="100"/></emitter>"#
            ),
        );
        let image = dir.join(format!("{name}.exr"));
        ok(&gonio(&["render", &scene, "-o", image.to_str().unwrap(), "--spp", "4", "--quiet"]));
        let img = gonio::image::read_image(&image).unwrap();
        assert!(img.data.iter().all(|v| v.is_finite()));
        means.push(img.mean().luminance());
    }
    assert_eq!(means[0], 0.0, "a one-sided diffuse sphere seen from inside is black");
    assert!(means[1] > 0.0, "a two-sided one is lit");
}

#[test]
fn zero_spp() {
    let dir = Scratch::new("errors-spp");
    let scene = scene_with(&dir, "ok.xml", "", "");
    assert_error(&gonio(&["render", &scene, "--spp", "0"]), &dir, "command line: --spp must be at least 1");
    let zero = scene_with(
        &dir,
        "zero.xml",
        "</sensor>",
        r#"<sampler type="independent"><integer name="sample_count" value="0"/></sampler></sensor>"#,
    );
    assert_error(
        &gonio(&["render", &zero]),
        &dir,
        "DIR/zero.xml:7:33: parameter `sample_count` of `independent` must be an integer in [1, 4294967295], got 0",
    );
}

#[test]
fn absurd_resolutions() {
    let dir = Scratch::new("errors-res");
    let scene = scene_with(&dir, "ok.xml", "", "");
    for (res, expected) in [
        ("res=0", "DIR/ok.xml:6:30: parameter `width` of `hdrfilm` must be an integer in [1, 65536], got 0"),
        ("res=1000000", "DIR/ok.xml:6:30: parameter `width` of `hdrfilm` must be an integer in [1, 65536], got 1000000"),
        ("res=65536", "DIR/ok.xml:6:9: a 65536×65536 film has more than 67108864 pixels (e.g. 8192×8192), the most gonio renders"),
    ] {
        let out = gonio(&["render", &scene, "-D", res, "-o", dir.join("o.exr").to_str().unwrap()]);
        assert_error(&out, &dir, expected);
    }
}

/// The output path is checked before the scene is even loaded.
#[test]
fn output_not_writable() {
    let dir = Scratch::new("errors-output");
    let scene = scene_with(&dir, "ok.xml", "", "");
    for (output, expected) in [
        (dir.join("no/such/dir/out.exr"), "DIR/no/such/dir/out.exr: No such file or directory (os error 2)"),
        (dir.join("ok.xml/out.exr"), "DIR/ok.xml/out.exr: Not a directory (os error 20)"),
        (dir.join("out.tiff"), "DIR/out.tiff: file name: cannot write this extension; accepted: .exr, .png, .hdr"),
    ] {
        assert_error(&gonio(&["render", &scene, "-o", output.to_str().unwrap()]), &dir, expected);
    }
    let out = gonio(&["render", "/no/such/scene.xml", "-o", dir.join("x/y.exr").to_str().unwrap()]);
    assert_error(&out, &dir, "DIR/x/y.exr: No such file or directory (os error 2)");
}

/// A good image stays byte for byte what it was when a later render fails: a bad scene, a bad -D, an
/// output whose directory is read-only (skipped as root, which may write anyway).
#[test]
fn a_failed_render_leaves_the_old_image_untouched() {
    use std::os::unix::fs::PermissionsExt;
    let dir = Scratch::new("errors-keep");
    let scene = scene_with(&dir, "ok.xml", "", "");
    let image = dir.join("keep.exr");
    ok(&gonio(&["render", &scene, "-o", image.to_str().unwrap(), "--spp", "2", "--quiet"]));
    let good = std::fs::read(&image).unwrap();
    let bad = scene_with(&dir, "bad.xml", SPHERE, r#"<shape type="sphere"><float name="radius" value="-1"/></shape>"#);
    for args in [vec!["render", &bad], vec!["render", &scene, "-D", "res=0"], vec!["render", &scene, "-D", "oops"]] {
        let mut args = args.clone();
        args.extend(["-o", image.to_str().unwrap()]);
        assert_eq!(gonio(&args).status.code(), Some(2));
        assert_eq!(std::fs::read(&image).unwrap(), good, "{args:?} changed the image");
    }
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    let out = gonio(&["render", &scene, "-o", image.to_str().unwrap(), "--spp", "2"]);
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    if out.status.code() == Some(0) {
        eprintln!("skipped the read-only directory case: running as root");
    } else {
        assert_error(&out, &dir, "DIR/keep.exr: Permission denied (os error 13)");
    }
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(names.iter().all(|n| !n.to_string_lossy().contains(".tmp-")), "temporary left behind: {names:?}");
    if out.status.code() != Some(0) {
        assert_eq!(std::fs::read(&image).unwrap(), good);
    }
}

/// SIGTERM mid-render: the samples so far are written (a valid, finite image whose EXR notes say how
/// many), stderr says so, the exit code is 130. The first pass may not have finished when the signal
/// comes on a loaded machine; then nothing is written and the test waits longer.
#[test]
fn sigterm_writes_the_samples_so_far() {
    let dir = Scratch::new("errors-sigterm");
    let scene = scene_with(&dir, "long.xml", "", "");
    let image = dir.join("long.exr");
    for wait in [1.0f64, 2.0, 4.0, 8.0] {
        let child = gonio_command()
            .args(["render", &scene, "-D", "res=32", "--spp", "100000000", "--threads", "1", "-o", image.to_str().unwrap()])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_secs_f64(wait));
        let kill = Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
        assert!(kill.success());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(130), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        if stderr.contains("before the first pass finished") {
            assert!(!image.exists());
            continue;
        }
        let spp: u32 = stderr
            .split("interrupted: wrote ")
            .nth(1)
            .and_then(|rest| rest.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no interruption note in {stderr}"));
        assert!(stderr.contains(&format!("wrote {spp} of 100000000 spp to {}", image.display())), "{stderr}");
        let img = gonio::image::read_image(&image).unwrap();
        assert_eq!((img.width, img.height), (32, 32));
        assert!(img.data.iter().all(|v| v.is_finite()) && img.mean().luminance() > 0.0);
        let notes = gonio::image::read_notes(&image).unwrap();
        let note = |k: &str| notes.iter().find(|(n, _)| n == k).map(|(_, v)| v.clone());
        assert_eq!(note("gonio.spp"), Some(spp.to_string()));
        assert_eq!(note("gonio.spp_requested").as_deref(), Some("100000000"));
        assert_eq!(note("gonio.interrupted").as_deref(), Some("true"));
        assert_eq!(note("gonio.nonfinite_samples").as_deref(), Some("0"));
        return;
    }
    panic!("the first pass never finished within 8 s");
}

/// A render with overflowing radiance (3·10³⁸, near f32::MAX) has non-finite samples: they are dropped,
/// counted on stderr and in the EXR notes, and the image is finite.
#[test]
fn non_finite_samples_are_reported() {
    let dir = Scratch::new("errors-nonfinite");
    let scene = scene_with(
        &dir,
        "hot.xml",
        "<emitter type=\"constant\"/>\n    <shape type=\"sphere\"/>",
        r#"<emitter type="constant"><rgb name="radiance" value="3e38"/></emitter>
        <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf></shape>"#,
    );
    let image = dir.join("hot.exr");
    let out = gonio(&["render", &scene, "-D", "res=8", "--spp", "8", "-o", image.to_str().unwrap(), "--quiet"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let count: u64 = stderr
        .split("gonio: warning: ")
        .nth(1)
        .and_then(|rest| rest.strip_suffix(" non-finite samples dropped (counted as black)\n"))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no non-finite report in {stderr:?}"));
    assert!(count > 0 && count < 8 * 8 * 8, "{count}");
    let img = gonio::image::read_image(&image).unwrap();
    assert!(img.data.iter().all(|v| v.is_finite()));
    let notes = gonio::image::read_notes(&image).unwrap();
    assert!(notes.contains(&("gonio.nonfinite_samples".to_string(), count.to_string())), "{notes:?}");
    assert!(notes.contains(&("gonio.interrupted".to_string(), "false".to_string())), "{notes:?}");
}
