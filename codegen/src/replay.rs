//! The QEMU twin's replay: the template profile adapted to a device's
//! ranges ([`adapt`]), the schedule's text form that the host-side replica
//! reads ([`Schedule`]), and (feature `replay`) the Rust constants the twin
//! image checks itself with, from the independent reference
//! (`Replay::rust`, `expectations`).
//!
//! The faults the replay injects are the shared table of
//! `compensator_testbench::faults`; their times are the template's, the
//! temperatures are adapted.
//!
//! A device file that names the condition monitor's second sensor gets
//! its readings too ([`MonitorTrack`]): the true device's reading at the
//! oil's temperature, healthy and with its capillary restricted
//! ([`RESTRICTION`]), tabulated by the independent reference; the replay
//! ends with [`MONITOR_TAIL`], whose first hold restricts the capillary
//! half-way through and whose ramp lets the monitor name the fault; and
//! the transducer's loop opens for [`OPEN_LOOP_SECONDS`] in the middle of
//! the [`OPEN_LOOP_HOLD`]-th hold.

use compensator_params::{RawEstimator, RawParams};
use compensator_testbench::faults::{FAULTS, Injected};

/// The template replay, written for the paper's 26-78 C and -20..150 C:
/// the oil's levels in order. Between two levels the oil moves at
/// [`transition_rate`], except into the second, the warm-up, at
/// [`WARM_UP_RATE`]; every level is held for [`hold_time`]. A hold is
/// checked at its end against the reference; a ramp along its way.
pub const LEVELS: [f64; 10] = [
    26.0, // cold start: window closed
    78.0, // the warm-up ramp, then the hot hold
    40.0, // down
    60.0, // up
    90.0, // outside the validated range
    50.0, // back, through a sensor outage
    // The cold excursion: hot oil, then cold (outside the validated range,
    // window closed), then warming back onto the closed stop.
    80.0, 10.0, 30.0, 30.0,
];

/// Levels a replay with the condition monitor's second sensor adds after
/// [`LEVELS`] (at the transition rate, each held): the capillary is
/// restricted half-way through the first hold, and the move to the second
/// spans the temperature the monitor's isolation needs
/// (`compensator::monitor::ISOLATION_SPAN`, 3 K).
pub const MONITOR_TAIL: [f64; 2] = [40.0, 50.0];

/// The capillary's conductance after its restriction, a fraction of the
/// file's (the goal's 20 % restriction: `laminar_throttle.diameter` x
/// 0.8^(1/4)).
pub const RESTRICTION: f64 = 0.8;

/// The hold (0-based, in time order) in whose middle the transducer's loop
/// opens: the 60 C hold of the template.
pub const OPEN_LOOP_HOLD: usize = 3;

/// How long the transducer's loop stays open \[s\].
pub const OPEN_LOOP_SECONDS: f64 = 1.0;

/// The truth table's first spacing \[C\], halved until linear
/// interpolation between its rows is within [`TRUTH_TOLERANCE`] of the
/// sensor's noise at every midpoint.
pub const TRUTH_STEP: f64 = 0.5;

/// The truth table's interpolation error allowed, in the second sensor's
/// noise standard deviations (`monitor.noise`; its span's 1e-4 when the
/// file gives none).
pub const TRUTH_TOLERANCE: f64 = 0.05;

/// The warm-up's rate [C/s].
pub const WARM_UP_RATE: f64 = 0.5;

/// Holds last this many of the probe's time constants (both lags): the
/// observer has settled on the new level by then.
pub const HOLD_LAGS: f64 = 4.0;

/// Shortest and longest hold \[s\].
pub const HOLD_RANGE: (f64, f64) = (3.0, 120.0);

/// How long each level is held for a probe of time constant `lag` \[s\]
/// (both lags): [`HOLD_LAGS`] of them, within [`HOLD_RANGE`].
pub fn hold_time(lag: f64) -> f64 {
    (HOLD_LAGS * lag).clamp(HOLD_RANGE.0, HOLD_RANGE.1)
}

/// The rate the oil moves between levels [C/s]: the file's
/// `estimator.max_oil_rate` (what it declares plausible: the observer
/// holds its rate within twice that), within 0.2-5 C/s so that the replay
/// stays minutes long.
pub fn transition_rate(est: &RawEstimator) -> f64 {
    est.max_oil_rate.clamp(0.2, 5.0)
}

