//! `indicators`: the step-response indicators of the paper's Table 3.

use crate::args::{Output, ParamsArg, TableArgs, rows_help};
use crate::error::CliError;

const HELP: &str = rows_help!(
    "step",
    "\
  from_c [C], to_c [C], x_star_m [m] (final displacement),
  settling_time_s [s], overshoot_pct [%], dominant_re [1/s],",
    "",
    "compensator indicators --params presets/paper.toml --steps 30:40,40:50"
);

/// Step-response indicators of Table 3 (reference solver).
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
    /// Steps as from:to pairs [C].
    #[arg(long, default_value = "30:40,40:50,50:60,60:70,70:80", allow_hyphen_values = true)]
    steps: String,
    /// Sampling interval [s].
    #[arg(long, default_value = "0.0001", allow_hyphen_values = true)]
    dt: f64,
    /// Simulated time per step [s].
    #[arg(long, default_value = "1.0", allow_hyphen_values = true)]
    t_end: f64,
    #[command(flatten)]
    table: TableArgs,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the steps, the times), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        let csv = crate::dynamics::indicators(&self.params.params, &self.steps, self.dt, self.t_end)?;
        Ok(Output::table(csv, &self.table))
    }
}
