//! BVH construction and traversal (criterion). Run with `make bench`; bench/render_vs_mitsuba.py has the
//! whole-render timings and the scaling tables.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gonio::geometry::{Bounds3, Bvh, Ray};
use gonio::math::Vec3;
use gonio::sampling::warp::sample_uniform_sphere;
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

criterion_group!(benches, bench_build, bench_traversal);
criterion_main!(benches);
