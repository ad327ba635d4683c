//! `calibrate`: the static parameters fitted to measured data.

use crate::args::{Calibrate, FitTable, Output};
use crate::calibration;
use crate::error::CliError;
use std::path::PathBuf;

const HELP: &str = "\
Fits fluid.walther_a, fluid.walther_b and laminar_throttle.length (through
the geometry factor G of A = G nu sqrt(rho)) to the pressure data, then
plunger.spring_rate and plunger.preload to the displacement data; the
other fields are the base file's. Refuses (exit 2, naming why) data that
cannot determine them: no more points than parameters, or parameters the
data do not separate; warns on stderr when they are barely separated.

Data (long form, one row per measurement; ',' ';' or tab separated, a BOM
and quoted cells accepted, '#' lines are comments):
  pressure:     t_c [C], dp_pa [Pa] (p_p - p_c), dp_ab_pa [Pa] (p_b - p_a)
  displacement: t_c [C], x_m [m] (optional dp_pa [Pa]; default: the base
                file's operating.pressure_drop)

Output: CSV, one row per fitted parameter:
  parameter, unit, value, std_error [unit], rel_std_error [-],
  data (pressure|displacement), points, dof (points - parameters of that
  data), residual_rms [residual_unit] (sqrt(RSS/dof)), residual_unit (Pa|m),
  corr_<parameter> [-] (the correlation matrix, one column per parameter)
stderr: points, dof and residual RMS per data set, and any warning.

--write-preset FILE: the calibrated file, its [tolerances] the fitted
fields' standard errors and its [[correlation]] their pairs beyond
|r| = 0.01 (the base's other tolerances kept). A field the data do not
determine (standard error above a third of its value, more than a file
holds) takes the base file's tolerance, the others' covariance conditioned
on it; without one it is refused (exit 2), naming it.

Without --pressure-data the paper's Tables 1 and 2 built into the binary
are used (data/calibration/), so the command works from any directory.

Example:
  compensator calibrate --base presets/model-example.toml \\
    --pressure-data data/calibration/paper-pressure.csv \\
    --displacement-data data/calibration/paper-displacement.csv \\
    --write-preset my-paper.toml --plot fit.svg --format table";

/// Fit the static parameters to measured pressures and displacements, with standard errors.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    /// Parameter file whose other fields are kept [default: the built-in presets/model-example.toml].
    #[arg(long, value_name = "FILE", alias = "base")]
    params: Option<PathBuf>,
    /// Pressure data t_c,dp_pa,dp_ab_pa (CSV) [default: the paper's Table 1, built in].
    #[arg(long, value_name = "P.csv")]
    pressure_data: Option<PathBuf>,
    /// Displacement data t_c,x_m[,dp_pa] (CSV) [default: the paper's Table 2 without --pressure-data].
    #[arg(long, value_name = "X.csv")]
    displacement_data: Option<PathBuf>,
    #[command(flatten)]
    output: FitTable<Calibrate>,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// As [`calibration::calibrate`].
    pub fn run(self) -> Result<Output, CliError> {
        let out = calibration::calibrate(&calibration::Options {
            base: self.params,
            pressure: self.pressure_data,
            displacement: self.displacement_data,
            write_preset: self.output.write_preset.clone(),
            plot: self.output.plot.plot.clone(),
        })?;
        Ok(self.output.output(out.table, &out.notes))
    }
}
