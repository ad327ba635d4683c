//! Quasi-static equilibrium (paper Eqs. 2-10, `docs/model.md` section 4).
//!
//! Each chamber is a series pair of an orifice and a capillary carrying the
//! same flow `Q_a = Q_b`. With `A(t) = R_l / sqrt(R_t)` and `q = sqrt(R_t) Q_a`:
//!
//! ```text
//! q       = (-A + sqrt(A^2 + 4 dp)) / 2  = 2 dp / (A + sqrt(A^2 + 4 dp))
//! p_a     = p_p - q^2,   p_b = p_c + q^2
//! p_b-p_a = 2 q^2 - dp   = dp + A^2 - A sqrt(4 dp + A^2)   (Eq. 5's bracket)
//! x       = clamp((p_b - p_a) A_p / c - x0, 0, x_max)        (Eqs. 4-5)
//! Q0      = 2 Q_a + eta pi d x sqrt(2 dp / rho)              (Eqs. 6-7)
//! ```
//!
//! The second form of `q` is used: it has no cancellation for large `A`
//! (cold oil), so the `f32` path keeps about 1e-7 of `dp` everywhere.
//! Eq. (5) prints `pi d^2` where the force balance (Eq. 4) has the plunger
//! area `pi D^2 / 4`; the plunger area is the physical one and is used here.
//!
//! Cost (f32, Cortex-M4F): fluid state (~250 instructions) plus ~60 for the
//! closed form, two of them square roots.

use crate::error::{ModelError, finite};
use crate::fluid::{Derivatives, FluidPoint, FluidState};
use crate::params::Params;
use crate::scalar::Float;

/// Where the plunger rests against its end stops: in a quasi-static
/// equilibrium ([`Equilibrium::stop`]), and in the dynamic models, which
/// name the same type [`crate::dynamics::Contact`] (held by a stop during
/// a step, [`crate::dynamics::stops`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stop {
    /// Between the stops.
    Free,
    /// Held against the stop at `x = 0` (window closed).
    Closed,
    /// Held against the stop at `x = x_max` (window fully open).
    Open,
}

/// The quasi-static operating point at one temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equilibrium<T> {
    /// Oil state at the temperature.
    pub fluid: FluidState<T>,
    /// Redistribution parameter `A(t)` [sqrt(Pa)].
    pub a: T,
    /// Pressure in chamber (a) \[Pa\].
    pub p_a: T,
    /// Pressure in chamber (b) \[Pa\].
    pub p_b: T,
    /// `p_b - p_a` \[Pa\].
    pub dp_ab: T,
    /// Plunger displacement, clamped to the stops \[m\].
    pub x: T,
    /// Displacement of the force balance without stops, `Phi(A) - x0` \[m\].
    pub x_free: T,
    /// Which stop, if any, holds the plunger.
    pub stop: Stop,
    /// Flow through each chamber branch, `Q_a = Q_b` [m^3/s].
    pub q_branch: T,
    /// Flow through the window, `Q_throt` [m^3/s] (Eq. 7).
    pub q_throt: T,
    /// Total flow `Q0 = Q_a + Q_b + Q_throt` [m^3/s] (Eq. 6).
    pub q_total: T,
}

/// `q / sqrt(dp)` for a dimensionless `a_hat = A / sqrt(dp)`:
/// `2 / (a_hat + sqrt(a_hat^2 + 4))`, in (0, 1]. Also returns
/// `s = sqrt(a_hat^2 + 4)`, which the derivatives reuse.
#[inline]
pub fn branch_fraction<T: Float>(a_hat: T) -> (T, T) {
    let four = T::from_f64(4.0);
    let s = (a_hat * a_hat + four).sqrt();
    (T::from_f64(2.0) / (a_hat + s), s)
}

/// Chamber pressure difference `p_b - p_a` \[Pa\] for `A` [sqrt(Pa)] and `dp` \[Pa\]
/// (the bracket of Eq. 5, evaluated without cancellation).
#[inline]
pub fn pressure_difference<T: Float>(a: T, dp: T) -> T {
    let (q, _) = branch_fraction(a / dp.sqrt());
    (T::from_f64(2.0) * q * q - T::ONE) * dp
}

/// `G` in `A(t) = G nu(t) sqrt(rho(t))`: `G = 128 sqrt(2) L C_d f / (pi d_l^4)`
/// [1/m]. It depends on the throttles' geometry only.
#[inline]
pub fn geometry_factor<T: Float>(params: &Params<T>) -> T {
    T::from_f64(core::f64::consts::SQRT_2) * params.orifice.discharge_coefficient * params.orifice.area()
        / params.capillary.bore_term()
}

