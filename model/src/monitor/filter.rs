//! The Kalman filter of the health parameters: a random walk of
//! [`PARAMETERS`] states observed through one scalar reading a sample,
//! and one more state, [`NOISE`]: the second sensor's noise as the probe's
//! lag has filtered it, coloured by the lag (see below).
//!
//! ```text
//! predict:  P <- P + Q dt                    (Q diagonal: the drift per hour)
//! update:   S = H P H' + R,  K = P H' / S,  theta <- theta + K nu,
//!           P <- P - K H P                  (then symmetrised)
//! ```
//!
//! **The lag's noise.** The probe's prediction is the lag of the second
//! sensor's temperature, and with it the lag of that temperature's noise
//! `n` (white, of variance `sigma_k^2` at reading `k`). The lag steps
//! `x_k = p x_(k-1) + c (n_k + n_(k-1))` (the midpoint rule, `c = (1 - p) /
//! 2`, `p = e^(-h / tau)`): its stationary variance is `sigma^2 (1 - p) /
//! 2`, and successive values share the lag's memory. For a slow probe the
//! share is a vanishing variance; for a probe whose time constant is
//! comparable with the readings' period it is a noise of the probe's
//! innovation comparable with the probe's own, correlated from one probe
//! reading to the next: taken as white it would make the innovations
//! correlated and their variance wrong. Written as `x_k = e_k + c n_k` it
//! is a Markov state `e_k = p e_(k-1) + c (1 + p) n_(k-1)` ([`Self::fade`]
//! at each step, of process noise `c^2 (1 + p)^2 sigma_(k-1)^2`) plus the
//! white `c n_k` of the reading at hand, which joins the probe's reading's
//! noise. That share drives `e` at the next step too: after an update the
//! next step is [`Self::fade_correlated`]. The filter carries `e`, so the
//! probe's innovations stay white whatever the probe's time constant.
//!
//! Cost: about 80 multiply-adds and one division per update.

use super::signature::PARAMETERS;
use crate::scalar::Real;

/// The lag's noise state: its index in the filter's states.
pub const NOISE: usize = PARAMETERS;

/// The filter's states: the health parameters and the lag's noise.
pub const STATES: usize = PARAMETERS + 1;

/// An update as the step after it needs it ([`HealthFilter::fade_correlated`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// The update's Jacobian.
    pub h: [f32; STATES],
    /// The variance of its measurement noise.
    pub r: f32,
    /// Its residual after the update, `z - H x`.
    pub residual: f32,
}

/// Estimates and covariance of the health parameters and of the lag's
/// noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HealthFilter {
    theta: [f32; STATES],
    p: [[f32; STATES]; STATES],
    prior: [f32; PARAMETERS],
    q: [f32; PARAMETERS],
}

impl HealthFilter {
    /// At zero, each parameter with its prior standard deviation `prior`
    /// and the random walk's variance per hour `q`; the lag's noise at
    /// zero, known.
    pub fn new(prior: [f32; PARAMETERS], q: [f32; PARAMETERS]) -> Self {
        let mut p = [[0.0; STATES]; STATES];
        for i in 0..PARAMETERS {
            p[i][i] = prior[i] * prior[i];
        }
        HealthFilter {
            theta: [0.0; STATES],
            p,
            prior,
            q,
        }
    }

    /// The estimates of the health parameters.
    pub fn theta(&self) -> [f32; PARAMETERS] {
        let mut theta = [0.0; PARAMETERS];
        theta.copy_from_slice(&self.theta[..PARAMETERS]);
        theta
    }

    /// The estimate of the lag's noise \[K\].
    pub fn noise(&self) -> f32 {
        self.theta[NOISE]
    }

    /// The standard deviation of state `i`.
    pub fn sd(&self, i: usize) -> f32 {
        let v = self.p[i][i];
        if v > 0.0 { <f32 as Real>::sqrt(v) } else { 0.0 }
    }

    /// The prior standard deviation of parameter `i`.
    pub fn prior(&self, i: usize) -> f32 {
        self.prior[i]
    }

