//! The state estimator the firmware runs every tick: temperature sample ->
//! filtered temperature -> fluid properties -> FSI twin step ->
//! closed-form equilibrium, sensitivity and stability -> [`StateEstimate`].
//!
//! Per tick, in this order:
//! 1. the latest sample (if any) is checked: not finite or outside the oil's
//!    range is a fault; further than `spike_threshold` from the filtered
//!    value is a spike and rejected, unless it is the `spike_limit + 1`-th
//!    consecutive out-of-band sample agreeing (within the threshold) with
//!    the one before: then it is a real step and the filter jumps to it;
//! 2. a first-order filter (time constant `filter_time_constant`) follows
//!    the last accepted sample;
//! 3. the twin advances one tick (its coefficients from the last Fluid
//!    job);
//! 4. one temperature-only job runs, in turn: the oil's properties (one
//!    Walther evaluation, handed to the twin and the flow laws) at the
//!    filtered temperature, reached at a bounded slew ([`TWIN_SLEW`]: the
//!    twin never sees an abrupt change, and while it is on its way every
//!    job is this one); the closed-form equilibrium with `dx/dt` (Eq. 31);
//!    the Routh-Hurwitz stability of the linearisation at that equilibrium;
//!    the machine's losses. None runs on a telemetry tick (at most every
//!    second tick), nor on a tick where the twin had an event (an impact, a
//!    release: a few steps more), which also moves a due telemetry record
//!    to the next tick. Each result is thus refreshed every four job ticks
//!    (4 ms at the default 1 kHz and 2 Hz telemetry: fluid properties five
//!    times the MAX31865's 50 Hz rate), while the oil's temperature changes
//!    over seconds. A job the model refuses keeps its previous results and
//!    flags the estimate `DEGRADED` until it succeeds again;
//! 5. flows and the compensation error follow from the twin's state.
//!
//! A consistency check catches a twin that settled where the physics does
//! not: once the twin's temperature has stayed within [`STEADY_BAND`] for
//! [`SETTLE_TIME_CONSTANTS`] of the twin's slowest time constants (the
//! decay rate of the slowest mode of the linearisation, found by the
//! Stability job), every Equilibrium job compares the twin's state with the
//! closed-form equilibrium it just computed (clamped to the stops). A twin
//! further than [`X_TOLERANCE`] of the stroke or [`P_TOLERANCE`] of `dp`
//! away is re-seated on the equilibrium, counted
//! ([`StateEstimate::reseats`]) and flagged [`Flags::TWIN_RESEATED`]. The
//! thresholds and their reasons are in the project's `docs/firmware.md`.
//!
//! The cost of a tick is bounded by the twin's step, the fluid properties
//! and the larger of one job or the telemetry packing: what the firmware's
//! budget measures. Nothing here allocates or panics; every failure becomes
//! a flag.

use crate::dynamics::fsi::{Contact, Fsi};
use crate::dynamics::linear::characteristic_polynomial;
use crate::dynamics::schemes::OdeSystem;
use crate::dynamics::{Twin, TwinConfig};
use crate::equilibrium::{a_parameter, equilibrium_for};
use crate::error::ModelError;
use crate::fluid::FluidPoint;
use crate::params::{ParamError, Params, RawEstimator};
use crate::scalar::Real;
use crate::sensor::SensorFault;
use crate::{asymptotic, compensation};

/// Largest relative change of the twin's capillary conductance (~ 1 / mu)
/// per Fluid job: below the twin's `ABRUPT_CHANGE` (1 %), so that the twin
/// never grades a tick in the estimator (`Twin::tick`: a graded tick costs
/// several substeps). While the twin's oil is on its way, every job tick is
/// a Fluid job: the paper preset's oil (2.6 %/K of viscosity at 80 C,
/// 11 %/K at 0 C) then follows a step at 70 C/s (0 C) to 300 C/s (80 C).
pub const TWIN_SLEW: f32 = 0.008;

/// Band [C] the filtered temperature must stay within to count as steady
/// for the consistency check. Over the band the closed form moves by
/// `|dx/dt| * 0.05 K`: 0.12 % of the stroke on the paper preset (37 um/K,
/// 1.5 mm), below 1 % on designs whose free displacement changes by up to
/// 2.5 strokes over 30-80 C; the pressures by at most 0.05 % of `dp`. It is
/// wider than the filter's response to one code of the MAX31865 (0.034 C),
/// so sensor noise does not keep the temperature unsteady.
pub const STEADY_BAND: f32 = 0.05;

/// Time constants of the twin's slowest mode the temperature must have been
/// steady before the twin is compared with the closed form. A linear mode
/// decays by `exp(-10) = 4.5e-5` over them: a full-stroke or full-`dp`
/// transient ends 200 times inside the tolerances, leaving room for the
/// nonlinear orifice law and the travel onto a stop.
pub const SETTLE_TIME_CONSTANTS: f32 = 10.0;