/// The ramp checkpoints' spacing \[s\].
pub const RAMP_CHECK_EVERY: f64 = 10.0;

/// Time the estimate needs to leave the validated range after the oil did
/// \[s\], in probe time constants (the probe's lag, then the observer's).
pub const OUT_OF_RANGE_LAGS: f64 = 2.0;

/// Margin kept inside the oil range by the replay's temperatures \[C\]: a
/// sample outside `estimator.oil_min..oil_max` is a sensor fault, not a
/// temperature.
pub const OIL_MARGIN: f64 = 1.0;

/// Room the out-of-range hold needs beyond the validated range \[C\].
pub const OUT_OF_RANGE_ROOM: f64 = 2.0;

/// How far the template's out-of-range hold lies beyond the validated
/// range (90 C against 78 C) \[C\].
pub const OUT_OF_RANGE_DEPTH: f64 = 12.0;

/// The template's pieces for levels `levels`: (start s, end s, from C, to
/// C), holds and ramps.
pub fn pieces(levels: &[f64], hold: f64, warm_up: f64, transition: f64) -> Vec<(f64, f64, f64, f64)> {
    let mut out = Vec::new();
    let mut t = 0.0;
    for (i, &level) in levels.iter().enumerate() {
        if i > 0 {
            let from = levels[i - 1];
            if from != level {
                let rate = if i == 1 { warm_up } else { transition };
                let secs = (level - from).abs() / rate;
                out.push((t, t + secs, from, level));
                t += secs;
            }
        }
        if i + 1 < levels.len() && levels[i + 1] == level {
            continue;
        }
        out.push((t, t + hold, level, level));
        t += hold;
    }
    out
}

/// The replay's profile: what the QEMU twin plays and the host replica
/// plays again. Its text form ([`Schedule::text`], `replay.txt` in the
/// build's output directory) is what the replica reads.
/// Read as `f32` (`Schedule::<f32>::parse`), the numbers are the ones the
/// twin image's constants hold: the same decimal text, rounded once.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule<T = f64> {
    /// (start s, end s, from C, to C).
    pub pieces: Vec<(T, T, T, T)>,
    /// What the injected spike adds to the temperature \[C\].
    pub spike: T,
    /// The second sensor's readings, for a device file that names one.
    pub monitor: Option<MonitorTrack<T>>,
}

/// What the condition monitor's second sensor reads in the replay.
#[derive(Clone, Debug, PartialEq)]
pub struct MonitorTrack<T = f64> {
    /// From this time on \[s\] the device's capillary is restricted to
    /// [`RESTRICTION`] of its conductance.
    pub restricted_from: T,
    /// The transducer's loop is open (a NAMUR fault low) over (from s,
    /// to s).
    pub open_loop: (T, T),
    /// The true device's reading \[Pa or m\] at oil temperatures over the
    /// replay's: (t C, healthy, restricted), evenly spaced, from the
    /// independent reference's equilibrium, each value rounded to `f32`
    /// (filled with the `replay` feature; empty without it).
    pub truth: Vec<(T, T, T)>,
}

impl Schedule<f64> {
    /// Temperature at `t` \[s\] (the last piece's end value after it).
    pub fn temperature_at(&self, t: f64) -> f64 {
        for &(t0, t1, a, b) in &self.pieces {
            if t >= t0 && t < t1 {
                return a + (b - a) * (t - t0) / (t1 - t0);
            }
        }
        self.pieces.last().map_or(0.0, |p| p.3)
    }
}

impl<T: Copy + Default + core::fmt::Debug + core::str::FromStr> Schedule<T> {
    /// The schedule as text, one item a line.
    pub fn text(&self) -> String {
        let mut s =
            String::from("# The QEMU twin's replay, generated by build.rs (read by cargo xtask's host-side replica)\n");
        for (a, b, c, d) in &self.pieces {
            s += &format!("piece {a:?} {b:?} {c:?} {d:?}\n");
        }
        s += &format!("spike_delta {:?}\n", self.spike);
        if let Some(m) = &self.monitor {
            s += &format!("monitor_restricted_from {:?}\n", m.restricted_from);
            s += &format!("monitor_open_loop {:?} {:?}\n", m.open_loop.0, m.open_loop.1);
            for (t, a, b) in &m.truth {
                s += &format!("monitor_truth {t:?} {a:?} {b:?}\n");
            }
        }
        s
    }

