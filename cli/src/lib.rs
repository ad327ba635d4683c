//! Host-side library of the `compensator` command-line tool: parameter
//! files, temperature lists, CSV output, calibration against the paper's
//! tables, design sizing and the dynamic-model commands.
//!
//! The binary (`src/main.rs`) is a thin argument parser over these modules,
//! so that the tests can call the same code.

pub mod commands;
pub mod csv;
pub mod dynamics;
pub mod lsq;
pub mod paper;
pub mod sizing;
pub mod temps;

pub use compensator_params::file as params_file;
pub use compensator_params::file::{LoadError, load, parse};
