//! `sweep`: design variants on a grid or within tolerances.

use crate::args::{Output, ParamsArg, TableArgs, Temps, Three};
use crate::error::CliError;
use crate::sweep;

const HELP: &str = "\
Output: CSV, one row per variant (grid points, each with --samples draws):
  variant [-] (0-based), one column per --set/--vary parameter [its unit in
  the file, SI], x_<T>c_m [m] (quasi-static displacement at each --temps T),
  monotonic (true/false: the Eq. 32 verdict over the validated range),
  min_dx_dt_m_k [m/K] (the smallest dx/dt found), dominant_re [1/s]
  (dominant eigenvalue at the step's final temperature), settling_time_s [s]
  (2 % settling of the --step response, f64 twin; --reference: the
  reference solver),
  comp_error_rms_m3s [m^3/s] (compensation error RMS over the validated
  range; only with a [machine] section), error (why a variant failed).
A variant outside its field's plausible range keeps its row, with the reason
in the error column; the exit status is then 1. Rows do not depend on the
number of threads (RAYON_NUM_THREADS); in CSV they are written as they are
computed. --shard K/N runs the K-th of N contiguous parts (only part 1
writes the header): the parts' outputs concatenated are the whole run's
(cli/scale-out/ runs them as a Slurm array or on Dask; docs/sweep.md).

Example:
  compensator sweep --params presets/paper.toml --set plunger.spring_rate=20e3:30e3:5
  compensator sweep --params presets/paper.toml --vary plunger.diameter=1% --samples 200 --seed 7";

/// Design variants on a grid of named parameters or drawn within tolerances.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    params: ParamsArg,
    /// Grid axis section.key=START:END:COUNT (COUNT values, ends included) or =V1,V2; repeatable.
    #[arg(long = "set", value_name = "NAME=SPEC", allow_hyphen_values = true)]
    set: Vec<String>,
    /// Tolerance section.key=P% or =A (uniform within +-P % or +-A of the value); repeatable.
    #[arg(long, value_name = "NAME=TOL", allow_hyphen_values = true)]
    vary: Vec<String>,
    /// Draws per grid point with --vary [default: 100].
    #[arg(long, value_name = "N")]
    samples: Option<usize>,
    /// Seed of the draws (same seed, same variants).
    #[arg(long, default_value = "1")]
    seed: u64,
    #[command(flatten)]
    temps: Temps<Three>,
    /// Step of the settling time and dominant eigenvalue, from:to [C].
    #[arg(long, default_value = "40:50", allow_hyphen_values = true)]
    step: String,
    /// Sampling interval of the step response [s].
    #[arg(long, default_value = "0.0001", allow_hyphen_values = true)]
    dt: f64,
    /// Simulated time of the step [s].
    #[arg(long, default_value = "0.2", allow_hyphen_values = true)]
    t_end: f64,
    /// Settling time from the reference solver (Radau5) instead of the f64 twin: for checking, ~100x slower.
    #[arg(long)]
    reference: bool,
    /// Run shard K of N (K = 1..N): contiguous variant ranges whose CSV outputs concatenate into the whole run's.
    #[arg(long, value_name = "K/N")]
    shard: Option<String>,
    #[command(flatten)]
    table: TableArgs,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the grid, the tolerances, the lists), naming it.
    pub fn run(self) -> Result<Output, CliError> {
        let shard = self.shard.as_deref().map(sweep::stream::Shard::parse).transpose()?;
        let streamed = self.table.format.format == crate::csv::Format::Csv;
        if shard.is_some() && !streamed {
            return Err(CliError::Input(
                "--shard: the shards' CSV concatenate into the whole table; json and table do not (use --format csv)"
                    .into(),
            ));
        }
        let raw = self.params.raw()?;
        let mut s = sweep::build(
            raw,
            &self.set,
            &self.vary,
            self.samples,
            self.seed,
            &self.temps.temps,
            &self.step,
            self.dt,
            self.t_end,
        )?;
        s.metrics.reference = self.reference;
        if streamed {
            return Ok(Output::Rows(Box::new(sweep::stream::Rows {
                sweep: s,
                shard,
                units: self.table.units.units,
            })));
        }
        Ok(Output::table(sweep::run(&s)?, &self.table))
    }
}
