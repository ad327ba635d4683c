//! The reduced-order fluid-structure model (paper section 4, Eqs. 33-36,
//! signs of MODEL.md section 6), nondimensionalised for fixed point.
//!
//! Dimensional form:
//!
//! ```text
//! C_a dp_a/dt = Q_turb(p_p - p_a) - (p_a - p_c) / R_l + A_p v
//! C_b dp_b/dt = (p_p - p_b) / R_l - Q_turb(p_b - p_c) - A_p v
//! m dv/dt     = A_p (p_b - p_a) - b v - c (x0 + x)        (+ stop reactions)
//! C_a = (V_a0 - A_p x) / beta_e,  C_b = (V_b0 + A_p x) / beta_e
//! ```
//!
//! Units: pressure by `dp` above `p_c` (`pi = (p - p_c) / dp`), displacement
//! by the stroke (`xi = x / L`), time by the mechanical scale
//! `T = sqrt(m / c)`, flow by the orifice's full-drop flow at 15 C
//! `Q* = C_d f sqrt(2 dp / rho_15)`, and velocity by `V = a_x L / T`, where
//! `a_x` balances the two couplings of the Jacobian (`phi / a_x` of the
//! plunger row against `omega sigma` of the pressure rows) so that no entry
//! dwarfs the others. With state `y = (xi, w, pi_a, pi_b)`:
//!
//! ```text
//! xi'   = a_x w
//! w'    = (phi (pi_b - pi_a) - xi0 - xi) / a_x - 2 zeta w
//! pi_a' = omega_a(xi) (q_t r(1 - pi_a) - g_l pi_a + sigma w)
//! pi_b' = omega_b(xi) (g_l (1 - pi_b) - q_t r(pi_b) - sigma w)
//! omega_a = omega_a0 / (1 - eps_a xi),  omega_b = omega_b0 / (1 + eps_b xi)
//! ```
//!
//! with `r` the C1 regularised root ([`crate::throttle::regularised_root`],
//! transition at `u_tr = 1e-5` of `dp`: equilibria move by `u_tr^2 / (4 u^2)` of
//! a branch flow at orifice drop `u`, 2.5e-7 even at `u = 0.01`), `phi = A_p dp / (c L)`,
//! `2 zeta = b / sqrt(c m)`, `q_t = sqrt(rho_15 / rho)` and
//! `g_l = dp / (R_l Q*)` (the only temperature-dependent coefficients).
//!
//! End stops are inelastic: on a stop, with the net static force pushing
//! into it and no velocity away from it, the plunger is held (`xi' = w' = 0`,
//! [`Contact`]); a step that crosses a stop ends on it with `w = 0`.

use super::schemes::OdeSystem;
use crate::equilibrium::Equilibrium;
use crate::error::{ModelError, finite};
use crate::fluid::FluidState;
use crate::params::Params;
use crate::scalar::{Float, Real};
use crate::throttle::regularised_root;

/// Transition pressure of the regularised orifice law, as a fraction of `dp`.
pub const TRANSITION_FRACTION: f64 = 1.0e-5;

/// Whether the plunger is held by a stop during a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Contact {
    /// Moving freely.
    Free,
    /// Held at `x = 0`.
    Closed,
    /// Held at `x = x_max`.
    Open,
}

/// Conversion between the model's units and SI (all `f64`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales {
    /// Time unit `T = sqrt(m / c)` [s].
    pub time: f64,
    /// Length unit: the stroke [m].
    pub length: f64,
    /// Velocity unit `V = a_x L / T` [m/s].
    pub velocity: f64,
    /// Pressure unit `dp` [Pa].
    pub pressure: f64,
    /// Pressure origin `p_c` [Pa].
    pub outlet_pressure: f64,
}

/// A state in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicState {
    /// Plunger displacement `x` [m].
    pub x: f64,
    /// Plunger velocity `v` [m/s].
    pub v: f64,
    /// Chamber (a) pressure [Pa].
    pub p_a: f64,
    /// Chamber (b) pressure [Pa].
    pub p_b: f64,
}

