//! The fit strategy of `identify`: a least-squares fit kept inside the
//! parameters' plausible ranges, and a search over sub-fits that guards
//! against reporting a fit that stopped short of the minimum.
//!
//! Why a search: the misfit of a transient is not convex in the dynamic
//! parameters. From a start with the mass doubled and the damping halved,
//! an underdamped record pulls the three-parameter fit (mass, damping,
//! bulk modulus) towards stiffer chambers first (a stiffer chamber raises
//! the frequency the heavy start lacks), the bulk modulus runs out of its
//! range and the fit stalls there with a residual several times what the
//! fit of mass and damping alone reaches on the same data. A fit's
//! minimum can never lie above a sub-fit's (the sub-fit's optimum is a
//! point of the larger fit's space), so a sub-fit that does better proves
//! the larger fit missed its minimum, and its optimum is a start from
//! which the larger fit cannot do worse (the Levenberg-Marquardt iteration
//! accepts only steps that lower the misfit).
//!
//! [`best_fit`] therefore fits every subset of the free parameters (the
//! others held at the start), each from the start and from the optimum of
//! each of its own subsets with one parameter fewer, and returns the full
//! fit of lowest residual sum of squares: for `p` parameters
//! `sum_k C(p, k) (k + 1)` minimisations (16 for three, 111 for all five),
//! each of a few tens of model runs.
//!
//! Bounds ([`Bounds`]): the residual function is evaluated at the point
//! clamped into the box, so the minimiser sees a misfit that is flat beyond
//! a bound instead of a model that refuses to run (a refusal becomes a
//! penalty wall whose one-sided differences wreck the Jacobian, and the
//! minimiser stops against it). A parameter whose optimum lies on a bound
//! is the caller's to fix there and refit the others without it: a
//! profile along that parameter, whose minimum is then interior.

use crate::lsq::{self, Fit};
use std::cell::RefCell;
use std::collections::HashMap;

/// A box in fit coordinates: `lo[i] <= u[i] <= hi[i]` (either may be
/// infinite).
#[derive(Clone, Debug, PartialEq)]
pub struct Bounds {
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
}

impl Bounds {
    /// `u` clamped into the box.
    pub fn clamp(&self, u: &[f64]) -> Vec<f64> {
        u.iter()
            .zip(self.lo.iter().zip(&self.hi))
            .map(|(v, (lo, hi))| v.max(*lo).min(*hi))
            .collect()
    }
}

/// The outcome of [`best_fit`].
#[derive(Debug, Clone)]
pub struct Found {
    /// The best full fit found (its `x` inside the box).
    pub fit: Fit,
    /// Residual sum of squares of the fit started from the start point
    /// alone (infinite when that fit failed): what a single minimisation
    /// would have reported.
    pub rss_from_start: f64,
    /// Minimisations run.
    pub minimisations: usize,
}

impl Found {
    /// Residual sum of squares of the best fit.
    pub fn rss(&self) -> f64 {
        rss(&self.fit.residuals)
    }
}

