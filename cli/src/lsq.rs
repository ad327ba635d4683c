//! Nonlinear least squares for the calibrations (`calibrate`, `identify`):
//! the minimisation is the `levenberg-marquardt` crate (a port of MINPACK's
//! `lmder`: trust region, pivoted QR, column scaling), the Jacobian central
//! differences of the caller's residual function; this module adds what a
//! fit must report besides its optimum — the parameters' standard errors
//! and correlations, and whether the data determine them at all.
//!
//! Uncertainty ([`analyse`]): with `n` residuals, `p` parameters and the
//! Jacobian `J` (n x p) at the optimum,
//!
//! ```text
//! s^2 = RSS / (n - p)          (residual variance, n - p degrees of freedom)
//! cov = s^2 (J^T J)^-1         (Gauss-Newton covariance of the estimate)
//! se_i = sqrt(cov_ii),  corr_ij = cov_ij / (se_i se_j)
//! ```
//!
//! computed from the singular value decomposition of `J` with its columns
//! scaled to unit length (so the condition number does not depend on the
//! parameters' units). Refusals ([`Undetermined`]): `n <= p` (no degree of
//! freedom: `s^2` is undefined, an exact fit says nothing about the noise)
//! and a rank-deficient `J` (smallest scaled singular value below
//! [`RANK_TOL`] of the largest: a direction of parameter space the data do
//! not see; the parameters with a weight of at least [`CONFOUNDED_WEIGHT`] in
//! it are named). Warnings: condition number above [`COND_WARN`] (the same
//! singular vector names the confounded parameters) and correlations of
//! magnitude above [`CORR_WARN`].

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};

/// Smallest singular value of the column-scaled Jacobian, relative to the
/// largest, below which the fit is refused as rank-deficient: central
/// differences with relative steps of 1e-6 resolve the Jacobian to about
/// 1e-9 of its largest column, so a ratio of 1e-7 is a direction the data
/// do not constrain, not rounding.
pub const RANK_TOL: f64 = 1e-7;

/// Condition number of the column-scaled Jacobian above which the fit
/// warns that parameters are confounded: the standard errors are then
/// amplified a thousandfold over a well-posed fit's along one direction.
pub const COND_WARN: f64 = 1e3;

/// Correlation magnitude above which a pair of parameters is reported as
/// determined only jointly.
pub const CORR_WARN: f64 = 0.99;

/// Weight (component of the unit singular vector) from which a parameter is
/// named as part of a confounded direction.
pub const CONFOUNDED_WEIGHT: f64 = 0.3;

/// Result of a least-squares fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// Parameters at the minimum.
    pub x: Vec<f64>,
    /// Residuals at the minimum.
    pub residuals: Vec<f64>,
    /// Jacobian of the residuals at the minimum (n x p), central differences.
    pub jacobian: DMatrix<f64>,
    /// Residual evaluations the minimiser used.
    pub evaluations: usize,
    /// The minimiser's reason for stopping (`Converged`, ...).
    pub termination: String,
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

/// The residual function as the crate's problem: parameters, residuals and
/// a central-difference Jacobian. A point the model cannot evaluate gets
/// residuals of `penalty` each (larger than any reachable fit), so that the
/// minimiser rejects the step and shrinks its trust region instead of
/// stopping.
struct Problem<'a> {
    f: &'a dyn Fn(&[f64]) -> Option<Vec<f64>>,
    x: DVector<f64>,
    step: &'a [f64],
    m: usize,
    penalty: f64,
}

impl Problem<'_> {
    fn eval(&self, x: &[f64]) -> Vec<f64> {
        match (self.f)(x) {
            Some(r) if r.len() == self.m && r.iter().all(|v| v.is_finite()) => r,
            _ => vec![self.penalty; self.m],
        }
    }

    fn jacobian_at(&self, x: &[f64]) -> DMatrix<f64> {
        // Non-finite only if the penalty itself overflows: NaN makes the
        // minimiser stop with a numerical error instead of a wrong step.
        jacobian(|y| Some(self.eval(y)), x, self.step)
            .unwrap_or_else(|| DMatrix::from_element(self.m, x.len(), f64::NAN))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        Some(DVector::from_vec(self.eval(self.x.as_slice())))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        Some(self.jacobian_at(self.x.as_slice()))
    }
}

