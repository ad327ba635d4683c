//! Asymptotic expansion of the equilibrium (paper section 3, Eqs. 11-32;
//! `docs/model.md` section 5).
//!
//! `Phi(A) = (dp + A^2 - A sqrt(4 dp + A^2)) A_p / c` (Eq. 16, with the
//! plunger area) and `x = Phi(A(t)) - x0` (Eq. 17). About a reference
//! `A0 = A(t0)`:
//!
//! ```text
//! x(0) = Phi(A0) - x0                                 (19)
//! x(1) = Phi'(A0) A1                                  (20)
//! x(2) = Phi'(A0) A2 + Phi''(A0) A1^2 / 2             (21)
//! ```
//!
//! Two readings of `A1`, `A2` (and of `rho1`, `rho2` in the flow terms):
//! * [`Reading::Temperature`]: Taylor in temperature,
//!   `A1 = A'(t0) (t - t0)`, `A2 = A''(t0) (t - t0)^2 / 2`;
//! * [`Reading::Property`]: expansion in the property itself,
//!   `A1 = A(t) - A0` exactly, `A2 = 0`.
//!
//! Closed forms (with `a = A / sqrt(dp)`, `s = sqrt(a^2 + 4)`,
//! `q = 2 / (a + s)`, `k = A_p / c`), free of cancellation:
//!
//! ```text
//! Phi   = k dp (2 q^2 - 1)
//! Phi'  = -4 k sqrt(dp) q^2 / s            (< 0: x falls as A grows)
//! Phi'' =  4 k q^2 (2 s + a) / s^3         (> 0)
//! ```
//!
//! The expansion describes the branch between the stops; the series value
//! is reported unclamped and clamped to the stops.

use crate::equilibrium::{
    Stop, a_derivatives, a_derivatives_at, a_parameter, a_slope_at, branch_fraction, clamp_to_stops,
};
use crate::error::{ModelError, finite};
use crate::fluid::{Derivatives, FluidPoint};
use crate::params::Params;
use crate::scalar::Float;

/// Which quantity the small parameter expands (`docs/model.md` section 5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reading {
    /// Taylor series in `t - t0`.
    Temperature,
    /// Series in `A - A0` (and `rho - rho0`), exact first-order increments.
    Property,
}

/// `Phi(A)`, `Phi'(A)`, `Phi''(A)` [m, m/sqrt(Pa), m/Pa].
pub fn phi_derivatives<T: Float>(params: &Params<T>, a: T) -> Derivatives<T> {
    let (value, d1, k, q2, s, ah) = phi_parts(params, a);
    let (two, four) = (T::from_f64(2.0), T::from_f64(4.0));
    Derivatives {
        value,
        d1,
        d2: four * k * q2 * (two * s + ah) / (s * s * s),
    }
}

/// `Phi(A)` and `Phi'(A)` alone: [`phi_derivatives`]' first two, the same
/// operations and values.
#[inline]
pub fn phi_slope<T: Float>(params: &Params<T>, a: T) -> (T, T) {
    let (value, d1, ..) = phi_parts(params, a);
    (value, d1)
}

/// `Phi`, `Phi'`, the compliance `k`, `q^2`, `s` ([`branch_fraction`])
/// and `A / sqrt(dp)`.
#[inline(always)]
fn phi_parts<T: Float>(params: &Params<T>, a: T) -> (T, T, T, T, T, T) {
    let dp = params.pressure_drop;
    let k = params.plunger.compliance();
    let sqrt_dp = dp.sqrt();
    let ah = a / sqrt_dp;
    let (q, s) = branch_fraction(ah);
    let q2 = q * q;
    let two = T::from_f64(2.0);
    let four = T::from_f64(4.0);
    (k * dp * (two * q2 - T::ONE), -four * k * sqrt_dp * q2 / s, k, q2, s, ah)
}

/// `Phi(A)` of Eq. (16) \[m\].
#[inline]
pub fn phi<T: Float>(params: &Params<T>, a: T) -> T {
    phi_derivatives(params, a).value
}

/// The terms of the series at one temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terms<T> {
    /// Temperature \[C\].
    pub temperature: T,
    /// `A1`, `A2` of the chosen reading [sqrt(Pa)].
    pub a_terms: [T; 2],
    /// `rho1`, `rho2` [kg/m^3].
    pub rho_terms: [T; 2],
    /// `x(0)`, `x(1)`, `x(2)` \[m\] (Eqs. 19-21).
    pub x: [T; 3],
    /// `Q_throt(0..2)` [m^3/s] (Eqs. 25-26 and the second order).
    pub q_throt: [T; 3],
    /// `Q_a(0..2)` [m^3/s] (Eq. 14, expanded in `A` and `rho`).
    pub q_branch: [T; 3],
    /// `Q0(0..2) = 2 Q_a(k) + Q_throt(k)` [m^3/s] (Eqs. 28-29).
    pub q_total: [T; 3],
    stroke: T,
}

