//! The soak with faults on the host; `docs/soak.md` has the figures.
//!
//! * [`run`]: the estimator through a seeded temperature walk with
//!   injected sensor faults, every tick checked. The walk, the faults and
//!   the checks are the QEMU soak image's own (`compensator_testbench::soak`):
//!   the same seed gives the same walk on both. On top,
//!   every settled hold is also compared with the independent reference
//!   ([`crate::reference`]), not only with the core's closed form.
//! * [`drift`]: a `Twin<f32, f32>` and a `Twin<f64, f64>` driven through the
//!   same temperatures (the walk, through the estimator's filter), every
//!   tick compared: the largest gap, and whether the gap at settled holds
//!   grows (the first tenth of the run against the last).
//!
//! `cargo test -p host-tests --test soak` runs both for CI;
//! `cargo run --release -p host-tests --example soak -- --ticks 10000000`
//! is the long run.

pub use compensator_testbench::soak::{
    CHECKS, Fault, HOLD_TOLERANCE, Kind, Limits, SENSOR_BAND, SETTLE, Segment, Soak, Stats, Walk, XorShift64,
};

use compensator::dynamics::config::choose;
use compensator::dynamics::{Twin, TwinConfig};
use compensator::estimator::EstimatorConfig;
use compensator::estimator::{ObserverDesign, observer_settings};
use compensator::sensor::device::SensorKind;
use compensator::sensor::simulated::{SimulatedNtc, SimulatedRtd, SimulatedSource};
use compensator::{Params, RawParams};
use std::fmt::Write as _;
use std::time::{Duration, Instant};

/// The QEMU soak image's seed (`src/bin/soak.rs`): the host soak's default.
pub const SEED: u64 = 2025;

/// Bound on the `f32` twin's distance from the `f64` one, every tick:
/// displacement as a fraction of the stroke, pressures of `dp`.
pub const DRIFT_TOLERANCE: f64 = 1e-3;

/// The preset `presets/paper.toml`.
pub fn paper() -> RawParams {
    compensator_cli::load(&crate::repo_root().join("presets/paper.toml")).expect("the paper preset loads")
}

/// The preset `presets/paper-ntc.toml` (the paper preset read through an
/// NTC on the STM32F4's ADC).
pub fn paper_ntc() -> RawParams {
    compensator_cli::load(&crate::repo_root().join("presets/paper-ntc.toml")).expect("the NTC paper preset loads")
}

/// The first `count` of `crate::survey::designs` (from `seed`) whose plunger
/// travels over the validated range (the reference's displacement at its
/// ends at least 10 % of the stroke apart): a design on one stop
/// throughout would compare two twins at rest.
pub fn moving_designs(count: usize, seed: u64) -> Vec<RawParams> {
    crate::survey::designs(20 * count.max(1), seed)
        .into_iter()
        .filter(|raw| {
            let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
            let x = |t: f64| crate::reference::equilibrium(&raw.core, t).x;
            (x(hi) - x(lo)).abs() >= 0.1 * raw.core.stroke
        })
        .take(count)
        .collect()
}

/// The twin's configuration for `raw`, as the firmware's build script
/// chooses it (`compensator::dynamics::config::choose` at the estimator's
/// tick over the validated range).
pub fn twin_config(raw: &RawParams) -> Result<TwinConfig, String> {
    let p = Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let e = &raw.estimator;
    choose(&p, 1.0 / e.tick_hz, (e.valid_min, e.valid_max))
        .map(|c| c.config)
        .map_err(|e| e.to_string())
}

/// A soak run of the estimator.
#[derive(Clone, Debug)]
pub struct Run {
    /// The simulated sensor (the device file's).
    pub sensor: SensorKind,
    /// What the shared checks counted.
    pub stats: Stats,
    /// The bounds they used.
    pub limits: Limits,
    /// Settled holds off the independent reference by more than
    /// [`HOLD_TOLERANCE`] (tick, displacement [strokes], pressure [dp]).
    pub reference_misses: Vec<(u32, f64, f64)>,
    /// Worst settled hold against the independent reference: displacement
    /// [strokes], pressure [dp].
    pub reference_worst: (f64, f64),
    /// Wall time.
    pub elapsed: Duration,
}

