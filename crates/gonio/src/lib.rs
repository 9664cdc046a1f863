//! # gonio — a physically based reflectance toolkit
//!
//! Reflection models with `f`, `sample` and `pdf` ([`bsdf`]), the Fresnel equations ([`fresnel`]),
//! sampling warps ([`sampling`]), and a verification harness that proves a model's physics
//! ([`verify`]: chi-square, reciprocity, energy, NaN sweeps).
//!
//! ```
//! use gonio::bsdf::{Bsdf, BsdfModel};
//! use gonio::math::Vec3;
//! // A gold mirror: no smooth lobe, so f is zero for any pair of directions...
//! let gold = Bsdf::from_json(r#"{"type": "conductor", "material": "Au"}"#).unwrap();
//! assert!(gold.f(Vec3::Z, Vec3::Z).is_black());
//! // ...and its albedo at normal incidence is the Fresnel reflectance of gold, reddish-yellow.
//! let a = gonio::verify::energy::albedo(&gold, Vec3::Z, 16, 1);
//! assert!(a.r() > a.b());
//! ```

// `!(x > 0.0)` is the deliberate NaN-rejecting form: it is true for NaN, where `x <= 0.0` is not.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod camera;
pub mod error;
pub mod explore;
pub mod film;
pub mod fit;
pub mod fresnel;
#[doc(hidden)]
pub mod fuzz;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod light;
pub mod math;
pub mod measured;
pub mod microfacet;
pub mod numerics;
pub mod plot;
pub mod preview;
pub mod props;
pub mod render;
pub mod sampling;
pub mod scene;
/// Scratch directories for the tests of this crate and of the crates built on it (not part of the API).
#[doc(hidden)]
pub mod scratch;
pub mod spectrum;
pub mod texture;
pub mod verify;
pub mod xml;

pub use bsdf::{Bsdf, BsdfFlags, BsdfModel, BsdfSample};
pub use error::{Error, Result};
pub use spectrum::Rgb;