    /// Reads [`Schedule::text`] back.
    ///
    /// # Errors
    ///
    /// A line that is not a piece or the spike (named), or no pieces.
    pub fn parse(text: &str) -> Result<Schedule<T>, String> {
        let mut s = Schedule {
            pieces: vec![],
            spike: T::default(),
            monitor: None,
        };

        for line in text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()) {
            let w: Vec<&str> = line.split_whitespace().collect();
            let num = |i: usize| -> Result<T, String> {
                w.get(i)
                    .and_then(|v| v.parse::<T>().ok())
                    .ok_or_else(|| format!("replay schedule: {line}"))
            };
            match w.first().copied() {
                Some("piece") => s.pieces.push((num(1)?, num(2)?, num(3)?, num(4)?)),
                Some("spike_delta") => s.spike = num(1)?,
                Some("monitor_restricted_from") => {
                    let v = num(1)?;
                    monitor_of(&mut s).restricted_from = v;
                }
                Some("monitor_open_loop") => {
                    let v = (num(1)?, num(2)?);
                    monitor_of(&mut s).open_loop = v;
                }
                Some("monitor_truth") => {
                    let v = (num(1)?, num(2)?, num(3)?);
                    monitor_of(&mut s).truth.push(v);
                }
                _ => return Err(format!("replay schedule: {line}")),
            }
        }
        if s.pieces.is_empty() {
            return Err("replay schedule without pieces".into());
        }
        Ok(s)
    }
}

/// The schedule's monitor track, started empty by its first line.
fn monitor_of<T: Copy + Default>(s: &mut Schedule<T>) -> &mut MonitorTrack<T> {
    s.monitor.get_or_insert_with(|| MonitorTrack {
        restricted_from: T::default(),
        open_loop: (T::default(), T::default()),
        truth: vec![],
    })
}

/// The replay as run for one device.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    /// The profile and the spike.
    pub schedule: Schedule,
    /// When OUT_OF_RANGE must be raised (from s, to s); `None` when the
    /// oil range leaves no room outside the validated one.
    pub out_of_range: Option<(f64, f64)>,
    /// The probe's time constant, both lags \[s\].
    pub lag: f64,
    /// What could not be adapted (for build warnings).
    pub notes: Vec<String>,
}