/// Minimises `sum r(x)_i^2` from `x0` with the `levenberg-marquardt` crate.
///
/// `residuals` returns the residual vector (always of the same length), or
/// `None` where the model cannot be evaluated; `step[j]` is the absolute
/// central-difference step of parameter `j`. Fails (with the minimiser's
/// reason) when the start cannot be evaluated, or when the minimiser stops
/// for a reason other than convergence.
pub fn least_squares(residuals: impl Fn(&[f64]) -> Option<Vec<f64>>, x0: &[f64], step: &[f64]) -> Result<Fit, String> {
    let r0 = residuals(x0)
        .filter(|r| r.iter().all(|v| v.is_finite()))
        .ok_or("the model cannot be evaluated at the starting parameters")?;
    let m = r0.len();
    let scale = r0.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
    let problem = Problem {
        f: &residuals,
        x: DVector::from_column_slice(x0),
        step,
        m,
        penalty: 1e6 * scale,
    };
    let (problem, report) = LevenbergMarquardt::new().with_patience(200).minimize(problem);
    if !report.termination.was_successful() {
        return Err(format!(
            "the least-squares fit did not converge ({:?})",
            report.termination
        ));
    }
    let x: Vec<f64> = problem.x.iter().copied().collect();
    let r = problem.eval(&x);
    if r.iter().any(|v| v.abs() >= problem.penalty) {
        return Err("the least-squares fit ended where the model cannot be evaluated".into());
    }
    Ok(Fit {
        jacobian: problem.jacobian_at(&x),
        residuals: r,
        x,
        evaluations: report.number_of_evaluations,
        termination: format!("{:?}", report.termination),
    })
}

/// Why the data cannot determine a fit's parameters.
#[derive(Debug, Clone, PartialEq)]
pub enum Undetermined {
    /// `points <= parameters`: no degree of freedom left for the noise.
    NoDegreesOfFreedom {
        /// Residuals.
        points: usize,
        /// Parameters.
        parameters: usize,
    },
    /// A direction of parameter space the data do not see.
    RankDeficient {
        /// The parameters (by name) that move along it.
        confounded: Vec<String>,
        /// Smallest over largest singular value of the scaled Jacobian.
        ratio: f64,
    },
    /// The residual sum of squares at the optimum overflows (or is NaN): a
    /// measurement so large (say a drop of 1e308 Pa) that the noise, hence
    /// every standard error, cannot be computed.
    NonFiniteResiduals {
        /// The largest residual's magnitude.
        largest: f64,
    },
}

impl std::fmt::Display for Undetermined {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Undetermined::NoDegreesOfFreedom { points, parameters } => write!(
                f,
                "{points} points for {parameters} parameters: {} degrees of freedom, so the fit is exact \
                 (or underdetermined) and the noise, hence every standard error, is unknown; \
                 give more than {parameters} points",
                *points as i64 - *parameters as i64
            ),
            Undetermined::RankDeficient { confounded, ratio } => write!(
                f,
                "the data do not separate {} (scaled Jacobian singular, smallest/largest singular value \
                 {ratio:.1e}): only a combination of them is determined",
                confounded.join(", ")
            ),
            Undetermined::NonFiniteResiduals { largest } => write!(
                f,
                "the residual sum of squares overflows (largest residual {largest:.3e}): a measurement \
                 is far out of any plausible range, so the noise and every standard error are unknown"
            ),
        }
    }
}

