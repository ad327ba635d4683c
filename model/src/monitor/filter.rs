//! The Kalman filter of the health parameters: a random walk of
//! [`PARAMETERS`] states observed through one scalar reading a sample.
//!
//! ```text
//! predict:  P <- P + Q dt                    (Q diagonal: the drift per hour)
//! update:   S = H P H' + R,  K = P H' / S,  theta <- theta + K nu,
//!           P <- P - K H P                  (then symmetrised)
//! ```
//!
//! Cost: about 60 multiply-adds and one division per update.

use super::signature::PARAMETERS;
use crate::scalar::Real;

/// Estimates and covariance of the health parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HealthFilter {
    theta: [f32; PARAMETERS],
    p: [[f32; PARAMETERS]; PARAMETERS],
    prior: [f32; PARAMETERS],
    q: [f32; PARAMETERS],
}

impl HealthFilter {
    /// At zero, each parameter with its prior standard deviation `prior`
    /// and the random walk's variance per hour `q`.
    pub fn new(prior: [f32; PARAMETERS], q: [f32; PARAMETERS]) -> Self {
        let mut p = [[0.0; PARAMETERS]; PARAMETERS];
        for i in 0..PARAMETERS {
            p[i][i] = prior[i] * prior[i];
        }
        HealthFilter {
            theta: [0.0; PARAMETERS],
            p,
            prior,
            q,
        }
    }

    /// The estimates.
    pub fn theta(&self) -> [f32; PARAMETERS] {
        self.theta
    }

    /// The standard deviation of parameter `i`.
    pub fn sd(&self, i: usize) -> f32 {
        let v = self.p[i][i];
        if v > 0.0 { <f32 as Real>::sqrt(v) } else { 0.0 }
    }

    /// The prior standard deviation of parameter `i`.
    pub fn prior(&self, i: usize) -> f32 {
        self.prior[i]
    }

    /// The covariance.
    pub fn covariance(&self) -> &[[f32; PARAMETERS]; PARAMETERS] {
        &self.p
    }

    /// `H P H'` for the Jacobian `h`.
    pub fn innovation_variance(&self, h: &[f32; PARAMETERS]) -> f32 {
        let mut s = 0.0;
        for i in 0..PARAMETERS {
            for j in 0..PARAMETERS {
                s += h[i] * self.p[i][j] * h[j];
            }
        }
        s
    }

    /// The random walk over `hours`.
    pub fn predict(&mut self, hours: f32) {
        for i in 0..PARAMETERS {
            self.p[i][i] += self.q[i] * hours;
        }
    }

    /// The update with the innovation `nu` of variance `s` (`H P H' + R`,
    /// positive) through the Jacobian `h`; returns the change of the
    /// estimates (zero when `s` is not positive).
    pub fn update(&mut self, h: &[f32; PARAMETERS], nu: f32, s: f32) -> [f32; PARAMETERS] {
        let mut change = [0.0; PARAMETERS];
        if !(s > 0.0) {
            return change;
        }
        let mut ph = [0.0f32; PARAMETERS];
        for (i, row) in self.p.iter().enumerate() {
            ph[i] = row.iter().zip(h).map(|(a, b)| a * b).sum();
        }
        let inv = 1.0 / s;
        for ((theta, k), c) in self.theta.iter_mut().zip(&ph).zip(change.iter_mut()) {
            *c = k * inv * nu;
            *theta += *c;
        }
        for i in 0..PARAMETERS {
            for j in 0..=i {
                let v = self.p[i][j] - ph[i] * ph[j] * inv;
                self.p[i][j] = v;
                self.p[j][i] = v;
            }
            if !(self.p[i][i] > 0.0) {
                self.p[i][i] = 0.0;
            }
        }
        change
    }

