//! Piecewise-constant 1-D and 2-D distributions (to be written).
