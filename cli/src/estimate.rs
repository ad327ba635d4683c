//! `estimate`: the firmware's estimator run over a recorded probe log.
//!
//! The estimator is the firmware's own ([`compensator::estimator::Estimator`],
//! `f32`), ticking at the file's `estimator.tick_hz`, its oil-temperature
//! observer designed by [`EstimatorConfig::with_sample_period`] for the
//! log's reading interval (the lower median of its intervals, in whole
//! ticks: 20 ms for a MAX31865 at 50 Hz, 0.5 s for a telemetry log at 2
//! Hz; of two intervals the shorter, as a reading missing only ever
//! lengthens one). It
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
//! A second sensor's column ([`SECOND_COLUMNS`]: `p_a_pa`, `p_b_pa`,
//! `dp_ab_pa` or `x_m`, the quantity of the device file's
//! `monitor.sensor`) feeds the estimator's condition monitor
//! (`Estimator::offer_second`, on the row's tick, before the probe's
//! reading of the same row), with the monitor's settings from the file
//! (`MonitorSettings::from_raw`) but its period, measured from the
//! column's readings: the lower median of the intervals of its stretch
//! with the most readings ([`stretches`]; one stretch, the whole column,
//! for a sensor that kept its rate). A handful of readings measure no
//! period (the median of two intervals may be a gap's): with fewer than
//! [`MIN_INTERVALS`] intervals the monitor takes the device file's
//! (`monitor.sample_hz`), no reading is counted missing, and standard
//! error says so, with the intervals the log has. A sensor whose rate
//! changed for good (10 Hz, then 1 Hz) is not one whose readings went
//! missing: where the local interval (the lower median of the
//! [`MIN_INTERVALS`] + 1 around each) moves by more than half as much
//! again and stays moved over at least [`MIN_INTERVALS`] intervals, a new
//! stretch begins, and standard error names the row (its line and time)
//! where the interval changed, from what to what, and the stretch the
//! monitor's period is of; a long interval or a few in a row stay a gap.
//! The monitor steps by each reading's own interval whatever its period
//! (the period is its first step's). The output then gains the health
//! estimate's
//! values ([`compensator::estimator::health::HEALTH_FIELDS`]) before
//! `flags`, which names the monitor's flags too. With a second column
//! either reading may be empty (or `NaN`) on a row, not both; the first
//! row holds a probe reading. A telemetry CSV (it has `t_oil_c`) carries
//! the estimator's own `x_m`, `p_a_pa` and `p_b_pa`: they are estimates,
//! never taken as a second sensor's readings. Where the second sensor
//! stopped reporting for a while between its first and last reading
//! ([`SecondGaps`]: more than one and a half of its stretch's period
//! between two readings), standard error says how many readings are
//! missing and names the rows of the longest such stretch.
//!
//! Bad input, each naming the row, its line and the column: no reading
//! column or two of them, times that do not increase, two readings within
//! one tick, a gap longer than the estimator's fault timeout
//! (`stale_after`), a log over [`MAX_ROWS`] readings or [`MAX_TICKS`]
//! ticks (and [`crate::input::MAX_LOG_BYTES`]), a first reading the oil
//! model does not take; a second sensor's column for a quantity the
//! device file's sensor does not measure, or in another unit
//! ([`check_second`]: a bar column in a Pa log, mm in an m log).

use crate::csv::{Numeric, read_columns_with};
use crate::display::sig;
use crate::error::CliError;
use compensator::Params;
use compensator::estimator::health::{HEALTH_FIELDS, HealthUnit};
use compensator::estimator::telemetry::{Encoding, FIELDS, Record};
use compensator::estimator::{Estimator, EstimatorConfig, Flags, StateEstimate};
use compensator::monitor::{HealthEstimate, MonitorSettings, ProbeModel, Quantity as MonitorQuantity};
use compensator::params::RawParams;
use compensator::sensor::max31865::Settings;
use compensator::sensor::transducer::{self, Quantity};
use compensator::sensor::{Detail, SensorFault};
use compensator::sensor::{device, rtd};

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

/// A column a second sensor's readings may be in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondColumn {
    /// Header name (as the telemetry names the quantity).
    pub name: &'static str,
    /// The quantity (`monitor.sensor`).
    pub quantity: Quantity,
    /// For help texts and messages.
    pub doc: &'static str,
}

/// The columns of the second sensor's readings, one per quantity the
/// device file's `monitor.sensor` may name; a log has at most one, the
/// file's.
pub const SECOND_COLUMNS: [SecondColumn; 4] = [
    SecondColumn {
        name: "p_a_pa",
        quantity: Quantity::PressureA,
        doc: "chamber (a) pressure [Pa]",
    },
    SecondColumn {
        name: "p_b_pa",
        quantity: Quantity::PressureB,
        doc: "chamber (b) pressure [Pa]",
    },
    SecondColumn {
        name: "dp_ab_pa",
        quantity: Quantity::PressureDifference,
        doc: "chamber pressure difference p_b - p_a [Pa]",
    },
    SecondColumn {
        name: "x_m",
        quantity: Quantity::Displacement,
        doc: "plunger displacement [m]",
    },
];

/// The column of `quantity`'s readings.
pub fn second_column(quantity: Quantity) -> SecondColumn {
    // Every quantity has its column (a test keeps it so).
    SECOND_COLUMNS
        .into_iter()
        .find(|c| c.quantity == quantity)
        .unwrap_or(SECOND_COLUMNS[0])
}

/// A column only the telemetry CSV has (the estimated oil temperature): a
/// log with it is a telemetry record, whose `x_m`, `p_a_pa` and `p_b_pa`
/// are the estimator's estimates, not a sensor's readings.
pub const TELEMETRY_MARK: &str = "t_oil_c";

/// The device file's second sensor as a log's column is checked against:
/// its transducer, and the range the device's quantity spans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondSensor {
    /// The transducer channel's settings (range, output, ADC).
    pub settings: transducer::Settings,
    /// The range the quantity spans on the device \[Pa or m\]: a chamber's
    /// pressure the outlet to the supply, their difference `-dp..dp`, the
    /// displacement the stroke.
    pub physical: (f64, f64),
    /// The oil-temperature probe the monitor tests the device with.
    pub probe: ProbeModel,
}

impl SecondSensor {
    /// The second sensor of the validated parameter set `raw`, `None`
    /// without one.
    ///
    /// # Errors
    ///
    /// [`CliError::Input`] naming the field its settings refuse.
    pub fn of(raw: &RawParams) -> Result<Option<SecondSensor>, CliError> {
        let Some(settings) = device::monitor_settings(raw).map_err(|e| CliError::Input(format!("--params: {e}")))?
        else {
            return Ok(None);
        };
        let (p_c, dp) = (raw.core.outlet_pressure, raw.core.pressure_drop);
        let physical = match settings.quantity {
            Quantity::PressureA | Quantity::PressureB => (p_c, p_c + dp),
            Quantity::PressureDifference => (-dp, dp),
            Quantity::Displacement => (0.0, raw.core.stroke),
        };
        Ok(Some(SecondSensor {
            settings,
            physical,
            probe: ProbeModel::new(raw),
        }))
    }

