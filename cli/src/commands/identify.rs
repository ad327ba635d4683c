//! `identify`: the dynamic parameters fitted to a measured transient.

use crate::args::{FitTable, Identify, Output, ParamsArg};
use crate::error::CliError;
use crate::identify;
use std::path::PathBuf;

const HELP: &str = "\
Simulates the measured temperature history with the dynamic twin in f64
(four times the substeps twin-config chooses for the sample interval) and
fits the dynamic parameters by least squares. 95 % intervals are profile
likelihood ones. A parameter is reported as not identifiable (no value
printed; kept at the --params value, the others fitted again without it)
when its relative standard error exceeds 50 %, the data cannot separate it
from another, it runs to the edge of its plausible range, fewer than 10
samples carry its information, or its profile likelihood is flat
(docs/calibration.md).

Data: time_s [s] (uniform samples), t_c [C], x_m [m], optionally
p_a_pa, p_b_pa [Pa]; the record starts at rest at the first temperature.

Output: CSV, one row per parameter of --fit:
  parameter, unit, identifiable (true|false), value [unit],
  std_error [unit], rel_std_error [-], ci95_low [unit], ci95_high [unit]
  (the numbers are empty when identifiable is false)
stderr: the twin used, residuals, degrees of freedom, residual RMS [m]
(and [Pa]), and why each parameter is not identifiable.

Example:
  compensator identify --params my-device.toml --data step.csv \\
    --fit mass,damping --write-preset my-device-dynamic.toml --format table";

/// Fit the dynamic parameters (mass, damping, compliance) to a measured transient, with intervals.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
    /// Transient time_s,t_c,x_m[,p_a_pa,p_b_pa] (CSV).
    #[arg(long, value_name = "STEP.csv")]
    data: PathBuf,
    /// Parameters to fit, comma list of mass, damping, bulk_modulus, volume_a, volume_b.
    #[arg(long, default_value = "mass,damping,bulk_modulus")]
    fit: String,
    #[command(flatten)]
    output: FitTable<Identify>,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// As [`identify::identify`].
    pub fn run(self) -> Result<Output, CliError> {
        let (table, notes) = identify::identify(&identify::Options {
            params: self.params.params,
            data: self.data,
            fit: Some(self.fit),
            write_preset: self.output.write_preset.clone(),
            plot: self.output.plot.plot.clone(),
        })?;
        Ok(self.output.output(table, &notes))
    }
}