/// A fit's uncertainty at its optimum (module docs).
#[derive(Debug, Clone)]
pub struct Uncertainty {
    /// Parameter names, in the fit's order.
    pub names: Vec<String>,
    /// Residuals.
    pub points: usize,
    /// Degrees of freedom, `points - parameters`.
    pub dof: usize,
    /// Residual sum of squares.
    pub rss: f64,
    /// Residual variance `s^2 = RSS / dof`.
    pub s2: f64,
    /// Covariance of the parameters (p x p), `s^2 (J^T J)^-1`.
    pub cov: DMatrix<f64>,
    /// Condition number of the column-scaled Jacobian.
    pub condition: f64,
    /// Parameters along the worst-determined direction (weight at least
    /// [`CONFOUNDED_WEIGHT`]), when the condition number exceeds [`COND_WARN`].
    pub confounded: Vec<String>,
}

impl Uncertainty {
    /// Standard error of each parameter, `sqrt(cov_ii)`.
    pub fn std_errors(&self) -> Vec<f64> {
        (0..self.cov.nrows())
            .map(|i| self.cov[(i, i)].max(0.0).sqrt())
            .collect()
    }

    /// Correlation matrix (p x p).
    pub fn correlation(&self) -> DMatrix<f64> {
        correlation(&self.cov)
    }

    /// Residual RMS over the degrees of freedom, `s = sqrt(RSS / dof)`.
    pub fn s(&self) -> f64 {
        self.s2.sqrt()
    }

    /// Warnings: the confounded direction and the pairs correlated beyond
    /// [`CORR_WARN`], one line each.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.confounded.is_empty() {
            out.push(format!(
                "ill-conditioned: the data barely separate {} (condition number {:.1e} of the scaled \
                 Jacobian, above {COND_WARN:.0e}); their standard errors are large and correlated",
                self.confounded.join(", "),
                self.condition
            ));
        }
        let corr = self.correlation();
        for i in 0..self.names.len() {
            for j in i + 1..self.names.len() {
                if corr[(i, j)].abs() > CORR_WARN {
                    out.push(format!(
                        "{} and {} are correlated {:+.4}: the data determine them jointly, not separately",
                        self.names[i],
                        self.names[j],
                        corr[(i, j)]
                    ));
                }
            }
        }
        out
    }
}

/// Correlation matrix of a covariance matrix (zero rows stay zero).
pub fn correlation(cov: &DMatrix<f64>) -> DMatrix<f64> {
    let n = cov.nrows();
    DMatrix::from_fn(n, n, |i, j| {
        let d = (cov[(i, i)] * cov[(j, j)]).sqrt();
        if d > 0.0 { cov[(i, j)] / d } else { 0.0 }
    })
}

/// Names of the parameters with weight at least [`CONFOUNDED_WEIGHT`] in
/// the unit vector `v`, largest first.
fn heavy(v: &[f64], names: &[&str]) -> Vec<String> {
    let mut idx: Vec<usize> = (0..v.len()).filter(|&i| v[i].abs() >= CONFOUNDED_WEIGHT).collect();
    idx.sort_by(|&a, &b| v[b].abs().total_cmp(&v[a].abs()));
    idx.into_iter().map(|i| names[i].to_string()).collect()
}

/// The column-scaled Jacobian's decomposition: column norms, SVD, the
/// condition number and the unit vector of the weakest direction.
struct Scaled {
    norms: Vec<f64>,
    svd: nalgebra::SVD<f64, Dyn, Dyn>,
    condition: f64,
    weakest: Vec<f64>,
}

