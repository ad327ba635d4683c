//! Independent `f64` references for the compensator twin.
//!
//! Written from `docs/model.md` in SI units, sharing no code with the core (only
//! the parameter values, read through `compensator_params::RawCore`):
//!
//! * [`statics`]: the quasi-static equilibrium by bisection on each
//!   chamber's flow balance (no closed form).
//! * [`dynamics`]: the FSI model integrated by an adaptive stiff solver
//!   (Radau IIA order 5, `differential-equations`) with exact location of
//!   the end-stop events (and, optionally, Coulomb friction with its stick
//!   and slip events), and the same with the explicit Dormand-Prince
//!   8(5,3) method as an unrelated cross-check.

#[cfg(feature = "dynamics")]
pub mod dynamics;
pub mod statics;
