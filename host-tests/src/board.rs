//! A board's run on the host, and the logs it leaves: what `cargo xtask
//! flash --csv` (or `run --csv` on QEMU) records, and a probe log of the
//! converter's readings, for `compensator estimate` to replay.
//!
//! The run drives the firmware's pieces as `src/bin/board.rs` and the
//! QEMU twin's host replica (`xtask/src/replica.rs`) do: the oil follows a
//! piecewise-linear profile; the probe lags it by the device file's
//! `[probe]` (its first-order lags, exact per tick for the oil's linear
//! change over the tick, in `f64`) and reads with the file's noise
//! (seeded); the simulated MAX31865 converts that temperature (the file's
//! RTD and reference: the converter's quantization), the real driver reads
//! it once per conversion period, with the replay's injected faults
//! (`compensator_testbench::faults`) if asked; the estimator is the `f32`
//! one of `EstimatorConfig::new`, ticking at `estimator.tick_hz`, and each
//! tick the firmware publishes on becomes a telemetry record
//! (`telemetry::Record::of`: the estimate as the wire carries it), at the
//! time in ms the firmware's line carries.

use crate::coverage::normal;
use crate::random::Rng;
use compensator::Params;
use compensator::estimator::telemetry::{Encoding, FIELDS, Record};
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::params::RawParams;
use compensator::sensor::TemperatureSource;
use compensator::sensor::max31865::{Max31865, Settings, fault};
use compensator::sensor::simulated::SimulatedMax31865;
use compensator_testbench::faults::{FAULTS, Injected, fault_at};

/// A profile of the oil: (start s, end s, from C, to C) in time order; a
/// piece with `from == to` is a hold.
pub type Pieces = [(f64, f64, f64, f64)];

/// The round trip's profile: holds of a minute (ten time constants of a
/// 6 s probe) at 40, 60, 50 and 30 C, joined by ramps of 0.5 C/s and a
/// 10 C step, 320 s in all. With the injected faults, the replay's
/// spike, bus errors, open RTD, saturated code (10-40 s, in the first
/// hold) and its one second without readings (69-70 s, in the first ramp)
/// fall in it.
pub const ROUND_TRIP: [(f64, f64, f64, f64); 6] = [
    (0.0, 60.0, 40.0, 40.0),
    (60.0, 100.0, 40.0, 60.0),
    (100.0, 160.0, 60.0, 60.0),
    (160.0, 220.0, 50.0, 50.0),
    (220.0, 260.0, 50.0, 30.0),
    (260.0, 320.0, 30.0, 30.0),
];

/// The documented log's profile (`data/logs/probe-warm-up.csv`): 20 s at
/// 40 C, a warm-up of 0.5 C/s to 60 C, a minute's hold.
pub const WARM_UP: [(f64, f64, f64, f64); 3] = [
    (0.0, 20.0, 40.0, 40.0),
    (20.0, 60.0, 40.0, 60.0),
    (60.0, 120.0, 60.0, 60.0),
];

/// The oil temperature of `pieces` at `t` [s] (the last piece's end value
/// after it).
pub fn oil_at(pieces: &Pieces, t: f64) -> f64 {
    for &(t0, t1, a, b) in pieces {
        if t >= t0 && t < t1 {
            return a + (b - a) * (t - t0) / (t1 - t0);
        }
    }
    pieces.last().map_or(0.0, |p| p.3)
}

/// One telemetry record: the line's time [s] (whole ms) and the record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Telemetry {
    /// Time since start [s], as the line's whole ms carry it.
    pub time_s: f64,
    /// The oil's true temperature then [C].
    pub oil: f64,
    /// The record.
    pub record: Record,
}

/// What a run left.
#[derive(Clone, Debug, PartialEq)]
pub struct BoardRun {
    /// The telemetry records.
    pub telemetry: Vec<Telemetry>,
    /// Every reading the driver returned a temperature for: (tick's time
    /// [s], temperature [C]).
    pub readings: Vec<(f64, f32)>,
}