impl Scales {
    /// Model state `(xi, w, pi_a, pi_b)` to SI.
    pub fn to_si<T: Real>(&self, y: &[T; 4]) -> DynamicState {
        DynamicState {
            x: y[0].to_f64() * self.length,
            v: y[1].to_f64() * self.velocity,
            p_a: self.outlet_pressure + y[2].to_f64() * self.pressure,
            p_b: self.outlet_pressure + y[3].to_f64() * self.pressure,
        }
    }

    /// SI state to model state.
    pub fn from_si<T: Real>(&self, s: &DynamicState) -> [T; 4] {
        [
            T::from_f64(s.x / self.length),
            T::from_f64(s.v / self.velocity),
            T::from_f64((s.p_a - self.outlet_pressure) / self.pressure),
            T::from_f64((s.p_b - self.outlet_pressure) / self.pressure),
        ]
    }
}

/// The model's coefficients in scalar type `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients<T> {
    /// `a_x`: `xi' = a_x w`.
    pub a_x: T,
    /// `1 / a_x`.
    pub inv_a_x: T,
    /// `phi / a_x`, with `phi = A_p dp / (c L)`.
    pub phi_over_a_x: T,
    /// `2 zeta = b / sqrt(c m)`.
    pub two_zeta: T,
    /// `xi0 = x0 / L` (preload).
    pub xi0: T,
    /// `omega_a0 = T Q* beta / (dp V_a0)`.
    pub omega_a0: T,
    /// `eps_a = A_p L / V_a0`.
    pub eps_a: T,
    /// `omega_b0 = T Q* beta / (dp V_b0)`.
    pub omega_b0: T,
    /// `eps_b = A_p L / V_b0`.
    pub eps_b: T,
    /// `sigma = A_p V / Q*`.
    pub sigma: T,
    /// Transition of the regularised root, fraction of `dp`.
    pub u_tr: T,
    /// `q_t = sqrt(rho_15 / rho(t))` (temperature-dependent).
    pub q_t: T,
    /// `g_l = dp / (R_l(t) Q*)` (temperature-dependent).
    pub g_l: T,
}

/// The temperature-independent part of the model, computed once in the
/// parameters' float type `F`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model<F> {
    params: Params<F>,
    /// Unit conversions.
    pub scales: Scales,
    q_star: F,
    a_x: F,
}

