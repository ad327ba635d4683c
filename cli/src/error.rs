//! A command's failure and the exit status it maps to: bad input (exit
//! status 2) or a computation that failed (1). The library's errors that
//! are bad input convert into it. (This module depends on no other of the
//! crate but the error types it converts; reading files is
//! [`crate::input`]'s.)

use crate::params_file::LoadError;
use crate::temps;
use std::fmt;

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
