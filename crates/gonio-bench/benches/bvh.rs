//! BVH construction and traversal (criterion). Run with `make bench`; bench/render_vs_mitsuba.py has the
//! whole-render timings and the scaling tables.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gonio::geometry::ray::{spawn_ray, RayLanes};
use gonio::geometry::{Bounds3, Bvh, Ray};
use gonio::math::simd::Float8;
use gonio::math::{Frame, Vec2, Vec3};
use gonio::sampling::warp::{sample_cosine_hemisphere, sample_uniform_sphere};
use gonio::sampling::Pcg32;
use gonio::scene::Scene;
use std::path::Path;

fn random_boxes(n: usize) -> Vec<Bounds3> {
    let mut rng = Pcg32::new(1, 1);
    (0..n)
        .map(|_| {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 100.0;
            Bounds3 { min: c, max: c + Vec3::splat(0.5 * rng.next_f32()) }
        })
        .collect()
}

fn bench_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("bvh build");
    group.sample_size(10);
    for n in [1_000, 100_000] {
        let boxes = random_boxes(n);
        group.bench_function(format!("{n} boxes"), |b| b.iter(|| Bvh::build(black_box(&boxes))));
    }
    group.finish();
}

/// Closest-hit and shadow queries on the Cornell box, from random points inside it in random directions.
fn bench_traversal(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/cornell-box.xml");
    let Ok(scene) = Scene::load(&path, &[]) else {
        eprintln!("bvh traversal: {} not found, skipped", path.display());
        return;
    };
    let mut rng = Pcg32::new(2, 3);
    let rays: Vec<Ray> = (0..4096)
        .map(|_| {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1.6 - Vec3::splat(0.8);
            Ray::new(o, sample_uniform_sphere(rng.next_vec2()), f32::INFINITY)
        })
        .collect();
    let mut group = c.benchmark_group("cornell box");
    group.bench_function("closest hit × 4096", |b| b.iter(|| rays.iter().filter(|r| scene.intersect(r).is_some()).count()));
    let shadow: Vec<Ray> = rays.iter().map(|r| Ray::new(r.o, r.d, 0.5)).collect();
    group.bench_function("occluded × 4096", |b| b.iter(|| shadow.iter().filter(|r| scene.occluded(r)).count()));
    group.finish();
}

/// Shadow rays in lanes, and the lanes that hold one.
type ShadowPacket = (RayLanes<Float8>, u32);

/// The packets a path tracer traces, as the renderer forms them: eight lanes, each following its own path
/// (camera samples eight per pixel, the pixels at random, then cosine-distributed bounces off every surface, at
/// most four, with a shadow ray towards a light sample at each hit); a lane whose path ends takes the next
/// camera sample. Returns the closest-hit packets and the shadow packets with the lanes that hold a ray.
fn path_packets(scene: &Scene, packets: usize) -> (Vec<RayLanes<Float8>>, Vec<ShadowPacket>) {
    const SPP: u32 = 8;
    const MAX_BOUNCES: u32 = 4;
    let (width, height) = (scene.film.width, scene.film.height);
    let mut rng = Pcg32::new(5, 11);
    let (mut sample, mut pixel) = (0u32, Vec2::ZERO);
    let mut camera = |rng: &mut Pcg32| {
        if sample % SPP == 0 {
            pixel = (rng.next_vec2() * Vec2::new(width as f32, height as f32)).floor();
        }
        sample += 1;
        (scene.camera.ray((pixel + rng.next_vec2()) / Vec2::new(width as f32, height as f32)), 0u32)
    };
    let mut lanes: [(Ray, u32); 8] = std::array::from_fn(|_| camera(&mut rng));
    let (mut closest, mut shadow) = (Vec::with_capacity(packets), Vec::with_capacity(packets));
    while closest.len() < packets {
        closest.push(RayLanes::from_rays(&lanes.map(|(r, _)| r)));
        let (mut shadows, mut tested) = ([Ray::new(Vec3::ZERO, Vec3::Z, 0.0); 8], 0u32);
        for (lane, (ray, depth)) in lanes.iter_mut().enumerate() {
            let Some(si) = scene.intersect(ray).filter(|_| *depth < MAX_BOUNCES) else {
                (*ray, *depth) = camera(&mut rng);
                continue;
            };
            let n = if si.n.dot(ray.d) < 0.0 { si.n } else { -si.n };
            let light = &scene.lights[(rng.next_f32() * scene.lights.len() as f32) as usize % scene.lights.len()];
            if let Some(ls) = light.sample_li(&scene.shapes, si.p, n, rng.next_f32(), rng.next_vec2()) {
                (shadows[lane], tested) = (ls.shadow, tested | 1 << lane);
            }
            let wi = Frame::from_normal(n).to_world(sample_cosine_hemisphere(rng.next_vec2()));
            (*ray, *depth) = (spawn_ray(si.p, n, wi), *depth + 1);
        }
        if tested != 0 {
            shadow.push((RayLanes::from_rays(&shadows), tested));
        }
    }
    (closest, shadow)
}

/// Packet traversal ([`Scene::intersect_rays`], [`Scene::occluded_rays`]) on the packets of a path tracer
/// ([`path_packets`]): mostly incoherent rays after the first bounce.
fn bench_packets(c: &mut Criterion) {
    // Two scenes of ../shared/scenes, and the suite's matpreview (Mitsuba's material preview: a mesh of
    // 61,600 triangles under an environment map, a deeper tree).
    for (name, file) in [
        ("cornell-box", "../../../shared/scenes/cornell-box.xml"),
        ("material-spheres", "../../../shared/scenes/material-spheres.xml"),
        ("matpreview", "../../bench/scenes/matpreview.xml"),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let Ok(scene) = Scene::load(&path, &[]) else {
            eprintln!("bvh packets: {} not found, skipped", path.display());
            continue;
        };
        let (closest, shadow) = path_packets(&scene, 4096);
        let mut group = c.benchmark_group(format!("{name} packets"));
        group.bench_function("closest hit × 4096 packets", |b| {
            b.iter(|| closest.iter().map(|r| scene.intersect_rays(r, 0xff).slot.iter().map(|&s| s as u64).sum::<u64>()).sum::<u64>())
        });
        group.bench_function(format!("occluded × {} packets", shadow.len()), |b| {
            b.iter(|| shadow.iter().map(|(r, lanes)| scene.occluded_rays(r, *lanes).count_ones()).sum::<u32>())
        });
        group.finish();
    }
}

criterion_group!(benches, bench_build, bench_traversal, bench_packets);
criterion_main!(benches);