impl Run {
    /// Violations of the shared checks and of the reference check.
    pub fn violations(&self) -> usize {
        self.stats.total_violations() as usize + self.reference_misses.len()
    }

    /// One line of figures.
    pub fn line(&self) -> String {
        let st = &self.stats;
        format!(
            "{} ticks in {:.1} s: {} faults, {} steps, {} cold excursions; worst flag {} ticks, worst DEGRADED {} ticks, worst recovery {} ticks; {} holds checked, worst {:.2e} of the stroke, {:.2e} of dp (reference {:.2e}, {:.2e}); {} re-seats; {} violations",
            st.ticks,
            self.elapsed.as_secs_f64(),
            st.total_injected(),
            st.steps,
            st.cold_excursions,
            st.detection.iter().max().unwrap_or(&0),
            st.degraded.iter().max().unwrap_or(&0),
            st.recovery.iter().max().unwrap_or(&0).max(&st.step_recovery),
            st.holds_checked,
            st.hold_x,
            st.hold_p,
            self.reference_worst.0,
            self.reference_worst.1,
            st.reseats,
            self.violations()
        )
    }

    /// The run as a Markdown report (the figures of `docs/soak.md`).
    pub fn table(&self) -> String {
        let st = &self.stats;
        let lim = &self.limits;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} ticks in {:.1} s; walk {:.1}..{:.1} C (levels {}..{} C, cold excursions {:.1}..{:.1} C); {} segments, {} steps, {} cold excursions",
            st.ticks,
            self.elapsed.as_secs_f64(),
            st.span.0,
            st.span.1,
            lim.range.0,
            lim.range.1,
            lim.cold.0,
            lim.cold.1,
            st.segments,
            st.steps,
            st.cold_excursions
        );
        let _ = writeln!(
            s,
            "samples: {} read, {} unusable, {} rejected as spikes",
            st.samples, st.unusable, st.spikes
        );
        let _ = writeln!(
            s,
            "bounds [ticks]: flag {}, DEGRADED {}, recovery {}\n",
            lim.detection_bound(),
            lim.degraded_bound(),
            lim.recovery_bound()
        );
        s += "| fault | injected | unread | worst flag [ticks] | long | worst DEGRADED [ticks] | worst recovery [ticks] |\n";
        s += "|---|---:|---:|---:|---:|---:|---:|\n";
        for kind in Kind::ALL {
            let i = kind.index();
            let flag = match kind.flag() {
                Some(_) => st.detection[i].to_string(),
                None => "-".into(),
            };
            let degraded = if st.long[i] > 0 {
                st.degraded[i].to_string()
            } else {
                "-".into()
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} |",
                kind.name(),
                st.injected[i],
                st.unread[i],
                flag,
                st.long[i],
                degraded,
                st.recovery[i]
            );
        }
        let _ = writeln!(s, "| step | {} | | | | | {} |", st.steps, st.step_recovery);
        let _ = writeln!(
            s,
            "\nholds: {} checked, {} too short; worst against the core's f64 closed form {:.2e} of the stroke, {:.2e} of dp; against the independent reference {:.2e}, {:.2e}",
            st.holds_checked, st.holds_skipped, st.hold_x, st.hold_p, self.reference_worst.0, self.reference_worst.1
        );
        let _ = writeln!(s, "re-seats: {}", st.reseats);
        for (i, what) in CHECKS.iter().enumerate() {
            if st.violations[i] > 0 {
                let _ = writeln!(
                    s,
                    "VIOLATED {} times, first at tick {}: {what}",
                    st.violations[i], st.first_violation[i]
                );
            }
        }
        for (k, dx, dp) in self.reference_misses.iter().take(10) {
            let _ = writeln!(
                s,
                "VIOLATED at tick {k}: a settled hold {dx:.2e} of the stroke, {dp:.2e} of dp off the reference"
            );
        }
        s
    }
}