/// Fewest steady ticks before the check (three rounds of the four jobs, so
/// that the twin's fluid properties and the equilibrium it is compared with
/// belong to the steady temperature).
pub const MIN_SETTLE_TICKS: u32 = 16;

/// Agreement required of a settled twin: displacement, as a fraction of the
/// stroke. Ten times the twin's accuracy goal at steady state (1e-3), so a
/// correct twin never trips it; a false equilibrium sits tens of percent
/// away (the paper preset's 40 -> 0 C step: 54 % of `dp`).
pub const X_TOLERANCE: f32 = 1e-2;

/// Agreement required of a settled twin: each chamber pressure, as a
/// fraction of `dp` (as [`X_TOLERANCE`]).
pub const P_TOLERANCE: f32 = 1e-2;

/// Estimator settings in `f32` (from the `[estimator]` section).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig {
    /// The twin's integrator. Its tick is the estimator's (`1 / tick_hz`);
    /// scheme and steps per tick are [`TwinConfig::SHIPPED`]'s unless
    /// changed before [`Estimator::new`].
    pub twin: TwinConfig,
    /// Filter gain per tick, `1 - exp(-tick / tau)`.
    pub filter_gain: f32,
    /// Spike threshold [C].
    pub spike_threshold: f32,
    /// Consecutive rejected samples accepted as a real step.
    pub spike_limit: u32,
    /// Validated temperature range [C].
    pub valid: (f32, f32),
    /// Range where the oil model is used at all [C].
    pub oil: (f32, f32),
    /// Ticks between telemetry records (0: never).
    pub telemetry_every: u32,
    /// Ticks without an accepted sample after which the estimate is degraded.
    pub stale_after: u32,
}

impl EstimatorConfig {
    /// From the parameter file's `[estimator]` section (validated).
    ///
    /// # Errors
    ///
    /// A [`ParamError`] naming the first field of `raw` that breaks its
    /// rule (`RawEstimator::validate`).
    pub fn new(raw: &RawEstimator) -> Result<Self, ParamError> {
        raw.validate()?;
        let tick = 1.0 / raw.tick_hz;
        let telemetry_every = if raw.telemetry_hz > 0.0 {
            libm::round(raw.tick_hz / raw.telemetry_hz).max(1.0) as u32
        } else {
            0
        };
        Ok(EstimatorConfig {
            twin: TwinConfig {
                tick,
                ..TwinConfig::SHIPPED
            },
            filter_gain: (1.0 - libm::exp(-tick / raw.filter_time_constant)) as f32,
            spike_threshold: raw.spike_threshold as f32,
            // A whole number of at most 65,534 (validated).
            spike_limit: raw.spike_limit as u32,
            valid: (raw.valid_min as f32, raw.valid_max as f32),
            oil: (raw.oil_min as f32, raw.oil_max as f32),
            telemetry_every,
            // Half a second without a usable sample (at least ten ticks).
            stale_after: (libm::round(raw.tick_hz * 0.5) as u32).max(10),
        })
    }

    /// Tick [s].
    pub fn tick(&self) -> f32 {
        self.twin.tick as f32
    }

    /// Ticks between samples of a source that delivers one every `period`
    /// [s] (at least one).
    pub fn ticks_per(&self, period: f32) -> u32 {
        let n = period / self.tick() + 0.5;
        if n >= 1.0 { n as u32 } else { 1 }
    }
}

/// Condition flags of an estimate (a bit set).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flags(pub u16);

impl Flags {
    /// The plunger rests on a stop (window closed or fully open).
    pub const AT_STOP: Flags = Flags(1 << 0);
    /// The filtered temperature is outside the validated range.
    pub const OUT_OF_RANGE: Flags = Flags(1 << 1);
    /// Eq. (32) does not hold over the validated range: the equilibrium
    /// branch may not be unique.
    pub const NOT_UNIQUE: Flags = Flags(1 << 2);
    /// The linearisation at the equilibrium is not Hurwitz-stable.
    pub const UNSTABLE: Flags = Flags(1 << 3);
    /// This tick's sample was missing or unusable (a sensor fault).
    pub const SENSOR_FAULT: Flags = Flags(1 << 4);
    /// This tick's sample was rejected as a spike.
    pub const SPIKE: Flags = Flags(1 << 5);
    /// The estimate is not trustworthy: no usable sample for a while, the
    /// oil model refused the temperature, or the twin had to be reset.
    pub const DEGRADED: Flags = Flags(1 << 6);
    /// The twin disagreed with the closed-form equilibrium although the
    /// temperature had been steady for several of its slowest time
    /// constants (a false equilibrium, or a state corrupted otherwise): it
    /// was re-seated on the equilibrium. Raised from the re-seat until a
    /// later check (one settling window on) finds the twin in agreement.
    pub const TWIN_RESEATED: Flags = Flags(1 << 7);

