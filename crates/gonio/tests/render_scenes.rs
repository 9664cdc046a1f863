//! Renders with analytic answers, loader error messages, and determinism.

use gonio::render::{render, RenderOutput};
use gonio::scene::{mitsuba_xml, Scene};
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn scene(xml: &str) -> Scene {
    Scene::build(mitsuba_xml::load_str(xml, "test.xml", Path::new("."), &[]).unwrap()).unwrap()
}

fn run(scene: &Scene) -> RenderOutput {
    render(scene, scene.sampler.sample_count, scene.sampler.seed, &AtomicBool::new(false), &|_| {})
}

/// Mean and standard error of the mean of one channel over all pixels.
fn mean_and_se(img: &RenderOutput, channel: usize) -> (f64, f64) {
    let v: Vec<f64> = img.data.chunks(3).map(|p| f64::from(p[channel])).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// A camera at (0, 0, `dist`) looking at the origin, `fov` degrees, `res`² pixels, `spp` samples.
fn sensor(dist: f32, fov: f32, res: u32, spp: u32) -> String {
    format!(
        r#"<sensor type="perspective"><float name="fov" value="{fov}"/>
            <transform name="to_world"><lookat origin="0, 0, {dist}" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="{res}"/><integer name="height" value="{res}"/></film></sensor>"#
    )
}

fn assert_close(img: &RenderOutput, expected: [f64; 3], what: &str) {
    for (c, &want) in expected.iter().enumerate() {
        let (mean, se) = mean_and_se(img, c);
        // 5 standard errors, plus 1e-4 relative for f32 rounding (2026-11).
        assert!((mean - want).abs() <= 5.0 * se + 1e-4 * want, "{what}: channel {c}: {mean} ± {se}, expected {want}");
    }
}

/// A convex diffuse object under a constant environment: every bounce escapes, so L = ρ L_env exactly.
#[test]
fn furnace_diffuse_sphere_is_rho_times_l() {
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="path"/>{}
        <emitter type="constant"><rgb name="radiance" value="2, 1, 0.5"/></emitter>
        <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.3, 0.9"/></bsdf></shape></scene>"#,
        sensor(5.0, 10.0, 16, 64)
    ));
    let img = run(&s);
    assert_close(&img, [1.2, 0.3, 0.45], "furnace sphere");
}

#[test]
fn lambertian_plane_under_constant_environment() {
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="direct"/>{}
        <emitter type="constant"><rgb name="radiance" value="1.5"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="100"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.4"/></bsdf></shape></scene>"#,
        sensor(3.0, 30.0, 16, 64)
    ));
    assert_close(&run(&s), [0.6; 3], "plane");
}

/// A sphere of radius r lit by a point light of intensity I at distance d from its centre, seen from the
/// light's side along the axis: L = ρ/π · I / (d − r)².
#[test]
fn point_light_on_sphere_nearest_point() {
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="3"/></integrator>{}
        <emitter type="point"><point name="position" x="0" y="0" z="5"/><rgb name="intensity" value="10"/></emitter>
        <shape type="sphere"><float name="radius" value="1"/><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape></scene>"#,
        sensor(10.0, 0.2, 4, 4)
    ));
    let img = run(&s);
    let expected = 0.5 / std::f64::consts::PI * 10.0 / 16.0;
    for p in img.data.chunks(3) {
        assert!((f64::from(p[0]) / expected - 1.0).abs() < 1e-3, "{} vs {expected}", p[0]);
    }
}

/// An area light seen directly: max_depth = 1 shows emitters only; the back of the light is black.
#[test]
fn max_depth_one_shows_only_emitters_on_their_front() {
    let xml = |flip: bool| {
        format!(
            r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="1"/></integrator>{}
            <emitter type="constant"><rgb name="radiance" value="0"/></emitter>
            <shape type="rectangle"><boolean name="flip_normals" value="{flip}"/><transform name="to_world"><scale value="10"/></transform>
                <emitter type="area"><rgb name="radiance" value="3, 2, 1"/></emitter></shape></scene>"#,
            sensor(3.0, 30.0, 4, 2)
        )
    };
    assert!(run(&scene(&xml(false))).data.chunks(3).all(|p| p == [3.0, 2.0, 1.0]));
    assert!(run(&scene(&xml(true))).data.iter().all(|&v| v == 0.0));
}

/// The camera's clipping planes bound its rays in both integrators: an emitter 3 away is seen with
/// `far_clip` 4, not with 2 (the constant environment, 0.5, is seen instead).
#[test]
fn far_clip_hides_what_lies_beyond() {
    for integrator in ["path", "direct"] {
        let xml = |far: f32| {
            format!(
                r#"<scene version="3.0.0"><integrator type="{integrator}"/>
                <sensor type="perspective"><float name="fov" value="30"/><float name="far_clip" value="{far}"/>
                    <transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
                    <sampler type="independent"><integer name="sample_count" value="2"/></sampler>
                    <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
                <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
                <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
                    <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
                    <emitter type="area"><rgb name="radiance" value="3, 2, 1"/></emitter></shape></scene>"#
            )
        };
        assert!(run(&scene(&xml(4.0))).data.chunks(3).all(|p| p == [3.0, 2.0, 1.0]), "{integrator}");
        assert!(run(&scene(&xml(2.0))).data.iter().all(|&v| v == 0.5), "{integrator}");
    }
}

