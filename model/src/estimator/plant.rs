//! The plant observer: the twin, the temperature-only jobs and the
//! publication of an estimate, driven by an oil temperature rather than by
//! sensor samples. The [`Estimator`](super::Estimator) drives it with its
//! observer's filtered temperature (one job per tick in rotation); a
//! co-simulation (the FMU) drives it with its input temperature and port
//! pressures (every job at once when an input changes,
//! [`Plant::refresh`]). Both publish through [`Plant::estimate`], so the
//! flags, the flows and the compensation error of an estimate are
//! computed in one place.
//!
//! Cost: [`Plant::advance`] is one twin tick ([`Twin::tick`]),
//! [`Plant::run_job`] one job (the largest, Stability, about 500
//! Cortex-M4F instructions: `docs/profile.md`; with a fixed-point twin, on
//! the cores without an FPU, one slice of a job: `jobs::Pending`),
//! [`Plant::estimate`] three
//! flow laws and a few products. Nothing allocates or panics.

use super::jobs::{self, Design, Job, Pending, Statics};
use super::{EstimatorConfig, Flags, ObserverDesign, P_TOLERANCE, STEADY_BAND, StateEstimate, X_TOLERANCE};
use crate::asymptotic;
use crate::dynamics::{DynamicState, Twin, TwinMemory};
use crate::equilibrium::equilibrium;
use crate::error::ModelError;
use crate::params::Params;
use crate::scalar::Real;
use crate::uncertainty::{Uncertainty, UncertaintyTable};
use core::borrow::Borrow;

/// The range of `operating.pressure_drop` the parameter schema calls
/// plausible \[Pa\]: an applied drop outside it is outside the model's
/// range ([`Flags::OUT_OF_RANGE`]), as a temperature outside the
/// validated one.
const DROP_RANGE: (f64, f64) = (
    compensator_params::RawCore::FIELD.pressure_drop.min,
    compensator_params::RawCore::FIELD.pressure_drop.max,
);

/// The twin, the results of the temperature-only jobs and the consistency
/// check, at an oil temperature given by the caller; the twin integrates
/// in `T` (`f32` or [`Fixed`](crate::scalar::Fixed)), everything else is
/// `f32`.
#[derive(Clone, Copy, Debug)]
pub struct Plant<T = f32> {
    /// The design at the applied port pressures (`pressure_drop`,
    /// `outlet_pressure`: the design's own until [`Plant::set_ports`]).
    params: Params<f32>,
    twin: Twin<f32, T>,
    /// Eq. (32) holds over the validated range (else `NOT_UNIQUE`).
    monotonic: bool,
    /// The applied drop is inside the schema's plausible range.
    drop_in_range: bool,
    /// Constants of the design the jobs need.
    design: Design,
    /// Temperature-only results, refreshed in rotation (see [`Job`]).
    statics: Statics,
    /// Jobs whose last run failed, one bit per [`Job`] (the oil model
    /// refused the temperature: the previous results stay in force). The
    /// estimate is degraded until each of them succeeds again.
    failed_jobs: u8,
    /// The job of the next [`Plant::run_job`].
    next_job: Job,
    /// The rest of a job under way, on a core without an FPU: the next job
    /// tick runs it (`jobs::resume`) in place of the rotation's next job.
    pending: Option<Pending>,
    /// The twin's temperature at the start of the current steady stretch \[C\].
    steady_anchor: f32,
    /// Job ticks the twin's temperature stayed within [`STEADY_BAND`] of
    /// `steady_anchor` (or since the last re-seat).
    steady_ticks: u32,
    /// Re-seats of the twin so far (saturating).
    reseats: u32,
    /// Consistency checks run so far (saturating).
    checks: u32,
    /// The last check re-seated the twin (raises `TWIN_RESEATED` until a
    /// check finds it in agreement).
    reseated: bool,
}

