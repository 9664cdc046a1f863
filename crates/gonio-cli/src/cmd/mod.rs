pub mod albedo;
pub mod check;
