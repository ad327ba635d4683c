//! The fixed-step, fixed-cost integrator of the FSI model: what runs every
//! tick on the controller.
//!
//! A tick of length `dt` is `substeps` steps of one [`Scheme`]; the
//! temperature-dependent coefficients are frozen over a tick (set them for
//! the tick's midpoint to follow a ramp to second order).
//!
//! The cost of a tick is bounded by the configuration. A substep is one
//! step of the scheme: for the shipped SDIRK ([`super::dirk`]) `stages`
//! stage solutions, each a fixed number of Newton iterations on the
//! plunger velocity with both chamber pressures in closed form; for a
//! Rosenbrock scheme one factorisation of the stage matrix with the
//! pressures eliminated ([`super::fsi::FsiFactor`], a 2x2 system) and
//! `stages` right-hand sides. A stop event adds at most one step per
//! substep ([`EVENTS_PER_SUBSTEP`]), and the first substep after an abrupt
//! change is at most [`MAX_GRADED_PIECES`] pieces ([`Twin::tick`]).
//!
//! The twin is generic over the parameters' float type `F` (used for the
//! fluid properties at the sensor rate) and the integration scalar `T`
//! (`f32`, `f64` or fixed point).

use super::coefficients::{Coefficients, Model};
use super::dirk::Dirk;
use super::fsi::Fsi;
use super::schemes::{Scheme, StepError, Stepper};
use super::stops::{Contact, away_from};
use super::units::DynamicState;
use crate::equilibrium::equilibrium;
use crate::error::{ModelError, finite, represent};
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
    /// Tick length \[s\].
    pub tick: f64,
    /// Steps per tick, `1..=MAX_SUBSTEPS`.
    pub substeps: u8,
}

impl TwinConfig {
    /// Checks for a positive, finite tick and `1..=MAX_SUBSTEPS` steps
    /// per tick.
    ///
    /// # Errors
    ///
    /// [`ModelError::OutOfRange`]`("tick")` for a tick that is not a
    /// positive, finite duration, `OutOfRange("substeps")` for a substep
    /// count outside `1..=MAX_SUBSTEPS`.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(self.tick > 0.0 && self.tick.is_finite()) {
            return Err(ModelError::OutOfRange("tick"));
        }
        if self.substeps == 0 || self.substeps > MAX_SUBSTEPS {
            return Err(ModelError::OutOfRange("substeps"));
        }
        Ok(())
    }

    /// The step length in the model's time unit `time_unit` \[s\].
    pub fn step(&self, time_unit: f64) -> f64 {
        self.tick / self.substeps as f64 / time_unit
    }

    /// The default configuration: SDIRK3 ([`super::dirk`]), one step per
    /// 1 ms tick, what [`super::config::choose`] picks for the paper
    /// preset. A device's own configuration is chosen for its parameter
    /// file (the firmware's build script and the CLI do); the trade-off
    /// against the other schemes is in the project's `docs/dynamics.md`.
    pub const SHIPPED: TwinConfig = TwinConfig {
        scheme: Scheme::Sdirk3,
        tick: 1.0e-3,
        substeps: 1,
    };
}

/// What happened during a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TickReport {
    /// Contact state at the end of the tick.
    pub contact: Contact,
    /// The plunger hit a stop during the tick (an inelastic impact).
    pub impact: bool,
    /// The plunger left a stop during the tick (a release).
    pub release: bool,
    /// The tick's first substep was graded (after an abrupt change).
    pub graded: bool,
}

impl TickReport {
    /// The tick did more than its plain substeps (an event or a graded
    /// substep): what a caller with a budget per tick defers work after.
    pub fn eventful(&self) -> bool {
        self.impact || self.release || self.graded
    }
}

/// Events of a piece of a substep (bit set).
const IMPACT: u8 = 1;
/// See [`IMPACT`].
const RELEASE: u8 = 2;

/// Bound on the chamber pressures, in units of `dp` beyond `[p_c, p_p]`,
/// past which a tick is reported as [`StepError::Diverged`]. The physical
/// excursions stay far inside it: a plunger stopped dead on a stop swings a
/// chamber by at most its quasi-steady pumping `sigma w / g_l` plus the
/// water-hammer-like transient, well under one `dp` on every surveyed design
/// (`host-tests/tests/survey.rs` records the reference's largest excursion).
pub const PRESSURE_MARGIN: f64 = 4.0;

