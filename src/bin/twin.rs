//! The QEMU twin (netduinoplus2, STM32F405 / Cortex-M4F): `cargo xtask run`.
//!
//! 1. Prints the quasi-static characteristic over 26-78 C (Eqs. 2-10):
//!    temperature, `A`, chamber pressures, displacement and flows, with the
//!    balance temperature, the Eq. (32) verdict and the linearisation.
//! 2. Replays an oil temperature profile (holds, a 0.5 C/s warm-up, moves
//!    between levels at the file's `max_oil_rate`, a trip outside the
//!    validated range, a cold excursion 80 -> 10 -> 30 C) through the
//!    file's probe (its lag and noise, `compensator_testbench::probe`) and
//!    the file's sensor, simulated at register level and read by its real
//!    driver (a MAX31865 by default; with `estimator.sensor = "ntc"` the
//!    NTC on the STM32F4's ADC: `build.rs` sets `cfg(sensor_ntc)`), with
//!    injected sensor faults, and runs the estimator every 1 ms tick,
//!    printing its telemetry.
//! 3. Checks itself against the f64 reference computed on the host at build
//!    time: at the end of every hold and along every ramp, the estimate's
//!    oil temperature, displacement and chamber pressures within their
//!    bands (+-1.96 standard deviations, the estimate's own) around the
//!    reference's equilibrium at the oil's temperature; OUT_OF_RANGE exactly
//!    outside the validated range; the flags each injected fault must
//!    raise, and no SPIKE but the injected one (a genuine change is
//!    followed, not rejected); no NaN; no re-seat of the twin. Reports the
//!    peak stack measured by stack painting, and exits 0 (all checks pass)
//!    or 1.
//!
//! With the condition monitor (feature `monitor`: the device file names a
//! second sensor) the replay also reads the true device through the
//! file's transducer, simulated at register level on the STM32F4 ADC and
//! read by its real driver (`compensator_testbench::monitor`: the
//! reference's reading at the oil's temperature), offers each reading to
//! the estimator, and checks the chain: after the first hold the healthy
//! device's divider factor is 1 and the sensor's offset 0 within their
//! bands (the readings reach the monitor in their unit); the transducer's
//! open loop raises `SECOND_SENSOR_FAULT` then and only then; the health
//! estimate stays finite. It reports the monitor's verdicts on the
//! healthy device and on the capillary restricted at the replay's last
//! levels (the algorithm's, `docs/monitoring.md`; the snapshot keeps
//! them).
#![no_std]
#![no_main]

use compensator::dynamics::linear::linearise;
use compensator::equilibrium::{balance_temperature, equilibrium};
use compensator::estimator::{Estimator, Flags, StateEstimate};
use compensator::sensor::TemperatureSource;
use compensator::sensor::simulated::SimulatedSource;
use compensator::{Params, asymptotic};
use compensator_firmware::qemu::{CORE, TwinScalar, exit};
use compensator_firmware::{BuiltConfig, BuiltEstimator};
use compensator_testbench::faults::{Expected, FAULTS, Injected, fault_at};
#[cfg(feature = "monitor")]
use compensator_testbench::monitor::Track;
use compensator_testbench::probe::SimulatedProbe;
use cortex_m as _; // links the critical-section implementation defmt needs
use cortex_m_rt::entry;
use defmt::{error, info};

include!(concat!(env!("OUT_DIR"), "/params.rs"));
include!(concat!(env!("OUT_DIR"), "/replay.rs"));

/// The parameter file's sensor behind its real driver, simulated at
/// register level: the MAX31865 ...
#[cfg(not(sensor_ntc))]
type Sensor = compensator::sensor::simulated::SimulatedRtd;
/// ... or the NTC on the STM32F4's ADC (`estimator.sensor = "ntc"`).
#[cfg(sensor_ntc)]
type Sensor = compensator::sensor::simulated::SimulatedNtc;

/// The condition monitor's second sensor: the file's transducer on the
/// simulated STM32F4 ADC, read by its driver.
#[cfg(feature = "monitor")]
type Second = compensator::sensor::transducer::SimulatedMonitor;

