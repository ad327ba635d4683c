//! The FSI model's coefficients in its units ([`super::units`]), and the
//! formulas of the model that every integrator shares: the static force on
//! the plunger, the chamber volumes, the chambers' net inflows, and their
//! quasi-steady root.
//!
//! With `r` the C1 regularised root ([`crate::throttle::regularised_root`],
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

use super::units::{DynamicState, Scales};
use crate::equilibrium::Equilibrium;
use crate::error::{ModelError, finite, represent};
use crate::fluid::FluidState;
use crate::params::Params;
use crate::scalar::{Float, Real};

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
    /// the unscaled [`OdeSystem::rhs`](super::schemes::OdeSystem::rhs) and
    /// [`OdeSystem::jacobian`](super::schemes::OdeSystem::jacobian) use it
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
    /// The pressure drop across the compensator in units of the model's
    /// `dp`: `D = (p_p - p_c) / dp`, one unless a changing drop is set
    /// ([`super::Twin::set_pressures`]; the model's units stay those of
    /// `dp`). It enters as the supply pressure `pi_p = D` above the outlet
    /// (the orifice drop of chamber (a) is `D - pi_a`) and through the
    /// chambers' drive `g_l D - sigma w`. Fixed point: `D <= 1` keeps the
    /// ranges of `docs/dynamics.md`.
    pub drop: T,
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

    /// The chamber rates `omega_a0`, `omega_b0` in the flow unit `2^shift
    /// Q*`, in `F`: what [`Coefficients::omega_a0`] and
    /// [`Coefficients::omega_b0`] are before a fixed-point twin saturates
    /// them (a product each, no `f64`).
    pub fn chamber_rates(&self, shift: u8) -> [F; 2] {
        let s = F::from_f64((1u32 << shift) as f64);
        [self.omega[0] * s, self.omega[1] * s]
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
            drop: T::ONE,
            flow_shift: shift,
        })
    }

    /// The model state of a quasi-static equilibrium (at rest).
    pub fn equilibrium_state<T: Real>(&self, eq: &Equilibrium<F>) -> [T; 4] {
        self.rest_state(eq.x, eq.p_a, eq.p_b)
    }

    /// The state at rest at displacement `x` \[m\] with chamber pressures
    /// `p_a`, `p_b` \[Pa\], in model units (an equilibrium's force
    /// balance, [`crate::equilibrium::Balance`]).
    pub fn rest_state<T: Real>(&self, x: F, p_a: F, p_b: F) -> [T; 4] {
        self.scales.from_si(&DynamicState {
            x,
            v: F::ZERO,
            p_a,
            p_b,
        })
    }
}

impl<T: Real> Coefficients<T> {
    /// The same coefficients in `f32` (rounded where `T` is wider; exact
    /// from fixed point, whose 32-bit words `f32` holds to 24 bits).
    pub fn to_f32(&self) -> Coefficients<f32> {
        Coefficients {
            a_x: self.a_x.to_f32(),
            inv_a_x: self.inv_a_x.to_f32(),
            phi_over_a_x: self.phi_over_a_x.to_f32(),
            two_zeta: self.two_zeta.to_f32(),
            xi0: self.xi0.to_f32(),
            omega_a0: self.omega_a0.to_f32(),
            inv_omega_a0: self.inv_omega_a0.to_f32(),
            eps_a: self.eps_a.to_f32(),
            omega_b0: self.omega_b0.to_f32(),
            inv_omega_b0: self.inv_omega_b0.to_f32(),
            eps_b: self.eps_b.to_f32(),
            sigma: self.sigma.to_f32(),
            u_tr: self.u_tr.to_f32(),
            q_t: self.q_t.to_f32(),
            g_l: self.g_l.to_f32(),
            drop: self.drop.to_f32(),
            flow_shift: self.flow_shift,
        }
    }

    /// Net static force on the plunger in units of the spring force at one
    /// stroke, divided by `a_x`: positive opens (towards `x_max`).
    #[inline]
    pub fn static_force(&self, y: &[T; 4]) -> T {
        self.phi_over_a_x * (y[3] - y[2]) - (self.xi0 + y[0]) * self.inv_a_x
    }

    /// The chamber volumes at displacement `xi`, relative to those at
    /// `xi = 0`: `(1 - eps_a xi, 1 + eps_b xi)`. The chamber rates are
    /// `omega_a = omega_a0 / (1 - eps_a xi)`, `omega_b = omega_b0 / (1 + eps_b xi)`.
    #[inline]
    pub fn relative_volumes(&self, xi: T) -> (T, T) {
        (T::ONE - self.eps_a * xi, T::ONE + self.eps_b * xi)
    }

    /// What drives each chamber's orifice at plunger velocity `w`: the
    /// capillary's full-drop flow less the flow the plunger displaces,
    /// `g_l D - sigma w` (both chambers' rows read `u' = -omega (q_t r(u) +
    /// g_l u - (g_l D - sigma w))` in their orifice drops `u = D - pi_a`,
    /// `u = pi_b`; `D` is [`Coefficients::drop`], one at the design's drop).
    #[inline]
    pub fn drive(&self, w: T) -> T {
        self.g_l * self.drop - self.sigma * w
    }

    /// The supply pressure above the outlet in model units, `pi_p = D`
    /// ([`Coefficients::drop`]): chamber (a)'s orifice drop is
    /// `supply() - pi_a`.
    #[inline]
    pub fn supply(&self) -> T {
        self.drop
    }

