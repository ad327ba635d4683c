//! `size`: the machine a compensator serves best, or the window a machine needs.

use crate::args::{Every1, Output, ParamsArg, Temps};
use crate::error::CliError;

/// What `size` fits.
#[derive(Copy, Clone, Debug, clap::ValueEnum, PartialEq, Eq)]
pub enum What {
    /// The machine (working flow, leakage) the compensator serves best.
    Machine,
    /// The window diameter the file's machine needs.
    Slot,
}

const HELP: &str = "\
Output: TOML with the fit's provenance in comments:
  --for machine: [machine] working_flow [m^3/s], leakage_reference [m^3/s],
                 leakage_temperature [C]
  --for slot:    [slot] diameter [m], discharge_coefficient [-]

Example:
  compensator size --params presets/paper.toml --for machine --temps 30:80:1";

/// Design sizing: the machine a compensator serves best (`machine`), or
/// the window diameter a machine needs (`slot`); prints TOML.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
    /// What to size: machine or slot.
    #[arg(long = "for", value_enum)]
    what: What,
    #[command(flatten)]
    temps: Temps<Every1>,
    /// Reference temperature of the fitted leakage [C].
    #[arg(long, default_value = "40", allow_hyphen_values = true)]
    reference: f64,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the list), naming it; a fit that fails.
    pub fn run(self) -> Result<Output, CliError> {
        let what = match self.what {
            What::Machine => "machine",
            What::Slot => "slot",
        };
        Ok(Output::Text(crate::sizing::size(
            &self.params.params,
            what,
            &self.temps.temps,
            self.reference,
        )?))
    }
}
