//! The reduced-order fluid-structure model (paper section 4, Eqs. 33-36,
//! signs of `docs/model.md` section 6), nondimensionalised for fixed point.
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
//! Flow unit: `Q*` as long as the capillary conducts at most
//! [`FLOW_SCALE_LIMIT`] times the orifice (`g_l <= 256`), else `2^n Q*`
//! with the smallest `n` that brings `g_l` back under it ([`flow_shift`]).
//! Every flow coefficient (`q_t`, `g_l`, `sigma`) is divided by `2^n`,
//! every chamber rate (`omega`) multiplied by it: the equations in
//! `(xi, w, pi_a, pi_b)` are homogeneous in that scale, so the state and
//! its trajectory are unchanged (exactly: a power of two), and no
//! coefficient outgrows fixed point when a thin oil runs hot (`g_l` of
//! the survey's designs reaches 1,944 at 150 C and 1,232 inside 26-78 C,
//! against Q12.20's 2,048; `docs/dynamics.md`, "Fixed-point ranges").
//!
//! End stops are inelastic: on a stop, with the net static force pushing
//! into it and no velocity away from it, the plunger is held (`xi' = w' = 0`,
//! [`Contact`]); a step that crosses a stop ends on it with `w = 0`.

use super::schemes::{OdeSystem, ShiftedSolve};
use crate::equilibrium::Equilibrium;
use crate::error::{ModelError, finite, represent};
use crate::fluid::FluidState;
use crate::params::Params;
use crate::scalar::{Float, Real};
use crate::throttle::{regularised_root, regularised_root_value};

/// Transition pressure of the regularised orifice law, as a fraction of `dp`.
pub const TRANSITION_FRACTION: f64 = 1.0e-5;

/// Largest capillary conductance `g_l` (in the flow unit) the coefficients
/// carry: beyond it the flow unit doubles ([`flow_shift`]). 256 keeps
/// every stage intermediate of the twin below half of Q12.20's range
/// (`g_l - sigma w`, `k + g_l`, `1 + beta g_l` and `R K` of
/// [`super::dirk`]), while `q_t` stays above `128 / g_l` in any unit.
pub const FLOW_SCALE_LIMIT: f64 = 256.0;

/// Largest exponent of the flow unit (`g_l` up to `256 * 2^24`, far beyond
/// any oil; beyond it the coefficients are refused as not representable).
pub const MAX_FLOW_SHIFT: u8 = 24;

/// The exponent `n` of the flow unit `2^n Q*` for a capillary conductance
/// `g_l` in units of `Q*`: the smallest `n <= MAX_FLOW_SHIFT` with
/// `g_l / 2^n <= FLOW_SCALE_LIMIT` (zero for NaN).
#[inline]
pub fn flow_shift<F: Float>(g_l: F) -> u8 {
    let mut limit = F::from_f64(FLOW_SCALE_LIMIT);
    let mut n = 0;
    while g_l > limit && n < MAX_FLOW_SHIFT {
        limit = limit + limit;
        n += 1;
    }
    n
}

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

/// Conversion between the model's units and SI, in the parameters' float
/// type `F` (so that an `f32` firmware never runs soft-double code).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales<F> {
    /// Time unit `T = sqrt(m / c)` [s].
    pub time: F,
    /// Length unit: the stroke [m].
    pub length: F,
    /// Velocity unit `V = a_x L / T` [m/s].
    pub velocity: F,
    /// Pressure unit `dp` [Pa].
    pub pressure: F,
    /// Pressure origin `p_c` [Pa].
    pub outlet_pressure: F,
}

