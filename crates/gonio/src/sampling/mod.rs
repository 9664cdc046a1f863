//! Sampling: warps of the unit square ([`warp`]), piecewise-constant distributions ([`distribution`]), alias
//! tables ([`alias`]),
//! bilinear interpolants conditioned on parameters ([`marginal2d`]), the random number generator ([`rng`]) and multiple importance sampling weights ([`mis`]).

pub mod alias;
pub mod distribution;
pub mod marginal2d;
pub mod mis;
pub mod rng;
pub mod warp;

pub use rng::{Pcg32, Pcg32x8};