fn rss(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Most parameters [`best_fit`] searches over (the subsets are a bit mask).
pub const MAX_PARAMETERS: usize = 16;

/// The best fit of `f` over the box `bounds` (module docs): the lowest
/// residual sum of squares among the fits of all parameters started from
/// `u0` and from the optimum of each sub-fit.
///
/// `f` returns the residuals at a point in fit coordinates (`None` where
/// the model cannot run); `step` the central-difference steps.
///
/// Errors: the start cannot be evaluated, or no minimisation of the full
/// set converged (the first failure's reason); more than
/// [`MAX_PARAMETERS`] parameters.
pub fn best_fit(
    f: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    u0: &[f64],
    step: &[f64],
    bounds: &Bounds,
) -> Result<Found, String> {
    let p = u0.len();
    if p == 0 || p > MAX_PARAMETERS {
        return Err(format!("{p} parameters: the fit takes 1 to {MAX_PARAMETERS}"));
    }
    let u0 = bounds.clamp(u0);
    let boxed = |u: &[f64]| f(&bounds.clamp(u));
    let search = Search {
        f: &boxed,
        u0: &u0,
        step,
        bounds,
        memo: RefCell::new(HashMap::new()),
        count: RefCell::new(0),
        from_start: RefCell::new(f64::INFINITY),
        failure: RefCell::new(None),
    };
    let full = (1u32 << p) - 1;
    let best = search.solve(full);
    let minimisations = *search.count.borrow();
    let rss_from_start = *search.from_start.borrow();
    match best {
        Some(x) => {
            // The full problem's residuals and Jacobian at the best point.
            let residuals = boxed(&x).ok_or("the model cannot be evaluated at the best fit")?;
            let jacobian = one_sided_where_needed(&boxed, &x, &residuals, step)
                .ok_or("the model cannot be evaluated around the best fit (its Jacobian)")?;
            let fit = Fit {
                x,
                residuals,
                jacobian,
                evaluations: 0,
                termination: "best of the sub-fit search".into(),
            };
            Ok(Found {
                fit,
                rss_from_start,
                minimisations,
            })
        }
        None => Err(search
            .failure
            .borrow()
            .clone()
            .unwrap_or_else(|| "the least-squares fit did not converge".into())),
    }
}

/// The Jacobian at `x` (residuals `r0`) by central differences, or by the
/// one-sided difference away from a side where the model cannot run (a
/// rule between fields the fit stopped against, say a chamber volume that
/// no longer exceeds what the plunger sweeps); `None` when neither side of
/// some parameter runs.
fn one_sided_where_needed(
    f: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    x: &[f64],
    r0: &[f64],
    step: &[f64],
) -> Option<nalgebra::DMatrix<f64>> {
    let ok = |r: Option<Vec<f64>>| r.filter(|r| r.len() == r0.len() && r.iter().all(|v| v.is_finite()));
    let mut jac = nalgebra::DMatrix::zeros(r0.len(), x.len());
    for j in 0..x.len() {
        let at = |d: f64| {
            let mut y = x.to_vec();
            y[j] += d;
            ok(f(&y))
        };
        let (h, rp, rm) = (step[j], at(step[j]), at(-step[j]));
        for i in 0..r0.len() {
            jac[(i, j)] = match (&rp, &rm) {
                (Some(p), Some(m)) => (p[i] - m[i]) / (2.0 * h),
                (Some(p), None) => (p[i] - r0[i]) / h,
                (None, Some(m)) => (r0[i] - m[i]) / h,
                (None, None) => return None,
            };
        }
    }
    Some(jac)
}

/// Per subset of the parameters: the best point (full coordinates) and
/// its RSS, or none when the fit failed.
type Memo = RefCell<HashMap<u32, Option<(Vec<f64>, f64)>>>;

struct Search<'a> {
    f: &'a dyn Fn(&[f64]) -> Option<Vec<f64>>,
    u0: &'a [f64],
    step: &'a [f64],
    bounds: &'a Bounds,
    /// Best point (full coordinates) and its RSS per subset.
    memo: Memo,
    count: RefCell<usize>,
    from_start: RefCell<f64>,
    failure: RefCell<Option<String>>,
}

