//! Throttle laws (`docs/model.md` section 3).
//!
//! * Laminar capillary, Hagen-Poiseuille: `Q = dp / R_l`,
//!   `R_l = 128 mu L / (pi d^4)`.
//! * Sharp-edged orifice: `Q = C_d f sqrt(2 |dp| / rho) sign(dp)`, i.e.
//!   `dp = R_t Q |Q|` with `R_t = rho / (2 C_d^2 f^2)`, `f = pi d^2 / 4`.
//! * The window the plunger opens: area `pi d x`, orifice law with the
//!   window's own discharge coefficient (Eq. 7).
//!
//! [`FlowLaws`] holds the three at one oil state, one coefficient each (what
//! the estimator evaluates every tick). The dynamic model needs the orifice
//! law to be C1 at zero flow; it uses [`regularised_root`], the `regRoot`
//! form of Modelica, Hopsan and Simscape.

use crate::scalar::{Float, Real};

/// Laminar throttle (capillary).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capillary<T> {
    /// Bore \[m\].
    pub diameter: T,
    /// Length \[m\].
    pub length: T,
}

impl<T: Float> Capillary<T> {
    /// `pi d^4 / (128 L)` [m^3]: the conductance times the dynamic viscosity.
    #[inline]
    pub fn bore_term(&self) -> T {
        let d2 = self.diameter * self.diameter;
        T::from_f64(core::f64::consts::PI / 128.0) * d2 * d2 / self.length
    }

    /// Resistance `R_l = 128 mu L / (pi d^4)` [Pa s/m^3] for dynamic viscosity `mu` [Pa s].
    #[inline]
    pub fn resistance(&self, dynamic_viscosity: T) -> T {
        dynamic_viscosity / self.bore_term()
    }
}

/// Turbulent throttle (sharp-edged orifice).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orifice<T> {
    /// Bore \[m\].
    pub diameter: T,
    /// Discharge coefficient `C_d` [-].
    pub discharge_coefficient: T,
}

impl<T: Float> Orifice<T> {
    /// Flow area `f = pi d^2 / 4` [m^2].
    #[inline]
    pub fn area(&self) -> T {
        T::from_f64(core::f64::consts::FRAC_PI_4) * self.diameter * self.diameter
    }

    /// Quadratic resistance `R_t = rho / (2 C_d^2 f^2)` [Pa s^2/m^6].
    #[inline]
    pub fn resistance(&self, density: T) -> T {
        let cf = self.discharge_coefficient * self.area();
        density / (T::from_f64(2.0) * cf * cf)
    }

    /// Signed flow for a pressure drop `dp` \[Pa\] at density `rho` [kg/m^3]:
    /// `C_d f sqrt(2 |dp| / rho) sign(dp)` [m^3/s].
    #[inline]
    pub fn flow(&self, dp: T, density: T) -> T {
        let q = self.discharge_coefficient * self.area() * (T::from_f64(2.0) * dp.abs() / density).sqrt();
        if dp < T::ZERO { -q } else { q }
    }
}

/// The window opened by the plunger (Eq. 7): area `pi d x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slot<T> {
    /// Window diameter `d` \[m\].
    pub diameter: T,
    /// Discharge coefficient `eta` [-].
    pub discharge_coefficient: T,
}

impl<T: Float> Slot<T> {
    /// Open area `f_throt = pi d x` [m^2] at opening `x` \[m\] (zero when closed).
    #[inline]
    pub fn area(&self, x: T) -> T {
        T::from_f64(core::f64::consts::PI) * self.diameter * x.max(T::ZERO)
    }

    /// `eta pi d sqrt(2 dp)` [m^2/s (kg/m^3)^(1/2)]: the window flow per
    /// metre of opening times `sqrt(rho)`, so that
    /// `Q_throt = window_factor(dp) x / sqrt(rho)` (Eq. 7).
    #[inline]
    pub fn window_factor(&self, dp: T) -> T {
        self.discharge_coefficient
            * T::from_f64(core::f64::consts::PI)
            * self.diameter
            * (T::from_f64(2.0) * dp.max(T::ZERO)).sqrt()
    }

    /// Flow through the window (Eq. 7): `eta pi d x sqrt(2 dp / rho)` [m^3/s].
    #[inline]
    pub fn flow(&self, x: T, dp: T, density: T) -> T {
        self.window_factor(dp) * x.max(T::ZERO) / density.sqrt()
    }
}