    /// The covariance.
    pub fn covariance(&self) -> &[[f32; STATES]; STATES] {
        &self.p
    }

    /// `H P H'` for the Jacobian `h`.
    pub fn innovation_variance(&self, h: &[f32; STATES]) -> f32 {
        let mut s = 0.0;
        for i in 0..STATES {
            for j in 0..STATES {
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
    /// health parameters (zero when `s` is not positive).
    pub fn update(&mut self, h: &[f32; STATES], nu: f32, s: f32) -> [f32; PARAMETERS] {
        let mut change = [0.0; PARAMETERS];
        if !(s > 0.0) {
            return change;
        }
        let mut ph = [0.0f32; STATES];
        for (i, row) in self.p.iter().enumerate() {
            ph[i] = row.iter().zip(h).map(|(a, b)| a * b).sum();
        }
        let inv = 1.0 / s;
        for (i, (theta, k)) in self.theta.iter_mut().zip(&ph).enumerate() {
            let c = k * inv * nu;
            *theta += c;
            if i < PARAMETERS {
                change[i] = c;
            }
        }
        for i in 0..STATES {
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

    /// The update of the lag's noise alone, the parameters held (they
    /// enter as considered, not estimated: a Schmidt update): while the
    /// tests hold the parameters, the noise still follows the readings,
    /// or the innovations would carry its correlation. Returns the
    /// residual after the update.
    pub fn update_noise(&mut self, h: &[f32; STATES], nu: f32, s: f32) -> f32 {
        if !(s > 0.0) {
            return nu;
        }
        let mut ph = [0.0f32; STATES];
        for (i, row) in self.p.iter().enumerate() {
            ph[i] = row.iter().zip(h).map(|(a, b)| a * b).sum();
        }
        let k = ph[NOISE] / s;
        self.theta[NOISE] += k * nu;
        for (j, phj) in ph.iter().enumerate() {
            if j != NOISE {
                let v = self.p[NOISE][j] - k * phj;
                self.p[NOISE][j] = v;
                self.p[j][NOISE] = v;
            }
        }
        let v = self.p[NOISE][NOISE] - k * ph[NOISE];
        self.p[NOISE][NOISE] = if v > 0.0 { v } else { 0.0 };
        nu - h[NOISE] * k * nu
    }

    /// State `i` as a Gauss-Markov process over a step whose
    /// correlation is `phi` (in `0..=1`): its estimate and its covariances
    /// decay by `phi`, its variance tends to `stationary`.
    pub fn decay(&mut self, i: usize, phi: f32, stationary: f32) {
        self.fade(i, phi, (1.0 - phi * phi) * stationary);
    }

    /// State `i` through one step of a first-order lag of factor `phi` (in
    /// `0..=1`) driven by a white noise of variance `q`: its estimate and
    /// its covariances decay by `phi`, its variance by `phi^2`, plus `q`.
    pub fn fade(&mut self, i: usize, phi: f32, q: f32) {
        self.theta[i] *= phi;
        for j in 0..STATES {
            self.p[i][j] *= phi;
            self.p[j][i] *= phi;
        }
        self.p[i][i] += q;
    }

    /// [`Self::fade`] of state `i` the step after an update `last` whose
    /// measurement noise was correlated with this
    /// step's process noise by `m` (`E[w v]`): the process noise is split
    /// into its part `m / r v` (the update's measurement noise, `v = z - H
    /// x`, known through the residual) and the rest, of variance `q - m^2
    /// / r`, independent of every reading so far (Simon, *Optimal State
    /// Estimation*, 7.1).
    pub fn fade_correlated(&mut self, i: usize, phi: f32, q: f32, m: f32, last: &Measured) {
        let Measured { h, r, residual } = last;
        let (r, residual) = (*r, *residual);
        if !(r > 0.0) || !m.is_finite() || !residual.is_finite() {
            self.fade(i, phi, q);
            return;
        }
        let g = m / r;
        // The state's row of the transition, `phi e_i - g h`.
        let mut row = [0.0f32; STATES];
        for (f, h) in row.iter_mut().zip(h) {
            *f = -g * h;
        }
        row[i] += phi;
        let mut rp = [0.0f32; STATES];
        for (j, v) in rp.iter_mut().enumerate() {
            *v = row.iter().zip(&self.p).map(|(f, p)| f * p[j]).sum();
        }
        let rpr: f32 = rp.iter().zip(&row).map(|(a, b)| a * b).sum();
        for (j, v) in rp.iter().enumerate() {
            if j != i {
                self.p[i][j] = *v;
                self.p[j][i] = *v;
            }
        }
        let v = rpr + q - m * g;
        self.p[i][i] = if v > 0.0 { v } else { 0.0 };
        self.theta[i] = phi * self.theta[i] + g * residual;
    }

    /// The lag's noise known to be zero with variance `v` (the lag set at
    /// rest), uncorrelated with the parameters.
    pub fn restart_noise(&mut self, v: f32) {
        self.theta[NOISE] = 0.0;
        for j in 0..STATES {
            self.p[NOISE][j] = 0.0;
            self.p[j][NOISE] = 0.0;
        }
        self.p[NOISE][NOISE] = v;
    }

    /// Projects the estimate onto `lo <= theta_i <= hi` when it has left
    /// it: every state moves by its regression on `theta_i`,
    /// `-P[:, i] / P[i][i] (theta_i - bound)` (the estimate projection of
    /// D. Simon and T. L. Chia, "Kalman filtering with state equality
    /// constraints", IEEE Trans. AES 38(1), 2002, with `W = P^-1`), so that
    /// the parameters correlated with it go back with it; the covariance
    /// stands. Returns the change of the health parameters (zero inside
    /// the bounds).
    pub fn project(&mut self, i: usize, lo: f32, hi: f32) -> [f32; PARAMETERS] {
        let mut change = [0.0; PARAMETERS];
        let v = self.theta[i];
        let excess = v - if v > hi {
            hi
        } else if v < lo {
            lo
        } else {
            v
        };
        let pii = self.p[i][i];
        // Inside the bounds, NaN, or a parameter the readings fixed exactly.
        if !(excess != 0.0 && pii > 0.0) {
            return change;
        }
        let k = excess / pii;
        // `j` indexes the estimate, the covariance's column and the
        // parameters' change alike (the change only below PARAMETERS).
        #[allow(clippy::needless_range_loop)]
        for j in 0..STATES {
            let c = if j == i { -excess } else { -self.p[j][i] * k };
            self.theta[j] += c;
            if j < PARAMETERS {
                change[j] = c;
            }
        }
        change
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
        for j in 0..STATES {
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
        let h = [3.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let (nu, r) = (1.5f32, 4.0f32);
        let s = f.innovation_variance(&h) + r;
        assert_eq!(s, 40.0);
        let change = f.update(&h, nu, s);
        assert_eq!(change, f.theta());
        assert_eq!(f.noise(), 0.0);
        assert!((f.theta()[0] - 4.0 * 3.0 * 1.5 / 40.0).abs() < 1e-6);
        assert!((f.covariance()[0][0] - 4.0 * 4.0 / 40.0).abs() < 1e-6);
        assert_eq!(f.theta()[1], 0.0);
    }

    /// A Gauss-Markov parameter forgets: its estimate decays, its variance
    /// tends to the stationary one, its correlations fade.
    #[test]
    fn a_projection_takes_the_correlated_parameters_back_along() {
        let mut f = HealthFilter::new([0.1, 0.05, 1.0, 0.5, 1.0], [0.0; PARAMETERS]);
        // One reading that cannot tell parameter 0 from parameter 3: their
        // estimates become correlated (negatively, for equal signs).
        let mut h = [0.0; STATES];
        h[0] = 1.0;
        h[3] = 1.0;
        let s = f.innovation_variance(&h) + 1e-4;
        f.update(&h, 5.0, s);
        let before = f.theta();
        assert!(before[3] > 1.0, "{before:?}");
        let change = f.project(3, -1.0, 1.0);
        let after = f.theta();
        assert!((after[3] - 1.0).abs() < 1e-6, "{after:?}");
        // The regression of parameter 0 on parameter 3, P[0][3] / P[3][3],
        // is negative after such a reading: it moves the other way.
        let p = f.covariance();
        let expected = -p[0][3] / p[3][3] * (before[3] - 1.0);
        assert!(expected > 0.0);
        assert!(
            (change[0] - expected).abs() < 1e-5 * expected.abs().max(1.0),
            "{change:?} {expected}"
        );
        assert!((after[0] - before[0] - expected).abs() < 1e-5, "{after:?}");
        // Inside the bounds nothing moves.
        assert_eq!(f.project(3, -1.0, 1.0), [0.0; PARAMETERS]);
        assert_eq!(f.theta(), after);
    }

    #[test]
    fn decay_forgets_towards_the_stationary_variance() {
        let mut f = HealthFilter::new([1.0, 0.5, 1.0, 1.0, 0.1], [0.0; PARAMETERS]);
        let h = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
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
            let h = [1.0 + t.sin(), t.cos(), 1.0, (0.5 * t).sin(), (0.3 * t).cos(), 0.0];
            let y: f32 = h[..PARAMETERS].iter().zip(&truth).map(|(a, b)| a * b).sum();
            let s = f.innovation_variance(&h) + 1e-4;
            let pred: f32 = h[..PARAMETERS].iter().zip(&f.theta()).map(|(a, b)| a * b).sum();
            f.update(&h, y - pred, s);
        }
        for (got, want) in f.theta().iter().zip(&truth) {
            assert!((got - want).abs() < 1e-3, "{:?}", f.theta());
        }
    }

    /// The second sensor's white noise through the midpoint lag, read by
    /// the probe every second step: with the lag's noise as a state (its
    /// correlated step after each update), the innovations are white and
    /// of unit variance for a lag as fast as the readings.
    #[test]
    fn the_lags_noise_leaves_white_innovations() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut normal = || {
            let mut u = || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                ((seed >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (libm::sqrt(-2.0 * libm::log(a)) * libm::cos(2.0 * core::f64::consts::PI * b)) as f32
        };
        for p in [0.37f32, 0.82, 0.98] {
            let (sigma, r) = (1.0f32, 0.05f32);
            let c = 0.5 * (1.0 - p);
            let drive = c * (1.0 + p);
            let mut f = HealthFilter::new([1e-3; PARAMETERS], [0.0; PARAMETERS]);
            f.restart_noise((1.0 - c) * (1.0 - c) * sigma * sigma);
            let mut n_prev = sigma * normal();
            let mut x = n_prev;
            let mut pending: Option<Measured> = None;
            let (mut s1, mut s2, mut lag1, mut last, mut count) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0u32);
            for k in 1..40_000 {
                let n = sigma * normal();
                x = p * x + c * (n + n_prev);
                n_prev = n;
                let q = drive * drive * sigma * sigma;
                match pending.take() {
                    Some(m) => f.fade_correlated(NOISE, p, q, -drive * c * sigma * sigma, &m),
                    None => f.fade(NOISE, p, q),
                }
                if k % 2 == 0 {
                    let mut h = [0.0; STATES];
                    h[NOISE] = -1.0;
                    let rr = r * r + c * c * sigma * sigma;
                    let nu = -x + r * normal() + f.noise();
                    let s = f.innovation_variance(&h) + rr;
                    let z = f64::from(nu / s.sqrt());
                    f.update(&h, nu, s);
                    pending = Some(Measured {
                        h,
                        r: rr,
                        residual: nu * rr / s,
                    });
                    s1 += z;
                    s2 += z * z;
                    lag1 += z * last;
                    last = z;
                    count += 1;
                }
            }
            let n = f64::from(count);
            let var = s2 / n - (s1 / n) * (s1 / n);
            let corr = lag1 / s2;
            assert!(
                (var - 1.0).abs() < 0.05 && corr.abs() < 0.03,
                "p {p}: variance {var}, lag-1 {corr}"
            );
        }
    }
}
