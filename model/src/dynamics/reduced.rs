//! The singular-perturbation limit of the FSI model: chamber pressures
//! quasi-steady (`C_a, C_b -> 0`), the plunger keeps its inertia.
//!
//! With the chambers' flow balances solved for a plunger velocity `w`
//! (orifice law without regularisation), both chambers give the same
//! quadratic, `g_l s^2 + q_t s - (g_l - sigma w) = 0`, with
//! `s = sqrt(1 - pi_a) = sqrt(pi_b)`:
//!
//! ```text
//! s(w)        = 2 (g_l - sigma w) / (q_t + sqrt(q_t^2 + 4 g_l (g_l - sigma w)))
//! pi_b - pi_a = 2 s^2 - 1
//! ```
//!
//! so the reduced model is two states `(xi, w)` whose pressure force
//! carries the hydraulic damping `d(2 s^2 - 1)/dw = -4 s sigma / (2 g_l s + q_t)`.
//! It is valid while `sigma w < g_l` (the plunger does not outrun the
//! capillaries' flow); beyond, `s` is held at zero. The root is
//! [`Coefficients::quasi_steady`], the one the full model's
//! [`Coefficients::quasi_steady_force`] takes at rest.

use super::TwinConfig;
use super::coefficients::{Coefficients, Model};
use super::schemes::{OdeSystem, StepError, Stepper, dense_linearisation};
use super::stops::{Contact, apply_stops, contact_for};
use super::units::DynamicState;
use crate::equilibrium::equilibrium;
use crate::error::ModelError;
use crate::linalg::Lu;
use crate::params::Params;
use crate::scalar::{Float, Real};

/// The reduced model in one contact state.
#[derive(Clone, Copy, Debug)]
pub struct ReducedFsi<'a, T> {
    /// Coefficients at the step's temperature.
    pub coefficients: &'a Coefficients<T>,
    /// Contact state, frozen over the step.
    pub contact: Contact,
}

impl<T: Real> ReducedFsi<'_, T> {
    /// Net static force at rest: [`Coefficients::quasi_steady_force`].
    pub fn static_force(&self, xi: T) -> T {
        self.coefficients.quasi_steady_force(xi)
    }
}

impl<T: Real> OdeSystem<T, 2> for ReducedFsi<'_, T> {
    type Factor = Lu<T, 2>;

    fn linearise(&self, y: &[T; 2], shift: T) -> Option<([T; 2], Lu<T, 2>)> {
        dense_linearisation(self, y, shift)
    }

    fn rhs(&self, y: &[T; 2]) -> [T; 2] {
        if self.contact != Contact::Free {
            return [T::ZERO; 2];
        }
        let c = self.coefficients;
        let (s, _) = c.quasi_steady(y[1]);
        let force = c.phi_over_a_x * (s * s + s * s - c.supply()) - (c.xi0 + y[0]) * c.inv_a_x;
        [c.a_x * y[1], force - c.two_zeta * y[1]]
    }

    fn jacobian(&self, y: &[T; 2]) -> [[T; 2]; 2] {
        if self.contact != Contact::Free {
            return [[T::ZERO; 2]; 2];
        }
        let c = self.coefficients;
        let (s, ds) = c.quasi_steady(y[1]);
        let four = T::from_f64(4.0);
        [
            [T::ZERO, c.a_x],
            [-c.inv_a_x, c.phi_over_a_x * four * s * ds - c.two_zeta],
        ]
    }
}

/// The reduced model as a fixed-step twin (same configuration and ticks as
/// [`super::Twin`]).
#[derive(Clone, Copy, Debug)]
pub struct ReducedTwin<F, T> {
    model: Model<F>,
    coefficients: Coefficients<T>,
    stepper: Stepper<T>,
    substeps: u8,
    state: [T; 2],
}

impl<F: Float, T: Real> ReducedTwin<F, T> {
    /// At rest in the equilibrium of `temperature` \[C\].
    ///
    /// # Errors
    ///
    /// As [`super::Twin::new`].
    pub fn new(params: &Params<F>, config: TwinConfig, temperature: F) -> Result<Self, ModelError> {
        config.validate()?;
        let model = Model::new(params)?;
        let eq = equilibrium(params, temperature)?;
        let y: [T; 4] = model.equilibrium_state(&eq);
        Ok(ReducedTwin {
            coefficients: model.coefficients(&eq.fluid)?,
            stepper: Stepper::new(config.scheme.generic(), config.step(model.scales.time.to_f64())),
            substeps: config.substeps,
            state: [y[0], T::ZERO],
            model,
        })
    }

    /// Sets the oil temperature \[C\] for the following ticks.
    ///
    /// # Errors
    ///
    /// As [`super::Twin::set_temperature`]; the previous coefficients stay
    /// in force then.
    pub fn set_temperature(&mut self, temperature: F) -> Result<(), ModelError> {
        let fluid = self.model.params().oil.state(temperature)?;
        self.coefficients.set_hydraulic(&self.model, &fluid)
    }

    /// Advances one tick. Stops are simpler than [`super::Twin::tick`]'s:
    /// a substep starting on a stop with the quasi-steady force pushing
    /// into it stays there, otherwise it moves freely and a substep ending
    /// beyond a stop ends on it at rest (no release redo: the pressures
    /// have no transient here).
    ///
    /// # Errors
    ///
    /// As [`Stepper::step`]: `Singular` when a Rosenbrock stage matrix
    /// cannot be factorised, `NonFinite` when the state is not finite. The
    /// state is then the last good substep's.
    pub fn tick(&mut self) -> Result<(), StepError> {
        for _ in 0..self.substeps {
            let probe = ReducedFsi {
                coefficients: &self.coefficients,
                contact: Contact::Free,
            };
            let contact = contact_for(self.state[0], self.state[1], probe.static_force(self.state[0]));
            let sys = ReducedFsi {
                coefficients: &self.coefficients,
                contact,
            };
            let mut next = self.stepper.step(&sys, &self.state)?;
            if contact != Contact::Free {
                next = [self.state[0], T::ZERO];
            }
            let [xi, w] = &mut next;
            apply_stops(xi, w);
            self.state = next;
        }
        Ok(())
    }

    /// The state in SI units, with the quasi-steady pressures.
    pub fn state(&self) -> DynamicState<F> {
        let (s, _) = self.coefficients.quasi_steady(self.state[1]);
        let pb = s * s;
        self.model
            .scales
            .to_si(&[self.state[0], self.state[1], self.coefficients.supply() - pb, pb])
    }
}

impl<F: Float, T: Real> super::Dynamic<F> for ReducedTwin<F, T> {
    fn set_temperature(&mut self, temperature: F) -> Result<(), ModelError> {
        ReducedTwin::set_temperature(self, temperature)
    }
    /// The report's contact is the state's at the tick's end; the reduced
    /// twin locates no events (`impact`, `release`, `graded` are false).
    fn tick(&mut self) -> Result<super::TickReport, StepError> {
        ReducedTwin::tick(self)?;
        let probe = ReducedFsi {
            coefficients: &self.coefficients,
            contact: Contact::Free,
        };
        Ok(super::TickReport {
            contact: contact_for(self.state[0], self.state[1], probe.static_force(self.state[0])),
            impact: false,
            release: false,
            graded: false,
        })
    }
    fn state(&self) -> DynamicState<F> {
        ReducedTwin::state(self)
    }
}
