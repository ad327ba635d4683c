//! Singly diagonally implicit Runge-Kutta (SDIRK) steps of the FSI model
//! with the chamber pressures eliminated exactly: the scheme the twin ships.
//!
//! A stiffly accurate SDIRK step (`y_next` is the last stage) solves, stage
//! by stage,
//!
//! ```text
//! Y_i = Z_i + h gamma f(Y_i),   Z_i = y_n + sum_{j<i} (a_ij / gamma) (Y_j - Z_j)
//! ```
//!
//! (`h a_ij f(Y_j) = (a_ij / gamma) (Y_j - Z_j)`: no stage derivative is ever
//! divided out, so no quantity grows like `1 / h`).
//!
//! Each stage equation is solved, not linearised. With the plunger velocity
//! `w` of the stage as the one unknown, `xi = Z_xi + h gamma a_x w` is
//! explicit, and each chamber's pressure row is a scalar equation in its
//! orifice drop `u` whose solution is closed-form (orifice law without
//! regularisation, `r(u) = sign(u) sqrt|u|`):
//!
//! ```text
//! K u + q_t r(u) = c,   K = k + g_l,  k = (1 - eps xi) / (omega_0 h gamma)
//! chamber (a): u = D - pi_a,  c = k (D - Z_a) + g_l D - sigma w
//! chamber (b): u = pi_b,      c = k Z_b       + g_l D - sigma w
//! (D the pressure drop in units of dp, one at the design's: Coefficients::drop)
//! s = 2 |c| / (q_t + R),  R = sqrt(q_t^2 + 4 K |c|),  u = sign(c) s^2
//! ```
//!
//! `K u + q_t r(u)` is strictly increasing, so the root is unique and the
//! formula is exact for any stiffness (`k -> 0` is the quasi-steady limit of
//! [`super::reduced`]); no Newton step ever overshoots a square root. The
//! momentum row is then one scalar equation `g(w) = 0`,
//!
//! ```text
//! g(w) = w - Z_w - h gamma (phi' (pi_b(w) - pi_a(w)) - (xi0 + xi(w)) / a_x - 2 zeta w)
//! g'(w) = 1 + 2 zeta h gamma + (h gamma)^2 - h gamma phi' (d pi_b/dw + d u_a/dw) > 1
//! ```
//!
//! (the pressure derivatives are negative: the plunger's motion compresses
//! the chamber it moves into, the hydraulic damping), solved by a fixed number
//! of Newton iterations from the previous stage's velocity. `g` is
//! strictly increasing and nearly linear (the only nonlinearity is the
//! square root through `s(w)`), so the iteration count is a property of the
//! scheme, not of the data. Held on a stop, `w = 0` and the stage is the two
//! closed forms alone.
//!
//! Stability: the stability function of each tableau is L-stable (`|R(z)|
//! <= 1` on the left half-plane, `R(-inf) = 0`), and because the stage
//! equations are solved rather than linearised, that holds for the
//! nonlinear chamber rows too: a pressure rate of `1e9 1/s` only makes `k`
//! small. `host-tests/tests/twin_cases.rs` checks it on designs with chamber
//! rates from `1e3` to `1e9 1/s`.
//!
//! | tableau | stages | order | source |
//! |---|---|---|---|
//! | [`SDIRK2`] | 2 | 2 | Alexander 1977, Table 1 (`gamma = 1 - 1/sqrt 2`) |
//! | [`SDIRK3`] | 3 | 3 | Alexander 1977, Table 2 (`gamma = 0.4358665215...`) |
//!
//! R. Alexander, "Diagonally implicit Runge-Kutta methods for stiff
//! O.D.E.'s", SIAM J. Numer. Anal. 14 (1977) 1006-1021; also Hairer &
//! Wanner, *Solving ODEs II*, IV.6.

// Tableau code indexes stages explicitly, as the methods are written.
#![allow(clippy::needless_range_loop)]

use super::coefficients::Coefficients;
use super::stops::Contact;
use crate::scalar::Real;

