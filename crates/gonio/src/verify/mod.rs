//! The verification harness (to be written).
pub mod energy;
