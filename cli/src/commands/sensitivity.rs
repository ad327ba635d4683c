//! `sensitivity`: the temperature sensitivities (Eqs. 30-31).

use crate::args::{Every2, Output, OverTemps, TableArgs, rows_help};
use crate::error::CliError;
use crate::statics;

const HELP: &str = rows_help!(
    "temperature",
    "\
  t_c [C], dx_dt_branch_m_k [m/K], dx_dt_m_k [m/K], dq_throt_dt_m3s_k [m^3/(s K)],",
    "",
    "compensator sensitivity --params presets/paper.toml --temps 26:78:2"
);

/// Temperature sensitivities (Eqs. 30-31) and the Eq. (32) verdict.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    over: OverTemps<Every2>,
    #[command(flatten)]
    table: TableArgs,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the list), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        Ok(Output::table(self.over.table(statics::sensitivity)?, &self.table))
    }
}
