//! The FSI model's units and their conversion to SI.
//!
//! Pressure by `dp` above `p_c` (`pi = (p - p_c) / dp`), displacement by
//! the stroke (`xi = x / L`), time by the mechanical scale `T = sqrt(m / c)`,
//! flow by the orifice's full-drop flow at 15 C `Q* = C_d f sqrt(2 dp / rho_15)`
//! (or a power of two times it, [`super::coefficients::flow_shift`]), and
//! velocity by `V = a_x L / T`, where `a_x` balances the two couplings of the
//! Jacobian (`phi / a_x` of the plunger row against `omega sigma` of the
//! pressure rows) so that no entry dwarfs the others. The model state is
//! `y = (xi, w, pi_a, pi_b)`; [`Scales`] converts it to and from a
//! [`DynamicState`] in SI units. [`super::coefficients::Model::new`] derives
//! the scales from a parameter set.

use crate::scalar::{Float, Real};

/// Conversion between the model's units and SI, in the parameters' float
/// type `F` (so that an `f32` firmware never runs soft-double code).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales<F> {
    /// Time unit `T = sqrt(m / c)` \[s\].
    pub time: F,
    /// Length unit: the stroke \[m\].
    pub length: F,
    /// Velocity unit `V = a_x L / T` [m/s].
    pub velocity: F,
    /// Pressure unit `dp` \[Pa\].
    pub pressure: F,
    /// Pressure origin `p_c` \[Pa\].
    pub outlet_pressure: F,
}

/// A state in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicState<F> {
    /// Plunger displacement `x` \[m\].
    pub x: F,
    /// Plunger velocity `v` [m/s].
    pub v: F,
    /// Chamber (a) pressure \[Pa\].
    pub p_a: F,
    /// Chamber (b) pressure \[Pa\].
    pub p_b: F,
}

impl<F: Float> Scales<F> {
    /// Model state `(xi, w, pi_a, pi_b)` to SI.
    pub fn to_si<T: Real>(&self, y: &[T; 4]) -> DynamicState<F> {
        DynamicState {
            x: F::from_real(y[0]) * self.length,
            v: F::from_real(y[1]) * self.velocity,
            p_a: self.outlet_pressure + F::from_real(y[2]) * self.pressure,
            p_b: self.outlet_pressure + F::from_real(y[3]) * self.pressure,
        }
    }

    /// SI state to model state.
    pub fn from_si<T: Real>(&self, s: &DynamicState<F>) -> [T; 4] {
        [
            (s.x / self.length).to_real(),
            (s.v / self.velocity).to_real(),
            ((s.p_a - self.outlet_pressure) / self.pressure).to_real(),
            ((s.p_b - self.outlet_pressure) / self.pressure).to_real(),
        ]
    }
}
