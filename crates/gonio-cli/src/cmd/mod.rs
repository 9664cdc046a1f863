pub mod albedo;
pub mod check;
pub mod explore;
pub mod fit;
pub mod measure;
pub mod plot;
pub mod preview;
pub mod render;
