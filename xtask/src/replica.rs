//! The QEMU twin's replay run again on the host: the same core (estimator,
//! MAX31865 driver, simulated converter) compiled for x86-64, fed the same
//! profile and faults (the schedule `build.rs` wrote for the firmware,
//! `replay.txt`), driven the way `src/bin/twin.rs` drives it. `cargo xtask
//! test` decodes the twin's telemetry from QEMU into CSV and compares it
//! with this replica's, row by row: the decoding (units, columns, flags)
//! and the firmware's arithmetic are both checked.

use crate::telemetry::{self, Record};
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, StateEstimate};
use compensator::params::RawParams;
use compensator::sensor::TemperatureSource;
use compensator::sensor::max31865::{Max31865, Settings, fault};
use compensator::sensor::simulated::SimulatedMax31865;
use std::path::Path;

/// The faults the replay injects: the twin image's own table, compiled
/// here too (a rename fails to compile in both).
#[path = "../../src/replay_faults.rs"]
mod replay_faults;
pub use replay_faults::Injected;
use replay_faults::{FAULTS, fault_at};

/// The replay schedule (the twin's `REPLAY_PIECES` and `SPIKE_DELTA`, in
/// `f32` as the firmware has them; the faults are [`FAULTS`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// (start s, end s, from C, to C).
    pub pieces: Vec<(f32, f32, f32, f32)>,
    /// What the spike adds [C].
    pub spike: f32,
}

impl Schedule {
    /// Parses `replay.txt`.
    pub fn parse(text: &str) -> Result<Schedule, String> {
        let mut s = Schedule {
            pieces: vec![],
            spike: 0.0,
        };
        for line in text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()) {
            let w: Vec<&str> = line.split_whitespace().collect();
            let num = |i: usize| -> Result<f32, String> {
                w.get(i)
                    .and_then(|v| v.parse::<f32>().ok())
                    .ok_or_else(|| format!("replay schedule: {line}"))
            };
            match w.first().copied() {
                Some("piece") => s.pieces.push((num(1)?, num(2)?, num(3)?, num(4)?)),
                Some("spike_delta") => s.spike = num(1)?,
                _ => return Err(format!("replay schedule: {line}")),
            }
        }
        if s.pieces.is_empty() {
            return Err("replay schedule without pieces".into());
        }
        Ok(s)
    }

    /// Reads `replay.txt` from the build script's output directory.
    pub fn read(out_dir: &Path) -> Result<Schedule, String> {
        let path = out_dir.join("replay.txt");
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        Schedule::parse(&text)
    }

    /// Temperature at `time` [s] (the twin's `temperature_at`).
    fn temperature_at(&self, time: f32) -> f32 {
        for &(t0, t1, a, b) in &self.pieces {
            if time >= t0 && time < t1 {
                return a + (b - a) * (time - t0) / (t1 - t0);
            }
        }
        self.pieces[self.pieces.len() - 1].3
    }
}

/// The telemetry line the firmware prints for `e` at `ms` (defmt and Rust
/// print an `f32` in the same shortest round-trip form).
fn line(ms: u32, e: &StateEstimate) -> String {
    let flags: Vec<&str> = e.flags.names().collect();
    let flags = if flags.is_empty() {
        "-".to_string()
    } else {
        flags.join("|")
    };
    format!(
        "{ms} ms t={} C x={} um v={} mm/s p_a={} p_b={} kPa Q_a={} Q_b={} Q_throt={} Q0={} err={} l/min [{flags}]",
        e.temperature,
        e.x * 1e6,
        e.v * 1e3,
        e.p_a * 1e-3,
        e.p_b * 1e-3,
        e.q_a * 6e4,
        e.q_b * 6e4,
        e.q_throt * 6e4,
        e.q_total * 6e4,
        e.compensation_error * 6e4,
    )
}

/// Runs the replay on the host; returns its telemetry records.
pub fn run(raw: &RawParams, schedule: &Schedule) -> Result<Vec<Record>, String> {
    let params = Params::<f32>::new(raw).map_err(|e| e.to_string())?;
    let config = EstimatorConfig::new(&raw.estimator).map_err(|e| e.to_string())?;
    let settings = Settings {
        fault_band: (-60.0, 250.0),
        ..Settings::from_params(&raw.estimator)
    };
    let start = schedule.temperature_at(0.0);
    let mut sensor = Max31865::new(SimulatedMax31865::new(settings, start), settings);
    sensor.configure().map_err(|e| format!("sensor: {e:?}"))?;
    let mut estimator = Estimator::new(&params, config, start).map_err(|e| e.to_string())?;
    let tick = config.tick();
    let end = schedule.pieces[schedule.pieces.len() - 1].1;
    let ticks = (end / tick) as u32;
    let sensor_every = config.ticks_per(settings.mains.conversion_period());
    let mut out = Vec::new();
    for k in 0..ticks {
        let time = k as f32 * tick;
        let sim = sensor.device_mut();
        sim.temperature = schedule.temperature_at(time);
        sim.bus_error = false;
        sim.fault = 0;
        sim.forced_code = None;
        match fault_at(time).map(|i| FAULTS[i].injected) {
            Some(Injected::Spike) => sim.temperature += schedule.spike,
            Some(Injected::BusError) => sim.bus_error = true,
            Some(Injected::OpenRtd) => sim.fault = fault::RTD_HIGH,
            Some(Injected::SaturatedCode) => sim.forced_code = Some(0x7FFF),
            None => {}
        }
        let sample = if k % sensor_every == 0 { sensor.read() } else { Ok(None) };
        let e = estimator.tick(sample);
        if estimator.telemetry_due() {
            let ms = (k as f32 * tick * 1e3 + 0.5) as u32;
            out.push(telemetry::parse(&line(ms, &e)).ok_or("the replica's own line does not parse")?);
        }
    }
    Ok(out)
}

