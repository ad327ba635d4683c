//! `equilibrium`: the quasi-static operating point per temperature (Eqs. 2-10).

use crate::args::{Every10, Output, OverTemps, PlottedTable, rows_help};
use crate::error::CliError;
use crate::{plot, statics};

/// Scalar type of a static computation.
#[derive(Copy, Clone, Debug, clap::ValueEnum, PartialEq, Eq)]
pub enum StaticPrecision {
    /// Double precision.
    F64,
    /// Single precision (the firmware's).
    F32,
}

const HELP: &str = rows_help!(
    "temperature",
    "\
  t_c [C], a_sqrt_pa [sqrt(Pa)] (the property A), p_a_pa [Pa], p_b_pa [Pa],
  dp_ab_pa [Pa] (p_b - p_a), x_m [m] (plunger displacement),
  q_branch_m3s [m^3/s], q_throt_m3s [m^3/s], q_total_m3s [m^3/s],
  nu_m2s [m^2/s] (kinematic viscosity; cSt with --units eng),",
    "\
A temperature outside the file's oil-model range is refused (exit 2,
naming the limit and why): docs/parameters.md, the temperature envelope.
",
    "compensator equilibrium --params presets/paper.toml --temps 30:80:10"
);

/// Quasi-static equilibrium (Eqs. 2-10) per temperature.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    over: OverTemps<Every10>,
    /// Scalar type of the computation.
    #[arg(long, value_enum, default_value = "f64")]
    precision: StaticPrecision,
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
        let single = self.precision == StaticPrecision::F32;
        let csv = self
            .over
            .table(|path, temps| statics::equilibrium(path, temps, single))?;
        self.output.output(csv, plot::equilibrium)
    }
}
