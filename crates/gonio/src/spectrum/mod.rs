//! Colour: linear RGB now ([`Rgb`]), named optical constants of metals and dielectrics ([`named`]).

pub mod cie;
pub mod named;
pub mod rgb;

pub use rgb::Rgb;
