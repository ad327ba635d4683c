//! `monitor`: what the condition monitor made of a log. The log is
//! replayed as `estimate` replays it ([`crate::estimate::replay`]: the
//! firmware's `f32` estimator with the monitor of the device file's second
//! sensor, its readings from the log's `p_a_pa`, `p_b_pa`, `dp_ab_pa` or
//! `x_m`), and summarised per flag of the monitor's
//! (`compensator::estimator::health::MONITOR_FLAGS`) that was raised: since
//! when (the row delivered on the tick that first carried it, and that
//! tick's time), for how long, and how sure (the health parameter the flag
//! is about, its estimate and standard deviation at the log's end, how
//! many standard deviations that is from the file's device, and the
//! largest CUSUM before the flag). The trace of every reading the monitor
//! took (standardised innovation, CUSUM, health parameters) is kept for
//! the figure ([`crate::plot::monitor`]).

use crate::csv::{Table, number};
use crate::error::CliError;
use crate::estimate::{Log, Run, Tick, replay};
use compensator::estimator::Flags;
use compensator::estimator::health::{HEALTH_FIELDS, MONITOR_FLAGS};
use compensator::monitor::{HealthEstimate, Quantity};
use compensator::params::RawParams;

/// The health parameter a flag is about: its field of
/// [`HEALTH_FIELDS`], the field of its standard deviation (of the
/// parameter's logarithm for a factor: `log`), or none.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Evidence {
    /// The flag's name.
    pub flag: &'static str,
    /// The health field it is about.
    pub field: &'static str,
    /// The field of its standard deviation, if it has one.
    pub sd: Option<&'static str>,
    /// The parameter is a factor whose standard deviation is of its
    /// logarithm (the file's device: 1).
    pub log: bool,
}

/// What each of the monitor's flags is about.
pub const EVIDENCE: [Evidence; 9] = [
    Evidence {
        flag: "DEVICE_CHANGED",
        field: "cusum",
        sd: None,
        log: false,
    },
    Evidence {
        flag: "CAPILLARY_RESTRICTED",
        field: "divider",
        sd: Some("sd_divider"),
        log: true,
    },
    Evidence {
        flag: "ORIFICE_CLOGGED",
        field: "divider",
        sd: Some("sd_divider"),
        log: true,
    },
    Evidence {
        flag: "SPRING_RELAXED",
        field: "spring",
        sd: Some("sd_spring"),
        log: true,
    },
    Evidence {
        flag: "PRELOAD_LOST",
        field: "offset",
        sd: Some("sd_offset"),
        log: false,
    },
    Evidence {
        flag: "PLUNGER_STICKING",
        field: "friction",
        sd: None,
        log: false,
    },
    Evidence {
        flag: "SENSOR_OFFSET",
        field: "offset",
        sd: Some("sd_offset"),
        log: false,
    },
    Evidence {
        flag: "SECOND_SENSOR_FAULT",
        field: "rejected",
        sd: None,
        log: false,
    },
    Evidence {
        flag: "INNOVATION_REJECTED",
        field: "rejected",
        sd: None,
        log: false,
    },
];

/// The summary's columns.
pub const COLUMNS: [&str; 11] = [
    "flag",
    "first_row",
    "first_line",
    "first_time_s",
    "ticks",
    "parameter",
    "estimate",
    "sd",
    "z",
    "cusum_max",
    "unit",
];

/// The value of the health field `name` in `h` (NaN for no such field).
pub fn field(h: &HealthEstimate, name: &str) -> f64 {
    HEALTH_FIELDS
        .iter()
        .find(|f| f.name == name)
        .map_or(f64::NAN, |f| (f.value)(h))
}

/// One reading the monitor took: the tick's time and its health estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// The tick's start \[s\].
    pub time_s: f64,
    /// The health estimate after the reading.
    pub health: HealthEstimate,
}

/// When a flag was first raised and how often.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Raised {
    /// The flag.
    pub flag: Flags,
    /// The log's row delivered on or last before the tick that first
    /// carried it (0-based).
    pub row: usize,
    /// That tick's start \[s\].
    pub time_s: f64,
    /// Ticks that carried it.
    pub ticks: u64,
    /// The largest CUSUM over the readings up to it.
    pub cusum_max: f64,
}

/// What [`summarise`] returns.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The table (CSV, [`COLUMNS`]): a row per flag raised, in bit order.
    pub table: String,
    /// The flags raised, in bit order.
    pub raised: Vec<Raised>,
    /// Every reading the monitor took.
    pub trace: Vec<Point>,
    /// The monitor's quantity.
    pub quantity: Quantity,
    /// The health estimate at the log's end.
    pub last: HealthEstimate,
    /// What the replay ran.
    pub run: Run,
}

