//! Colour and spectra: linear RGB ([`Rgb`]), named optical constants ([`named`]), the CIE 1931 observer
//! ([`cie`]), and the building blocks of spectral mode — hero-wavelength sampling ([`wavelengths`]),
//! tabulated spectra ([`piecewise`]), light spectra ([`illuminant`]), RGB → spectrum upsampling
//! ([`upsample`]), wavelength-dependent indices of refraction ([`dispersion`]) and the film's estimate of
//! a path's colour from its wavelengths ([`observer`]); what a path carries in the renderer's spectral mode
//! ([`sampled`]; docs/spectral.md).

pub mod cie;
pub mod dispersion;
pub mod illuminant;
pub mod named;
pub mod observer;
pub mod piecewise;
pub mod rgb;
pub mod sampled;
pub mod upsample;
pub mod wavelengths;

pub use rgb::Rgb;