/// The simulated element's fault band \[C\]: wide, so that the
/// estimator's oil range is what rejects samples.
const SENSOR_BAND: (f32, f32) = (-60.0, 250.0);

// A fault reports its registers and exits 1 (not a spin until the deadline).
compensator_firmware::qemu_hard_fault_handler!();

/// Numerical margin of the checkpoints beyond the band: displacement, as a
/// fraction of the stroke (f32 steady state: ~2e-6; Q12.20: the
/// fixed-point end-state goal of `host-tests/tests/fixed_point.rs`).
const X_TOLERANCE: f32 = if compensator_firmware::qemu::FIXED_TWIN {
    1e-4
} else {
    1e-5
};
/// Numerical margin of the checkpoints: pressures, as a fraction of the drop.
const P_TOLERANCE: f32 = X_TOLERANCE;
/// Numerical margin of the checkpoints: the oil temperature [C].
const T_TOLERANCE: f32 = 1e-3;
/// The band's half-width in standard deviations (95 % where the error is
/// near normal: `docs/firmware.md`, "Reading the band").
const BAND: f32 = 1.96;

/// Oil temperature of the replay at `time` [s].
fn temperature_at(time: f32) -> f32 {
    compensator_testbench::temperature_at(&REPLAY_PIECES, time)
}

/// The flag an injected fault must raise.
fn flag(expected: Expected) -> Flags {
    match expected {
        Expected::Spike => Flags::SPIKE,
        Expected::SensorFault => Flags::SENSOR_FAULT,
        Expected::Degraded => Flags::DEGRADED,
    }
}

/// Counts passed checks and keeps the failed ones (a bounded list: the
/// summary names at most 8).
struct Checks {
    passed: u32,
    failed: heapless::Vec<&'static str, 8>,
    overflow: u32,
}

impl Checks {
    fn check(&mut self, ok: bool, what: &'static str, time: f32) {
        if ok {
            self.passed += 1;
        } else {
            error!("check failed at {=f32} s: {=str}", time, what);
            if self.failed.push(what).is_err() {
                self.overflow += 1;
            }
        }
    }

    fn failures(&self) -> u32 {
        self.failed.len() as u32 + self.overflow
    }
}

#[entry]
fn main() -> ! {
    // The Cortex-M0's f32 fast paths against compiler_builtins' routines
    // (nothing to check on the other cores).
    if let Err(m) = compensator_firmware::softfloat::self_check(3000) {
        error!(
            "f32 {=str} wrong: operands {=u32:#x} {=u32:#x}, got {=u32:#x}, want {=u32:#x}",
            m.operation, m.operands.0, m.operands.1, m.got, m.want
        );
        exit(false)
    }
    let params = match Params::<f32>::new(&RAW_PARAMS) {
        Ok(p) => p,
        Err(e) => {
            error!("parameters rejected: {=str}", e.field);
            exit(false)
        }
    };
    let config = compensator_firmware::qemu::built_estimator_config(
        &RAW_PARAMS.estimator,
        &OBSERVER,
        &UNCERTAINTY,
        TWIN_SCHEME,
        TWIN_SUBSTEPS,
    );
    info!(
        "compensator twin on the emulated {=str} ({=str} twin); parameters {=str}",
        CORE,
        <TwinScalar as compensator::Real>::NAME,
        PARAMS_SOURCE
    );
    info!(
        "twin: {=str}, {=u8} steps per tick (chosen at build time, estimated within {=f32} % of a step)",
        TWIN_SCHEME, TWIN_SUBSTEPS, TWIN_ESTIMATED_ERROR_PCT
    );
    static_characteristic(&params);
    let ok = replay(&params, config);
    let stack = stack_peak();
    info!("[measure] peak stack {=u32} bytes (stack painting)", stack as u32);
    exit(ok)
}

