//! The state estimator the firmware runs every tick: probe reading ->
//! oil-temperature observer -> fluid properties -> FSI twin step ->
//! closed-form equilibrium, sensitivity, stability and uncertainty ->
//! [`StateEstimate`].
//!
//! Per tick, in this order:
//! 1. the oil-temperature observer predicts to this tick ([`OilObserver`]:
//!    a Kalman filter of the oil temperature, its rate and the probe's
//!    lagging temperature);
//! 2. the twin advances one tick (its coefficients from the last Fluid
//!    job), driven by the estimated oil temperature, not the reading;
//! 3. the latest reading (if any) is checked: not finite or outside the
//!    oil's range is a fault; further than `spike_threshold` from the
//!    reading the observer expects is a spike and rejected, unless it is
//!    the `spike_limit + 1`-th consecutive out-of-band reading agreeing
//!    (within the threshold) with the one before: then it is a real step
//!    and the observer restarts at it; else the observer updates with it.
//!    Where the twin is fixed point (no FPU) a reading that arrives on a
//!    tick the twin spent on an event (step 2) is held back to the first
//!    tick without one, at most [`MAX_DEFERRED`] ticks; a newer reading
//!    supersedes it;
//! 4. one temperature-only job runs, in turn: the oil's properties (one
//!    Walther evaluation, handed to the twin and the flow laws) at the
//!    estimated temperature, reached at a bounded slew ([`TWIN_SLEW`]: the
//!    twin never sees an abrupt change, and while it is on its way every
//!    job is this one); the closed-form equilibrium with `dx/dt` (Eq. 31);
//!    the Routh-Hurwitz stability of the linearisation at that equilibrium;
//!    the machine's losses; the uncertainty of the estimate
//!    ([`Uncertainty`]: the observer's variance, the probe's tolerance and
//!    the device's parameter uncertainties, [`crate::uncertainty`]). None
//!    runs on a telemetry tick (at most every second tick), nor on a tick
//!    where the twin had an event (an impact, a release: a few steps
//!    more), which also moves a due telemetry record to the next tick.
//!    Each result is thus refreshed every five job ticks (5 ms at the
//!    default 1 kHz and 2 Hz telemetry), while the oil's temperature
//!    changes over seconds. A job the model refuses keeps its previous
//!    results and flags the estimate `DEGRADED` until it succeeds again.
//!    Where the twin is fixed point (the cores without an FPU, whose `f32`
//!    is software) the Fluid, Equilibrium, Stability and Uncertainty jobs
//!    run in slices on consecutive job ticks ([`Plant::run_job`]), so that
//!    no tick carries a whole job, and a tick that took a reading's update
//!    runs no job;
//! 5. flows and the compensation error follow from the twin's state.
//!
//! The pieces, one concept per file: [`EstimatorConfig`] and its
//! [`TemperatureRange`]s (`config`); the oil-temperature observer
//! ([`OilObserver`], [`ObserverDesign`], `observer`) and its spike gate
//! ([`SpikeGate`], `spike`); the plant observer of steps 3-5, driven by a
//! temperature rather than samples (the twin, the rotation of the jobs,
//! the consistency check, the publication: [`Plant`], `plant`, which the
//! FMU drives with its inputs); the jobs of step 4 and the results they
//! keep (`jobs`); the stability test and decay-rate bound of the Stability job
//! ([`quartic_hurwitz`], [`slowest_decay_rate`], `stability`); the flags
//! ([`Flags`], `flags`); the estimate ([`StateEstimate`], `estimate`) and
//! its telemetry record, declared once as a table ([`telemetry`]). The
//! flows of step 5 are the throttle laws'
//! ([`FlowLaws`](crate::throttle::FlowLaws)). This module runs the tick:
//! the sequence above, when a job runs and when an estimate is published.
//!
//! A consistency check catches a twin that settled where the physics does
//! not: once the twin's temperature has stayed within [`STEADY_BAND`] for
//! [`SETTLE_TIME_CONSTANTS`] of the twin's slowest time constants (the
//! decay rate of the slowest mode of the linearisation, found by the
//! Stability job; for the travel onto the closed stop up to
//! [`STOP_SETTLE_TIME_CONSTANTS`] within [`MAX_STOP_SETTLE`]), every Equilibrium job compares the twin's state with the
//! closed-form equilibrium it just computed (clamped to the stops). A twin
//! further than [`X_TOLERANCE`] of the stroke or [`P_TOLERANCE`] of `dp`
//! away is re-seated on the equilibrium, counted
//! ([`StateEstimate::reseats`]) and flagged [`Flags::TWIN_RESEATED`]. The
//! thresholds and their reasons are in the project's `docs/firmware.md`.
//!
//! The cost of a tick is bounded by the observer's prediction, the twin's
//! step, the fluid properties and the larger of one job or the telemetry
//! packing: what the firmware's budget measures. Nothing here allocates or
//! panics; every failure becomes a flag.