/// The estimator soak of `raw` for `ticks` ticks from `seed`, with the
/// twin configuration the firmware would be built with. The walk's
/// readings are the oil's temperature: the observer is designed for a
/// probe without lag
/// ([`ObserverSettings::without_lag`](compensator::estimator::ObserverSettings::without_lag)), as in the QEMU
/// soak image. The sensor is the file's (`estimator.sensor`: the MAX31865
/// or the NTC), simulated at register level behind its real driver.
pub fn run(raw: &RawParams, ticks: u32, seed: u64) -> Result<Run, String> {
    match SensorKind::of(&raw.estimator) {
        SensorKind::Rtd => run_with::<SimulatedRtd>(raw, ticks, seed),
        SensorKind::Ntc => run_with::<SimulatedNtc>(raw, ticks, seed),
    }
}

/// [`run`] with the simulated sensor `S`.
fn run_with<S: SimulatedSource>(raw: &RawParams, ticks: u32, seed: u64) -> Result<Run, String> {
    let p = Params::<f32>::new(raw).map_err(|e| e.to_string())?;
    let p64 = Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let mut config = EstimatorConfig::new(raw).map_err(|e| e.to_string())?;
    let direct = observer_settings(raw, config.sample_period()).without_lag();
    config.observer = ObserverDesign::new(&direct).map_err(|e| e.to_string())?;
    config.twin = TwinConfig {
        tick: config.twin.tick,
        ..twin_config(raw)?
    };
    let mut soak = Soak::<S, _, _>::new(&p, &p64, config, &raw.estimator, seed)?;
    let mut misses = Vec::new();
    let mut worst = (0.0f64, 0.0f64);
    let started = Instant::now();
    for _ in 0..ticks {
        if let Some(h) = soak.step() {
            let e = &h.estimate;
            let r = crate::reference::equilibrium(&raw.core, f64::from(e.temperature));
            let c = &raw.core;
            let dx = (f64::from(e.x) - r.x).abs() / c.stroke;
            let dp = (f64::from(e.p_a) - r.p_a).abs().max((f64::from(e.p_b) - r.p_b).abs()) / c.pressure_drop;
            worst = (worst.0.max(dx), worst.1.max(dp));
            if !(dx <= HOLD_TOLERANCE && dp <= HOLD_TOLERANCE) {
                misses.push((h.tick, dx, dp));
            }
        }
    }
    Ok(Run {
        sensor: SensorKind::of(&raw.estimator),
        stats: soak.stats,
        limits: soak.limits,
        reference_misses: misses,
        reference_worst: worst,
        elapsed: started.elapsed(),
    })
}

/// The soak's [`Limits`] for `raw` with its sensor (`estimator.sensor`).
pub fn limits(raw: &RawParams, params: &Params<f32>, config: &EstimatorConfig) -> Result<Limits, String> {
    fn with<S: SimulatedSource>(
        raw: &RawParams,
        params: &Params<f32>,
        config: &EstimatorConfig,
    ) -> Result<Limits, String> {
        let source = S::simulated(&raw.estimator, SENSOR_BAND, config.oil.min);
        Ok(Limits::new(params, config, &source)?)
    }
    match SensorKind::of(&raw.estimator) {
        SensorKind::Rtd => with::<SimulatedRtd>(raw, params, config),
        SensorKind::Ntc => with::<SimulatedNtc>(raw, params, config),
    }
}

