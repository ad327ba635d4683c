//! The reduced-order fluid-structure model (paper section 4, Eqs. 33-36,
//! signs of `docs/model.md` section 6), nondimensionalised for fixed point: its
//! right-hand side, its Jacobian and the structured factorisation of the
//! implicit schemes' stage matrix ([`FsiFactor`]).
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
//! In the model's units ([`super::units`]: pressure by `dp` above `p_c`,
//! displacement by the stroke, time by `T = sqrt(m / c)`, velocity by
//! `a_x L / T`), with state `y = (xi, w, pi_a, pi_b)`:
//!
//! ```text
//! xi'   = a_x w
//! w'    = (phi (pi_b - pi_a) - xi0 - xi) / a_x - 2 zeta w
//! pi_a' = omega_a(xi) (q_t r(D - pi_a) - g_l pi_a + sigma w)
//! pi_b' = omega_b(xi) (g_l (D - pi_b) - q_t r(pi_b) - sigma w)
//! omega_a = omega_a0 / (1 - eps_a xi),  omega_b = omega_b0 / (1 + eps_b xi)
//! ```
//!
//! `D = (p_p - p_c) / dp` is the drop across the compensator in units of the
//! design's ([`Coefficients::drop`]): one unless a changing drop is set.
//!
//! The coefficients, their flow unit and the formulas every integrator
//! shares (static force, chamber volumes, net inflows, quasi-steady root)
//! are in [`super::coefficients`]; the end stops ([`Contact`]) in
//! [`super::stops`]. The names below are re-exported from them, so that
//! `dynamics::fsi::{Coefficients, Model, Contact, DynamicState, ...}` keep
//! naming the model's parts.

pub use super::coefficients::{Coefficients, FLOW_SCALE_LIMIT, MAX_FLOW_SHIFT, Model, TRANSITION_FRACTION, flow_shift};
use super::schemes::{OdeSystem, ShiftedSolve};
pub use super::stops::{Contact, apply_stops, contact_for};
pub use super::units::{DynamicState, Scales};
use crate::scalar::Real;
use crate::throttle::{regularised_root, regularised_root_value};

/// The model in one contact state: what the schemes integrate.
#[derive(Clone, Copy, Debug)]
pub struct Fsi<'a, T> {
    /// Coefficients at the step's temperature.
    pub coefficients: &'a Coefficients<T>,
    /// Contact state, frozen over the step.
    pub contact: Contact,
}

/// What the Jacobian needs at one state.
#[derive(Clone, Copy)]
struct Local<T> {
    /// `omega_a(xi)`, `omega_b(xi)`.
    oa: T,
    ob: T,
    /// Their `xi` derivatives.
    doa: T,
    dob: T,
    /// Orifice slopes `r'(D - pi_a)`, `r'(pi_b)`.
    sa: T,
    sb: T,
    /// Net inflows `F_a`, `F_b` ([`Coefficients::inflows`]).
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
        self.local_with(y, self.orifice_a(y), self.orifice_b(y))
    }

    /// Chamber (a)'s orifice law at `y`: `(r, r')` of its drop `D - pi_a`
    /// ([`regularised_root`]).
    #[inline]
    pub fn orifice_a(&self, y: &[T; 4]) -> (T, T) {
        regularised_root(self.coefficients.supply() - y[2], self.coefficients.u_tr)
    }

    /// Chamber (b)'s orifice law at `y`: `(r, r')` of its drop `pi_b`.
    #[inline]
    pub fn orifice_b(&self, y: &[T; 4]) -> (T, T) {
        regularised_root(y[3], self.coefficients.u_tr)
    }

    /// [`OdeSystem::jacobian`] with the orifice laws given
    /// ([`Fsi::orifice_a`], [`Fsi::orifice_b`] at `y`): a caller that
    /// spreads the Jacobian's cost over several calls (the estimator's
    /// Stability job on the cores without an FPU) evaluates them apart.
    pub fn jacobian_with(&self, y: &[T; 4], a: (T, T), b: (T, T)) -> [[T; 4]; 4] {
        self.jacobian_of(&self.local_with(y, a, b))
    }

    #[inline]
    fn local_with(&self, y: &[T; 4], (ra, sa): (T, T), (rb, sb): (T, T)) -> Local<T> {
        let c = self.coefficients;
        let (da, db) = c.relative_volumes(y[0]);
        let (oa, ob) = (c.omega_a0 / da, c.omega_b0 / db);
        let (fa, fb) = c.inflows(y, ra, rb);
        Local {
            oa,
            ob,
            // d omega_a / d xi = omega_a eps_a / (1 - eps_a xi); omega_b: -omega_b eps_b / (1 + eps_b xi).
            doa: oa * c.eps_a / da,
            dob: -(ob * c.eps_b / db),
            sa,
            sb,
            fa,
            fb,
        }
    }

    /// The Jacobian from the local quantities at a state.
    #[inline]
    fn jacobian_of(&self, l: &Local<T>) -> [[T; 4]; 4] {
        let c = self.coefficients;
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

    /// The net chamber inflows ([`Coefficients::inflows`]) without the
    /// orifice slopes: what the right-hand sides need.
    #[inline]
    fn inflow_values(&self, y: &[T; 4]) -> (T, T) {
        let c = self.coefficients;
        let ra = regularised_root_value(c.supply() - y[2], c.u_tr);
        let rb = regularised_root_value(y[3], c.u_tr);
        c.inflows(y, ra, rb)
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
        let (da, db) = c.relative_volumes(y[0]);
        let (fa, fb) = self.inflow_values(y);
        self.rhs_from(y, c.omega_a0 / da, c.omega_b0 / db, fa, fb)
    }

    fn scaled_rhs(&self, y: &[T; 4], factor: &FsiFactor<T>) -> [T; 4] {
        // D f: the pressure rows are omega(y) F(y) / omega(y_n)
        //      = F(y) (1 - eps_a xi_n) / (1 - eps_a xi), never forming omega.
        let c = self.coefficients;
        let (fa, fb) = self.inflow_values(y);
        let (da, db) = c.relative_volumes(y[0]);
        self.rhs_from(y, factor.da / da, factor.db / db, fa, fb)
    }

    fn jacobian(&self, y: &[T; 4]) -> [[T; 4]; 4] {
        self.jacobian_of(&self.local(y))
    }

    fn linearise(&self, y: &[T; 4], shift: T) -> Option<([T; 4], FsiFactor<T>)> {
        let c = self.coefficients;
        let (da, db) = c.relative_volumes(y[0]);
        let (ra, sa) = regularised_root(c.supply() - y[2], c.u_tr);
        let (rb, sb) = regularised_root(y[3], c.u_tr);
        let (fa, fb) = c.inflows(y, ra, rb);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::schemes::dense_linearisation;

    fn coefficients() -> Coefficients<f64> {
        crate::dynamics::coefficients::tests::coefficients_with(1e-5)
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
