//! `gonio render` end to end: a tiny scene renders to EXR and PNG; bad scenes exit 2 with one line.

use std::process::{Command, Output};

fn gonio(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gonio")).args(args).output().expect("run gonio")
}

const SCENE: &str = r#"<scene version="3.0.0">
    <default name="res" value="4"/>
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="sphere"/>
</scene>"#;

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("gonio-render-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn renders_exr_next_to_the_scene_and_png_on_request() {
    let dir = temp_dir("ok");
    let scene = dir.join("ball.xml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = gonio(&["render", scene.to_str().unwrap(), "--spp", "2", "-D", "res=6", "--quiet"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.join("ball.exr").exists());
    let png = dir.join("ball.png");
    let out = gonio(&["render", scene.to_str().unwrap(), "-o", png.to_str().unwrap(), "--threads", "1", "--seed", "3"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(png.exists());
    assert!(String::from_utf8_lossy(&out.stderr).contains("4 spp"), "{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bad_scenes_exit_two_with_one_line() {
    let dir = temp_dir("bad");
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
    let _ = std::fs::remove_dir_all(dir);
}