/// The three throttle laws at one oil state and the design's pressure
/// drop, each reduced to one coefficient: what changes between evaluations
/// (a chamber's pressure drop, the opening) then costs a multiply, and a
/// root for the orifice. The estimator keeps one, refreshed with the oil's
/// properties, and evaluates the flows from it every tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowLaws<T> {
    /// Capillary conductance `1 / R_l` [m^3/(s Pa)].
    pub capillary_conductance: T,
    /// `C_d f sqrt(2 / rho)` of the orifice [m^3/(s sqrt(Pa))].
    pub orifice_factor: T,
    /// `eta pi d sqrt(2 dp / rho)` of the window [m^2/s].
    pub window_factor: T,
}

impl<T: Float> FlowLaws<T> {
    /// The laws of `capillary`, `orifice` and the window for oil of
    /// `density` [kg/m^3] and `dynamic_viscosity` [Pa s]. The window enters
    /// as its [`Slot::window_factor`] at the pressure drop across it, which
    /// does not depend on the oil: a caller evaluating the laws at many oil
    /// states computes it once.
    #[inline]
    pub fn new(
        capillary: &Capillary<T>,
        orifice: &Orifice<T>,
        slot_window_factor: T,
        density: T,
        dynamic_viscosity: T,
    ) -> Self {
        let inv_sqrt_rho = T::ONE / density.sqrt();
        FlowLaws {
            capillary_conductance: T::ONE / capillary.resistance(dynamic_viscosity),
            orifice_factor: orifice.discharge_coefficient
                * orifice.area()
                * T::from_f64(core::f64::consts::SQRT_2)
                * inv_sqrt_rho,
            window_factor: slot_window_factor * inv_sqrt_rho,
        }
    }

    /// Flow through the capillary for the pressure drop `drop` \[Pa\] across
    /// it: `drop / R_l` [m^3/s].
    #[inline]
    pub fn capillary_flow(&self, drop: T) -> T {
        drop * self.capillary_conductance
    }

    /// Signed flow through the orifice for the pressure drop `drop` \[Pa\]
    /// across it: `C_d f sqrt(2 |drop| / rho) sign(drop)` [m^3/s]
    /// ([`Orifice::flow`] with the oil's density in the coefficient).
    #[inline]
    pub fn orifice_flow(&self, drop: T) -> T {
        self.orifice_factor * drop.abs().sqrt().copysign(drop)
    }

    /// Flow through the window at the opening `x` \[m\] (zero when closed):
    /// `eta pi d x sqrt(2 dp / rho)` [m^3/s] ([`Slot::flow`], Eq. 7).
    #[inline]
    pub fn window_flow(&self, x: T) -> T {
        self.window_factor * x.max(T::ZERO)
    }
}

/// The value of [`regularised_root`] alone.
#[inline]
pub fn regularised_root_value<T: Real>(u: T, u_tr: T) -> T {
    regularised_root(u, u_tr).0
}