/// Per column: what two runs may differ by, `rel * |reference| + abs`,
/// in SI units (the absolute part a tenth of the display's resolution).
const TOLERANCE: [(&str, f64, f64); 11] = [
    ("time_s", 0.0, 0.0),
    ("t_c", 1e-6, 1e-3),
    ("x_m", 1e-5, 1e-8),
    ("v_m_s", 1e-5, 1e-7),
    ("p_a_pa", 1e-6, 10.0),
    ("p_b_pa", 1e-6, 10.0),
    ("q_a_m3s", 1e-5, 1.7e-9),
    ("q_b_m3s", 1e-5, 1.7e-9),
    ("q_throt_m3s", 1e-5, 1.7e-9),
    ("q_total_m3s", 1e-5, 1.7e-9),
    ("compensation_error_m3s", 1e-5, 1.7e-9),
];

/// Compares the firmware's records with the replica's: same rows, same
/// flags, numbers within [`TOLERANCE`]. `Ok` says how many rows were
/// bit-identical and the largest difference per column.
pub fn compare(firmware: &[Record], replica: &[Record]) -> Result<String, String> {
    if firmware.len() != replica.len() {
        return Err(format!(
            "the firmware sent {} telemetry records, the host replica {}",
            firmware.len(),
            replica.len()
        ));
    }
    let mut worst = [0.0f64; 11];
    let mut identical = 0;
    for (i, (f, r)) in firmware.iter().zip(replica).enumerate() {
        if f.flags != r.flags {
            return Err(format!(
                "record {i} (t = {} s): flags [{}] on the firmware, [{}] on the host",
                r.time_s, f.flags, r.flags
            ));
        }
        let (a, b) = (f.numbers(), r.numbers());
        let mut same = true;
        for (c, &(name, rel, abs)) in TOLERANCE.iter().enumerate() {
            if a[c].is_nan() && b[c].is_nan() {
                continue;
            }
            let d = (a[c] - b[c]).abs();
            same &= d == 0.0;
            worst[c] = worst[c].max(d);
            if !(d <= rel * b[c].abs() + abs) {
                return Err(format!(
                    "record {i} (t = {} s): {name} {} on the firmware, {} on the host",
                    r.time_s, a[c], b[c]
                ));
            }
        }
        identical += usize::from(same);
    }
    let summary: Vec<String> = TOLERANCE
        .iter()
        .zip(worst)
        .filter(|(_, w)| *w > 0.0)
        .map(|((n, ..), w)| format!("{n} {w:.3e}"))
        .collect();
    Ok(format!(
        "{} telemetry records, {identical} bit-identical to the host replica{}",
        firmware.len(),
        if summary.is_empty() {
            String::new()
        } else {
            format!("; largest differences: {}", summary.join(", "))
        }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_reads_back_and_drives_the_same_profile() {
        let text = "# comment\npiece 0.0 3.0 26.0 26.0\npiece 3.0 55.0 26.0 78.0\nspike_delta -40.0\n";
        let s = Schedule::parse(text).unwrap();
        assert_eq!(s.pieces.len(), 2);
        assert_eq!(s.spike, -40.0);
        assert_eq!(s.temperature_at(29.0), 52.0);
        assert_eq!(s.temperature_at(100.0), 78.0);
        assert!(Schedule::parse("fault 1 2 Spike\npiece 0 1 2 3\n").is_err());
        assert!(Schedule::parse("").is_err());
        // The faults are the twin's own table.
        assert_eq!(fault_at(10.01).map(|i| FAULTS[i].injected), Some(Injected::Spike));
        assert_eq!(fault_at(10.02), None);
    }

    #[test]
    fn a_replica_agrees_with_itself_and_a_changed_row_is_found() {
        // Two seconds of the paper preset (before the first fault): the
        // comparison is exact on identical runs and names the column that
        // moved.
        let raw = compensator_params::file::load(&crate::root().join("presets/paper.toml")).unwrap();
        let s = Schedule::parse("piece 0.0 2.0 30.0 30.0\nspike_delta 40.0\n").unwrap();
        let a = run(&raw, &s).unwrap();
        assert_eq!(a.len(), 3, "telemetry every 0.5 s");
        assert!(
            compare(&a, &run(&raw, &s).unwrap())
                .unwrap()
                .contains("3 bit-identical")
        );
        let mut b = a.clone();
        b[1].p_a_pa += 50.0;
        let e = compare(&b, &a).unwrap_err();
        assert!(e.contains("p_a_pa"), "{e}");
        assert!(compare(&a[..2], &a).is_err());
    }
}
