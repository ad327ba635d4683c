//! `estimate`: the firmware's estimator run over a recorded probe log.
//!
//! The estimator is the firmware's own ([`compensator::estimator::Estimator`],
//! `f32`), ticking at the file's `estimator.tick_hz`, its oil-temperature
//! observer designed by [`EstimatorConfig::with_sample_period`] for the
//! log's reading interval (the median of its intervals, in whole ticks:
//! 20 ms for a MAX31865 at 50 Hz, 0.5 s for a telemetry log at 2 Hz). It
//! starts at rest at the first reading, and each row is delivered as a
//! reading on the tick its time falls in (tick `k` covers `t0 + k / tick_hz
//! ..` one tick on, `t0` the first row's time); ticks between rows get no
//! reading, as the firmware's ticks between two conversions. Output: one
//! row per telemetry period (`estimator.telemetry_hz`, the ticks the
//! firmware publishes on), or one per input row ([`Options::every_sample`]),
//! each the estimate after that tick, with the telemetry record's columns
//! ([`COLUMNS`], from `compensator::estimator::telemetry`: the same names,
//! units and digits as `cargo xtask flash --csv` and `run --csv` write).
//!
//! The readings ([`READING_COLUMNS`]): a probe temperature `t_c` (or
//! `t_probe_c`, as the telemetry CSV names it), an RTD resistance `rtd_ohm`
//! converted with the file's Callendar-Van Dusen coefficients, or the
//! MAX31865's 15-bit `code` converted as the firmware's driver does (`R =
//! code R_ref / 2^15`; codes 0 and 32767 are sensor faults). A reading the
//! firmware would flag (outside `estimator.oil_min..oil_max`, a saturated
//! code) is flagged the same way; a value no probe reads (a `t_c` of
//! 300,000: [`crate::data`]) is bad input.
//!
//! Bad input, each naming the row, its line and the column: no reading
//! column or two of them, times that do not increase, two readings within
//! one tick, a gap longer than the estimator's fault timeout
//! (`stale_after`), a log over [`MAX_ROWS`] readings or [`MAX_TICKS`]
//! ticks (and [`crate::input::MAX_LOG_BYTES`]), a first reading the oil
//! model does not take.

use crate::csv::{Numeric, read_columns};
use crate::display::sig;
use crate::error::CliError;
use compensator::Params;
use compensator::estimator::telemetry::{Encoding, FIELDS, Record};
use compensator::estimator::{Estimator, EstimatorConfig, StateEstimate};
use compensator::params::RawParams;
use compensator::sensor::max31865::Settings;
use compensator::sensor::rtd;
use compensator::sensor::{Detail, SensorFault};

/// What a log's reading column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reading {
    /// The probe's temperature [C].
    Temperature,
    /// The RTD's resistance [ohm].
    Resistance,
    /// The MAX31865's 15-bit RTD code.
    Code,
}

/// A column a log's readings may be in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadingColumn {
    /// Header name (its plausible range: [`crate::data::DATA_COLUMNS`]).
    pub name: &'static str,
    /// What it holds.
    pub reading: Reading,
    /// For help texts and messages.
    pub doc: &'static str,
}

/// The columns a log's readings may be in; a log has exactly one.
pub const READING_COLUMNS: [ReadingColumn; 4] = [
    ReadingColumn {
        name: "t_c",
        reading: Reading::Temperature,
        doc: "probe temperature [C]",
    },
    ReadingColumn {
        name: "t_probe_c",
        reading: Reading::Temperature,
        doc: "probe temperature [C], as the telemetry CSV names it",
    },
    ReadingColumn {
        name: "rtd_ohm",
        reading: Reading::Resistance,
        doc: "RTD resistance [ohm], through the file's Callendar-Van Dusen coefficients",
    },
    ReadingColumn {
        name: "code",
        reading: Reading::Code,
        doc: "the MAX31865's 15-bit RTD code, through estimator.rtd_reference",
    },
];

/// The column of the sample times.
pub const TIME_COLUMN: &str = "time_s";

/// The telemetry record's columns the output carries, in this order,
/// between `time_s` and `flags` (their units, digits and descriptions are
/// the record's table's, `compensator::estimator::telemetry::FIELDS`).
pub const COLUMNS: [&str; 14] = [
    "t_probe_c",
    "t_oil_c",
    "t_oil_sd_c",
    "x_m",
    "x_sd_m",
    "p_a_pa",
    "p_a_sd_pa",
    "p_b_pa",
    "p_b_sd_pa",
    "q_total_m3s",
    "q_total_sd_m3s",
    "compensation_error_m3s",
    "compensation_error_sd_m3s",
    "reseats",
];