/// C1 square-root law `u / (u^2 + u_tr^2)^(1/4)` and its derivative.
///
/// Equals `sign(u) sqrt(|u|)` to a relative `u_tr^2 / (4 u^2)` for
/// `|u| >> u_tr`, has the finite slope `1 / sqrt(u_tr)` at zero, and is odd.
/// Returns `(value, d value / du)`. Works in any [`Real`], including fixed
/// point: everything is scaled by `m = max(|u|, u_tr)` first,
///
/// ```text
/// r  = sign(u) (|u|/m) sqrt(m) / S^(1/4)
/// r' = ((|u|/m)^2 / 2 + (u_tr/m)^2) / (sqrt(m) S^(5/4)),   S = (|u|/m)^2 + (u_tr/m)^2 in [1, 2]
/// ```
///
/// so no square of a small drop is ever formed (in Q12.20, `u^2` and
/// `u_tr^2` both vanish below `u ~ 1e-3`: the unscaled law returned the
/// saturated 2048 at `u = 5e-4`). A zero `u_tr` is the plain root, with
/// the saturated (or infinite) slope at `u = 0`.
#[inline]
pub fn regularised_root<T: Real>(u: T, u_tr: T) -> (T, T) {
    let a = u.abs();
    let t = u_tr.abs();
    let m = a.max(t);
    if !(m > T::ZERO) {
        return (T::ZERO, T::ONE / m.max(T::ZERO));
    }
    let (ra, rt) = (a / m, t / m);
    let s = ra * ra + rt * rt;
    let s14 = s.sqrt().sqrt();
    let sm = m.sqrt();
    let value = ra * sm / s14;
    let slope = (T::HALF * ra * ra + rt * rt) / (sm * s * s14);
    (if u < T::ZERO { -value } else { value }, slope)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regularised_root_matches_root_away_from_zero() {
        let (v, s) = regularised_root(0.25f64, 1e-4);
        assert!((v - 0.5).abs() < 1e-7);
        assert!((s - 1.0).abs() < 1e-6);
        let (v0, s0) = regularised_root(0.0f64, 1e-4);
        assert_eq!(v0, 0.0);
        assert!((s0 - 100.0).abs() < 1e-9);
        let (vn, _) = regularised_root(-0.25f64, 1e-4);
        assert!((vn + 0.5).abs() < 1e-7);
    }

    #[test]
    fn regularised_root_keeps_its_resolution_in_fixed_point() {
        use crate::scalar::Fixed;
        for &(u, tr) in &[(5e-4, 1e-5), (1e-5, 1e-5), (2e-6, 1e-5), (0.3, 1e-5), (-7e-4, 1e-5)] {
            let (uf, tf) = (Fixed::from_f64(u), Fixed::from_f64(tr));
            let (v, d) = regularised_root(uf, tf);
            // Against the same law at the inputs as Q12.20 holds them.
            let (v64, d64) = regularised_root(uf.to_f64(), tf.to_f64());
            // One LSB of Q12.20 on the inputs moves the value by at most
            // 1e-6 / (2 sqrt(u_tr)) ~ 2e-4 near zero.
            assert!(
                (v.to_f64() - v64).abs() <= 3e-4 * (1.0 + v64.abs()),
                "value at {u}: {v:?} vs {v64}"
            );
            // The slope against the law at the inputs as Q12.20 holds them:
            // u_tr = 1e-5 is 10 LSB (4.6 % low), which alone moves the slope
            // near zero by 2.4 %; the computation adds a few LSB.
            assert!((d.to_f64() - d64).abs() <= 2e-3 * d64, "slope at {u}: {d:?} vs {d64}");
        }
    }

    #[test]
    fn f32_agrees_with_f64() {
        // The scaled law in f32 against the same law in f64: a few
        // roundings (three roots, three divisions).
        for i in 1..2000 {
            let u = i as f32 * 5e-4 - 0.4;
            let (v32, s32) = regularised_root(u, 1e-5f32);
            let (v64, s64) = regularised_root(u as f64, 1e-5f64);
            assert!(
                ((v32 as f64) - v64).abs() <= 6.0 * f32::EPSILON as f64 * v64.abs(),
                "value at {u}"
            );
            assert!(
                ((s32 as f64) - s64).abs() <= 10.0 * f32::EPSILON as f64 * s64.abs(),
                "slope at {u}"
            );
        }
    }

    #[test]
    fn flow_laws_agree_with_the_laws() {
        let capillary = Capillary {
            diameter: 1.2e-3f64,
            length: 0.03,
        };
        let orifice = Orifice {
            diameter: 0.7e-3f64,
            discharge_coefficient: 0.61,
        };
        let slot = Slot {
            diameter: 8e-3f64,
            discharge_coefficient: 0.7,
        };
        let (dp, rho, mu) = (3.0e5, 870.0, 0.02);
        let laws = FlowLaws::new(&capillary, &orifice, slot.window_factor(dp), rho, mu);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
        for drop in [2.0e5, 1.0, 0.0, -3.5e4] {
            assert!(
                close(laws.capillary_flow(drop), drop / capillary.resistance(mu)),
                "{drop}"
            );
            assert!(close(laws.orifice_flow(drop), orifice.flow(drop, rho)), "{drop}");
        }
        for x in [1e-3, 2e-5, 0.0, -1e-4] {
            assert!(close(laws.window_flow(x), slot.flow(x, dp, rho)), "{x}");
        }
    }

    #[test]
    fn orifice_flow_and_resistance_agree() {
        let o = Orifice {
            diameter: 0.7e-3f64,
            discharge_coefficient: 0.61,
        };
        let rho = 870.0;
        let dp = 2.0e5;
        let q = o.flow(dp, rho);
        assert!((o.resistance(rho) * q * q - dp).abs() < 1e-6 * dp);
        assert_eq!(o.flow(-dp, rho), -q);
    }
}