/// Part 1: the quasi-static model over 26-78 C.
#[inline(never)]
fn static_characteristic(params: &Params<f32>) {
    info!(
        "quasi-static equilibrium (Eqs. 2-10), dp = {=f32} bar",
        params.pressure_drop * 1e-5
    );
    info!("  t[C]   A[sqrt(Pa)]  p_a[kPa]  p_b[kPa]  x[um]   Q_a[l/min] Q_throt[l/min] Q0[l/min]");
    let mut t = 26.0f32;
    while t <= 78.0 {
        match equilibrium(params, t) {
            Ok(e) => info!(
                "  {=f32} {=f32} {=f32} {=f32} {=f32} {=f32} {=f32} {=f32}",
                t,
                e.a,
                e.p_a * 1e-3,
                e.p_b * 1e-3,
                e.x * 1e6,
                e.q_branch * 6e4,
                e.q_throt * 6e4,
                e.q_total * 6e4
            ),
            Err(e) => error!("  {=f32}: {}", t, e),
        }
        t += 4.0;
    }
    match balance_temperature(params, 0.0, 100.0) {
        Ok(t0) => info!("balance temperature (p_a = p_b, Eq. 2): {=f32} C", t0),
        Err(e) => info!("balance temperature: {}", e),
    }
    match asymptotic::monotonicity(params, 26.0, 78.0, 53) {
        Ok(m) => info!(
            "Eq. (32) over 26-78 C: monotonic = {=bool}, smallest dx/dt {=f32} um/K at {=f32} C",
            m.monotonic,
            m.worst_dx_dt * 1e6,
            m.worst_temperature
        ),
        Err(e) => error!("Eq. (32): {}", e),
    }
    for t in [30.0f32, 80.0] {
        match linearise(params, t) {
            Ok(l) => info!(
                "linearisation at {=f32} C: dominant eigenvalue {=f32} 1/s, stable = {=bool}, plunger damping ratio {=f32}",
                t, l.dominant.re, l.stable, l.plunger_damping_ratio
            ),
            Err(e) => error!("linearisation at {=f32} C: {}", t, e),
        }
    }
}

