//! Enables `cfg(gonio_avx512)` when the compiler has the AVX-512 target features and intrinsics (Rust
//! 1.89 and later), which the batch kernels' 16-lane path (`math::avx512`) needs. Older compilers, down to
//! the MSRV, build gonio without that path. It uses none of its build-dependencies (see Cargo.toml): the
//! version is read from `rustc --version`.

use std::process::Command;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(gonio_avx512)");
    println!("cargo::rerun-if-changed=build.rs");
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    // "rustc 1.95.0 (59807616e 2026-04-14)": the minor version is the second dot-separated field.
    let minor = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|v| v.split('.').nth(1)?.parse::<u32>().ok());
    if minor.is_some_and(|m| m >= 89) {
        println!("cargo::rustc-cfg=gonio_avx512");
    }
}
