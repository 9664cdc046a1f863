//! Named optical constants: complex indices of metals and indices of dielectrics (placeholder; being
//! written).

use super::Rgb;

/// Names accepted by `conductor.material`.
pub const CONDUCTORS: &[&str] = &["none"];

/// (η, k) of a named conductor, reduced to RGB.
#[must_use]
pub fn conductor(name: &str) -> Option<(Rgb, Rgb)> {
    match name {
        "none" => Some((Rgb::ZERO, Rgb::ONE)),
        _ => None,
    }
}

/// Names accepted as dielectric indices (`int_ior`, `ext_ior`).
pub const DIELECTRICS: &[&str] = &["vacuum", "air", "bk7"];

/// The index of refraction of a named dielectric at ~589 nm.
#[must_use]
pub fn dielectric_ior(name: &str) -> Option<f32> {
    match name {
        "vacuum" => Some(1.0),
        "air" => Some(1.000_277),
        "bk7" => Some(1.5046),
        _ => None,
    }
}