/// The gap between the `f32` and the `f64` twin over a run.
#[derive(Clone, Debug)]
pub struct Drift {
    /// Ticks run.
    pub ticks: u32,
    /// The twins' configuration.
    pub config: TwinConfig,
    /// Largest displacement gap over every tick [strokes], its tick and
    /// temperature.
    pub x: (f64, u32, f32),
    /// Largest pressure gap over every tick [dp], its tick and temperature.
    pub p: (f64, u32, f32),
    /// Holds that ended settled (at least [`SETTLE`] after their step).
    pub settled: u32,
    /// Largest displacement and pressure gaps at the end of the settled
    /// holds of the first tenth of the run (what a drift would move).
    pub first_tenth: (f64, f64),
    /// ... and of the last tenth.
    pub last_tenth: (f64, f64),
    /// Settled holds in the first and the last tenth.
    pub tenth_holds: (u32, u32),
    /// RMS displacement and pressure gaps over every tick of the first
    /// tenth (transients included).
    pub first_rms: (f64, f64),
    /// ... and of the last tenth.
    pub last_rms: (f64, f64),
    /// Ticks either twin refused (a step error).
    pub failed_ticks: u32,
    /// Wall time.
    pub elapsed: Duration,
}

impl Drift {
    /// What is wrong: a failed tick, a gap beyond [`DRIFT_TOLERANCE`] on
    /// any tick, or a settled gap that grew: the last tenth's largest at
    /// more than twice the first tenth's plus 1e-6 (the `f32` state's own
    /// rounding is ~1e-7), or a tenth without a settled hold to compare.
    /// Transients are left out of the growth check: at an impact on a stop
    /// the twins locate the impact a rounding apart and the pressures
    /// differ for that one tick (up to ~2e-4 of `dp` seen), whenever in the
    /// run it happens.
    pub fn problems(&self) -> Vec<String> {
        let mut v = Vec::new();
        if self.failed_ticks > 0 {
            v.push(format!("{} ticks failed", self.failed_ticks));
        }
        if !(self.x.0 <= DRIFT_TOLERANCE) {
            v.push(format!(
                "x gap {:.2e} of the stroke at tick {} ({:.2} C)",
                self.x.0, self.x.1, self.x.2
            ));
        }
        if !(self.p.0 <= DRIFT_TOLERANCE) {
            v.push(format!(
                "pressure gap {:.2e} of dp at tick {} ({:.2} C)",
                self.p.0, self.p.1, self.p.2
            ));
        }
        if self.tenth_holds.0 == 0 || self.tenth_holds.1 == 0 {
            v.push(format!(
                "settled holds in the first and last tenth: {:?}, nothing to compare",
                self.tenth_holds
            ));
        }
        let grows = |first: f64, last: f64| !(last <= 2.0 * first + 1e-6);
        if grows(self.first_tenth.0, self.last_tenth.0) || grows(self.first_tenth.1, self.last_tenth.1) {
            v.push(format!(
                "the settled gap grows: first tenth {:.2e}, {:.2e}; last tenth {:.2e}, {:.2e}",
                self.first_tenth.0, self.first_tenth.1, self.last_tenth.0, self.last_tenth.1
            ));
        }
        v
    }

    /// One line of figures.
    pub fn line(&self) -> String {
        format!(
            "{} ticks ({:?} x{}) in {:.1} s: max |x32 - x64| {:.2e} of the stroke ({:.1} C), max pressure gap {:.2e} of dp ({:.1} C); settled holds ({}; {} / {} in the first / last tenth): max {:.2e} / {:.2e} first tenth, {:.2e} / {:.2e} last tenth; rms over every tick {:.2e} / {:.2e} first tenth, {:.2e} / {:.2e} last tenth",
            self.ticks,
            self.config.scheme,
            self.config.substeps,
            self.elapsed.as_secs_f64(),
            self.x.0,
            self.x.2,
            self.p.0,
            self.p.2,
            self.settled,
            self.tenth_holds.0,
            self.tenth_holds.1,
            self.first_tenth.0,
            self.first_tenth.1,
            self.last_tenth.0,
            self.last_tenth.1,
            self.first_rms.0,
            self.first_rms.1,
            self.last_rms.0,
            self.last_rms.1
        )
    }
}

/// A `Twin<f32, f32>` and a `Twin<f64, f64>` of `raw`, with the firmware's
/// configuration, through `ticks` ticks of the walk of `seed` (its oil
/// temperature only, through a first-order lag of [`DRIFT_LAG`]: a smooth
/// temperature as the estimator hands its twin, without the walk's
/// jumps): both twins get the same `f32` temperature every tick.
/// Time constant of the lag the drift run's temperatures pass [s].
pub const DRIFT_LAG: f64 = 0.2;