    /// Parameter `i` as a Gauss-Markov process over a step whose
    /// correlation is `phi` (in `0..=1`): its estimate and its covariances
    /// decay by `phi`, its variance tends to `stationary`.
    pub fn decay(&mut self, i: usize, phi: f32, stationary: f32) {
        self.theta[i] *= phi;
        for j in 0..PARAMETERS {
            self.p[i][j] *= phi;
            self.p[j][i] *= phi;
        }
        self.p[i][i] += (1.0 - phi * phi) * stationary;
    }

    /// Moves parameter `i` by `by` (a change isolated and sized by the
    /// tests).
    pub fn shift(&mut self, i: usize, by: f32) {
        if by.is_finite() {
            self.theta[i] += by;
        }
    }

    /// Reopens parameter `i` to the standard deviation `sd`, its
    /// correlations with the others dropped: a change was isolated in it,
    /// and the filter is to find its new value.
    pub fn reopen(&mut self, i: usize, sd: f32) {
        for j in 0..PARAMETERS {
            self.p[i][j] = 0.0;
            self.p[j][i] = 0.0;
        }
        self.p[i][i] = sd * sd;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One update is the closed-form Bayesian posterior of a scalar
    /// Gaussian: `theta = P h nu / (h^2 P + R)`, `P' = P R / (h^2 P + R)`.
    #[test]
    fn one_update_is_the_gaussian_posterior() {
        let mut f = HealthFilter::new([2.0, 1.0, 1.0, 1.0, 1.0], [0.0; PARAMETERS]);
        let h = [3.0, 0.0, 0.0, 0.0, 0.0];
        let (nu, r) = (1.5f32, 4.0f32);
        let s = f.innovation_variance(&h) + r;
        assert_eq!(s, 40.0);
        let change = f.update(&h, nu, s);
        assert_eq!(change, f.theta());
        assert!((f.theta()[0] - 4.0 * 3.0 * 1.5 / 40.0).abs() < 1e-6);
        assert!((f.covariance()[0][0] - 4.0 * 4.0 / 40.0).abs() < 1e-6);
        assert_eq!(f.theta()[1], 0.0);
    }

    /// A Gauss-Markov parameter forgets: its estimate decays, its variance
    /// tends to the stationary one, its correlations fade.
    #[test]
    fn decay_forgets_towards_the_stationary_variance() {
        let mut f = HealthFilter::new([1.0, 0.5, 1.0, 1.0, 0.1], [0.0; PARAMETERS]);
        let h = [1.0, 0.0, 0.0, 0.0, 1.0];
        let s = f.innovation_variance(&h) + 0.01;
        f.update(&h, 0.5, s);
        assert!(f.covariance()[0][4] < 0.0);
        for _ in 0..400 {
            f.decay(4, 0.99, 0.04);
        }
        assert!(f.theta()[4].abs() < 0.02 * 0.5);
        assert!((f.covariance()[4][4] - 0.04).abs() < 1e-3, "{}", f.covariance()[4][4]);
        assert!(f.covariance()[0][4].abs() < 1e-3);
    }

    /// Repeated readings of one parameter through a changing Jacobian
    /// converge on it with the least-squares variance.
    #[test]
    fn converges_on_a_constant() {
        let mut f = HealthFilter::new([1.0; PARAMETERS], [0.0; PARAMETERS]);
        let truth = [0.2f32, -0.1, 0.05, 0.3, -0.2];
        for k in 0..2000 {
            let t = k as f32 * 0.01;
            let h = [1.0 + t.sin(), t.cos(), 1.0, (0.5 * t).sin(), (0.3 * t).cos()];
            let y: f32 = h.iter().zip(&truth).map(|(a, b)| a * b).sum();
            let s = f.innovation_variance(&h) + 1e-4;
            let pred: f32 = h.iter().zip(&f.theta()).map(|(a, b)| a * b).sum();
            f.update(&h, y - pred, s);
        }
        for (got, want) in f.theta().iter().zip(&truth) {
            assert!((got - want).abs() < 1e-3, "{:?}", f.theta());
        }
    }
}