/// The output's last column: the condition flags' names joined by `|`
/// (empty for none), as the telemetry CSV writes them.
pub const FLAGS_COLUMN: &str = "flags";

/// Most readings a log may have: a million (5.6 hours at 50 Hz, 5.8 days
/// of telemetry at 2 Hz).
pub const MAX_ROWS: usize = 1_000_000;

/// Most estimator ticks a log may span: 1e8 (27.8 hours at 1 kHz). The
/// replay runs every tick of the span, so this bounds its time as
/// [`MAX_ROWS`] bounds its memory.
pub const MAX_TICKS: u64 = 100_000_000;

/// What to do with a log too long to replay at once.
pub const SPLIT: &str = "split the log (each part replays from its first reading)";

/// A tick's share of float noise allowed in placing a time on its tick:
/// a row at `t0 + 0.5 s` is on tick 500 at 1 kHz although `0.999 - 0.499`
/// is 0.49999999999999994 in `f64`.
const TICK_SLACK: f64 = 1e-6;

/// A probe log: its reading column and its rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Log {
    /// The reading column.
    pub column: ReadingColumn,
    /// Sample times [s].
    pub time_s: Vec<f64>,
    /// Readings, in the column's unit.
    pub value: Vec<f64>,
    /// Each row's line in the file (1-based).
    pub lines: Vec<u64>,
}

impl Log {
    /// `row R (line L), column C` for the 0-based row `i`.
    pub fn at(&self, i: usize, column: &str) -> String {
        format!("row {} (line {}), column {column}", i + 1, self.lines[i])
    }
}

/// Reads a probe log: `time_s` and exactly one of [`READING_COLUMNS`]
/// (other columns are ignored, text or numbers), with the `csv` crate as
/// every data file ([`crate::csv::read_columns`]: separators, quotes,
/// comments; each cell checked against its column's plausible range).
///
/// # Errors
///
/// One line naming row, line and column where there is one: more than
/// [`MAX_ROWS`] readings (counted before the cells are read), an empty
/// file or one without rows, no `time_s`, no reading column or two, a
/// cell that is not a plausible number, a `code` that is not whole.
pub fn read_log(text: &str) -> Result<Log, String> {
    let lines = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .count()
        .saturating_sub(1);
    if lines > MAX_ROWS {
        return Err(format!(
            "{lines} rows, more than the limit of {MAX_ROWS} readings: {SPLIT}"
        ));
    }
    let mut wanted = vec![TIME_COLUMN];
    wanted.extend(READING_COLUMNS.iter().map(|c| c.name));
    let t: Numeric = read_columns(text, &wanted)?;
    let expected = || {
        let names: Vec<&str> = READING_COLUMNS.iter().map(|c| c.name).collect();
        format!(
            "(columns: {}; expected {TIME_COLUMN} and one of {})",
            t.header.join(","),
            names.join(", ")
        )
    };
    let time = t
        .column(TIME_COLUMN)
        .ok_or_else(|| format!("no column {TIME_COLUMN} {}", expected()))?;
    let present: Vec<(usize, ReadingColumn)> = READING_COLUMNS
        .iter()
        .filter_map(|c| t.column(c.name).map(|i| (i, *c)))
        .collect();
    let (index, column) = match present.as_slice() {
        [one] => *one,
        [] => return Err(format!("no reading column {}", expected())),
        [a, b, ..] => {
            return Err(format!(
                "two reading columns, {} and {}: which one the probe read is unknown; keep one",
                a.1.name, b.1.name
            ));
        }
    };
    if t.rows.is_empty() {
        return Err("no readings: the file has a header and no rows".into());
    }
    let log = Log {
        column,
        time_s: t.rows.iter().map(|r| r[time]).collect(),
        value: t.rows.iter().map(|r| r[index]).collect(),
        lines: t.lines.clone(),
    };
    if column.reading == Reading::Code
        && let Some(i) = log.value.iter().position(|v| v.fract() != 0.0)
    {
        return Err(format!(
            "{}: {} is not a whole number (the MAX31865's RTD code is an integer 0 to 32767)",
            log.at(i, column.name),
            sig(log.value[i], 8)
        ));
    }
    Ok(log)
}

/// Options of [`run`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Options {
    /// One row per input row instead of one per telemetry period.
    pub every_sample: bool,
}

