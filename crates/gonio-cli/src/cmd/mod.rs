pub mod albedo;
pub mod check;
pub mod render;
