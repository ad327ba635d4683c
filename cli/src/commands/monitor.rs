//! `monitor`: what the condition monitor made of a log with the second
//! sensor's readings.

use crate::args::{FormatArg, Output, PlotArg, ReplayInputs};
use crate::error::CliError;

const HELP: &str = "\
Replays a log through the firmware's estimator with the condition monitor
of the device file's second sensor ([monitor] section), as estimate does,
and summarises the monitor's flags: which were raised, since when, and how
sure it is.

Log (CSV, as estimate reads it): time_s [s], the probe's column (t_c,
rtd_ohm or code) and the second sensor's, p_a_pa, p_b_pa or dp_ab_pa [Pa]
or x_m [m] (the file's monitor.sensor); either reading may be empty on a
row. A column in bar, MPa or mm is refused naming its row and column;
readings outside the sensor's measuring band (a few) or stuck are
flagged SECOND_SENSOR_FAULT, as the firmware's driver flags them.

Output: CSV, one row per flag of the monitor's raised over the log
(DEVICE_CHANGED, CAPILLARY_RESTRICTED, ORIFICE_CLOGGED, SPRING_RELAXED,
PRELOAD_LOST, PLUNGER_STICKING, SENSOR_OFFSET, SECOND_SENSOR_FAULT,
INNOVATION_REJECTED), in that order; none: a header alone:
  flag, first_row [-] (the log's row on or before the tick that first
  carried it), first_line [-] (its line in the file), first_time_s [s]
  (that tick's start), ticks [-] (ticks that carried it),
  parameter (the health value it is about: divider, spring, offset,
  friction, cusum, rejected), estimate (its value at the log's end),
  sd (its standard deviation: of the logarithm for divider and spring),
  z [-] (how many sd the estimate lies from the file's device: ln(f)/sd
  for a factor, offset/sd), cusum_max [-] (the largest CUSUM up to the
  flag; DEVICE_CHANGED above 10), unit (of estimate and sd: 1, Pa, m,
  N or K; a string in JSON as in CSV)
stderr: what ran, the second sensor's readings missing (more than 1.5 of
its period between two of them: the rows, line numbers and length of
the longest such stretch), where its rate changed (the row, from what
interval to what; each stretch's missing readings counted at its own),
or that its readings are too few (under 8 intervals) to measure a
period, the device file's taken, and the health estimate at the log's
end.
--plot FILE.png|svg: the standardised innovations with the gate, the CUSUM
with its threshold, the divider and spring factors and the offset, each
with its 95 % band, over time.

Example:
  compensator monitor --params presets/paper-monitor.toml \\
    --sensor-data log.csv --plot monitor.png --format table";

/// Summarise what the condition monitor made of a log with the second sensor's readings: faults, since when, how sure.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    inputs: ReplayInputs,
    #[command(flatten)]
    plot: PlotArg,
    #[command(flatten)]
    format: FormatArg,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the log: naming row, line and column) as
    /// [`estimate::read_log`] and [`crate::monitor::summarise`].
    pub fn run(self) -> Result<Output, CliError> {
        let input = self.inputs.read()?;
        let (log, shown) = (&input.log, &input.shown);
        let summary = crate::monitor::summarise(&input.raw, log).map_err(|e| input.in_log(e))?;
        if let Some(path) = &self.plot.plot {
            let figure = crate::plot::monitor(
                &summary.trace,
                summary.quantity.is_pressure(),
                &format!("Condition monitor over {shown}"),
            );
            crate::plot::write(path, &figure)?;
        }
        for line in summary.notes(log) {
            eprintln!("{line}");
        }
        Ok(Output::si_table(summary.table, &self.format))
    }
}