/// What [`run`] returns.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    /// The output table, CSV (SI units).
    pub table: String,
    /// The reading interval the observer was designed for [s].
    pub sample_period: f64,
    /// Ticks run.
    pub ticks: u64,
    /// The summary line for standard error.
    pub note: String,
}

/// The output's header: `time_s`, [`COLUMNS`], `flags`.
pub fn header() -> Vec<&'static str> {
    let mut h = vec![TIME_COLUMN];
    h.extend(COLUMNS);
    h.push(FLAGS_COLUMN);
    h
}

/// `v` as a cell: an `f32` in the shorter of its two shortest round-trip
/// forms (positional or with an exponent), so that it reads back as the
/// same `f32` (`0.00018324`, `1.2e-7`).
pub fn f32_cell(v: f32) -> String {
    let (plain, exp) = (format!("{v}"), format!("{v:?}"));
    if exp.len() < plain.len() { exp } else { plain }
}

/// One output row: the estimate `e` at `time_s` (the record's fields as
/// they travel: `f32` digits, a count whole).
pub fn row(time_s: f64, e: &StateEstimate) -> String {
    let values = Record::of(e).values();
    let mut cells = vec![crate::csv::number(time_s)];
    for name in COLUMNS {
        // Every name of COLUMNS is a field of the table (a test keeps it so).
        let Some(i) = FIELDS.iter().position(|f| f.column == name) else {
            cells.push(String::new());
            continue;
        };
        cells.push(match FIELDS[i].encoding {
            Encoding::F32 => f32_cell(values[i] as f32),
            _ => crate::csv::number(values[i]),
        });
    }
    cells.push(e.flags.names().collect::<Vec<_>>().join("|"));
    cells.join(",")
}

/// The reading of row `i` as the estimator takes it: a temperature, or the
/// fault the firmware's driver would report (a code of 0 or 32767, a
/// resistance or code the probe's curve has no temperature for).
fn sample(log: &Log, settings: &Settings, i: usize) -> Result<Option<f32>, SensorFault> {
    let v = log.value[i];
    let ohm = match log.column.reading {
        Reading::Temperature => return Ok(Some(v as f32)),
        Reading::Resistance => v as f32,
        // As the driver: saturated codes are faults, R = code R_ref / 2^15.
        Reading::Code if v == 0.0 || v >= 32767.0 => {
            return Err(SensorFault::OutOfRange(Detail::code(v as u16)));
        }
        Reading::Code => v as u16 as f32 * settings.reference / 32768.0,
    };
    match settings.cvd.temperature(settings.r0, ohm) {
        Some(t) => Ok(Some(t)),
        None if log.column.reading == Reading::Code => Err(SensorFault::OutOfRange(Detail::code(v as u16))),
        None => Err(SensorFault::OutOfRange(Detail::NONE)),
    }
}

/// The start of tick `k` of a log starting at `t0` [s], ticking at `hz`:
/// `t0 + k / hz`, rounded to the nanosecond (so that `0.499 + 0.5` prints
/// as the `0.999` of the telemetry it replays, not `0.9990000000000001`).
pub fn tick_time(t0: f64, k: u64, hz: f64) -> f64 {
    let t = t0 + k as f64 / hz;
    if t.abs() < 1e6 { (t * 1e9).round() / 1e9 } else { t }
}

/// `1 ms` for a tick of 1e-3 s: a duration in words.
fn seconds(s: f64) -> String {
    if s < 1.0 {
        format!("{} ms", sig(s * 1e3, 4))
    } else {
        format!("{} s", sig(s, 4))
    }
}

