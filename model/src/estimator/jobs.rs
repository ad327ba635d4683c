//! The temperature-only jobs and the results they keep: one job per tick
//! that is neither a telemetry tick nor an eventful one, in turn (the
//! rotation is the estimator's, in the parent module).

use super::stability::{DecaySearch, quartic_hurwitz, slowest_decay_rate};
use super::{MAX_STOP_SETTLE, MIN_SETTLE_TICKS, SETTLE_TIME_CONSTANTS, STOP_SETTLE_TIME_CONSTANTS, TWIN_SLEW};
use crate::asymptotic;
use crate::compensation;
use crate::dynamics::Twin;
use crate::dynamics::coefficients::Coefficients;
use crate::dynamics::fsi::{Contact, Fsi};
use crate::dynamics::linear::{characteristic_polynomial, fsi_characteristic_polynomial};
use crate::dynamics::schemes::OdeSystem;
use crate::equilibrium::{Stop, a_parameter, balance_for};
use crate::error::ModelError;
use crate::fluid::{FluidPoint, WaltherLog};
use crate::params::Params;
use crate::scalar::Real;
use crate::throttle::FlowLaws;
use crate::uncertainty::{Lookup, Uncertainty, UncertaintyTable};

/// The temperature-only jobs, one per tick in turn (the uncertainty's
/// depends on the observer's variance too).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Job {
    /// Oil properties (one Walther evaluation) for the twin and the flows:
    /// the requirement "fluid properties at the sensor rate", here every four
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
    /// The uncertainty of the estimate at the observer's temperature and
    /// variance ([`crate::uncertainty::UncertaintyTable::at`]).
    Uncertainty,
}

impl Job {
    /// Every job, in rotation order.
    pub(super) const ALL: [Job; 5] = [
        Job::Fluid,
        Job::Equilibrium,
        Job::Stability,
        Job::Losses,
        Job::Uncertainty,
    ];

    /// The job after this one in the rotation.
    pub(super) fn next(self) -> Job {
        match self {
            Job::Fluid => Job::Equilibrium,
            Job::Equilibrium => Job::Stability,
            Job::Stability => Job::Losses,
            Job::Losses => Job::Uncertainty,
            Job::Uncertainty => Job::Fluid,
        }
    }

    /// This job's bit in `Estimator::failed_jobs`.
    pub(super) fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

/// What the jobs need of the design besides its parameters, computed once
/// (the window's factor is a root and a few products the Fluid job would
/// otherwise repeat).
#[derive(Clone, Copy, Debug)]
pub(super) struct Design {
    /// The window's `eta pi d sqrt(2 dp)` at the design's `dp`
    /// ([`Slot::window_factor`](crate::throttle::Slot::window_factor)):
    /// the oil-independent part of its law.
    slot_window_factor: f32,
    /// Dynamic viscosity at the machine's reference temperature [Pa s]
    /// (NaN, and never read, without a `[machine]`).
    machine_mu_ref: f32,
}

impl Design {
    /// For the design `p`, with the oil's dynamic viscosity at the
    /// machine's reference temperature `machine_mu_ref` [Pa s] (NaN without
    /// a `[machine]`).
    // Out of line: inlined (with `Estimator::new`) into the QEMU twin's
    // `main`, it grew main's frame, which is the peak stack, by 16 bytes.
    #[inline(never)]
    pub(super) fn new(p: &Params<f32>, machine_mu_ref: f32) -> Self {
        Design {
            slot_window_factor: p.slot.window_factor(p.pressure_drop),
            machine_mu_ref,
        }
    }