/// A small Cornell-like box: same seed, same bits with one and with two threads.
#[test]
fn same_seed_same_image_with_one_or_two_threads() {
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="6"/><integer name="rr_depth" value="2"/></integrator>{}
        <shape type="cube"><boolean name="flip_normals" value="true"/><transform name="to_world"><scale value="3"/></transform></shape>
        <shape type="sphere"><float name="radius" value="0.5"/><bsdf type="conductor"><string name="material" value="Au"/></bsdf></shape>
        <shape type="disk"><transform name="to_world"><rotate x="1" angle="90"/><translate y="2.9"/></transform>
            <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape></scene>"#,
        sensor(2.5, 60.0, 40, 8)
    ));
    let render_with = |threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| run(&s));
    let (a, b) = (render_with(1), render_with(2));
    assert!(a.data.iter().zip(&b.data).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert!(a.data.iter().any(|&v| v > 0.0) && a.nonfinite == 0);
}

fn load_error(xml: &str) -> String {
    match mitsuba_xml::load_str(xml, "bad.xml", Path::new("."), &[]).and_then(Scene::build) {
        Ok(_) => panic!("expected an error for {xml}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn loader_errors_name_file_line_and_element() {
    let cases = [
        ("<scene version=\"3.0.0\">\n  <shape type=\"torus\"/></scene>", "bad.xml:2:3: unsupported shape `torus`"),
        ("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n    <float name=\"radius2\" value=\"1\"/></shape></scene>", "bad.xml:3:5: unknown parameter `radius2` for `sphere`"),
        ("<scene version=\"3.0.0\">\n <include filename=\"missing.xml\"/></scene>", "bad.xml:2:2: file `missing.xml` not found"),
        ("<scene version=\"3.0.0\">\n<shape type=\"sphere\"><transform name=\"to_world\">\n<rotate angle=\"30\"/></transform></shape></scene>", "bad.xml:3:1: <rotate>: the rotation axis is zero"),
        ("<scene version=\"3.0.0\">\n<shape type=\"sphere\"><bsdf type=\"velvet\"/></shape></scene>", "bad.xml:2:22: unknown BSDF type `velvet`"),
        ("<scene version=\"3.0.0\">\n<shape type=\"sphere\"><ref id=\"nope\"/></shape></scene>", "bad.xml:2:22: <ref id=\"nope\">"),
        ("<scene version=\"3.0.0\">\n<integrator type=\"path\"><integer name=\"max_depth\" value=\"$d\"/></integrator></scene>", "bad.xml:2:25: `$d` is not defined"),
        ("<scene version=\"3.0.0\">\n<emitter type=\"envmapp\"/></scene>", "bad.xml:2:1: unsupported emitter `envmapp`"),
        ("<scene version=\"3.0.0\">\n<shape type=\"sphere\"><bsdf type=\"diffuse\">\n<texture name=\"reflectance\" type=\"gradient\"/></bsdf></shape></scene>", "bad.xml:3:1: unsupported texture `gradient`"),
        ("<scene>\n</scene>", "bad.xml:1:1: <scene> needs a version"),
    ];
    for (xml, want) in cases {
        let e = load_error(xml);
        assert!(e.starts_with(want), "got: {e}\nwant: {want}");
    }
}

#[test]
fn defaults_and_overrides_substitute() {
    let xml = r#"<scene version="3.0.0"><default name="spp" value="3"/><default name="res" value="8"/>
        <sensor type="perspective"><sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film></sensor></scene>"#;
    let s = Scene::build(mitsuba_xml::load_str(xml, "t.xml", Path::new("."), &[("spp".into(), "7".into())]).unwrap()).unwrap();
    assert_eq!((s.sampler.sample_count, s.film.width), (7, 8));
}

/// Orientation of `lookat` against Mitsuba: the same scene rendered by Mitsuba 3.9.1 (scalar_rgb, 16 spp)
/// puts the red sphere (world +x) at pixel centroid (23.9, 12.0) and the green one (world +y, −x) at
/// (12.0, 4.5) of a 32×24 image, with mean (0.957, 0.898, 0.870). Recorded with
/// `tests/mitsuba_compare.py` (which needs the `mitsuba` Python package).
#[test]
fn lookat_orientation_matches_mitsuba() {
    let s = scene(
        r#"<scene version="3.0.0">
        <integrator type="path"><integer name="max_depth" value="2"/></integrator>
        <sensor type="perspective"><float name="fov" value="40"/>
            <transform name="to_world"><lookat origin="1, 2, 6" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
            <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/><rfilter type="box"/></film></sensor>
        <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
        <shape type="sphere"><point name="center" x="1.2" y="0" z="0"/><float name="radius" value="0.7"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.9, 0.05, 0.05"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="-0.5" y="1" z="0"/><float name="radius" value="0.4"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.05, 0.9, 0.05"/></bsdf></shape></scene>"#,
    );
    let img = run(&s);
    let centroid = |pick: &dyn Fn(&[f32]) -> bool| {
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
        for (i, p) in img.data.chunks(3).enumerate() {
            if pick(p) {
                sx += (i % 32) as f64;
                sy += (i / 32) as f64;
                n += 1.0;
            }
        }
        (sx / n, sy / n)
    };
    let red = centroid(&|p| p[0] - p[1] > 0.3);
    let green = centroid(&|p| p[1] - p[0] > 0.3);
    assert!((red.0 - 23.94).abs() < 0.5 && (red.1 - 11.96).abs() < 0.5, "red at {red:?}");
    assert!((green.0 - 12.0).abs() < 0.5 && (green.1 - 4.5).abs() < 0.5, "green at {green:?}");
    for (c, m) in [0.957, 0.898, 0.870].iter().enumerate() {
        let (mean, _) = mean_and_se(&img, c);
        assert!((mean - m).abs() < 0.01, "channel {c}: {mean} vs Mitsuba {m}");
    }
}

/// A spherical area light (radiance L, radius r) at height d above a Lambertian plane: the irradiance
/// below its centre is π L r²/d², so the plane's radiance there is ρ L r²/d².
#[test]
fn sphere_area_light_over_plane() {
    let s = scene(
        r#"<scene version="3.0.0"><integrator type="direct"/>
        <sensor type="perspective"><float name="fov" value="0.5"/>
            <transform name="to_world"><lookat origin="3, 0, 1" target="0, 0, 0" up="0, 0, 1"/></transform>
            <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
            <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
        <shape type="sphere"><point name="center" x="0" y="0" z="2"/><float name="radius" value="0.5"/>
            <emitter type="area"><rgb name="radiance" value="4"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape></scene>"#,
    );
    let img = run(&s);
    // The 0.5° field of view spans ±0.014 around the origin: the irradiance varies by < 1e-4 there.
    assert_close(&img, [0.125; 3], "sphere light");
}

/// A checkerboard on Mitsuba's rectangle (uv = ((x + 1)/2, (y + 1)/2)) framed exactly by the camera:
/// top-left and bottom-right quadrants show `color1`, the others `color0` (times L = 1).
#[test]
fn checkerboard_on_rectangle_follows_mitsuba_uv() {
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="direct"/>{}
        <emitter type="constant"/>
        <shape type="rectangle"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
            <rgb name="color0" value="0.8"/><rgb name="color1" value="0.2"/></texture></bsdf></shape></scene>"#,
        sensor(1.0, 90.0, 4, 256)
    ));
    let img = run(&s);
    let px = |x: usize, y: usize| img.data[3 * (y * 4 + x)];
    for (x, y, want) in [(0, 0, 0.2), (3, 0, 0.8), (0, 3, 0.8), (3, 3, 0.2)] {
        assert!((px(x, y) - want).abs() < 0.05 * want + 0.01, "pixel ({x}, {y}) = {}, expected {want}", px(x, y));
    }
}