    /// Names of the flags, in bit order.
    pub const NAMES: [&'static str; 8] = [
        "AT_STOP",
        "OUT_OF_RANGE",
        "NOT_UNIQUE",
        "UNSTABLE",
        "SENSOR_FAULT",
        "SPIKE",
        "DEGRADED",
        "TWIN_RESEATED",
    ];

    /// No flag set.
    pub const fn empty() -> Self {
        Flags(0)
    }
    /// All of `other`'s flags are set.
    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }
    /// Sets `other`'s flags.
    pub fn insert(&mut self, other: Flags) {
        self.0 |= other.0;
    }
    /// No flag set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Flags {
    /// Names as interned strings: two bytes each in the log stream, not the
    /// name's bytes (what keeps a telemetry record cheap to pack).
    fn format(&self, f: defmt::Formatter) {
        if self.is_empty() {
            defmt::write!(f, "-");
            return;
        }
        let names = [
            defmt::intern!("AT_STOP"),
            defmt::intern!("OUT_OF_RANGE"),
            defmt::intern!("NOT_UNIQUE"),
            defmt::intern!("UNSTABLE"),
            defmt::intern!("SENSOR_FAULT"),
            defmt::intern!("SPIKE"),
            defmt::intern!("DEGRADED"),
            defmt::intern!("TWIN_RESEATED"),
        ];
        let mut first = true;
        for (i, name) in names.iter().enumerate() {
            if self.0 & (1 << i) != 0 {
                if first {
                    defmt::write!(f, "{=istr}", *name);
                } else {
                    defmt::write!(f, "|{=istr}", *name);
                }
                first = false;
            }
        }
    }
}

/// The estimator's output for one tick (SI units, `f32`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateEstimate {
    /// Tick counter.
    pub tick: u32,
    /// Filtered oil temperature [C].
    pub temperature: f32,
    /// Plunger displacement [m].
    pub x: f32,
    /// Plunger velocity [m/s].
    pub v: f32,
    /// Chamber (a) pressure [Pa].
    pub p_a: f32,
    /// Chamber (b) pressure [Pa].
    pub p_b: f32,
    /// Flow leaving chamber (a) through its capillary [m^3/s].
    pub q_a: f32,
    /// Flow leaving chamber (b) through its orifice [m^3/s].
    pub q_b: f32,
    /// Flow through the window [m^3/s].
    pub q_throt: f32,
    /// Total flow `Q0 = Q_a + Q_b + Q_throt` [m^3/s].
    pub q_total: f32,
    /// `Q0 - (Q_work + dQ_lost(t))` [m^3/s]; NaN without a `[machine]`.
    pub compensation_error: f32,
    /// Quasi-static equilibrium displacement at this temperature [m].
    pub x_equilibrium: f32,
    /// `dx/dt` of the equilibrium branch (Eq. 31) [m/K].
    pub dx_dt: f32,
    /// Times the consistency check has re-seated the twin on the
    /// closed-form equilibrium since start (saturating; 0 for a twin that
    /// never settled at a false state).
    pub reseats: u32,
    /// Conditions.
    pub flags: Flags,
}

impl StateEstimate {
    /// Whether every state, flow and equilibrium field is finite (the
    /// estimator's promise on any input). `compensation_error` is left out:
    /// it is NaN by design without a `[machine]`.
    pub fn is_finite(&self) -> bool {
        [
            self.temperature,
            self.x,
            self.v,
            self.p_a,
            self.p_b,
            self.q_a,
            self.q_b,
            self.q_throt,
            self.q_total,
            self.x_equilibrium,
            self.dx_dt,
        ]
        .iter()
        .all(|v| v.is_finite())
    }
}

/// The telemetry record: the state estimate in engineering units. The
/// equilibrium `x*` and `dx/dt` stay out of it (each float costs ~80
/// instructions to pack); they are in the struct for whoever needs them.
#[cfg(feature = "defmt")]
impl defmt::Format for StateEstimate {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "t={=f32} C x={=f32} um v={=f32} mm/s p_a={=f32} p_b={=f32} kPa Q_a={=f32} Q_b={=f32} Q_throt={=f32} Q0={=f32} err={=f32} l/min reseats={=u32} [{}]",
            self.temperature,
            self.x * 1e6,
            self.v * 1e3,
            self.p_a * 1e-3,
            self.p_b * 1e-3,
            self.q_a * 6e4,
            self.q_b * 6e4,
            self.q_throt * 6e4,
            self.q_total * 6e4,
            self.compensation_error * 6e4,
            self.reseats,
            self.flags
        )
    }
}

