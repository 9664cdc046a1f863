//! Colour and spectra: linear RGB ([`Rgb`]), named optical constants ([`named`]), the CIE 1931 observer
//! ([`cie`]), and the building blocks of spectral mode — hero-wavelength sampling ([`wavelengths`]),
//! tabulated spectra ([`piecewise`]), light spectra ([`illuminant`]), RGB → spectrum upsampling
//! ([`upsample`]) and wavelength-dependent indices of refraction ([`dispersion`]).

pub mod cie;
pub mod dispersion;
pub mod illuminant;
pub mod named;
pub mod piecewise;
pub mod rgb;
pub mod upsample;
pub mod wavelengths;

pub use rgb::Rgb;
