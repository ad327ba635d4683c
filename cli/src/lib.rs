//! Host-side library of the `compensator` command-line tool, one module per
//! concern:
//!
//! * commands: [`statics`] (equilibrium, asymptotic, sensitivity),
//!   [`dynamics`] (step, twin-config, eigen, indicators), [`sizing`]
//!   (compensation, size), [`calibration`] (calibrate), [`identify`]
//!   (identify), [`estimate`] (the firmware's estimator over a probe log),
//!   [`monitor`] (the condition monitor's flags over a log), [`paper`] (the paper report, with the paper's tables in
//!   [`paper::tables`]), [`report`] (the paper's tables and figures as
//!   files) and [`sweep`] (design variants on a grid or within tolerances);
//! * their plumbing: [`error`] (a command's failure and exit status,
//!   parameter loading), [`input`] (bounded reading of a parameter file,
//!   the built-in presets and paper data), [`temps`] (temperature lists), [`csv`] (output),
//!   [`units`] (`--units si|eng`), [`plot`] (`--plot FILE.svg|FILE.png`: a
//!   command's output as a figure),
//!   [`lsq`] (least squares with standard errors, for calibrate and identify),
//!   [`data`] (the measured data columns and their plausible ranges),
//!   [`envelope`] (the temperatures a file's model takes, checked on every
//!   command), [`display`] (rounding for people: `--format table`, messages).
//!
//! * the command line: [`commands`] (one module per command: its clap
//!   `Args` and `run`), [`args`] (the arguments several commands share,
//!   declared once), [`app`] (parsing, the one error path, writing the
//!   output); `src/main.rs` calls [`app::main`].
//!
//! Each computation is a function returning its complete output, so that
//! the tests can call the same code as the binary.

pub mod app;
pub mod args;
pub mod calibration;
pub mod commands;
pub mod csv;
pub mod data;
pub mod display;
pub mod dynamics;
pub mod envelope;
pub mod error;
pub mod estimate;
pub mod identify;
pub mod input;
pub mod lsq;
pub mod monitor;
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