fn scaled(jac: &DMatrix<f64>, names: &[&str]) -> Result<Scaled, Undetermined> {
    let (n, p) = jac.shape();
    let norms: Vec<f64> = (0..p).map(|j| jac.column(j).norm()).collect();
    if let Some(j) = norms.iter().position(|v| !(*v > 0.0 && v.is_finite())) {
        return Err(Undetermined::RankDeficient {
            confounded: vec![names[j].to_string()],
            ratio: 0.0,
        });
    }
    let scaled = DMatrix::from_fn(n, p, |i, j| jac[(i, j)] / norms[j]);
    let svd = scaled.svd(false, true);
    let v_t = svd.v_t.as_ref().expect("SVD computed with V");
    let (mut kmax, mut kmin) = (0, 0);
    for k in 0..svd.singular_values.len() {
        if svd.singular_values[k] > svd.singular_values[kmax] {
            kmax = k;
        }
        if svd.singular_values[k] < svd.singular_values[kmin] {
            kmin = k;
        }
    }
    let (smax, smin) = (svd.singular_values[kmax], svd.singular_values[kmin]);
    let weakest: Vec<f64> = v_t.row(kmin).iter().copied().collect();
    if svd.singular_values.len() < p || !(smin > RANK_TOL * smax) {
        return Err(Undetermined::RankDeficient {
            confounded: heavy(&weakest, names),
            ratio: smin / smax,
        });
    }
    Ok(Scaled {
        norms,
        condition: smax / smin,
        weakest,
        svd,
    })
}

/// Central-difference Jacobian of `residuals` at `x` with steps `step`;
/// `None` where the model cannot be evaluated.
pub fn jacobian(residuals: impl Fn(&[f64]) -> Option<Vec<f64>>, x: &[f64], step: &[f64]) -> Option<DMatrix<f64>> {
    let m = residuals(x)?.len();
    let mut jac = DMatrix::zeros(m, x.len());
    for j in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[j] += step[j];
        xm[j] -= step[j];
        let (rp, rm) = (residuals(&xp)?, residuals(&xm)?);
        for i in 0..m {
            jac[(i, j)] = (rp[i] - rm[i]) / (2.0 * step[j]);
        }
    }
    jac.iter().all(|v| v.is_finite()).then_some(jac)
}

/// Whether data with Jacobian `jac` (n x p) can determine p parameters at
/// all: `n > p` and `jac` of full rank ([`RANK_TOL`]). Run at the start of
/// a fit, it refuses a design that cannot work before the minimiser
/// wanders along a direction the data do not see.
pub fn check_design(jac: &DMatrix<f64>, names: &[&str]) -> Result<(), Undetermined> {
    let (n, p) = jac.shape();
    if n <= p {
        return Err(Undetermined::NoDegreesOfFreedom {
            points: n,
            parameters: p,
        });
    }
    scaled(jac, names).map(|_| ())
}

