//! # compensator
//!
//! A `no_std`, allocation-free digital twin of the passive throttle-based
//! temperature flow compensator of "Asymptotic analysis and reduced-order
//! modeling of a passive throttle-based temperature flow compensator", with
//! the physics fixed in the project's `docs/model.md` (what the paper
//! leaves open or gets wrong, and where the code departs from the plain
//! equations: the regularised orifice law, the stops as inelastic events,
//! the twin's units).
//!
//! The paper's three levels:
//!
//! | level | module | paper |
//! |---|---|---|
//! | quasi-static equilibrium | [`equilibrium`], [`compensation`] | Eqs. 2-10 |
//! | asymptotic closed forms, sensitivities, Eq. 32 | [`asymptotic`] | Eqs. 11-32 |
//! | reduced-order FSI model, fixed-step twin, linearisation | [`dynamics`] | Eqs. 33-37 |
//!
//! On top: [`estimator`] (what the firmware runs every tick) and [`sensor`]
//! (the temperature source: PT100 through a MAX31865).
//!
//! Building blocks: [`params`] (validated parameter sets), [`fluid`] (oil
//! properties), [`throttle`] (throttle laws), [`scalar`] (the `f32` / `f64` /
//! fixed-point scalar traits).
//!
//! Nothing in this crate allocates or panics: bad parameters give a
//! [`params::ParamError`] naming the field, a model evaluation outside its
//! range gives a [`ModelError`] naming the quantity, a twin tick that fails
//! gives a [`dynamics::StepError`], a temperature sensor a
//! [`sensor::SensorFault`]. Each fallible function's documentation says
//! what makes it fail; [`ModelError`], [`dynamics::StepError`] and the
//! sensor's errors implement `Display` and `core::error::Error`.
#![cfg_attr(not(test), no_std)]
#![deny(missing_docs)]
#![forbid(unsafe_op_in_unsafe_fn)]

pub mod asymptotic;
pub mod compensation;
pub mod dynamics;
pub mod equilibrium;
mod error;
pub mod estimator;
pub mod fluid;
pub mod linalg;
pub mod mathf;
pub mod monitor;
pub mod params;
pub mod scalar;
pub mod sensor;
pub mod softfloat;
pub mod throttle;
pub mod uncertainty;

pub use error::ModelError;
pub use params::{ParamError, Params, RawParams};
pub use scalar::{Float, Real};

/// The examples of the crate's README, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