/// `A = R_l / sqrt(R_t)` [sqrt(Pa)] for a fluid state.
#[inline]
pub fn a_parameter<T: Float>(params: &Params<T>, fluid: &FluidState<T>) -> T {
    geometry_factor(params) * fluid.kinematic_viscosity * fluid.density.sqrt()
}

/// `A(t)`, `dA/dt`, `d2A/dt2` in closed form from the viscosity and density
/// derivatives: with `L1 = nu'/nu + rho'/(2 rho)` and
/// `L2 = nu''/nu - (nu'/nu)^2 + rho''/(2 rho) - (rho'/rho)^2 / 2`,
/// `A' = A L1` and `A'' = A (L1^2 + L2)`.
///
/// # Errors
///
/// The oil model refuses `t` ([`crate::fluid::Oil::point`]), or as
/// [`a_derivatives_at`].
pub fn a_derivatives<T: Float>(params: &Params<T>, t: T) -> Result<Derivatives<T>, ModelError> {
    a_derivatives_at(params, &params.oil.point(t)?)
}

/// As [`a_derivatives`] from an evaluated [`FluidPoint`].
///
/// # Errors
///
/// [`ModelError::NonFinite`] naming `A(t)`, `dA/dt` or `d2A/dt2` when one
/// of them is not finite.
pub fn a_derivatives_at<T: Float>(params: &Params<T>, point: &FluidPoint<T>) -> Result<Derivatives<T>, ModelError> {
    let (nu, rho) = (&point.viscosity, &point.density);
    let (a, n1, r1, l1) = a_logarithmic(params, point);
    let half = T::from_f64(0.5);
    let l2 = nu.d2 / nu.value - n1 * n1 + half * rho.d2 / rho.value - half * r1 * r1;
    Ok(Derivatives {
        value: finite(a, "A(t)")?,
        d1: finite(a * l1, "dA/dt")?,
        d2: finite(a * (l1 * l1 + l2), "d2A/dt2")?,
    })
}

/// `A(t)` and `dA/dt` alone: [`a_derivatives_at`]'s first two, the same
/// operations and values, without `d2A/dt2` (two divisions and its check,
/// in software on a core without an FPU).
///
/// # Errors
///
/// [`ModelError::NonFinite`] naming `A(t)` or `dA/dt` when one of them is
/// not finite.
pub fn a_slope_at<T: Float>(params: &Params<T>, point: &FluidPoint<T>) -> Result<(T, T), ModelError> {
    let (a, _, _, l1) = a_logarithmic(params, point);
    Ok((finite(a, "A(t)")?, finite(a * l1, "dA/dt")?))
}

/// `A`, the viscosity's and the density's logarithmic slopes `nu'/nu`,
/// `rho'/rho`, and `L1 = nu'/nu + rho'/(2 rho)` (`A' = A L1`).
#[inline(always)]
fn a_logarithmic<T: Float>(params: &Params<T>, point: &FluidPoint<T>) -> (T, T, T, T) {
    let (nu, rho) = (&point.viscosity, &point.density);
    let a = geometry_factor(params) * nu.value * rho.value.sqrt();
    let n1 = nu.d1 / nu.value;
    let r1 = rho.d1 / rho.value;
    (a, n1, r1, n1 + T::from_f64(0.5) * r1)
}

/// Clamps a free displacement to the stops.
#[inline]
pub fn clamp_to_stops<T: Float>(x_free: T, stroke: T) -> (T, Stop) {
    if x_free <= T::ZERO {
        (T::ZERO, Stop::Closed)
    } else if x_free >= stroke {
        (stroke, Stop::Open)
    } else {
        (x_free, Stop::Free)
    }
}

/// The force balance of the equilibrium for a given `A` [sqrt(Pa)]: its
/// chamber pressures and displacement, without the flows
/// ([`equilibrium_for`] adds them; the estimator's Equilibrium job needs
/// only these).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balance<T> {
    /// Pressure in chamber (a) \[Pa\].
    pub p_a: T,
    /// Pressure in chamber (b) \[Pa\].
    pub p_b: T,
    /// `p_b - p_a` \[Pa\].
    pub dp_ab: T,
    /// Plunger displacement, clamped to the stops \[m\].
    pub x: T,
    /// Displacement of the force balance without stops \[m\].
    pub x_free: T,
    /// Which stop, if any, holds the plunger.
    pub stop: Stop,
    /// Each branch's flow fraction `q / sqrt(dp)` ([`branch_fraction`]).
    pub q: T,
}

