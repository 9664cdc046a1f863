//! The `thinlens` sensor against the thin-lens model: a point on the focal plane is seen through the whole
//! lens from one film position; a point at another depth z from a disk of film positions whose diameter
//! on the plane z = 1 is the circle of confusion 2 A |z − f| / (z f); rays in lanes equal the scalar ones;
//! bad parameters are errors with their place.

use gonio::camera::Camera;
use gonio::math::simd::Float8;
use gonio::math::{Transform, Vec2, Vec3};
use gonio::props::Props;
use gonio::sampling::warp::sample_uniform_disk_concentric;
use gonio::sampling::Pcg32;
use gonio::scene::{mitsuba_xml, Scene};
use std::path::Path;

const W: u32 = 96;
const H: u32 = 64;
const FOV: f32 = 40.0;
const APERTURE: f32 = 0.2;
const FOCUS: f32 = 5.9;

fn look() -> Transform {
    Transform::look_at(Vec3::new(3.7, -3.5, 3.3), Vec3::new(0.0, 0.0, 0.5), Vec3::new(-0.3, 0.3, 0.9)).unwrap()
}

fn camera() -> Camera {
    Camera::new(look(), FOV, "x", W, H, 0.01, 1e4, "test").unwrap().with_thin_lens(APERTURE, FOCUS)
}

/// tan of half the field of view, across and down.
fn tan_half() -> Vec2 {
    let t = (FOV.to_radians() / 2.0).tan();
    Vec2::new(t, t * H as f32 / W as f32)
}

/// The film position whose pinhole direction is camera-space (x, y, 1) (the module doc's mapping inverted).
fn film_position(local: Vec2) -> Vec2 {
    (Vec2::ONE - local / tan_half()) * 0.5
}

/// The distance from world point `p` to the ray's line.
fn miss_distance(o: Vec3, d: Vec3, p: Vec3) -> f32 {
    (p - o).cross(d).length()
}

/// A point on the focal plane: every lens sample's ray from its film position passes through it, so it
/// lands in one pixel; a point at depth z: the film positions that see it through lens point a lie on a
/// disk of radius A |z − f| / (z f) on the plane z = 1, and the camera's ray from each passes through it.
#[test]
fn focal_plane_is_sharp_and_other_depths_blur_to_the_circle_of_confusion() {
    let cam = camera();
    let mut rng = Pcg32::new(30, 1);
    for (qx, qy) in [(0.0f32, 0.0f32), (0.6, -0.3), (-1.1, 0.4)] {
        for z in [FOCUS, 2.0, 4.0, 9.0, 30.0] {
            let q_cam = Vec3::new(qx, qy, z);
            let q = look().point(q_cam);
            let centre = Vec2::new(qx, qy) / z;
            let coc = APERTURE * (z - FOCUS).abs() / (z * FOCUS);
            let mut widest = 0.0f32;
            for _ in 0..4000 {
                let u = rng.next_vec2();
                let a = sample_uniform_disk_concentric(u) * APERTURE;
                // The line from lens point a through Q meets the focal plane at a + (Q − a) f / z.
                let on_focal = Vec2::new(a.x, a.y) + (Vec2::new(qx, qy) - a) * (FOCUS / z);
                let local = on_focal / FOCUS;
                let ray = cam.ray_through_lens(film_position(local), u);
                let tol = 2e-5 * q_cam.length().max(FOCUS);
                assert!(miss_distance(ray.o, ray.d, q) < tol, "z {z}: the ray misses Q by {}", miss_distance(ray.o, ray.d, q));
                // The ray starts at camera depth near_clip.
                let start = look().inverse().point(ray.o);
                assert!((start.z - 0.01).abs() < 1e-5 && (ray.d.length() - 1.0).abs() < 1e-5);
                let r = (local - centre).length();
                assert!(r <= coc * (1.0 + 1e-3) + 1e-6, "z {z}: film offset {r} beyond the circle of confusion {coc}");
                widest = widest.max(r);
            }
            if z == FOCUS {
                assert!(widest < 1e-6, "in focus: one film position, got a spread of {widest}");
            } else {
                // 4000 uniform lens points reach the rim to within about a thousandth of the radius.
                assert!(widest > coc * 0.99, "z {z}: the widest offset {widest} falls short of the circle of confusion {coc}");
                let pixel = 2.0 * tan_half().x / W as f32;
                if z == 2.0 {
                    assert!(coc > 2.0 * pixel, "the near point blurs over pixels ({coc} vs {pixel})");
                }
            }
        }
    }
}