/// Pieces of a graded substep (see [`Twin::tick`]): the first is
/// `2^-(pieces - 1)` of the substep, no longer than [`GRADED_FIRST`].
pub const GRADED_FIRST: f64 = 0.5e-6;

/// Most pieces of a graded substep (bounds its cost).
pub const MAX_GRADED_PIECES: u8 = 16;

/// Relative change of the capillary conductance `g_l` between ticks above
/// which the next tick is graded: about 0.3 C of a mineral oil's viscosity
/// (a 1 C/s ramp changes it by 0.003 % per 1 ms tick; a step accepted by the
/// estimator's spike filter by far more).
pub const ABRUPT_CHANGE: f64 = 0.01;

/// Stop events (releases, impacts) located inside one substep; a further
/// one waits for the next substep (an impact then ends on the stop at the
/// substep's end, a release at its start).
pub const EVENTS_PER_SUBSTEP: u8 = 1;

/// The rest of a substep that a stop event left to the next substep, in a
/// fixed-point twin (the cores without an FPU): the state stands at the
/// event (an impact, a release), behind the substep's end by the rest, and
/// the next substep is longer by `frac` (one step of `1 + frac`
/// substeps). An event then costs its substep no second step, and the
/// twin still follows real time: behind by at most two substeps (an event
/// in a substep that took a rest can leave a longer one; a rest beyond two
/// substeps is stepped at once), for as long as events follow each other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Owed<T> {
    /// The rest, in substeps: `0 <= frac <= 2`.
    pub frac: T,
    /// How the rest is taken.
    pub rest: Rest,
}

/// How an owed rest ([`Owed`]) is taken: as the event left the plunger,
/// not as the contact test at the event finds it (the force there is zero
/// to within rounding).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rest {
    /// Nothing owed: the contact test at the substep's start decides.
    Tested,
    /// Held on this stop (an impact).
    Held(Contact),
    /// Free (a touch: an impact the force at the stop pulls off again).
    Free,
    /// Free after a release from this stop; a rest that ends back beyond
    /// it leaves the plunger held for the whole substep, its pressures by
    /// implicit Euler (the release did not last; [`Twin::held_piece`]).
    Released(Contact),
}

impl<T: Real> Owed<T> {
    /// Nothing owed.
    pub const NONE: Owed<T> = Owed {
        frac: T::ZERO,
        rest: Rest::Tested,
    };
}

/// Largest pressure drop [`Twin::set_pressures`] takes, in units of the
/// design's `dp` (either sign).
pub const MAX_DROP: f64 = 64.0;

/// The chamber-pressure bounds for drop `d` (model units): [`PRESSURE_MARGIN`]
/// beyond `[min(0, d), max(0, d)]`.
fn pressure_bounds<T: Real>(d: T) -> (T, T) {
    let m = T::from_f64(PRESSURE_MARGIN);
    (d.min(T::ZERO) - m, d.max(T::ZERO) + m)
}

/// `v` in `T`, as [`represent`], zero included.
fn represent_or_zero<F: Float, T: Real>(v: F, what: &'static str) -> Result<T, ModelError> {
    if v == F::ZERO { Ok(T::ZERO) } else { represent(v, what) }
}

/// What the tick's length decides: the scheme's prepared step, the step
/// times `a_x` and the graded substep's pieces.
struct Timing<T> {
    engine: Engine<T>,
    fine_dirk: Dirk<T>,
    h_a_x: T,
    graded_pieces: u8,
}

impl<T: Real> Timing<T> {
    fn new(config: &TwinConfig, time_unit: f64, c: &Coefficients<T>) -> Self {
        let h = config.step(time_unit);
        let engine = match config.scheme.dirk() {
            Some(tableau) => Engine::Dirk(Dirk::new(tableau, h, c)),
            None => Engine::Generic(Stepper::new(config.scheme, h)),
        };
        let substep = config.tick / config.substeps as f64;
        let mut graded_pieces = 1u8;
        while graded_pieces < MAX_GRADED_PIECES && substep / (1u64 << (graded_pieces - 1)) as f64 > GRADED_FIRST {
            graded_pieces += 1;
        }
        Timing {
            engine,
            fine_dirk: Dirk::new(&super::dirk::FINE, h, c),
            h_a_x: T::from_f64(h) * c.a_x,
            graded_pieces,
        }
    }
}

