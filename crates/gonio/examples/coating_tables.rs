//! Run by hand: `cargo run --release -p gonio --example coating_tables`.
//! Prints the cost of integrating `roughplastic`'s coating tables (`CoatingTables::compute`: T(μ) at the
//! table's nodes and R̄ᵢ) for a few coatings, among them the one of scenes like material-spheres.xml (GGX
//! α = 0.1, polypropylene in air): wall-clock and CPU time of the process (all threads, from /proc on Linux,
//! 10 ms resolution), per table, the mean of `REPEAT` integrations.

use gonio::bsdf::rough_plastic::CoatingTables;
use gonio::microfacet::{MicrofacetDistribution, MicrofacetKind};
use std::hint::black_box;
use std::time::Instant;

mod common;
use common::cpu_seconds;

/// Integrations per coating.
const REPEAT: usize = 10;

fn main() {
    let polypropylene = 1.49f32 / 1.000_277;
    let coatings = [
        (MicrofacetKind::Ggx, 0.1f32, polypropylene),
        (MicrofacetKind::Beckmann, 0.1, polypropylene),
        (MicrofacetKind::Ggx, 0.01, 1.5),
        (MicrofacetKind::Ggx, 1.0, 1.5),
        (MicrofacetKind::Beckmann, 0.3, 1.0 / 1.5),
    ];
    for (kind, alpha, eta) in coatings {
        let d = MicrofacetDistribution::new(kind, alpha, alpha);
        let (wall, cpu) = (Instant::now(), cpu_seconds());
        for _ in 0..REPEAT {
            black_box(CoatingTables::compute(d, eta));
        }
        let (wall, cpu) = (wall.elapsed().as_secs_f64() / REPEAT as f64, (cpu_seconds() - cpu) / REPEAT as f64);
        println!("{kind:?} α = {alpha}, η = {eta:.4}: {:.1} ms wall, {:.1} ms CPU per table", wall * 1e3, cpu * 1e3);
    }
}