/// The template replay ([`LEVELS`], and the faults of
/// `compensator_testbench::faults`) adapted to a device: its probe's lag
/// sets the holds ([`hold_time`]), its `max_oil_rate` the transitions
/// ([`transition_rate`]), its ranges the levels, so that any parameter
/// file the CLI accepts builds the QEMU twin: every temperature inside the
/// oil range; an out-of-range hold outside the validated range (the
/// template's if it is, else the hottest hold moved above it, or the
/// coldest below, where the oil range leaves room); a spike larger than the
/// spike threshold that stays inside the oil range.
pub fn adapt(raw: &RawParams) -> Replay {
    let est = &raw.estimator;
    let (oil_lo, oil_hi) = (est.oil_min + OIL_MARGIN, est.oil_max - OIL_MARGIN);
    let (valid_lo, valid_hi) = (est.valid_min, est.valid_max);
    let clamp = |t: f64| {
        if oil_lo < oil_hi {
            t.clamp(oil_lo, oil_hi)
        } else {
            (est.oil_min + est.oil_max) / 2.0
        }
    };
    let mut notes = Vec::new();
    let lag = raw.probe.time_constant + raw.probe.well_time_constant;
    let hold = hold_time(lag);
    if hold < HOLD_LAGS * lag {
        notes.push(format!(
            "the probe's {lag} s lag needs holds of {} s; the QEMU twin holds {hold} s and its hold checks may fail",
            HOLD_LAGS * lag
        ));
    }
    let transition = transition_rate(est);
    if transition > 2.0 * est.max_oil_rate {
        notes.push(format!(
            "the replay moves the oil at {transition} C/s, beyond twice estimator.max_oil_rate = {}: the estimate will lag it",
            est.max_oil_rate
        ));
    }
    let monitored = raw.monitor.has_sensor();
    let mut levels: Vec<f64> = LEVELS.iter().map(|&t| clamp(t)).collect();
    if monitored {
        levels.extend(MONITOR_TAIL.iter().map(|&t| clamp(t)));
    }
    let outside = |t: f64| !(valid_lo..=valid_hi).contains(&t);
    if !levels.iter().any(|&t| outside(t)) {
        let above = oil_hi - valid_hi;
        let below = valid_lo - oil_lo;
        let hottest = (0..levels.len()).max_by(|&i, &j| levels[i].total_cmp(&levels[j]));
        let coldest = (0..levels.len()).min_by(|&i, &j| levels[i].total_cmp(&levels[j]));
        if let (Some(i), true) = (hottest, above >= OUT_OF_RANGE_ROOM) {
            levels[i] = valid_hi + OUT_OF_RANGE_DEPTH.min(above);
        } else if let (Some(i), true) = (coldest, below >= OUT_OF_RANGE_ROOM) {
            levels[i] = valid_lo - OUT_OF_RANGE_DEPTH.min(below);
        } else {
            notes.push(format!(
                "the validated range {valid_lo}..{valid_hi} C leaves no room inside the oil range {}..{} C: the QEMU twin does not check OUT_OF_RANGE",
                est.oil_min, est.oil_max
            ));
        }
    }
    let pieces = pieces(&levels, hold, WARM_UP_RATE, transition);
    let is_hold = |p: &(f64, f64, f64, f64)| p.2 == p.3;
    let out_of_range = pieces
        .iter()
        .find(|p| is_hold(p) && outside(p.3))
        .map(|p| (p.0 + (OUT_OF_RANGE_LAGS * lag).min(0.5 * (p.1 - p.0)), p.1));
    let monitor = if monitored {
        let holds: Vec<&(f64, f64, f64, f64)> = pieces.iter().filter(|p| is_hold(p)).collect();
        let tail = holds.len().saturating_sub(MONITOR_TAIL.len());
        let restricted_from = holds.get(tail).map_or(0.0, |h| 0.5 * (h.0 + h.1));
        let open = holds.get(OPEN_LOOP_HOLD).map_or(0.0, |h| 0.5 * (h.0 + h.1));
        Some(MonitorTrack {
            restricted_from,
            open_loop: (open, open + OPEN_LOOP_SECONDS),
            truth: vec![],
        })
    } else {
        None
    };
    let mut schedule = Schedule {
        pieces,
        spike: 0.0,
        monitor,
    };
    #[cfg(feature = "replay")]
    if let Some(m) = schedule.monitor.as_mut() {
        let (lo, hi) = schedule
            .pieces
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.2).min(p.3), hi.max(p.2).max(p.3))
            });
        let (truth, note) = monitor_truth(raw, lo, hi);
        m.truth = truth;
        notes.extend(note);
    }
    // The spike: out of the gate's band (more than spike_threshold away),
    // inside the oil range (else it is a sensor fault, not a spike).
    let at = FAULTS
        .iter()
        .find(|f| f.injected == Injected::Spike)
        .map_or(0.0, |f| f64::from(f.start));
    let t = schedule.temperature_at(at);
    let want = (2.0 * est.spike_threshold).max(40.0);
    let (up, down) = (oil_hi - t, t - oil_lo);
    schedule.spike = if up >= want {
        want
    } else if down >= want {
        -want
    } else if up >= down {
        up
    } else {
        -down
    };
    if schedule.spike.abs() <= est.spike_threshold {
        notes.push(format!(
            "the oil range leaves no room for a spike beyond estimator.spike_threshold = {}: the QEMU twin's spike check will fail",
            est.spike_threshold
        ));
    }
    Replay {
        schedule,
        out_of_range,
        lag,
        notes,
    }
}

/// Half a code of the device's sensor in degrees at `t` \[C\]: for the
/// MAX31865 `(R_ref / 2^16) / (dR/dt)`, with the device's Callendar-Van
/// Dusen slope; for the NTC half an ADC code over the divider's slope
/// (`RawEstimator::resolution`).
pub fn half_code(est: &RawEstimator, t: f64) -> f64 {
    if est.is_ntc() {
        0.5 * est.resolution(t)
    } else {
        (est.rtd_reference / 65536.0) / est.rtd_slope(t)
    }
}