/// Runs the estimator of the validated parameter set `raw` over `log` (see
/// the module docs).
///
/// # Errors
///
/// [`CliError::Input`] naming row, line and column (prefixed by the
/// caller with the file): times that do not increase, two rows within one
/// tick, a gap longer than the fault timeout, a log longer than
/// [`MAX_TICKS`], fewer than two rows, a first reading the estimator cannot
/// start at, a log without a telemetry tick without
/// [`Options::every_sample`] (no row to print); a file whose estimator
/// cannot be built (named); `estimator.telemetry_hz = 0` without
/// [`Options::every_sample`].
pub fn run(raw: &RawParams, log: &Log, options: Options) -> Result<Replay, CliError> {
    let n = log.time_s.len();
    if n < 2 {
        return Err(CliError::Input(
            "one reading: the estimator needs at least two to know the log's reading interval".into(),
        ));
    }
    let hz = raw.estimator.tick_hz;
    let tick = 1.0 / hz;
    let t0 = log.time_s[0];
    let ticks = ticks_of(log, hz)?;
    // The reading interval: the median of the intervals, in whole ticks.
    let mut gaps: Vec<u64> = ticks.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_unstable();
    let median = gaps[gaps.len() / 2];
    let sample_period = median as f64 * tick;
    let config = EstimatorConfig::with_sample_period(raw, sample_period)
        .map_err(|e| CliError::Input(format!("--params: {e}")))?;
    check_gaps(log, &ticks, u64::from(config.stale_after), hz)?;
    if config.telemetry_every == 0 && !options.every_sample {
        return Err(CliError::Input(
            "--params: estimator.telemetry_hz = 0: the file asks for no telemetry; give --every-sample for one row \
             per reading"
                .into(),
        ));
    }
    let settings = Settings::from_params(&raw.estimator);
    let name = log.column.name;
    let start = first_reading(raw, log, &settings)?;
    let params = Params::<f64>::new(raw).map_err(|e| CliError::Input(format!("--params: {e}")))?;
    let envelope = crate::envelope::Envelope::of(raw, &params);
    envelope.check(
        f64::from(start),
        &format!("{} (the estimator starts at the first reading)", log.at(0, name)),
    )?;
    let params32 = Params::<f32>::new(raw).map_err(|e| CliError::Input(format!("--params: {e}")))?;
    let mut estimator = Estimator::new(&params32, config, start).map_err(|e| {
        CliError::Input(format!(
            "{}: the estimator cannot start at {} C: {e}",
            log.at(0, name),
            sig(f64::from(start), 6)
        ))
    })?;
    let last = ticks[n - 1];
    let mut out = header().join(",");
    out.push('\n');
    let mut next = 0;
    let mut rows = 0usize;
    for k in 0..=last {
        let delivered = ticks.get(next) == Some(&k);
        let reading = if delivered {
            next += 1;
            sample(log, &settings, next - 1)
        } else {
            Ok(None)
        };
        let e = estimator.tick(reading);
        if (options.every_sample && delivered) || (!options.every_sample && estimator.telemetry_due()) {
            out.push_str(&row(tick_time(t0, k, hz), &e));
            out.push('\n');
            rows += 1;
        }
    }
    let telemetry_period = seconds(config.telemetry_every as f64 * tick);
    if rows == 0 {
        return Err(CliError::Input(format!(
            "no telemetry tick in the log's {} s (the firmware publishes one every {telemetry_period}): no row to \
             print; give --every-sample for one row per reading",
            sig(log.time_s[n - 1] - t0, 8),
        )));
    }
    let note = format!(
        "estimate: {n} readings ({name}) over {} s, one every {} (the median interval: the observer is designed \
         for it), {} ticks of {}; {rows} rows{}",
        sig(log.time_s[n - 1] - t0, 8),
        seconds(sample_period),
        last + 1,
        seconds(tick),
        if options.every_sample {
            String::from(", one per reading")
        } else {
            format!(", one per telemetry period ({telemetry_period})")
        }
    );
    Ok(Replay {
        table: out,
        sample_period,
        ticks: last + 1,
        note,
    })
}

/// The estimator's tick each row of `log` is delivered on (at `hz`, from
/// the first row's time).
///
/// Errors: times that do not increase, two rows within one tick, a log
/// longer than [`MAX_TICKS`] (naming the row).
fn ticks_of(log: &Log, hz: f64) -> Result<Vec<u64>, CliError> {
    let bad = |i: usize, why: String| CliError::Input(format!("{}: {why}", log.at(i, TIME_COLUMN)));
    let tick = 1.0 / hz;
    let t0 = log.time_s[0];
    let mut ticks: Vec<u64> = Vec::with_capacity(log.time_s.len());
    for (i, &t) in log.time_s.iter().enumerate() {
        let k = ((t - t0) * hz + TICK_SLACK).floor();
        if i > 0 {
            let prev = log.time_s[i - 1];
            if !(t > prev) {
                return Err(bad(
                    i,
                    format!(
                        "{} s is not after the row before ({} s): the sample times must increase",
                        sig(t, 10),
                        sig(prev, 10)
                    ),
                ));
            }
            if k as u64 == ticks[i - 1] {
                return Err(bad(
                    i,
                    format!(
                        "{} after the row before, within one tick of the estimator ({} at estimator.tick_hz = \
                         {} Hz): it takes one reading a tick",
                        seconds(t - prev),
                        seconds(tick),
                        sig(hz, 6)
                    ),
                ));
            }
        }
        if k >= MAX_TICKS as f64 {
            return Err(bad(
                i,
                format!(
                    "the log spans {} s, more than the limit of {} ticks ({} s at estimator.tick_hz = {} Hz): \
                     {SPLIT}",
                    sig(t - t0, 8),
                    sig(MAX_TICKS as f64, 6),
                    sig(MAX_TICKS as f64 * tick, 6),
                    sig(hz, 6)
                ),
            ));
        }
        ticks.push(k as u64);
    }
    Ok(ticks)
}