    /// The readings the sensor gives as readings, its measuring band
    /// \[Pa or m\]: `range_min..range_max` widened by the output's margins
    /// (NAMUR NE 43's, 1.25 % of the span below and 3.125 % above); beyond
    /// it the driver reports a fault, not a reading.
    pub fn band(&self) -> (f64, f64) {
        let (s, l) = (&self.settings, self.settings.output.limits());
        (
            f64::from(s.reading_of_signal(l.measure_low)),
            f64::from(s.reading_of_signal(l.measure_high)),
        )
    }

    /// The monitor's settings for readings every `period` \[s\].
    pub fn monitor(&self, period: f64) -> MonitorSettings {
        MonitorSettings {
            sample_period: period as f32,
            ..MonitorSettings::of_transducer(&self.settings, self.probe)
        }
    }
}

/// A log's second sensor: its column and readings.
#[derive(Clone, Debug, PartialEq)]
pub struct Second {
    /// The column.
    pub column: SecondColumn,
    /// Readings \[Pa or m\], one per row (NaN: none on that row).
    pub value: Vec<f64>,
}

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
    /// Readings, in the column's unit (NaN: none on that row, with a
    /// second sensor's column only).
    pub value: Vec<f64>,
    /// Each row's line in the file (1-based).
    pub lines: Vec<u64>,
    /// The second sensor's readings, if the log has its column.
    pub second: Option<Second>,
    /// What the log holds that is not taken, for standard error (a
    /// telemetry CSV's estimates).
    pub note: Option<String>,
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
/// comments; each cell checked against its column's plausible range), and
/// the readings of the device file's second sensor `sensor` if the log has
/// its column ([`SECOND_COLUMNS`]; never in a telemetry CSV, whose
/// columns of those names are estimates).
///
/// # Errors
///
/// One line naming row, line and column where there is one: more than
/// [`MAX_ROWS`] readings (counted before the cells are read), an empty
/// file or one without rows, no `time_s`, no reading column or two, a
/// cell that is not a plausible number, a `code` that is not whole; a
/// second sensor's column when the file has none or measures another
/// quantity, a row with neither reading, a first row without a probe
/// reading, a second sensor's reading outside its band or a column in
/// another unit ([`check_second`]).
pub fn read_log(text: &str, sensor: Option<&SecondSensor>) -> Result<Log, String> {
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
    let names = crate::csv::header(text)?;
    let telemetry = names.iter().any(|h| h == TELEMETRY_MARK);
    // A log without its time or probe column is refused for that first.
    let probe_log =
        names.iter().any(|h| h == TIME_COLUMN) && names.iter().any(|h| READING_COLUMNS.iter().any(|c| c.name == h));
    let second = if telemetry || !probe_log {
        None
    } else {
        second_of(&names, sensor)?
    };
    if let (None, Some(sensor), false, true) = (second, sensor, telemetry, probe_log) {
        misnamed_second(&names, sensor)?;
    }
    let note = (telemetry && sensor.is_some()).then(|| {
        format!(
            "the log is a telemetry CSV ({TELEMETRY_MARK}): its x_m, p_a_pa and p_b_pa are the estimator's estimates, \
             not the second sensor's readings; the monitor gets none"
        )
    });
    let mut wanted = vec![TIME_COLUMN];
    wanted.extend(READING_COLUMNS.iter().map(|c| c.name));
    let mut sparse: Vec<&str> = Vec::new();
    let mut unchecked: Vec<&str> = Vec::new();
    if let Some(c) = second {
        wanted.push(c.name);
        sparse.extend(READING_COLUMNS.iter().map(|c| c.name));
        sparse.push(c.name);
        unchecked.push(c.name);
    }
    let t: Numeric = read_columns_with(text, &wanted, &sparse, &unchecked)?;
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
    let mut log = Log {
        column,
        time_s: t.rows.iter().map(|r| r[time]).collect(),
        value: t.rows.iter().map(|r| r[index]).collect(),
        lines: t.lines.clone(),
        second: None,
        note,
    };
    if let Some(c) = second {
        let i = t.column(c.name).unwrap_or(index);
        log.second = Some(Second {
            column: c,
            value: t.rows.iter().map(|r| r[i]).collect(),
        });
    }
    if column.reading == Reading::Code
        && let Some(i) = log.value.iter().position(|v| v.is_finite() && v.fract() != 0.0)
    {
        return Err(format!(
            "{}: {} is not a whole number (the MAX31865's RTD code is an integer 0 to 32767)",
            log.at(i, column.name),
            sig(log.value[i], 8)
        ));
    }
    if let (Some(second), Some(sensor)) = (&log.second, sensor) {
        if !log.value[0].is_finite() {
            return Err(format!(
                "{}: no probe reading on the first row: the estimator starts at the first row's probe reading; \
                 begin the log at a row with one",
                log.at(0, column.name)
            ));
        }
        if let Some(i) = (0..log.value.len()).find(|&i| !log.value[i].is_finite() && !second.value[i].is_finite()) {
            return Err(format!(
                "row {} (line {}): neither a probe reading ({}) nor a second sensor's ({}): a row holds at least one",
                i + 1,
                log.lines[i],
                column.name,
                second.column.name
            ));
        }
        check_second(&log, second, sensor)?;
    }
    Ok(log)
}

/// The second sensor's column of a log whose header is `names`, for the
/// device file's sensor `sensor`.
///
/// Errors: a second sensor's column when the file has none, or for
/// another quantity than the file's sensor measures (naming the column).
fn second_of(names: &[String], sensor: Option<&SecondSensor>) -> Result<Option<SecondColumn>, String> {
    let present: Vec<SecondColumn> = SECOND_COLUMNS
        .into_iter()
        .filter(|c| names.iter().any(|h| h == c.name))
        .collect();
    let Some(first) = present.first() else {
        return Ok(None);
    };
    let Some(sensor) = sensor else {
        return Err(format!(
            "column {}: a second sensor's readings ({}), but the device file has no second sensor \
             (monitor.sensor = \"none\"): name it in the file's [monitor] section (docs/parameters.md), or leave the \
             column out",
            first.name, first.doc
        ));
    };
    let q = sensor.settings.quantity;
    if let Some(other) = present.iter().find(|c| c.quantity != q) {
        return Err(format!(
            "column {}: readings of the {}, but the device file's second sensor measures {} (monitor.sensor = \
             \"{}\"), whose column is {}: leave the other column out",
            other.name,
            other.doc,
            q.name(),
            q.name(),
            second_column(q).name
        ));
    }
    Ok(Some(*first))
}

