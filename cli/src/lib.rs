//! Host-side library of the `compensator` command-line tool, one module per
//! concern:
//!
//! * commands: [`statics`] (equilibrium, asymptotic, sensitivity),
//!   [`dynamics`] (step, twin-config, eigen, indicators), [`sizing`]
//!   (compensation, size), [`calibration`] (calibrate), [`identify`]
//!   (identify), [`paper`] (the paper report, with the paper's tables in
//!   [`paper::tables`]), [`report`] (the paper's tables and figures as
//!   files) and [`sweep`] (design variants on a grid or within tolerances);
//! * their plumbing: [`error`] (a command's failure and exit status,
//!   parameter loading), [`input`] (bounded reading of a parameter file,
//!   the built-in presets and paper data), [`temps`] (temperature lists), [`csv`] (output),
//!   [`units`] (`--units si|eng`), [`plot`] (`--plot FILE.svg|FILE.png`: a
//!   command's output as a figure),
//!   [`lsq`] (least squares with standard errors, for calibrate and identify).
//!
//! Each command is a function returning its complete standard output; the
//! binary (`src/main.rs`) is a thin argument parser over them, so that the
//! tests can call the same code.

pub mod calibration;
pub mod csv;
pub mod dynamics;
pub mod error;
pub mod identify;
pub mod input;
pub mod lsq;
pub mod paper;
pub mod plot;
pub mod report;
pub mod sizing;
pub mod statics;
pub mod sweep;
pub mod temps;
pub mod units;

pub use compensator_params::file as params_file;
pub use compensator_params::file::{LoadError, load, parse};
