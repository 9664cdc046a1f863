pub mod albedo;
pub mod check;
pub mod measure;
pub mod render;