/// The second sensor's true reading \[Pa or m\] of the file's device at
/// `t` \[C\], healthy and with its capillary restricted to [`RESTRICTION`]
/// of its conductance (the bore by its fourth root), from the independent
/// reference's equilibrium.
#[cfg(feature = "replay")]
pub fn monitor_reading(raw: &RawParams, t: f64) -> (f64, f64) {
    let mut restricted = raw.core;
    restricted.laminar_diameter *= RESTRICTION.powf(0.25);
    use compensator::sensor::transducer::Quantity;
    let quantity = Quantity::of(raw.monitor.sensor);
    let reading = |core: &compensator_params::RawCore| {
        let e = compensator_reference::statics::equilibrium(core, t);
        match quantity {
            Some(Quantity::PressureB) => e.p_b,
            Some(Quantity::PressureDifference) => e.p_b - e.p_a,
            Some(Quantity::Displacement) => e.x,
            Some(Quantity::PressureA) | None => e.p_a,
        }
    };
    (reading(&raw.core), reading(&restricted))
}

/// The truth table of [`MonitorTrack::truth`] over `lo..=hi` \[C\]: rows
/// [`TRUTH_STEP`] apart, halved until linear interpolation is within
/// [`TRUTH_TOLERANCE`] of the noise at every midpoint (at most 1/64 C);
/// and a note if even that is not enough.
#[cfg(feature = "replay")]
pub fn monitor_truth(raw: &RawParams, lo: f64, hi: f64) -> (Vec<(f64, f64, f64)>, Option<String>) {
    let m = &raw.monitor;
    let tolerance = TRUTH_TOLERANCE * if m.noise > 0.0 { m.noise } else { 1e-4 * m.span() };
    let mut step = TRUTH_STEP;
    loop {
        let n = ((hi - lo) / step).ceil().max(1.0) as usize;
        // Rounded to f32 where they are made: the twin's constants (f32
        // literals) and the replica's text (read as f32) hold the same
        // values, with no second rounding.
        let f = |v: f64| f64::from(v as f32);
        let rows: Vec<(f64, f64, f64)> = (0..=n)
            .map(|i| {
                let t = lo + i as f64 * step;
                let (a, b) = monitor_reading(raw, t);
                (f(t), f(a), f(b))
            })
            .collect();
        let worst = rows
            .windows(2)
            .map(|w| {
                let (a, b) = monitor_reading(raw, 0.5 * (w[0].0 + w[1].0));
                (a - 0.5 * (w[0].1 + w[1].1))
                    .abs()
                    .max((b - 0.5 * (w[0].2 + w[1].2)).abs())
            })
            .fold(0.0, f64::max);
        if worst <= tolerance {
            return (rows, None);
        }
        if step <= 1.0 / 64.0 {
            let note = format!(
                "the second sensor's truth table interpolates within {worst:.3e}, beyond {TRUTH_TOLERANCE} of its noise"
            );
            return (rows, Some(note));
        }
        step *= 0.5;
    }
}

#[cfg(feature = "replay")]
impl Replay {
    /// The checkpoints: the end of every hold, and every
    /// [`RAMP_CHECK_EVERY`] along a ramp once two probe time constants of
    /// it have passed, none within three seconds after an injected fault:
    /// (time s, oil temperature C).
    pub fn checkpoints(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for &(t0, t1, a, b) in &self.schedule.pieces {
            if a == b {
                out.push((t1 - 0.001, b));
                continue;
            }
            let mut t = t0 + 2.0 * self.lag.max(1.0);
            while t < t1 - 1.0 {
                let near_fault = FAULTS
                    .iter()
                    .any(|f| t >= f64::from(f.start) - 1.0 && t < f64::from(f.end) + 3.0);
                if !near_fault {
                    out.push((t, a + (b - a) * (t - t0) / (t1 - t0)));
                }
                t += RAMP_CHECK_EVERY;
            }
        }
        out
    }

