//! The fixed-step, fixed-cost integrator of the FSI model: what runs every
//! tick on the controller.
//!
//! A tick of length `dt` is `substeps` steps of one [`Scheme`]; the
//! temperature-dependent coefficients are frozen over a tick (set them for
//! the tick's midpoint to follow a ramp to second order). The cost of a
//! tick depends on the configuration only: one Jacobian, one 4x4 LU and
//! `stages` right-hand sides per substep, whatever the state.
//!
//! The twin is generic over the parameters' float type `F` (used for the
//! fluid properties at the sensor rate) and the integration scalar `T`
//! (`f32`, `f64` or fixed point).

use super::dirk::Dirk;
use super::fsi::{Coefficients, Contact, DynamicState, Fsi, Model};
use super::schemes::{Scheme, StepError, Stepper};
use crate::equilibrium::equilibrium;
use crate::error::ModelError;
use crate::fluid::FluidState;
use crate::params::Params;
use crate::scalar::{Float, Real};

/// Most substeps per tick (bounds the cost of a tick).
pub const MAX_SUBSTEPS: u8 = 64;

/// How the twin integrates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinConfig {
    /// One-step scheme.
    pub scheme: Scheme,
    /// Tick length [s].
    pub tick: f64,
    /// Steps per tick, `1..=MAX_SUBSTEPS`.
    pub substeps: u8,
}

impl TwinConfig {
    /// A positive, finite tick and `1..=MAX_SUBSTEPS` steps per tick.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(self.tick > 0.0 && self.tick.is_finite()) {
            return Err(ModelError::OutOfRange("tick"));
        }
        if self.substeps == 0 || self.substeps > MAX_SUBSTEPS {
            return Err(ModelError::OutOfRange("substeps"));
        }
        Ok(())
    }

    /// The step length in the model's time unit `time_unit` [s].
    pub fn step(&self, time_unit: f64) -> f64 {
        self.tick / self.substeps as f64 / time_unit
    }

    /// What the firmware ships: ROS3 (three-stage, L-stable, order 3), two
    /// steps per 1 ms tick. The accuracy/cost trade-off against the other
    /// schemes is in the project's `docs/dynamics.md`.
    pub const SHIPPED: TwinConfig = TwinConfig {
        scheme: Scheme::Sdirk3,
        tick: 1.0e-3,
        substeps: 2,
    };
}

/// What happened during a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TickReport {
    /// Contact state at the end of the tick.
    pub contact: Contact,
    /// A substep ended beyond a stop and was put on it (an impact).
    pub impact: bool,
}

/// Bound on the chamber pressures, in units of `dp` beyond `[p_c, p_p]`,
/// past which a tick is reported as [`StepError::Diverged`]. The physical
/// excursions stay far inside it: a plunger stopped dead on a stop swings a
/// chamber by at most its quasi-steady pumping `sigma w / g_l` plus the
/// water-hammer-like transient, well under one `dp` on every surveyed design
/// (`host-tests/tests/survey.rs` records the reference's largest excursion).
pub const PRESSURE_MARGIN: f64 = 4.0;

/// Iterations of the release-time search on a stop (Illinois regula falsi
/// on the held force; each costs one held step, two closed forms per stage
/// for the SDIRK schemes).
pub const RELEASE_ITERATIONS: u8 = 4;

/// Iterations of the impact-time search on the step's cubic Hermite
/// interpolant (no model evaluation).
pub const IMPACT_ITERATIONS: u8 = 6;

/// Steps per held substep.
pub const HELD_STEPS: u8 = 4;

/// The integrator behind a twin.
#[derive(Clone, Copy, Debug)]
enum Engine<T> {
    /// SDIRK with the pressures eliminated exactly ([`super::dirk`]).
    Dirk(Dirk<T>),
    /// A generic scheme (Rosenbrock, RK4) on the [`Fsi`] system.
    Generic(Stepper<T>),
}

