//! `gonio render` end to end: a tiny scene renders to EXR and PNG; bad scenes exit 2 with one line.

mod common;

use common::{gonio, ok, Scratch, SCENE};

#[test]
fn renders_exr_next_to_the_scene_and_png_on_request() {
    let dir = Scratch::new("render-ok");
    let scene = dir.join("ball.xml");
    std::fs::write(&scene, SCENE).unwrap();
    ok(&gonio(&["render", scene.to_str().unwrap(), "--spp", "2", "-D", "res=6", "--quiet"]));
    assert!(dir.join("ball.exr").exists());
    let png = dir.join("ball.png");
    let out = gonio(&["render", scene.to_str().unwrap(), "-o", png.to_str().unwrap(), "--threads", "1", "--seed", "3"]);
    ok(&out);
    assert!(png.exists());
    assert!(String::from_utf8_lossy(&out.stderr).contains("4 spp"), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn bad_scenes_exit_two_with_one_line() {
    let dir = Scratch::new("render-bad");
    let scene = dir.join("bad.xml");
    std::fs::write(
        &scene,
        SCENE.replace("<shape type=\"sphere\"/>", "<shape type=\"sphere\">\n<float name=\"radius\" value=\"-1\"/></shape>"),
    )
    .unwrap();
    let out = gonio(&["render", scene.to_str().unwrap(), "--quiet"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("bad.xml:10:1") && stderr.contains("`radius`"), "{stderr}");
    let out = gonio(&["render", scene.to_str().unwrap(), "-D", "nonsense"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("NAME=VALUE"));
}

/// An `aov` integrator's channels go into the EXR file under Mitsuba's names beside the nested `path`
/// integrator's RGB (the image the `path` integrator alone writes); a PNG holds the RGB only, and says so.
#[test]
fn aov_channels_go_to_exr_files() {
    let dir = Scratch::new("render-aov");
    let (plain, aov) = (dir.join("plain.xml"), dir.join("aov.xml"));
    std::fs::write(&plain, SCENE).unwrap();
    let nested = r#"<integrator type="aov"><string name="aovs" value="dd.y:depth, nn:sh_normal"/>
        <integrator type="path" name="image"><integer name="max_depth" value="3"/></integrator></integrator>"#;
    std::fs::write(&aov, SCENE.replace(r#"<integrator type="path"><integer name="max_depth" value="3"/></integrator>"#, nested)).unwrap();
    for scene in [&plain, &aov] {
        ok(&gonio(&["render", scene.to_str().unwrap(), "--spp", "3", "--seed", "5", "-D", "res=6", "--quiet"]));
    }
    let (a, b) = (gonio::image::read_image(&dir.join("plain.exr")).unwrap(), gonio::image::read_image(&dir.join("aov.exr")).unwrap());
    assert_eq!(a, b);
    // The header lists each channel's name, NUL-terminated.
    let bytes = std::fs::read(dir.join("aov.exr")).unwrap();
    for name in ["R", "G", "B", "image.R", "image.G", "image.B", "image.A", "dd.y.T", "nn.X", "nn.Y", "nn.Z"] {
        let name = format!("{name}\0");
        assert!(bytes.windows(name.len()).any(|w| w == name.as_bytes()), "{name} is not in the EXR header");
    }
    let png = dir.join("aov.png");
    let out = gonio(&["render", aov.to_str().unwrap(), "-o", png.to_str().unwrap(), "--spp", "1", "-D", "res=6", "--quiet"]);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("holds the RGB only; the aov channels (image.R, image.G, image.B, image.A, dd.y.T, nn.X, nn.Y, nn.Z)"),
        "{stderr}"
    );
}
