//! The verification harness (to be written).
pub mod chi2;
pub mod energy;
