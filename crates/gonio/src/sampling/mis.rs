//! Multiple importance sampling weights (Veach & Guibas 1995, "Optimally Combining Sampling Techniques
//! for Monte Carlo Rendering", eq. 8 and the power heuristic with β = 2).

use crate::math::lanes::Real;

/// Balance heuristic weight of technique `f` against `g`: n_f p_f / (n_f p_f + n_g p_g).
#[inline]
#[must_use]
pub fn balance_heuristic(nf: f32, pdf_f: f32, ng: f32, pdf_g: f32) -> f32 {
    let (f, g) = (nf * pdf_f, ng * pdf_g);
    if f + g == 0.0 {
        0.0
    } else {
        f / (f + g)
    }
}

/// Power heuristic (β = 2) weight of technique `f` against `g`. Infinite `pdf_f` (a delta) gets weight 1.
#[inline]
#[must_use]
pub fn power_heuristic(nf: f32, pdf_f: f32, ng: f32, pdf_g: f32) -> f32 {
    power_heuristic_lanes(nf, pdf_f, ng, pdf_g)
}

/// [`power_heuristic`] in lanes: the same operations, so that a lane's weight equals the single call's bit
/// for bit.
#[inline(always)]
#[must_use]
pub fn power_heuristic_lanes<R: Real>(nf: R, pdf_f: R, ng: R, pdf_g: R) -> R {
    let (f, g) = (nf * pdf_f, ng * pdf_g);
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let w = R::select(f.eq(zero) & g.eq(zero), zero, (f * f) / (f * f + g * g));
    R::select(f.abs().eq(R::splat(f32::INFINITY)), one, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_two_techniques_sum_to_one() {
        for &(a, b) in &[(0.3f32, 2.0f32), (5.0, 0.01), (1.0, 1.0)] {
            assert!((power_heuristic(1.0, a, 1.0, b) + power_heuristic(1.0, b, 1.0, a) - 1.0).abs() < 1e-6);
            assert!((balance_heuristic(1.0, a, 1.0, b) + balance_heuristic(1.0, b, 1.0, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(1.0, f32::INFINITY, 1.0, 3.0), 1.0);
        assert_eq!(power_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
    }
}