impl<T: Float> Terms<T> {
    fn sum(terms: &[T; 3], order: usize) -> T {
        let mut s = T::ZERO;
        for t in terms.iter().take(order.min(2) + 1) {
            s += *t;
        }
        s
    }

    /// Series displacement up to `order` (0, 1 or 2), without stops \[m\].
    pub fn x_series(&self, order: usize) -> T {
        Self::sum(&self.x, order)
    }

    /// Series displacement clamped to the stops \[m\].
    pub fn x(&self, order: usize) -> (T, Stop) {
        clamp_to_stops(self.x_series(order), self.stroke)
    }

    /// Series window flow up to `order` [m^3/s].
    pub fn q_throt_series(&self, order: usize) -> T {
        Self::sum(&self.q_throt, order)
    }

    /// Series branch flow up to `order` [m^3/s].
    pub fn q_branch_series(&self, order: usize) -> T {
        Self::sum(&self.q_branch, order)
    }

    /// Series total flow up to `order` [m^3/s].
    pub fn q_total_series(&self, order: usize) -> T {
        Self::sum(&self.q_total, order)
    }
}

/// An expansion about a reference temperature `t0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Expansion<T> {
    params: Params<T>,
    /// Reference temperature \[C\].
    pub t0: T,
    /// The reading of `A1`, `A2`.
    pub reading: Reading,
    /// `A(t0)`, `A'(t0)`, `A''(t0)`.
    pub a0: Derivatives<T>,
    /// `rho(t0)`, `rho'(t0)`, `rho''(t0)`.
    pub rho0: Derivatives<T>,
    /// `Phi(A0)`, `Phi'(A0)`, `Phi''(A0)`.
    pub phi0: Derivatives<T>,
}

impl<T: Float> Expansion<T> {
    /// Prepares the expansion about `t0` \[C\].
    ///
    /// # Errors
    ///
    /// The oil model refuses `t0`, or `A` or its derivatives there are not
    /// finite ([`a_derivatives`], [`crate::fluid::Oil::density_derivatives`]).
    pub fn new(params: &Params<T>, t0: T, reading: Reading) -> Result<Self, ModelError> {
        let a0 = a_derivatives(params, t0)?;
        let rho0 = params.oil.density_derivatives(t0)?;
        Ok(Expansion {
            params: *params,
            t0,
            reading,
            a0,
            rho0,
            phi0: phi_derivatives(params, a0.value),
        })
    }

    /// The series terms at temperature `t` \[C\].
    ///
    /// # Errors
    ///
    /// `NonFinite("temperature")` for a `t` that is not finite; with
    /// [`Reading::Property`], the oil model refuses `t`
    /// ([`crate::fluid::Oil::state`]); `NonFinite("asymptotic term")` when a
    /// displacement or total-flow term is not finite.
    pub fn at(&self, t: T) -> Result<Terms<T>, ModelError> {
        let p = &self.params;
        let t = finite(t, "temperature")?;
        let half = T::from_f64(0.5);
        let dt = t - self.t0;
        let (a1, a2, r1, r2) = match self.reading {
            Reading::Temperature => (
                self.a0.d1 * dt,
                half * self.a0.d2 * dt * dt,
                self.rho0.d1 * dt,
                half * self.rho0.d2 * dt * dt,
            ),
            Reading::Property => {
                let fluid = p.oil.state(t)?;
                (
                    a_parameter(p, &fluid) - self.a0.value,
                    T::ZERO,
                    fluid.density - self.rho0.value,
                    T::ZERO,
                )
            }
        };
        let ph = &self.phi0;
        let x0 = ph.value - p.plunger.preload;
        let x1 = ph.d1 * a1;
        let x2 = ph.d1 * a2 + half * ph.d2 * a1 * a1;

        // rho^(-1/2) and its derivatives at rho0.
        let rho = self.rho0.value;
        let h0 = T::ONE / rho.sqrt();
        let h1 = -half * h0 / rho;
        let h2 = T::from_f64(0.75) * h0 / (rho * rho);

        // Window flow: eta pi d sqrt(2 dp) x rho^(-1/2)  (Eqs. 22-26).
        let w = p.slot.window_factor(p.pressure_drop);
        let qt0 = w * x0 * h0;
        let qt1 = w * (x1 * h0 + x0 * h1 * r1);
        let qt2 = w * (x2 * h0 + x1 * h1 * r1 + x0 * (h1 * r2 + half * h2 * r1 * r1));

        // Branch flow Q_a = K sqrt(dp) g(A) rho^(-1/2), g = q(A / sqrt(dp)),
        // K = C_d f sqrt(2): g' = -q / (s sqrt(dp)), g'' = q (s + a) / (dp s^3).
        let dp = p.pressure_drop;
        let sqrt_dp = dp.sqrt();
        let ah = self.a0.value / sqrt_dp;
        let (g0, s) = branch_fraction(ah);
        let g1 = -g0 / (s * sqrt_dp);
        let g2 = g0 * (s + ah) / (dp * s * s * s);
        let kq = p.orifice.discharge_coefficient * p.orifice.area() * T::from_f64(core::f64::consts::SQRT_2) * sqrt_dp;
        let qa0 = kq * g0 * h0;
        let qa1 = kq * (g1 * h0 * a1 + g0 * h1 * r1);
        let qa2 = kq
            * (g1 * h0 * a2 + g0 * h1 * r2 + half * g2 * h0 * a1 * a1 + g1 * h1 * a1 * r1 + half * g0 * h2 * r1 * r1);

        let two = T::from_f64(2.0);
        let terms = Terms {
            temperature: t,
            a_terms: [a1, a2],
            rho_terms: [r1, r2],
            x: [x0, x1, x2],
            q_throt: [qt0, qt1, qt2],
            q_branch: [qa0, qa1, qa2],
            q_total: [two * qa0 + qt0, two * qa1 + qt1, two * qa2 + qt2],
            stroke: p.plunger.stroke,
        };
        for v in terms.x.iter().chain(terms.q_total.iter()) {
            finite(*v, "asymptotic term")?;
        }
        Ok(terms)
    }
}