/// The estimator.
#[derive(Clone, Copy, Debug)]
pub struct Estimator {
    params: Params<f32>,
    config: EstimatorConfig,
    twin: Twin<f32, f32>,
    /// Filtered temperature [C].
    filtered: f32,
    /// Last accepted sample [C] (the filter's input).
    held: f32,
    /// Consecutive out-of-band samples agreeing with each other.
    spikes: u32,
    /// The last out-of-band sample [C].
    candidate: f32,
    /// Jobs whose last run failed, one bit per [`Job`] (the oil model
    /// refused the temperature: the previous results stay in force). The
    /// estimate is degraded until each of them succeeds again.
    failed_jobs: u8,
    since_sample: u32,
    tick: u32,
    monotonic: bool,
    /// Dynamic viscosity at the machine's reference temperature [Pa s].
    machine_mu_ref: Option<f32>,
    /// Temperature-only results, refreshed in rotation (see [`Job`]).
    statics: Statics,
    /// The job of the next tick that is not a telemetry tick.
    next_job: Job,
    last: Option<StateEstimate>,
    /// Filtered temperature at the start of the current steady stretch [C].
    steady_anchor: f32,
    /// Ticks that ran a job while the filtered temperature stayed within
    /// [`STEADY_BAND`] of `steady_anchor` (or since the last re-seat).
    steady_ticks: u32,
    /// Re-seats of the twin so far (saturating).
    reseats: u32,
    /// Consistency checks run so far (saturating).
    checks: u32,
    /// The last check re-seated the twin (raises `TWIN_RESEATED` until a
    /// check finds it in agreement).
    reseated: bool,
    /// This tick's estimate is to be published ([`Estimator::telemetry_due`]).
    publish: bool,
    /// A publication was due on a tick the twin spent on an event: the
    /// next tick publishes.
    telemetry_pending: bool,
}

/// Results that depend on the temperature only. Each tick that is not a
/// telemetry tick refreshes one of them, so each is refreshed every four
/// such ticks (telemetry is at most every second tick, validated), while
/// the oil's temperature changes over seconds, and the cost of a tick stays
/// bounded by the twin plus the largest single job.
#[derive(Clone, Copy, Debug)]
struct Statics {
    /// Oil state and derivatives at `temperature`.
    point: FluidPoint<f32>,
    /// Capillary conductance `1 / R_l` [m^3/(s Pa)].
    capillary_conductance: f32,
    /// `C_d f sqrt(2 / rho)` of the orifice [m^3/(s sqrt(Pa))].
    orifice_factor: f32,
    /// `eta pi d sqrt(2 dp / rho)` of the window [m^2/s].
    window_factor: f32,
    x_equilibrium: f32,
    dx_dt: f32,
    /// The equilibrium in the twin's model units `(x / L, v / V,
    /// (p_a - p_c) / dp, (p_b - p_c) / dp)` (for the linearisation and the
    /// consistency check).
    y_equilibrium: [f32; 4],
    stable: bool,
    /// `SETTLE_TIME_CONSTANTS / tick` [1/s] (constant).
    settle_per_second: f32,
    /// Lower bound of the slowest decay rate of the linearisation, in the
    /// twin's time unit (0: none, not stable); the next search's hint.
    slowest_rate: f32,
    /// Time constant of the slowest mode of the linearisation [s].
    slowest_time_constant: f32,
    /// Steady ticks before the consistency check: [`SETTLE_TIME_CONSTANTS`]
    /// of the slowest time constant, at least [`MIN_SETTLE_TICKS`];
    /// `u32::MAX` (never) while the linearisation is not stable.
    settle_ticks: u32,
    /// Machine losses at the last refreshed temperature [m^3/s].
    losses: f32,
    /// The last Fluid job moved the twin's oil by its whole slew limit
    /// ([`TWIN_SLEW`]): the twin is still on its way to the filtered
    /// temperature, and the next job is the Fluid job again.
    slewing: bool,
}

/// The temperature-only jobs, one per tick in turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Job {
    /// Oil properties (one Walther evaluation) for the twin and the flows:
    /// the "fluid properties at the sensor rate", here every four
    /// non-telemetry ticks (4 ms at the defaults), five times the
    /// MAX31865's 50 Hz.
    Fluid,
    /// Closed-form equilibrium and `dx/dt` (Eqs. 5, 31), then the twin's
    /// consistency check against it once the temperature is steady.
    Equilibrium,
    /// Routh-Hurwitz stability of the linearisation at the equilibrium, and
    /// the decay rate of its slowest mode (the settling window).
    Stability,
    /// The machine's losses (compensation error).
    Losses,
}

impl Job {
    const ALL: [Job; 4] = [Job::Fluid, Job::Equilibrium, Job::Stability, Job::Losses];

    fn next(self) -> Job {
        match self {
            Job::Fluid => Job::Equilibrium,
            Job::Equilibrium => Job::Stability,
            Job::Stability => Job::Losses,
            Job::Losses => Job::Fluid,
        }
    }