/// Part 2: the estimator on the replayed profile; returns whether every
/// check passed.
#[inline(never)]
fn replay(params: &Params<f32>, config: BuiltConfig) -> bool {
    let start = temperature_at(0.0);
    let probe_settings = &RAW_PARAMS.probe;
    let tick = config.tick();
    let mut probe = SimulatedProbe::new(
        start,
        probe_settings.time_constant as f32,
        probe_settings.well_time_constant as f32,
        probe_settings.noise as f32,
        tick,
        compensator_testbench::probe::REPLAY_SEED,
    );
    // The device's sensor settings, with the wide fault band.
    let mut sensor = Sensor::simulated(&RAW_PARAMS.estimator, SENSOR_BAND, start);
    #[cfg(sensor_ntc)]
    info!(
        "sensor: NTC on the STM32F4 ADC, {=u8} bits, {=u8} conversions a reading",
        sensor.settings().bits,
        sensor.settings().oversampling
    );
    let mut checks = Checks {
        passed: 0,
        failed: heapless::Vec::new(),
        overflow: 0,
    };
    checks.check(sensor.start().is_ok(), "sensor configuration", 0.0);
    #[cfg_attr(
        feature = "monitor",
        allow(unused_mut, reason = "the monitor's image moves it into its own")
    )]
    let mut estimator = match Estimator::<TwinScalar, _, _>::with_scalar(params, config, start) {
        Ok(e) => e,
        Err(e) => {
            error!("estimator: {}", e);
            return false;
        }
    };
    #[cfg(feature = "monitor")]
    let (mut estimator, mut second, track, second_every) = {
        let (Some(transducer), Some(settings)) = (MONITOR_TRANSDUCER, MONITOR) else {
            error!("the monitor's image without a second sensor");
            return false;
        };
        let estimator = match estimator.with_monitor(settings) {
            Ok(e) => e,
            Err(compensator::monitor::MonitorError::NotPositive(field)) => {
                error!("monitor: {=str} must be finite and positive", field);
                return false;
            }
        };
        let track = Track {
            truth: &MONITOR_TRUTH,
            restricted_from: MONITOR_RESTRICTED_FROM,
            open_loop: MONITOR_OPEN_LOOP,
        };
        let second = compensator::sensor::transducer::simulated(
            transducer,
            track.reading(0.0, start),
            compensator_testbench::monitor::SEED,
        );
        info!(
            "second sensor: {=str} transducer on the STM32F4 ADC, {=u8} bits, {=f32} Pa or m a code, read every {=f32} ms",
            transducer.quantity.name(),
            transducer.bits,
            transducer.units_per_code(),
            transducer.period * 1e3
        );
        (estimator, second, track, config.ticks_per(transducer.period))
    };
    #[cfg(feature = "monitor")]
    let mut watch = MonitorWatch::new(config.telemetry_every as f32 * tick);
    let end = REPLAY_PIECES[REPLAY_PIECES.len() - 1].1;
    let ticks = (end / tick) as u32;
    let sensor_every = config.ticks_per(sensor.sample_period());
    let mut seen = [Flags::empty(); FAULTS.len()];
    let mut next_checkpoint = 0;
    let mut out_of_range_seen = false;
    let mut nan_ticks = 0u32;
    let mut stray_spikes = 0u32;
    let mut reseats = 0u32;
    // The worst checkpoint error, in units of its band (1: on its edge).
    let mut worst_band = 0.0f32;
    info!(
        "replaying {=f32} s through a {=f32} s probe (noise {=f32} C): ticks of {=f32} ms, sensor every {=u32} ticks, telemetry every {=u32} ticks",
        end,
        probe_settings.time_constant as f32,
        probe_settings.noise as f32,
        tick * 1e3,
        sensor_every,
        config.telemetry_every
    );
    for k in 0..ticks {
        let time = k as f32 * tick;
        let fault_now = fault_at(time);
        let oil = temperature_at(time);
        let reading = probe.advance(oil);
        // Drive the simulated sensor.
        let injected = fault_now.map(|i| FAULTS[i].injected);
        let delta = if injected == Some(Injected::Spike) {
            SPIKE_DELTA
        } else {
            0.0
        };
        sensor.set_temperature(reading + delta);
        sensor.inject(injected.and_then(Injected::injection));
        #[cfg(not(feature = "monitor"))]
        let e = tick_path(&mut sensor, &mut estimator, k % sensor_every == 0);
        #[cfg(feature = "monitor")]
        let e = {
            track.drive(&mut second, time, oil);
            let e = tick_path(
                &mut sensor,
                &mut second,
                &mut estimator,
                k % sensor_every == 0,
                k % second_every == 0,
            );
            watch.tick(&track, time, &e);
            e
        };
        if let Some(i) = fault_now {
            seen[i].insert(e.flags);
        }
        let injected_spike = fault_now.is_some_and(|i| FAULTS[i].injected == Injected::Spike);
        if e.flags.contains(Flags::SPIKE) && !injected_spike {
            stray_spikes += 1;
        }
        if (OUT_OF_RANGE_HOLD.0..OUT_OF_RANGE_HOLD.1).contains(&time) && e.flags.contains(Flags::OUT_OF_RANGE) {
            out_of_range_seen = true;
        }
        if !e.is_finite() {
            nan_ticks += 1;
        }
        reseats = e.reseats;
        if next_checkpoint < CHECKPOINTS.len() && time >= CHECKPOINTS[next_checkpoint].0 {
            let (_, temp, x_ref, pa_ref, pb_ref, outside) = CHECKPOINTS[next_checkpoint];
            let u = e.uncertainty;
            let (dx, dp) = (X_TOLERANCE * params.plunger.stroke, P_TOLERANCE * params.pressure_drop);
            // How far out of its band, 1 at the edge.
            let off = |v: f32, reference: f32, sd: f32, margin: f32| (v - reference).abs() / (BAND * sd + margin);
            let worst = off(e.temperature, temp, u.t_oil, T_TOLERANCE)
                .max(off(e.x, x_ref, u.x, dx))
                .max(off(e.p_a, pa_ref, u.p_a, dp))
                .max(off(e.p_b, pb_ref, u.p_b, dp));
            worst_band = worst_band.max(worst);
            info!(
                "checkpoint {=f32} s, oil {=f32} C: t {=f32} +- {=f32} C, x {=f32} +- {=f32} um against {=f32}, p_a {=f32} +- {=f32} kPa against {=f32}",
                time,
                temp,
                e.temperature,
                BAND * u.t_oil,
                e.x * 1e6,
                BAND * u.x * 1e6,
                x_ref * 1e6,
                e.p_a * 1e-3,
                BAND * u.p_a * 1e-3,
                pa_ref * 1e-3
            );
            checks.check(worst <= 1.0, "estimate within its band around the reference", time);
            if x_ref == 0.0 && outside.is_some() {
                checks.check(e.flags.contains(Flags::AT_STOP), "AT_STOP on the closed stop", time);
            }
            if let Some(outside) = outside {
                checks.check(
                    e.flags.contains(Flags::OUT_OF_RANGE) == outside,
                    "OUT_OF_RANGE exactly outside the validated range",
                    time,
                );
            }
            next_checkpoint += 1;
        }
        if estimator.telemetry_due() {
            telemetry_path((k as f32 * tick * 1e3 + 0.5) as u32, &e);
        }
    }
    checks.check(next_checkpoint == CHECKPOINTS.len(), "every checkpoint reached", end);
    info!(
        "[measure] worst checkpoint error {=f32} of its band ({=u32} checkpoints)",
        worst_band,
        CHECKPOINTS.len() as u32
    );
    info!("SPIKE outside the injected spike: {=u32} ticks", stray_spikes);
    checks.check(stray_spikes == 0, "no genuine change rejected as a spike", end);
    // A correct twin settles on the closed form by itself: the estimator's
    // consistency check never has to re-seat it.
    info!("twin re-seated {=u32} times by the consistency check", reseats);
    checks.check(reseats == 0, "the twin never needed re-seating", end);
    for (i, f) in FAULTS.iter().enumerate() {
        let ok = seen[i].contains(flag(f.expected));
        info!("injected {} at {=f32} s raised [{}]", f.injected, f.start, seen[i]);
        checks.check(ok, "the injected fault raised its flag", f.start);
    }
    checks.check(
        out_of_range_seen || !OUT_OF_RANGE_REACHABLE,
        "OUT_OF_RANGE outside the validated range",
        OUT_OF_RANGE_HOLD.0,
    );
    checks.check(nan_ticks == 0, "no NaN in any estimate", end);
    #[cfg(feature = "monitor")]
    watch.check(&mut checks, &track, end);
    info!("checks: {=u32} passed, {=u32} failed", checks.passed, checks.failures());
    for what in checks.failed.iter() {
        error!("failed: {=str}", what);
    }
    checks.failures() == 0
}

