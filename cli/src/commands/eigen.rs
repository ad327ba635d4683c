//! `eigen`: eigenvalues of the linearisation (Eq. 37) per temperature.

use crate::args::{Every10, Output, OverTemps, PlottedTable, rows_help};
use crate::error::CliError;
use crate::plot;

const HELP: &str = rows_help!(
    "temperature",
    "\
  t_c [C], re_1, im_1, ..., re_4, im_4 [1/s] (eigenvalues),
  zeta_dominant [-], omega_n_dominant [rad/s] (the dominant mode: 1 and
  |lambda| when it is real), zeta_plunger [-] (the plunger with the
  chambers' hydraulic damping, (b + b_hyd) / (2 sqrt(c m)): above 1,
  overdamped),",
    "",
    "compensator eigen --params presets/paper.toml --temps 30:80:10"
);

/// Eigenvalues of the linearisation at the equilibrium (Eq. 37).
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
    /// Bad input (the file, the list), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        let csv = self.over.table(crate::dynamics::eigen)?;
        self.output.output(csv, |csv, _| plot::eigen(csv))
    }
}
