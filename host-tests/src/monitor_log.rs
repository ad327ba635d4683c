//! Logs for `compensator estimate` and `compensator monitor` with a second
//! sensor's column: the records of a seeded device of a parameter file
//! ([`crate::campaign`]), a fault injected, as a CSV of `time_s`, the
//! probe's `t_c` and the second sensor's column (`p_a_pa`, `p_b_pa`,
//! `dp_ab_pa` or `x_m`), a cell empty where its sensor has no reading on
//! that tick. `data/logs/monitor-capillary.csv` is [`documented`]'s,
//! `data/logs/monitor-capillary-bar.csv` [`in_bar`]'s.

use crate::campaign::{Fault, Injection, Profile, Quantity, Scenario, SecondSensor};
use compensator::params::RawParams;
use std::fmt::Write;

/// Where the documented log lives in the repository.
pub const DOCUMENTED_LOG: &str = "data/logs/monitor-capillary.csv";

/// Where the documented log's first second, in bar, lives.
pub const DOCUMENTED_BAR_LOG: &str = "data/logs/monitor-capillary-bar.csv";

/// The documented log's device file.
pub const DOCUMENTED_PARAMS: &str = "presets/paper-monitor.toml";

/// What a log holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// The fault, from `onset` \[s\] on.
    pub fault: Fault,
    /// Its onset \[s\].
    pub onset: f64,
    /// The oil: held at `from` \[C\] until the onset, then ramping at `rate`
    /// \[C/s\] (negative: cooling) for the rest of the log.
    pub from: f64,
    /// The ramp's rate \[C/s\].
    pub rate: f64,
    /// The log's length \[s\].
    pub duration: f64,
    /// The second sensor's reading rate \[Hz\].
    pub sensor_hz: f64,
    /// The seed of the device as built, the sensors' offsets and noises.
    pub seed: u64,
}

impl Spec {
    /// The documented log's: a capillary restricted to 0.8 of its
    /// conductance at 20 s, the oil held at 60 C, then cooling at 0.1 C/s,
    /// 60 s, the second sensor at the file's 100 Hz, seed 11.
    pub const DOCUMENTED: Spec = Spec {
        fault: Fault::CapillaryRestricted(0.8),
        onset: 20.0,
        from: 60.0,
        rate: -0.1,
        duration: 60.0,
        sensor_hz: 100.0,
        seed: 11,
    };
}

/// The log of `spec` for the device file `raw` (its `monitor.sensor`
/// names the quantity; the campaign's default sensor for it reads:
/// class 0.1, noise 0.05 % of the span, 12 bits) and its rows.
///
/// # Errors
///
/// A file without a second sensor; a fault the device cannot have.
pub fn log(raw: &RawParams, spec: &Spec) -> Result<(String, usize), String> {
    let names = ["none", "p_a", "p_b", "dp_ab", "x"];
    let name = names.get(raw.monitor.sensor as usize).copied().unwrap_or("none");
    let quantity = Quantity::parse(name).ok_or("no second sensor (monitor.sensor = \"none\")")?;
    let column = format!("{name}_{}", quantity.unit().to_ascii_lowercase());
    let sensor = SecondSensor {
        rate_hz: spec.sensor_hz,
        ..SecondSensor::default_for(quantity, &raw.core)
    };
    let injection = Injection {
        fault: spec.fault,
        onset: spec.onset,
    };
    let end = spec.from + spec.rate * (spec.duration - spec.onset);
    let profile = Profile::ramp(spec.from, end, spec.rate.abs(), spec.onset);
    let scenario = Scenario::new(raw, sensor, injection, profile, spec.duration, spec.seed);
    let mut text = format!("time_s,t_c,{column}\n");
    let cell = |v: Option<f64>| v.filter(|v| v.is_finite()).map_or(String::new(), |v| format!("{v}"));
    let mut rows = 0;
    for s in scenario.records()? {
        let (probe, second) = (cell(s.probe), cell(s.second));
        if probe.is_empty() && second.is_empty() {
            continue;
        }
        let _ = writeln!(text, "{},{probe},{second}", s.t);
        rows += 1;
    }
    Ok((text, rows))
}

/// [`DOCUMENTED_LOG`]'s text: [`log`] of [`Spec::DOCUMENTED`] for
/// [`DOCUMENTED_PARAMS`].
///
/// # Errors
///
/// As [`log`]; the preset not loading.
pub fn documented() -> Result<String, String> {
    let raw = compensator_cli::load(&crate::repo_root().join(DOCUMENTED_PARAMS)).map_err(|e| e.to_string())?;
    log(&raw, &Spec::DOCUMENTED).map(|(text, _)| text)
}

/// The first `seconds` \[s\] of a pressure log `text` of [`log`] with its
/// second sensor's column in bar instead of Pa (the column's name kept):
/// the mistake `compensator estimate` and `monitor` refuse.
pub fn in_bar(text: &str, seconds: f64) -> String {
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        if i == 0 {
            out.push_str(line);
        } else {
            let t: f64 = cells[0].parse().unwrap_or(f64::INFINITY);
            if t > seconds {
                break;
            }
            let bar = cells[2]
                .parse::<f64>()
                .map_or(String::new(), |p| format!("{}", p / 1e5));
            let _ = write!(out, "{},{},{bar}", cells[0], cells[1]);
        }
        out.push('\n');
    }
    out
}
