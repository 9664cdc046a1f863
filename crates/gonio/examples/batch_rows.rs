//! Run by hand under callgrind, to count the instructions per row of the batch methods (repeatable on a
//! loaded machine, unlike wall time):
//!
//! ```text
//! cargo build --release -p gonio --example batch_rows
//! valgrind --tool=callgrind --toggle-collect='*BsdfModel*_batch*' target/release/examples/batch_rows MODEL METHOD [N]
//! ```
//!
//! MODEL is `diffuse`, `roughconductor` or `roughplastic` (the models of bench/python_bsdf_vs_mitsuba.py),
//! METHOD `f`, `pdf` or `sample`; N rows (default 100 000) of random directions above the surface, one
//! thread, one call of `Bsdf::f_batch` (or `pdf_batch`, `sample_batch`). Instructions per row = the
//! collected total / N.
//!
//! Instructions per row (2026-11, AVX2 build, 10⁵ rows), first with the kernels' loops compiled for the
//! baseline target (what `simd_batch!` did before it was fixed), then for AVX2 + FMA:
//!
//! | model (GGX α = 0.3)   | f        | pdf     | sample    |
//! |-----------------------|----------|---------|-----------|
//! | diffuse               | 7 → 8    | 6 → 5   | 119 → 72  |
//! | roughconductor (Au)   | 189 → 54 | 45 → 26 | 425 → 158 |
//! | roughplastic          | 226 → 198| 92 → 57 | 562 → 245 |
//!
//! roughplastic's `f` spends most of its instructions in the per-lane lookup of the transmittance table.

use gonio::bsdf::{Bsdf, BsdfModel, SampleColumns};
use gonio::math::{Vec2, Vec3};
use gonio::sampling::Pcg32;
use gonio::Rgb;
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let model = args.get(1).map_or("roughconductor", String::as_str);
    let method = args.get(2).map_or("f", String::as_str);
    let n: usize = args.get(3).and_then(|v| v.parse().ok()).unwrap_or(100_000);
    let spec = match model {
        "diffuse" => r#"{"type": "diffuse", "reflectance": [0.2, 0.5, 0.8]}"#,
        "roughconductor" => r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "Au"}"#,
        "roughplastic" => r#"{"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": [0.2, 0.5, 0.8]}"#,
        other => panic!("unknown model {other}: diffuse, roughconductor or roughplastic"),
    };
    let bsdf = Bsdf::from_json(spec).expect("a valid spec");
    let mut rng = Pcg32::new(1, 0);
    let mut dir = || {
        let v = Vec3::new(2.0 * rng.next_f32() - 1.0, 2.0 * rng.next_f32() - 1.0, rng.next_f32() + 1e-3);
        v.normalize()
    };
    let wo: Vec<Vec3> = (0..n).map(|_| dir()).collect();
    let wi: Vec<Vec3> = (0..n).map(|_| dir()).collect();
    let mut rng = Pcg32::new(2, 0);
    let uc: Vec<f32> = (0..n).map(|_| rng.next_f32()).collect();
    let u: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect();
    match method {
        "f" => {
            let mut out = vec![Rgb::ZERO; n];
            bsdf.f_batch(&wo, &wi, &mut out);
            black_box(&out);
        }
        "pdf" => {
            let mut out = vec![0.0; n];
            bsdf.pdf_batch(&wo, &wi, &mut out);
            black_box(&out);
        }
        "sample" => {
            let (mut wi_s, mut f, mut pdf, mut weight) = (vec![Vec3::ZERO; n], vec![Rgb::ZERO; n], vec![0.0; n], vec![Rgb::ZERO; n]);
            let (mut flags, mut eta, mut valid) = (vec![0; n], vec![0.0; n], vec![false; n]);
            let mut columns = SampleColumns {
                wi: &mut wi_s,
                f: &mut f,
                pdf: &mut pdf,
                weight: &mut weight,
                flags: &mut flags,
                eta: &mut eta,
                valid: &mut valid,
            };
            bsdf.sample_batch(&wo, &uc, &u, &mut columns);
            black_box(&valid);
        }
        other => panic!("unknown method {other}: f, pdf or sample"),
    }
}