/// The force balance for a given `A` [sqrt(Pa)] (Eqs. 2-5).
///
/// # Errors
///
/// [`ModelError::NonFinite`] when `a` or the free displacement is not
/// finite.
pub fn balance_for<T: Float>(params: &Params<T>, a: T) -> Result<Balance<T>, ModelError> {
    let dp = params.pressure_drop;
    let sqrt_dp = dp.sqrt();
    let (q, _) = branch_fraction(finite(a, "A(t)")? / sqrt_dp);
    let drop = q * q * dp; // pressure drop over each orifice
    let p_a = params.inlet_pressure() - drop;
    let p_b = params.outlet_pressure + drop;
    let dp_ab = (T::from_f64(2.0) * q * q - T::ONE) * dp;
    let x_free = dp_ab * params.plunger.compliance() - params.plunger.preload;
    let (x, stop) = clamp_to_stops(x_free, params.plunger.stroke);
    Ok(Balance {
        p_a,
        p_b,
        dp_ab,
        x,
        x_free: finite(x_free, "displacement")?,
        stop,
        q,
    })
}

/// The equilibrium for a given `A` [sqrt(Pa)] and fluid state: the force
/// balance ([`balance_for`]) and the flows (Eqs. 6-7).
///
/// # Errors
///
/// [`ModelError::NonFinite`] when `a`, the free displacement or the total
/// flow is not finite.
pub fn equilibrium_for<T: Float>(params: &Params<T>, fluid: FluidState<T>, a: T) -> Result<Equilibrium<T>, ModelError> {
    let b = balance_for(params, a)?;
    // Orifice flow at the full drop; each branch carries the fraction q.
    let dp = params.pressure_drop;
    let q_full = params.orifice.flow(dp, fluid.density);
    let q_branch = b.q * q_full;
    let q_throt = params.slot.flow(b.x, dp, fluid.density);
    Ok(Equilibrium {
        fluid,
        a,
        p_a: b.p_a,
        p_b: b.p_b,
        dp_ab: b.dp_ab,
        x: b.x,
        x_free: b.x_free,
        stop: b.stop,
        q_branch,
        q_throt,
        q_total: finite(q_branch + q_branch + q_throt, "total flow")?,
    })
}

/// The quasi-static equilibrium at temperature `t` \[C\].
///
/// # Errors
///
/// The oil model refuses `t` ([`crate::fluid::Oil::state`]: `NonFinite`
/// or `OutOfRange`), or as [`equilibrium_for`].
pub fn equilibrium<T: Float>(params: &Params<T>, t: T) -> Result<Equilibrium<T>, ModelError> {
    let fluid = params.oil.state(t)?;
    let a = a_parameter(params, &fluid);
    equilibrium_for(params, fluid, a)
}

/// The balance temperature `t0` where `p_a = p_b` (Eq. 2), i.e.
/// `A(t0) = sqrt(dp / 2)`, searched in `[lo, hi]` \[C\] by bisection.
///
/// `A` falls monotonically with temperature for every valid parameter set
/// (viscosity and density both fall), so the root is unique when bracketed.
/// Fixed cost: 64 halvings at most (stops early at the type's resolution).
///
/// # Errors
///
/// * [`ModelError::NonFinite`]`("temperature")`: `lo` or `hi` is not finite;
/// * `OutOfRange("temperature interval")`: `lo < hi` does not hold;
/// * `OutOfRange("balance temperature (not bracketed)")`: `A(t) -
///   sqrt(dp / 2)` has the same sign at both ends (no balance point in the
///   interval);
/// * the oil model refuses a temperature it evaluates
///   ([`crate::fluid::Oil::state`]).
pub fn balance_temperature<T: Float>(params: &Params<T>, lo: T, hi: T) -> Result<T, ModelError> {
    let target = (params.pressure_drop * T::from_f64(0.5)).sqrt();
    let g = |t: T| -> Result<T, ModelError> {
        let f = params.oil.state(t)?;
        Ok(a_parameter(params, &f) - target)
    };
    let (mut lo, mut hi) = (finite(lo, "temperature")?, finite(hi, "temperature")?);
    if !(lo < hi) {
        return Err(ModelError::OutOfRange("temperature interval"));
    }
    let (g_lo, g_hi) = (g(lo)?, g(hi)?);
    if g_lo == T::ZERO {
        return Ok(lo);
    }
    if g_hi == T::ZERO {
        return Ok(hi);
    }
    if (g_lo > T::ZERO) == (g_hi > T::ZERO) {
        return Err(ModelError::OutOfRange("balance temperature (not bracketed)"));
    }
    let lo_positive = g_lo > T::ZERO;
    for _ in 0..64 {
        let mid = (lo + hi) * T::from_f64(0.5);
        if !(mid > lo && mid < hi) {
            break;
        }
        let gm = g(mid)?;
        if (gm > T::ZERO) == lo_positive {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok((lo + hi) * T::from_f64(0.5))
}