    /// The oil's dynamic viscosity at the machine's reference temperature
    /// \[Pa s\] (NaN without a `[machine]`).
    pub(super) fn machine_mu_ref(self) -> f32 {
        self.machine_mu_ref
    }
}

/// Results that depend on the temperature only. Each tick that is not a
/// telemetry tick refreshes one of them, so each is refreshed every four
/// such ticks (telemetry is at most every second tick, validated), while
/// the oil's temperature changes over seconds, and the cost of a tick stays
/// bounded by the twin plus the largest single job.
#[derive(Clone, Copy, Debug)]
pub(super) struct Statics {
    /// Oil state and derivatives at `temperature`.
    pub(super) point: FluidPoint<f32>,
    /// The throttle laws at that oil state.
    pub(super) flows: FlowLaws<f32>,
    pub(super) x_equilibrium: f32,
    pub(super) dx_dt: f32,
    /// The equilibrium in the twin's model units `(x / L, v / V,
    /// (p_a - p_c) / dp, (p_b - p_c) / dp)` (for the linearisation and the
    /// consistency check).
    pub(super) y_equilibrium: [f32; 4],
    /// The equilibrium holds the plunger on the closed stop (the settling
    /// window then covers the travel onto it: [`STOP_SETTLE_TIME_CONSTANTS`]).
    pub(super) on_closed_stop: bool,
    pub(super) stable: bool,
    /// `1 / tick` [1/s] (constant).
    ticks_per_second: f32,
    /// Lower bound of the slowest decay rate of the linearisation, in the
    /// twin's time unit (0: none, not stable); the next search's hint.
    slowest_rate: f32,
    /// Time constant of the slowest mode of the linearisation [s].
    pub(super) slowest_time_constant: f32,
    /// Steady ticks before the consistency check: [`SETTLE_TIME_CONSTANTS`]
    /// of the slowest time constant (on the closed stop, up to
    /// [`STOP_SETTLE_TIME_CONSTANTS`] of it within [`MAX_STOP_SETTLE`]), at
    /// least [`MIN_SETTLE_TICKS`];
    /// `u32::MAX` (never) while the linearisation is not stable.
    pub(super) settle_ticks: u32,
    /// Machine losses at the last refreshed temperature [m^3/s].
    pub(super) losses: f32,
    /// The uncertainty of the estimate at the last Uncertainty job.
    pub(super) uncertainty: Uncertainty,
    /// The last Fluid job moved the twin's oil by its whole slew limit
    /// ([`TWIN_SLEW`]): the twin is still on its way to the filtered
    /// temperature, and the next job is the Fluid job again.
    pub(super) slewing: bool,
}

impl Statics {
    /// Before any job: the oil at `point`, nothing else computed yet, for
    /// an estimator ticking every `tick` [s].
    pub(super) fn new(point: FluidPoint<f32>, tick: f32) -> Self {
        Statics {
            point,
            flows: FlowLaws {
                capillary_conductance: 0.0,
                orifice_factor: 0.0,
                window_factor: 0.0,
            },
            x_equilibrium: f32::NAN,
            dx_dt: f32::NAN,
            y_equilibrium: [0.0; 4],
            on_closed_stop: false,
            stable: true,
            ticks_per_second: 1.0 / tick,
            slowest_rate: 0.0,
            slowest_time_constant: f32::INFINITY,
            settle_ticks: u32::MAX,
            losses: f32::NAN,
            uncertainty: Uncertainty::UNKNOWN,
            slewing: false,
        }
    }
}

/// Moves the twin's oil and the flow laws towards `target` \[C\], at most
/// by what changes the capillary conductance (~ 1 / mu) by `slew`
/// (relative); `statics.slewing` says whether the limit held it short.
fn move_oil<T: Real>(
    p: &Params<f32>,
    twin: &mut Twin<f32, T>,
    design: Design,
    statics: &mut Statics,
    target: f32,
    slew: f32,
) -> Result<(), ModelError> {
    let point = slewed_point(p, statics, target, slew)?;
    apply(p, twin, design, statics, point)
}

/// The oil the twin moves to towards `target` \[C\] ([`move_oil`]'s first
/// half: the oil's properties there, `statics.slewing` set).
#[inline(always)]
fn slewed_point(p: &Params<f32>, statics: &mut Statics, target: f32, slew: f32) -> Result<FluidPoint<f32>, ModelError> {
    let (t, slewing) = slewed_temperature(statics, target, slew);
    let point = p.oil.point(t)?;
    statics.slewing = slewing;
    Ok(point)
}

/// The temperature the twin's oil moves to towards `target` \[C\], and
/// whether the slew limit held it short of `target`.
#[inline(always)]
fn slewed_temperature(statics: &Statics, target: f32, slew: f32) -> (f32, bool) {
    let prev = &statics.point;
    let now = prev.state.temperature;
    let dln_mu = libm::fabsf(prev.viscosity.d1 / prev.viscosity.value + prev.density.d1 / prev.density.value);
    let max_step = if dln_mu > 0.0 { slew / dln_mu } else { f32::INFINITY };
    let step = super::clamp(target - now, -max_step, max_step);
    (now + step, step != target - now)
}

/// The twin's oil and the flow laws at `t` \[C\] at once (the Fluid job's
/// last step; a co-simulation's input, which the twin grades itself when
/// the change is abrupt).
pub(super) fn set_oil<T: Real>(
    p: &Params<f32>,
    twin: &mut Twin<f32, T>,
    design: Design,
    statics: &mut Statics,
    t: f32,
) -> Result<(), ModelError> {
    let point = p.oil.point(t)?;
    apply(p, twin, design, statics, point)
}

/// The twin's oil and the flow laws at `point`.
fn apply<T: Real>(
    p: &Params<f32>,
    twin: &mut Twin<f32, T>,
    design: Design,
    statics: &mut Statics,
    point: FluidPoint<f32>,
) -> Result<(), ModelError> {
    twin.set_fluid(&point.state)?;
    statics.point = point;
    statics.flows = FlowLaws::new(
        &p.capillary,
        &p.orifice,
        design.slot_window_factor,
        point.state.density,
        point.state.dynamic_viscosity,
    );
    Ok(())
}

/// Routh-Hurwitz tests per slice of the Stability job's decay-rate search
/// on a core without an FPU ([`Pending::Search`]): the usual case, the
/// hint confirmed (two tests), is one slice; a whole search (at most ten
/// tests) five. A test costs a Cortex-M0 about 3,800 instructions in
/// software `f32`: three on one tick made the costliest slice.
pub(super) const SEARCH_STEPS: u32 = 2;

/// The characteristic polynomial of the linearisation at the equilibrium
/// (in the twin's model units), in `f32` whatever the twin's scalar. A
/// fixed-point twin's chamber rates are stored saturated
/// (`Coefficients::omega_a0`), so the model's are put in their place: a
/// product each, where forming every coefficient again from the model took
/// `f64` arithmetic (about 8,000 software-float instructions on a
/// Cortex-M0); the others are the twin's own.
#[inline(always)]
fn stability_polynomial<T: Real>(twin: &Twin<f32, T>, statics: &Statics) -> [f32; 4] {
    characteristic_polynomial(&stability_jacobian(twin, statics))
}

/// The Jacobian whose characteristic polynomial [`stability_polynomial`] is.
#[inline(always)]
fn stability_jacobian<T: Real>(twin: &Twin<f32, T>, statics: &Statics) -> [[f32; 4]; 4] {
    linearised(&stability_coefficients(twin)).jacobian(&statics.y_equilibrium)
}

/// The twin's coefficients in `f32` for the Stability job's linearisation
/// (the chamber rates the model's, see [`stability_polynomial`]).
#[inline(always)]
fn stability_coefficients<T: Real>(twin: &Twin<f32, T>) -> Coefficients<f32> {
    let mut coefficients = twin.coefficients().to_f32();
    if T::SATURATES {
        [coefficients.omega_a0, coefficients.omega_b0] = twin.model().chamber_rates(coefficients.flow_shift);
    }
    coefficients
}

/// The free plunger's model with `coefficients`, what the Stability job
/// linearises.
#[inline(always)]
fn linearised(coefficients: &Coefficients<f32>) -> Fsi<'_, f32> {
    Fsi {
        coefficients,
        contact: Contact::Free,
    }
}