/// The state a free piece just released from a stop returns when it ends
/// back beyond that stop ([`Twin::free_piece`]).
#[derive(Clone, Copy, Debug)]
enum Back<'a, T> {
    /// The held step's, already taken.
    Held(&'a [T; 4]),
    /// Held from the piece's start by implicit Euler (a rest owed after a
    /// release: no held step was taken).
    Euler(&'a Dirk<T>),
}

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
    /// The scheme of a graded substep's pieces when the engine is a DIRK
    /// (see [`Twin::substep`]; a generic engine grades with itself).
    fine_dirk: Dirk<T>,
    substeps: u8,
    /// The substep length times `a_x` (model units): `xi' = a_x w`.
    h_a_x: T,
    /// [`ABRUPT_CHANGE`] in `T`.
    abrupt_threshold: T,
    /// Pressure bounds `[min(0, D) - PRESSURE_MARGIN, max(0, D) + PRESSURE_MARGIN]`
    /// (`D` the drop, one at the design's).
    pressure_bounds: (T, T),
    state: [T; 4],
    /// What rounding has left out of `xi` so far ([`Real::mul_add_compensated`]).
    xi_carry: T,
    /// The coefficients changed abruptly since the last tick.
    abrupt: bool,
    /// The rest of a substep an event left to the next one ([`Owed`]).
    owed: Owed<T>,
    /// Pieces of a graded substep: the first no longer than [`GRADED_FIRST`].
    graded_pieces: u8,
    config: TwinConfig,
}

impl<F: Float, T: Real> Twin<F, T> {
    /// A twin at rest in the quasi-static equilibrium of `temperature` \[C\].
    ///
    /// # Errors
    ///
    /// * the configuration is refused ([`TwinConfig::validate`]);
    /// * the parameters give no finite, positive unit of velocity
    ///   ([`Model::new`]);
    /// * the oil model refuses `temperature`, or the equilibrium there is
    ///   not finite ([`crate::equilibrium::equilibrium`]);
    /// * a coefficient of the model does not fit `T`
    ///   ([`Model::coefficients`]: `NotRepresentable`, fixed point only).
    pub fn new(params: &Params<F>, config: TwinConfig, temperature: F) -> Result<Self, ModelError> {
        config.validate()?;
        let model = Model::new(params)?;
        let eq = equilibrium(params, temperature)?;
        let coefficients: Coefficients<T> = model.coefficients(&eq.fluid)?;
        let timing = Timing::new(&config, model.scales.time.to_f64(), &coefficients);
        Ok(Twin {
            fine_dirk: timing.fine_dirk,
            h_a_x: timing.h_a_x,
            abrupt_threshold: T::from_f64(ABRUPT_CHANGE),
            coefficients,
            engine: timing.engine,
            substeps: config.substeps,
            pressure_bounds: pressure_bounds(T::ONE),
            state: model.equilibrium_state(&eq),
            xi_carry: T::ZERO,
            abrupt: false,
            owed: Owed::NONE,
            graded_pieces: timing.graded_pieces,
            model,
            config,
        })
    }

    /// Changes the tick to `tick` \[s\], keeping the scheme, the substeps per
    /// tick, the state and the coefficients: a tick that adapts, for a
    /// caller whose steps are not whole ticks (an FMU's communication
    /// steps). A shorter tick is at least as accurate as the configured
    /// one (the same substeps, each shorter); the result equals a twin
    /// built with `tick` from the start and given the same state. A rest
    /// an event left to the next substep ([`Owed`], fixed point) keeps its
    /// length in time, up to two of the new substeps. Costs a few `f64`
    /// operations (the scheme's step prepared again), nothing per tick.
    ///
    /// # Errors
    ///
    /// `OutOfRange("tick")` for a tick that is not a positive, finite
    /// duration; nothing changes then.
    pub fn set_tick(&mut self, tick: f64) -> Result<(), ModelError> {
        let config = TwinConfig { tick, ..self.config };
        config.validate()?;
        let timing = Timing::new(&config, self.model.scales.time.to_f64(), &self.coefficients);
        // A rest owed in substeps of the old tick, in the new one's (at most
        // two of them: the longest step the twin takes stays three).
        if self.owed.frac > T::ZERO {
            let frac = self.owed.frac.to_f64() * self.config.tick / tick;
            self.owed.frac = T::from_f64(frac.min(2.0));
        }
        self.engine = timing.engine;
        self.fine_dirk = timing.fine_dirk;
        self.h_a_x = timing.h_a_x;
        self.graded_pieces = timing.graded_pieces;
        self.config = config;
        Ok(())
    }