impl Search<'_> {
    /// The best point of the fit of the parameters in `mask` (the others at
    /// the start), in full coordinates.
    fn solve(&self, mask: u32) -> Option<Vec<f64>> {
        self.solve_rss(mask).map(|(x, _)| x)
    }

    fn solve_rss(&self, mask: u32) -> Option<(Vec<f64>, f64)> {
        if let Some(done) = self.memo.borrow().get(&mask) {
            return done.clone();
        }
        let idx: Vec<usize> = (0..self.u0.len()).filter(|i| mask & (1 << i) != 0).collect();
        let mut starts: Vec<Vec<f64>> = vec![self.u0.to_vec()];
        if idx.len() > 1 {
            for &j in &idx {
                if let Some((x, _)) = self.solve_rss(mask & !(1 << j))
                    && !starts.contains(&x)
                {
                    starts.push(x);
                }
            }
        }
        let full = mask.count_ones() as usize == self.u0.len();
        let mut best: Option<(Vec<f64>, f64)> = None;
        for (k, start) in starts.iter().enumerate() {
            let embed = |v: &[f64]| {
                let mut u = start.clone();
                for (i, vi) in idx.iter().zip(v) {
                    u[*i] = *vi;
                }
                u
            };
            let g = |v: &[f64]| (self.f)(&embed(v));
            let v0: Vec<f64> = idx.iter().map(|&i| start[i]).collect();
            let st: Vec<f64> = idx.iter().map(|&i| self.step[i]).collect();
            *self.count.borrow_mut() += 1;
            match lsq::least_squares(g, &v0, &st) {
                Ok(fit) => {
                    let x = self.bounds.clamp(&embed(&fit.x));
                    let r = rss(&fit.residuals);
                    if full && k == 0 {
                        *self.from_start.borrow_mut() = r;
                    }
                    if best.as_ref().is_none_or(|(_, b)| r < *b) {
                        best = Some((x, r));
                    }
                }
                Err(e) => {
                    if full {
                        self.failure.borrow_mut().get_or_insert(e);
                    }
                }
            }
        }
        self.memo.borrow_mut().insert(mask, best.clone());
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The best fit lies at or below every sub-fit's minimum (each is a
    /// point of the full space), and the count of minimisations is the
    /// family's: two single fits, the pair from the start and from each.
    #[test]
    fn the_search_returns_no_worse_than_any_sub_fit() {
        // r = (x0 - 1)^2-ish bowl in x0, and x1 whose fit alone from the
        // start is trivial: the best fit must reach the exact optimum.
        let f = |u: &[f64]| Some(vec![u[0] - 1.0, 10.0 * (u[1] - u[0] * u[0]), 0.1 * u[1]]);
        let b = Bounds {
            lo: vec![-5.0, -5.0],
            hi: vec![5.0, 5.0],
        };
        let found = best_fit(&f, &[-1.2, 1.0], &[1e-7, 1e-7], &b).unwrap();
        // Every sub-fit's minimum (x0 alone at x1 = 1; x1 alone at x0 = -1.2)
        // is a point of the full space: the best full fit is below both.
        let sub0 = lsq::least_squares(|v: &[f64]| f(&[v[0], 1.0]), &[-1.2], &[1e-7]).unwrap();
        let sub1 = lsq::least_squares(|v: &[f64]| f(&[-1.2, v[0]]), &[1.0], &[1e-7]).unwrap();
        assert!(found.rss() <= rss(&sub0.residuals) + 1e-12);
        assert!(found.rss() <= rss(&sub1.residuals) + 1e-12);
        assert_eq!(found.minimisations, 2 + 3);
    }

    #[test]
    fn a_bound_stops_the_fit_on_it_without_stalling_the_others() {
        // The unconstrained optimum has u0 = 3, beyond the bound 2; u1's
        // optimum (4) does not depend on u0. A model that refused to run
        // beyond the bound would be a penalty wall; the clamped one is flat.
        let f = |u: &[f64]| (u[0] <= 2.0).then(|| vec![u[0] - 3.0, u[1] - 4.0, 0.5 * (u[1] - 4.0)]);
        let b = Bounds {
            lo: vec![-10.0, -10.0],
            hi: vec![2.0, 10.0],
        };
        let found = best_fit(&f, &[0.0, 0.0], &[1e-6, 1e-6], &b).unwrap();
        assert!((found.fit.x[0] - 2.0).abs() < 1e-9, "{:?}", found.fit.x);
        assert!((found.fit.x[1] - 4.0).abs() < 1e-6, "{:?}", found.fit.x);
        assert!((found.rss() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_joint_fit_stuck_in_a_local_minimum_is_replaced_by_the_sub_fits_start() {
        // r = (10 (u0 - 2), sin(u1 - 5 (u0 - 2)), 0.1 u1): the global minimum
        // is (2, 0), rss 0. From (0, 0) the joint Gauss-Newton step keeps the
        // phase u1 - 5 (u0 - 2) near a zero of the sine while u0 moves to 2,
        // so u1 lands near 10 and the fit stops in the well at u1 = 3 pi
        // (rss 0.88). The sub-fit of u0 alone (u1 held at 0) reaches (2, 0),
        // and the joint fit from there stays.
        let f = |u: &[f64]| Some(vec![10.0 * (u[0] - 2.0), (u[1] - 5.0 * (u[0] - 2.0)).sin(), 0.1 * u[1]]);
        let b = Bounds {
            lo: vec![-50.0, -50.0],
            hi: vec![50.0, 50.0],
        };
        let u0 = [0.0, 0.0];
        let plain = lsq::least_squares(f, &u0, &[1e-7, 1e-7]).unwrap();
        assert!(rss(&plain.residuals) > 0.5, "the trap: {:?}", plain.x);
        let found = best_fit(&f, &u0, &[1e-7, 1e-7], &b).unwrap();
        assert!((found.rss_from_start - rss(&plain.residuals)).abs() < 1e-9);
        assert!(found.rss() < 1e-20, "{}", found.rss());
        assert!(
            (found.fit.x[0] - 2.0).abs() < 1e-9 && found.fit.x[1].abs() < 1e-9,
            "{:?}",
            found.fit.x
        );
    }
}
