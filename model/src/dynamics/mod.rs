//! The reduced-order fluid-structure model (paper section 4, Eqs. 33-37)
//! and its fixed-step integration.
//!
//! * [`units`]: the model's units (chosen for fixed point) and SI states.
//! * [`coefficients`]: the model's coefficients for a parameter set and an
//!   oil temperature, and the formulas every integrator shares (static
//!   force, chamber volumes, net inflows, quasi-steady root).
//! * [`stops`]: the inelastic end stops ([`Contact`], the equilibrium's
//!   [`crate::equilibrium::Stop`]).
//! * [`fsi`]: the model's right-hand side, Jacobian and structured
//!   factorisation (what the generic schemes integrate).
//! * [`dirk`]: the SDIRK steps with the pressures eliminated exactly (the
//!   shipped scheme); [`config`]: choosing a configuration for a design.
//! * [`schemes`]: Rosenbrock and Runge-Kutta one-step schemes.
//! * [`twin`]: the fixed-cost integrator the firmware ticks.
//! * [`reduced`]: the singular-perturbation limit (pressures quasi-steady).
//! * [`linear`]: linearisation at an equilibrium (Eq. 37): eigenvalues,
//!   natural frequencies, damping ratios, stability.

pub mod coefficients;
pub mod config;
pub mod dirk;
pub mod fsi;
pub mod linear;
pub mod reduced;
pub mod schemes;
pub mod stops;
pub mod twin;
pub mod units;

pub use coefficients::Model;
pub use schemes::{Scheme, StepError};
pub use stops::Contact;
pub use twin::{Owed, Rest, TickReport, Twin, TwinConfig, TwinMemory};
pub use units::DynamicState;

use crate::error::ModelError;
use crate::scalar::Float;

/// What a caller drives, the full twin ([`Twin`]) or the reduced one
/// ([`reduced::ReducedTwin`]): the oil temperature in, one tick, the state
/// out (SI units).
pub trait Dynamic<F: Float> {
    /// Sets the oil temperature \[C\] for the following ticks.
    ///
    /// # Errors
    /// [`ModelError`] when the oil model refuses the temperature or a
    /// coefficient does not fit the scalar type; the twin keeps its
    /// previous coefficients.
    fn set_temperature(&mut self, temperature: F) -> Result<(), ModelError>;
    /// Advances one tick (`TwinConfig::tick` seconds).
    ///
    /// # Errors
    /// [`StepError`] when a step fails (a singular stage, a non-finite or
    /// diverged state); the state is left as before the tick.
    fn tick(&mut self) -> Result<TickReport, StepError>;
    /// The state: `x` \[m\], `v` [m/s], `p_a`, `p_b` \[Pa\].
    fn state(&self) -> DynamicState<F>;
}