impl<F: Float> Model<F> {
    /// Prepares the model for a parameter set.
    pub fn new(params: &Params<F>) -> Result<Self, ModelError> {
        let p = params;
        let pl = &p.plunger;
        let t = (pl.mass / pl.spring_rate).sqrt();
        let area = pl.area();
        let dp = p.pressure_drop;
        let q_star = p.orifice.discharge_coefficient
            * p.orifice.area()
            * (F::from_f64(2.0) * dp / p.oil.density_15).sqrt();
        let phi = area * dp / (pl.spring_rate * pl.stroke);
        let sigma1 = area * pl.stroke / (t * q_star);
        let omega_mean = t * q_star * p.oil.bulk_modulus / dp
            * F::from_f64(0.5)
            * (F::ONE / p.volume_a + F::ONE / p.volume_b);
        let a_x = (phi / (omega_mean * sigma1)).sqrt();
        finite(a_x, "velocity scale")?;
        if !(a_x > F::ZERO) {
            return Err(ModelError::OutOfRange("velocity scale"));
        }
        let scales = Scales {
            time: t.to_f64(),
            length: pl.stroke.to_f64(),
            velocity: (a_x * pl.stroke / t).to_f64(),
            pressure: dp.to_f64(),
            outlet_pressure: p.outlet_pressure.to_f64(),
        };
        Ok(Model {
            params: *params,
            scales,
            q_star,
            a_x,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &Params<F> {
        &self.params
    }

    /// Temperature-dependent coefficients `(q_t, g_l)` for a fluid state.
    pub fn hydraulic(&self, fluid: &FluidState<F>) -> Result<(F, F), ModelError> {
        let p = &self.params;
        let q_t = (p.oil.density_15 / fluid.density).sqrt();
        let g_l =
            p.pressure_drop * p.capillary.bore_term() / (fluid.dynamic_viscosity * self.q_star);
        Ok((finite(q_t, "q_t")?, finite(g_l, "g_l")?))
    }

    /// All coefficients for a fluid state, converted to `T`.
    pub fn coefficients<T: Real>(
        &self,
        fluid: &FluidState<F>,
    ) -> Result<Coefficients<T>, ModelError> {
        let p = &self.params;
        let pl = &p.plunger;
        let s = &self.scales;
        let (q_t, g_l) = self.hydraulic(fluid)?;
        let swept = pl.area().to_f64() * s.length;
        let omega =
            |v: f64| s.time * self.q_star.to_f64() * p.oil.bulk_modulus.to_f64() / (s.pressure * v);
        let a_x = self.a_x.to_f64();
        let phi = pl.area().to_f64() * s.pressure / (pl.spring_rate.to_f64() * s.length);
        let c = |v: f64, what: &'static str| -> Result<T, ModelError> {
            let t = T::from_f64(v);
            if v.is_finite() && t.is_finite() {
                Ok(t)
            } else {
                Err(ModelError::NonFinite(what))
            }
        };
        Ok(Coefficients {
            a_x: c(a_x, "a_x")?,
            inv_a_x: c(1.0 / a_x, "1/a_x")?,
            phi_over_a_x: c(phi / a_x, "phi")?,
            two_zeta: c(
                pl.damping.to_f64() / (pl.spring_rate.to_f64() * pl.mass.to_f64()).sqrt(),
                "zeta",
            )?,
            xi0: c(pl.preload.to_f64() / s.length, "preload")?,
            omega_a0: c(omega(p.volume_a.to_f64()), "omega_a")?,
            eps_a: c(swept / p.volume_a.to_f64(), "eps_a")?,
            omega_b0: c(omega(p.volume_b.to_f64()), "omega_b")?,
            eps_b: c(swept / p.volume_b.to_f64(), "eps_b")?,
            sigma: c(
                pl.area().to_f64() * s.velocity / self.q_star.to_f64(),
                "sigma",
            )?,
            u_tr: c(TRANSITION_FRACTION, "u_tr")?,
            q_t: c(q_t.to_f64(), "q_t")?,
            g_l: c(g_l.to_f64(), "g_l")?,
        })
    }

    /// The model state of a quasi-static equilibrium (at rest).
    pub fn equilibrium_state<T: Real>(&self, eq: &Equilibrium<F>) -> [T; 4] {
        self.scales.from_si(&DynamicState {
            x: eq.x.to_f64(),
            v: 0.0,
            p_a: eq.p_a.to_f64(),
            p_b: eq.p_b.to_f64(),
        })
    }
}

impl<T: Real> Coefficients<T> {
    /// Net static force on the plunger in units of the spring force at one
    /// stroke, divided by `a_x`: positive opens (towards `x_max`).
    #[inline]
    pub fn static_force(&self, y: &[T; 4]) -> T {
        self.phi_over_a_x * (y[3] - y[2]) - (self.xi0 + y[0]) * self.inv_a_x
    }

    /// The contact state for `y` (see [`contact_for`]).
    #[inline]
    pub fn contact(&self, y: &[T; 4]) -> Contact {
        contact_for(y[0], y[1], self.static_force(y))
    }
}

/// The model in one contact state: what the schemes integrate.
#[derive(Clone, Copy, Debug)]
pub struct Fsi<'a, T> {
    /// Coefficients at the step's temperature.
    pub coefficients: &'a Coefficients<T>,
    /// Contact state, frozen over the step.
    pub contact: Contact,
}

impl<T: Real> Fsi<'_, T> {
    #[inline]
    fn omegas(&self, xi: T) -> (T, T) {
        let c = self.coefficients;
        (
            c.omega_a0 / (T::ONE - c.eps_a * xi),
            c.omega_b0 / (T::ONE + c.eps_b * xi),
        )
    }
}