/// Newton iterations of a step's first stage: its starting velocity is the
/// step's initial one, which an abrupt change of temperature or a release
/// can leave far from the stage's (one iteration cost 0.18 % of the step on
/// the paper preset's 80 -> 30 C step, two iterations 0.01 %).
pub const FIRST_STAGE_ITERATIONS: u8 = 1;
/// Newton iterations of the later stages, which start from the previous
/// stage's velocity (a second one changes no survey figure).
pub const LATER_STAGE_ITERATIONS: u8 = 1;
/// Most stages of any tableau here.
pub const MAX_STAGES: usize = 3;

/// A stiffly accurate SDIRK tableau (`b` is the last row of `A`), as data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tableau {
    /// Stages.
    pub stages: usize,
    /// Diagonal `gamma`.
    pub gamma: f64,
    /// Strictly lower part of `A`: `a[i][j]`, `j < i`.
    pub a: [[f64; MAX_STAGES]; MAX_STAGES],
    /// Order of accuracy.
    pub order: u8,
}

/// Alexander's two-stage, order-2, L-stable SDIRK: `gamma = 1 - 1/sqrt(2)`,
/// `c = (gamma, 1)`, `a21 = 1 - gamma`.
pub const SDIRK2: Tableau = {
    let g = 1.0 - core::f64::consts::FRAC_1_SQRT_2;
    Tableau {
        stages: 2,
        gamma: g,
        a: [[0.0; 3], [1.0 - g, 0.0, 0.0], [0.0; 3]],
        order: 2,
    }
};

/// Alexander's three-stage, order-3, L-stable SDIRK: `gamma` the root of
/// `x^3 - 3x^2 + 3x/2 - 1/6` in `(1/6, 1/2)`, `c = (gamma, (1 + gamma)/2, 1)`,
/// `a21 = (1 - gamma)/2`, `a31 = -(6 gamma^2 - 16 gamma + 1)/4`,
/// `a32 = (6 gamma^2 - 20 gamma + 5)/4`.
pub const SDIRK3: Tableau = {
    let g = 0.435_866_521_508_459;
    Tableau {
        stages: 3,
        gamma: g,
        a: [
            [0.0; 3],
            [(1.0 - g) / 2.0, 0.0, 0.0],
            [
                -(6.0 * g * g - 16.0 * g + 1.0) / 4.0,
                (6.0 * g * g - 20.0 * g + 5.0) / 4.0,
                0.0,
            ],
        ],
        order: 3,
    }
};

/// The scheme of a graded substep's short pieces (`Twin::substep`).
pub const FINE: Tableau = SDIRK3;

/// An SDIRK scheme prepared for a fixed step, in scalar type `T`.
#[derive(Clone, Copy, Debug)]
pub struct Dirk<T> {
    stages: usize,
    /// `a_ij / gamma`.
    alpha: [[T; MAX_STAGES]; MAX_STAGES],
    /// The weights `b` (the last row of `A`) times `h` (model time units).
    h_b: [T; MAX_STAGES],
    /// What the whole step's stages share.
    full: StepFactors<T>,
    /// `1 / gamma`: the step of an implicit Euler piece from the stages' `h gamma`.
    inv_gamma: T,
}

/// What the stages of a step of one length share: `h gamma` and the
/// products and reciprocals that follow from it and the model's constant
/// coefficients, formed once per step instead of once per stage and
/// chamber (each stage then multiplies where it divided).
#[derive(Clone, Copy, Debug)]
struct StepFactors<T> {
    /// `h gamma` (model time units).
    hg: T,
    /// `1 / hg` where it is resolved (`hg >= 2^-10`: `1 / hg <= 1024`),
    /// else zero and the stiff chamber's `tau / hg` is divided.
    inv_hg: T,
    /// `h gamma a_x`.
    hg_a_x: T,
    /// `1 + 2 zeta hg + hg^2`, the momentum row's own slope.
    base: T,
    /// `hg phi'`, the hydraulic coupling over the stage.
    hp: T,
    /// `1 / hp` and `base / hp` (zero unless `hp > 1` in a saturating
    /// type: the Newton step's scaled form, [`Dirk::free_stage`]).
    inv_hp: T,
    base_over_hp: T,
}