    /// The replay's Rust constants (`replay.rs`): the pieces, the spike,
    /// when OUT_OF_RANGE is due, and the checkpoints with the reference's
    /// equilibrium of the device at the oil's temperature there (the
    /// estimate must hold it within its band, OUT_OF_RANGE exactly outside
    /// the validated range at the holds' ends).
    pub fn rust(&self, raw: &RawParams) -> String {
        let (core, est) = (&raw.core, &raw.estimator);
        let pieces = &self.schedule.pieces;
        let mut s = String::from("// Generated by build.rs (compensator-codegen).\n");
        s += "/// Temperature pieces of the oil: (start s, end s, from C, to C).\n";
        s += &format!("const REPLAY_PIECES: [(f32, f32, f32, f32); {}] = [\n", pieces.len());
        for (a, b, c, d) in pieces {
            s += &format!("    ({a:?}, {b:?}, {c:?}, {d:?}),\n");
        }
        s += "];\n";
        s += "/// What the injected spike adds to the reading [C] (beyond the\n";
        s += "/// spike threshold, inside the oil range).\n";
        s += &format!("const SPIKE_DELTA: f32 = {:?};\n", self.schedule.spike);
        let (from, to) = self.out_of_range.unwrap_or((0.0, 0.0));
        s += "/// When the estimate must be flagged OUT_OF_RANGE: (from s, to s).\n";
        s += &format!("const OUT_OF_RANGE_HOLD: (f32, f32) = ({from:?}, {to:?});\n");
        s += "/// Whether the replay leaves the validated range at all (the oil\n";
        s += "/// range may leave no room beyond it).\n";
        s += &format!(
            "const OUT_OF_RANGE_REACHABLE: bool = {};\n",
            self.out_of_range.is_some()
        );
        s += "/// Checkpoints from the f64 reference at the oil's temperature: (time\n";
        s += "/// s, oil C, x m, p_a Pa, p_b Pa, whether OUT_OF_RANGE is due at a hold's\n";
        s += "/// end: None along a ramp, or where half a code either side straddles a\n";
        s += "/// bound of the validated range).\n";
        let (valid_lo, valid_hi) = (est.valid_min, est.valid_max);
        let holds: Vec<f64> = pieces.iter().filter(|p| p.2 == p.3).map(|p| p.1 - 0.001).collect();
        let checkpoints = self.checkpoints();
        s += &format!(
            "const CHECKPOINTS: [(f32, f32, f32, f32, f32, Option<bool>); {}] = [\n",
            checkpoints.len()
        );
        for (t, temp) in checkpoints {
            let e = compensator_reference::statics::equilibrium(core, temp);
            let half = half_code(est, temp);
            let at_hold_end = holds.contains(&t);
            let outside = if !at_hold_end {
                None
            } else if temp + half < valid_lo || temp - half > valid_hi {
                Some(true)
            } else if temp - half >= valid_lo && temp + half <= valid_hi {
                Some(false)
            } else {
                None
            };
            s += &format!(
                "    ({t:?}, {temp:?}, {:?}, {:?}, {:?}, {outside:?}),\n",
                e.x as f32, e.p_a as f32, e.p_b as f32
            );
        }
        s += "];\n";
        if let Some(m) = &self.schedule.monitor {
            s += "/// The condition monitor's second sensor: from this time on [s] the\n";
            s += "/// device's capillary is restricted to MONITOR_RESTRICTION of its\n";
            s += "/// conductance.\n";
            s += &format!("const MONITOR_RESTRICTED_FROM: f32 = {:?};\n", m.restricted_from);
            s += "/// The restricted capillary's conductance, a fraction of the file's.\n";
            s += &format!("const MONITOR_RESTRICTION: f32 = {RESTRICTION:?};\n");
            s += "/// The transducer's loop is open over (from s, to s).\n";
            s += &format!(
                "const MONITOR_OPEN_LOOP: (f32, f32) = ({:?}, {:?});\n",
                m.open_loop.0, m.open_loop.1
            );
            s += "/// The true device's reading [Pa or m] from the f64 reference: (oil C,\n";
            s += "/// healthy, restricted), evenly spaced.\n";
            s += &format!("const MONITOR_TRUTH: [(f32, f32, f32); {}] = [\n", m.truth.len());
            for &(t, a, b) in &m.truth {
                s += &format!("    ({:?}, {:?}, {:?}),\n", t as f32, a as f32, b as f32);
            }
            s += "];\n";
        }
        s
    }
}

