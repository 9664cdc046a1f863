//! Run by hand: `cargo run --release -p gonio --example merl_bench -- FILE.binary`.
//! Prints the load time of a MERL file (reading alone, and with the sampling tables), the evaluation rate
//! of f (trilinear and nearest) and of sample, single-threaded. Wall-clock and CPU time (the machine may
//! be shared: CPU time of the process, all threads, from /proc on Linux, 10 ms resolution).

use gonio::bsdf::{BsdfModel, Merl};
use gonio::math::Vec3;
use gonio::measured::{Interpolation, MerlTable};
use gonio::sampling::Pcg32;
use std::hint::black_box;
use std::time::Instant;

mod common;
use common::cpu_seconds;

struct Clock(Instant, f64);

impl Clock {
    fn start() -> Self {
        Clock(Instant::now(), cpu_seconds())
    }
    /// (wall, cpu) seconds since start.
    fn elapsed(&self) -> (f64, f64) {
        (self.0.elapsed().as_secs_f64(), cpu_seconds() - self.1)
    }
}

fn main() {
    let path = std::env::args().nth(1).expect("usage: merl_bench FILE.binary");
    let path = std::path::Path::new(&path);
    // Warm the page cache once, then time.
    let _ = std::fs::read(path).unwrap();
    let t = Clock::start();
    let table = MerlTable::read(path).unwrap();
    let read = t.elapsed();
    drop(table);
    let t = Clock::start();
    let merl = Merl::open(path, Interpolation::Trilinear).unwrap();
    let open = t.elapsed();
    println!("read: {:.3} s wall, {:.3} s CPU; read + sampling tables: {:.3} s wall, {:.3} s CPU", read.0, read.1, open.0, open.1);
    let mut rng = Pcg32::new(1, 1);
    let dirs: Vec<(Vec3, Vec3)> = (0..1 << 16)
        .map(|_| {
            let d = |r: &mut Pcg32| gonio::sampling::warp::sample_cosine_hemisphere(r.next_vec2());
            (d(&mut rng), d(&mut rng))
        })
        .collect();
    for interp in [Interpolation::Trilinear, Interpolation::Nearest] {
        let mut m = merl.clone();
        m.interpolation = interp;
        let n = 4_000_000;
        let t = Clock::start();
        let mut acc = 0.0;
        for k in 0..n {
            let (wo, wi) = dirs[k & 0xffff];
            acc += m.f(black_box(wo), black_box(wi)).r();
        }
        black_box(acc);
        let (wall, cpu) = t.elapsed();
        println!("f {interp:?}: {:.2e} evals/s wall, {:.2e} per CPU second", n as f64 / wall, n as f64 / cpu);
    }
    let n = 1_000_000;
    let t = Clock::start();
    let mut acc = 0.0;
    for k in 0..n {
        let (wo, _) = dirs[k & 0xffff];
        if let Some(s) = merl.sample(wo, rng.next_f32(), rng.next_vec2()) {
            acc += s.weight.r();
        }
    }
    black_box(acc);
    let (wall, cpu) = t.elapsed();
    println!("sample (with f and pdf): {:.2e} samples/s wall, {:.2e} per CPU second", n as f64 / wall, n as f64 / cpu);
}
