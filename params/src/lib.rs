//! The parameter file of the compensator twin (`docs/model.md` section 8): its
//! fields, units and physical rules, in plain `f64`, and (feature `toml`)
//! the reader of the TOML file.
//!
//! This crate is the single place where the format is defined. The core
//! (`compensator`) re-exports it as `compensator::params`; the command-line
//! tools read files with `file::parse` (feature `toml`); the firmware's
//! build script turns a file into checked constants with the same reader,
//! so a device is flashed only with a parameter set that passed the same
//! validation.
//!
//! Every field carries its plausible range beside its unit and default
//! ([`Field::min`], [`Field::max`], [`Field::kind`]); validation checks
//! every field against its own range before any rule between fields, so
//! that an error names the field that is wrong. `docs/parameters.md`
//! tabulates the fields and the bad-input matrix.
#![cfg_attr(not(any(feature = "toml", test)), no_std)]
#![deny(missing_docs)]

mod schema;
mod text;

#[cfg(feature = "toml")]
pub mod file;

pub use schema::*;
pub use text::{Compact, ECHO_MAX, Echo};

#[cfg(test)]
mod tests;

/// The examples of the crate's README (they read TOML), compiled and run as
/// doctests.
#[cfg(all(doctest, feature = "toml"))]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