/// The uncertainty of a fit with Jacobian `jac` (n x p) and residuals `r`
/// at its optimum; `names` names the p parameters (module docs).
///
/// Errors: [`Undetermined`] when `n <= p`, `jac` is rank-deficient or the
/// residual sum of squares is not finite.
pub fn analyse(jac: &DMatrix<f64>, r: &[f64], names: &[&str]) -> Result<Uncertainty, Undetermined> {
    check_design(jac, names)?;
    let (n, p) = jac.shape();
    let Scaled {
        norms,
        svd,
        condition,
        weakest,
    } = scaled(jac, names)?;
    let v_t = svd.v_t.as_ref().expect("SVD computed with V");
    // (Js^T Js)^-1 = V diag(1/s^2) V^T; unscale: cov = D^-1 (..) D^-1.
    let rss: f64 = r.iter().map(|v| v * v).sum();
    if !rss.is_finite() {
        return Err(Undetermined::NonFiniteResiduals {
            largest: r.iter().fold(0.0, |m, v| m.max(v.abs())),
        });
    }
    let dof = n - p;
    let s2 = rss / dof as f64;
    let cov = DMatrix::from_fn(p, p, |a, b| {
        let mut sum = 0.0;
        for k in 0..p {
            let s = svd.singular_values[k];
            sum += v_t[(k, a)] * v_t[(k, b)] / (s * s);
        }
        s2 * sum / (norms[a] * norms[b])
    });
    Ok(Uncertainty {
        names: names.iter().map(|s| s.to_string()).collect(),
        points: n,
        dof,
        rss,
        s2,
        cov,
        condition,
        confounded: if condition > COND_WARN {
            heavy(&weakest, names)
        } else {
            Vec::new()
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential_exactly() {
        // y = 2 exp(-0.5 t) + 1, noise-free: the fit must recover it.
        let t: Vec<f64> = (0..20).map(|i| i as f64 * 0.3).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-0.5 * t).exp() + 1.0).collect();
        let fit = least_squares(
            |p| {
                Some(
                    t.iter()
                        .zip(&y)
                        .map(|(t, y)| p[0] * (-p[1] * t).exp() + p[2] - y)
                        .collect(),
                )
            },
            &[1.0, 1.0, 0.0],
            &[1e-6, 1e-6, 1e-6],
        )
        .unwrap();
        assert!((fit.x[0] - 2.0).abs() < 1e-8, "{:?}", fit.x);
        assert!((fit.x[1] - 0.5).abs() < 1e-8);
        assert!((fit.x[2] - 1.0).abs() < 1e-8);
        assert!(fit.rms() < 1e-10);
    }

    #[test]
    fn straight_line_standard_errors_match_the_closed_form() {
        // y = a + b t with residuals of known sum of squares: the textbook
        // se(b) = s / sqrt(sum (t - mean)^2), se(a) = s sqrt(1/n + mean^2 / Sxx).
        let t = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let e = [0.1, -0.2, 0.05, 0.15, -0.1, 0.0];
        let y: Vec<f64> = t.iter().zip(&e).map(|(t, e)| 1.0 + 2.0 * t + e).collect();
        let f = |p: &[f64]| Some(t.iter().zip(&y).map(|(t, y)| p[0] + p[1] * t - y).collect());
        let fit = least_squares(f, &[0.0, 0.0], &[1e-6, 1e-6]).unwrap();
        let u = analyse(&fit.jacobian, &fit.residuals, &["a", "b"]).unwrap();
        let n = t.len() as f64;
        let mean = t.iter().sum::<f64>() / n;
        let sxx: f64 = t.iter().map(|t| (t - mean).powi(2)).sum();
        let s = (fit.residuals.iter().map(|r| r * r).sum::<f64>() / (n - 2.0)).sqrt();
        let se = u.std_errors();
        assert_eq!(u.dof, 4);
        assert!((se[1] - s / sxx.sqrt()).abs() < 1e-9 * se[1]);
        assert!((se[0] - s * (1.0 / n + mean * mean / sxx).sqrt()).abs() < 1e-9 * se[0]);
        let corr = u.correlation();
        let expected = -mean / (sxx / n + mean * mean).sqrt();
        assert!((corr[(0, 1)] - expected).abs() < 1e-9);
    }

    #[test]
    fn refuses_exact_and_confounded_fits() {
        let jac = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]);
        assert_eq!(
            analyse(&jac, &[0.0, 0.0], &["a", "b"]).unwrap_err(),
            Undetermined::NoDegreesOfFreedom {
                points: 2,
                parameters: 2
            }
        );
        // y = (a + b) t: only a + b is seen.
        let jac = DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 0.0, 2.0, 2.0, 1.0, 3.0, 3.0, 0.5]);
        let jac = jac.insert_row(3, 0.0);
        let e = analyse(&jac, &[0.1, 0.2, 0.0, 0.1], &["a", "b", "c"]).unwrap_err();
        match e {
            Undetermined::RankDeficient { confounded, .. } => assert_eq!(
                {
                    let mut c = confounded;
                    c.sort();
                    c
                },
                ["a", "b"]
            ),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn refuses_an_overflowing_residual_sum_of_squares() {
        let jac = DMatrix::from_row_slice(3, 1, &[1.0, 2.0, 3.0]);
        let e = analyse(&jac, &[0.1, 1e308, 0.0], &["a"]).unwrap_err();
        assert_eq!(e, Undetermined::NonFiniteResiduals { largest: 1e308 });
        assert!(e.to_string().contains("overflows"), "{e}");
    }
}