/// Refuses a column that reads as the device file's second sensor's under
/// another name (`p_a_bar`, `P_A_PA`, `x_mm`, `p_a`): "other columns are
/// ignored", and a log whose sensor column was ignored replays without the
/// monitor, or fails on the probe's empty cells beside it.
///
/// Errors: the column, the sensor's column and its unit.
fn misnamed_second(names: &[String], sensor: &SecondSensor) -> Result<(), String> {
    let column = second_column(sensor.settings.quantity);
    // The name without its unit: `p_a` of `p_a_pa`, `x` of `x_m`.
    let stem = column.name.rsplit_once('_').map_or(column.name, |(stem, _)| stem);
    // The stem alone, or with a unit of the quantity's (as a suffix or in
    // brackets); any other column (`x_ref_m`, `p_a_set_pa`, the
    // telemetry's `x_sd_m`) is another quantity's, and ignored.
    const UNITS: [&str; 9] = ["pa", "kpa", "mpa", "bar", "mbar", "psi", "m", "mm", "um"];
    let looks = |h: &str| {
        let h = h.trim().to_ascii_lowercase();
        let Some(rest) = h.strip_prefix(stem) else {
            return false;
        };
        let unit = rest
            .trim_start_matches(['_', ' ', '[', '(', '/'])
            .trim_end_matches([']', ')']);
        rest.is_empty() || (rest.len() > unit.len() && UNITS.contains(&unit))
    };
    match names.iter().find(|h| looks(h)) {
        Some(h) => Err(format!(
            "column {h}: the device file's second sensor's readings (monitor.sensor = \"{}\") are read from \
             column {}, the {}: rename the column, its readings in {}",
            sensor.settings.quantity.name(),
            column.name,
            column.doc,
            sensor.settings.quantity.unit()
        )),
        None => Ok(()),
    }
}

/// Checks the second sensor's readings against the device file:
///
/// * at least half of them inside the sensor's measuring band
///   ([`SecondSensor::band`]), the likely unit named when they are not (a
///   displacement in mm); fewer outside it are the sensor's level faults,
///   which [`replay`] flags (`SECOND_SENSOR_FAULT`) as the driver does;
/// * the column as a whole not evidently in another unit: readings that
///   vary, yet all lie within one step of the sensor's ADC of zero, while
///   some likely unit (bar, kPa, MPa, psi; mm, um) puts every one inside
///   the range the device's quantity spans, are that unit's (a chamber
///   pressure in bar reads 0.4 to 3.2 where the sensor's steps are 152
///   Pa). The unit named is the largest such.
///
/// # Errors
///
/// The row (the offending reading, or the column's largest), its line,
/// the column, the value, the band or the ADC's step, and the likely unit.
pub fn check_second(log: &Log, second: &Second, sensor: &SecondSensor) -> Result<(), String> {
    let name = second.column.name;
    let unit = sensor.settings.quantity.unit();
    let (lo, hi) = sensor.band();
    let (min, max) = (f64::from(sensor.settings.range.0), f64::from(sensor.settings.range.1));
    let data = crate::data::column(name);
    let hint = |v: f64, lo: f64, hi: f64| data.map_or(String::new(), |c| crate::data::unit_hint(c, v, lo, hi));
    // A few readings outside the band are the sensor's faults (an open
    // loop, a short), flagged as the driver flags them ([`replay`]); most
    // of them outside it are a column in another unit, or no sensor.
    let outside: Vec<usize> = (0..second.value.len())
        .filter(|&i| second.value[i].is_finite() && !(lo..=hi).contains(&second.value[i]))
        .collect();
    let readings = second.value.iter().filter(|v| v.is_finite()).count();
    if let Some(&i) = outside.first()
        && 2 * outside.len() > readings
    {
        let v = second.value[i];
        return Err(format!(
            "{}: {} {unit} is outside the second sensor's measuring band {} to {} {unit} \
             (monitor.range_min..range_max = {} to {} {unit} with the output's margins; beyond it the sensor \
             reports a fault, not a reading), as {} of the column's {} readings are: a column in another unit, or \
             a sensor that failed{}",
            log.at(i, name),
            sig(v, 6),
            sig(lo, 6),
            sig(hi, 6),
            sig(min, 6),
            sig(max, 6),
            outside.len(),
            readings,
            hint(v, lo, hi)
        ));
    }
    let finite: Vec<(usize, f64)> = second
        .value
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .collect();
    let Some(&(largest, top)) = finite.iter().max_by(|a, b| a.1.abs().total_cmp(&b.1.abs())) else {
        return Ok(());
    };
    let step = f64::from(sensor.settings.units_per_code());
    let varies = finite.iter().any(|&(_, v)| v != finite[0].1);
    if !(varies && top.abs() < step) {
        return Ok(());
    }
    let (p_lo, p_hi) = sensor.physical;
    let Some(other) = data.and_then(|c| {
        let mut units: Vec<_> = c.likely.iter().collect();
        units.sort_by(|a, b| b.factor.total_cmp(&a.factor));
        units.into_iter().find(|u| {
            finite
                .iter()
                .all(|&(_, v)| (p_lo..=p_hi).contains(&(v * u.factor + u.offset)))
        })
    }) else {
        return Ok(());
    };
    Err(format!(
        "{}: {} {unit}, the column's largest reading: every reading lies within {} {unit} of zero, less than one \
         step of the sensor's {}-bit ADC over monitor.range_min..range_max = {} to {} {unit}, where the device's {} \
         spans {} to {} {unit}; written in {}? ({} {} = {} {unit})",
        log.at(largest, name),
        sig(top, 6),
        sig(step, 4),
        sensor.settings.bits,
        sig(min, 6),
        sig(max, 6),
        second.column.doc.split(" [").next().unwrap_or(name),
        sig(p_lo, 6),
        sig(p_hi, 6),
        other.name,
        sig(top, 6),
        other.name,
        sig(top * other.factor + other.offset, 6)
    ))
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

/// The output's header: `time_s`, [`COLUMNS`], with a monitor of
/// `quantity` its health columns ([`health_columns`]), `flags`.
pub fn header(quantity: Option<MonitorQuantity>) -> Vec<String> {
    let mut h = vec![TIME_COLUMN.to_string()];
    h.extend(COLUMNS.iter().map(|c| c.to_string()));
    if let Some(q) = quantity {
        h.extend(health_columns(q));
    }
    h.push(FLAGS_COLUMN.to_string());
    h
}

/// The health estimate's columns for a sensor of `quantity`, in
/// [`HEALTH_FIELDS`]' order: each field's name with its unit's suffix
/// (`divider`, `offset_pa`, `friction_n`).
pub fn health_columns(quantity: MonitorQuantity) -> Vec<String> {
    HEALTH_FIELDS
        .iter()
        .map(|f| format!("{}{}", f.name, f.unit.suffix(quantity)))
        .collect()
}

/// The health estimate's cells, in [`health_columns`]' order: `f32`
/// digits, a count whole, empty where the monitor has no value (before its
/// first reading; the innovation of a reading it did not apply).
pub fn health_cells(h: &HealthEstimate) -> Vec<String> {
    HEALTH_FIELDS
        .iter()
        .map(|f| {
            let v = (f.value)(h);
            if !v.is_finite() {
                String::new()
            } else if f.unit == HealthUnit::Count {
                crate::csv::number(v)
            } else {
                f32_cell(v as f32)
            }
        })
        .collect()
}

/// `v` as a cell: an `f32` in the shorter of its two shortest round-trip
/// forms (positional or with an exponent), so that it reads back as the
/// same `f32` (`0.00018324`, `1.2e-7`).
pub fn f32_cell(v: f32) -> String {
    let (plain, exp) = (format!("{v}"), format!("{v:?}"));
    if exp.len() < plain.len() { exp } else { plain }
}

/// One output row: the estimate `e` at `time_s` (the record's fields as
/// they travel: `f32` digits, a count whole), with its health estimate
/// when `health` (a monitor is fitted).
pub fn row(time_s: f64, e: &StateEstimate, health: bool) -> String {
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
    if health {
        cells.extend(health_cells(&e.health));
    }
    cells.push(e.flags.names().collect::<Vec<_>>().join("|"));
    cells.join(",")
}

/// The reading of row `i` as the estimator takes it: a temperature, or the
/// fault the firmware's driver would report (a code of 0 or 32767, a
/// resistance or code the probe's curve has no temperature for).
fn sample(log: &Log, settings: &Settings, i: usize) -> Result<Option<f32>, SensorFault> {
    let v = log.value[i];
    if v.is_nan() {
        return Ok(None);
    }
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

/// One tick of a replay ([`replay`]).
#[derive(Clone, Copy, Debug)]
pub struct Tick<'a> {
    /// The tick's number from the first row's (0).
    pub k: u64,
    /// The tick's start \[s\] ([`tick_time`]).
    pub time_s: f64,
    /// The log's row delivered on this tick (0-based), if any.
    pub row: Option<usize>,
    /// The estimate after the tick.
    pub estimate: &'a StateEstimate,
    /// The firmware publishes this tick's estimate (a telemetry tick).
    pub published: bool,
}

/// What a replay ran ([`replay`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The probe's reading interval the observer was designed for \[s\].
    pub sample_period: f64,
    /// Ticks run.
    pub ticks: u64,
    /// The estimator's tick \[s\].
    pub tick: f64,
    /// Ticks between telemetry records (0: none).
    pub telemetry_every: u32,
    /// Probe readings (rows with one).
    pub probe_readings: usize,
    /// The monitor's settings, with a second sensor's column.
    pub monitor: Option<MonitorSettings>,
    /// The second sensor's readings (rows with one).
    pub second_readings: usize,
    /// Where the second sensor stopped reporting between its first and
    /// last reading ([`SecondGaps::over`]), if it did.
    pub second_gaps: Option<SecondGaps>,
    /// The second sensor's stretches at one interval each
    /// ([`stretches`]): one for a sensor that kept its rate; none when its
    /// readings are too few to measure a period (the monitor then takes
    /// the device file's).
    pub second_stretches: Vec<Stretch>,
    /// The shortest and longest interval of the second sensor's readings
    /// \[s\], when they are too few to measure a period and have one.
    pub second_intervals: Option<(f64, f64)>,
}