/// A state in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicState<F> {
    /// Plunger displacement `x` [m].
    pub x: F,
    /// Plunger velocity `v` [m/s].
    pub v: F,
    /// Chamber (a) pressure [Pa].
    pub p_a: F,
    /// Chamber (b) pressure [Pa].
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
    /// `omega_a0 = T Q* beta / (dp V_a0)`. The one coefficient allowed to
    /// saturate in fixed point (above 2,048 in Q12.20, stiff chambers): only
    /// the unscaled [`OdeSystem::rhs`] and [`OdeSystem::jacobian`] use it
    /// (explicit schemes, the `f32` linearisation); the Rosenbrock stage
    /// equations are row-scaled and use `inv_omega_a0` instead.
    pub omega_a0: T,
    /// `1 / omega_a0`.
    pub inv_omega_a0: T,
    /// `eps_a = A_p L / V_a0`.
    pub eps_a: T,
    /// `omega_b0 = T Q* beta / (dp V_b0)` (may saturate, as `omega_a0`).
    pub omega_b0: T,
    /// `1 / omega_b0`.
    pub inv_omega_b0: T,
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
    /// The flow unit is `2^flow_shift Q*` ([`flow_shift`]): `q_t`, `g_l`
    /// and `sigma` above are divided by `2^flow_shift`, `omega_a0`,
    /// `omega_b0` multiplied by it (`inv_omega_a0`, `inv_omega_b0`
    /// divided). Zero unless the capillary conducts more than
    /// [`FLOW_SCALE_LIMIT`] times the orifice.
    pub flow_shift: u8,
}

/// The coefficients that carry the flow unit, for one [`flow_shift`].
struct Flows<T> {
    omega_a0: T,
    inv_omega_a0: T,
    omega_b0: T,
    inv_omega_b0: T,
    sigma: T,
}

/// The temperature-independent part of the model, computed once in the
/// parameters' float type `F`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Model<F> {
    params: Params<F>,
    /// Unit conversions.
    pub scales: Scales<F>,
    q_star: F,
    a_x: F,
    /// `omega_a0`, `omega_b0`, their reciprocals and `sigma` in units of
    /// `Q*` (computed in `f64`, rounded once to `F`; a flow unit of `2^n Q*`
    /// scales them exactly).
    omega: [F; 2],
    inv_omega: [F; 2],
    sigma: F,
}

impl<F: Float> Model<F> {
    /// Prepares the model for a parameter set.
    ///
    /// # Errors
    ///
    /// `NonFinite` or `OutOfRange` naming the velocity scale when `a_x` is
    /// not a finite, positive number, and `NonFinite` naming `omega_a`,
    /// `omega_b` or `sigma` when a chamber rate or the plunger's pumping
    /// coefficient is not finite (parameters that validated but whose
    /// combination overflows).
    pub fn new(params: &Params<F>) -> Result<Self, ModelError> {
        let p = params;
        let pl = &p.plunger;
        let t = (pl.mass / pl.spring_rate).sqrt();
        let area = pl.area();
        let dp = p.pressure_drop;
        let q_star =
            p.orifice.discharge_coefficient * p.orifice.area() * (F::from_f64(2.0) * dp / p.oil.density_15).sqrt();
        let phi = area * dp / (pl.spring_rate * pl.stroke);
        let sigma1 = area * pl.stroke / (t * q_star);
        let omega_mean =
            t * q_star * p.oil.bulk_modulus / dp * F::from_f64(0.5) * (F::ONE / p.volume_a + F::ONE / p.volume_b);
        let a_x = (phi / (omega_mean * sigma1)).sqrt();
        finite(a_x, "velocity scale")?;
        if !(a_x > F::ZERO) {
            return Err(ModelError::OutOfRange("velocity scale"));
        }
        let scales = Scales {
            time: t,
            length: pl.stroke,
            velocity: a_x * pl.stroke / t,
            pressure: dp,
            outlet_pressure: p.outlet_pressure,
        };
        let swept_rate = |v: F| t.to_f64() * q_star.to_f64() * p.oil.bulk_modulus.to_f64() / (dp.to_f64() * v.to_f64());
        let (oa, ob) = (
            finite(swept_rate(p.volume_a), "omega_a")?,
            finite(swept_rate(p.volume_b), "omega_b")?,
        );
        let sigma = F::from_f64(finite(
            area.to_f64() * scales.velocity.to_f64() / q_star.to_f64(),
            "sigma",
        )?);
        Ok(Model {
            params: *params,
            scales,
            q_star,
            a_x,
            omega: [F::from_f64(oa), F::from_f64(ob)],
            inv_omega: [F::from_f64(1.0 / oa), F::from_f64(1.0 / ob)],
            sigma,
        })
    }