impl<T: Real> Plant<T> {
    /// The twin at rest in the equilibrium of `initial` \[C\] at the
    /// design's pressures, every job run there (the uncertainty with the
    /// oil temperature's variance `variance` \[C^2\]). Eq. (32) is checked once here over the
    /// validated range (201 samples; a range the oil model refuses in part
    /// is not an error, it raises `NOT_UNIQUE`).
    ///
    /// # Errors
    ///
    /// * the twin cannot be built at `initial` ([`Twin::new`]);
    /// * the oil model refuses `initial` or the machine's reference
    ///   temperature ([`crate::fluid::Oil::state`]);
    /// * a job fails at `initial` (the equilibrium, its sensitivity or the
    ///   machine's losses not finite).
    pub fn new<U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy>(
        params: &Params<f32>,
        config: &EstimatorConfig<U, O>,
        initial: f32,
        variance: f32,
    ) -> Result<Self, ModelError> {
        let monotonic = asymptotic::monotonicity(params, config.valid.min, config.valid.max, 201)
            .map(|m| m.monotonic)
            .unwrap_or(false);
        let mut twin = Twin::new(params, config.twin, initial)?;
        let machine_mu_ref = match &params.machine {
            Some(m) => params.oil.state(m.leakage_temperature)?.dynamic_viscosity,
            None => f32::NAN,
        };
        let point = params.oil.point(initial)?;
        let design = Design::new(params, machine_mu_ref);
        let mut statics = Statics::new(point, config.tick());
        let table = config.table();
        for job in Job::ALL {
            jobs::run(
                job,
                params,
                table,
                &mut twin,
                design,
                initial,
                || variance,
                &mut statics,
            )?;
        }
        Ok(Plant {
            params: *params,
            twin,
            monotonic,
            drop_in_range: true,
            design,
            statics,
            failed_jobs: 0,
            next_job: Job::Fluid,
            pending: None,
            steady_anchor: initial,
            steady_ticks: 0,
            reseats: 0,
            checks: 0,
            reseated: false,
        })
    }

    /// The twin.
    pub fn twin(&self) -> &Twin<f32, T> {
        &self.twin
    }

    /// The twin, mutable: to inject a fault (a wrong state, with
    /// [`Twin::set_state`]) and watch the consistency check undo it.
    pub fn twin_mut(&mut self) -> &mut Twin<f32, T> {
        &mut self.twin
    }

    /// The twin's oil (its temperature, viscosity and density with their
    /// temperature derivatives) at the last Fluid job.
    pub fn oil(&self) -> &crate::fluid::FluidPoint<f32> {
        &self.statics.point
    }

    /// The design at the applied port pressures.
    pub fn params(&self) -> &Params<f32> {
        &self.params
    }

    /// The flags of the design and its inputs, before any tick: Eq. (32)
    /// fails over the validated range (`NOT_UNIQUE`); the oil temperature
    /// `t` \[C\] is outside the validated range or the applied drop outside
    /// the schema's plausible range (`OUT_OF_RANGE`).
    pub fn flags_at<U, O>(&self, config: &EstimatorConfig<U, O>, t: f32) -> Flags {
        let mut flags = Flags::empty();
        if !self.monotonic {
            flags.insert(Flags::NOT_UNIQUE);
        }
        if !(config.valid.contains(t) && self.drop_in_range) {
            flags.insert(Flags::OUT_OF_RANGE);
        }
        flags
    }

    /// Applies the port pressures `supply`, `outlet` \[Pa\] to the twin
    /// ([`Twin::set_pressures`]) and makes them the operating point of the
    /// jobs; [`Plant::refresh`] then recomputes the results at them.
    ///
    /// # Errors
    ///
    /// As [`Twin::set_pressures`]; nothing changes then.
    pub fn set_ports(&mut self, supply: f32, outlet: f32) -> Result<(), ModelError> {
        self.twin.set_pressures(supply, outlet)?;
        self.params.pressure_drop = supply - outlet;
        self.params.outlet_pressure = outlet;
        self.design = Design::new(&self.params, self.design.machine_mu_ref());
        let drop = self.params.pressure_drop as f64;
        self.drop_in_range = (DROP_RANGE.0..=DROP_RANGE.1).contains(&drop);
        Ok(())
    }

    /// Puts the twin at rest in the closed-form equilibrium of its oil at
    /// the applied port pressures (no transient to grade).
    ///
    /// # Errors
    ///
    /// The equilibrium cannot be computed there ([`equilibrium`]).
    pub fn rest(&mut self) -> Result<(), ModelError> {
        let eq = equilibrium(&self.params, self.statics.point.state.temperature)?;
        self.twin.set_state(&DynamicState {
            x: eq.x,
            v: 0.0,
            p_a: eq.p_a,
            p_b: eq.p_b,
        });
        let memory = self.twin.memory();
        self.twin.restore(&TwinMemory {
            abrupt: false,
            ..memory
        });
        Ok(())
    }