/// Temperature sensitivities at one temperature (Eqs. 30-31).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensitivity<T> {
    /// Temperature \[C\].
    pub temperature: T,
    /// `dx/dt = Phi'(A) dA/dt` of the free branch [m/K] (Eq. 31).
    pub dx_dt_branch: T,
    /// `dx/dt` of the plunger: the branch value between the stops, zero on a stop [m/K].
    pub dx_dt: T,
    /// `dQ_throt/dt` [m^3/(s K)] (Eq. 30), with the plunger's `x` and `dx/dt`.
    pub dq_throt_dt: T,
    /// Where the plunger rests.
    pub stop: Stop,
}

/// Sensitivities of the equilibrium to temperature at `t` \[C\] (Eqs. 30-31).
///
/// # Errors
///
/// The oil model refuses `t` ([`crate::fluid::Oil::point`]), or as
/// [`sensitivity_at`].
pub fn sensitivity<T: Float>(params: &Params<T>, t: T) -> Result<Sensitivity<T>, ModelError> {
    sensitivity_at(params, &params.oil.point(t)?)
}

/// As [`sensitivity`] from an evaluated [`FluidPoint`] (what the estimator
/// uses, sharing one Walther evaluation with the fluid state).
///
/// # Errors
///
/// As [`a_derivatives_at`], and `NonFinite` naming `dx/dt` or
/// `dQ_throt/dt` when one of them is not finite.
pub fn sensitivity_at<T: Float>(params: &Params<T>, point: &FluidPoint<T>) -> Result<Sensitivity<T>, ModelError> {
    let (dx_branch, dx, x, stop) = dx_dt_parts(params, point)?;
    let rho = &point.density;
    let w = params.slot.window_factor(params.pressure_drop);
    let inv_sqrt_rho = T::ONE / rho.value.sqrt();
    // Eq. (30): eta pi d sqrt(2 dp / rho) dx/dt - eta pi d x sqrt(2 dp) rho^(-3/2) rho' / 2
    let dq = w * inv_sqrt_rho * dx - w * x * T::from_f64(0.5) * inv_sqrt_rho / rho.value * rho.d1;
    Ok(Sensitivity {
        temperature: point.state.temperature,
        dx_dt_branch: finite(dx_branch, "dx/dt")?,
        dx_dt: dx,
        dq_throt_dt: finite(dq, "dQ_throt/dt")?,
        stop,
    })
}

/// [`sensitivity_at`]'s `dx/dt` alone [m/K] (0 on a stop), without the
/// throttle flow's sensitivity (a square root and two divisions, in
/// software on a core without an FPU): the same operations, the same
/// value.
///
/// # Errors
///
/// As [`sensitivity_at`], but for `dQ_throt/dt`, which is not formed.
pub fn dx_dt_at<T: Float>(params: &Params<T>, point: &FluidPoint<T>) -> Result<T, ModelError> {
    // As dx_dt_parts with the first derivatives alone: the second ones
    // (three divisions in software on a core without an FPU) go nowhere.
    let (a, da) = a_slope_at(params, point)?;
    let (phi, dphi) = phi_slope(params, a);
    let dx_branch = finite(dphi * da, "dx/dt")?;
    let (_, stop) = clamp_to_stops(phi - params.plunger.preload, params.plunger.stroke);
    Ok(if stop == Stop::Free { dx_branch } else { T::ZERO })
}