/// The rays in eight lanes are the scalar rays, bit for bit; aperture 0 is the pinhole's ray.
#[test]
fn rays_in_lanes_match_and_aperture_zero_is_a_pinhole() {
    let cam = camera();
    let mut rng = Pcg32::new(2, 2);
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    for _ in 0..200 {
        let s: [Vec2; 8] = std::array::from_fn(|_| rng.next_vec2());
        let u: [Vec2; 8] = std::array::from_fn(|_| rng.next_vec2());
        let f = |g: &dyn Fn(usize) -> f32| Float8::from_fn(g);
        let lanes = cam.rays_through_lens(f(&|i| s[i].x), f(&|i| s[i].y), f(&|i| u[i].x), f(&|i| u[i].y));
        for i in 0..8 {
            let one = cam.ray_through_lens(s[i], u[i]);
            let lane = |v: &gonio::math::lanes::V3<Float8>| Vec3::new(v.x.lane(i), v.y.lane(i), v.z.lane(i));
            assert_eq!(
                (bits(lane(&lanes.o)), bits(lane(&lanes.d)), lanes.tmax.lane(i).to_bits()),
                (bits(one.o), bits(one.d), one.tmax.to_bits())
            );
        }
    }
    let pinhole = Camera::new(look(), FOV, "x", W, H, 0.01, 1e4, "test").unwrap();
    let closed = pinhole.clone().with_thin_lens(0.0, FOCUS);
    assert!(!closed.has_lens() && camera().has_lens());
    for _ in 0..100 {
        let (s, u) = (rng.next_vec2(), rng.next_vec2());
        assert_eq!(closed.ray_through_lens(s, u), pinhole.ray(s));
    }
}

fn error(sensor: &str) -> String {
    let xml = format!("<scene version=\"3.0.0\">\n{sensor}\n<shape type=\"sphere\"/>\n</scene>",);
    match mitsuba_xml::load_str(&xml, "lens.xml", Path::new("."), &[]).and_then(Scene::build) {
        Ok(_) => panic!("{sensor}: loads"),
        Err(e) => e.to_string(),
    }
}

/// `thinlens` reads `perspective`'s parameters and its own; a negative or missing aperture, a focus
/// distance ≤ 0 and a scaling `to_world` are errors naming the place.
#[test]
fn parameters_and_errors() {
    let film = r#"<film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film>"#;
    let e = error(&format!(r#"<sensor type="thinlens"><float name="aperture_radius" value="-0.1"/>{film}</sensor>"#));
    assert!(e.contains("lens.xml:2:") && e.contains("`aperture_radius` of `thinlens`") && e.contains("-0.1"), "{e}");
    let e = error(&format!(r#"<sensor type="thinlens"><float name="fov" value="30"/>{film}</sensor>"#));
    assert!(e.contains("lens.xml:2:1") && e.contains("needs an `aperture_radius`"), "{e}");
    let e = error(&format!(
        r#"<sensor type="thinlens"><float name="aperture_radius" value="0.1"/><float name="focus_distance" value="0"/>{film}</sensor>"#
    ));
    assert!(e.contains("lens.xml:2:") && e.contains("`focus_distance` of `thinlens`"), "{e}");
    let e = error(&format!(
        r#"<sensor type="thinlens"><float name="aperture_radius" value="0.1"/><transform name="to_world"><scale value="2"/></transform>{film}</sensor>"#
    ));
    assert!(e.contains("lens.xml:2:") && e.contains("must not scale"), "{e}");
    // The defaults: focus at far_clip; fov and fov_axis as `perspective`.
    let p =
        Props::from_json(r#"{"type": "thinlens", "aperture_radius": 0.05, "fov": 28.8, "fov_axis": "smaller", "far_clip": 100}"#).unwrap();
    let cam = Camera::from_props(&p, 96, 72).unwrap();
    p.finish().unwrap();
    let want = Camera::new(Transform::IDENTITY, 28.8, "smaller", 96, 72, 0.01, 100.0, "t").unwrap().with_thin_lens(0.05, 100.0);
    assert_eq!(cam, want);
}
