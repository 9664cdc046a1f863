//! Run by hand under callgrind, to count the instructions per row of the batch methods (repeatable on a
//! loaded machine, unlike wall time):
//!
//! ```text
//! cargo build --release -p gonio --example batch_rows
//! valgrind --tool=callgrind --toggle-collect='*_batch::with_avx2' target/release/examples/batch_rows MODEL METHOD [N]
//! ```
//!
//! MODEL is `diffuse`, `roughconductor` or `roughplastic` (the models of bench/python_bsdf_vs_mitsuba.py),
//! METHOD `f`, `pdf` or `sample`; N rows (default 100 000) of random directions above the surface, one
//! thread, one call of `Bsdf::f_batch` (or `pdf_batch`, `sample_batch`). Instructions per row = the
//! collected total / N. (Only `Bsdf`'s own AVX2 function may be named in `--toggle-collect`: a pattern that
//! also matches a function it calls, such as the drivers' `f_rows::with_avx2`, switches collection off
//! there again.) Valgrind (3.19) does not run AVX-512: under it the drivers take their AVX2 path, which is
//! what the table counts; on CPUs with AVX-512 the kernels run 16 rows per instruction instead of 8.
//!
//! Instructions per row (AVX2 build machine, 10⁵ rows): first with the kernels' loops compiled for the
//! baseline target (before `simd_batch!` was fixed), then for AVX2 + FMA with `F32x8` (its lanes
//! vectorised by LLVM's SLP pass), then (2026-11) on `Avx8`, whose every operation is its AVX instruction,
//! with rows moved in and out by shuffles and roughplastic's table lookups by gathers (`math::avx2`), then
//! (2026-12) with the GGX terms taken from the unnormalised half vector (`Ggx::reflection_term`) and the
//! conductor Fresnel term over one division per channel:
//!
//! | model (GGX α = 0.3)   | f                       | pdf                   | sample                  |
//! |-----------------------|-------------------------|-----------------------|-------------------------|
//! | diffuse               | 7 → 8 → 4.8 → 4.8       | 6 → 5 → 3.5 → 3.5     | 119 → 72 → 18.9 → 18.9  |
//! | roughconductor (Au)   | 189 → 54 → 38.3 → 37.5  | 45 → 26 → 13.3 → 9.6  | 425 → 158 → 78.5 → 75.4 |
//! | roughplastic          | 226 → 198 → 37.5 → 28.5 | 92 → 57 → 24.4 → 16.6 | 562 → 245 → 97.3 → 87.0 |
//!
//! roughplastic's `f` spent most of its 198 instructions in the per-lane lookup of the transmittance table.
//! What remains is arithmetic; the glossy models' is bound by divisions and square roots, which the
//! instruction counts hardly show: roughconductor's `f` takes 13 per register of rows (it took 20): √(h·h),
//! the two masking sums' roots and one division for D G1 G1 / (4 cos θo cos θi), then two roots and one
//! division per RGB channel of the Fresnel term. One thread with AVX-512 (criterion, `batch` group of
//! `gonio-bench/benches/bsdf.rs`): 2.50 → 1.95 ns per row.

use gonio::bsdf::{Bsdf, BsdfModel, SampleBuffers};
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
            let mut rows = SampleBuffers::new(n);
            bsdf.sample_batch(&wo, &uc, &u, &mut rows.columns());
            black_box(&rows.valid);
        }
        other => panic!("unknown method {other}: f, pdf or sample"),
    }
}
