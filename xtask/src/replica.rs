//! The QEMU twin's replay run again on the host: the same core (estimator,
//! the file's sensor driver over its simulator: the MAX31865's or the NTC's
//! on the STM32F4 ADC) compiled for x86-64, fed the same
//! profile, through the same simulated probe (its lag and noise,
//! `compensator_testbench::probe`), and faults (the schedule `build.rs` wrote for the firmware,
//! `replay.txt`, and the faults of `compensator_testbench::faults`), driven the way `src/bin/twin.rs` drives it. `cargo xtask
//! test` decodes the twin's telemetry from QEMU into CSV and compares it
//! with this replica's estimates, row by row: the decoding (units,
//! columns, flags) and the firmware's arithmetic are both checked. The
//! replica's records are its estimates as the wire carries them
//! (`telemetry::Record::of`), never decoded text, so a column the decoder
//! drops or misplaces shows. For a device file with the condition
//! monitor's second sensor, the replica reads it as the twin image does
//! (the same transducer on the simulated ADC, driven by the schedule's
//! `compensator_testbench::monitor` track) and its records carry the
//! health columns.

use crate::telemetry::Record;
use compensator::Params;
use compensator::estimator::telemetry::{self as wire, FIELDS};
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::params::RawParams;
use compensator::sensor::device::SensorKind;
use compensator::sensor::simulated::{SimulatedNtc, SimulatedRtd, SimulatedSource};
use compensator_testbench::faults::{FAULTS, Injected, fault_at};
use compensator_testbench::monitor::{SEED, Track};
use compensator_testbench::probe::{REPLAY_SEED, SimulatedProbe};
use compensator_testbench::temperature_at;
use std::path::Path;

/// The replay schedule as the twin image has it (`f32`), from the text
/// the build script wrote for the replica (`replay.txt`,
/// `compensator_codegen::replay::Schedule`).
pub type Schedule = compensator_codegen::replay::Schedule<f32>;

/// Reads `replay.txt` from the build script's output directory.
pub fn read_schedule(out_dir: &Path) -> Result<Schedule, String> {
    let path = out_dir.join("replay.txt");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    Schedule::parse(&text)
}

/// The simulated element's fault band in the replay \[C\]: wide, so that
/// the estimator's oil range is what rejects samples (as `src/bin/twin.rs`).
pub const REPLAY_BAND: (f32, f32) = (-60.0, 250.0);

/// Runs the replay on the host with the file's sensor; returns its
/// telemetry records.
pub fn run(raw: &RawParams, schedule: &Schedule) -> Result<Vec<Record>, String> {
    match SensorKind::of(&raw.estimator) {
        SensorKind::Rtd => run_with::<SimulatedRtd>(raw, schedule),
        SensorKind::Ntc => run_with::<SimulatedNtc>(raw, schedule),
    }
}

/// [`run`] with the simulated sensor `S`.
fn run_with<S: SimulatedSource>(raw: &RawParams, schedule: &Schedule) -> Result<Vec<Record>, String> {
    let params = Params::<f32>::new(raw).map_err(|e| e.to_string())?;
    let config = EstimatorConfig::new(raw).map_err(|e| e.to_string())?;
    let (pieces, spike) = (&schedule.pieces, schedule.spike);
    let start = temperature_at(pieces, 0.0);
    let mut sensor = S::simulated(&raw.estimator, REPLAY_BAND, start);
    sensor.start().map_err(|e| format!("sensor: {e}"))?;
    let mut estimator = Estimator::new(&params, config, start).map_err(|e| e.to_string())?;
    let tick = config.tick();
    // The second sensor, as the twin image with the monitor reads it.
    let monitor = compensator_codegen::monitor_settings(raw)?;
    let track = match (&monitor, &schedule.monitor) {
        (Some(_), Some(m)) => Some(Track {
            truth: &m.truth,
            restricted_from: m.restricted_from,
            open_loop: m.open_loop,
        }),
        (None, None) => None,
        _ => return Err("the replay schedule and the device file disagree on a second sensor".into()),
    };
    let mut second = match (monitor, &track) {
        (Some((transducer, settings)), Some(track)) => {
            estimator = estimator.with_monitor(settings).map_err(|e| e.to_string())?;
            let sim = compensator::sensor::transducer::simulated(transducer, track.reading(0.0, start), SEED);
            Some((sim, config.ticks_per(transducer.period)))
        }
        _ => None,
    };
    let layout = if second.is_some() {
        wire::Layout::Monitor
    } else {
        wire::Layout::Plain
    };
    // The probe the twin image reads the oil through (its lag and noise).
    let p = &raw.probe;
    let mut probe = SimulatedProbe::new(
        start,
        p.time_constant as f32,
        p.well_time_constant as f32,
        p.noise as f32,
        tick,
        REPLAY_SEED,
    );
    let end = pieces[pieces.len() - 1].1;
    let ticks = (end / tick) as u32;
    let sensor_every = config.ticks_per(sensor.sample_period());
    let mut out = Vec::new();
    for k in 0..ticks {
        let time = k as f32 * tick;
        let oil = temperature_at(pieces, time);
        let reading = probe.advance(oil);
        let injected = fault_at(time).map(|i| FAULTS[i].injected);
        let delta = if injected == Some(Injected::Spike) { spike } else { 0.0 };
        sensor.set_temperature(reading + delta);
        sensor.inject(injected.and_then(Injected::injection));
        let sample = if k % sensor_every == 0 { sensor.read() } else { Ok(None) };
        if let (Some((sim, every)), Some(track)) = (second.as_mut(), &track) {
            track.drive(sim, time, oil);
            if k % *every == 0 {
                estimator.offer_second(sim.read());
            }
        }
        let e = estimator.tick(sample);
        if estimator.telemetry_due() {
            let ms = (k as f32 * tick * 1e3 + 0.5) as u32;
            // The estimate as its record carries it, straight from the
            // estimate (not through the decoder the firmware's records
            // went through: a field the decoder dropped or misplaced
            // differs).
            out.push(Record {
                time_s: f64::from(ms) * 1e-3,
                values: wire::Record::of_layout(&e, layout),
            });
        }
    }
    Ok(out)
}