/// Refuses more than `timeout` ticks without a reading between two rows
/// (readings `timeout + 1` ticks apart keep the estimate good: the count
/// is reset on the tick a reading arrives), naming the row after the gap.
fn check_gaps(log: &Log, ticks: &[u64], timeout: u64, hz: f64) -> Result<(), CliError> {
    let Some(w) = ticks.windows(2).position(|w| w[1] - w[0] - 1 > timeout) else {
        return Ok(());
    };
    let i = w + 1;
    Err(CliError::Input(format!(
        "{}: {} after the row before, longer than the estimator's fault timeout: it flags the estimate DEGRADED \
         after {} without a reading ({timeout} ticks at estimator.tick_hz = {} Hz); split the log at this row and \
         replay each part on its own",
        log.at(i, TIME_COLUMN),
        seconds(log.time_s[i] - log.time_s[i - 1]),
        seconds(timeout as f64 * (1.0 / hz)),
        sig(hz, 6)
    )))
}

/// The temperature of the log's first reading, which the estimator starts
/// at.
///
/// Errors: a first reading the firmware would flag or that is no
/// temperature (a saturated code, a resistance outside the RTD's curve),
/// naming why.
fn first_reading(raw: &RawParams, log: &Log, settings: &Settings) -> Result<f32, CliError> {
    if let Ok(Some(t)) = sample(log, settings, 0) {
        return Ok(t);
    }
    let v = log.value[0];
    let curve = |t: f32| sig(f64::from(settings.cvd.resistance(settings.r0, t)), 4);
    let range = format!(
        "the file's RTD, estimator.rtd_r0 = {} ohm, reads {} to {} ohm over IEC 60751's {} to {} C",
        sig(raw.estimator.rtd_r0, 6),
        curve(rtd::T_MIN),
        curve(rtd::T_MAX),
        rtd::T_MIN,
        rtd::T_MAX
    );
    let what = match log.column.reading {
        Reading::Code if v == 0.0 || v >= 32767.0 => {
            format!(
                "{} is a saturated code, a sensor fault (a shorted or open RTD)",
                sig(v, 8)
            )
        }
        Reading::Code => format!(
            "code {} is {} ohm (estimator.rtd_reference = {} ohm), no temperature: {range}",
            sig(v, 8),
            sig(v * raw.estimator.rtd_reference / 32768.0, 6),
            sig(raw.estimator.rtd_reference, 6)
        ),
        _ => format!("{} ohm is no temperature: {range}", sig(v, 8)),
    };
    Err(CliError::Input(format!(
        "{}: {what}; the estimator starts at the first reading: begin the log at a valid one",
        log.at(0, log.column.name)
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_columns_are_the_telemetry_records() {
        for c in COLUMNS {
            assert!(FIELDS.iter().any(|f| f.column == c), "{c} is not a telemetry column");
        }
        for c in READING_COLUMNS {
            assert!(
                crate::data::column(c.name).is_some(),
                "{} has no plausible range",
                c.name
            );
        }
        assert_eq!(
            header().join(","),
            "time_s,t_probe_c,t_oil_c,t_oil_sd_c,x_m,x_sd_m,p_a_pa,p_a_sd_pa,p_b_pa,p_b_sd_pa,q_total_m3s,\
             q_total_sd_m3s,compensation_error_m3s,compensation_error_sd_m3s,reseats,flags"
        );
    }

    #[test]
    fn f32_cells_read_back_exactly_and_short() {
        for v in [0.00018324f32, 1.2e-7, 40.0, -3.5e-12, 123456.79, f32::MIN_POSITIVE] {
            let c = f32_cell(v);
            assert_eq!(c.parse::<f32>().unwrap().to_bits(), v.to_bits(), "{c}");
            assert!(c.len() <= 15, "{c}");
        }
        assert_eq!(f32_cell(1.2e-7), "1.2e-7");
        assert_eq!(f32_cell(0.00018324), "0.00018324");
        assert_eq!(f32_cell(f32::NAN), "NaN");
    }
}