pub fn drift(raw: &RawParams, ticks: u32, seed: u64) -> Result<Drift, String> {
    if ticks < 10 {
        return Err(format!("{ticks} ticks: a drift run needs tenths to compare"));
    }
    let p32 = Params::<f32>::new(raw).map_err(|e| e.to_string())?;
    let p64 = Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let estimator = EstimatorConfig::new(raw).map_err(|e| e.to_string())?;
    let gain = (1.0 - (-estimator.twin.tick / DRIFT_LAG).exp()) as f32;
    let config = TwinConfig {
        tick: estimator.twin.tick,
        ..twin_config(raw)?
    };
    let limits = limits(raw, &p32, &estimator)?;
    let mut walk = Walk::new(limits, seed);
    let mut t = walk.at(0).temperature(0);
    let mut a = Twin::<f32, f32>::new(&p32, config, t).map_err(|e| e.to_string())?;
    let mut b = Twin::<f64, f64>::new(&p64, config, f64::from(t)).map_err(|e| e.to_string())?;
    let (stroke, dp) = (p64.plunger.stroke, p64.pressure_drop);
    let tenth = (ticks / 10).max(1);
    let mut d = Drift {
        ticks,
        config,
        x: (0.0, 0, t),
        p: (0.0, 0, t),
        settled: 0,
        first_tenth: (0.0, 0.0),
        last_tenth: (0.0, 0.0),
        tenth_holds: (0, 0),
        first_rms: (0.0, 0.0),
        last_rms: (0.0, 0.0),
        failed_ticks: 0,
        elapsed: Duration::ZERO,
    };
    let (mut first_sq, mut last_sq) = ((0.0f64, 0.0f64), (0.0f64, 0.0f64));
    let started = Instant::now();
    let settle = limits.ticks(SETTLE);
    for k in 0..ticks {
        let seg = *walk.at(k);
        t += gain * (seg.temperature(k) - t);
        let set = a.set_temperature(t).is_ok() && b.set_temperature(f64::from(t)).is_ok();
        if !(set && a.tick().is_ok() && b.tick().is_ok()) {
            d.failed_ticks += 1;
            continue;
        }
        let (s, r) = (a.state(), b.state());
        let ex = (f64::from(s.x) - r.x).abs() / stroke;
        let ep = (f64::from(s.p_a) - r.p_a).abs().max((f64::from(s.p_b) - r.p_b).abs()) / dp;
        // NaN counts as the largest gap.
        if !(ex <= d.x.0) {
            d.x = (if ex.is_nan() { f64::INFINITY } else { ex }, k, t);
        }
        if !(ep <= d.p.0) {
            d.p = (if ep.is_nan() { f64::INFINITY } else { ep }, k, t);
        }
        let settled = seg.hold && k + 1 == seg.end && k - seg.start >= settle;
        d.settled += u32::from(settled);
        if k < tenth {
            first_sq = (first_sq.0 + ex * ex, first_sq.1 + ep * ep);
            if settled {
                d.first_tenth = (d.first_tenth.0.max(ex), d.first_tenth.1.max(ep));
                d.tenth_holds.0 += 1;
            }
        }
        if k >= ticks - tenth {
            last_sq = (last_sq.0 + ex * ex, last_sq.1 + ep * ep);
            if settled {
                d.last_tenth = (d.last_tenth.0.max(ex), d.last_tenth.1.max(ep));
                d.tenth_holds.1 += 1;
            }
        }
    }
    let n = f64::from(tenth);
    d.first_rms = ((first_sq.0 / n).sqrt(), (first_sq.1 / n).sqrt());
    d.last_rms = ((last_sq.0 / n).sqrt(), (last_sq.1 / n).sqrt());
    d.elapsed = started.elapsed();
    Ok(d)
}
