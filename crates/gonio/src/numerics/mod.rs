//! Special functions, with no physics in them: the error-function family (exact `f64` forms for tables
//! and verification, fast `f32` forms over [`Real`](crate::math::lanes::Real) lanes for the models), and
//! the lane exponential and logarithm those need.
//!
//! Every `f32` approximation states its error bound in its doc comment and is tested against the exact
//! `f64` form beside it. The polynomial coefficients are fits made by `tools/fit_special_functions.py`.

pub mod erf;
pub mod exp_log;

pub use erf::{erf, erf_inv, erfc};

use crate::math::lanes::Real;

/// c₀ + u (c₁ + u (c₂ + …)) by Horner's scheme with [`Real::mad`].
#[inline(always)]
pub(crate) fn horner<R: Real, const N: usize>(u: R, c: &[f32; N]) -> R {
    let mut p = R::splat(c[N - 1]);
    for k in (0..N - 1).rev() {
        p = u.mad(p, R::splat(c[k]));
    }
    p
}