    /// Every job at once at `t` \[C\] with the oil temperature's variance
    /// `variance` \[C^2\]: the twin's oil set to `t` without a slew limit
    /// (an abrupt change is graded by the twin itself), the equilibrium
    /// and the stability where the applied drop is positive (else the last
    /// verdict stands), the losses and the uncertainty.
    ///
    /// # Errors
    ///
    /// The first job the model refuses; the results computed before it
    /// stand, the rest keep their previous values, and the estimates are
    /// `DEGRADED` until a refresh succeeds.
    pub fn refresh<U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy>(
        &mut self,
        config: &EstimatorConfig<U, O>,
        t: f32,
        variance: f32,
    ) -> Result<(), ModelError> {
        let table = config.table();
        let mut statics = self.statics;
        let drop_positive = self.params.pressure_drop > 0.0;
        statics.slewing = false;
        let outcome = jobs::set_oil(&self.params, &mut self.twin, self.design, &mut statics, t).and_then(|()| {
            for job in [Job::Equilibrium, Job::Stability, Job::Losses, Job::Uncertainty] {
                if drop_positive || !matches!(job, Job::Equilibrium | Job::Stability) {
                    jobs::run(
                        job,
                        &self.params,
                        table,
                        &mut self.twin,
                        self.design,
                        t,
                        || variance,
                        &mut statics,
                    )?;
                }
            }
            Ok(())
        });
        match outcome {
            Ok(()) => {
                self.statics = statics;
                self.failed_jobs = 0;
                self.pending = None;
            }
            Err(_) => self.failed_jobs |= Job::Fluid.bit(),
        }
        outcome
    }

    /// One twin tick: `Ok(true)` when the twin had an event in it (an
    /// impact, a release: a few steps more). A failed step (never seen
    /// with valid parameters) puts the twin at rest in the closed-form
    /// equilibrium of its oil at the applied pressures ([`Plant::rest`]),
    /// raises `DEGRADED` in `flags` and counts as an event, rather than
    /// continuing from garbage (its coefficients are the oil's, not
    /// garbage: only its state is replaced).
    ///
    /// # Errors
    ///
    /// The equilibrium cannot be computed ([`Plant::rest`]).
    pub fn advance(&mut self, flags: &mut Flags) -> Result<bool, ModelError> {
        match self.twin.tick() {
            Ok(report) => Ok(report.eventful()),
            Err(_) => {
                flags.insert(Flags::DEGRADED);
                self.rest()?;
                Ok(true)
            }
        }
    }

    /// One twin tick without its report: what a late tick's catch-up runs
    /// (a failed step is the next [`Plant::advance`]'s to handle).
    pub(super) fn coast(&mut self) {
        let _ = self.twin.tick();
    }

