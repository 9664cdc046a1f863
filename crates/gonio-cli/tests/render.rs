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
