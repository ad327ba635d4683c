//! `estimate`: the firmware's estimator replayed over a recorded probe log.

use crate::args::{Output, PlottedTable, ReplayInputs};
use crate::error::CliError;
use crate::estimate::{self, Options};

const HELP: &str = "\
Runs the firmware's estimator (the same code, f32, the same tick
1/estimator.tick_hz) over a recorded probe log: it starts at rest at the
first reading, each row is delivered on the tick its time falls in, and
the oil-temperature observer is designed for the log's reading interval
(the median of its intervals). A board's or QEMU's telemetry CSV
(cargo xtask flash --csv / run --csv) replays as it is, through its
t_probe_c column.

Log (CSV; ',' ';' or tab separated, '#' lines are comments, other columns
ignored): time_s [s], increasing, no gap longer than the estimator's fault
timeout (0.5 s at the default tick), and exactly one of
  t_c        probe temperature [C] (t_probe_c: the same, as telemetry names it)
  rtd_ohm    RTD resistance [ohm], through the file's Callendar-Van Dusen coefficients
  code       the MAX31865's 15-bit code, R = code * estimator.rtd_reference / 2^15
A reading the firmware flags (outside estimator.oil_min..oil_max, a code
of 0 or 32767) is flagged SENSOR_FAULT the same way.

With a second sensor in the file's [monitor] section, its column
  p_a_pa, p_b_pa or dp_ab_pa [Pa], or x_m [m]   (the file's monitor.sensor)
feeds the condition monitor on the row's tick; a row may then leave the
probe's or the second sensor's cell empty (or NaN), not both, and the
first row holds a probe reading. A column for another quantity, or one
evidently in bar, MPa or mm, is refused naming the row and column (the
file's monitor.range_min..range_max gives the plausible readings). As the
firmware's driver, a reading outside the sensor's measuring band (an open
loop, a short; most of the column outside it is refused), or on the same
ADC code as the readings before it monitor.noise says a healthy sensor
repeats once in 1e9 times (stuck), is flagged SECOND_SENSOR_FAULT, not
taken. A telemetry CSV's
x_m, p_a_pa, p_b_pa are estimates, never readings.

Output: CSV, one row per telemetry period (estimator.telemetry_hz), or
per input row with --every-sample; SI units, every digit of the f32
estimate:
  time_s [s] (the tick's start), t_probe_c [C] (the last accepted reading),
  t_oil_c [C] (estimated oil temperature), t_oil_sd_c [C],
  x_m [m], x_sd_m [m], p_a_pa [Pa], p_a_sd_pa [Pa], p_b_pa [Pa], p_b_sd_pa [Pa],
  q_total_m3s [m^3/s], q_total_sd_m3s [m^3/s],
  compensation_error_m3s [m^3/s], compensation_error_sd_m3s [m^3/s]
  (NaN without a [machine] section), reseats [-],
  with a second sensor's column, the monitor's health estimate:
  divider [-] (A / A_file), sd_divider [-] (of ln divider), spring [-]
  (c / c_file), sd_spring [-], offset_pa|_m, sd_offset_pa|_m,
  probe_bias_k [K], sd_probe_bias_k [K] (the probe's error within its
  tolerance), oil_c [C] (the oil temperature the reading gives),
  friction_n [N], predicted_pa|_m (the reading the monitor predicted),
  innovation [-] (standardised), cusum [-], rejected [-] (readings not
  applied); empty before the monitor's first reading (rejected: 0),
  flags (names joined by |, the monitor's among them)
The *_sd_* columns are standard uncertainties (k = 1): +-1.96 of them is
the 95 % band (docs/firmware.md). stderr: the readings, their interval and
the ticks run; with a second sensor's column, the readings it missed
(more than 1.5 of its period between two of them) and the rows of the
longest such stretch, where its rate changed (the row, from what
interval to what), or that its readings are too few (under 8 intervals)
to measure a period, the device file's taken.

Example:
  compensator estimate --params presets/paper.toml \\
    --sensor-data data/logs/probe-warm-up.csv --plot estimate.svg";

/// Replay a recorded probe log through the firmware's estimator: state estimates with their uncertainties.
#[derive(clap::Args, Debug, Clone)]
#[command(after_long_help = HELP)]
pub struct Args {
    #[command(flatten)]
    inputs: ReplayInputs,
    /// One row per row of the log instead of one per telemetry period.
    #[arg(long)]
    every_sample: bool,
    #[command(flatten)]
    output: PlottedTable,
}

impl Args {
    /// Runs the command.
    ///
    /// # Errors
    ///
    /// Bad input (the file, the log: naming row, line and column) as
    /// [`estimate::read_log`] and [`estimate::run`].
    pub fn run(self) -> Result<Output, CliError> {
        let input = self.inputs.read()?;
        let (raw, shown) = (&input.raw, &input.shown);
        let replay = estimate::run(
            raw,
            &input.log,
            Options {
                every_sample: self.every_sample,
            },
        )
        .map_err(|e| input.in_log(e))?;
        eprintln!("{}", replay.note);
        self.output.output(replay.table, |csv, units| {
            crate::plot::estimate(csv, raw.core.stroke, &format!("Estimate over {shown}"), units)
        })
    }
}