/// The Stability job's results from the slowest decay rate `sigma` (in the
/// twin's time unit; 0: none, not stable): its time constant and the
/// consistency check's settling window.
#[inline(always)]
fn set_decay_rate<T: Real>(twin: &Twin<f32, T>, statics: &mut Statics, sigma: f32) {
    statics.slowest_rate = sigma;
    if sigma > 0.0 {
        statics.slowest_time_constant = twin.model().scales.time / sigma;
        let tau = statics.slowest_time_constant;
        let mut window = SETTLE_TIME_CONSTANTS * tau;
        if statics.on_closed_stop {
            window = window.max((STOP_SETTLE_TIME_CONSTANTS * tau).min(MAX_STOP_SETTLE));
        }
        let ticks = window * statics.ticks_per_second;
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

/// What the next job tick runs in place of the rotation's next job, on a
/// core without an FPU: the rest of a job whose whole would cost a tick
/// several times the twin's (in software `f32` on a Cortex-M0: the
/// Fluid job about 19,000 instructions, the Equilibrium job 18,000, the Stability job's
/// linearisation 20,000 and its decay-rate search up to 27,000).
#[derive(Clone, Copy, Debug)]
pub(super) enum Pending {
    /// The first half of the Fluid job's Walther evaluation at the slewed
    /// temperature, which [`Oil::point_from_log`](crate::fluid::Oil::point_from_log)
    /// ends, and whether the slew limit held that temperature short.
    Walther(WaltherLog<f32>, bool),
    /// The Fluid job's new oil, for the twin and the flow laws ([`apply`]).
    Apply(FluidPoint<f32>),
    /// The Equilibrium job's `dx/dt` ([`asymptotic::sensitivity_at`]).
    Sensitivity,
    /// The Stability job's coefficients in `f32` and chamber (a)'s
    /// orifice law at the equilibrium ([`Fsi::orifice_a`]), whose Jacobian
    /// is next (the conversion and the whole Jacobian on one tick made the
    /// Cortex-M0's costliest job slice, about 13,000 instructions).
    Linearise(Coefficients<f32>, (f32, f32)),
    /// The Stability job's Jacobian at the equilibrium, whose
    /// characteristic polynomial and Routh-Hurwitz verdict are next.
    Jacobian([[f32; 4]; 4]),
    /// The Uncertainty job's oil temperature \[C\] and its variance
    /// \[C^2\] (the observer's, taken on the job's first tick), the
    /// table's input.
    Uncertainty(f32, f32),
    /// The Uncertainty job's place on the table and its first three
    /// outputs' standard uncertainties (`x`, `p_a`, `p_b`), the rest next:
    /// the five outputs' square roots on one tick made the Cortex-M0's
    /// costliest slice, about 12,000 instructions in software `f32`.
    UncertaintyRest(Lookup, [f32; 3]),
    /// The Stability job's decay-rate search.
    Search(DecaySearch),
}

/// The first slice of `job` on a core without an FPU: the first half of
/// the Fluid job's Walther evaluation at the slewed temperature (the oil's
/// properties for the twin and the flow laws next, then their hand-over),
/// the Equilibrium job's closed form (its results published at once; `dx/dt` next), the
/// Stability job's Jacobian; another job whole ([`run`]). `Ok(Some)`: the
/// continuation the next job tick runs ([`resume`]).
#[allow(clippy::too_many_arguments, reason = "the tick's state, borrowed apart")]
pub(super) fn start<T: Real>(
    job: Job,
    p: &Params<f32>,
    table: &UncertaintyTable,
    twin: &mut Twin<f32, T>,
    design: Design,
    t: f32,
    variance: impl FnOnce() -> f32,
    statics: &mut Statics,
) -> Result<Option<Pending>, ModelError> {
    match job {
        Job::Fluid => {
            let (t, slewing) = slewed_temperature(statics, t, TWIN_SLEW);
            Ok(Some(Pending::Walther(p.oil.walther_log(t)?, slewing)))
        }
        Job::Equilibrium => {
            equilibrium(p, twin, statics)?;
            Ok(Some(Pending::Sensitivity))
        }
        Job::Stability => {
            let coefficients = stability_coefficients(twin);
            let a = linearised(&coefficients).orifice_a(&statics.y_equilibrium);
            Ok(Some(Pending::Linearise(coefficients, a)))
        }
        Job::Uncertainty => Ok(Some(Pending::Uncertainty(t, variance()))),
        _ => run(job, p, table, twin, design, t, variance, statics).map(|()| None),
    }
}

/// The next slice of a job begun by [`start`]: the job it belongs to, and
/// what follows it (`Ok(None)`: the job is done).
pub(super) fn resume<T: Real>(
    pending: Pending,
    p: &Params<f32>,
    table: &UncertaintyTable,
    twin: &mut Twin<f32, T>,
    design: Design,
    statics: &mut Statics,
) -> (Job, Result<Option<Pending>, ModelError>) {
    match pending {
        Pending::Walther(log, slewing) => (
            Job::Fluid,
            p.oil.point_from_log(log).map(|point| {
                statics.slewing = slewing;
                Some(Pending::Apply(point))
            }),
        ),
        Pending::Apply(point) => (Job::Fluid, apply(p, twin, design, statics, point).map(|()| None)),
        Pending::Sensitivity => (
            Job::Equilibrium,
            asymptotic::dx_dt_at(p, &statics.point).map(|dx_dt| {
                statics.dx_dt = dx_dt;
                None
            }),
        ),
        Pending::Uncertainty(t, variance) => {
            let lookup = table.lookup(t, variance);
            let first = [0, 1, 2].map(|o| table.output(&lookup, o));
            (Job::Uncertainty, Ok(Some(Pending::UncertaintyRest(lookup, first))))
        }
        Pending::UncertaintyRest(lookup, [x, p_a, p_b]) => {
            let (q_total, error) = (table.output(&lookup, 3), table.output(&lookup, 4));
            statics.uncertainty = table.assemble(&lookup, [x, p_a, p_b, q_total, error]);
            (Job::Uncertainty, Ok(None))
        }
        Pending::Linearise(coefficients, a) => {
            let sys = linearised(&coefficients);
            let y = &statics.y_equilibrium;
            (
                Job::Stability,
                Ok(Some(Pending::Jacobian(sys.jacobian_with(y, a, sys.orifice_b(y))))),
            )
        }
        Pending::Jacobian(m) => {
            let poly = fsi_characteristic_polynomial(&m);
            statics.stable = quartic_hurwitz(&poly);
            let next = if statics.stable {
                Some(Pending::Search(DecaySearch::new(&poly, statics.slowest_rate)))
            } else {
                set_decay_rate(twin, statics, 0.0);
                None
            };
            (Job::Stability, Ok(next))
        }
        Pending::Search(mut search) => {
            let mut done = None;
            for _ in 0..SEARCH_STEPS {
                done = search.step();
                if done.is_some() {
                    break;
                }
            }
            let next = match done {
                Some(sigma) => {
                    set_decay_rate(twin, statics, sigma);
                    None
                }
                None => Some(Pending::Search(search)),
            };
            (Job::Stability, Ok(next))
        }
    }
}

/// The Equilibrium job's closed form at the twin's oil: the equilibrium,
/// in SI and in the twin's model units, and whether it holds the plunger
/// on the closed stop.
#[inline(always)]
fn equilibrium<T: Real>(p: &Params<f32>, twin: &Twin<f32, T>, statics: &mut Statics) -> Result<(), ModelError> {
    let point = &statics.point;
    let eq = balance_for(p, a_parameter(p, &point.state))?;
    statics.x_equilibrium = eq.x;
    statics.y_equilibrium = twin.model().rest_state(eq.x, eq.p_a, eq.p_b);
    statics.on_closed_stop = eq.stop == Stop::Closed;
    Ok(())
}

/// Runs `job` at the estimated oil temperature `t` \[C\], updating
/// `statics`; `variance` gives the oil temperature's variance \[C^2\] for
/// the Uncertainty job (the table's input). On an error the job's previous
/// results stay in force.
#[allow(clippy::too_many_arguments, reason = "the tick's state, borrowed apart")]
pub(super) fn run<T: Real>(
    job: Job,
    p: &Params<f32>,
    table: &UncertaintyTable,
    twin: &mut Twin<f32, T>,
    design: Design,
    t: f32,
    variance: impl FnOnce() -> f32,
    statics: &mut Statics,
) -> Result<(), ModelError> {
    match job {
        Job::Fluid => {
            // The twin's oil moves towards `t` by at most what changes
            // its capillary conductance (~ 1 / mu) by TWIN_SLEW: a step
            // the spike filter takes as real reaches the twin as a
            // fast ramp, never as an abrupt change (which the twin
            // would grade, at several substeps' cost: `Twin::tick`).
            move_oil(p, twin, design, statics, t, TWIN_SLEW)?;
        }
        Job::Equilibrium => {
            // Both or neither: an error leaves the previous results.
            let dx_dt = asymptotic::dx_dt_at(p, &statics.point)?;
            equilibrium(p, twin, statics)?;
            statics.dx_dt = dx_dt;
        }
        Job::Stability => {
            let poly = stability_polynomial(twin, statics);
            statics.stable = quartic_hurwitz(&poly);
            let sigma = if statics.stable {
                slowest_decay_rate(&poly, statics.slowest_rate)
            } else {
                0.0
            };
            set_decay_rate(twin, statics, sigma);
        }
        Job::Losses => {
            statics.losses = match &p.machine {
                Some(m) => compensation::losses_for(m, design.machine_mu_ref, statics.point.state.dynamic_viscosity)?,
                None => f32::NAN,
            };
        }
        Job::Uncertainty => {
            statics.uncertainty = table.at(t, variance());
        }
    }
    Ok(())
}
