//! `report`: the paper's tables and figures recomputed, as files in a folder.

use crate::args::{Output, PaperInputs, Tables123, UnitsArg};
use crate::error::CliError;
use std::path::PathBuf;

const HELP: &str = "\
Output: files in --dir (their names listed on stdout):
  report.md   Tables 1-3, each model value beside the paper's, the figures
              linked, and the findings of `compensator paper`
  table1.csv  t_c [C], dp_pa, paper_dp_ab_pa, model_dp_ab_pa, residual_pa [Pa]
  table2.csv  t_c [C], paper/model x_qs_m and x_asym_m, residuals [m]
  table3.csv  from_c, to_c [C], paper/model x_star_m [m], paper_settling_rel [-],
              model_settling_time_s [s], overshoot_pct [%], dominant_re [1/s]
  fig2_pressure_difference, fig3_displacement, fig4_step_responses,
  fig5_normalised_responses, eigenvalues, compensation: .svg (and .png
  with --png)
--units eng writes bar, mm, L/min (columns renamed). Without --params /
--data the copies built into the binary are used, so the command works
from any directory.

Example:
  compensator report --dir paper-report --units eng --png";

/// The paper's Tables 1-3 and Figures 2-5 recomputed, as files in a folder.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    inputs: PaperInputs<Tables123>,
    /// Folder to write into (created if absent; files in it are replaced).
    #[arg(long, value_name = "DIR", alias = "out")]
    dir: PathBuf,
    /// Also write each figure as PNG.
    #[arg(long)]
    png: bool,
    #[command(flatten)]
    units: UnitsArg,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the tables, the folder), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        Ok(Output::Text(crate::report::report(&crate::report::Options {
            params: self.inputs.params.as_deref(),
            data: self.inputs.data.as_deref(),
            out: &self.dir,
            png: self.png,
            units: self.units.units,
        })?))
    }
}