    /// This job's bit in `Estimator::failed_jobs`.
    fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

impl Estimator {
    /// An estimator at rest in the equilibrium of `initial` [C], which must
    /// be a temperature the oil model accepts. Eq. (32) is checked once here
    /// over the validated range (201 samples; a range the oil model refuses
    /// in part is not an error, it raises `NOT_UNIQUE`).
    ///
    /// # Errors
    ///
    /// * the twin cannot be built at `initial` ([`Twin::new`]: the oil
    ///   model refuses the temperature, or the parameters' model);
    /// * the oil model refuses `initial` or the machine's reference
    ///   temperature ([`crate::fluid::Oil::state`]);
    /// * a temperature-only job fails at `initial` (the equilibrium, its
    ///   sensitivity or the machine's losses not finite).
    pub fn new(params: &Params<f32>, config: EstimatorConfig, initial: f32) -> Result<Self, ModelError> {
        let (lo, hi) = config.valid;
        let monotonic = asymptotic::monotonicity(params, lo, hi, 201)
            .map(|m| m.monotonic)
            .unwrap_or(false);
        let twin = Twin::new(params, config.twin, initial)?;
        let machine_mu_ref = match &params.machine {
            Some(m) => Some(params.oil.state(m.leakage_temperature)?.dynamic_viscosity),
            None => None,
        };
        let point = params.oil.point(initial)?;
        let mut statics = Statics {
            point,
            capillary_conductance: 0.0,
            orifice_factor: 0.0,
            window_factor: 0.0,
            x_equilibrium: f32::NAN,
            dx_dt: f32::NAN,
            y_equilibrium: [0.0; 4],
            stable: true,
            settle_per_second: SETTLE_TIME_CONSTANTS / config.tick(),
            slowest_rate: 0.0,
            slowest_time_constant: f32::INFINITY,
            settle_ticks: u32::MAX,
            losses: f32::NAN,
            slewing: false,
        };
        let mut twin = twin;
        for job in Job::ALL {
            Self::run_job(job, params, &mut twin, machine_mu_ref, initial, &mut statics)?;
        }
        Ok(Estimator {
            params: *params,
            config,
            twin,
            filtered: initial,
            held: initial,
            spikes: 0,
            candidate: initial,
            failed_jobs: 0,
            since_sample: 0,
            tick: 0,
            monotonic,
            machine_mu_ref,
            statics,
            next_job: Job::Fluid,
            last: None,
            steady_anchor: initial,
            steady_ticks: 0,
            reseats: 0,
            checks: 0,
            reseated: false,
            publish: false,
            telemetry_pending: false,
        })
    }

    /// The time constant of the twin's slowest mode at the last Stability
    /// job [s]: `1 / sigma`, with `sigma` a lower bound (within 25 %) of the
    /// smallest decay rate `-Re(lambda)` of the linearisation at the
    /// equilibrium. Infinite while the linearisation is not stable.
    pub fn slowest_time_constant(&self) -> f32 {
        self.statics.slowest_time_constant
    }

    /// Consistency checks run since start (saturating): each compared the
    /// settled twin with the closed form, and re-seated it or not.
    pub fn consistency_checks(&self) -> u32 {
        self.checks
    }

    /// Steady ticks the consistency check waits for at the last Stability
    /// job (`u32::MAX`: it does not run, the linearisation is not stable).
    pub fn settle_ticks(&self) -> u32 {
        self.statics.settle_ticks
    }

    /// The settings.
    pub fn config(&self) -> &EstimatorConfig {
        &self.config
    }

    /// The twin.
    pub fn twin(&self) -> &Twin<f32, f32> {
        &self.twin
    }

    /// The twin, mutable: to inject a fault (a wrong state, with
    /// [`Twin::set_state`]) and watch the consistency check undo it.
    pub fn twin_mut(&mut self) -> &mut Twin<f32, f32> {
        &mut self.twin
    }