    /// The chambers' net inflows `(F_a, F_b)` at `y`, for the orifice flows
    /// `ra = r(D - pi_a)`, `rb = r(pi_b)` (`D` the drop,
    /// [`Coefficients::drop`]):
    ///
    /// ```text
    /// F_a = q_t r(D - pi_a) - g_l pi_a + sigma w
    /// F_b = g_l (D - pi_b) - q_t r(pi_b) - sigma w
    /// ```
    ///
    /// The pressure rows of the model are `pi_a' = omega_a F_a`,
    /// `pi_b' = omega_b F_b`. The caller evaluates the orifice law, with
    /// [`regularised_root`](crate::throttle::regularised_root) where it
    /// also needs the slopes (the Jacobian, the stage matrix) and with
    /// [`regularised_root_value`](crate::throttle::regularised_root_value)
    /// where not (the right-hand sides): a version returning both and
    /// relying on the optimiser to drop the slopes cost the explicit and
    /// Rosenbrock ticks 2-8 % on Cortex-M4F or on the host, depending on
    /// what LLVM chose to inline.
    #[inline]
    pub fn inflows(&self, y: &[T; 4], ra: T, rb: T) -> (T, T) {
        let sw = self.sigma * y[1];
        (
            self.q_t * ra - self.g_l * y[2] + sw,
            self.g_l * (self.drop - y[3]) - self.q_t * rb - sw,
        )
    }

    /// The root `s >= 0` of `g_l s^2 + q_t s = drive` (`drive >= 0`):
    /// `s = 2 drive / (q_t + sqrt(q_t^2 + 4 g_l drive))`, the orifice flow
    /// of a chamber whose inflow vanishes (orifice law without
    /// regularisation).
    #[inline]
    fn quasi_steady_root(&self, drive: T) -> T {
        let two = T::ONE + T::ONE;
        let root = (self.q_t * self.q_t + two * two * self.g_l * drive).sqrt();
        two * drive / (self.q_t + root)
    }

    /// The chambers' quasi-steady state at plunger velocity `w` (their
    /// inflows zero, the limit `C_a, C_b -> 0` of [`super::reduced`]):
    /// `s = sqrt(D - pi_a) = sqrt(pi_b)` and `ds/dw`. Both chambers give
    /// the same quadratic, `g_l s^2 + q_t s - (g_l D - sigma w) = 0`; beyond
    /// `sigma w >= g_l D` (the plunger outruns the capillaries) `s` is held
    /// at zero.
    #[inline]
    pub fn quasi_steady(&self, w: T) -> (T, T) {
        let two = T::ONE + T::ONE;
        let drive = self.drive(w).max(T::ZERO);
        let s = self.quasi_steady_root(drive);
        let ds = if drive > T::ZERO {
            -(self.sigma / (two * self.g_l * s + self.q_t))
        } else {
            T::ZERO
        };
        (s, ds)
    }

    /// The static force with the chambers at their quasi-steady pressures
    /// for the current temperature (what the force settles to within tens
    /// of microseconds at rest): `phi' (2 s0^2 - D) - (xi0 + xi) / a_x`,
    /// `s0` the quasi-steady root at rest ([`Coefficients::quasi_steady`]
    /// at `w = 0`).
    #[inline]
    pub fn quasi_steady_force(&self, xi: T) -> T {
        let two = T::ONE + T::ONE;
        let s0 = self.quasi_steady_root(self.drive(T::ZERO));
        self.phi_over_a_x * (two * s0 * s0 - self.drop) - (self.xi0 + xi) * self.inv_a_x
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
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::throttle::regularised_root;

    /// A paper-like coefficient set for unit tests (`u_tr` is the
    /// regularised law's transition: zero for the plain root).
    pub(crate) fn coefficients_with(u_tr: f64) -> Coefficients<f64> {
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
            u_tr,
            q_t: 1.02,
            g_l: 1.4,
            drop: 1.0,
            flow_shift: 0,
        }
    }

    fn coefficients() -> Coefficients<f64> {
        coefficients_with(0.0)
    }

    #[test]
    fn the_quasi_steady_root_zeroes_both_inflows() {
        // With the plain orifice law (u_tr = 0) the quasi-steady pressures
        // pi_a = 1 - s^2, pi_b = s^2 make both net inflows vanish, and
        // ds/dw matches a central difference.
        let c = coefficients();
        for w in [-0.8, -0.1, 0.0, 0.05, 0.9] {
            let (s, ds) = c.quasi_steady(w);
            let y = [0.3, w, 1.0 - s * s, s * s];
            let (ra, rb) = (regularised_root(1.0 - y[2], 0.0).0, regularised_root(y[3], 0.0).0);
            let (fa, fb) = c.inflows(&y, ra, rb);
            assert!(fa.abs() < 1e-12 && fb.abs() < 1e-12, "w {w}: {fa} {fb}");
            let h = 1e-6;
            let fd = (c.quasi_steady(w + h).0 - c.quasi_steady(w - h).0) / (2.0 * h);
            assert!((ds - fd).abs() < 1e-8, "w {w}: {ds} vs {fd}");
        }
        // At rest the quasi-steady force is the static force at those pressures.
        let (s0, _) = c.quasi_steady(0.0);
        let xi = 0.4;
        let at_rest = c.static_force(&[xi, 0.0, 1.0 - s0 * s0, s0 * s0]);
        assert!((c.quasi_steady_force(xi) - at_rest).abs() < 1e-12);
        // Beyond sigma w = g_l the root is held at zero.
        assert_eq!(c.quasi_steady(2.0 * c.g_l / c.sigma), (0.0, 0.0));
    }

    #[test]
    fn flow_shift_keeps_g_l_under_the_limit() {
        assert_eq!(flow_shift(FLOW_SCALE_LIMIT), 0);
        assert_eq!(flow_shift(FLOW_SCALE_LIMIT * 1.5), 1);
        assert_eq!(flow_shift(f64::NAN), 0);
        assert_eq!(flow_shift(f64::INFINITY), MAX_FLOW_SHIFT);
    }
}