    /// Sets the supply and outlet pressures `p_p`, `p_c` \[Pa\] for the
    /// following ticks: the drop across the compensator changes from the
    /// design's `dp` (`operating.pressure_drop`, the model's pressure
    /// unit, which stays). Per call: two divisions and the chamber
    /// pressures re-referred to the new outlet (they are continuous: the
    /// state in SI units does not move); per tick nothing changes
    /// ([`Coefficients::drop`] enters the stage equations as the supply
    /// pressure and the chambers' drive, where the design's drop had one).
    /// A change of the drop or of the outlet by more than
    /// [`ABRUPT_CHANGE`] of `dp` makes the next tick start graded (the
    /// chambers' pressures re-equilibrate in microseconds).
    ///
    /// The drop may be any within `[-MAX_DROP, MAX_DROP]` times `dp`: the
    /// throttle laws are odd in their drops, so a reversed drop reverses
    /// the flows. Fixed point keeps its documented ranges only for drops
    /// up to the design's (`D <= 1`).
    ///
    /// # Errors
    ///
    /// `NonFinite` naming the pressure for a value that is not finite,
    /// `OutOfRange("pressure drop")` beyond [`MAX_DROP`] times `dp`, and
    /// `NotRepresentable` when `T` cannot hold the drop or the shifted
    /// chamber pressures. Nothing changes then.
    pub fn set_pressures(&mut self, supply: F, outlet: F) -> Result<(), ModelError> {
        let scales = &self.model.scales;
        let drop = finite(
            finite(supply, "supply pressure")? - finite(outlet, "outlet pressure")?,
            "pressure drop",
        )? / scales.pressure;
        if !(drop.abs() <= F::from_f64(MAX_DROP)) {
            return Err(ModelError::OutOfRange("pressure drop"));
        }
        let shift = (scales.outlet_pressure - outlet) / scales.pressure;
        let d: T = represent_or_zero(drop, "pressure drop")?;
        let s: T = represent_or_zero(shift, "outlet pressure")?;
        let (pa, pb) = (self.state[2] + s, self.state[3] + s);
        if !(pa.is_finite() && pb.is_finite()) {
            return Err(ModelError::NotRepresentable("outlet pressure"));
        }
        let change = (d - self.coefficients.drop).abs() + s.abs();
        self.abrupt |= change > self.abrupt_threshold;
        self.coefficients.drop = d;
        self.state[2] = pa;
        self.state[3] = pb;
        self.model.scales.outlet_pressure = outlet;
        self.pressure_bounds = pressure_bounds(d);
        Ok(())
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

    /// Sets the oil temperature \[C\] for the following ticks. On error the
    /// previous coefficients stay in force.
    ///
    /// # Errors
    ///
    /// The oil model refuses `temperature` ([`crate::fluid::Oil::state`]),
    /// or its coefficients are refused as by [`Twin::set_fluid`].
    pub fn set_temperature(&mut self, temperature: F) -> Result<(), ModelError> {
        let fluid = self.model.params().oil.state(temperature)?;
        self.set_fluid(&fluid)
    }

    /// As [`Twin::set_temperature`] from an already evaluated fluid state.
    /// A change of the capillary conductance by more than
    /// [`ABRUPT_CHANGE`] (relative), or of the flow unit
    /// ([`super::coefficients::flow_shift`]), makes the next tick start graded.
    ///
    /// # Errors
    ///
    /// The fluid's coefficients `q_t`, `g_l` are not finite (`NonFinite`),
    /// or do not fit `T` in any flow unit (`NotRepresentable`, fixed point
    /// only); see [`Coefficients::set_hydraulic`]. Nothing changes then.
    pub fn set_fluid(&mut self, fluid: &FluidState<F>) -> Result<(), ModelError> {
        let (before, unit) = (self.coefficients.g_l, self.coefficients.flow_shift);
        self.coefficients.set_hydraulic(&self.model, fluid)?;
        let change = (self.coefficients.g_l - before).abs();
        self.abrupt |= change > self.abrupt_threshold * before || self.coefficients.flow_shift != unit;
        Ok(())
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
    ///   throughout). If the force at its end pulls away, the plunger is
    ///   released where the force, interpolated over the step, crosses zero:
    ///   held up to it, free after it;
    /// * moving freely, a substep that ends beyond a stop is redone up to
    ///   the impact (located on the step's cubic Hermite interpolant of
    ///   `xi`), the plunger stops there (inelastic: `w = 0`), and the rest of
    ///   the substep is held, or free if the force there pulls it off again
    ///   (a touch).
    ///
    /// After an abrupt change of the coefficients ([`ABRUPT_CHANGE`], set
    /// by [`Twin::set_fluid`]) the tick's first substep is graded: taken in
    /// pieces growing geometrically from at most [`GRADED_FIRST`], so that
    /// the transients the change starts (pressures re-equilibrating in
    /// microseconds, the plunger accelerating into its new motion) are
    /// followed, not stepped over.
    ///
    /// Whatever the tick's phase, a release and an impact are placed where
    /// the force and the motion put them, not at a substep's boundary. The
    /// cost is bounded: a substep is one step of the scheme; one with
    /// events at most [`EVENTS_PER_SUBSTEP`] of them, each adding one free
    /// or one held step; a graded substep at most [`MAX_GRADED_PIECES`]
    /// such pieces (host simulations of abrupt steps: the estimator never
    /// changes the coefficients abruptly). In fixed point (the cores
    /// without an FPU, where a step is the tick's cost) an event's rest is
    /// not stepped in its substep but added to the next one ([`Owed`]): a
    /// substep is then one step with or without an event (two when a rest
    /// beyond two substeps is stepped at once, or a held rest is pulled
    /// off at both ends), and the state at the tick's end may stand up to
    /// two substeps behind it, at the event.
    ///
    /// # Errors
    ///
    /// * [`StepError::Diverged`]: a chamber pressure is more than
    ///   [`PRESSURE_MARGIN`] `dp` outside `[p_c, p_p]` (the scheme is
    ///   unstable at this step);
    /// * [`StepError::NonFinite`]: the state is not finite;
    /// * [`StepError::Singular`]: a Rosenbrock scheme's stage matrix could
    ///   not be factorised (the SDIRK schemes never fail this way).
    ///
    /// The state is then the last good substep's.
    pub fn tick(&mut self) -> Result<TickReport, StepError> {
        let mut events = 0u8;
        let graded = self.abrupt;
        self.abrupt = false;
        for k in 0..self.substeps {
            let mut carry = self.xi_carry;
            let mut owed = Owed::NONE;
            let (next, e) = self.substep(&self.state, &mut carry, graded && k == 0, self.owed, &mut owed)?;
            self.check(&next)?;
            events |= e;
            self.state = next;
            self.xi_carry = carry;
            if T::SATURATES {
                self.owed = owed;
            }
        }
        Ok(TickReport {
            contact: self.coefficients.contact(&self.state),
            impact: events & IMPACT != 0,
            release: events & RELEASE != 0,
            graded,
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
    fn step(&self, y: &[T; 4], frac: T, contact: Contact, xi_carry: &mut T, fine: bool) -> Result<[T; 4], StepError> {
        let c = &self.coefficients;
        match &self.engine {
            Engine::Dirk(d) => Ok(if fine { &self.fine_dirk } else { d }.step(c, y, frac, contact, xi_carry)),
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

    /// `frac` of a substep from `y`; `carry` is `xi`'s compensated-summation carry.
    /// `fine`: a piece of a graded substep (see [`Twin::substep`]).
    /// `owed`: where an event's rest is left to the next substep.
    fn piece(
        &self,
        y: &[T; 4],
        frac: T,
        carry: &mut T,
        fine: bool,
        owed: &mut Owed<T>,
    ) -> Result<([T; 4], u8), StepError> {
        match self.coefficients.contact(y) {
            Contact::Free => self.free_piece(y, frac, carry, EVENTS_PER_SUBSTEP, fine, None, owed),
            held => self.held_piece(y, frac, held, carry, EVENTS_PER_SUBSTEP, fine, owed),
        }
    }

    /// An event's rest of `rest` substeps is left to the next substep
    /// ([`Owed`]): fixed point, a plain substep's SDIRK step, and a rest of
    /// at most two substeps (a rest longer than that, left by a substep
    /// that was itself lengthened, is stepped at once, so that the twin is
    /// never more than two substeps behind, nor a step longer than three).
    fn defers(&self, rest: T, fine: bool) -> bool {
        T::SATURATES && !fine && rest <= T::TWO && matches!(self.engine, Engine::Dirk(_))
    }

    /// One substep from `y`; after an abrupt change of the coefficients the
    /// substep is taken in pieces growing geometrically from
    /// `2^-(pieces - 1)` of it (at most [`GRADED_FIRST`]), so that the transient the
    /// change starts (the pressures re-equilibrating, the plunger
    /// accelerating into its new motion) is followed rather than stepped
    /// over.
    ///
    /// `from`: the rest an event of the last substep left to this one
    /// (taken with the substep: one step of `1 + from.frac` substeps, or
    /// with a graded substep's last piece); `owed`: the rest this one
    /// leaves to the next.
    fn substep(
        &self,
        y: &[T; 4],
        carry: &mut T,
        graded: bool,
        from: Owed<T>,
        owed: &mut Owed<T>,
    ) -> Result<([T; 4], u8), StepError> {
        // Only fixed point leaves a rest ([`Twin::defers`]): a float twin
        // compiles none of this.
        let from = if T::SATURATES { from } else { Owed::NONE };
        if !graded {
            let frac = T::ONE + from.frac;
            let events = EVENTS_PER_SUBSTEP;
            return match (from.rest, &self.engine) {
                (Rest::Released(stop), Engine::Dirk(d)) => {
                    self.free_piece(y, frac, carry, events, false, Some((stop, Back::Euler(d))), owed)
                }
                (Rest::Free | Rest::Released(_), _) => self.free_piece(y, frac, carry, events, false, None, owed),
                (Rest::Held(stop), _) if stop != Contact::Free => {
                    self.held_piece(y, frac, stop, carry, events, false, owed)
                }
                _ => self.piece(y, frac, carry, false, owed),
            };
        }
        let mut frac = T::ONE;
        for _ in 1..self.graded_pieces {
            frac *= T::HALF;
        }
        // Graded pieces are fine: they leave nothing owed. The last takes
        // the rest owed to this substep.
        let mut none = Owed::NONE;
        let (mut state, mut events) = (*y, 0u8);
        for k in 0..self.graded_pieces {
            let piece = if k + 1 == self.graded_pieces {
                frac + from.frac
            } else {
                frac
            };
            let (next, e) = self.piece(&state, piece, carry, true, &mut none)?;
            state = next;
            events |= e;
            if k > 0 {
                frac = frac + frac;
            }
        }
        Ok((state, events))
    }

    /// Free motion from `y` over `frac` of a substep. A step that ends
    /// beyond a stop stops at the impact (located on its cubic Hermite
    /// interpolant; the pressures there interpolated over the step) at rest
    /// (inelastic), and the rest of the piece is held (or free again after
    /// a touch). With no `events` left the rest is held. `released`: the
    /// stop the piece was just released from and the state held on it to
    /// the piece's end; a step that ends back beyond that stop returns that
    /// held state (the release did not last: see [`Twin::held_piece`]).
    /// Returns the state and the events.
    // The piece's state, length, carries and budget: one recursion's
    // arguments, not a record worth naming.
    #[allow(clippy::too_many_arguments)]
    fn free_piece(
        &self,
        y: &[T; 4],
        frac: T,
        carry: &mut T,
        events: u8,
        fine: bool,
        released: Option<(Contact, Back<'_, T>)>,
        owed: &mut Owed<T>,
    ) -> Result<([T; 4], u8), StepError> {
        let mut tried = *carry;
        let next = self.step(y, frac, Contact::Free, &mut tried, fine)?;
        let (stop, contact) = if next[0] < T::ZERO {
            (T::ZERO, Contact::Closed)
        } else if next[0] > T::ONE {
            (T::ONE, Contact::Open)
        } else {
            *carry = tried;
            return Ok((next, 0));
        };
        if let Some((from, back)) = released
            && from == contact
        {
            *carry = T::ZERO;
            let held = match back {
                Back::Held(held) => *held,
                Back::Euler(d) if T::SATURATES => d.held_euler(&self.coefficients, &[y[0], T::ZERO, y[2], y[3]], frac),
                Back::Euler(_) => *y,
            };
            return Ok((held, RELEASE | IMPACT));
        }
        *carry = T::ZERO;
        let theta = self.impact_fraction(y, &next, frac, stop);
        // The pressures at the impact, interpolated over the step.
        let mut at = *y;
        at[2] += theta * (next[2] - y[2]);
        at[3] += theta * (next[3] - y[3]);
        at[0] = stop;
        at[1] = T::ZERO;
        let rest = frac * (T::ONE - theta);
        if !(rest > T::ZERO) {
            return Ok((at, IMPACT));
        }
        // Held for the rest, unless the plunger travelled before the impact
        // and the force there pulls it off the stop again (a touch).
        let touch = theta > T::ZERO && away_from(&self.coefficients, contact, &at) > T::ZERO;
        if self.defers(rest, fine) {
            *owed = Owed {
                frac: rest,
                rest: if touch { Rest::Free } else { Rest::Held(contact) },
            };
            return Ok((at, IMPACT));
        }
        if events == 0 {
            // No event left: held for the rest (its pressures relax with the
            // plunger at rest, never with the pumping of a motion the stop
            // forbids); a lift-off waits for the next substep. Fixed point
            // (the cores without an FPU) holds it by implicit Euler: the
            // substep's third step (a touch: an impact, a free rest, an
            // impact again) made a Cortex-M0 tick over three plain ones.
            if T::SATURATES
                && !fine
                && let Engine::Dirk(d) = &self.engine
            {
                *carry = T::ZERO;
                return Ok((d.held_euler(&self.coefficients, &at, rest), IMPACT));
            }
            let (end, _) = self.held_piece(&at, rest, contact, carry, 0, fine, owed)?;
            return Ok((end, IMPACT));
        }
        let (end, e) = if touch {
            self.free_piece(&at, rest, carry, events - 1, fine, None, owed)?
        } else {
            self.held_piece(&at, rest, contact, carry, events - 1, fine, owed)?
        };
        Ok((end, e | IMPACT))
    }

    /// Held on a stop from `y` over `frac` of a substep: the plunger at
    /// rest, the pressures in one step. When the held force pulls away at
    /// the step's end and `events` remain, the plunger is released where
    /// the force, interpolated linearly over the step, crosses zero (exact
    /// for the slow drift of a ramp; after an abrupt change the graded
    /// tick's short pieces follow the transient) and the piece goes on free
    /// from there. In a plain substep, a free rest that ends back beyond the
    /// same stop (the force barely pulls: the motion's own pressures push
    /// the plunger back) leaves the plunger held for the whole piece, with
    /// the held step's state: it did not leave in the net, and the held
    /// rest after the bounce would cost a third step for a motion below the
    /// step's resolution.
    // The piece's state, length, carries and budget: one recursion's
    // arguments, not a record worth naming.
    #[allow(clippy::too_many_arguments)]
    fn held_piece(
        &self,
        y: &[T; 4],
        frac: T,
        held: Contact,
        carry: &mut T,
        events: u8,
        fine: bool,
        owed: &mut Owed<T>,
    ) -> Result<([T; 4], u8), StepError> {
        let c = &self.coefficients;
        // On the stop exactly: nothing is left to carry.
        *carry = T::ZERO;
        let away = |s: &[T; 4]| away_from(c, held, s);
        let y0 = [y[0], T::ZERO, y[2], y[3]];
        let end = self.step(&y0, frac, held, carry, fine)?;
        let (f0, f1) = (away(&y0), away(&end));
        if f1 <= T::ZERO || events == 0 {
            return Ok((end, 0));
        }
        if f0 > T::ZERO {
            // Held although pulled away at the start (the piece after an
            // impact at its start): released there.
            let back = (!fine).then_some((held, Back::Held(&end)));
            let (end, e) = self.free_piece(&y0, frac, carry, events - 1, fine, back, owed)?;
            return Ok((end, e | RELEASE));
        }
        // Released where the held force, interpolated linearly over the
        // step, crosses zero. The pressures there: interpolated over the
        // held step (as at an impact) in a plain substep, where they drift
        // slowly; a step to the release in a graded piece, whose transient
        // the interpolation would cut short.
        let theta = f0 / (f0 - f1);
        let at = if fine && theta > T::ZERO {
            let mut no_carry = T::ZERO;
            self.step(&y0, frac * theta, held, &mut no_carry, fine)?
        } else {
            let mut at = y0;
            at[2] += theta * (end[2] - y0[2]);
            at[3] += theta * (end[3] - y0[3]);
            at
        };
        let rest = frac * (T::ONE - theta);
        if !(rest > T::ZERO) {
            return Ok((at, RELEASE));
        }
        if self.defers(rest, fine) {
            *owed = Owed {
                frac: rest,
                rest: Rest::Released(held),
            };
            return Ok((at, RELEASE));
        }
        let back = (!fine).then_some((held, Back::Held(&end)));
        let (end, e) = self.free_piece(&at, rest, carry, events - 1, fine, back, owed)?;
        Ok((end, e | RELEASE))
    }

    /// The fraction of a free step `y -> next` of `frac` substeps at which
    /// `xi` reaches `stop`: the chord's crossing, refined by one Newton step
    /// on the step's cubic Hermite interpolant (no model evaluation).
    fn impact_fraction(&self, y: &[T; 4], next: &[T; 4], frac: T, stop: T) -> T {
        let hx = self.h_a_x * frac;
        // The cubic Hermite interpolant of `xi - stop` over the step, as
        // `((c3 t + c2) t + c1) t + c0`, and one Newton step on it from the
        // chord's crossing (the chord alone is exact for a creeping plunger).
        let (e0, e1) = (y[0] - stop, next[0] - stop);
        let (d0, d1) = (hx * y[1], hx * next[1]);
        let c2 = (e1 - e0) * T::TWO + (e1 - e0) - (d0 + d0) - d1;
        let c3 = (e0 - e1) * T::TWO + d0 + d1;
        let span = e1 - e0;
        if span == T::ZERO {
            return T::ZERO;
        }
        let t = (-e0 / span).clamp_to(T::ZERO, T::ONE);
        let p = ((c3 * t + c2) * t + d0) * t + e0;
        let dp = (c3 * (t + t + t) + (c2 + c2)) * t + d0;
        // Newton only where it moves by at most the whole step (the
        // quotient then stays within [-1, 1], in range for fixed point,
        // and a flat interpolant never divides by zero).
        if dp != T::ZERO && p.abs() <= dp.abs() {
            let newton = t - p / dp;
            if newton >= T::ZERO && newton <= T::ONE {
                return newton;
            }
        }
        t
    }

    /// The state in SI units.
    pub fn state(&self) -> DynamicState<F> {
        self.model.scales.to_si(&self.state)
    }

    /// The state in model units `(xi, w, pi_a, pi_b)`.
    pub fn raw_state(&self) -> [T; 4] {
        self.state
    }

    /// Replaces the state (SI units); the compensated carry of `xi` starts
    /// afresh.
    pub fn set_state(&mut self, s: &DynamicState<F>) {
        self.state = self.model.scales.from_si(s);
        self.xi_carry = T::ZERO;
        self.owed = Owed::NONE;
    }

    /// What the next ticks depend on besides the configuration and the
    /// coefficients (which follow from the last temperature and pressures
    /// set): the state
    /// in model units, the compensated carry of `xi` and whether the next
    /// tick is graded. With [`Twin::restore`] it saves and restores a twin
    /// exactly (an FMU's state, rolled back by a co-simulation master).
    pub fn memory(&self) -> TwinMemory<T> {
        TwinMemory {
            state: self.state,
            xi_carry: self.xi_carry,
            abrupt: self.abrupt,
            owed: self.owed,
        }
    }

    /// Puts back what [`Twin::memory`] saved: the twin, with the same
    /// parameters, configuration, last temperature and last pressures, then ticks exactly
    /// as the one it was saved from.
    pub fn restore(&mut self, memory: &TwinMemory<T>) {
        self.state = memory.state;
        self.xi_carry = memory.xi_carry;
        self.abrupt = memory.abrupt;
        self.owed = memory.owed;
    }
}

/// A twin's memory ([`Twin::memory`]): everything its next ticks depend on
/// besides the parameters, the configuration and the last temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinMemory<T> {
    /// State `(xi, w, pi_a, pi_b)` in model units.
    pub state: [T; 4],
    /// What rounding has left out of `xi` so far.
    pub xi_carry: T,
    /// The next tick starts graded (the coefficients changed abruptly).
    pub abrupt: bool,
    /// The rest of a substep an event left to the next tick (fixed point
    /// only; [`Owed::NONE`] in floating point).
    pub owed: Owed<T>,
}

impl<F: Float, T: Real> super::Dynamic<F> for Twin<F, T> {
    fn set_temperature(&mut self, temperature: F) -> Result<(), ModelError> {
        Twin::set_temperature(self, temperature)
    }
    fn tick(&mut self) -> Result<TickReport, StepError> {
        Twin::tick(self)
    }
    fn state(&self) -> DynamicState<F> {
        Twin::state(self)
    }
}
