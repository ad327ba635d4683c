//! `compensation`: demand, supply and compensation error per temperature.

use crate::args::{Every10, Output, OverTemps, PlottedTable, rows_help};
use crate::error::CliError;
use crate::{plot, sizing};

const HELP: &str = rows_help!(
    "temperature",
    "\
  t_c [C], losses_m3s [m^3/s], demand_m3s [m^3/s], supply_m3s [m^3/s],
  error_m3s [m^3/s] (supply - demand), required_area_m2 [m^2],
  required_x_m [m], x_m [m],",
    "The file needs a [machine] section.\n",
    "compensator compensation --params presets/paper.toml --temps 30:80:10"
);

/// Demand, supply, compensation error and the Eq. (9) window per temperature.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    over: OverTemps<Every10>,
    #[command(flatten)]
    output: PlottedTable,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the list, no `[machine]` section), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        let csv = self.over.table(sizing::compensation_table)?;
        self.output.output(csv, plot::compensation)
    }
}