/// Timing of any scene: `GONIO_SCENE=path.xml cargo test -p gonio --test render_scenes -- --ignored --nocapture`.
#[test]
#[ignore = "timing run on a scene given by GONIO_SCENE"]
fn time_scene_from_env() {
    let Ok(path) = std::env::var("GONIO_SCENE") else { return };
    let t = std::time::Instant::now();
    let s = Scene::load(Path::new(&path), &[]).unwrap();
    let load = t.elapsed().as_secs_f64();
    let img = run(&s);
    let mean: Vec<f64> = (0..3).map(|c| mean_and_se(&img, c).0).collect();
    println!("{path}: load {load:.3} s, render {:.3} s, {} spp, {} prims, mean {mean:?}", img.seconds, img.spp_done, s.primitive_count());
}

/// A constant-valued EXR environment map of `w × h` texels and radiance `value`, written to a temporary file.
fn constant_envmap_file(tag: &str, w: usize, h: usize, value: gonio::Rgb) -> std::path::PathBuf {
    let mut img = gonio::image::Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            img.set(x, y, value);
        }
    }
    let path = std::env::temp_dir().join(format!("gonio-test-{tag}-{}.exr", std::process::id()));
    gonio::image::write_image(&path, &img).unwrap();
    path
}

/// The furnace sphere of `furnace_diffuse_sphere_is_rho_times_l`, lit by a constant-valued `envmap` and by
/// `constant`: both converge to ρ L, and agree pixel by pixel within their noise.
#[test]
fn constant_envmap_matches_constant_emitter() {
    let file = constant_envmap_file("furnace", 8, 5, gonio::Rgb::new(2.0, 1.0, 0.5));
    let xml = |emitter: &str| {
        format!(
            r#"<scene version="3.0.0"><integrator type="path"/>{}
            {emitter}
            <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.3, 0.9"/></bsdf></shape></scene>"#,
            sensor(5.0, 10.0, 16, 64)
        )
    };
    let env = run(&scene(&xml(&format!(r#"<emitter type="envmap"><string name="filename" value="{}"/></emitter>"#, file.display()))));
    let constant = run(&scene(&xml(r#"<emitter type="constant"><rgb name="radiance" value="2, 1, 0.5"/></emitter>"#)));
    std::fs::remove_file(&file).ok();
    assert_close(&env, [1.2, 0.3, 0.45], "envmap furnace");
    assert_close(&constant, [1.2, 0.3, 0.45], "constant furnace");
    for c in 0..3 {
        let (a, sa) = mean_and_se(&env, c);
        let (b, sb) = mean_and_se(&constant, c);
        assert!((a - b).abs() <= 5.0 * (sa * sa + sb * sb).sqrt() + 1e-4 * b, "channel {c}: {a} vs {b}");
    }
}

/// A Lambertian plane under a constant-valued `envmap` with `scale`, one bounce: L = ρ · scale · L_map.
#[test]
fn lambertian_plane_under_envmap_is_rho_times_l() {
    let file = constant_envmap_file("plane", 6, 4, gonio::Rgb::splat(0.75));
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="direct"/>{}
        <emitter type="envmap"><string name="filename" value="{}"/><float name="scale" value="2"/>
            <transform name="to_world"><rotate x="1" angle="30"/></transform></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="100"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.4"/></bsdf></shape></scene>"#,
        sensor(3.0, 30.0, 16, 64),
        file.display()
    ));
    let img = run(&s);
    std::fs::remove_file(&file).ok();
    assert_close(&img, [0.6; 3], "plane under envmap");
}

/// The camera looks straight at the environment in direction (1, 0, −1)/√2, which Mitsuba's mapping puts at
/// u = 1/8, v = ½: the centre of texel (0, 1) of a 4 × 3 map. Every other texel has another colour.
#[test]
fn envmap_orientation_follows_mitsuba() {
    let mut img = gonio::image::Image::new(4, 3);
    for y in 0..3 {
        for x in 0..4 {
            img.set(x, y, gonio::Rgb::new(x as f32, y as f32, 10.0));
        }
    }
    img.set(0, 1, gonio::Rgb::new(5.0, 7.0, 3.0));
    let path = std::env::temp_dir().join(format!("gonio-test-orient-{}.exr", std::process::id()));
    gonio::image::write_image(&path, &img).unwrap();
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="path"/>
        <sensor type="perspective"><float name="fov" value="0.01"/>
            <transform name="to_world"><lookat origin="0, 0, 0" target="1, 0, -1" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="1"/></sampler>
            <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/></film></sensor>
        <emitter type="envmap"><string name="filename" value="{}"/></emitter></scene>"#,
        path.display()
    ));
    let out = run(&s);
    std::fs::remove_file(&path).ok();
    for (got, want) in out.data.iter().zip([5.0, 7.0, 3.0]) {
        assert!((got - want).abs() < 1e-2, "{:?}", out.data);
    }
}

/// A spot light (intensity I) at height d above a Lambertian plane, pointing down; the camera looks at the
/// spot's axis: L = ρ/π · I / d². Outside the cutoff the plane is black; halfway through the linear
/// falloff it gets half.
#[test]
fn spot_light_on_plane_closed_form() {
    let xml = |target_x: f32| {
        format!(
            r#"<scene version="3.0.0"><integrator type="direct"/>
            <sensor type="perspective"><float name="fov" value="0.05"/>
                <transform name="to_world"><lookat origin="{target_x}, 0, 5" target="{target_x}, 0, 0" up="0, 1, 0"/></transform>
                <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
                <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
            <emitter type="spot"><rgb name="intensity" value="8, 4, 2"/><float name="cutoff_angle" value="30"/><float name="beam_width" value="10"/>
                <transform name="to_world"><lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/></transform></emitter>
            <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform>
                <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape></scene>"#
        )
    };
    let pi = std::f64::consts::PI;
    let on_axis = run(&scene(&xml(0.0)));
    for (c, i) in [8.0, 4.0, 2.0].iter().enumerate() {
        let want = 0.5 / pi * i / 4.0;
        assert!(on_axis.data.chunks(3).all(|p| (f64::from(p[c]) / want - 1.0).abs() < 1e-3), "{:?} vs {want}", &on_axis.data[..3]);
    }
    // 20° off axis (halfway between beam 10° and cutoff 30°): distance d / cos 20°, cosine cos 20°.
    let t = 20f64.to_radians();
    let half = run(&scene(&xml((2.0 * t.tan()) as f32)));
    let want = 0.5 / pi * 8.0 * 0.5 * t.cos().powi(3) / 4.0;
    assert!((f64::from(half.data[0]) / want - 1.0).abs() < 1e-2, "{} vs {want}", half.data[0]);
    let outside = run(&scene(&xml((2.0 * 35f64.to_radians().tan()) as f32)));
    assert!(outside.data.iter().all(|&v| v == 0.0));
}

/// A directional light of irradiance E at angle θ from the normal of a Lambertian plane: L = ρ/π · E cos θ.
#[test]
fn directional_light_on_plane_closed_form() {
    let s = scene(&format!(
        r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="2"/></integrator>{}
        <emitter type="directional"><vector name="direction" x="1" y="0" z="-1"/><rgb name="irradiance" value="3"/></emitter>
        <shape type="rectangle"><transform name="to_world"><scale value="100"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape></scene>"#,
        sensor(3.0, 30.0, 4, 2)
    ));
    let img = run(&s);
    let want = 0.5 / std::f64::consts::PI * 3.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert!(img.data.iter().all(|&v| (f64::from(v) / want - 1.0).abs() < 1e-3), "{:?} vs {want}", &img.data[..3]);
}

/// `serialized`: mesh `shape_index` of Mitsuba's matpreview file loads through the scene; an index past the
/// last mesh is an error naming the shape.
#[test]
fn serialized_shape_loads_by_index() {
    let file = "/work/shared/data/mitsuba/common/meshes/matpreview.serialized";
    if !Path::new(file).exists() {
        eprintln!("skipped: {file} is missing");
        return;
    }
    let xml = |index: u32| {
        format!(
            r#"<scene version="3.0.0">{}
            <shape type="serialized"><string name="filename" value="{file}"/><integer name="shape_index" value="{index}"/>
                <boolean name="face_normals" value="true"/></shape></scene>"#,
            sensor(3.0, 30.0, 4, 1)
        )
    };
    assert!(scene(&xml(0)).primitive_count() > 100);
    let e = load_error(&xml(1000));
    assert!(e.contains("test.xml") || e.contains("bad.xml"), "{e}");
    assert!(e.contains("serialized"), "{e}");
}

/// An anisotropic `roughconductor` sphere (GGX, alpha_u 0.05 along the shading tangent s, alpha_v 0.4) seen
/// from above its +z pole under a point light: where its highlight falls depends on the tangent. Mitsuba's s
/// runs along the parallels of the sphere's parameterisation, so the highlight converges at the pole; a
/// frame built from the normal alone gave a mean 43 % below Mitsuba's. The references are Mitsuba 3.9.1
/// (`scalar_rgb`, 4096 spp): the image mean, and the means of its 4 × 4 blocks of 8 × 8 pixels (rows from
/// the top).
#[test]
fn anisotropic_sphere_highlight_follows_mitsubas_tangent() {
    let s = scene(
        r#"<scene version="3.0.0"><integrator type="direct"/>
        <sensor type="perspective"><float name="fov" value="30"/>
            <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="512"/></sampler>
            <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film></sensor>
        <emitter type="point"><point name="position" x="1" y="1.5" z="5"/><rgb name="intensity" value="20"/></emitter>
        <shape type="sphere"><bsdf type="roughconductor"><string name="distribution" value="ggx"/>
            <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.4"/></bsdf></shape></scene>"#,
    );
    const MEAN: f64 = 0.068_376_44;
    const BLOCKS: [[f64; 4]; 4] = [
        [0.000_230, 0.016_345, 0.109_765, 0.003_304],
        [0.006_242, 0.021_992, 0.635_813, 0.036_290],
        [0.011_180, 0.194_253, 0.019_840, 0.007_819],
        [0.000_003, 0.022_371, 0.008_441, 0.000_134],
    ];
    let img = run(&s);
    let (mean, _) = mean_and_se(&img, 0);
    let mut blocks = [[0.0f64; 4]; 4];
    for (i, p) in img.data.chunks(3).enumerate() {
        let (x, y) = (i % 32, i / 32);
        blocks[y / 8][x / 8] += f64::from(p[0]) / 64.0;
    }
    // 2026-12: 1 % is over ten standard deviations of a 512-spp mean (0.08 %, measured over Mitsuba's
    // seeds); the frame from the normal alone, before 2026-12, was 43 % low.
    assert!((mean / MEAN - 1.0).abs() < 0.01, "mean {mean}, Mitsuba {MEAN}; blocks {blocks:?}");
    for (row, want_row) in blocks.iter().zip(BLOCKS) {
        for (&got, want) in row.iter().zip(want_row) {
            // 2026-12: 3 % and 10⁻³ absorb the sampling noise of the brightest and the darkest blocks.
            assert!((got - want).abs() < 0.03 * want + 1e-3, "block {got} vs Mitsuba {want}; blocks {blocks:?}");
        }
    }
}

/// A reconstruction filter blurs an edge as it should: the left half of the view is an emitter of radiance
/// 1 (noiseless: every sample sees 1 or 0), so a pixel column at distance δ from the edge develops to the
/// lit share of the filter's weight, ∫_lit w(x) dx / ∫ w(x) dx, computed here by quadrature from the
/// filter itself. The box filter leaves the edge sharp.
#[test]
fn filters_blur_an_edge_by_their_weights() {
    for (rfilter, filter) in [
        (r#"<rfilter type="gaussian"/>"#, gonio::film::Filter::gaussian(0.5)),
        ("", gonio::film::Filter::gaussian(0.5)), // Mitsuba's default
        (r#"<rfilter type="tent"><float name="radius" value="1.5"/></rfilter>"#, gonio::film::Filter::tent(1.5)),
        (r#"<rfilter type="box"/>"#, gonio::film::Filter::BOX),
    ] {
        let (w, h) = (16u32, 8u32);
        let s = scene(&format!(
            r#"<scene version="3.0.0"><integrator type="direct"/>
            <sensor type="perspective"><float name="fov" value="30"/>
                <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
                <film type="hdrfilm"><integer name="width" value="{w}"/><integer name="height" value="{h}"/>{rfilter}</film></sensor>
            <shape type="rectangle"><transform name="to_world"><scale value="100"/><translate x="-100"/></transform>
                <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape></scene>"#
        ));
        assert_eq!(s.film.filter, filter, "{rfilter}");
        let img = run(&s);
        let column = |c: u32| (0..h).map(|y| f64::from(img.data[3 * (y * w + c) as usize])).sum::<f64>() / f64::from(h);
        // Camera +x is the image's left; world −x is lit, which is the image's right half here.
        let lit_right = column(w - 1) > 0.5;
        for c in 0..w {
            // Distance of the column's centre from the edge (the image's centre line), positive on the lit side.
            let delta = (f64::from(c) + 0.5 - f64::from(w) / 2.0) * if lit_right { 1.0 } else { -1.0 };
            // The lit share of the filter's weight around this centre: samples at x lit where x > 0 (edge
            // at 0), weighted by w(centre − x).
            let (mut lit, mut all) = (0.0, 0.0);
            let r = f64::from(filter.radius());
            let n = 4000;
            for i in 0..n {
                let x = delta - r + 2.0 * r * (f64::from(i) + 0.5) / f64::from(n);
                let wgt = f64::from(filter.eval((delta - x) as f32));
                all += wgt;
                if x > 0.0 {
                    lit += wgt;
                }
            }
            let want = lit / all;
            assert!((column(c) - want).abs() < 0.02, "{rfilter}: column {c}: {} vs {want}", column(c));
        }
    }
}

/// Spheres of radius 0.5 with the models `bsdfs` (`<bsdf>` elements), `per_row` to a row 1.1 apart, the
/// rows 1.1 apart, centred on x = 0 and y = 0 for two rows, at z = 0.
fn spheres_in_rows(bsdfs: &[impl AsRef<str>], per_row: usize) -> String {
    let left = (per_row - 1) as f32 * 0.55;
    bsdfs
        .iter()
        .enumerate()
        .map(|(i, bsdf)| {
            let (x, y) = ((i % per_row) as f32 * 1.1 - left, (i / per_row) as f32 * 1.1 - 0.55);
            format!(
                r#"<shape type="sphere"><point name="center" x="{x}" y="{y}" z="0"/><float name="radius" value="0.5"/>{}</shape>"#,
                bsdf.as_ref()
            )
        })
        .collect()
}

/// `direct` renders through the path tracer's packets at max_depth 2 (`integrator::radiance`), with any
/// numbers of light and BSDF samples; the scalar `direct` integrator (`integrator::direct_each`) is its
/// reference: every camera sample's radiance the same bit for bit, over every light type, smooth, glossy,
/// delta and layered models, composites, textures, with and without `hide_emitters`, with one sample of
/// each, several of either, and none of either. A difference in the estimator, its MIS weights (with the
/// sample counts) or the order of its random numbers fails here.
#[test]
fn direct_is_the_path_tracer_at_depth_two() {
    use gonio::integrator::{direct_each, radiance, CameraSample};
    let spheres = [
        r#"<bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf>"#,
        r#"<bsdf type="roughplastic"><float name="alpha" value="0.3"/></bsdf>"#,
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.2"/></bsdf>"#,
        r#"<bsdf type="dielectric"/>"#,
        r#"<bsdf type="thindielectric"/>"#,
        r#"<bsdf type="plastic"/>"#,
        r#"<bsdf type="conductor"><string name="material" value="Au"/></bsdf>"#,
        r#"<bsdf type="roughconductor"><float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.4"/></bsdf>"#,
        r#"<bsdf type="twosided"><bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"/><bsdf type="roughconductor"/></bsdf></bsdf>"#,
        r#"<bsdf type="mask"><float name="opacity" value="0.5"/><bsdf type="oren_nayar"/></bsdf>"#,
    ];
    let shapes = spheres_in_rows(&spheres, 5);
    // A mesh light from a file whose flat vertex normals oppose its winding: it emits on their side, in
    // lanes as for one ray.
    let obj = std::env::temp_dir().join(format!("gonio-test-direct-{}.obj", std::process::id()));
    std::fs::write(&obj, "v -0.4 -0.4 2\nv 0.4 -0.4 2\nv 0.4 0.4 2\nv -0.4 0.4 2\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n")
        .unwrap();
    let obj_light = format!(
        r#"<shape type="obj"><string name="filename" value="{}"/><emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>"#,
        obj.display()
    );
    let counts = [(1, 1, false), (1, 1, true), (4, 0, false), (2, 3, true), (0, 2, false), (3, 1, false), (1, 0, true), (0, 0, false)];
    for (ne, nb, hide) in counts {
        let xml = format!(
            r#"<scene version="3.0.0"><integrator type="direct"><boolean name="hide_emitters" value="{hide}"/>
                <integer name="emitter_samples" value="{ne}"/><integer name="bsdf_samples" value="{nb}"/></integrator>{sensor}
            {shapes}{obj_light}
            <shape type="rectangle"><transform name="to_world"><scale value="10"/><translate z="-1"/></transform>
                <bsdf type="roughplastic"><string name="distribution" value="ggx"/></bsdf></shape>
            <shape type="rectangle"><transform name="to_world"><scale x="0.5" y="0.3"/><rotate x="1" angle="160"/><translate y="2" z="1"/></transform>
                <emitter type="area"><rgb name="radiance" value="4, 3, 2"/></emitter></shape>
            <shape type="sphere"><point name="center" x="2" y="2" z="1.5"/><float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
            <emitter type="point"><point name="position" x="-2" y="1" z="2"/><rgb name="intensity" value="3"/></emitter>
            <emitter type="spot"><transform name="to_world"><lookat origin="0, -2, 3" target="0, 0, 0"/></transform><rgb name="intensity" value="8"/></emitter>
            <emitter type="directional"><vector name="direction" x="0.3" y="-0.2" z="-1"/><rgb name="irradiance" value="0.5"/></emitter>
            <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter></scene>"#,
            sensor = sensor(7.0, 60.0, 24, 4)
        );
        let s = scene(&xml);
        let samples: Vec<CameraSample> =
            (0..24).flat_map(|y| (0..24).flat_map(move |x| (0..4).map(move |k| CameraSample { x, y, k }))).collect();
        let (mut packets, mut each) = (vec![gonio::spectrum::Rgb::ZERO; samples.len()], vec![gonio::spectrum::Rgb::ZERO; samples.len()]);
        radiance(&s, 7, &samples, &mut packets);
        direct_each(&s, 7, &samples, &mut each, ne, nb, hide);
        let differ = packets.iter().zip(&each).filter(|(a, b)| a.0.map(f32::to_bits) != b.0.map(f32::to_bits)).count();
        let lit = each.iter().filter(|l| l.0.iter().any(|&v| v > 0.0)).count();
        let case = format!("emitter_samples {ne}, bsdf_samples {nb}, hide_emitters {hide}");
        // With samples, the lights light most camera samples; without, only the emitters seen are lit.
        let least = if ne + nb > 0 { samples.len() / 2 } else { 1 };
        assert!(lit >= least, "{case}: the scene is lit ({lit} of {} samples)", samples.len());
        assert_eq!(differ, 0, "{case}: {differ} of {} samples differ", samples.len());
    }
    std::fs::remove_file(&obj).unwrap();
}

/// A textured material whose textures only tint its model (a conductor's `specular_reflectance`, a
/// dielectric's `specular_reflectance` and `specular_transmittance`, also inside a `twosided`) or set its
/// roughness (`alpha`, `alpha_u`, `alpha_v` of the rough conductors and dielectric, GGX and Beckmann) or
/// base colour (`plastic`, `roughplastic`, `principled`) runs one model — or one kernel with each lane's value — for all its
/// lanes in the packets and scales
/// each lane's values by its texels (`Material::lanes_at`). The scalar `direct` integrator, which builds
/// each hit's model with the texel written into it, is its reference: every camera sample's radiance the
/// same to rounding (the model multiplies its tint in its own order, so not bit for bit), with paths
/// through both lobes of the dielectrics, through a tinted material seen through another, and texels out
/// of range (a roughness of 0, clamped to 10⁻⁴; a reflectance above 1), clamped alike in both.
#[test]
fn tinted_and_per_lane_textures_in_packets_are_the_textured_models() {
    use gonio::integrator::{direct_each, radiance, CameraSample};
    let checker = |name: &str, c0: &str, c1: &str| {
        format!(
            r#"<texture type="checkerboard" name="{name}"><rgb name="color0" value="{c0}"/><rgb name="color1" value="{c1}"/>
               <transform name="to_uv"><scale x="6" y="4"/></transform></texture>"#
        )
    };
    let spheres = [
        format!(
            r#"<bsdf type="conductor"><string name="material" value="Au"/>{}</bsdf>"#,
            checker("specular_reflectance", "0.9, 0.2, 0.4", "0.1, 0.8, 1")
        ),
        format!(r#"<bsdf type="roughconductor">{}</bsdf>"#, checker("specular_reflectance", "1, 0.5, 0.2", "0.3, 0.3, 0.9")),
        format!(
            r#"<bsdf type="dielectric">{}{}</bsdf>"#,
            checker("specular_reflectance", "0.5, 1, 0.5", "1, 1, 1"),
            checker("specular_transmittance", "1, 0.4, 0.4", "0.6, 0.8, 1")
        ),
        format!(r#"<bsdf type="thindielectric">{}</bsdf>"#, checker("specular_transmittance", "0.2, 0.9, 0.9", "1, 1, 0.3")),
        format!(
            r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.2"/>{}</bsdf>"#,
            checker("specular_transmittance", "1, 0.6, 0.6", "0.6, 0.8, 1")
        ),
        format!(
            r#"<bsdf type="twosided"><bsdf type="roughconductor"><float name="alpha" value="0.3"/>{}</bsdf></bsdf>"#,
            checker("specular_reflectance", "0.9, 0.9, 0.2", "0.2, 0.5, 0.9")
        ),
        format!(r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/>{}</bsdf>"#, checker("alpha", "0.05", "0.5")),
        format!(
            r#"<bsdf type="roughconductor"><float name="alpha_v" value="0.3"/>{}{}</bsdf>"#,
            checker("alpha_u", "0.02", "0.6"),
            checker("specular_reflectance", "1, 0.5, 0.2", "0.3, 0.3, 0.9")
        ),
        format!(r#"<bsdf type="roughdielectric">{}</bsdf>"#, checker("alpha", "0", "0.3")),
        format!(
            r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>{}{}</bsdf>"#,
            checker("alpha_u", "0.1", "0.5"),
            checker("alpha_v", "0.4", "0.05")
        ),
        format!(r#"<bsdf type="roughplastic">{}</bsdf>"#, checker("diffuse_reflectance", "0.9, 0.1, 0.3", "1.5, 0.6, 0")),
        format!(
            r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/><boolean name="nonlinear" value="true"/>{}</bsdf>"#,
            checker("diffuse_reflectance", "0.2, 0.7, 0.9", "0.8, 0.8, 0.1")
        ),
        format!(r#"<bsdf type="plastic">{}</bsdf>"#, checker("diffuse_reflectance", "0.1, 0.5, 0.9", "0.9, 0.5, 0.1")),
        format!(
            r#"<bsdf type="principled"><float name="metallic" value="0.3"/><float name="spec_trans" value="0.4"/><float name="clearcoat" value="0.5"/>{}</bsdf>"#,
            checker("base_color", "0.9, 0.3, 0.1", "0.1, 0.6, 0.8")
        ),
    ];
    let shapes = spheres_in_rows(&spheres, 4);
    let xml = format!(
        r#"<scene version="3.0.0"><integrator type="direct"><integer name="emitter_samples" value="2"/><integer name="bsdf_samples" value="2"/></integrator>{sensor}
        {shapes}
        <shape type="rectangle"><transform name="to_world"><scale value="10"/><translate z="-1"/></transform>
            <bsdf type="diffuse">{floor}</bsdf></shape>
        <shape type="sphere"><point name="center" x="2" y="2" z="1.5"/><float name="radius" value="0.3"/>
            <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
        <emitter type="point"><point name="position" x="-2" y="1" z="2"/><rgb name="intensity" value="3"/></emitter>
        <emitter type="constant"><rgb name="radiance" value="0.3"/></emitter></scene>"#,
        sensor = sensor(6.0, 60.0, 32, 4),
        floor = checker("reflectance", "0.8, 0.8, 0.8", "0.2, 0.2, 0.2"),
    );
    let s = scene(&xml);
    let half = gonio::math::simd::Float8::splat(0.5);
    let in_lanes: Vec<_> = s.materials.iter().filter_map(|m| m.lanes_at(half, half, 1)).collect();
    assert_eq!(in_lanes.len(), spheres.len(), "every sphere's material is in the lane form");
    assert_eq!(
        in_lanes.iter().filter(|m| m.kernel.is_some()).count(),
        8,
        "the rough ones, the plastics and the principled with a parameter per lane"
    );
    let samples: Vec<CameraSample> =
        (0..32).flat_map(|y| (0..32).flat_map(move |x| (0..4).map(move |k| CameraSample { x, y, k }))).collect();
    let (mut packets, mut each) = (vec![gonio::spectrum::Rgb::ZERO; samples.len()], vec![gonio::spectrum::Rgb::ZERO; samples.len()]);
    radiance(&s, 5, &samples, &mut packets);
    direct_each(&s, 5, &samples, &mut each, 2, 2, false);
    let mut lit = 0;
    for (i, (a, b)) in packets.iter().zip(&each).enumerate() {
        for c in 0..3 {
            let (a, b) = (a.0[c], b.0[c]);
            assert!((a - b).abs() <= 1e-5 * b.abs() + 1e-7, "sample {:?}, channel {c}: packets {a}, single {b}", samples[i]);
        }
        lit += usize::from(b.0.iter().any(|&v| v > 0.0));
    }
    assert!(lit > samples.len() / 2, "the scene is lit ({lit} of {} samples)", samples.len());
}

/// A glass whose index equals its surroundings' bends and reflects nothing, so a scene with index-matched
/// `thindielectric` and `dielectric` spheres is the scene without them. Not trivially: a shadow ray stops at
/// glass, so the wall in the spheres' shadow is lit only by BSDF-sampled paths through two delta
/// transmissions each (weight 1 at the light, the last lobe being delta), and the spheres are seen through
/// by the same delta lobes; everywhere else light sampling and BSDF sampling share the work by MIS. Any
/// error in the delta lobes' weights or in the MIS weights after them shifts the mean of the difference.
#[test]
fn index_matched_glass_is_invisible() {
    let scene_with = |spheres: &str| {
        scene(&format!(
            r#"<scene version="3.0.0"><integrator type="path"><integer name="max_depth" value="8"/></integrator>
            <sensor type="orthographic">
                <transform name="to_world"><scale x="2.5" y="2.5"/><lookat origin="0, 0, 10" target="0, 0, 0" up="0, 1, 0"/></transform>
                <sampler type="independent"><integer name="sample_count" value="512"/></sampler>
                <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film></sensor>
            <shape type="rectangle"><transform name="to_world"><scale value="8"/><translate z="-2"/></transform>
                <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
            {spheres}
            <shape type="disk"><transform name="to_world"><scale value="0.6"/><lookat origin="3, 4, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape></scene>"#
        ))
    };
    let glass = r#"<shape type="sphere"><point name="center" x="-1.2" y="0" z="0"/><float name="radius" value="1"/>
            <bsdf type="thindielectric"><float name="int_ior" value="1.5"/><float name="ext_ior" value="1.5"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="1.2" y="0" z="0"/><float name="radius" value="1"/>
            <bsdf type="dielectric"><float name="int_ior" value="1.33"/><float name="ext_ior" value="1.33"/></bsdf></shape>"#;
    let (with, without) = (run(&scene_with(glass)), run(&scene_with("")));
    // Each pixel's difference is an independent sample: its mean must be 0 within 5 standard errors. (A
    // weight that is not 1 after the delta lobes moves it by 25 standard errors.)
    for c in 0..3 {
        let d: Vec<f64> = with.data.iter().zip(&without.data).skip(c).step_by(3).map(|(a, b)| f64::from(a - b)).collect();
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let se = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        let (level, _) = mean_and_se(&without, c);
        assert!(mean.abs() <= 5.0 * se, "channel {c}: with − without = {mean} ± {se} (image mean {level})");
    }
}
