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

use super::fsi::{Coefficients, Contact, DynamicState, Fsi, Model, apply_stops, contact_for};
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
        scheme: Scheme::Ros3,
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

/// The dynamic twin.
#[derive(Clone, Copy, Debug)]
pub struct Twin<F, T> {
    model: Model<F>,
    coefficients: Coefficients<T>,
    stepper: Stepper<T>,
    substeps: u8,
    state: [T; 4],
    config: TwinConfig,
}

impl<F: Float, T: Real> Twin<F, T> {
    /// A twin at rest in the quasi-static equilibrium of `temperature` [C].
    pub fn new(params: &Params<F>, config: TwinConfig, temperature: F) -> Result<Self, ModelError> {
        config.validate()?;
        let model = Model::new(params)?;
        let eq = equilibrium(params, temperature)?;
        Ok(Twin {
            coefficients: model.coefficients(&eq.fluid)?,
            stepper: Stepper::new(config.scheme, config.step(model.scales.time.to_f64())),
            substeps: config.substeps,
            state: model.equilibrium_state(&eq),
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

    /// Advances one tick. On a failed step the state is left at the last
    /// good substep and the error is returned.
    ///
    /// Stops are handled per substep:
    /// * on a stop, the plunger stays held only if both the actual static
    ///   force and the quasi-steady one (the force the pressures settle to
    ///   within tens of microseconds) push into the stop; otherwise it is
    ///   released at the substep's start. A held substep whose final force
    ///   pulls away is redone in free motion from its start: the pressure
    ///   transient that flips the force is much shorter than a substep, so
    ///   the release belongs at the start (interpolating the force would
    ///   place it far too late). A release substep that ends a little beyond
    ///   the stop but moving away from it is put on the stop, velocity kept;
    /// * a free substep that ends beyond a stop, or on it moving into it,
    ///   ends on it at rest (inelastic impact).
    ///
    /// The cost is bounded: one scheme step per substep, two when a held
    /// substep turns out to release (the quasi-steady test makes that rare).
    pub fn tick(&mut self) -> Result<TickReport, StepError> {
        let mut impact = false;
        for _ in 0..self.substeps {
            let (next, hit) = self.substep()?;
            impact |= hit;
            self.state = next;
        }
        Ok(TickReport {
            contact: self.coefficients.contact(&self.state),
            impact,
        })
    }

    fn substep(&self) -> Result<([T; 4], bool), StepError> {
        let c = &self.coefficients;
        let mut contact = c.contact(&self.state);
        if contact != Contact::Free {
            let [xi, w, ..] = self.state;
            if contact_for(xi, w, c.quasi_steady_force(xi)) != contact {
                contact = Contact::Free;
            }
        }
        let held_at_start = c.contact(&self.state);
        if contact != Contact::Free {
            let held = Fsi {
                coefficients: c,
                contact,
            };
            let mut next = self.stepper.step(&held, &self.state)?;
            // The stop's reaction cancels the motion exactly.
            next[0] = self.state[0];
            next[1] = T::ZERO;
            if c.contact(&next) == contact {
                return Ok((next, false));
            }
        }
        let free = Fsi {
            coefficients: c,
            contact: Contact::Free,
        };
        let mut next = self.stepper.step(&free, &self.state)?;
        let [xi, w, ..] = &mut next;
        let leaving = match held_at_start {
            Contact::Closed => *xi < T::ZERO && *w > T::ZERO,
            Contact::Open => *xi > T::ONE && *w < T::ZERO,
            Contact::Free => false,
        };
        if leaving {
            *xi = xi.clamp_to(T::ZERO, T::ONE);
            return Ok((next, false));
        }
        let hit = apply_stops(xi, w);
        Ok((next, hit))
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
