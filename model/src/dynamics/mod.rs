//! The reduced-order fluid-structure model (paper section 4, Eqs. 33-37)
//! and its fixed-step integration.
//!
//! * [`fsi`]: the model, nondimensionalised (units chosen for fixed point).
//! * [`schemes`]: Rosenbrock and Runge-Kutta one-step schemes.
//! * [`twin`]: the fixed-cost integrator the firmware ticks.
//! * [`reduced`]: the singular-perturbation limit (pressures quasi-steady).
//! * [`linear`]: linearisation at an equilibrium (Eq. 37): eigenvalues,
//!   natural frequencies, damping ratios, stability.

pub mod config;
pub mod dirk;
pub mod fsi;
pub mod linear;
pub mod reduced;
pub mod schemes;
pub mod twin;

pub use fsi::{Contact, DynamicState, Model};
pub use schemes::{Scheme, StepError};
pub use twin::{TickReport, Twin, TwinConfig};

use crate::error::ModelError;
use crate::scalar::Float;

/// What a caller drives, the full twin ([`Twin`]) or the reduced one
/// ([`reduced::ReducedTwin`]): the oil temperature in, one tick, the state
/// out (SI units).
pub trait Dynamic<F: Float> {
    /// Sets the oil temperature [C] for the following ticks.
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
    /// The state: `x` [m], `v` [m/s], `p_a`, `p_b` [Pa].
    fn state(&self) -> DynamicState<F>;
}
