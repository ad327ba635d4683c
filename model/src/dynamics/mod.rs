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