/// Compares the firmware's records with the replica's: same rows, same
/// times and flags, every field within its [`wire::Field::tolerance`] (NaN
/// where the other is NaN). `Ok` says how many rows were bit-identical and
/// the largest difference per column.
pub fn compare(firmware: &[Record], replica: &[Record]) -> Result<String, String> {
    if firmware.len() != replica.len() {
        return Err(format!(
            "the firmware sent {} telemetry records, the host replica {}",
            firmware.len(),
            replica.len()
        ));
    }
    let mut worst = [0.0f64; FIELDS.len()];
    let mut identical = 0;
    for (i, (f, r)) in firmware.iter().zip(replica).enumerate() {
        if f.time_s != r.time_s {
            return Err(format!(
                "record {i}: at {} s on the firmware, {} s on the host",
                f.time_s, r.time_s
            ));
        }
        if f.values.flags != r.values.flags {
            return Err(format!(
                "record {i} (t = {} s): flags [{}] on the firmware, [{}] on the host",
                r.time_s,
                f.flags(),
                r.flags()
            ));
        }
        let (a, b) = (f.values.values(), r.values.values());
        let mut same = true;
        for (c, field) in FIELDS.iter().enumerate() {
            if a[c].is_nan() && b[c].is_nan() {
                continue;
            }
            let d = if a[c] == b[c] { 0.0 } else { (a[c] - b[c]).abs() };
            same &= d == 0.0;
            worst[c] = worst[c].max(d);
            if !(d <= field.tolerance(b[c])) {
                return Err(format!(
                    "record {i} (t = {} s): {} {} on the firmware, {} on the host",
                    r.time_s, field.column, a[c], b[c]
                ));
            }
        }
        identical += usize::from(same);
    }
    let summary: Vec<String> = FIELDS
        .iter()
        .zip(worst)
        .filter(|(_, w)| *w > 0.0)
        .map(|(f, w)| format!("{} {w:.3e}", f.column))
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
        b[1].values.p_a_pa += 50.0;
        let e = compare(&b, &a).unwrap_err();
        assert!(e.contains("p_a_pa"), "{e}");
        // Every column the record carries is compared: one the decoder
        // lost (NaN) is found (a plain record's health columns are NaN on
        // both sides).
        for (c, field) in wire::Layout::Plain.fields().iter().enumerate() {
            let mut values = a[2].values.values();
            values[c] = f64::NAN;
            let mut b = a.clone();
            b[2].values = wire::Record::from_values(values, a[2].values.flags);
            let e = compare(&b, &a).unwrap_err();
            assert!(e.contains(field.column), "{e}");
        }
        assert!(compare(&a[..2], &a).is_err());
    }

    #[test]
    fn a_replica_with_the_monitor_carries_its_columns() {
        // Two seconds at 30 C of the monitor's preset: its transducer
        // reads 2.4e5 Pa (the schedule's truth, not the device's: the
        // replica reads what it is given), its loop open from 1.0 to 1.2 s.
        let raw = compensator_params::file::load(&crate::root().join("presets/paper-monitor.toml")).unwrap();
        let text = "piece 0.0 2.0 30.0 30.0\nspike_delta 40.0\nmonitor_restricted_from 100.0\n\
                    monitor_open_loop 1.0 1.2\nmonitor_truth 20.0 240000.0 250000.0\n\
                    monitor_truth 40.0 240000.0 250000.0\n";
        let s = Schedule::parse(text).unwrap();
        let a = run(&raw, &s).unwrap();
        assert_eq!(a.len(), 3);
        assert!(a.iter().all(|r| r.values.layout() == wire::Layout::Monitor));
        // The monitor took readings (its divider's standard deviation
        // shrank from its prior, 0.1) and read no fault but the open loop.
        assert!(a[2].values.divider_sd < 0.1, "{}", a[2].values.divider_sd);
        assert_eq!(a[2].values.rejected, 0.0);
        assert!(
            compare(&a, &run(&raw, &s).unwrap())
                .unwrap()
                .contains("3 bit-identical")
        );
        for (c, field) in FIELDS.iter().enumerate().skip(wire::HEALTH_FROM) {
            let mut values = a[1].values.values();
            values[c] = f64::NAN;
            let mut b = a.clone();
            b[1].values = wire::Record::from_values(values, a[1].values.flags);
            let e = compare(&b, &a).unwrap_err();
            assert!(e.contains(field.column), "{e}");
        }
        // A schedule without the track for a file with the sensor is refused.
        let plain = Schedule::parse("piece 0.0 2.0 30.0 30.0\nspike_delta 40.0\n").unwrap();
        assert!(run(&raw, &plain).is_err());
    }
}