    /// One tick with this tick's sample (see the module docs).
    pub fn tick(&mut self, sample: Result<Option<f32>, SensorFault>) -> StateEstimate {
        let mut flags = Flags::empty();
        if !self.monotonic {
            flags.insert(Flags::NOT_UNIQUE);
        }
        self.tick = self.tick.wrapping_add(1);
        self.since_sample = self.since_sample.saturating_add(1);
        let (oil_lo, oil_hi) = self.config.oil;
        match sample {
            Ok(Some(t)) if t.is_finite() && t >= oil_lo && t <= oil_hi => {
                let threshold = self.config.spike_threshold;
                if libm::fabsf(t - self.filtered) <= threshold {
                    self.accept(t);
                } else {
                    // Out of band: a spike, unless it is the
                    // (spike_limit + 1)-th consecutive sample agreeing with
                    // the previous out-of-band one: then a real step.
                    let agrees = self.spikes > 0 && libm::fabsf(t - self.candidate) <= threshold;
                    self.spikes = if agrees { self.spikes.saturating_add(1) } else { 1 };
                    self.candidate = t;
                    if self.spikes > self.config.spike_limit {
                        self.filtered = t;
                        self.accept(t);
                    } else {
                        flags.insert(Flags::SPIKE);
                    }
                }
            }
            Ok(Some(_)) | Err(_) => flags.insert(Flags::SENSOR_FAULT),
            Ok(None) => {}
        }
        if self.since_sample > self.config.stale_after {
            flags.insert(Flags::DEGRADED);
        }
        self.filtered += self.config.filter_gain * (self.held - self.filtered);
        let t = self.filtered;
        let (lo, hi) = self.config.valid;
        if !(t >= lo && t <= hi) {
            flags.insert(Flags::OUT_OF_RANGE);
        }
        match self.update(t, &mut flags) {
            Ok(e) => {
                self.last = Some(e);
                e
            }
            Err(_) => {
                // The model cannot evaluate this temperature: keep the last
                // estimate's physics, flagged.
                flags.insert(Flags::DEGRADED);
                let mut e = self.last.unwrap_or(StateEstimate {
                    tick: 0,
                    temperature: t,
                    x: f32::NAN,
                    v: f32::NAN,
                    p_a: f32::NAN,
                    p_b: f32::NAN,
                    q_a: f32::NAN,
                    q_b: f32::NAN,
                    q_throt: f32::NAN,
                    q_total: f32::NAN,
                    compensation_error: f32::NAN,
                    x_equilibrium: f32::NAN,
                    dx_dt: f32::NAN,
                    reseats: self.reseats,
                    flags,
                });
                e.tick = self.tick;
                e.temperature = t;
                e.reseats = self.reseats;
                e.flags = flags;
                e
            }
        }
    }

    /// Runs one temperature-only job at the filtered temperature `t` [C].
    fn run_job(
        job: Job,
        p: &Params<f32>,
        twin: &mut Twin<f32, f32>,
        machine_mu_ref: Option<f32>,
        t: f32,
        statics: &mut Statics,
    ) -> Result<(), ModelError> {
        match job {
            Job::Fluid => {
                // The twin's oil moves towards `t` by at most what changes
                // its capillary conductance (~ 1 / mu) by TWIN_SLEW: a step
                // the spike filter takes as real reaches the twin as a
                // fast ramp, never as an abrupt change (which the twin
                // would grade, at several substeps' cost: `Twin::tick`).
                let prev = &statics.point;
                let now = prev.state.temperature;
                let dln_mu =
                    libm::fabsf(prev.viscosity.d1 / prev.viscosity.value + prev.density.d1 / prev.density.value);
                let max_step = if dln_mu > 0.0 {
                    TWIN_SLEW / dln_mu
                } else {
                    f32::INFINITY
                };
                // max/min, not `f32::clamp`: its assertion formats f32 with
                // core::fmt, 17 KiB of flash on the controller.
                let step = (t - now).max(-max_step).min(max_step);
                let point = p.oil.point(now + step)?;
                statics.slewing = step != t - now;
                twin.set_fluid(&point.state)?;
                let inv_sqrt_rho = 1.0 / Real::sqrt(point.state.density);
                statics.point = point;
                statics.capillary_conductance = 1.0 / p.capillary.resistance(point.state.dynamic_viscosity);
                statics.orifice_factor =
                    p.orifice.discharge_coefficient * p.orifice.area() * core::f32::consts::SQRT_2 * inv_sqrt_rho;
                statics.window_factor = p.slot.window_factor(p.pressure_drop) * inv_sqrt_rho;
            }
            Job::Equilibrium => {
                let point = &statics.point;
                let eq = equilibrium_for(p, point.state, a_parameter(p, &point.state))?;
                statics.dx_dt = asymptotic::sensitivity_at(p, point)?.dx_dt;
                statics.x_equilibrium = eq.x;
                statics.y_equilibrium = twin.model().equilibrium_state(&eq);
            }
            Job::Stability => {
                let sys = Fsi {
                    coefficients: twin.coefficients(),
                    contact: Contact::Free,
                };
                let poly = characteristic_polynomial(&sys.jacobian(&statics.y_equilibrium));
                statics.stable = quartic_hurwitz(&poly);
                let sigma = if statics.stable {
                    slowest_decay_rate(&poly, statics.slowest_rate)
                } else {
                    0.0
                };
                statics.slowest_rate = sigma;
                if sigma > 0.0 {
                    statics.slowest_time_constant = twin.model().scales.time / sigma;
                    let ticks = statics.slowest_time_constant * statics.settle_per_second;
                    // Saturating conversion; NaN is impossible here (sigma > 0).
                    statics.settle_ticks = if ticks < u32::MAX as f32 {
                        (ticks as u32).saturating_add(1).max(MIN_SETTLE_TICKS)
                    } else {
                        u32::MAX
                    };
                } else {
                    statics.slowest_time_constant = f32::INFINITY;
                    statics.settle_ticks = u32::MAX;
                }
            }
            Job::Losses => {
                statics.losses = match (&p.machine, machine_mu_ref) {
                    (Some(m), Some(mu_ref)) => {
                        compensation::losses_for(m, mu_ref, statics.point.state.dynamic_viscosity)?
                    }
                    _ => f32::NAN,
                };
            }
        }
        Ok(())
    }