/// The second sensor's readings missing from a log: between two of its
/// consecutive readings more than one and a half of its period apart (its
/// stretch's, [`stretches`]: the lower median of its intervals), the readings
/// due in between, `round(interval / period) - 1`, where each end's slot
/// is placed by the readings beside it (up to 8, on average): a reading
/// stamped early next to one stamped late, each by under half a period,
/// are no reading missing. A sensor slower than
/// the probe (a reading every few rows) has its median interval for its
/// period, so its regularly empty cells are none missing; nor are the rows
/// before its first reading or after its last.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SecondGaps {
    /// Readings missing over the log.
    pub missing: u64,
    /// Stretches where they are missing.
    pub gaps: usize,
    /// The longest stretch: the rows of the readings either side (0-based).
    pub longest: (usize, usize),
    /// Its first and last row where a reading was due (more than half a
    /// period from the readings either side), if the log has one.
    pub due: Option<(usize, usize)>,
    /// Readings missing in it.
    pub longest_missing: u64,
}

impl SecondGaps {
    /// The gaps of the readings on rows `rows` (0-based, increasing), row
    /// `i` on tick `ticks[i]`, one due every `period` ticks; `None`
    /// without one.
    pub fn of(rows: &[usize], ticks: &[u64], period: u64) -> Option<SecondGaps> {
        let period = period.max(1);
        let t = |r: usize| ticks[rows[r]] as f64;
        // Each reading's slot, counted from the first: one an interval
        // under two periods (two readings stamped up to half a period off
        // their slots), round(interval / period) from there.
        let mut slots = vec![0u64; rows.len()];
        for r in 1..rows.len() {
            let interval = ticks[rows[r]] - ticks[rows[r - 1]];
            slots[r] = slots[r - 1]
                + if interval < 2 * period {
                    1
                } else {
                    (2 * interval + period) / (2 * period)
                };
        }
        let p = period as f64;
        // Where reading `at`'s slot lies, as the readings `from` place it
        // on average: the two readings either side of a long interval may
        // be stamped late and early by up to half a period each, so their
        // interval alone can hold one slot too many.
        let nominal = |from: std::ops::Range<usize>, at: usize| {
            let n = from.len() as f64;
            from.map(|j| t(j) + (slots[at] as f64 - slots[j] as f64) * p)
                .sum::<f64>()
                / n
        };
        const AROUND: usize = 8;
        let mut found: Option<SecondGaps> = None;
        let mut longest_ticks = 0;
        for r in 1..rows.len() {
            let (a, b) = (rows[r - 1], rows[r]);
            let interval = ticks[b] - ticks[a];
            if 2 * interval <= 3 * period {
                continue;
            }
            // round(interval / period) - 1 between the slots either side.
            let before = nominal(r.saturating_sub(AROUND)..r, r - 1);
            let after = nominal(r..(r + AROUND).min(rows.len()), r);
            let between = ((after - before) / p).round();
            if between < 2.0 {
                continue;
            }
            let missing = between as u64 - 1;
            let g = found.get_or_insert(SecondGaps {
                missing: 0,
                gaps: 0,
                longest: (a, b),
                due: None,
                longest_missing: missing,
            });
            g.missing += missing;
            g.gaps += 1;
            if interval > longest_ticks {
                longest_ticks = interval;
                let due = |j: &usize| 2 * (ticks[*j] - ticks[a]) > period && 2 * (ticks[b] - ticks[*j]) > period;
                g.longest = (a, b);
                g.due = (a + 1..b).find(due).zip((a + 1..b).rev().find(due));
                g.longest_missing = missing;
            }
        }
        found
    }

    /// The line for standard error naming the longest stretch: the column,
    /// its first and last row where a reading was due (or the rows either
    /// side, when the log has none between them), how long, and what is
    /// missing.
    pub fn note(&self, log: &Log, column: &str, period: f64) -> String {
        let (a, b) = self.longest;
        let row = |i: usize| format!("row {} (line {})", i + 1, log.lines[i]);
        let rows = match self.due {
            Some((first, last)) if first == last => format!("no reading on {}", row(first)),
            Some((first, last)) => format!("no reading from {} to {}", row(first), row(last)),
            None => format!("no reading between {} and {}", row(a), row(b)),
        };
        let mut note = format!(
            "column {column}: {rows}: {} s between the readings either side, where the second sensor reads one \
             every {}; {} missing, the monitor ran without them",
            sig(log.time_s[b] - log.time_s[a], 6),
            seconds(period),
            readings(self.longest_missing)
        );
        if self.gaps > 1 {
            note.push_str(&format!(
                " (the longest of {} stretches, {} missing over the log)",
                self.gaps,
                readings(self.missing)
            ));
        }
        note
    }

