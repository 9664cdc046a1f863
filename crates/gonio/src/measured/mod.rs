//! Measured reflectance data: the file formats gonio reads measured materials from.
//!
//! - [`tensor_file`]: the `tensor_file` container of Mitsuba and the RGL material database
//!   (read by the [`measured`](crate::bsdf::measured) BSDF).

pub mod tensor_file;