    fn update(&mut self, t: f32, flags: &mut Flags) -> Result<StateEstimate, ModelError> {
        // The twin first: its events (an impact, a release) cost it a few
        // steps more, and the tick then runs neither a job nor telemetry
        // (both wait for the next tick), so that the worst tick stays the
        // twin's plain tick plus the larger of one job or the telemetry.
        let p = &self.params;
        let eventful = match self.twin.tick() {
            Ok(report) => report.eventful(),
            Err(_) => {
                // A failed step (never seen with valid parameters): restart
                // from the equilibrium rather than continue from garbage.
                self.twin = Twin::new(p, self.twin.config(), self.statics.point.state.temperature)?;
                flags.insert(Flags::DEGRADED);
                true
            }
        };
        let due = self.telemetry_pending
            || (self.config.telemetry_every > 0 && self.tick.is_multiple_of(self.config.telemetry_every));
        self.publish = due && !eventful;
        self.telemetry_pending = due && eventful;
        if !due && !eventful {
            // The steady stretch, counted in ticks that run a job (a
            // telemetry tick only publishes): the window in time is at
            // least as long, and the telemetry tick, the costliest, is
            // spared. A drift out of the band shows at the next job tick.
            // The twin's temperature (it follows the filter at most at
            // its slew rate): steady once it has arrived and stays.
            let tw = self.statics.point.state.temperature;
            if libm::fabsf(tw - self.steady_anchor) <= STEADY_BAND {
                self.steady_ticks = self.steady_ticks.saturating_add(1);
            } else {
                self.steady_anchor = tw;
                self.steady_ticks = 0;
            }
            // While the twin's oil is on its way to a new temperature, every
            // job tick moves it on (the other jobs' results wait: the
            // temperature they belong to is moving).
            let job = if self.statics.slewing {
                Job::Fluid
            } else {
                let job = self.next_job;
                self.next_job = job.next();
                job
            };
            // A temperature the model refuses leaves the job's previous
            // results in force; the estimate goes on, flagged, until the
            // job succeeds again.
            match Self::run_job(
                job,
                &self.params,
                &mut self.twin,
                self.machine_mu_ref,
                t,
                &mut self.statics,
            ) {
                Ok(()) => {
                    self.failed_jobs &= !job.bit();
                    if job == Job::Equilibrium {
                        self.check_twin();
                    }
                }
                Err(_) => self.failed_jobs |= job.bit(),
            }
        }
        if self.failed_jobs != 0 {
            flags.insert(Flags::DEGRADED);
        }
        if self.reseated {
            flags.insert(Flags::TWIN_RESEATED);
        }
        let p = &self.params;
        if !self.statics.stable {
            flags.insert(Flags::UNSTABLE);
        }
        let s = self.twin.state();
        let [xi, ..] = self.twin.raw_state();
        if xi <= 0.0 || xi >= 1.0 {
            flags.insert(Flags::AT_STOP);
        }
        let st = &self.statics;
        let q_a = (s.p_a - p.outlet_pressure) * st.capillary_conductance;
        let drop_b = s.p_b - p.outlet_pressure;
        let q_b = st.orifice_factor * libm::copysignf(Real::sqrt(libm::fabsf(drop_b)), drop_b);
        let q_throt = st.window_factor * Real::max(s.x, 0.0);
        let q_total = q_a + q_b + q_throt;
        let compensation_error = match &p.machine {
            Some(m) => q_total - (m.working_flow + st.losses),
            None => f32::NAN,
        };
        Ok(StateEstimate {
            tick: self.tick,
            temperature: t,
            x: s.x,
            v: s.v,
            p_a: s.p_a,
            p_b: s.p_b,
            q_a,
            q_b,
            q_throt,
            q_total,
            compensation_error,
            x_equilibrium: st.x_equilibrium,
            dx_dt: st.dx_dt,
            reseats: self.reseats,
            flags: *flags,
        })
    }