/// The dynamic twin.
#[derive(Clone, Copy, Debug)]
pub struct Twin<F, T> {
    model: Model<F>,
    coefficients: Coefficients<T>,
    engine: Engine<T>,
    substeps: u8,
    /// The substep length times `a_x` (model units): `xi' = a_x w`.
    h_a_x: T,
    /// `1 / HELD_STEPS`: the length of a held step, in substeps.
    held_part: T,
    /// Pressure bounds `[-PRESSURE_MARGIN, 1 + PRESSURE_MARGIN]`.
    pressure_bounds: (T, T),
    state: [T; 4],
    /// What rounding has left out of `xi` so far ([`Real::mul_add_compensated`]).
    xi_carry: T,
    config: TwinConfig,
}

impl<F: Float, T: Real> Twin<F, T> {
    /// A twin at rest in the quasi-static equilibrium of `temperature` [C].
    pub fn new(params: &Params<F>, config: TwinConfig, temperature: F) -> Result<Self, ModelError> {
        config.validate()?;
        let model = Model::new(params)?;
        let eq = equilibrium(params, temperature)?;
        let h = config.step(model.scales.time.to_f64());
        let engine = match config.scheme.dirk() {
            Some(tableau) => Engine::Dirk(Dirk::new(tableau, h)),
            None => Engine::Generic(Stepper::new(config.scheme, h)),
        };
        let coefficients: Coefficients<T> = model.coefficients(&eq.fluid)?;
        Ok(Twin {
            h_a_x: T::from_f64(h) * coefficients.a_x,
            held_part: T::from_f64(1.0 / HELD_STEPS as f64),
            coefficients,
            engine,
            substeps: config.substeps,
            pressure_bounds: (T::from_f64(-PRESSURE_MARGIN), T::from_f64(1.0 + PRESSURE_MARGIN)),
            state: model.equilibrium_state(&eq),
            xi_carry: T::ZERO,
            model,
            config,
        })
    }

    /// The model (scales, parameters).
    pub fn model(&self) -> &Model<F> {
        &self.model
    }

    /// The configuration.
    pub fn config(&self) -> TwinConfig {
        self.config
    }

    /// Current coefficients.
    pub fn coefficients(&self) -> &Coefficients<T> {
        &self.coefficients
    }

    /// Sets the oil temperature [C] for the following ticks. On error the
    /// previous coefficients stay in force.
    pub fn set_temperature(&mut self, temperature: F) -> Result<(), ModelError> {
        let fluid = self.model.params().oil.state(temperature)?;
        self.set_fluid(&fluid)
    }

    /// As [`Twin::set_temperature`] from an already evaluated fluid state.
    pub fn set_fluid(&mut self, fluid: &FluidState<F>) -> Result<(), ModelError> {
        self.coefficients.set_hydraulic(&self.model, fluid)
    }

    /// Advances one tick of `substeps` substeps. On a failed substep the
    /// state is left at the last good one and the error is returned: a
    /// state that is not finite or beyond the physical bounds
    /// ([`PRESSURE_MARGIN`]) is [`StepError::Diverged`] /
    /// [`StepError::NonFinite`], never silently kept.
    ///
    /// The end stops are a constraint, handled as events inside each
    /// substep, so that the pressures always see the motion the plunger
    /// actually makes:
    /// * held on a stop (on it, at rest, the static force of the current
    ///   pressures pushing into it), the substep is integrated held (`w = 0`
    ///   throughout). If the force at its end pulls away, the release time
    ///   is located (Illinois on the held force, [`RELEASE_ITERATIONS`]
    ///   held steps): held up to it, free after it;
    /// * moving freely, a substep that ends beyond a stop is redone up to
    ///   the impact (located on the step's cubic Hermite interpolant of
    ///   `xi`), the plunger stops there (inelastic: `w = 0`), and the rest of
    ///   the substep is integrated held.
    ///
    /// Whatever the tick's phase, a release and an impact are placed where
    /// the force and the motion put them, not at a substep's boundary. The
    /// cost is bounded: a quiet substep is one step; one with an event is
    /// at most two free and `RELEASE_ITERATIONS + 2` held steps.
    pub fn tick(&mut self) -> Result<TickReport, StepError> {
        let mut impact = false;
        for _ in 0..self.substeps {
            let mut carry = self.xi_carry;
            let (next, hit) = self.substep(&self.state, &mut carry)?;
            self.check(&next)?;
            impact |= hit;
            self.state = next;
            self.xi_carry = carry;
        }
        Ok(TickReport {
            contact: self.coefficients.contact(&self.state),
            impact,
        })
    }

