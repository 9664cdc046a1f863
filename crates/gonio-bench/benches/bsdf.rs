//! Throughput of f, pdf and sample for every example model, one call at a time, and of the batch methods
//! behind the Python package's `f`, `pdf` and `sample` for the models of bench/python_bsdf_vs_mitsuba.py
//! (one thread, 16 384 rows: in cache, so that the kernels' arithmetic is what is timed). Run with
//! `make bench`.

use criterion::Throughput;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use gonio::bsdf::{Bsdf, BsdfModel, SampleBuffers};
use gonio::math::{Vec2, Vec3};
use gonio::sampling::Pcg32;
use gonio::Rgb;

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

fn bench_batches(c: &mut Criterion) {
    const N: usize = 16_384;
    let mut rng = Pcg32::new(1, 0);
    let mut dir = || Vec3::new(2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0, rng.next_f32() + 1e-3).normalize();
    let wo: Vec<Vec3> = (0..N).map(|_| dir()).collect();
    let wi: Vec<Vec3> = (0..N).map(|_| dir()).collect();
    let mut rng = Pcg32::new(2, 0);
    let uc: Vec<f32> = (0..N).map(|_| rng.next_f32()).collect();
    let u: Vec<Vec2> = (0..N).map(|_| rng.next_vec2()).collect();
    let mut group = c.benchmark_group("batch");
    group.throughput(Throughput::Elements(N as u64));
    for (name, spec) in [
        ("diffuse", r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#),
        ("roughconductor", r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Au"}"#),
        ("roughplastic", r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": [0.2, 0.5, 0.8]}"#),
    ] {
        let bsdf = Bsdf::from_json(spec).unwrap();
        let mut f = vec![Rgb::ZERO; N];
        let mut pdf = vec![0.0f32; N];
        group.bench_function(format!("f {name}"), |b| b.iter(|| bsdf.f_batch(black_box(&wo), black_box(&wi), &mut f)));
        group.bench_function(format!("pdf {name}"), |b| b.iter(|| bsdf.pdf_batch(black_box(&wo), black_box(&wi), &mut pdf)));
        let mut rows = SampleBuffers::new(N);
        group.bench_function(format!("sample {name}"), |b| {
            b.iter(|| bsdf.sample_batch(black_box(&wo), black_box(&uc), black_box(&u), &mut rows.columns()));
        });
    }
    group.finish();
}

criterion_group!(benches, bench_models, bench_batches);
criterion_main!(benches);