/// Replays `log` through the estimator of the validated parameter set
/// `raw` with its monitor and summarises the monitor's flags.
///
/// # Errors
///
/// [`CliError::Input`]: a file without a second sensor, a log without its
/// column (naming both), and as [`replay`].
pub fn summarise(raw: &RawParams, log: &Log) -> Result<Summary, CliError> {
    let Some(sensor) = crate::estimate::SecondSensor::of(raw)? else {
        return Err(CliError::Input(
            "--params: monitor.sensor = \"none\": the file has no second sensor for the monitor; name it in a \
             [monitor] section (docs/parameters.md)"
                .into(),
        ));
    };
    let column = crate::estimate::second_column(sensor.settings.quantity).name;
    let Some(second) = &log.second else {
        // A telemetry CSV has a column of that name, the estimator's
        // estimate: say so rather than that the column is missing.
        let why = match &log.note {
            Some(note) => format!("{note}; the monitor's input is a log of the sensor's readings"),
            None => format!(
                "no column {column}: the readings of the file's second sensor (monitor.sensor = \"{}\") are the \
                 monitor's input",
                sensor.settings.quantity.name()
            ),
        };
        return Err(CliError::Input(why));
    };
    if second.value.iter().all(|v| v.is_nan()) {
        return Err(CliError::Input(format!(
            "column {column}: no reading in any row: the readings of the file's second sensor (monitor.sensor = \
             \"{}\") are the monitor's input",
            sensor.settings.quantity.name()
        )));
    }
    let quantity = sensor.monitor(1.0).quantity;
    let mut raised: Vec<Raised> = Vec::new();
    let mut trace: Vec<Point> = Vec::new();
    let mut cusum_max = 0.0f64;
    let mut last_row = 0usize;
    let mut last = HealthEstimate::NONE;
    let mut seen = (u32::MAX, u32::MAX, u32::MAX);
    let run = replay(raw, log, |t: Tick<'_>| {
        if let Some(r) = t.row {
            last_row = r;
        }
        let h = t.estimate.health;
        // A reading taken: the monitor's prediction, innovation or CUSUM moved.
        let key = (h.predicted.to_bits(), h.innovation.to_bits(), h.cusum.to_bits());
        if key != seen && h.predicted.is_finite() {
            seen = key;
            trace.push(Point {
                time_s: t.time_s,
                health: h,
            });
            if h.cusum.is_finite() {
                cusum_max = cusum_max.max(f64::from(h.cusum));
            }
        }
        last = h;
        let flags = t.estimate.flags.0 & MONITOR_FLAGS.0;
        for bit in 0..32 {
            let flag = Flags(1 << bit);
            if flags & flag.0 == 0 {
                continue;
            }
            match raised.iter_mut().find(|r| r.flag == flag) {
                Some(r) => r.ticks += 1,
                None => raised.push(Raised {
                    flag,
                    row: last_row,
                    time_s: t.time_s,
                    ticks: 1,
                    cusum_max,
                }),
            }
        }
    })?;
    raised.sort_by_key(|r| r.flag.0);
    let mut table = Table::complete(&COLUMNS);
    for r in &raised {
        let name = r.flag.names().next().unwrap_or("");
        let evidence = EVIDENCE.iter().find(|e| e.flag == name);
        let (parameter, estimate, sd, z) = match evidence {
            Some(e) => {
                let v = field(&last, e.field);
                let sd = e.sd.map_or(f64::NAN, |s| field(&last, s));
                let z = if e.log { v.ln() / sd } else { v / sd };
                (e.field, v, sd, z)
            }
            None => ("", f64::NAN, f64::NAN, f64::NAN),
        };
        let unit = HEALTH_FIELDS
            .iter()
            .find(|f| f.name == parameter)
            .map_or("", |f| f.unit.symbol(quantity));
        let cell = |v: f64| if v.is_finite() { number(v) } else { String::new() };
        table.row_cells(&[
            name.to_string(),
            (r.row + 1).to_string(),
            log.lines[r.row].to_string(),
            number(r.time_s),
            r.ticks.to_string(),
            parameter.to_string(),
            cell(estimate),
            cell(sd),
            cell(z),
            cell(r.cusum_max),
            unit.to_string(),
        ]);
    }
    Ok(Summary {
        table: table.as_str().to_string(),
        raised,
        trace,
        quantity,
        last,
        run,
    })
}

impl Summary {
    /// The lines for standard error: what ran, and the health estimate at
    /// the log's end (or that no flag was raised).
    pub fn notes(&self, log: &Log) -> Vec<String> {
        let mut notes = vec![self.run.note("monitor", log, None)];
        let h = &self.last;
        let unit = if self.quantity.is_pressure() { "Pa" } else { "m" };
        notes.push(format!(
            "monitor: at the log's end divider {} (sd of ln {}), spring {} (sd of ln {}), offset {} {unit} (sd {}), \
             friction {} N, CUSUM {}, {} readings rejected",
            crate::display::sig(f64::from(h.divider), 5),
            crate::display::sig(f64::from(h.sd_divider), 3),
            crate::display::sig(f64::from(h.spring), 5),
            crate::display::sig(f64::from(h.sd_spring), 3),
            crate::display::sig(f64::from(h.offset), 4),
            crate::display::sig(f64::from(h.sd_offset), 3),
            crate::display::sig(f64::from(h.friction), 3),
            crate::display::sig(f64::from(h.cusum), 3),
            h.rejected
        ));
        if self.raised.is_empty() {
            notes.push("monitor: no flag raised over the log".into());
        }
        notes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_monitor_flag_has_its_evidence_among_the_health_fields() {
        let names: Vec<&str> = MONITOR_FLAGS.names().collect();
        assert_eq!(names, EVIDENCE.iter().map(|e| e.flag).collect::<Vec<_>>());
        for e in EVIDENCE {
            assert!(HEALTH_FIELDS.iter().any(|f| f.name == e.field), "{}", e.field);
            if let Some(sd) = e.sd {
                assert!(HEALTH_FIELDS.iter().any(|f| f.name == sd), "{sd}");
            }
        }
        assert!(field(&HealthEstimate::NONE, "no such field").is_nan());
    }
}
