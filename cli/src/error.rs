//! A command's failure and the exit status it maps to, with the helpers
//! every command uses to turn bad input into one: loading a parameter file.
//! (A temperature the model cannot evaluate is not bad input: the tables
//! give its row an `error` cell, `crate::csv::Table::row_error`.)

use crate::params_file::LoadError;
use crate::temps;
use compensator::{Float, Params, RawParams};
use std::fmt;
use std::path::Path;

/// A command's failure: bad input (exit status 2) or a computation that
/// could not be completed (exit status 1). `Display` is one line.
#[derive(Debug)]
pub enum CliError {
    /// Bad input: the message names the field or argument.
    Input(String),
    /// A computation failed.
    Failed(String),
}

impl CliError {
    /// Process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Failed(_) => 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(s) | CliError::Failed(s) => f.write_str(s),
        }
    }
}

impl From<LoadError> for CliError {
    fn from(e: LoadError) -> Self {
        CliError::Input(e.to_string())
    }
}

impl From<temps::TempsError> for CliError {
    fn from(e: temps::TempsError) -> Self {
        CliError::Input(e.to_string())
    }
}

/// Loads a parameter file (`-`: standard input) and converts it to `T`.
pub fn load_params<T: Float>(path: &Path) -> Result<(RawParams, Params<T>), CliError> {
    let raw = crate::input::load_raw(path, "--params")?;
    let params = Params::<T>::new(&raw).map_err(|e| CliError::Input(e.to_string()))?;
    Ok((raw, params))
}
