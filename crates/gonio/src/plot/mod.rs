//! The numbers behind gonio's reflectance plots — no drawing here: `gonio plot` (the CLI) and
//! `gonio.plot` (Python, matplotlib) both draw from these functions, so a terminal and a notebook show
//! the same values.
//!
//! | function | what it tabulates | used for |
//! |---|---|---|
//! | [`lobe_data`] | f·cos θi (sr⁻¹) along two planes for a fixed ωo, and over the whole hemisphere of ωi | polar plots, 3-D lobes |
//! | [`slice_data`] | f (sr⁻¹) on a θh × θd grid at a fixed φd (Rusinkiewicz's half/difference angles) | the image slices of Disney's BRDF Explorer and the MERL papers |
//! | [`albedo_data`] | the directional albedo ∫ f cos θi dωi against θo | energy curves |
//!
//! # Conventions
//! As everywhere in gonio (ARCHITECTURE.md): the normal is +z, `wo` points towards the viewer and `wi`
//! towards the light, both away from the surface, and `f` excludes the cosine. In this module every
//! angle is in **degrees** (they are axis labels); directions are built in `f64` and rounded to `f32`
//! once, so the same angle always gives the same direction.
//!
//! - ωo = (sin θo, 0, cos θo): the viewer lies in the xz-plane, on the +x side (φo = 0).
//! - ωr = (−sin θo, 0, cos θo) is its mirror direction.
//! - Values are RGB ([`Rgb`]); [`Channel`] picks r, g, b or the Rec. 709 luminance for a plot.
//!
//! ```
//! use gonio::plot::{lobe_data, Channel};
//! use gonio::Bsdf;
//! let paper = Bsdf::from_json(r#"{"type": "diffuse", "reflectance": 0.5}"#).unwrap();
//! let lobe = lobe_data(&paper, 30.0, 181, 0, 0).unwrap();
//! // At normal incidence of the light (θi = 0, the middle sample) f·cos θi = ρ/π.
//! let at_normal = Channel::Lum.of(lobe.incidence[90]);
//! assert!((at_normal - 0.5 / std::f32::consts::PI).abs() < 1e-6);
//! ```

mod albedo;
mod lobe;
mod slice;

pub use albedo::{albedo_data, AlbedoData};
pub use lobe::{check_theta_o, incidence_direction, lobe_data, perpendicular_direction, LobeData, LobeGrid};
pub use slice::{slice_data, SliceData};

use crate::math::Vec3;

/// The default resolutions of the plots, shared by `gonio plot` and the explorer (one source of numbers):
/// angles per plane of the polar plot (half-degree steps), the 3-D grid (θ, φ), the slice (MERL's θh × θd)
/// and the albedo curve (viewing angles, samples per angle).
pub const POLAR_SAMPLES: usize = 721;
pub const GRID_THETA: usize = 31;
pub const GRID_PHI: usize = 72;
pub const SLICE_RES: usize = 90;
pub const ALBEDO_ANGLES: usize = 30;
pub const ALBEDO_SAMPLES: usize = 16_384;
use crate::spectrum::Rgb;

/// Which number of an RGB value a plot shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    R,
    G,
    B,
    /// Rec. 709 luminance ([`Rgb::luminance`]).
    Lum,
}

impl Channel {
    /// All four, in the order of the columns of the Python arrays: r, g, b, lum.
    pub const ALL: [Channel; 4] = [Channel::R, Channel::G, Channel::B, Channel::Lum];

    /// `r`, `g`, `b` or `lum`.
    #[must_use]
    pub fn parse(name: &str) -> Option<Channel> {
        match name {
            "r" => Some(Channel::R),
            "g" => Some(Channel::G),
            "b" => Some(Channel::B),
            "lum" => Some(Channel::Lum),
            _ => None,
        }
    }

    /// The name `parse` accepts.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Channel::R => "r",
            Channel::G => "g",
            Channel::B => "b",
            Channel::Lum => "lum",
        }
    }

    /// This channel of `value` (NaN stays NaN).
    #[inline]
    #[must_use]
    pub fn of(self, value: Rgb) -> f32 {
        match self {
            Channel::R => value.r(),
            Channel::G => value.g(),
            Channel::B => value.b(),
            Channel::Lum => value.luminance(),
        }
    }

    /// This channel of every value.
    #[must_use]
    pub fn of_all(self, values: &[Rgb]) -> Vec<f32> {
        values.iter().map(|&v| self.of(v)).collect()
    }
}

/// The unit direction at polar angle `theta` and azimuth `phi` (radians, `f64`), rounded to `f32` once.
#[inline]
fn direction(theta: f64, phi: f64) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32)
}

/// ωo for a viewer at `theta_o_deg` in the xz-plane (see the module docs).
#[must_use]
pub fn outgoing(theta_o_deg: f64) -> Vec3 {
    direction(theta_o_deg.to_radians(), 0.0)
}

/// `count` evenly spaced values from `lo` to `hi` inclusive (one value: `lo`).
fn linspace(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    if count < 2 {
        return vec![lo; count];
    }
    (0..count).map(|k| lo + (hi - lo) * k as f64 / (count - 1) as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_parse_and_pick() {
        let v = Rgb::new(0.1, 0.2, 0.3);
        for c in Channel::ALL {
            assert_eq!(Channel::parse(c.name()), Some(c));
        }
        assert_eq!(Channel::parse("red"), None);
        assert_eq!((Channel::R.of(v), Channel::G.of(v), Channel::B.of(v)), (0.1, 0.2, 0.3));
        assert_eq!(Channel::Lum.of(v), v.luminance());
    }

    #[test]
    fn linspace_ends_exactly() {
        let x = linspace(-90.0, 90.0, 181);
        assert_eq!((x[0], x[90], x[180]), (-90.0, 0.0, 90.0));
        assert_eq!(linspace(3.0, 4.0, 1), vec![3.0]);
    }
}
