//! `asymptotic`: the asymptotic displacement (Eqs. 16-21) beside the quasi-static one.

use crate::args::{Every10, Output, ParamsArg, PlottedTable, Temps, rows_help};
use crate::error::CliError;
use crate::{plot, statics};
use compensator::asymptotic::Reading;

/// Reading of the asymptotic expansion.
#[derive(Copy, Clone, Debug, clap::ValueEnum, PartialEq, Eq)]
pub enum ReadingArg {
    /// A series in the temperature.
    Temperature,
    /// A series in the property A itself.
    Property,
}

const HELP: &str = rows_help!(
    "temperature",
    "\
  t_c [C], x_qs_m [m] (quasi-static), x_asym_m [m] (the series),",
    "",
    "compensator asymptotic --params presets/paper.toml --order 2 --reading temperature --t0 balance"
);

/// Asymptotic displacement (Eqs. 16-21) beside the quasi-static one.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
    /// Order of the series: 0, 1 or 2.
    #[arg(long, value_parser = clap::value_parser!(u8).range(0..=2))]
    order: u8,
    /// Expansion in temperature or in the property A itself.
    #[arg(long, value_enum)]
    reading: ReadingArg,
    /// Reference temperature [C], or `balance` (where p_a = p_b, Eq. 2).
    #[arg(long, default_value = "balance", allow_hyphen_values = true)]
    t0: String,
    #[command(flatten)]
    temps: Temps<Every10>,
    #[command(flatten)]
    output: PlottedTable,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the list, `--t0`), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        let reading = match self.reading {
            ReadingArg::Temperature => Reading::Temperature,
            ReadingArg::Property => Reading::Property,
        };
        let order = usize::from(self.order);
        let csv = statics::asymptotic(&self.params.params, order, reading, &self.t0, &self.temps.temps)?;
        self.output
            .output(csv, |csv, units| plot::asymptotic(csv, order, units))
    }
}