    /// The gaps of the readings on rows `rows` over its `stretches`
    /// ([`stretches`]), each counted at its own stretch's period: those of
    /// all of them, the longest (in time) named; `None` without one.
    pub fn over(rows: &[usize], ticks: &[u64], stretches: &[Stretch]) -> Option<SecondGaps> {
        let mut found: Option<SecondGaps> = None;
        for s in stretches {
            let Some(g) = SecondGaps::of(&rows[s.readings.0..=s.readings.1], ticks, s.period) else {
                continue;
            };
            let Some(f) = found.as_mut() else {
                found = Some(g);
                continue;
            };
            let long = |(a, b): (usize, usize)| ticks[b] - ticks[a];
            if long(g.longest) > long(f.longest) {
                (f.longest, f.due, f.longest_missing) = (g.longest, g.due, g.longest_missing);
            }
            f.missing += g.missing;
            f.gaps += g.gaps;
        }
        found
    }
}

/// Fewest intervals a reading period is measured from: the log's for the
/// second sensor (with fewer, the device file's `monitor.sample_hz`), and
/// a stretch's at another rate (a shorter one is no change of rate).
pub const MIN_INTERVALS: usize = 8;

/// The lower median of `v` (reordered; `None` when empty), in O(n): of an
/// even count the shorter of the two middle values, as a reading missing
/// only ever lengthens an interval.
pub fn lower_median(v: &mut [u64]) -> Option<u64> {
    if v.is_empty() {
        return None;
    }
    let middle = (v.len() - 1) / 2;
    Some(*v.select_nth_unstable(middle).1)
}

/// A stretch of the second sensor's readings at one interval
/// ([`stretches`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stretch {
    /// Its first and last reading, as indices into the readings' rows
    /// (a stretch's last reading is the next one's first).
    pub readings: (usize, usize),
    /// Their rows (0-based).
    pub rows: (usize, usize),
    /// Its period \[ticks\]: the lower median of its intervals.
    pub period: u64,
}

impl Stretch {
    /// Its intervals.
    pub fn intervals(&self) -> usize {
        self.readings.1 - self.readings.0
    }
}

/// The stretches of the readings on rows `rows` (row `i` on tick
/// `ticks[i]`) at one interval each, in order, one for a sensor that kept
/// its rate. Each interval's local one is the lower median of the
/// [`MIN_INTERVALS`] + 1 around it: a long interval or a few (a gap) leave
/// it alone, a rate that lasts moves it. A stretch ends where the local
/// interval leaves its first one's by more than half as much again (the
/// 1.5 of a gap); one of fewer than [`MIN_INTERVALS`] intervals is no rate
/// of its own, but part of the stretch before it (the first, of the one
/// after), and neighbours within 1.5 of each other's period are one. Empty
/// with fewer than [`MIN_INTERVALS`] intervals: the log measures no
/// period. O(n) in the readings.
pub fn stretches(rows: &[usize], ticks: &[u64]) -> Vec<Stretch> {
    let d: Vec<u64> = rows.windows(2).map(|w| ticks[w[1]] - ticks[w[0]]).collect();
    let m = d.len();
    if m < MIN_INTERVALS {
        return Vec::new();
    }
    const HALF: usize = MIN_INTERVALS / 2;
    let mut window = [0u64; 2 * HALF + 1];
    let w = window.len().min(m);
    let local: Vec<u64> = (0..m)
        .map(|i| {
            let from = i.saturating_sub(HALF).min(m - w);
            window[..w].copy_from_slice(&d[from..from + w]);
            lower_median(&mut window[..w]).unwrap_or(1)
        })
        .collect();
    let same = |a: u64, b: u64| 2 * a.max(b) <= 3 * a.min(b);
    // Runs of one local interval, over the intervals `start..end`.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for i in 1..m {
        if !same(local[i], local[start]) {
            runs.push((start, i));
            start = i;
        }
    }
    runs.push((start, m));
    // A short run joins the one before it; short runs at the start, the
    // first long one.
    let mut kept: Vec<(usize, usize)> = Vec::new();
    let mut lead = None;
    for (s, e) in runs {
        if e - s < MIN_INTERVALS {
            match kept.last_mut() {
                Some(last) => last.1 = e,
                None => {
                    lead.get_or_insert(s);
                }
            }
        } else {
            kept.push((lead.take().unwrap_or(s), e));
        }
    }
    if kept.is_empty() {
        // Short runs only: no rate lasted apart from the others.
        kept.push((0, m));
    }
    let period = |(s, e): (usize, usize)| {
        let mut v = d[s..e].to_vec();
        lower_median(&mut v).unwrap_or(1).max(1)
    };
    // Neighbours at one rate (a short run between them joined the first).
    let mut joined: Vec<((usize, usize), u64)> = Vec::new();
    for run in kept {
        let p = period(run);
        match joined.last_mut() {
            Some((last, q)) if same(*q, p) => last.1 = run.1,
            _ => joined.push((run, p)),
        }
    }
    joined
        .into_iter()
        .map(|(run, _)| Stretch {
            readings: run,
            rows: (rows[run.0], rows[run.1]),
            period: period(run),
        })
        .collect()
}

/// `1 reading`, `n readings`.
fn readings(n: u64) -> String {
    if n == 1 {
        "1 reading".to_string()
    } else {
        format!("{n} readings")
    }
}

impl Run {
    /// `estimate: 9001 readings (t_c) over 180 s, one every 20 ms ...`:
    /// what ran, for standard error (`rows` the output's rows).
    pub fn note(&self, command: &str, log: &Log, rows: Option<(usize, bool)>) -> String {
        let n = log.time_s.len();
        let span = sig(log.time_s[n - 1] - log.time_s[0], 8);
        let mut note = format!(
            "{command}: {} readings ({}) over {span} s, one every {} (the median interval: the observer is \
             designed for it), {} ticks of {}",
            self.probe_readings,
            log.column.name,
            seconds(self.sample_period),
            self.ticks,
            seconds(self.tick),
        );
        let mut lines = Vec::new();
        if let (Some(m), Some(second)) = (&self.monitor, &log.second) {
            let name = second.column.name;
            let period = f64::from(m.sample_period);
            let stretches = &self.second_stretches;
            note.push_str(&format!(
                "; {} readings of the second sensor ({name}), one every {}",
                self.second_readings,
                seconds(period)
            ));
            if stretches.is_empty() {
                note.push_str(" (the monitor's period, the device file's: too few readings to measure one)");
                lines.push(self.few_second_readings(name, period));
            } else if stretches.len() == 1 {
                note.push_str(" (the monitor's period)");
            } else {
                let changes = stretches.len() - 1;
                note.push_str(&format!(
                    " (the monitor's period), {changes} {} of rate",
                    if changes == 1 { "change" } else { "changes" }
                ));
                lines.extend(self.second_rate_changes(log, name, period));
            }
            if let Some(g) = &self.second_gaps {
                note.push_str(&format!(", {} missing", g.missing));
                // Counted at the period of the stretch it is in.
                let at = stretches
                    .iter()
                    .find(|s| s.rows.0 <= g.longest.0 && g.longest.1 <= s.rows.1)
                    .map_or(period, |s| s.period as f64 * self.tick);
                lines.push(g.note(log, name, at));
            }
        }
        if let Some((rows, every_sample)) = rows {
            note.push_str(&format!("; {rows} rows"));
            if every_sample {
                note.push_str(", one per reading");
            } else {
                note.push_str(&format!(
                    ", one per telemetry period ({})",
                    seconds(self.telemetry_every as f64 * self.tick)
                ));
            }
        }
        for line in lines {
            note.push_str(&format!("\n{command}: {line}"));
        }
        if let Some(extra) = &log.note {
            note.push_str(&format!("\n{command}: {extra}"));
        }
        note
    }