impl<T: Real> StepFactors<T> {
    fn new(hg: T, c: &Coefficients<T>) -> Self {
        // 2^-10: 1 / hg stays within half of Q12.20's range (a float's
        // reciprocal always is).
        let resolved = !T::SATURATES || hg >= T::from_f64(1.0 / 1024.0);
        let hp = hg * c.phi_over_a_x;
        let base = T::ONE + hg * c.two_zeta + hg * hg;
        let scaled = T::SATURATES && hp > T::ONE;
        let inv_hp = if scaled { T::ONE / hp } else { T::ZERO };
        StepFactors {
            hg,
            inv_hg: if resolved { T::ONE / hg } else { T::ZERO },
            hg_a_x: hg * c.a_x,
            base,
            hp,
            inv_hp,
            base_over_hp: if scaled { base * inv_hp } else { T::ZERO },
        }
    }

    /// `tau / hg`, multiplied where `1 / hg` is resolved.
    #[inline]
    fn over_hg(&self, tau: T) -> T {
        if !T::SATURATES || self.inv_hg > T::ZERO {
            tau * self.inv_hg
        } else {
            tau / self.hg
        }
    }
}

/// One chamber's stage solution.
#[derive(Clone, Copy, Debug)]
struct Chamber<T> {
    /// Orifice drop `u` (`D - pi_a` or `pi_b`).
    u: T,
    /// `du/dw`, the chamber's response to the stage's plunger velocity.
    du_dw: T,
}

/// `K u + q sign(u) sqrt|u| = c` for `u` (unique: the left side is
/// strictly increasing in `u`), and `du/dc`.
///
/// With `R = sqrt(q^2 + 4 K |c|)`: `s = 2 |c| / (q + R)` (never the
/// cancelling `(R - q) / 2K`), `u = sign(c) s^2` and `du/dc = 2 s / R`
/// (`R = 2 K s + q`). `K > 0` and `q >= 0` come from [`chamber`]: `K <=
/// 1 + g_l`, `q <= 1.1` and `|c|` of the order of `K`, so every result
/// stays within a few hundred; only `R^2`, up to `4 K^2`, may exceed
/// fixed point's range, and [`Real::sqrt_sum_products`] forms it from
/// exact products (`q q + 2K 2|c|`). One division, and one square root
/// with its reciprocal ([`Real::sqrt_recip_sum_products`]).
#[inline]
fn root<T: Real>(k: T, q: T, c: T) -> (T, T) {
    let ac = c.abs();
    let (r, inv_r) = T::sqrt_recip_sum_products(q, q, k + k, ac + ac);
    let s = (ac + ac) / (q + r).max(T::tiny());
    let u = s * s;
    // The root's reciprocal, divided where the type cannot hold it.
    let d = if !T::SATURATES || inv_r > T::ZERO {
        (s + s) * inv_r
    } else {
        (s + s) / r.max(T::tiny())
    };
    (if c < T::ZERO { -u } else { u }, d)
}

/// A chamber's stage equation in its orifice drop `u` (both chambers have
/// the same form, `u' = -omega (q_t r(u) + g_l u - e)`, `e = g_l D - sigma w`
/// the drive [`Coefficients::drive`], shared by both chambers):
///
/// ```text
/// u - u_z = -beta (q_t r(u) + g_l u - e),  beta = h gamma omega = h gamma / tau
/// ```
///
/// written with bounded coefficients whatever the stiffness: divided by
/// `beta` (`k = tau / (h gamma) <= 1`, a product by the step's `1 / hg`)
/// for a stiff chamber, as it stands (`beta < 1`, one division) for a
/// slow one or a short step. `tau = 1 / omega(xi)` is the
/// chamber's time constant. `du/dw` is the chamber's response to the
/// stage's velocity at fixed `tau` (the volume's own dependence on `xi(w)`,
/// `eps = A_p L / V` of a few percent, is left to the Newton iteration:
/// leaving it out of the derivative changes no survey figure).
#[inline]
fn chamber<T: Real>(c: &Coefficients<T>, tau: T, f: &StepFactors<T>, u_z: T, e: T) -> Chamber<T> {
    // du/dw = -D n sigma, n = 1 (k-form) or beta.
    let (u, d) = if tau <= f.hg {
        let k = f.over_hg(tau);
        root(k + c.g_l, c.q_t, k * u_z + e)
    } else {
        let beta = f.hg / tau;
        let (u, d) = root(T::ONE + beta * c.g_l, beta * c.q_t, u_z + beta * e);
        (u, d * beta)
    };
    Chamber {
        u,
        du_dw: -(d * c.sigma),
    }
}

