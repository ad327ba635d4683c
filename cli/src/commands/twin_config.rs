//! `twin-config`: the twin's scheme and substeps chosen for a file.

use crate::args::{Output, ParamsArg, TableArgs};
use crate::error::CliError;

const HELP: &str = "\
Output: CSV, one row:
  scheme, substeps, tick_s [s], valid_min_c [C], valid_max_c [C],
  estimated_error_pct [%], target_pct [%], goal_met (true/false)

Example:
  compensator twin-config --params presets/paper.toml --dt 0.001";

/// The twin's scheme and substeps per tick chosen for a file (CSV).
///
/// Chosen from the design's own dynamics over the file's validated
/// range ([estimator] valid_min, valid_max): the cheapest substep count
/// whose estimated error stays within the target (% of a step).
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
    /// Tick [s].
    #[arg(long, default_value = "0.001", allow_hyphen_values = true)]
    dt: f64,
    #[command(flatten)]
    table: TableArgs,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, `--dt`), naming it; a chooser that fails.
    pub fn run(self) -> Result<Output, CliError> {
        Ok(Output::table(
            crate::dynamics::twin_config(&self.params.params, self.dt)?,
            &self.table,
        ))
    }
}