    /// The next job in the rotation at the estimated oil temperature `t`
    /// \[C\] (the Fluid job again while the twin's oil is on its way to `t`,
    /// at most [`super::TWIN_SLEW`] per job), with the oil temperature's
    /// variance from `variance` \[C^2\] for the Uncertainty job; then, after
    /// an Equilibrium job, the consistency check. A job the model refuses
    /// leaves its previous results in force, and the estimates `DEGRADED`
    /// until it succeeds again. With a fixed-point twin (the cores without
    /// an FPU) the Fluid, Equilibrium, Stability and Uncertainty jobs run in slices, one
    /// a call: a job's rest runs before the rotation's next job, and each
    /// result is published when its slice ends.
    pub fn run_job(&mut self, table: &UncertaintyTable, t: f32, variance: impl FnOnce() -> f32) {
        // The steady stretch, counted in ticks that run a job: the twin's
        // temperature (it follows `t` at most at its slew rate), steady once
        // it has arrived and stays.
        let tw = self.statics.point.state.temperature;
        if libm::fabsf(tw - self.steady_anchor) <= STEADY_BAND {
            self.steady_ticks = self.steady_ticks.saturating_add(1);
        } else {
            self.steady_anchor = tw;
            self.steady_ticks = 0;
        }
        // Without an FPU a job's rest, begun on an earlier job tick, runs
        // first.
        if T::SATURATES
            && let Some(pending) = self.pending.take()
        {
            let (job, outcome) = jobs::resume(
                pending,
                &self.params,
                table,
                &mut self.twin,
                self.design,
                &mut self.statics,
            );
            match outcome {
                Ok(next) => {
                    self.pending = next;
                    if next.is_none() {
                        self.failed_jobs &= !job.bit();
                    }
                }
                Err(_) => self.failed_jobs |= job.bit(),
            }
            return;
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
        // Without an FPU the Fluid, Equilibrium, Stability and Uncertainty jobs run in
        // slices (their first here, the rest on the next job ticks); with
        // one, whole.
        let outcome = if T::SATURATES {
            jobs::start(
                job,
                &self.params,
                table,
                &mut self.twin,
                self.design,
                t,
                variance,
                &mut self.statics,
            )
            .map(|next| self.pending = next)
        } else {
            jobs::run(
                job,
                &self.params,
                table,
                &mut self.twin,
                self.design,
                t,
                variance,
                &mut self.statics,
            )
        };
        match outcome {
            Ok(()) => {
                self.failed_jobs &= !job.bit();
                if job == Job::Equilibrium {
                    self.check_twin();
                }
            }
            Err(_) => self.failed_jobs |= job.bit(),
        }
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
        let [xi, _, pi_a, pi_b] = self.twin.raw_state().map(Real::to_f32);
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

    /// The estimate of the twin's state now at the oil temperature `t`
    /// \[C\], with `flags` and those of the plant's own condition (a failed
    /// job: `DEGRADED`; the last check re-seated the twin:
    /// `TWIN_RESEATED`; the linearisation unstable: `UNSTABLE`; the plunger
    /// on a stop: `AT_STOP`): the state, the flows at the applied outlet
    /// pressure, the compensation error, the last equilibrium and
    /// uncertainty. The fields that are the caller's (`tick`, `t_probe`,
    /// `deadline_misses`, `lost_ticks`) are 0 and NaN.
    pub fn estimate(&self, t: f32, mut flags: Flags) -> StateEstimate {
        if self.failed_jobs != 0 {
            flags.insert(Flags::DEGRADED);
        }
        if self.reseated {
            flags.insert(Flags::TWIN_RESEATED);
        }
        let p = &self.params;
        let st = &self.statics;
        if !st.stable {
            flags.insert(Flags::UNSTABLE);
        }
        let s = self.twin.state();
        let [xi, ..] = self.twin.raw_state();
        if xi <= T::ZERO || xi >= T::ONE {
            flags.insert(Flags::AT_STOP);
        }
        let q_a = st.flows.capillary_flow(s.p_a - p.outlet_pressure);
        let q_b = st.flows.orifice_flow(s.p_b - p.outlet_pressure);
        let q_throt = st.flows.window_flow(s.x);
        let q_total = q_a + q_b + q_throt;
        let compensation_error = match &p.machine {
            Some(m) => q_total - (m.working_flow + st.losses),
            None => f32::NAN,
        };
        StateEstimate {
            tick: 0,
            temperature: t,
            t_probe: f32::NAN,
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
            deadline_misses: 0,
            lost_ticks: 0,
            uncertainty: st.uncertainty,
            health: crate::monitor::HealthEstimate::NONE,
            flags,
        }
    }

    /// The time constant of the twin's slowest mode at the last Stability
    /// job \[s\]: `1 / sigma`, with `sigma` a lower bound (within 25 %) of the
    /// smallest decay rate `-Re(lambda)` of the linearisation at the
    /// equilibrium. Infinite while the linearisation is not stable.
    pub fn slowest_time_constant(&self) -> f32 {
        self.statics.slowest_time_constant
    }

    /// Steady job ticks the consistency check waits for at the last
    /// Stability job (`u32::MAX`: it does not run, the linearisation is not
    /// stable).
    pub fn settle_ticks(&self) -> u32 {
        self.statics.settle_ticks
    }

    /// Consistency checks run since start (saturating).
    pub fn consistency_checks(&self) -> u32 {
        self.checks
    }

    /// Re-seats of the twin since start (saturating).
    pub fn reseats(&self) -> u32 {
        self.reseats
    }

    /// The uncertainty at the last Uncertainty job.
    pub fn uncertainty(&self) -> Uncertainty {
        self.statics.uncertainty
    }
}