mod config;
mod deadline;
mod estimate;
mod flags;
pub mod health;
mod jobs;
mod observer;
mod plant;
mod spike;
mod stability;
pub mod telemetry;

pub use config::{ConfigError, EstimatorConfig, TemperatureRange, observer_settings, reading_period};
pub use deadline::MAX_CATCH_UP;
pub use estimate::StateEstimate;
pub use flags::Flags;
pub use observer::{
    CUSUM_DRIFT, CUSUM_THRESHOLD, DesignError, HOLD_RATIO, ModeGains, NO_LAG, ObserverDesign, ObserverSettings,
    OilObserver,
};
pub use plant::Plant;
pub use spike::{SpikeGate, SpikeSettings, Verdict};
pub use stability::{quartic_hurwitz, slowest_decay_rate};

use crate::dynamics::Twin;
use crate::error::ModelError;
use crate::monitor::{HealthEstimate, Monitor};
#[cfg(feature = "monitor")]
use crate::monitor::{MonitorError, MonitorSettings, PlantView, ProbeSample};
use crate::params::Params;
use crate::scalar::Real;
use crate::sensor::SensorFault;
use crate::uncertainty::{Uncertainty, UncertaintyTable};
use core::borrow::Borrow;

/// Largest relative change of the twin's capillary conductance (~ 1 / mu)
/// per Fluid job: below the twin's `ABRUPT_CHANGE` (1 %), so that the twin
/// never grades a tick in the estimator (`Twin::tick`: a graded tick costs
/// several substeps). While the twin's oil is on its way, every job tick is
/// a Fluid job: the paper preset's oil (2.6 %/K of viscosity at 80 C,
/// 11 %/K at 0 C) then follows a step at 70 C/s (0 C) to 300 C/s (80 C).
pub const TWIN_SLEW: f32 = 0.008;

/// Band \[C\] the filtered temperature must stay within to count as steady
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

/// As [`SETTLE_TIME_CONSTANTS`], when the closed-form equilibrium holds the
/// plunger on the closed stop, within [`MAX_STOP_SETTLE`]. The travel onto
/// it after an abrupt cold step is no linear decay: over 1,000 seeded
/// designs and 7 abrupt steps each it takes up to 110 slowest time
/// constants (0.21 s) to come within 1e-3 of the stroke, 99 % of steps
/// within 20 (the open stop: at most 6.9; `cargo run --release -p
/// host-tests --example settling -- 1000`). With 10 alone the check
/// re-seated 3 of 5,456 correct twins still on their way.
pub const STOP_SETTLE_TIME_CONSTANTS: f32 = 150.0;

/// Longest settling window \[s\] [`STOP_SETTLE_TIME_CONSTANTS`] may give: the
/// slowest time constant linearised at a closed-stop state can be seconds
/// (a mode the stop holds still), and a window of minutes would leave a
/// wrong state unchecked that long. [`SETTLE_TIME_CONSTANTS`] of it still
/// apply when longer.
pub const MAX_STOP_SETTLE: f32 = 1.0;

/// Event ticks in a row after which the job and the telemetry run on an
/// event tick too ([`Estimator::tick`]: the twin's oil must keep moving).
pub const MAX_DEFERRED: u32 = 3;

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