    /// The line for standard error on a second sensor whose readings are
    /// too few to measure its period (the monitor ran at `period` \[s\],
    /// the device file's).
    fn few_second_readings(&self, column: &str, period: f64) -> String {
        let n = self.second_readings;
        let intervals = match self.second_intervals {
            Some((lo, _)) if n == 2 => format!("1 interval, {}", seconds(lo)),
            Some((lo, hi)) if lo == hi => format!("{} intervals, each {}", n - 1, seconds(lo)),
            Some((lo, hi)) => format!("{} intervals, {} to {}", n - 1, seconds(lo), seconds(hi)),
            None => "no interval".to_string(),
        };
        format!(
            "column {column}: {}, {intervals}: fewer than the {MIN_INTERVALS} intervals the second sensor's period \
             is measured from; the monitor's period is the device file's, {} (monitor.sample_hz = {} Hz), and no \
             reading is counted missing",
            readings(n as u64),
            seconds(period),
            sig(1.0 / period, 6)
        )
    }

    /// The lines for standard error on a second sensor whose interval
    /// changed (the monitor ran at `period` \[s\]): each change, and the
    /// monitor's period.
    fn second_rate_changes(&self, log: &Log, column: &str, period: f64) -> Vec<String> {
        let row = |i: usize| format!("row {} (line {}, {} s)", i + 1, log.lines[i], sig(log.time_s[i], 8));
        let at = |s: &Stretch| seconds(s.period as f64 * self.tick);
        let mut lines: Vec<String> = self
            .second_stretches
            .windows(2)
            .map(|w| {
                let (before, after) = (&w[0], &w[1]);
                format!(
                    "column {column}: the second sensor's interval changed from {} to {} at {}: one reading every \
                     {} from there to {}, {} intervals; a change of its rate, not readings missing (each stretch's \
                     missing readings are counted at its own interval)",
                    at(before),
                    at(after),
                    row(after.rows.0),
                    at(after),
                    row(after.rows.1),
                    after.intervals()
                )
            })
            .collect();
        if let Some(most) = self.second_stretches.iter().rev().max_by_key(|s| s.intervals()) {
            lines.push(format!(
                "column {column}: the monitor's period is {}, the interval of its stretch with the most readings \
                 ({} intervals of the column's {}, {} to {}); the monitor steps by each reading's own interval",
                seconds(period),
                most.intervals(),
                self.second_readings.saturating_sub(1),
                row(most.rows.0),
                row(most.rows.1)
            ));
        }
        lines
    }
}