/// Eq. (31) at `point`: `dx/dt` on the branch and clamped to the stops (0
/// on one), with the clamped opening `x` \[m\] and its stop, what
/// [`sensitivity_at`] forms ([`dx_dt_at`] the same from the first
/// derivatives alone).
fn dx_dt_parts<T: Float>(params: &Params<T>, point: &FluidPoint<T>) -> Result<(T, T, T, Stop), ModelError> {
    let a = a_derivatives_at(params, point)?;
    let ph = phi_derivatives(params, a.value);
    let dx_branch = ph.d1 * a.d1;
    let (x, stop) = clamp_to_stops(ph.value - params.plunger.preload, params.plunger.stroke);
    Ok((dx_branch, if stop == Stop::Free { dx_branch } else { T::ZERO }, x, stop))
}

/// Verdict of the monotonicity test of Eq. (32) over a temperature range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Monotonicity<T> {
    /// `Phi'(A(t)) dA/dt` kept one strict sign at every sample: `t -> x(t)`
    /// is monotonic, so the equilibrium branch is unique (sufficient condition).
    pub monotonic: bool,
    /// Sign of `dx/dt` where monotonic (+1 rising, -1 falling, 0 otherwise).
    pub sign: i8,
    /// The sample where `|dx/dt|` is smallest (the closest to violating Eq. 32) \[C\].
    pub worst_temperature: T,
    /// `dx/dt` at that sample [m/K].
    pub worst_dx_dt: T,
    /// Samples evaluated.
    pub samples: u32,
}

/// The most samples [`monotonicity`] evaluates (bounds its cost).
pub const MAX_MONOTONICITY_SAMPLES: u32 = 100_000;

/// Checks Eq. (32), `Phi'(A(t)) dA/dt != 0` with one sign, on `samples`
/// evenly spaced temperatures of `[lo, hi]` \[C\] (clamped to
/// `2..=MAX_MONOTONICITY_SAMPLES`).
///
/// # Errors
///
/// `NonFinite("temperature")` for a bound that is not finite,
/// `OutOfRange("temperature interval")` unless `lo < hi`, and any sample's
/// error from [`sensitivity`] (the oil model refusing a temperature of the
/// range): the verdict needs every sample.
pub fn monotonicity<T: Float>(params: &Params<T>, lo: T, hi: T, samples: u32) -> Result<Monotonicity<T>, ModelError> {
    let (lo, hi) = (finite(lo, "temperature")?, finite(hi, "temperature")?);
    if !(hi > lo) {
        return Err(ModelError::OutOfRange("temperature interval"));
    }
    let n = samples.clamp(2, MAX_MONOTONICITY_SAMPLES);
    monotonicity_of((0..n).map(|i| {
        let frac = T::from_f64(i as f64 / (n - 1) as f64);
        let t = lo + (hi - lo) * frac;
        Ok((t, sensitivity(params, t)?.dx_dt_branch))
    }))
}

/// The Eq. (32) verdict over samples `(t [C], dx/dt [m/K])` of the
/// equilibrium branch, in temperature order: [`monotonicity`]'s tally,
/// for a caller that has the sensitivities another way (cached oil
/// points). No sample: not monotonic, `samples` 0.
///
/// # Errors
///
/// The first sample's error (the verdict needs every sample).
pub fn monotonicity_of<T: Float>(
    samples: impl Iterator<Item = Result<(T, T), ModelError>>,
) -> Result<Monotonicity<T>, ModelError> {
    let (mut worst_t, mut worst) = (T::ZERO, T::ZERO);
    let mut first = true;
    let (mut n, mut positive, mut negative) = (0u32, 0u32, 0u32);
    for sample in samples {
        let (t, d) = sample?;
        n += 1;
        if d > T::ZERO {
            positive += 1;
        } else if d < T::ZERO {
            negative += 1;
        }
        if first || d.abs() < worst.abs() {
            worst = d;
            worst_t = t;
            first = false;
        }
    }
    let monotonic = n > 0 && (positive == n || negative == n);
    let sign = if !monotonic {
        0
    } else if positive == n {
        1
    } else {
        -1
    };
    Ok(Monotonicity {
        monotonic,
        sign,
        worst_temperature: worst_t,
        worst_dx_dt: worst,
        samples: n,
    })
}