impl<T: Real> OdeSystem<T, 4> for Fsi<'_, T> {
    fn rhs(&self, y: &[T; 4]) -> [T; 4] {
        let c = self.coefficients;
        let (xi, w, pa, pb) = (y[0], y[1], y[2], y[3]);
        let (oa, ob) = self.omegas(xi);
        let (ra, _) = regularised_root(T::ONE - pa, c.u_tr);
        let (rb, _) = regularised_root(pb, c.u_tr);
        let sw = c.sigma * w;
        let dpa = oa * (c.q_t * ra - c.g_l * pa + sw);
        let dpb = ob * (c.g_l * (T::ONE - pb) - c.q_t * rb - sw);
        let (dxi, dw) = match self.contact {
            Contact::Free => (c.a_x * w, c.static_force(y) - c.two_zeta * w),
            Contact::Closed | Contact::Open => (T::ZERO, T::ZERO),
        };
        [dxi, dw, dpa, dpb]
    }

    fn jacobian(&self, y: &[T; 4]) -> [[T; 4]; 4] {
        let c = self.coefficients;
        let (xi, w, pa, pb) = (y[0], y[1], y[2], y[3]);
        let (oa, ob) = self.omegas(xi);
        let (ra, sa) = regularised_root(T::ONE - pa, c.u_tr);
        let (rb, sb) = regularised_root(pb, c.u_tr);
        let sw = c.sigma * w;
        let fa = c.q_t * ra - c.g_l * pa + sw;
        let fb = c.g_l * (T::ONE - pb) - c.q_t * rb - sw;
        // d omega_a / d xi = omega_a eps_a / (1 - eps_a xi); omega_b: -omega_b eps_b / (1 + eps_b xi).
        let doa = oa * c.eps_a / (T::ONE - c.eps_a * xi);
        let dob = -(ob * c.eps_b / (T::ONE + c.eps_b * xi));
        let mech = match self.contact {
            Contact::Free => [
                [T::ZERO, c.a_x, T::ZERO, T::ZERO],
                [-c.inv_a_x, -c.two_zeta, -c.phi_over_a_x, c.phi_over_a_x],
            ],
            Contact::Closed | Contact::Open => [[T::ZERO; 4]; 2],
        };
        [
            mech[0],
            mech[1],
            [
                doa * fa,
                oa * c.sigma,
                -(oa * (c.q_t * sa + c.g_l)),
                T::ZERO,
            ],
            [
                dob * fb,
                -(ob * c.sigma),
                T::ZERO,
                -(ob * (c.g_l + c.q_t * sb)),
            ],
        ]
    }
}

/// The contact state of a plunger at `xi` moving at `w` under net static
/// force `force` (positive opens): held by a stop when on it, not moving
/// away from it, and pushed into it.
#[inline]
pub fn contact_for<T: Real>(xi: T, w: T, force: T) -> Contact {
    if xi <= T::ZERO && w <= T::ZERO && force <= T::ZERO {
        Contact::Closed
    } else if xi >= T::ONE && w >= T::ZERO && force >= T::ZERO {
        Contact::Open
    } else {
        Contact::Free
    }
}

/// Applies the inelastic stops after a step: a plunger beyond a stop (or
/// on it and moving into it) is put on it at rest. Returns `true` when the
/// state was changed (an impact).
#[inline]
pub fn apply_stops<T: Real>(xi: &mut T, w: &mut T) -> bool {
    let (stop, hit) = if *xi < T::ZERO || (*xi == T::ZERO && *w < T::ZERO) {
        (T::ZERO, true)
    } else if *xi > T::ONE || (*xi == T::ONE && *w > T::ZERO) {
        (T::ONE, true)
    } else {
        (*xi, false)
    };
    if hit {
        *xi = stop;
        *w = T::ZERO;
    }
    hit
}
