//! `paper`: the paper's tables reproduced and its findings, as text.

use crate::args::{Output, PaperInputs, Tables12};
use crate::error::CliError;

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
    #[command(flatten)]
    inputs: PaperInputs<Tables12>,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the tables), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        Ok(Output::Text(crate::paper::report(
            self.inputs.params.as_deref(),
            self.inputs.data.as_deref(),
        )?))
    }
}