/// A stage's known part `Z` and its solution `Y` (model units).
type State<T> = [T; 4];

impl<T: Real> Dirk<T> {
    /// Prepares `tableau` for step `h` (model time units) of the model
    /// whose coefficients are `c`: only the constant ones are read (`a_x`,
    /// `2 zeta`, `phi / a_x`, which no temperature changes), and
    /// [`Dirk::step`] must be given coefficients with the same.
    pub fn new(tableau: &Tableau, h: f64, c: &Coefficients<T>) -> Self {
        let mut alpha = [[T::ZERO; MAX_STAGES]; MAX_STAGES];
        for i in 0..MAX_STAGES {
            for j in 0..MAX_STAGES {
                alpha[i][j] = T::from_f64(tableau.a[i][j] / tableau.gamma);
            }
        }
        // Stiffly accurate: `b` is the last row of `A` (`gamma` on the
        // diagonal). `stages` clamped to `1..=MAX_STAGES`, which the cited
        // tableaus satisfy, so that no index can fail (the estimator may
        // rebuild a twin on its tick).
        let stages = tableau.stages.clamp(1, MAX_STAGES);
        let last = tableau.a.get(stages - 1).copied().unwrap_or([0.0; MAX_STAGES]);
        let mut h_b = [T::ZERO; MAX_STAGES];
        for (j, (hb, a)) in h_b.iter_mut().zip(last).enumerate().take(stages) {
            let b = if j + 1 == stages { tableau.gamma } else { a };
            *hb = T::from_f64(h * b);
        }
        Dirk {
            stages,
            alpha,
            h_b,
            full: StepFactors::new(T::from_f64(h * tableau.gamma), c),
            inv_gamma: T::from_f64(1.0 / tableau.gamma),
        }
    }

    /// One step of `frac` times the prepared step (`0 < frac <= 3`:
    /// `T::ONE` for a whole substep, less for a piece of one, more for a
    /// fixed-point substep that takes the rest an event left it,
    /// [`super::Owed`]; the fixed-point audit's ramps take them) from `y` in `contact`. Held on a stop
    /// the plunger does not move (`xi` kept, `w = 0`) and only the
    /// pressures evolve.
    ///
    /// In free motion the new displacement is `xi + h a_x sum_i b_i w_i`
    /// (exact for the linear row `xi' = a_x w`), accumulated with
    /// [`Real::dot_add_compensated`] and `xi_carry`: a plunger creeping by
    /// less than the resolution per step still arrives.
    pub fn step(&self, c: &Coefficients<T>, y: &State<T>, frac: T, contact: Contact, xi_carry: &mut T) -> State<T> {
        // A whole step shares the prepared factors; a piece of one (a
        // graded substep, an event) forms its own.
        let piece;
        let f = if frac == T::ONE {
            &self.full
        } else {
            piece = StepFactors::new(self.full.hg * frac, c);
            &piece
        };
        if contact != Contact::Free {
            return self.held(c, y, f);
        }
        // Stage increments `Y_j - Z_j`: `Z_i = y + sum_j alpha_ij (Y_j - Z_j)`.
        let mut d = [[T::ZERO; 4]; MAX_STAGES];
        let mut yi = *y;
        let mut ws = [T::ZERO; MAX_STAGES];
        // `stages <= MAX_STAGES` by construction; the `min` lets the
        // compiler see it, so the tick indexes without bounds checks.
        let stages = self.stages.min(MAX_STAGES);
        for i in 0..stages {
            let mut z = *y;
            for j in 0..i {
                let a = self.alpha[i][j];
                for k in 0..4 {
                    z[k] += a * d[j][k];
                }
            }
            let iterations = if i == 0 {
                FIRST_STAGE_ITERATIONS
            } else {
                LATER_STAGE_ITERATIONS
            };
            // The velocity guess: the previous stage's.
            yi = self.free_stage(c, &z, f, yi[1], iterations);
            for k in 0..4 {
                d[i][k] = yi[k] - z[k];
            }
            ws[i] = yi[1];
        }
        // xi + h a_x sum_i b_i w_i, compensated (exact for xi' = a_x w).
        // Fixed point sums the products h b_i w_i exactly: rounded one by
        // one they vanish for a plunger creeping over short steps (0.47 LSB
        // each at w = 31 LSB, 32 substeps per tick), and it stopped 4e-4 of
        // the stroke short (`docs/dynamics.md`, "Fixed-point ranges").
        let h_a_x = if frac == T::ONE { c.a_x } else { c.a_x * frac };
        yi[0] = y[0].dot_add_compensated(h_a_x, &self.h_b[..stages], &ws[..stages], xi_carry);
        yi
    }

