//! A small Levenberg-Marquardt least-squares solver for the calibrations
//! (a handful of parameters, tens of residuals). Central-difference
//! Jacobian, Marquardt's diagonal scaling, dense normal equations solved by
//! Cholesky with pivot checks.

/// Result of a least-squares fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// Parameters at the minimum.
    pub x: Vec<f64>,
    /// Residuals at the minimum.
    pub residuals: Vec<f64>,
    /// Iterations used.
    pub iterations: usize,
}

impl Fit {
    /// Root-mean-square residual.
    pub fn rms(&self) -> f64 {
        rms(&self.residuals)
    }
    /// Largest absolute residual.
    pub fn max_abs(&self) -> f64 {
        max_abs(&self.residuals)
    }
}

/// Root-mean-square of a slice (NaN for an empty one).
pub fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt()
}

/// Largest absolute value (0 for none).
pub fn max_abs(r: &[f64]) -> f64 {
    r.iter().fold(0.0, |m, v| m.max(v.abs()))
}

fn cost(r: &[f64]) -> f64 {
    let c: f64 = r.iter().map(|v| v * v).sum();
    if c.is_finite() { c } else { f64::INFINITY }
}

/// Solves `A x = b` for symmetric positive definite `A` (n x n, row-major).
fn cholesky_solve(a: &[f64], b: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                if !(s > 0.0) {
                    return None;
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    let mut y = vec![0.0; n];
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * y[k];
        }
        y[i] = s / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let mut s = y[i];
        for k in i + 1..n {
            s -= l[k * n + i] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
    Some(x)
}

/// Minimises `sum f(x)_i^2` from `x0`. `step` gives the finite-difference
/// step of each parameter (absolute). Stops when the relative cost decrease
/// falls below 1e-15 or after `max_iter` iterations.
pub fn levenberg_marquardt(f: impl Fn(&[f64]) -> Vec<f64>, x0: &[f64], step: &[f64], max_iter: usize) -> Fit {
    let n = x0.len();
    let mut x = x0.to_vec();
    let mut r = f(&x);
    let m = r.len();
    let mut c = cost(&r);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    for it in 0..max_iter {
        iterations = it + 1;
        // Jacobian by central differences.
        let mut jac = vec![0.0; m * n];
        for j in 0..n {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[j] += step[j];
            xm[j] -= step[j];
            let (rp, rm) = (f(&xp), f(&xm));
            for i in 0..m {
                jac[i * n + j] = (rp[i] - rm[i]) / (2.0 * step[j]);
            }
        }
        let mut jtj = vec![0.0; n * n];
        let mut jtr = vec![0.0; n];
        for i in 0..m {
            for a in 0..n {
                jtr[a] += jac[i * n + a] * r[i];
                for b in 0..n {
                    jtj[a * n + b] += jac[i * n + a] * jac[i * n + b];
                }
            }
        }
        let mut improved = false;
        for _ in 0..30 {
            let mut damped = jtj.clone();
            for a in 0..n {
                damped[a * n + a] += lambda * jtj[a * n + a].max(1e-300);
            }
            let rhs: Vec<f64> = jtr.iter().map(|v| -v).collect();
            if let Some(dx) = cholesky_solve(&damped, &rhs, n) {
                let xn: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + b).collect();
                let rn = f(&xn);
                let cn = cost(&rn);
                if cn < c {
                    let rel = (c - cn) / c.max(1e-300);
                    x = xn;
                    r = rn;
                    c = cn;
                    lambda = (lambda * 0.3).max(1e-12);
                    improved = rel > 1e-15;
                    break;
                }
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Fit {
        x,
        residuals: r,
        iterations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential_exactly() {
        // y = 2 exp(-0.5 t) + 1, noise-free: the fit must recover it.
        let t: Vec<f64> = (0..20).map(|i| i as f64 * 0.3).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-0.5 * t).exp() + 1.0).collect();
        let fit = levenberg_marquardt(
            |p| {
                t.iter()
                    .zip(&y)
                    .map(|(t, y)| p[0] * (-p[1] * t).exp() + p[2] - y)
                    .collect()
            },
            &[1.0, 1.0, 0.0],
            &[1e-6, 1e-6, 1e-6],
            200,
        );
        assert!((fit.x[0] - 2.0).abs() < 1e-8, "{:?}", fit.x);
        assert!((fit.x[1] - 0.5).abs() < 1e-8);
        assert!((fit.x[2] - 1.0).abs() < 1e-8);
        assert!(fit.rms() < 1e-10);
    }
}
