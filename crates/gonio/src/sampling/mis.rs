//! Multiple importance sampling weights (Veach & Guibas 1995, "Optimally Combining Sampling Techniques
//! for Monte Carlo Rendering", eq. 8 and the power heuristic with β = 2).

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
    let (f, g) = (nf * pdf_f, ng * pdf_g);
    if f.is_infinite() {
        return 1.0;
    }
    if f == 0.0 && g == 0.0 {
        return 0.0;
    }
    (f * f) / (f * f + g * g)
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