    /// A held piece of `frac` of the step by implicit Euler, L-stable and
    /// of first order: one stage for each chamber where the scheme's step
    /// takes `stages`. What a core without an FPU takes for the held rest
    /// of a substep after its second event ([`super::Twin::tick`]).
    pub fn held_euler(&self, c: &Coefficients<T>, y: &State<T>, frac: T) -> State<T> {
        let f = StepFactors::new(self.full.hg * frac * self.inv_gamma, c);
        let (ta, tb) = time_constants(c, y[0]);
        let e = c.drive(T::ZERO);
        let ua = chamber(c, ta, &f, c.supply() - y[2], e).u;
        let ub = chamber(c, tb, &f, y[3], e).u;
        [y[0], T::ZERO, c.supply() - ua, ub]
    }

    /// A held step: `xi` kept, `w = 0`, each chamber's pressure alone (the
    /// stages in the chambers' orifice drops).
    fn held(&self, c: &Coefficients<T>, y: &State<T>, f: &StepFactors<T>) -> State<T> {
        let (ta, tb) = time_constants(c, y[0]);
        let (ua0, ub0) = (c.supply() - y[2], y[3]);
        let (mut ua, mut ub) = (ua0, ub0);
        let mut da = [T::ZERO; MAX_STAGES];
        let mut db = [T::ZERO; MAX_STAGES];
        // At rest the drive is the capillary's full-drop flow.
        let e = c.drive(T::ZERO);
        for i in 0..self.stages.min(MAX_STAGES) {
            let (mut za, mut zb) = (ua0, ub0);
            for j in 0..i {
                let a = self.alpha[i][j];
                za += a * da[j];
                zb += a * db[j];
            }
            ua = chamber(c, ta, f, za, e).u;
            ub = chamber(c, tb, f, zb, e).u;
            da[i] = ua - za;
            db[i] = ub - zb;
        }
        [y[0], T::ZERO, c.supply() - ua, ub]
    }