/// One controller tick as the board runs it: the sensor read when due
/// (`read`), then the estimator (filter, twin, job). Not inlined, so that
/// `cargo xtask test` can check that nothing reachable from it panics.
#[cfg(not(feature = "monitor"))]
#[inline(never)]
fn tick_path(sensor: &mut Sensor, estimator: &mut BuiltEstimator<TwinScalar>, read: bool) -> StateEstimate {
    let sample = if read { sensor.read() } else { Ok(None) };
    estimator.tick(sample)
}

/// One controller tick with the condition monitor: the sensor read when
/// due (`read`), the second sensor when due (`read_second`, offered to the
/// estimator, whose monitor takes it in a job's place), then the
/// estimator. Not inlined (the panic-free check).
#[cfg(feature = "monitor")]
#[inline(never)]
fn tick_path(
    sensor: &mut Sensor,
    second: &mut Second,
    estimator: &mut BuiltEstimator<TwinScalar>,
    read: bool,
    read_second: bool,
) -> StateEstimate {
    let sample = if read { sensor.read() } else { Ok(None) };
    if read_second {
        estimator.offer_second(second.read());
    }
    estimator.tick(sample)
}

/// The monitor's alarms: a change detected or a fault named.
#[cfg(feature = "monitor")]
const ALARMS: Flags = Flags(Flags::DEVICE_CHANGED.0 | compensator::monitor::LATCHED.0);

