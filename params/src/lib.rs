//! The parameter file of the compensator twin (`docs/model.md` section 8): its
//! fields, units and physical rules, in plain `f64`, and (feature `toml`)
//! the reader of the TOML file.
//!
//! This crate is the single place where the format is defined. The core
//! (`compensator`) re-exports it as `compensator::params`; the command-line
//! tools read files with [`file::parse`]; the firmware's build script turns a
//! file into checked constants with the same reader, so a device is flashed
//! only with a parameter set that passed the same validation.
#![cfg_attr(not(any(feature = "toml", test)), no_std)]
#![deny(missing_docs)]

mod schema;

#[cfg(feature = "toml")]
pub mod file;

pub use schema::*;

#[cfg(test)]
mod tests;