    /// The coefficients that carry the flow unit `2^shift Q*`, in `T`.
    /// `omega` may saturate fixed point (see [`Coefficients::omega_a0`]).
    fn flows<T: Real>(&self, shift: u8) -> Result<Flows<T>, ModelError> {
        let s = F::from_f64((1u32 << shift) as f64);
        let saturating = |v: F, what: &'static str| finite(finite(v, what)?.to_real::<T>(), what);
        Ok(Flows {
            omega_a0: saturating(self.omega[0] * s, "omega_a")?,
            inv_omega_a0: represent(self.inv_omega[0] / s, "omega_a")?,
            omega_b0: saturating(self.omega[1] * s, "omega_b")?,
            inv_omega_b0: represent(self.inv_omega[1] / s, "omega_b")?,
            sigma: represent(self.sigma / s, "sigma")?,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &Params<F> {
        &self.params
    }

    /// Temperature-dependent coefficients `(q_t, g_l)` for a fluid state.
    ///
    /// # Errors
    ///
    /// `NonFinite("q_t")` or `NonFinite("g_l")` when the fluid state makes
    /// one of them infinite or NaN (a zero density or viscosity).
    pub fn hydraulic(&self, fluid: &FluidState<F>) -> Result<(F, F), ModelError> {
        let p = &self.params;
        let q_t = (p.oil.density_15 / fluid.density).sqrt();
        let g_l = p.pressure_drop * p.capillary.bore_term() / (fluid.dynamic_viscosity * self.q_star);
        Ok((finite(q_t, "q_t")?, finite(g_l, "g_l")?))
    }

    /// All coefficients for a fluid state, converted to `T` (in the flow
    /// unit [`flow_shift`] picks for the fluid's `g_l`).
    ///
    /// # Errors
    ///
    /// As [`Model::hydraulic`], and, naming the coefficient,
    /// [`ModelError::NotRepresentable`] when `T` cannot hold it (fixed point
    /// saturating or losing it to rounding; `omega_a0` and `omega_b0` are
    /// allowed to saturate) or `NonFinite` when it is not finite.
    pub fn coefficients<T: Real>(&self, fluid: &FluidState<F>) -> Result<Coefficients<T>, ModelError> {
        let p = &self.params;
        let pl = &p.plunger;
        let (q_t, g_l) = self.hydraulic(fluid)?;
        let shift = flow_shift(g_l);
        let s = F::from_f64((1u32 << shift) as f64);
        let length = self.scales.length.to_f64();
        let swept = pl.area().to_f64() * length;
        let a_x = self.a_x.to_f64();
        let phi = pl.area().to_f64() * self.scales.pressure.to_f64() / (pl.spring_rate.to_f64() * length);
        let c = |v: f64, what: &'static str| represent::<f64, T>(v, what);
        let flows = self.flows::<T>(shift)?;
        Ok(Coefficients {
            a_x: c(a_x, "a_x")?,
            inv_a_x: c(1.0 / a_x, "1/a_x")?,
            phi_over_a_x: c(phi / a_x, "phi")?,
            two_zeta: c(
                pl.damping.to_f64() / (pl.spring_rate.to_f64() * pl.mass.to_f64()).sqrt(),
                "zeta",
            )?,
            xi0: c(pl.preload.to_f64() / length, "preload")?,
            omega_a0: flows.omega_a0,
            inv_omega_a0: flows.inv_omega_a0,
            eps_a: c(swept / p.volume_a.to_f64(), "eps_a")?,
            omega_b0: flows.omega_b0,
            inv_omega_b0: flows.inv_omega_b0,
            eps_b: c(swept / p.volume_b.to_f64(), "eps_b")?,
            sigma: flows.sigma,
            u_tr: c(TRANSITION_FRACTION, "u_tr")?,
            q_t: represent(q_t / s, "q_t")?,
            g_l: represent(g_l / s, "g_l")?,
            flow_shift: shift,
        })
    }

    /// The model state of a quasi-static equilibrium (at rest).
    pub fn equilibrium_state<T: Real>(&self, eq: &Equilibrium<F>) -> [T; 4] {
        self.scales.from_si(&DynamicState {
            x: eq.x,
            v: F::ZERO,
            p_a: eq.p_a,
            p_b: eq.p_b,
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

    /// The static force with the chambers at their quasi-steady pressures
    /// for the current temperature (what the force settles to within tens
    /// of microseconds at rest): `phi' (2 s0^2 - 1) - (xi0 + xi) / a_x`,
    /// `s0 = 2 g_l / (q_t + sqrt(q_t^2 + 4 g_l^2))`.
    #[inline]
    pub fn quasi_steady_force(&self, xi: T) -> T {
        let two = T::ONE + T::ONE;
        let s0 = two * self.g_l / (self.q_t + (self.q_t * self.q_t + two * two * self.g_l * self.g_l).sqrt());
        self.phi_over_a_x * (two * s0 * s0 - T::ONE) - (self.xi0 + xi) * self.inv_a_x
    }

    /// Sets the temperature-dependent `q_t`, `g_l` for a fluid state, and
    /// the flow unit with them ([`flow_shift`]: `sigma` and the chamber
    /// rates change only when the unit does).
    ///
    /// # Errors
    ///
    /// As [`Model::hydraulic`], and `NotRepresentable` naming `q_t`, `g_l`
    /// or a coefficient of the new flow unit that `T` cannot hold. Nothing
    /// changes then.
    pub fn set_hydraulic<F: Float>(&mut self, model: &Model<F>, fluid: &FluidState<F>) -> Result<(), ModelError> {
        let (q_t, g_l) = model.hydraulic(fluid)?;
        let shift = flow_shift(g_l);
        let s = F::from_f64((1u32 << shift) as f64);
        let (q_t, g_l) = (represent(q_t / s, "q_t")?, represent(g_l / s, "g_l")?);
        if shift != self.flow_shift {
            let f = model.flows::<T>(shift)?;
            self.omega_a0 = f.omega_a0;
            self.inv_omega_a0 = f.inv_omega_a0;
            self.omega_b0 = f.omega_b0;
            self.inv_omega_b0 = f.inv_omega_b0;
            self.sigma = f.sigma;
            self.flow_shift = shift;
        }
        self.q_t = q_t;
        self.g_l = g_l;
        Ok(())
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

/// What the right-hand side and the Jacobian share at one state.
#[derive(Clone, Copy)]
struct Local<T> {
    /// `omega_a(xi)`, `omega_b(xi)`.
    oa: T,
    ob: T,
    /// Their `xi` derivatives.
    doa: T,
    dob: T,
    /// Orifice slopes `r'(1 - pi_a)`, `r'(pi_b)`.
    sa: T,
    sb: T,
    /// Net inflows `q_t r(1 - pi_a) - g_l pi_a + sigma w` and its (b) twin.
    fa: T,
    fb: T,
}

impl<T: Real> Fsi<'_, T> {
    /// `true` in free motion; while held the mechanical rows vanish.
    #[inline]
    fn moving(&self) -> bool {
        self.contact == Contact::Free
    }

    #[inline]
    fn local(&self, y: &[T; 4]) -> Local<T> {
        let c = self.coefficients;
        let (xi, w, pa, pb) = (y[0], y[1], y[2], y[3]);
        let (da, db) = (T::ONE - c.eps_a * xi, T::ONE + c.eps_b * xi);
        let (oa, ob) = (c.omega_a0 / da, c.omega_b0 / db);
        let (ra, sa) = regularised_root(T::ONE - pa, c.u_tr);
        let (rb, sb) = regularised_root(pb, c.u_tr);
        let sw = c.sigma * w;
        Local {
            oa,
            ob,
            // d omega_a / d xi = omega_a eps_a / (1 - eps_a xi); omega_b: -omega_b eps_b / (1 + eps_b xi).
            doa: oa * c.eps_a / da,
            dob: -(ob * c.eps_b / db),
            sa,
            sb,
            fa: c.q_t * ra - c.g_l * pa + sw,
            fb: c.g_l * (T::ONE - pb) - c.q_t * rb - sw,
        }
    }

    /// Net chamber inflows `F_a = q_t r(1 - pi_a) - g_l pi_a + sigma w`
    /// and `F_b = g_l (1 - pi_b) - q_t r(pi_b) - sigma w` (values only).
    #[inline]
    fn inflows(&self, y: &[T; 4]) -> (T, T) {
        let c = self.coefficients;
        let ra = regularised_root_value(T::ONE - y[2], c.u_tr);
        let rb = regularised_root_value(y[3], c.u_tr);
        let sw = c.sigma * y[1];
        (
            c.q_t * ra - c.g_l * y[2] + sw,
            c.g_l * (T::ONE - y[3]) - c.q_t * rb - sw,
        )
    }

    /// `f(y)` (or a row-scaled `D f`) from the net chamber inflows and the
    /// factors of the pressure rows.
    #[inline]
    fn rhs_from(&self, y: &[T; 4], oa: T, ob: T, fa: T, fb: T) -> [T; 4] {
        let c = self.coefficients;
        let (dxi, dw) = if self.moving() {
            (c.a_x * y[1], c.static_force(y) - c.two_zeta * y[1])
        } else {
            (T::ZERO, T::ZERO)
        };
        [dxi, dw, oa * fa, ob * fb]
    }
}

/// `D (shift I - J)` of the FSI model, factorised by its structure, with
/// the pressure rows scaled by `D = diag(1, 1, 1/omega_a, 1/omega_b)`.
///
/// The scaling keeps every number bounded: `omega` (a chamber's pressure
/// rate, up to 1e4 in the model's units for small, stiff chambers) only
/// appears as `shift / omega` and as ratios of chamber compliances, so
/// fixed point keeps both range and resolution.
///
/// Each chamber's pressure couples only to itself and to the plunger, so
/// the pressures are eliminated analytically and a 2x2 system in
/// `(xi, w)` remains: four divisions to factorise, ~14 multiply-adds to
/// solve (a pivoted 4x4 LU takes four divisions and ~50). With `m = 1` in
/// free motion and `0` while held, `s = shift`, `phi' = phi / a_x`, and the
/// scaled rows `d2 = s / omega_a + q_t r'_a + g_l`, `J20 = eps_a F_a / (1 - eps_a xi)`,
/// `J21 = sigma` (and their chamber (b) twins):
///
/// ```text
/// u2 = (r2 + J20 u0 + J21 u1) / d2,   u3 = (r3 + J30 u0 + J31 u1) / d3
/// [ s     -a_x m ] [u0]   [ r0                            ]
/// [ A10    A11   ] [u1] = [ r1 - phi' m (r2 / d2 - r3 / d3) ] = [r0, b1]
/// A10 = m / a_x + phi' m (J20 / d2 - J30 / d3),  A11 = s + 2 zeta m + phi' m (J21 / d2 - J31 / d3)
/// u1 = (b1 - A10 r0 / s) / (A11 + a_x m A10 / s),  u0 = (r0 + a_x m u1) / s
/// ```
#[derive(Clone, Copy, Debug)]
pub struct FsiFactor<T> {
    a_x_m: T,
    phi_m: T,
    j20: T,
    j21: T,
    j30: T,
    j31: T,
    e2: T,
    e3: T,
    a10: T,
    /// `1 / s`.
    inv_s: T,
    /// `1 / (A11 + a_x m A10 / s)`.
    inv_k: T,
    /// `1 / omega_a`, `1 / omega_b` at the step's start.
    inv_oa: T,
    inv_ob: T,
    /// `1 - eps_a xi`, `1 + eps_b xi` at the step's start.
    da: T,
    db: T,
}

impl<T: Real> ShiftedSolve<T, 4> for FsiFactor<T> {
    #[inline]
    fn solve(&self, r: &[T; 4]) -> [T; 4] {
        let (r2e, r3e) = (r[2] * self.e2, r[3] * self.e3);
        let b1 = r[1] - self.phi_m * (r2e - r3e);
        // Row 0 gives u0 = (r0 + a_x m u1) / s; row 1 then gives u1. No
        // product of two large entries is formed (s A11 would overflow
        // Q12.20 on designs with slow mechanics, where s is large).
        let r0s = r[0] * self.inv_s;
        let u1 = (b1 - self.a10 * r0s) * self.inv_k;
        let u0 = r0s + self.a_x_m * u1 * self.inv_s;
        let u2 = r2e + (self.j20 * u0 + self.j21 * u1) * self.e2;
        let u3 = r3e + (self.j30 * u0 + self.j31 * u1) * self.e3;
        [u0, u1, u2, u3]
    }

    #[inline]
    fn scale(&self, v: &[T; 4]) -> [T; 4] {
        [v[0], v[1], v[2] * self.inv_oa, v[3] * self.inv_ob]
    }
}

impl<T: Real> OdeSystem<T, 4> for Fsi<'_, T> {
    type Factor = FsiFactor<T>;

    fn rhs(&self, y: &[T; 4]) -> [T; 4] {
        let c = self.coefficients;
        let (da, db) = (T::ONE - c.eps_a * y[0], T::ONE + c.eps_b * y[0]);
        let (fa, fb) = self.inflows(y);
        self.rhs_from(y, c.omega_a0 / da, c.omega_b0 / db, fa, fb)
    }

    fn scaled_rhs(&self, y: &[T; 4], factor: &FsiFactor<T>) -> [T; 4] {
        // D f: the pressure rows are omega(y) F(y) / omega(y_n)
        //      = F(y) (1 - eps_a xi_n) / (1 - eps_a xi), never forming omega.
        let c = self.coefficients;
        let (fa, fb) = self.inflows(y);
        let (da, db) = (T::ONE - c.eps_a * y[0], T::ONE + c.eps_b * y[0]);
        self.rhs_from(y, factor.da / da, factor.db / db, fa, fb)
    }

    fn jacobian(&self, y: &[T; 4]) -> [[T; 4]; 4] {
        let c = self.coefficients;
        let l = self.local(y);
        let mech = if self.moving() {
            [
                [T::ZERO, c.a_x, T::ZERO, T::ZERO],
                [-c.inv_a_x, -c.two_zeta, -c.phi_over_a_x, c.phi_over_a_x],
            ]
        } else {
            [[T::ZERO; 4]; 2]
        };
        [
            mech[0],
            mech[1],
            [l.doa * l.fa, l.oa * c.sigma, -(l.oa * (c.q_t * l.sa + c.g_l)), T::ZERO],
            [
                l.dob * l.fb,
                -(l.ob * c.sigma),
                T::ZERO,
                -(l.ob * (c.g_l + c.q_t * l.sb)),
            ],
        ]
    }

    fn linearise(&self, y: &[T; 4], shift: T) -> Option<([T; 4], FsiFactor<T>)> {
        let c = self.coefficients;
        let xi = y[0];
        let (da, db) = (T::ONE - c.eps_a * xi, T::ONE + c.eps_b * xi);
        let (ra, sa) = regularised_root(T::ONE - y[2], c.u_tr);
        let (rb, sb) = regularised_root(y[3], c.u_tr);
        let sw = c.sigma * y[1];
        let fa = c.q_t * ra - c.g_l * y[2] + sw;
        let fb = c.g_l * (T::ONE - y[3]) - c.q_t * rb - sw;
        // Scaled rows: D f = (xi', w', F_a, F_b).
        let f = self.rhs_from(y, T::ONE, T::ONE, fa, fb);
        let (inv_oa, inv_ob) = (da * c.inv_omega_a0, db * c.inv_omega_b0);
        let d2 = shift * inv_oa + c.q_t * sa + c.g_l;
        let d3 = shift * inv_ob + c.g_l + c.q_t * sb;
        if !(d2 > T::ZERO && d3 > T::ZERO) {
            return None;
        }
        let (e2, e3) = (T::ONE / d2, T::ONE / d3);
        let (j20, j21) = (c.eps_a * fa / da, c.sigma);
        let (j30, j31) = (-(c.eps_b * fb / db), -c.sigma);
        let (a_x_m, phi_m, inv_a_x_m, two_zeta_m) = if self.moving() {
            (c.a_x, c.phi_over_a_x, c.inv_a_x, c.two_zeta)
        } else {
            (T::ZERO, T::ZERO, T::ZERO, T::ZERO)
        };
        let a10 = inv_a_x_m + phi_m * (j20 * e2 - j30 * e3);
        let a11 = shift + two_zeta_m + phi_m * (j21 * e2 - j31 * e3);
        if !(shift > T::ZERO) {
            return None;
        }
        let inv_s = T::ONE / shift;
        let k = a11 + a_x_m * a10 * inv_s;
        if !(k.abs() > T::tiny()) || !k.is_finite() {
            return None;
        }
        let factor = FsiFactor {
            a_x_m,
            phi_m,
            j20,
            j21,
            j30,
            j31,
            e2,
            e3,
            a10,
            inv_s,
            inv_k: T::ONE / k,
            inv_oa,
            inv_ob,
            da,
            db,
        };
        Some((f, factor))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::schemes::dense_linearisation;

    fn coefficients() -> Coefficients<f64> {
        Coefficients {
            a_x: 0.062,
            inv_a_x: 1.0 / 0.062,
            phi_over_a_x: 13.5,
            two_zeta: 0.09,
            xi0: 0.007,
            omega_a0: 13.4,
            inv_omega_a0: 1.0 / 13.4,
            eps_a: 0.059,
            omega_b0: 13.4,
            inv_omega_b0: 1.0 / 13.4,
            eps_b: 0.059,
            sigma: 1.02,
            u_tr: 1e-5,
            q_t: 1.02,
            g_l: 1.4,
            flow_shift: 0,
        }
    }

    #[test]
    fn structured_factor_solves_like_a_dense_lu() {
        let c = coefficients();
        for contact in [Contact::Free, Contact::Closed] {
            let sys = Fsi {
                coefficients: &c,
                contact,
            };
            for (k, y) in [[0.3, 0.01, 0.4, 0.6], [0.0, 0.0, 0.8, 0.2], [0.9, -0.2, 0.15, 0.95]]
                .iter()
                .enumerate()
            {
                let shift = 0.5 + k as f64;
                let (f, structured) = sys.linearise(y, shift).unwrap();
                let (f_dense, dense) = dense_linearisation(&sys, y, shift).unwrap();
                let scaled = structured.scale(&f_dense);
                for i in 0..4 {
                    assert!(
                        (f[i] - scaled[i]).abs() <= 1e-13 * (1.0 + scaled[i].abs()),
                        "{f:?} vs {scaled:?}"
                    );
                }
                let r = [0.3, -1.2, 2.5, 0.7];
                let (a, b) = (structured.solve(&structured.scale(&r)), dense.solve(&r));
                for i in 0..4 {
                    assert!(
                        (a[i] - b[i]).abs() <= 1e-12 * (1.0 + b[i].abs()),
                        "{contact:?} {y:?}: {a:?} vs {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        let c = coefficients();
        let sys = Fsi {
            coefficients: &c,
            contact: Contact::Free,
        };
        let y = [0.4, 0.02, 0.35, 0.7];
        let jac = sys.jacobian(&y);
        for j in 0..4 {
            let h = 1e-6;
            let (mut yp, mut ym) = (y, y);
            yp[j] += h;
            ym[j] -= h;
            let (fp, fm) = (sys.rhs(&yp), sys.rhs(&ym));
            for i in 0..4 {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (jac[i][j] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "J[{i}][{j}] = {} vs {fd}",
                    jac[i][j]
                );
            }
        }
    }
}