/// Time after the open loop's end in which its flag may still show \[s\]
/// (the window's last reading is taken on a later tick), besides one
/// telemetry period: the next published estimate carries the flags of the
/// readings since the last.
#[cfg(feature = "monitor")]
const OPEN_LOOP_TAIL: f32 = 0.05;

/// What the replay saw of the condition monitor.
///
/// Checked: the transducer's chain (readings reach the monitor in their
/// unit: after the first hold, before any ramp, the healthy device's
/// divider factor is 1 and the offset 0, each within 1.96 of the filter's
/// own standard deviation; its open loop raises `SECOND_SENSOR_FAULT`
/// then and only then; the health estimate stays finite). Reported, for
/// the snapshot: the monitor's verdicts on the healthy device and on the
/// restricted capillary, which are its algorithm's (`docs/monitoring.md`).
#[cfg(feature = "monitor")]
struct MonitorWatch {
    /// Time after the open loop's end in which its flag may still show
    /// \[s\] ([`OPEN_LOOP_TAIL`]).
    tail: f32,
    /// The health estimate at the end of the first hold.
    settled: compensator::monitor::HealthEstimate,
    /// Ticks with a health estimate not finite after the first reading.
    not_finite: u32,
    /// Flags seen while the transducer's loop was open.
    open_flags: Flags,
    /// Ticks flagged `SECOND_SENSOR_FAULT` outside the open loop, the
    /// first \[s\].
    stray_sensor_faults: u32,
    first_stray: f32,
    /// Ticks with an alarm while the device was healthy, and the first \[s\].
    false_alarms: u32,
    first_false_alarm: f32,
    /// The alarms raised while the device was healthy.
    false_flags: Flags,
    /// After the restriction: when a change was first flagged and a fault
    /// first named \[s\] (NaN: never), and the faults named.
    detected: f32,
    named: f32,
    named_flags: Flags,
    /// The health estimate just before the restriction, and at the end.
    healthy: compensator::monitor::HealthEstimate,
    last: compensator::monitor::HealthEstimate,
}

#[cfg(feature = "monitor")]
impl MonitorWatch {
    /// `telemetry` the telemetry's period \[s\].
    fn new(telemetry: f32) -> Self {
        MonitorWatch {
            tail: OPEN_LOOP_TAIL + telemetry,
            settled: compensator::monitor::HealthEstimate::NONE,
            not_finite: 0,
            open_flags: Flags::empty(),
            stray_sensor_faults: 0,
            first_stray: f32::NAN,
            false_alarms: 0,
            first_false_alarm: f32::NAN,
            false_flags: Flags::empty(),
            detected: f32::NAN,
            named: f32::NAN,
            named_flags: Flags::empty(),
            healthy: compensator::monitor::HealthEstimate::NONE,
            last: compensator::monitor::HealthEstimate::NONE,
        }
    }

    fn tick(&mut self, track: &Track<'_>, time: f32, e: &StateEstimate) {
        let h = &e.health;
        if time < REPLAY_PIECES[0].1 {
            self.settled = *h;
        }
        if time >= 1.0
            && ![h.divider, h.sd_divider, h.spring, h.offset, h.sd_offset, h.cusum]
                .iter()
                .all(|v| v.is_finite())
        {
            self.not_finite += 1;
        }
        let alarm = Flags(e.flags.0 & ALARMS.0);
        if !track.restricted(time) {
            self.healthy = *h;
            if !alarm.is_empty() {
                if self.false_alarms == 0 {
                    self.first_false_alarm = time;
                }
                self.false_alarms += 1;
                self.false_flags.insert(alarm);
            }
        } else {
            if !alarm.is_empty() && self.detected.is_nan() {
                self.detected = time;
            }
            let named = Flags(e.flags.0 & compensator::monitor::LATCHED.0);
            if !named.is_empty() && self.named.is_nan() {
                self.named = time;
            }
            self.named_flags.insert(named);
        }
        if track.open(time) {
            self.open_flags.insert(e.flags);
        } else if e.flags.contains(Flags::SECOND_SENSOR_FAULT)
            && !(time >= track.open_loop.0 && time < track.open_loop.1 + self.tail)
        {
            if self.stray_sensor_faults == 0 {
                self.first_stray = time;
            }
            self.stray_sensor_faults += 1;
        }
        self.last = *h;
    }