    /// A state the twin can continue from: finite, pressures within the
    /// physical bounds.
    fn check(&self, y: &[T; 4]) -> Result<(), StepError> {
        if !y.iter().all(|v| v.is_finite()) {
            return Err(StepError::NonFinite);
        }
        let (lo, hi) = self.pressure_bounds;
        if y[2] < lo || y[2] > hi || y[3] < lo || y[3] > hi {
            return Err(StepError::Diverged);
        }
        Ok(())
    }

    /// One step of `frac` of a substep from `y`, in `contact`.
    /// `xi_carry`: the compensated summation's carry of `xi` (free motion).
    fn step(&self, y: &[T; 4], frac: T, contact: Contact, xi_carry: &mut T) -> Result<[T; 4], StepError> {
        let c = &self.coefficients;
        match &self.engine {
            Engine::Dirk(d) => Ok(d.step(c, y, frac, contact, xi_carry)),
            Engine::Generic(s) => {
                let sys = Fsi {
                    coefficients: c,
                    contact,
                };
                let mut next = s.step_fraction(&sys, y, frac)?;
                if contact != Contact::Free {
                    next[0] = y[0];
                    next[1] = T::ZERO;
                }
                Ok(next)
            }
        }
    }

    /// One substep from `y`; `carry` is `xi`'s compensated-summation carry.
    fn substep(&self, y: &[T; 4], carry: &mut T) -> Result<([T; 4], bool), StepError> {
        let c = &self.coefficients;
        let held = c.contact(y);
        if held == Contact::Free {
            return self.free_part(y, T::ONE, carry);
        }
        // On the stop exactly: nothing left to carry.
        *carry = T::ZERO;
        // Held: the plunger on the stop at rest; the pressures evolve, in
        // HELD_STEPS equal steps (a pressure transient after a change of
        // temperature decides when the plunger lifts off: it is followed,
        // not stepped over).
        // Positive: the force pulls away from the stop (a release).
        let away = |s: &[T; 4]| match held {
            Contact::Open => -c.static_force(s),
            _ => c.static_force(s),
        };
        let part = self.held_part;
        let mut start = [y[0], T::ZERO, y[2], y[3]];
        let mut t0 = T::ZERO;
        for _ in 0..HELD_STEPS {
            let end = self.step(&start, part, held, carry)?;
            let f1 = away(&end);
            if f1 > T::ZERO {
                // Release inside this step: Illinois on the held force over
                // its fraction, bracket [0 (into the stop), 1 (away)].
                let (lo_f, at) = self.release(&start, end, f1, held, &away)?;
                return self.free_part(&at, T::ONE - (t0 + part * lo_f), carry);
            }
            start = end;
            t0 += part;
        }
        Ok((start, false))
    }

    /// Locates the release inside a held step of `held_part` from `start`
    /// whose end `end` pulls away with force `f1`: the first bracketed
    /// fraction of the step at which the force pulls away, and the state
    /// there.
    fn release(
        &self,
        start: &[T; 4],
        end: [T; 4],
        f1: T,
        held: Contact,
        away: &impl Fn(&[T; 4]) -> T,
    ) -> Result<(T, [T; 4]), StepError> {
        let (mut lo, mut f_lo) = (T::ZERO, away(start));
        let (mut hi, mut f_hi) = (T::ONE, f1);
        let mut at_hi = end;
        let mut side = 0i8;
        for _ in 0..RELEASE_ITERATIONS {
            let span = f_hi - f_lo;
            let mut t = if span > T::ZERO {
                lo - f_lo * (hi - lo) / span
            } else {
                (lo + hi) * T::HALF
            };
            if !(t > lo && t < hi) {
                t = (lo + hi) * T::HALF;
            }
            let mut no_carry = T::ZERO;
            let s = self.step(start, t * self.held_part, held, &mut no_carry)?;
            let f = away(&s);
            if f > T::ZERO {
                (hi, f_hi, at_hi) = (t, f, s);
                if side == -1 {
                    f_lo = f_lo * T::HALF;
                }
                side = -1;
            } else {
                (lo, f_lo) = (t, f);
                if side == 1 {
                    f_hi = f_hi * T::HALF;
                }
                side = 1;
            }
        }
        Ok((hi, at_hi))
    }