/// Runs the estimator of the validated parameter set `raw` over `log` (see
/// the module docs), with the condition monitor of the file's second
/// sensor when the log has its column, calling `each` after every tick.
///
/// # Errors
///
/// [`CliError::Input`] naming row, line and column (prefixed by the
/// caller with the file): times that do not increase, two rows within one
/// tick, a gap between probe readings longer than the fault timeout, a log
/// longer than [`MAX_TICKS`], fewer than two probe readings, a first
/// reading the estimator cannot start at; a file whose estimator or
/// monitor cannot be built (named).
pub fn replay(raw: &RawParams, log: &Log, mut each: impl FnMut(Tick<'_>)) -> Result<Run, CliError> {
    let n = log.time_s.len();
    let probe: Vec<usize> = (0..n).filter(|&i| !log.value[i].is_nan()).collect();
    if probe.len() < 2 {
        return Err(CliError::Input(
            "one reading: the estimator needs at least two to know the log's reading interval".into(),
        ));
    }
    let hz = raw.estimator.tick_hz;
    let tick = 1.0 / hz;
    let t0 = log.time_s[0];
    let ticks = ticks_of(log, hz)?;
    // A reading interval: the lower median of the intervals, in whole
    // ticks (of two, the shorter: a missing reading lengthens one).
    let sample_period = {
        let mut intervals: Vec<u64> = probe.windows(2).map(|w| ticks[w[1]] - ticks[w[0]]).collect();
        lower_median(&mut intervals).unwrap_or(1) as f64 * tick
    };
    let config = EstimatorConfig::with_sample_period(raw, sample_period)
        .map_err(|e| CliError::Input(format!("--params: {e}")))?;
    check_gaps(log, &ticks, &probe, u64::from(config.stale_after), hz)?;
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
    let mut monitor = None;
    let mut second_readings = 0;
    let mut second_gaps = None;
    let mut second_stretches = Vec::new();
    let mut second_intervals = None;
    // The transducer driver's checks on each reading ([`DriverChecks`]).
    let mut checks = None;
    if let (Some(second), Some(sensor)) = (&log.second, SecondSensor::of(raw)?) {
        let rows: Vec<usize> = (0..n).filter(|&i| !second.value[i].is_nan()).collect();
        second_readings = rows.len();
        second_stretches = stretches(&rows, &ticks);
        // The period of the stretch with the most readings (the first of
        // equals); too few readings to measure one: the file's own.
        let m = match second_stretches.iter().rev().max_by_key(|s| s.intervals()) {
            Some(most) => {
                second_gaps = SecondGaps::over(&rows, &ticks, &second_stretches);
                sensor.monitor(most.period as f64 * tick)
            }
            None => {
                second_intervals = rows
                    .windows(2)
                    .map(|w| log.time_s[w[1]] - log.time_s[w[0]])
                    .fold(None, |r: Option<(f64, f64)>, d| {
                        Some(r.map_or((d, d), |(lo, hi)| (lo.min(d), hi.max(d))))
                    });
                sensor.monitor(f64::from(sensor.settings.period))
            }
        };
        estimator = estimator
            .with_monitor(m)
            .map_err(|e| CliError::Input(format!("--params: {e}")))?;
        monitor = Some(m);
        checks = Some(DriverChecks::new(&sensor));
    }
    let last = ticks[n - 1];
    let mut next = 0;
    for k in 0..=last {
        let row = (ticks.get(next) == Some(&k)).then_some(next);
        let reading = match row {
            Some(i) => {
                next += 1;
                if let Some(y) = log.second.as_ref().map(|s| s.value[i]).filter(|y| !y.is_nan()) {
                    let y = y as f32;
                    let reading = checks.as_mut().map_or(Ok(y), |c| c.reading(y));
                    estimator.offer_second(reading);
                }
                sample(log, &settings, i)
            }
            None => Ok(None),
        };
        let e = estimator.tick(reading);
        each(Tick {
            k,
            time_s: tick_time(t0, k, hz),
            row,
            estimate: &e,
            published: estimator.telemetry_due(),
        });
    }
    Ok(Run {
        sample_period,
        ticks: last + 1,
        tick,
        telemetry_every: config.telemetry_every,
        probe_readings: probe.len(),
        monitor,
        second_readings,
        second_gaps,
        second_stretches,
        second_intervals,
    })
}

/// Runs the estimator of the validated parameter set `raw` over `log` (see
/// the module docs) and tabulates its estimates.
///
/// # Errors
///
/// As [`replay`]; a log without a telemetry tick without
/// [`Options::every_sample`] (no row to print);
/// `estimator.telemetry_hz = 0` without [`Options::every_sample`].
pub fn run(raw: &RawParams, log: &Log, options: Options) -> Result<Replay, CliError> {
    if raw.estimator.telemetry_hz == 0.0 && !options.every_sample {
        return Err(CliError::Input(
            "--params: estimator.telemetry_hz = 0: the file asks for no telemetry; give --every-sample for one row \
             per reading"
                .into(),
        ));
    }
    let quantity = match &log.second {
        Some(_) => SecondSensor::of(raw)?.map(|s| s.monitor(1.0).quantity),
        None => None,
    };
    let mut out = header(quantity).join(",");
    out.push('\n');
    let mut rows = 0usize;
    // A reading's own flags are on its tick's estimate (never a published
    // one's: the monitor runs in a job's place) and on the next published
    // one; a row per input row carries those of the ticks since the last
    // row as well.
    let mut since = Flags::empty();
    let run = replay(raw, log, |t| {
        if !t.published {
            since.insert(Flags(t.estimate.flags.0 & compensator::monitor::PER_READING.0));
        }
        if options.every_sample && t.row.is_some() {
            // Those of its own tick are in `since` (a published tick has
            // none but the ones rows before carried).
            let mut e = *t.estimate;
            let own = core::mem::replace(&mut since, Flags::empty());
            e.flags = Flags((e.flags.0 & !compensator::monitor::PER_READING.0) | own.0);
            out.push_str(&row(t.time_s, &e, quantity.is_some()));
            out.push('\n');
            rows += 1;
        } else if !options.every_sample && t.published {
            out.push_str(&row(t.time_s, t.estimate, quantity.is_some()));
            out.push('\n');
            rows += 1;
        }
    })?;
    if rows == 0 {
        let n = log.time_s.len();
        return Err(CliError::Input(format!(
            "no telemetry tick in the log's {} s (the firmware publishes one every {}): no row to print; give \
             --every-sample for one row per reading",
            sig(log.time_s[n - 1] - log.time_s[0], 8),
            seconds(run.telemetry_every as f64 * run.tick),
        )));
    }
    Ok(Replay {
        table: out,
        sample_period: run.sample_period,
        ticks: run.ticks,
        note: run.note("estimate", log, Some((rows, options.every_sample))),
    })
}

/// The transducer driver's checks (`Transducer::read_reading`), which the
/// firmware runs on every code, on a log's readings of the second sensor:
/// first the level faults (a reading outside the measuring band: an open
/// loop, a short, out of range), one of which resets the checks, then the
/// stuck check (a reading repeated on the same code `stuck_after` times in
/// a row). Either is a fault the monitor is told of (`SECOND_SENSOR_FAULT`),
/// not a reading it takes. The driver's noisy check is not applied: a
/// log's step of the reading within one of its 64-reading windows (the
/// campaign's and `data/logs/monitor-capillary.csv`'s injected faults are
/// steps) would read as a noisy sensor.
struct DriverChecks {
    settings: transducer::Settings,
    checks: transducer::Checks,
    /// The measuring band \[Pa or m\] ([`SecondSensor::band`]).
    band: (f64, f64),
}

impl DriverChecks {
    fn new(sensor: &SecondSensor) -> Self {
        DriverChecks {
            settings: sensor.settings,
            checks: transducer::Checks::new(&sensor.settings),
            band: sensor.band(),
        }
    }

    /// Reading `y` \[Pa or m\] as the driver would pass it, or its fault.
    fn reading(&mut self, y: f32) -> Result<f32, SensorFault> {
        let code = self.settings.code_of(y);
        match self.settings.classify(code) {
            Err(fault) if !(self.band.0..=self.band.1).contains(&f64::from(y)) => {
                self.checks.reset();
                Err(fault)
            }
            _ => match self.checks.update(code) {
                Err(SensorFault::Noisy(_)) | Ok(()) => Ok(y),
                Err(fault) => Err(fault),
            },
        }
    }
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
                // A probe reading on one row and the second sensor's on
                // the other (a logger that writes each sensor's reading on
                // its own row): the estimator takes one of each a tick, on
                // one row.
                let apart = log.second.as_ref().is_some_and(|s| {
                    let probe = |j: usize| !log.value[j].is_nan();
                    let second = |j: usize| !s.value[j].is_nan();
                    (probe(i) && !second(i) && second(i - 1) && !probe(i - 1))
                        || (second(i) && !probe(i) && probe(i - 1) && !second(i - 1))
                });
                let hint = if apart {
                    format!(
                        "; the probe's reading and the second sensor's of one tick go on one row: merge rows {} and {}",
                        i,
                        i + 1
                    )
                } else {
                    String::new()
                };
                return Err(bad(
                    i,
                    format!(
                        "{} after the row before, within one tick of the estimator ({} at estimator.tick_hz = \
                         {} Hz): it takes one reading a tick{hint}",
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
fn check_gaps(log: &Log, ticks: &[u64], probe: &[usize], timeout: u64, hz: f64) -> Result<(), CliError> {
    let Some(w) = probe.windows(2).find(|w| ticks[w[1]] - ticks[w[0]] - 1 > timeout) else {
        return Ok(());
    };
    let (i, before) = (w[1], w[0]);
    let after = if before + 1 == i {
        "the row before".to_string()
    } else {
        format!("the probe reading before (row {})", before + 1)
    };
    Err(CliError::Input(format!(
        "{}: {} after {after}, longer than the estimator's fault timeout: it flags the estimate DEGRADED after {} \
         without a reading ({timeout} ticks at estimator.tick_hz = {} Hz); split the log at this row and replay \
         each part on its own",
        log.at(i, TIME_COLUMN),
        seconds(log.time_s[i] - log.time_s[before]),
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
        for q in [
            Quantity::PressureA,
            Quantity::PressureB,
            Quantity::PressureDifference,
            Quantity::Displacement,
        ] {
            assert_eq!(second_column(q).quantity, q);
            assert!(crate::data::column(second_column(q).name).is_some(), "{q:?}");
        }
        assert_eq!(
            header(None).join(","),
            "time_s,t_probe_c,t_oil_c,t_oil_sd_c,x_m,x_sd_m,p_a_pa,p_a_sd_pa,p_b_pa,p_b_sd_pa,q_total_m3s,\
             q_total_sd_m3s,compensation_error_m3s,compensation_error_sd_m3s,reseats,flags"
        );
    }

    #[test]
    fn second_gaps_count_the_readings_due_at_the_sensor_s_period() {
        // A reading every 10 ticks on rows 0..=10, none for rows 11..=39
        // (ticks 110..=390), again from row 40 (tick 400).
        let ticks: Vec<u64> = (0..60).map(|i| i * 10).collect();
        let rows: Vec<usize> = (0..60).filter(|i| !(11..40).contains(i)).collect();
        let g = SecondGaps::of(&rows, &ticks, 10).unwrap();
        assert_eq!(
            g,
            SecondGaps {
                missing: 29,
                gaps: 1,
                longest: (10, 40),
                due: Some((11, 39)),
                longest_missing: 29
            }
        );
        // A sensor at a third of the rows' rate: its period, none missing;
        // stopped, the rows where its readings were due, not the empty
        // ones beside them.
        let slow: Vec<usize> = (0..60).step_by(3).collect();
        assert_eq!(SecondGaps::of(&slow, &ticks, 30), None);
        let stopped: Vec<usize> = slow.iter().copied().filter(|i| !(12..=27).contains(i)).collect();
        let g = SecondGaps::of(&stopped, &ticks, 30).unwrap();
        assert_eq!((g.longest, g.due, g.missing), ((9, 30), Some((11, 28)), 6));
        // No row between the readings either side: none named as due.
        assert_eq!(
            SecondGaps::of(&[0, 1], &[0, 50], 10).map(|g| (g.due, g.missing)),
            Some((None, 4))
        );
        // Jitter within half a period is none; a reading dropped is one;
        // two stretches, the longer named, both counted.
        assert_eq!(SecondGaps::of(&[0, 1, 2], &[0, 14, 24], 10), None);
        assert_eq!(SecondGaps::of(&[0, 1, 2], &[0, 16, 26], 10).map(|g| g.missing), Some(1));
        let g = SecondGaps::of(&[0, 1, 2, 3], &[0, 20, 60, 70], 10).unwrap();
        assert_eq!((g.missing, g.gaps, g.longest, g.longest_missing), (4, 2, (1, 2), 3));
    }

    #[test]
    fn second_gaps_are_not_made_of_a_timestamp_s_jitter() {
        // A reading every 10 ticks, each stamped up to 3 ticks early or
        // late (under half a period): none is missing, though a reading 3
        // early followed by one 3 late are 16 ticks apart.
        let jitter = [0i64, 3, -3, 3, -2, 1, -3, 3, 0, -1, 2, -3, 3, -3, 1, 0, 2, -2, 0, 1];
        let ticks: Vec<u64> = (0..200)
            .map(|i: i64| (100 + 10 * i + jitter[i as usize % 20]) as u64)
            .collect();
        let rows: Vec<usize> = (0..200).collect();
        assert_eq!(SecondGaps::of(&rows, &ticks, 10), None);
        // The same readings with 30 of them dropped: 30 missing, one
        // stretch.
        let dropped: Vec<usize> = rows.iter().copied().filter(|i| !(90..120).contains(i)).collect();
        let g = SecondGaps::of(&dropped, &ticks, 10).unwrap();
        assert_eq!(
            (g.missing, g.gaps, g.longest, g.longest_missing),
            (30, 1, (89, 120), 30)
        );
    }

    #[test]
    fn a_reading_interval_is_the_lower_median() {
        assert_eq!(lower_median(&mut []), None);
        assert_eq!(lower_median(&mut [30]), Some(30));
        // Of two intervals the shorter: the longer may hold a gap.
        assert_eq!(lower_median(&mut [20, 980]), Some(20));
        assert_eq!(lower_median(&mut [980, 20]), Some(20));
        assert_eq!(lower_median(&mut [50, 10, 10]), Some(10));
        assert_eq!(lower_median(&mut [40, 10, 30, 20]), Some(20));
    }

    /// Rows `0..n`, row `i` on tick `ticks[i]`: every row a reading.
    fn stretches_of(ticks: &[u64]) -> Vec<(usize, usize, u64)> {
        let rows: Vec<usize> = (0..ticks.len()).collect();
        stretches(&rows, ticks)
            .iter()
            .map(|s| (s.readings.0, s.readings.1, s.period))
            .collect()
    }

    #[test]
    fn a_change_of_the_second_sensor_s_rate_is_a_stretch_of_its_own() {
        // Fewer than 8 intervals: no period measured.
        assert_eq!(stretches_of(&[0, 10, 20, 30, 40, 50, 60, 70]), []);
        assert_eq!(stretches_of(&[0, 10, 20, 30, 40, 50, 60, 70, 80]), [(0, 8, 10)]);
        // A reading every 10 ticks, 100 readings, then every 100: two
        // stretches meeting on the first reading at 100 (row 100).
        let mut ticks: Vec<u64> = (0..100).map(|i| 10 * i).collect();
        ticks.extend((0..20).map(|i| 1000 + 100 * i));
        assert_eq!(stretches_of(&ticks), [(0, 100, 10), (100, 119, 100)]);
        // The reverse.
        let mut ticks: Vec<u64> = (0..20).map(|i| 100 * i).collect();
        ticks.extend((0..100).map(|i| 2000 + 10 * i));
        assert_eq!(stretches_of(&ticks), [(0, 20, 100), (20, 119, 10)]);
        // Back and forth: three.
        let mut ticks: Vec<u64> = (0..50).map(|i| 10 * i).collect();
        ticks.extend((0..12).map(|i| 500 + 100 * i));
        ticks.extend((0..50).map(|i| 1700 + 10 * i));
        assert_eq!(stretches_of(&ticks), [(0, 50, 10), (50, 62, 100), (62, 111, 10)]);
        // Seven long intervals in a row are no rate (a gap each): one
        // stretch, the seven counted missing at its period.
        let mut ticks: Vec<u64> = (0..50).map(|i| 10 * i).collect();
        ticks.extend((1..=7).map(|i| 490 + 100 * i));
        ticks.extend((1..=50).map(|i| 1190 + 10 * i));
        assert_eq!(stretches_of(&ticks), [(0, 106, 10)]);
        let rows: Vec<usize> = (0..ticks.len()).collect();
        let g = SecondGaps::over(&rows, &ticks, &stretches(&rows, &ticks)).unwrap();
        assert_eq!((g.missing, g.gaps), (63, 7));
        // Jitter under half a period (intervals of 4 to 16 ticks) moves no
        // stretch; the lower median of those intervals is 11.
        let jitter = [0i64, 3, -3, 3, -2, 1, -3, 3, 0, -1, 2, -3, 3, -3, 1, 0, 2, -2, 0, 1];
        let ticks: Vec<u64> = (0..200)
            .map(|i: i64| (100 + 10 * i + jitter[i as usize % 20]) as u64)
            .collect();
        assert_eq!(stretches_of(&ticks), [(0, 199, 11)]);
    }

    #[test]
    fn second_gaps_are_counted_at_their_stretch_s_period() {
        // Every 10 ticks for 100 readings, then every 100 for 20, the
        // reading at tick 1500 missing: the slower stretch's intervals are
        // none missing, the dropped one is one.
        let mut ticks: Vec<u64> = (0..100).map(|i| 10 * i).collect();
        ticks.extend((0..20).map(|i| 1000 + 100 * i).filter(|&t| t != 1500));
        let rows: Vec<usize> = (0..ticks.len()).collect();
        let s = stretches(&rows, &ticks);
        assert_eq!(s.iter().map(|s| s.period).collect::<Vec<_>>(), [10, 100]);
        let g = SecondGaps::over(&rows, &ticks, &s).unwrap();
        assert_eq!((g.missing, g.gaps, g.longest, g.longest_missing), (1, 1, (104, 105), 1));
        // One period for the whole column, as before: 17 intervals of 100
        // ticks, 9 missing each, and the one of 200, 19.
        assert_eq!(SecondGaps::of(&rows, &ticks, 10).map(|g| g.missing), Some(17 * 9 + 19));
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
