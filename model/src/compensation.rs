//! What the compensator is for: covering the driven machine's
//! temperature-dependent losses (paper Eqs. 8-9).
//!
//! The machine's volumetric losses are laminar leakage, proportional to
//! `1/mu`: `dQ_lost(t) = dQ_ref mu(t_ref) / mu(t)`. The compensator should
//! deliver `Q0(t) = Q_work + dQ_lost(t)` (Eq. 8); the window area that would
//! do so exactly is Eq. (9):
//!
//! ```text
//! f_throt(t) = (dQ_lost(t) + Q_work - 2 Q_a(t)) / (eta sqrt(2 dp / rho))
//! ```
//!
//! and the compensation error is `Q0(t) - (Q_work + dQ_lost(t))`.

use crate::equilibrium::{Equilibrium, equilibrium};
use crate::error::{ModelError, finite};
use crate::params::{Machine, Params};
use crate::scalar::Float;

/// The machine's demand and the compensator's supply at one temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compensation<T> {
    /// The equilibrium the supply comes from.
    pub equilibrium: Equilibrium<T>,
    /// Volumetric losses `dQ_lost(t)` [m^3/s].
    pub losses: T,
    /// Demand `Q_work + dQ_lost(t)` [m^3/s].
    pub demand: T,
    /// Compensation error `Q0(t) - demand` [m^3/s] (positive: oversupply).
    pub error: T,
    /// Window area of Eq. (9) that would make the error zero [m^2]
    /// (negative when the branches alone already oversupply).
    pub required_area: T,
    /// Displacement that opens `required_area`, `f_throt / (pi d)` \[m\].
    pub required_x: T,
}

/// Laminar leakage of the machine at `t` \[C\]: `dQ_ref mu(t_ref) / mu(t)` [m^3/s].
///
/// # Errors
///
/// The oil model refuses `t` or the machine's reference temperature
/// ([`crate::fluid::Oil::state`]), or as [`losses_for`].
pub fn losses<T: Float>(params: &Params<T>, machine: &Machine<T>, t: T) -> Result<T, ModelError> {
    let mu_ref = params.oil.state(machine.leakage_temperature)?.dynamic_viscosity;
    let mu = params.oil.state(t)?.dynamic_viscosity;
    losses_for(machine, mu_ref, mu)
}

/// Laminar leakage for the oil's dynamic viscosity `mu` [Pa s], given the
/// viscosity `mu_ref` at the machine's reference temperature [m^3/s].
///
/// # Errors
///
/// `NonFinite("losses")` when the quotient is not finite (a zero `mu`).
pub fn losses_for<T: Float>(machine: &Machine<T>, mu_ref: T, mu: T) -> Result<T, ModelError> {
    finite(machine.leakage_reference * mu_ref / mu, "losses")
}

/// Demand, supply, error and the Eq. (9) window at `t` \[C\].
///
/// # Errors
///
/// * `OutOfRange("machine (no [machine] section)")` when the parameter set
///   describes no machine;
/// * as [`equilibrium`] and [`losses`] at `t`;
/// * `NonFinite` naming the compensation error, the required area or the
///   required displacement when one of them is not finite.
pub fn compensation<T: Float>(params: &Params<T>, t: T) -> Result<Compensation<T>, ModelError> {
    let machine = params
        .machine
        .as_ref()
        .ok_or(ModelError::OutOfRange("machine (no [machine] section)"))?;
    let eq = equilibrium(params, t)?;
    let lost = losses(params, machine, t)?;
    let demand = machine.working_flow + lost;
    let velocity = (T::from_f64(2.0) * params.pressure_drop / eq.fluid.density).sqrt();
    let required_area = (demand - eq.q_branch - eq.q_branch) / (params.slot.discharge_coefficient * velocity);
    let required_x = required_area / (T::from_f64(core::f64::consts::PI) * params.slot.diameter);
    Ok(Compensation {
        equilibrium: eq,
        losses: lost,
        demand,
        error: finite(eq.q_total - demand, "compensation error")?,
        required_area: finite(required_area, "required area")?,
        required_x: finite(required_x, "required displacement")?,
    })
}