    fn check(&self, checks: &mut Checks, track: &Track<'_>, end: f32) {
        let at = REPLAY_PIECES[0].1;
        let s = &self.settled;
        info!(
            "monitor after the first hold ({=f32} s): divider {=f32} (sd of its log {=f32}), offset {=f32} +- {=f32} (sd), spring {=f32}",
            at, s.divider, s.sd_divider, s.offset, s.sd_offset, s.spring
        );
        checks.check(
            libm::fabsf(libm::logf(s.divider)) <= BAND * s.sd_divider,
            "the healthy device's divider factor is 1 within its band",
            at,
        );
        checks.check(
            libm::fabsf(s.offset) <= BAND * s.sd_offset,
            "the second sensor's offset is 0 within its band",
            at,
        );
        checks.check(self.not_finite == 0, "the health estimate is finite", end);
        info!(
            "transducer loop open {=f32}-{=f32} s: [{}]; SECOND_SENSOR_FAULT outside it: {=u32} ticks (the first at {=f32} s)",
            track.open_loop.0, track.open_loop.1, self.open_flags, self.stray_sensor_faults, self.first_stray
        );
        checks.check(
            self.open_flags.contains(Flags::SECOND_SENSOR_FAULT) && self.stray_sensor_faults == 0,
            "SECOND_SENSOR_FAULT exactly while the transducer's loop is open",
            track.open_loop.0,
        );
        // The monitor's verdicts: its algorithm's, reported, not checked.
        let h = &self.healthy;
        info!(
            "monitor verdict, healthy device until {=f32} s: {=u32} ticks alarmed [{}], the first at {=f32} s; divider {=f32} (sd of its log {=f32}), offset {=f32}, {=u32} readings rejected",
            track.restricted_from,
            self.false_alarms,
            self.false_flags,
            self.first_false_alarm,
            h.divider,
            h.sd_divider,
            h.offset,
            h.rejected
        );
        let l = &self.last;
        info!(
            "monitor verdict, capillary at {=f32} of its conductance from {=f32} s: alarm at {=f32} s, named [{}] first at {=f32} s; divider at the end {=f32} (sd of its log {=f32})",
            MONITOR_RESTRICTION,
            track.restricted_from,
            self.detected,
            self.named_flags,
            self.named,
            l.divider,
            l.sd_divider
        );
    }
}

/// The telemetry record of `e` at `ms`, packed by defmt (checked as
/// [`tick_path`] is).
#[inline(never)]
fn telemetry_path(ms: u32, e: &StateEstimate) {
    info!("{=u32} ms {}", ms, e);
}

/// Peak stack use [bytes]: cortex-m-rt painted the stack with
/// `0xCCCC_CCCC` at reset (feature `paint-stack`); the lowest word no longer
/// painted marks the deepest the stack has been.
fn stack_peak() -> usize {
    unsafe extern "C" {
        static _stack_start: u32;
        static _stack_end: u32;
    }
    let (lo, hi) = (&raw const _stack_end as usize, &raw const _stack_start as usize);
    let mut p = lo;
    // SAFETY: [lo, hi) is the stack region, word-aligned, always mapped.
    while p < hi && unsafe { (p as *const u32).read_volatile() } == 0xCCCC_CCCC {
        p += 4;
    }
    hi - p
}