/// Runs a board with the device `raw` over `pieces` (see the module docs);
/// the converter's noise from `seed`; the replay's faults when `faults`.
///
/// # Errors
///
/// The parameters, the estimator's settings or the converter refused
/// (described).
pub fn run(raw: &RawParams, pieces: &Pieces, faults: bool, seed: u64) -> Result<BoardRun, String> {
    let params = Params::<f32>::new(raw).map_err(|e| e.to_string())?;
    let config = EstimatorConfig::new(raw).map_err(|e| e.to_string())?;
    let settings = Settings {
        fault_band: (-60.0, 250.0),
        ..Settings::from_params(&raw.estimator)
    };
    let start = oil_at(pieces, 0.0);
    let mut sensor = Max31865::new(SimulatedMax31865::new(settings, start as f32), settings);
    sensor.configure().map_err(|e| format!("sensor: {e:?}"))?;
    let mut estimator = Estimator::new(&params, config, start as f32).map_err(|e| e.to_string())?;
    let tick = f64::from(config.tick());
    let every = config.ticks_per(settings.mains.conversion_period());
    let end = pieces.last().map_or(0.0, |p| p.1);
    let ticks = (end / tick).round() as u32;
    let (tau, tau_w) = (raw.probe.time_constant, raw.probe.well_time_constant);
    let (mut well, mut probe) = (start, start);
    let mut rng = Rng::new(seed);
    let mut out = BoardRun {
        telemetry: Vec::new(),
        readings: Vec::new(),
    };
    for k in 0..ticks {
        let time = k as f64 * tick;
        // The lags' exact response to the oil's linear change over the
        // tick before this one.
        if k > 0 {
            let (u0, u1) = (oil_at(pieces, time - tick), oil_at(pieces, time));
            let slope = (u1 - u0) / tick;
            let lag = |y: f64, u0: f64, s: f64, tc: f64| {
                let e = (-tick / tc).exp();
                u0 + s * tick - s * tc + (y - u0 + s * tc) * e
            };
            if tau_w > 0.0 {
                let w0 = well;
                well = lag(well, u0, slope, tau_w);
                probe = lag(probe, w0, (well - w0) / tick, tau);
            } else {
                probe = lag(probe, u0, slope, tau);
            }
        }
        let reading = k % every == 0;
        let sim = sensor.device_mut();
        sim.temperature = if reading {
            (probe + raw.probe.noise * normal(&mut rng)) as f32
        } else {
            probe as f32
        };
        sim.bus_error = false;
        sim.fault = 0;
        sim.forced_code = None;
        if faults {
            match fault_at(time as f32).map(|i| FAULTS[i].injected) {
                Some(Injected::Spike) => sim.temperature += 2.0 * raw.estimator.spike_threshold as f32,
                Some(Injected::BusError) => sim.bus_error = true,
                Some(Injected::Open) => sim.fault = fault::RTD_HIGH,
                Some(Injected::SaturatedCode) => sim.forced_code = Some(0x7FFF),
                None => {}
            }
        }
        let sample = if reading { sensor.read() } else { Ok(None) };
        if let Ok(Some(t)) = sample {
            out.readings.push((time, t));
        }
        let e = estimator.tick(sample);
        if estimator.telemetry_due() {
            // The line's time in whole ms, as the firmware prints it.
            let ms = (time * 1e3).round();
            out.telemetry.push(Telemetry {
                time_s: ms * 1e-3,
                oil: oil_at(pieces, time),
                record: Record::of(&e),
            });
        }
    }
    Ok(out)
}

/// The header of the telemetry CSV (`cargo xtask run --csv`): `time_s`,
/// the record's columns, `flags`.
pub fn telemetry_header() -> String {
    let mut h = vec!["time_s"];
    h.extend(FIELDS.iter().map(|f| f.column));
    h.push("flags");
    h.join(",")
}

/// The telemetry CSV of `records`, as `cargo xtask run --csv` and `flash
/// --csv` write it (`xtask/src/telemetry.rs`): an `f32` field in its
/// shortest `f32` digits, the rest as `f64`, the flags' names joined by
/// `|`.
pub fn telemetry_csv(records: &[Telemetry]) -> String {
    let mut out = telemetry_header();
    out.push('\n');
    for r in records {
        let mut cells = vec![r.time_s.to_string()];
        for (f, v) in FIELDS.iter().zip(r.record.values()) {
            cells.push(match f.encoding {
                Encoding::F32 => (v as f32).to_string(),
                _ => v.to_string(),
            });
        }
        cells.push(r.record.flags.names().collect::<Vec<_>>().join("|"));
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// A probe log of `readings` (`time_s,t_c`, the converter's temperatures
/// to every `f32` digit), headed by `comment` lines.
pub fn probe_log_csv(readings: &[(f64, f32)], comment: &[&str]) -> String {
    let mut out = String::new();
    for line in comment {
        out.push_str("# ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str("time_s,t_c\n");
    for (t, v) in readings {
        out.push_str(&format!("{},{}\n", (t * 1e6).round() / 1e6, v));
    }
    out
}

/// Where the documented probe log lives in the repository.
pub const WARM_UP_LOG: &str = "data/logs/probe-warm-up.csv";

/// The documented probe log (`data/logs/probe-warm-up.csv`): the readings
/// of a board with the device `raw` (the paper preset: a 6 s probe, noise
/// 0.02 C, a PT100 through a MAX31865 at 50 Hz) over [`WARM_UP`], without
/// faults, seed 1.
///
/// # Errors
///
/// As [`run`].
pub fn warm_up_log(raw: &RawParams) -> Result<String, String> {
    let run = run(raw, &WARM_UP, false, 1)?;
    Ok(probe_log_csv(
        &run.readings,
        &[
            "A probe log: the MAX31865's readings of a PT100 in its well (6 s) while the oil",
            "holds 40 C for 20 s, warms up at 0.5 C/s to 60 C and holds a minute (a board with",
            "presets/paper.toml, simulated: host-tests/src/board.rs). Written by",
            "cargo run -p host-tests --example probe_log",
        ],
    ))
}