/// `x` inside `[lo, hi]` (`lo <= hi`), NaN taken to `lo` (as `x.max(lo).min(hi)`),
/// inline: `f32::max` and `min` are calls to `fmaxf` and `fminf` on the
/// Cortex-M4F (its FPU has no `vmaxnm`), about 11 instructions each, on
/// every tick; `f32::clamp`'s assertion formats f32 with `core::fmt`.
#[inline(always)]
pub(crate) fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if !(x >= lo) {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// The estimator, its twin integrating in `T` (`f32` where there is an
/// FPU, [`Fixed`](crate::scalar::Fixed) where there is none); everything
/// else (observer, jobs, flows) is `f32`.
#[derive(Clone, Copy, Debug)]
pub struct Estimator<T = f32, U = UncertaintyTable, O = ObserverDesign> {
    config: EstimatorConfig<U, O>,
    /// The twin, its jobs and the consistency check (steps 3-5 of the
    /// tick), driven by the observer's temperature.
    plant: Plant<T>,
    /// The oil-temperature observer (steps 1-2 of the tick).
    observer: OilObserver,
    /// Ticks since the last accepted sample.
    since_sample: u32,
    tick: u32,
    /// This tick's estimate is to be published ([`Estimator::telemetry_due`]).
    publish: bool,
    /// A publication was due on a tick the twin spent on an event: the
    /// next tick publishes.
    telemetry_pending: bool,
    /// Tick deadlines missed so far (saturating; [`Estimator::tick_after`]).
    deadline_misses: u32,
    /// Ticks of real time the twin did not advance through (beyond
    /// [`MAX_CATCH_UP`] per late tick; saturating).
    lost_ticks: u32,
    /// This tick started late (raises `DEADLINE_MISSED`).
    late: bool,
    /// Consecutive ticks the twin had an event on (saturating).
    deferred: u32,
    /// The last tick gave up its job to a reading's update (FPU-less
    /// cores): the next one runs its job whatever it takes, so that a probe
    /// read every tick cannot starve the jobs.
    yielded: bool,
    /// A reading held back from an event tick (FPU-less cores) and the
    /// tick it was taken on: the next tick offers it.
    held_reading: Option<(f32, u32)>,
    /// The condition monitor, with a second sensor ([`Estimator::with_monitor`]).
    /// Only with the `monitor` feature: an image without a second sensor
    /// carries none, so that its RAM and its ticks do not move with the
    /// monitor's state (a field the size of the monitor's placed the
    /// tick's hot fields at offsets the loads' immediates could not reach).
    #[cfg(feature = "monitor")]
    monitor: Option<Monitor>,
    /// The second sensor's reading not yet given to the monitor (it runs
    /// in a job's place: [`Estimator::offer_second`]).
    #[cfg(feature = "monitor")]
    second: Option<Result<f32, SensorFault>>,
    /// The monitor's estimate at its last reading.
    health: HealthEstimate,
    /// Flags of the monitor's last reading, for the next estimate only.
    #[cfg(feature = "monitor")]
    health_flags: Flags,
    /// The monitor's readings' own flags (`PER_READING`) since the last
    /// published estimate, for the next (kept through a reset).
    #[cfg(feature = "monitor")]
    unreported: Flags,
    /// The probe's last accepted reading and its tick, until the monitor
    /// takes it.
    #[cfg(feature = "monitor")]
    probe_sample: Option<(f32, u32)>,
    /// The tick of the monitor's last reading.
    #[cfg(feature = "monitor")]
    monitor_tick: u32,
}

impl<U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy> Estimator<f32, U, O> {
    /// An estimator with an `f32` twin at rest in the equilibrium of
    /// `initial` \[C\]: [`Estimator::with_scalar`] for `f32`.
    ///
    /// # Errors
    ///
    /// As [`Estimator::with_scalar`].
    pub fn new(params: &Params<f32>, config: EstimatorConfig<U, O>, initial: f32) -> Result<Self, ModelError> {
        Self::with_scalar(params, config, initial)
    }
}

impl<T: Real, U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy> Estimator<T, U, O> {
    /// An estimator at rest in the equilibrium of `initial` \[C\], which must
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
    pub fn with_scalar(params: &Params<f32>, config: EstimatorConfig<U, O>, initial: f32) -> Result<Self, ModelError> {
        let observer = OilObserver::new(initial);
        let variance = observer.variance(config.observer_design());
        let plant = Plant::new(params, &config, initial, variance)?;
        Ok(Estimator {
            config,
            plant,
            observer,
            since_sample: 0,
            tick: 0,
            publish: false,
            telemetry_pending: false,
            deadline_misses: 0,
            lost_ticks: 0,
            late: false,
            deferred: 0,
            yielded: false,
            held_reading: None,
            #[cfg(feature = "monitor")]
            monitor: None,
            #[cfg(feature = "monitor")]
            second: None,
            health: HealthEstimate::NONE,
            #[cfg(feature = "monitor")]
            health_flags: Flags::empty(),
            #[cfg(feature = "monitor")]
            unreported: Flags::empty(),
            #[cfg(feature = "monitor")]
            probe_sample: None,
            #[cfg(feature = "monitor")]
            monitor_tick: 0,
        })
    }

    /// This estimator with a condition monitor of a second sensor
    /// (`crate::monitor`): its readings, given by
    /// [`Estimator::offer_second`], correct nothing of the temperature
    /// estimate; they estimate the device's health parameters and raise the
    /// monitor's flags.
    ///
    /// # Errors
    ///
    /// As [`Monitor::new`]: a setting not finite and positive, named.
    #[cfg(feature = "monitor")]
    pub fn with_monitor(mut self, settings: MonitorSettings) -> Result<Self, MonitorError> {
        self.monitor = Some(Monitor::new(self.plant.params(), settings)?);
        Ok(self)
    }

    /// The condition monitor, if one is fitted.
    pub fn monitor(&self) -> Option<&Monitor> {
        #[cfg(feature = "monitor")]
        return self.monitor.as_ref();
        #[cfg(not(feature = "monitor"))]
        None
    }

    /// Clears the monitor's latched faults and restarts its health
    /// parameters at their priors (after the device's maintenance or an
    /// inspection that found it healthy); nothing without a monitor.
    #[cfg(feature = "monitor")]
    pub fn reset_monitor(&mut self) {
        if let Some(m) = self.monitor.as_mut() {
            m.reset(self.plant.params());
            self.health = HealthEstimate::NONE;
            self.health_flags = Flags::empty();
        }
    }

    /// A reading of the second sensor \[Pa or m\] (`Err`: refused by its
    /// own checks). The monitor takes it on the next tick that would run a
    /// job (in the job's place: the worst tick stays the twin's plus one
    /// job, the monitor or the telemetry); a newer reading replaces one not
    /// yet taken. Without a monitor it is ignored.
    #[cfg(feature = "monitor")]
    pub fn offer_second(&mut self, reading: Result<f32, SensorFault>) {
        if self.monitor.is_some() {
            self.second = Some(reading);
        }
    }

    /// The monitor's next stage in a job's place: the pending reading's
    /// next stage ([`Monitor::advance`]; its health estimate published when
    /// done), else a waiting reading of the second sensor begun
    /// ([`Monitor::begin`]); `false` when there is neither. A reading's
    /// stages run on consecutive job ticks, so that no tick carries the
    /// whole update.
    #[cfg(feature = "monitor")]
    fn take_second(&mut self) -> bool {
        let Some(monitor) = self.monitor.as_mut() else {
            return false;
        };
        if monitor.pending() {
            if let Some(health) = monitor.advance() {
                self.health = health;
                self.health_flags = health.flags;
                self.unreported
                    .insert(Flags(health.flags.0 & crate::monitor::PER_READING.0));
            }
            return true;
        }
        let Some(reading) = self.second.take() else {
            return false;
        };
        let s = self.plant.twin().state();
        let tick = self.config.observer_design().tick;
        let view = PlantView {
            oil: *self.plant.oil(),
            x: s.x,
            p_a: s.p_a,
            p_b: s.p_b,
            dt: self.tick.wrapping_sub(self.monitor_tick) as f32 * tick,
            probe: self.probe_sample.take().map(|(value, at)| ProbeSample {
                value,
                age: self.tick.wrapping_sub(at) as f32 * tick,
            }),
        };
        self.monitor_tick = self.tick;
        monitor.begin(self.plant.params(), &view, reading);
        true
    }

    /// The monitor's estimate at its last reading ([`HealthEstimate::NONE`]
    /// without one).
    pub fn health(&self) -> &HealthEstimate {
        &self.health
    }

    /// The time constant of the twin's slowest mode at the last Stability
    /// job \[s\] ([`Plant::slowest_time_constant`]).
    pub fn slowest_time_constant(&self) -> f32 {
        self.plant.slowest_time_constant()
    }

    /// Consistency checks run since start (saturating): each compared the
    /// settled twin with the closed form, and re-seated it or not.
    pub fn consistency_checks(&self) -> u32 {
        self.plant.consistency_checks()
    }

    /// Steady ticks the consistency check waits for at the last Stability
    /// job (`u32::MAX`: it does not run, the linearisation is not stable).
    pub fn settle_ticks(&self) -> u32 {
        self.plant.settle_ticks()
    }

    /// The oil-temperature observer.
    pub fn observer(&self) -> &OilObserver {
        &self.observer
    }

    /// The uncertainty of the estimate now, computed at once (the tick
    /// refreshes it in the job rotation, [`StateEstimate::uncertainty`]).
    pub fn uncertainty_now(&self) -> Uncertainty {
        let t = self.observer.oil();
        self.config
            .table()
            .at(t, self.observer.variance(self.config.observer_design()))
    }

    /// The settings.
    pub fn config(&self) -> &EstimatorConfig<U, O> {
        &self.config
    }

    /// The twin.
    pub fn twin(&self) -> &Twin<f32, T> {
        self.plant.twin()
    }

    /// The twin, mutable: to inject a fault (a wrong state, with
    /// [`Twin::set_state`]) and watch the consistency check undo it.
    pub fn twin_mut(&mut self) -> &mut Twin<f32, T> {
        self.plant.twin_mut()
    }

    /// The plant observer: the twin, its jobs and the consistency check.
    pub fn plant(&self) -> &Plant<T> {
        &self.plant
    }

    /// One tick with this tick's sample (see the module docs).
    pub fn tick(&mut self, sample: Result<Option<f32>, SensorFault>) -> StateEstimate {
        let mut flags = Flags::empty();
        if core::mem::take(&mut self.late) {
            flags.insert(Flags::DEADLINE_MISSED);
        }
        self.tick = self.tick.wrapping_add(1);
        self.since_sample = self.since_sample.saturating_add(1);
        let design = self.config.observer_design();
        self.observer.predict(design);
        // The twin first (it does not depend on the observer): its events
        // (an impact, a release) cost it a step or two more, and the tick
        // then runs neither a job nor telemetry (both wait for the next
        // tick), so that the worst tick stays the twin's plain tick plus
        // the larger of one job or the telemetry.
        let event = match self.plant.advance(&mut flags) {
            Ok(event) => event,
            Err(_) => {
                // Not even a restart could be made (never seen with valid
                // parameters): the twin's last good state is published,
                // flagged, and the tick counts as eventful.
                flags.insert(Flags::DEGRADED);
                true
            }
        };
        // A plunger resting on a stop where the force is nearly zero can
        // have an event every tick (released and stopped again, within the
        // tick), while the oil that would move it on is the Fluid job's to
        // change: deferring every job to the next tick would freeze the
        // twin's oil and with it the plunger, for good. After
        // MAX_DEFERRED event ticks in a row the job (or the telemetry) runs
        // anyway: the worst tick is then an event tick plus one job.
        self.deferred = if event { self.deferred.saturating_add(1) } else { 0 };
        let eventful = event && self.deferred <= MAX_DEFERRED;
        let tick = self.tick;
        let mut reading = match sample {
            Ok(Some(t)) if t.is_finite() && self.config.oil.contains(t) => Some((t, tick)),
            Ok(Some(_)) | Err(_) => {
                flags.insert(Flags::SENSOR_FAULT);
                None
            }
            Ok(None) => None,
        };
        // Without an FPU a reading's update costs about a job's slice, and
        // on a tick the twin spent on an event it is held back until a
        // tick without one (at most MAX_DEFERRED ticks late: the probe's
        // lag is seconds). A newer reading supersedes one held back.
        if T::SATURATES {
            reading = reading.or(self.held_reading.take());
            if eventful {
                self.held_reading = reading.take();
            }
        }
        // A reading's update took this tick (without an FPU it costs about
        // a job slice: the tick then runs no job).
        let mut updated = false;
        if let Some((t, at)) = reading {
            let verdict = self.observer.offer(design, &self.config.spikes, t);
            updated = verdict == Verdict::Accepted;
            match verdict {
                Verdict::Accepted | Verdict::Step => {
                    // A reading held back (fixed point only) is as old as
                    // the tick it came on.
                    self.since_sample = if T::SATURATES { self.tick.wrapping_sub(at) } else { 0 };
                    #[cfg(feature = "monitor")]
                    if self.monitor.is_some() {
                        self.probe_sample = Some((t, at));
                    }
                    #[cfg(not(feature = "monitor"))]
                    let _ = at;
                }
                Verdict::Spike => flags.insert(Flags::SPIKE),
            }
        }
        if self.since_sample > self.config.stale_after {
            flags.insert(Flags::DEGRADED);
        }
        // The estimated oil temperature, inside the range the oil model is
        // used in (the observer may overshoot it for a moment).
        let t = clamp(self.observer.oil(), self.config.oil.min, self.config.oil.max);
        flags.insert(self.plant.flags_at(&self.config, t));
        let due = self.telemetry_pending
            || (self.config.telemetry_every > 0 && self.tick.is_multiple_of(self.config.telemetry_every));
        self.publish = due && !eventful;
        self.telemetry_pending = due && eventful;
        // Without an FPU (a fixed-point twin: the estimator's own `f32` is
        // software) a tick that took a reading's update runs no job either:
        // the update costs about what a job's slice does, and the two on
        // one tick made the worst tick.
        let busy = T::SATURATES && updated && !self.yielded;
        // Only a job tick given up to a reading counts: the next reading's
        // update then shares its tick with the job, so that readings on
        // every tick cannot starve the jobs.
        self.yielded = busy && !due && !eventful;
        if !due && !eventful && !busy {
            // A job tick (a telemetry tick only publishes: the costliest
            // tick is spared); a waiting reading of the second sensor takes
            // the job's place.
            #[cfg(feature = "monitor")]
            let taken = self.take_second();
            #[cfg(not(feature = "monitor"))]
            let taken = false;
            if !taken {
                let (observer, design) = (&self.observer, self.config.observer_design());
                self.plant.run_job(self.config.table(), t, || observer.variance(design));
            }
        }
        // A reading's own flags (`PER_READING`) are on its tick's estimate
        // and on the next published one (the telemetry's): the monitor runs
        // in a job's place, never on a telemetry tick, and a flag on its
        // tick's estimate alone never reached the telemetry.
        #[cfg(feature = "monitor")]
        {
            flags.insert(core::mem::replace(
                &mut self.health_flags,
                Flags(self.health.flags.0 & !crate::monitor::PER_READING.0),
            ));
            if self.publish {
                flags.insert(core::mem::replace(&mut self.unreported, Flags::empty()));
            }
        }
        let mut e = self.plant.estimate(t, flags);
        #[cfg(feature = "monitor")]
        {
            e.health = self.health;
        }
        e.tick = self.tick;
        e.t_probe = self.observer.last_reading();
        e.deadline_misses = self.deadline_misses;
        e.lost_ticks = self.lost_ticks;
        e
    }

    /// `true` when this tick's estimate should be published: every
    /// `telemetry_every` ticks, a tick later when the twin had an event on
    /// the scheduled one.
    pub fn telemetry_due(&self) -> bool {
        self.publish
    }
}

#[cfg(test)]
mod tests {
    use super::clamp;

    #[test]
    fn clamp_is_max_then_min_without_the_calls() {
        for x in [f32::NAN, f32::NEG_INFINITY, -3.0, -1.0, 0.5, 2.0, 7.0, f32::INFINITY] {
            for (lo, hi) in [(-1.0f32, 2.0f32), (0.5, 0.5), (f32::NEG_INFINITY, f32::INFINITY)] {
                let expected = x.max(lo).min(hi);
                assert_eq!(clamp(x, lo, hi).to_bits(), expected.to_bits(), "{x} in [{lo}, {hi}]");
            }
        }
    }
}
