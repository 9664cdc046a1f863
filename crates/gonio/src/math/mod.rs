//! Vectors (re-exported from `glam`), the shading frame and spherical coordinates.

#[cfg(target_arch = "x86_64")]
pub mod avx2;
#[cfg(all(target_arch = "x86_64", gonio_avx512))]
pub mod avx512;
pub mod frame;
pub mod lanes;
pub mod param;
pub mod perspective;
pub mod simd;
pub mod spherical;
pub mod transform;
pub mod trig;
pub(crate) mod twice;

pub use frame::Frame;
pub use glam::{DVec3, Vec2, Vec3};
pub use transform::Transform;

/// For tests: the widest lanes the batch drivers may use on this thread (2: AVX-512, 1: AVX2, 0: the portable
/// `F32x8`), so that every path is tested on a machine that has the widest (the drivers run on the calling
/// thread).
#[cfg(test)]
pub(crate) mod simd_level {
    use std::cell::Cell;

    thread_local!(static LEVEL: Cell<u8> = const { Cell::new(2) });

    /// Whether `level` is allowed.
    pub(crate) fn allows(level: u8) -> bool {
        LEVEL.with(|l| l.get() >= level)
    }

    /// `f()` with lanes up to `level`.
    pub(crate) fn with<T>(level: u8, f: impl FnOnce() -> T) -> T {
        let before = LEVEL.with(|l| l.replace(level));
        let r = f();
        LEVEL.with(|l| l.set(before));
        r
    }
}
