//! `paper`: the paper's tables reproduced and its findings, as text.

use crate::args::Output;
use crate::error::CliError;
use std::path::PathBuf;

const HELP: &str = "\
Output: a text report: Table 1 inverted for A(t) [sqrt(Pa)], Table 1
residuals [bar], Table 2 displacements [mm], the \"asym\" column's expansion,
the Eq. (1) chamber-pressure gradient [kPa/C] and the Eq. (32) verdict.

Without --params / --data the copies built into the binary are used, so
the command works from any directory.

Example:
  compensator paper";

/// Reproduce the paper's tables and report the findings (text).
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    /// Parameter file (TOML) [default: the built-in presets/paper.toml].
    #[arg(long, value_name = "FILE")]
    params: Option<PathBuf>,
    /// Folder with table1.csv and table2.csv [default: the built-in data/paper].
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the tables), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        Ok(Output::Text(crate::paper::report(
            self.params.as_deref(),
            self.data.as_deref(),
        )?))
    }
}
