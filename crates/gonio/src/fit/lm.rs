//! Levenberg–Marquardt for small non-linear least-squares problems (Levenberg 1944, Marquardt 1963;
//! Madsen, Nielsen & Tingleff 2004, "Methods for Non-Linear Least Squares Problems", §3.2, with
//! Marquardt's scaling of the damping by diag(JᵀJ)). The Jacobian is a forward difference.

/// The result of [`minimize`].
#[derive(Clone, Debug, PartialEq)]
pub struct Minimum {
    pub x: Vec<f64>,
    /// ½‖r(x)‖² is not used: this is ‖r(x)‖².
    pub cost: f64,
    pub iterations: usize,
}

/// Minimise ‖r(x)‖² from `x0`; `residuals` fills its output slice (a fixed length `m`).
pub fn minimize(residuals: &dyn Fn(&[f64], &mut [f64]), m: usize, x0: &[f64], max_iterations: usize) -> Minimum {
    let n = x0.len();
    let mut x = x0.to_vec();
    let mut r = vec![0.0; m];
    residuals(&x, &mut r);
    let mut cost = sum_sq(&r);
    let mut lambda = 1e-3;
    let mut jac = vec![0.0; m * n];
    let mut r_step = vec![0.0; m];
    let mut iterations = 0;
    while iterations < max_iterations {
        iterations += 1;
        // Forward differences, column by column.
        for j in 0..n {
            let h = 1e-4 * (1.0 + x[j].abs());
            let mut xp = x.clone();
            xp[j] += h;
            residuals(&xp, &mut r_step);
            for i in 0..m {
                jac[i * n + j] = (r_step[i] - r[i]) / h;
            }
        }
        // Normal equations JᵀJ δ = −Jᵀr.
        let mut jtj = vec![0.0; n * n];
        let mut jtr = vec![0.0; n];
        for i in 0..m {
            let row = &jac[i * n..(i + 1) * n];
            for a in 0..n {
                jtr[a] += row[a] * r[i];
                for b in a..n {
                    jtj[a * n + b] += row[a] * row[b];
                }
            }
        }
        for a in 0..n {
            for b in 0..a {
                jtj[a * n + b] = jtj[b * n + a];
            }
        }
        let mut improved = false;
        while lambda < 1e12 {
            let mut a = jtj.clone();
            for k in 0..n {
                a[k * n + k] += lambda * jtj[k * n + k].max(1e-12);
            }
            let Some(delta) = solve(&mut a, &jtr.iter().map(|v| -v).collect::<Vec<_>>(), n) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = x.iter().zip(&delta).map(|(a, b)| a + b).collect();
            residuals(&trial, &mut r_step);
            let trial_cost = sum_sq(&r_step);
            if trial_cost.is_finite() && trial_cost < cost {
                let relative = (cost - trial_cost) / cost.max(1e-300);
                x = trial;
                std::mem::swap(&mut r, &mut r_step);
                cost = trial_cost;
                lambda = (lambda / 3.0).max(1e-12);
                improved = relative > 1e-9;
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    Minimum { x, cost, iterations }
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Gaussian elimination with partial pivoting; `None` when singular.
fn solve(a: &mut [f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut b = b.to_vec();
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if !(a[pivot * n + col].abs() > 1e-300) {
            return None;
        }
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
        }
        b.swap(col, pivot);
        for row in col + 1..n {
            let factor = a[row * n + col] / a[col * n + col];
            for k in col..n {
                a[row * n + k] -= factor * a[col * n + k];
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row * n + k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row * n + row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential_decay() {
        // r_i = a e^{−b t_i} − y_i with a = 2, b = 0.7: the minimum is exact.
        let t: Vec<f64> = (0..30).map(|i| i as f64 * 0.2).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-0.7 * t).exp()).collect();
        let r = |x: &[f64], out: &mut [f64]| {
            for i in 0..t.len() {
                out[i] = x[0] * (-x[1] * t[i]).exp() - y[i];
            }
        };
        let m = minimize(&r, t.len(), &[1.0, 0.1], 200);
        assert!((m.x[0] - 2.0).abs() < 1e-6 && (m.x[1] - 0.7).abs() < 1e-6, "{m:?}");
    }

    #[test]
    fn rosenbrock() {
        let r = |x: &[f64], out: &mut [f64]| {
            out[0] = 10.0 * (x[1] - x[0] * x[0]);
            out[1] = 1.0 - x[0];
        };
        let m = minimize(&r, 2, &[-1.2, 1.0], 500);
        assert!((m.x[0] - 1.0).abs() < 1e-5 && (m.x[1] - 1.0).abs() < 1e-5, "{m:?}");
    }
}