    /// The free stage `Y = Z + h gamma f(Y)`: `iterations` Newton
    /// iterations on `w` from `w0`. The state after the last one follows
    /// from the last evaluation by the derivatives (its error is second
    /// order in the last correction) instead of a further evaluation.
    fn free_stage(&self, c: &Coefficients<T>, z: &State<T>, f: &StepFactors<T>, w0: T, iterations: u8) -> State<T> {
        let u_za = c.supply() - z[2];
        let mut w = w0;
        let mut out = [T::ZERO; 4];
        // The chambers' time constants at the stage's known displacement:
        // the volumes change by `eps` (a few percent) over a whole stroke,
        // and by far less over a stage.
        let (ta, tb) = time_constants(c, z[0]);
        for _ in 0..iterations.max(1) {
            let xi = z[0] + f.hg_a_x * w;
            let e = c.drive(w);
            let a = chamber(c, ta, f, u_za, e);
            let b = chamber(c, tb, f, z[3], e);
            let force = c.phi_over_a_x * (b.u - (c.supply() - a.u)) - (c.xi0 + xi) * c.inv_a_x;
            let g = w - z[1] - f.hg * (force - c.two_zeta * w);
            // d(pi_b - pi_a)/dw = du_b/dw + du_a/dw < 0 (hydraulic damping):
            // g' = base + hp s. On strongly damped designs hp s (the
            // hydraulic damping over a step) reaches 1,850 (survey, 10,000
            // designs): a saturating type divides g and g' by hp first,
            // with the step's 1 / hp (`docs/dynamics.md`, "Fixed-point ranges").
            let s = -(b.du_dw + a.du_dw);
            let dw = if T::SATURATES && f.hp > T::ONE && s > T::ONE {
                -((g * f.inv_hp) / (f.base_over_hp + s))
            } else {
                -(g / (f.base + f.hp * s))
            };
            w += dw;
            out = [
                xi + f.hg_a_x * dw,
                w,
                c.supply() - (a.u + a.du_dw * dw),
                b.u + b.du_dw * dw,
            ];
        }
        out
    }
}

/// The chambers' time constants `tau = 1 / omega(xi)` (model units), with
/// `xi` limited to the stroke (the volumes at the stops).
#[inline]
fn time_constants<T: Real>(c: &Coefficients<T>, xi: T) -> (T, T) {
    let (va, vb) = c.relative_volumes(xi.clamp_to(T::ZERO, T::ONE));
    (va * c.inv_omega_a0, vb * c.inv_omega_b0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn root_solves_its_equation_for_any_stiffness() {
        for &k in &[1e-9, 1e-3, 0.5, 10.0, 1e6] {
            for &c in &[-2.0, -1e-7, 0.0, 1e-9, 0.3, 5.0] {
                for &q in &[0.0, 1e-6, 1.02, 40.0] {
                    let (u, d) = root(k, q, c);
                    let r = if u < 0.0 { -(-u).sqrt() } else { u.sqrt() };
                    let resid = k * u + q * r - c;
                    assert!(resid.abs() <= 1e-12 * (1.0 + c.abs()), "k {k} q {q} c {c}: {resid}");
                    // du/dc against a central difference (away from the kink at 0).
                    if c.abs() > 1e-6 {
                        let e = 1e-7 * c.abs();
                        let fd = (root(k, q, c + e).0 - root(k, q, c - e).0) / (2.0 * e);
                        assert!(
                            (d - fd).abs() <= 1e-5 * (1.0 + fd.abs()),
                            "k {k} q {q} c {c}: {d} vs {fd}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn tableaus_have_their_order_conditions() {
        for t in [SDIRK2, SDIRK3] {
            let n = t.stages;
            let mut a = t.a;
            for i in 0..n {
                a[i][i] = t.gamma;
            }
            let b = a[n - 1];
            let c: Vec<f64> = (0..n).map(|i| a[i].iter().sum()).collect();
            let sum_b: f64 = b.iter().sum();
            assert!((sum_b - 1.0).abs() < 1e-14);
            let bc: f64 = (0..n).map(|i| b[i] * c[i]).sum();
            assert!((bc - 0.5).abs() < 1e-14, "{bc}");
            if t.order >= 3 {
                let bcc: f64 = (0..n).map(|i| b[i] * c[i] * c[i]).sum();
                let bac: f64 = (0..n).map(|i| b[i] * (0..n).map(|j| a[i][j] * c[j]).sum::<f64>()).sum();
                assert!((bcc - 1.0 / 3.0).abs() < 1e-13, "{bcc}");
                assert!((bac - 1.0 / 6.0).abs() < 1e-13, "{bac}");
            }
        }
    }
}