    /// Free motion over `frac` of a substep from `y`; an impact on a stop
    /// inside it ends the motion there and holds the plunger for the rest.
    fn free_part(&self, y: &[T; 4], frac: T, carry: &mut T) -> Result<([T; 4], bool), StepError> {
        if !(frac > T::ZERO) {
            return Ok((*y, false));
        }
        let mut tried = *carry;
        let next = self.step(y, frac, Contact::Free, &mut tried)?;
        let (x0, x1) = (y[0], next[0]);
        let (stop, contact) = if x1 < T::ZERO {
            (T::ZERO, Contact::Closed)
        } else if x1 > T::ONE {
            (T::ONE, Contact::Open)
        } else {
            *carry = tried;
            return Ok((next, false));
        };
        // Impact time on the cubic Hermite interpolant of xi over the step
        // (theta in [0, 1]), first crossing of the stop: Illinois.
        let hx = self.h_a_x * frac;
        let (d0, d1) = (hx * y[1], hx * next[1]);
        let p = |t: T| {
            // Hermite basis on [0, 1].
            let t2 = t * t;
            let t3 = t2 * t;
            let h00 = T::TWO * t3 - (t2 + t2 + t2) + T::ONE;
            let h10 = t3 - T::TWO * t2 + t;
            let h01 = (t2 + t2 + t2) - T::TWO * t3;
            let h11 = t3 - t2;
            h00 * x0 + h10 * d0 + h01 * x1 + h11 * d1 - stop
        };
        let sign = if contact == Contact::Closed { -T::ONE } else { T::ONE };
        // Positive: beyond the stop.
        let (mut lo, mut f_lo) = (T::ZERO, sign * (x0 - stop));
        let (mut hi, mut f_hi) = (T::ONE, sign * (x1 - stop));
        let mut side = 0i8;
        for _ in 0..IMPACT_ITERATIONS {
            let span = f_hi - f_lo;
            let mut t = if span > T::ZERO {
                lo - f_lo * (hi - lo) / span
            } else {
                (lo + hi) * T::HALF
            };
            if !(t > lo && t < hi) {
                t = (lo + hi) * T::HALF;
            }
            let f = sign * p(t);
            if f > T::ZERO {
                (hi, f_hi) = (t, f);
                if side == -1 {
                    f_lo = f_lo * T::HALF;
                }
                side = -1;
            } else {
                (lo, f_lo) = (t, f);
                if side == 1 {
                    f_hi = f_hi * T::HALF;
                }
                side = 1;
            }
        }
        let theta = lo;
        let mut at = if theta > T::ZERO {
            self.step(y, frac * theta, Contact::Free, carry)?
        } else {
            *y
        };
        // Inelastic impact: on the stop, at rest.
        at[0] = stop;
        at[1] = T::ZERO;
        *carry = T::ZERO;
        let rest = frac * (T::ONE - theta);
        let end = if rest > T::ZERO {
            self.step(&at, rest, contact, carry)?
        } else {
            at
        };
        Ok((end, true))
    }

    /// The state in SI units.
    pub fn state(&self) -> DynamicState<F> {
        self.model.scales.to_si(&self.state)
    }

    /// The state in model units `(xi, w, pi_a, pi_b)`.
    pub fn raw_state(&self) -> [T; 4] {
        self.state
    }

    /// Replaces the state (SI units).
    pub fn set_state(&mut self, s: &DynamicState<F>) {
        self.state = self.model.scales.from_si(s);
    }
}