    /// The consistency check, right after a successful Equilibrium job:
    /// once the temperature has been steady for the settling window, the
    /// twin must sit within [`X_TOLERANCE`] of the stroke and
    /// [`P_TOLERANCE`] of `dp` of the closed-form equilibrium (clamped to
    /// the stops, in the twin's model units, where both are fractions
    /// already). Otherwise it is put there at rest, counted, flagged, and
    /// given a new window before the next check. Skipped while any job's
    /// results are stale (the equilibrium may not be the twin's) or the
    /// linearisation is unstable (no attracting equilibrium to agree with).
    fn check_twin(&mut self) {
        let st = &self.statics;
        if self.failed_jobs != 0 || !st.stable || self.steady_ticks < st.settle_ticks {
            return;
        }
        self.checks = self.checks.saturating_add(1);
        let [xi, _, pi_a, pi_b] = self.twin.raw_state();
        let [xi_eq, _, pi_a_eq, pi_b_eq] = st.y_equilibrium;
        // Written so that a NaN state fails the check too.
        let agrees = libm::fabsf(xi - xi_eq) <= X_TOLERANCE
            && libm::fabsf(pi_a - pi_a_eq) <= P_TOLERANCE
            && libm::fabsf(pi_b - pi_b_eq) <= P_TOLERANCE;
        if agrees {
            self.reseated = false;
        } else {
            let at_rest = self.twin.model().scales.to_si(&st.y_equilibrium);
            self.twin.set_state(&at_rest);
            self.reseats = self.reseats.saturating_add(1);
            self.reseated = true;
            self.steady_ticks = 0;
        }
    }

    /// Takes `t` [C] as the filter's input.
    fn accept(&mut self, t: f32) {
        self.spikes = 0;
        self.held = t;
        self.since_sample = 0;
    }

    /// `true` when this tick's estimate should be published: every
    /// `telemetry_every` ticks, a tick later when the twin had an event on
    /// the scheduled one.
    pub fn telemetry_due(&self) -> bool {
        self.publish
    }
}

/// The Routh-Hurwitz conditions of `s^4 + a3 s^3 + a2 s^2 + a1 s + a0`
/// (coefficients `[a3, a2, a1, a0]`, as [`characteristic_polynomial`]
/// returns them): `true` when every root has a negative real part. The
/// same verdict as `dynamics::linear::hurwitz_stable`, from coefficients
/// already at hand.
pub fn quartic_hurwitz(a: &[f32; 4]) -> bool {
    let [a3, a2, a1, a0] = *a;
    a3 > 0.0 && a2 > 0.0 && a1 > 0.0 && a0 > 0.0 && a3 * a2 > a1 && a3 * a2 * a1 > a1 * a1 + a3 * a3 * a0
}

/// Coefficients of `p(s - sigma)` for the monic quartic `p` with
/// coefficients `[a3, a2, a1, a0]`: the characteristic polynomial of
/// `M + sigma I` when `p` is `M`'s. Taylor shift by four passes of
/// synthetic division at `-sigma` (ten multiply-adds).
fn shifted(a: &[f32; 4], sigma: f32) -> [f32; 4] {
    let r = -sigma;
    let [mut c3, mut c2, mut c1, mut c0] = *a;
    c3 += r;
    c2 += r * c3;
    c1 += r * c2;
    c0 += r * c1;
    c3 += r;
    c2 += r * c3;
    c1 += r * c2;
    c3 += r;
    c2 += r * c3;
    c3 += r;
    [c3, c2, c1, c0]
}

/// A lower bound, within 25 %, of the smallest decay rate
/// `min(-Re(lambda))` over the roots of the monic quartic `[a3, a2, a1, a0]`
/// (in the polynomial's time unit), or 0 when the polynomial is not Hurwitz
/// or the rate is below `a3 / 4 * 2^-32`.
///
/// `M + sigma I` is Hurwitz exactly when `sigma` is below that rate, and the
/// rate is at most the mean `a3 / 4`: a binary search over `sigma =
/// a3 / 4 * 2^-k` (`k` = 0..32, five Routh-Hurwitz tests) brackets it
/// within a factor two, two bisections within 25 %; the stable end is
/// returned. Eight tests of ~30 flops: no eigenvalue iteration, bounded
/// cost, and exact for complex modes too (underdamped designs).
///
/// `hint` (a previous result, or 0) is tried first: when `hint` is still
/// below the rate and `1.25 hint` is not, `hint` is the answer (two tests,
/// the usual case at a steady temperature); otherwise the search runs.
pub fn slowest_decay_rate(a: &[f32; 4], hint: f32) -> f32 {
    let stable = |sigma: f32| quartic_hurwitz(&shifted(a, sigma));
    if hint > 0.0 && stable(hint) && !stable(1.25 * hint) {
        return hint;
    }
    let top = 0.25 * a[0];
    // 2^-k, exactly, for k in 0..=32.
    let scaled = |k: u32| top * f32::from_bits((127 - k) << 23);
    if !(top > 0.0) || !stable(scaled(32)) {
        return 0.0;
    }
    // Invariant: sigma(lo) is not below the rate (or lo = 0, the mean),
    // sigma(hi) is.
    let (mut lo, mut hi) = (0u32, 32u32);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if stable(scaled(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (mut below, mut above) = (scaled(hi), scaled(lo));
    for _ in 0..2 {
        let mid = 0.5 * (below + above);
        if stable(mid) {
            below = mid;
        } else {
            above = mid;
        }
    }
    below
}