/// Host-computed values the core's `f32` results on the target are
/// checked against (`expectations.rs`): (t C, nu m^2/s, rho kg/m^3, p_a
/// Pa, p_b Pa, x m, Q0 m^3/s), from the independent reference.
#[cfg(feature = "replay")]
pub fn expectations(core: &compensator_params::RawCore) -> String {
    let mut s = String::from("// Generated by build.rs (compensator-codegen) from the f64 reference.\n");
    let temps = [26.0, 30.0, 35.0, 40.0, 50.0, 60.0, 70.0, 78.0];
    s += &format!(
        "pub const EXPECTED: [(f32, f64, f64, f64, f64, f64, f64); {}] = [\n",
        temps.len()
    );
    for t in temps {
        let (nu, rho) = compensator_reference::statics::oil(core, t);
        let e = compensator_reference::statics::equilibrium(core, t);
        s += &format!(
            "    ({t:?}, {nu:?}, {rho:?}, {:?}, {:?}, {:?}, {:?}),\n",
            e.p_a, e.p_b, e.x, e.q_total
        );
    }
    s += "];\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> RawParams {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../presets/paper.toml");
        compensator_params::file::load(std::path::Path::new(path)).unwrap()
    }

    #[test]
    fn the_schedule_reads_back_and_drives_the_same_profile() {
        let text = "# comment\npiece 0.0 3.0 26.0 26.0\npiece 3.0 55.0 26.0 78.0\nspike_delta -40.0\n";
        let s = Schedule::<f64>::parse(text).unwrap();
        assert_eq!(s.pieces.len(), 2);
        assert_eq!(s.spike, -40.0);
        assert_eq!(s.temperature_at(29.0), 52.0);
        assert_eq!(s.temperature_at(100.0), 78.0);
        assert_eq!(Schedule::<f64>::parse(&s.text()).unwrap(), s);
        assert!(Schedule::<f64>::parse("fault 1 2 Spike\npiece 0 1 2 3\n").is_err());
        assert!(Schedule::<f64>::parse("").is_err());
        // As f32: the decimal text rounded once, as the firmware's constants.
        let f = Schedule::<f32>::parse("piece 0.0 0.1 26.3 26.3\nspike_delta 40.0\n").unwrap();
        assert_eq!(f.pieces[0].1, 0.1f32);
    }

    #[test]
    fn the_paper_device_plays_the_template_through_its_probe() {
        let raw = paper();
        let r = adapt(&raw);
        assert_eq!(r.lag, 6.0);
        let p = &r.schedule.pieces;
        // Hold, the 0.5 C/s warm-up, then a hold at each level, the moves
        // between them at 1 C/s.
        assert_eq!(p[0], (0.0, 24.0, 26.0, 26.0));
        assert_eq!(p[1], (24.0, 128.0, 26.0, 78.0));
        assert_eq!(p[2], (128.0, 152.0, 78.0, 78.0));
        assert_eq!(p[3], (152.0, 190.0, 78.0, 40.0));
        assert_eq!(p.iter().filter(|q| q.2 == q.3).count(), 9);
        for w in p.windows(2) {
            assert_eq!(w[0].1, w[1].0, "contiguous");
            assert_eq!(w[0].3, w[1].2, "continuous");
        }
        let hot = p.iter().find(|q| q.2 == 90.0 && q.3 == 90.0).unwrap();
        assert_eq!(r.out_of_range, Some((hot.0 + 12.0, hot.1)));
        assert_eq!(r.schedule.spike, 40.0);
        assert!(r.notes.is_empty(), "{:?}", r.notes);
        // Every fault within the replay.
        let end = p.last().unwrap().1;
        assert!(FAULTS.iter().all(|f| f64::from(f.end) < end));
    }

    #[test]
    fn a_narrow_oil_range_moves_the_holds_inside_it() {
        let mut raw = paper();
        raw.estimator.oil_min = 0.0;
        raw.estimator.oil_max = 85.0;
        let r = adapt(&raw);
        for p in &r.schedule.pieces {
            assert!(p.2 >= 1.0 && p.3 <= 84.0, "{p:?}");
        }
        // The out-of-range hold, clamped to 84 C, is still outside 26-78 C.
        assert!(r.out_of_range.is_some());
        raw.estimator.valid_min = 0.5;
        raw.estimator.valid_max = 84.5;
        let r = adapt(&raw);
        assert_eq!(r.out_of_range, None);
        assert_eq!(r.notes.len(), 1, "{:?}", r.notes);
    }

    #[test]
    fn a_slow_probe_or_a_slow_oil_is_said() {
        let mut raw = paper();
        raw.probe.time_constant = 100.0;
        raw.estimator.max_oil_rate = 0.01;
        let r = adapt(&raw);
        assert_eq!(r.notes.len(), 2, "{:?}", r.notes);
        assert!(r.schedule.pieces.iter().all(|p| p.1 - p.0 <= 400.0));
    }
}
