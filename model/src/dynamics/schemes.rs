//! One-step schemes for `y' = f(y)` with a frozen right-hand side over the
//! step, generic over the scalar type and the state dimension.
//!
//! Rosenbrock (linearly implicit Runge-Kutta) methods in the transformed
//! form of Hairer & Wanner (IV.7), one factorisation of the stage matrix
//! per step (a dense LU, or the system's own: [`OdeSystem::linearise`]):
//!
//! ```text
//! (I / (h gamma) - J) U_i = f(y + sum_j a_ij U_j) + sum_j (c_ij / h) U_j
//! y_next = y + sum_i m_i U_i
//! ```
//!
//! | scheme | stages | order | stability | source |
//! |---|---|---|---|---|
//! | [`Scheme::LinearlyImplicitEuler`] | 1 | 1 | L-stable | - |
//! | [`Scheme::Ros2`] | 2 | 2 | L-stable | Verwer, Spee, Blom, Hundsdorfer 1999 |
//! | [`Scheme::Ros3`] | 3 | 3 | L-stable | Sandu et al. 1997 |
//! | [`Scheme::Rodas3`] | 4 | 3 | L-stable, stiffly accurate | Sandu et al. 1997 |
//! | [`Scheme::Rk4`] | 4 | 4 | explicit (|h lambda| < 2.8) | Kutta 1901 |
//!
//! The cost is fixed by the scheme: no iteration depends on the data.
//!
//! The FSI twin ships neither: its scheme is an SDIRK whose stage equations
//! are solved with the chamber pressures eliminated exactly
//! ([`super::dirk`], [`Scheme::Sdirk3`]). The linearly implicit schemes
//! here linearise the orifice's square root over a whole step, which
//! overshoots (and can diverge) where a stiff chamber's orifice drop is near
//! zero; they stay for comparison and for generic systems (the reduced
//! model).

// Matrix code indexes rows and columns explicitly, as the algorithms are
// written (EISPACK, Hairer & Wanner); iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

use crate::linalg::Lu;
use crate::scalar::Real;

/// A system `y' = f(y)` with its Jacobian.
pub trait OdeSystem<T: Copy, const N: usize> {
    /// How the system factorises `shift I - J` (a dense [`Lu`] through
    /// [`dense_linearisation`], or something exploiting its structure).
    type Factor: ShiftedSolve<T, N>;
    /// The right-hand side `f(y)`.
    fn rhs(&self, y: &[T; N]) -> [T; N];
    /// The Jacobian `df/dy` at `y`.
    fn jacobian(&self, y: &[T; N]) -> [[T; N]; N];
    /// `D f(y)` together with a factorisation of `D (shift I - J(y))`, for
    /// the row scaling `D` the factor carries (one pass can share the work
    /// of both); `None` when the matrix is singular.
    fn linearise(&self, y: &[T; N], shift: T) -> Option<([T; N], Self::Factor)>;
    /// `D f(y)` with the scaling of `factor` (a system whose `f` has large
    /// rows may compute the scaled rows without forming the large values).
    fn scaled_rhs(&self, y: &[T; N], factor: &Self::Factor) -> [T; N] {
        factor.scale(&self.rhs(y))
    }
}

/// Solves `D (shift I - J) u = r` with a factorised, row-scaled matrix.
///
/// The diagonal row scaling `D` lets a system keep every number of the
/// stage equations bounded (what fixed point needs): a row whose rate is
/// large is divided by it. The stage equations are the same equations; the
/// solution `u` is unchanged by the scaling.
pub trait ShiftedSolve<T: Copy, const N: usize> {
    /// The solution `u` for an already scaled right-hand side `r = D b`.
    fn solve(&self, r: &[T; N]) -> [T; N];
    /// `D v` (the identity unless the factor scales rows).
    fn scale(&self, v: &[T; N]) -> [T; N] {
        *v
    }
}

impl<T: Real, const N: usize> ShiftedSolve<T, N> for Lu<T, N> {
    fn solve(&self, r: &[T; N]) -> [T; N] {
        Lu::solve(self, r)
    }
}

/// [`OdeSystem::linearise`] for any system: `f(y)` and a dense pivoted LU
/// of `shift I - J(y)`; `None` when [`Lu::new`] finds a zero or non-finite
/// pivot (the matrix is singular, or `J(y)` is not finite).
pub fn dense_linearisation<T: Real, S: OdeSystem<T, N> + ?Sized, const N: usize>(
    sys: &S,
    y: &[T; N],
    shift: T,
) -> Option<([T; N], Lu<T, N>)> {
    let jac = sys.jacobian(y);
    let mut w = [[T::ZERO; N]; N];
    for i in 0..N {
        for j in 0..N {
            w[i][j] = -jac[i][j];
        }
        w[i][i] += shift;
    }
    Some((sys.rhs(y), Lu::new(w)?))
}

/// The one-step schemes the integrator can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Scheme {
    /// Classical explicit Runge-Kutta of order 4.
    Rk4,
    /// Linearly implicit (Rosenbrock) Euler, order 1.
    LinearlyImplicitEuler,
    /// Two-stage L-stable Rosenbrock method ROS2, order 2.
    Ros2,
    /// Three-stage L-stable Rosenbrock method ROS3, order 3.
    Ros3,
    /// Four-stage stiffly accurate Rosenbrock method RODAS3, order 3.
    Rodas3,
    /// Alexander's two-stage L-stable SDIRK, order 2, stages solved with
    /// the pressures eliminated exactly (FSI model only, [`super::dirk`]).
    Sdirk2,
    /// Alexander's three-stage L-stable SDIRK, order 3 (FSI model only,
    /// [`super::dirk`]).
    Sdirk3,
}

impl Scheme {
    /// Every scheme, for benchmarks.
    pub const ALL: [Scheme; 7] = [
        Scheme::Rk4,
        Scheme::LinearlyImplicitEuler,
        Scheme::Ros2,
        Scheme::Ros3,
        Scheme::Rodas3,
        Scheme::Sdirk2,
        Scheme::Sdirk3,
    ];

    /// Short name (`"ros2"`...).
    pub const fn name(self) -> &'static str {
        match self {
            Scheme::Rk4 => "rk4",
            Scheme::LinearlyImplicitEuler => "linearly-implicit-euler",
            Scheme::Ros2 => "ros2",
            Scheme::Ros3 => "ros3",
            Scheme::Rodas3 => "rodas3",
            Scheme::Sdirk2 => "sdirk2",
            Scheme::Sdirk3 => "sdirk3",
        }
    }

    /// Order of accuracy.
    pub const fn order(self) -> u8 {
        match self {
            Scheme::Rk4 => 4,
            Scheme::LinearlyImplicitEuler => 1,
            Scheme::Ros2 | Scheme::Sdirk2 => 2,
            Scheme::Ros3 | Scheme::Rodas3 | Scheme::Sdirk3 => 3,
        }
    }

    /// The SDIRK tableau of an SDIRK scheme ([`super::dirk`]); `None` for
    /// the others.
    pub const fn dirk(self) -> Option<&'static super::dirk::Tableau> {
        match self {
            Scheme::Sdirk2 => Some(&super::dirk::SDIRK2),
            Scheme::Sdirk3 => Some(&super::dirk::SDIRK3),
            _ => None,
        }
    }

    /// The scheme a generic [`OdeSystem`] runs for this choice: itself, or
    /// for an SDIRK (which needs the FSI model's structure) the L-stable
    /// Rosenbrock scheme of the same order.
    pub const fn generic(self) -> Scheme {
        match self {
            Scheme::Sdirk2 => Scheme::Ros2,
            Scheme::Sdirk3 => Scheme::Ros3,
            s => s,
        }
    }

    /// The scheme with this [`Scheme::name`]; `None` when no scheme has
    /// that name.
    pub fn from_name(name: &str) -> Option<Scheme> {
        Scheme::ALL.iter().copied().find(|s| s.name() == name)
    }
}

/// Most stages of any scheme.
const MAX_STAGES: usize = 4;

/// A Rosenbrock tableau in transformed form (all in `f64`).
struct Tableau {
    stages: usize,
    gamma: f64,
    a: [[f64; MAX_STAGES]; MAX_STAGES],
    c: [[f64; MAX_STAGES]; MAX_STAGES],
    m: [f64; MAX_STAGES],
}

fn tableau(scheme: Scheme) -> Tableau {
    let z = [[0.0; MAX_STAGES]; MAX_STAGES];
    match scheme {
        Scheme::LinearlyImplicitEuler | Scheme::Rk4 => Tableau {
            stages: 1,
            gamma: 1.0,
            a: z,
            c: z,
            m: [1.0, 0.0, 0.0, 0.0],
        },
        Scheme::Ros2 | Scheme::Sdirk2 => {
            let g = 1.0 + core::f64::consts::FRAC_1_SQRT_2;
            let mut a = z;
            let mut c = z;
            a[1][0] = 1.0 / g;
            c[1][0] = -2.0 / g;
            Tableau {
                stages: 2,
                gamma: g,
                a,
                c,
                m: [1.5 / g, 0.5 / g, 0.0, 0.0],
            }
        }
        Scheme::Ros3 | Scheme::Sdirk3 => {
            let mut a = z;
            let mut c = z;
            a[1][0] = 1.0;
            a[2][0] = 1.0;
            c[1][0] = -1.015_617_108_387_770_2;
            c[2][0] = 4.075_995_645_253_77;
            c[2][1] = 9.207_679_429_833_079;
            Tableau {
                stages: 3,
                gamma: 0.435_866_521_508_459,
                a,
                c,
                m: [1.0, 6.169_794_704_382_824_5, -0.427_722_565_432_185_7, 0.0],
            }
        }
        Scheme::Rodas3 => {
            let mut a = z;
            let mut c = z;
            a[2][0] = 2.0;
            a[3][0] = 2.0;
            a[3][2] = 1.0;
            c[1][0] = 4.0;
            c[2][0] = 1.0;
            c[2][1] = -1.0;
            c[3][0] = 1.0;
            c[3][1] = -1.0;
            c[3][2] = -8.0 / 3.0;
            Tableau {
                stages: 4,
                gamma: 0.5,
                a,
                c,
                m: [2.0, 0.0, 1.0, 1.0],
            }
        }
    }
}

/// A scheme prepared for a fixed step `h`, in scalar type `T`.
#[derive(Clone, Copy, Debug)]
pub struct Stepper<T> {
    scheme: Scheme,
    stages: usize,
    h: T,
    inv_gamma_h: T,
    a: [[T; MAX_STAGES]; MAX_STAGES],
    c_over_h: [[T; MAX_STAGES]; MAX_STAGES],
    m: [T; MAX_STAGES],
    /// Stage `i` evaluates `f` at the same point as stage `i - 1`.
    reuse_f: [bool; MAX_STAGES],
    /// `h / 6` for RK4.
    rk4_sixth_h: T,
}

/// Why a step was not taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StepError {
    /// `I / (h gamma) - J` is singular (or not finite).
    Singular,
    /// The new state is not finite.
    NonFinite,
    /// The state left its physical bounds (a chamber pressure more than
    /// [`super::twin::PRESSURE_MARGIN`] `dp` outside `[p_c, p_p]`; the
    /// plunger cannot leave its stroke, the stops are events): the scheme
    /// is unstable at this step length. An L-stable scheme or more steps
    /// per tick cure it.
    Diverged,
}

impl core::fmt::Display for StepError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            StepError::Singular => "the stage matrix is singular",
            StepError::NonFinite => "the state is not finite",
            StepError::Diverged => {
                "the state left its physical bounds: the scheme is unstable at this step \
                 (use an L-stable scheme or more substeps)"
            }
        })
    }
}

impl core::error::Error for StepError {}

impl<T: Real> Stepper<T> {
    /// Prepares `scheme` for step `h` (in the system's time unit).
    pub fn new(scheme: Scheme, h: f64) -> Self {
        let tab = tableau(scheme);
        let mut a = [[T::ZERO; MAX_STAGES]; MAX_STAGES];
        let mut c_over_h = [[T::ZERO; MAX_STAGES]; MAX_STAGES];
        let mut m = [T::ZERO; MAX_STAGES];
        let mut reuse_f = [false; MAX_STAGES];
        for i in 0..MAX_STAGES {
            for j in 0..MAX_STAGES {
                a[i][j] = T::from_f64(tab.a[i][j]);
                c_over_h[i][j] = T::from_f64(tab.c[i][j] / h);
            }
            m[i] = T::from_f64(tab.m[i]);
            // Same evaluation point as the previous stage: row i of `a`
            // equals row i-1 (whose entry at i-1 is zero by triangularity).
            reuse_f[i] = i > 0 && (0..MAX_STAGES).all(|j| tab.a[i][j] == tab.a[i - 1][j]);
        }
        Stepper {
            scheme,
            stages: tab.stages,
            h: T::from_f64(h),
            inv_gamma_h: T::from_f64(1.0 / (tab.gamma * h)),
            a,
            c_over_h,
            m,
            reuse_f,
            rk4_sixth_h: T::from_f64(h / 6.0),
        }
    }

    /// Advances `y` by one step of `sys`.
    ///
    /// # Errors
    ///
    /// As [`Stepper::step_fraction`].
    pub fn step<S: OdeSystem<T, N>, const N: usize>(&self, sys: &S, y: &[T; N]) -> Result<[T; N], StepError> {
        self.step_fraction(sys, y, T::ONE)
    }

    /// Advances `y` by `frac` (in `(0, 1]`) of the prepared step.
    ///
    /// # Errors
    ///
    /// * [`StepError::Singular`]: a Rosenbrock scheme's stage matrix
    ///   `D (I / (h gamma) - J)` could not be factorised
    ///   ([`OdeSystem::linearise`] returned `None`: singular, or not finite).
    /// * [`StepError::NonFinite`]: the new state has a NaN or infinite
    ///   component (floating point only: fixed point saturates instead).
    ///
    /// A state that is finite but physically absurd is not caught here: the
    /// caller's bounds do that ([`StepError::Diverged`] from
    /// [`super::Twin::tick`]).
    pub fn step_fraction<S: OdeSystem<T, N>, const N: usize>(
        &self,
        sys: &S,
        y: &[T; N],
        frac: T,
    ) -> Result<[T; N], StepError> {
        let next = match self.scheme {
            Scheme::Rk4 => self.rk4(sys, y, frac),
            _ => self.rosenbrock(sys, y, if frac == T::ONE { T::ONE } else { T::ONE / frac })?,
        };
        if next.iter().all(|v| v.is_finite()) {
            Ok(next)
        } else {
            Err(StepError::NonFinite)
        }
    }

    /// One Rosenbrock step of `h / inv_frac`.
    fn rosenbrock<S: OdeSystem<T, N>, const N: usize>(
        &self,
        sys: &S,
        y: &[T; N],
        inv_frac: T,
    ) -> Result<[T; N], StepError> {
        let (f0, lu) = sys
            .linearise(y, self.inv_gamma_h * inv_frac)
            .ok_or(StepError::Singular)?;
        let mut u = [[T::ZERO; N]; MAX_STAGES];
        let mut f = f0;
        for i in 0..self.stages {
            if i > 0 && !self.reuse_f[i] {
                let mut yi = *y;
                for (j, uj) in u.iter().enumerate().take(i) {
                    let aij = self.a[i][j];
                    if aij != T::ZERO {
                        for k in 0..N {
                            yi[k] += aij * uj[k];
                        }
                    }
                }
                f = sys.scaled_rhs(&yi, &lu);
            }
            let mut rhs = f;
            for (j, uj) in u.iter().enumerate().take(i) {
                let cij = self.c_over_h[i][j] * inv_frac;
                if cij != T::ZERO {
                    let su = lu.scale(uj);
                    for k in 0..N {
                        rhs[k] += cij * su[k];
                    }
                }
            }
            u[i] = lu.solve(&rhs);
        }
        let mut next = *y;
        for (i, ui) in u.iter().enumerate().take(self.stages) {
            let mi = self.m[i];
            if mi != T::ZERO {
                for k in 0..N {
                    next[k] += mi * ui[k];
                }
            }
        }
        Ok(next)
    }

    fn rk4<S: OdeSystem<T, N>, const N: usize>(&self, sys: &S, y: &[T; N], frac: T) -> [T; N] {
        let h = self.h * frac;
        let half = h * T::HALF;
        let sixth = self.rk4_sixth_h * frac;
        let shifted = |base: &[T; N], k: &[T; N], s: T| {
            let mut out = *base;
            for i in 0..N {
                out[i] += s * k[i];
            }
            out
        };
        let k1 = sys.rhs(y);
        let k2 = sys.rhs(&shifted(y, &k1, half));
        let k3 = sys.rhs(&shifted(y, &k2, half));
        let k4 = sys.rhs(&shifted(y, &k3, h));
        let mut next = *y;
        for i in 0..N {
            next[i] += sixth * (k1[i] + T::TWO * k2[i] + T::TWO * k3[i] + k4[i]);
        }
        next
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = A y with a stiff, non-normal A; exact solution by eigenvectors.
    struct Linear;
    const A: [[f64; 2]; 2] = [[-1.0, 1.0], [0.0, -100.0]];
    impl OdeSystem<f64, 2> for Linear {
        type Factor = Lu<f64, 2>;
        fn linearise(&self, y: &[f64; 2], shift: f64) -> Option<([f64; 2], Lu<f64, 2>)> {
            dense_linearisation(self, y, shift)
        }
        fn rhs(&self, y: &[f64; 2]) -> [f64; 2] {
            [A[0][0] * y[0] + A[0][1] * y[1], A[1][1] * y[1]]
        }
        fn jacobian(&self, _: &[f64; 2]) -> [[f64; 2]; 2] {
            A
        }
    }
    fn exact(t: f64) -> [f64; 2] {
        // y0 = (1, 1): y2 = e^{-100t}; y1 = e^{-t} + (e^{-t} - e^{-100t}) / 99.
        let (e1, e100) = ((-t).exp(), (-100.0 * t).exp());
        [e1 + (e1 - e100) / 99.0, e100]
    }
    /// Non-stiff test (observable order): y' = -y + cos-like coupling.
    struct Smooth;
    impl OdeSystem<f64, 2> for Smooth {
        type Factor = Lu<f64, 2>;
        fn linearise(&self, y: &[f64; 2], shift: f64) -> Option<([f64; 2], Lu<f64, 2>)> {
            dense_linearisation(self, y, shift)
        }
        fn rhs(&self, y: &[f64; 2]) -> [f64; 2] {
            [y[1], -y[0]]
        }
        fn jacobian(&self, _: &[f64; 2]) -> [[f64; 2]; 2] {
            [[0.0, 1.0], [-1.0, 0.0]]
        }
    }

    fn error(scheme: Scheme, n: usize) -> f64 {
        let h = 1.0 / n as f64;
        let s = Stepper::<f64>::new(scheme, h);
        let mut y = [1.0, 0.0];
        for _ in 0..n {
            y = s.step(&Smooth, &y).unwrap();
        }
        ((y[0] - 1f64.cos()).powi(2) + (y[1] + 1f64.sin()).powi(2)).sqrt()
    }

    #[test]
    fn each_scheme_converges_at_its_order() {
        for scheme in Scheme::ALL {
            let (e1, e2) = (error(scheme, 40), error(scheme, 80));
            let observed = (e1 / e2).log2();
            assert!(
                (observed - scheme.order() as f64).abs() < 0.2,
                "{scheme:?}: observed order {observed}"
            );
        }
    }

    #[test]
    fn rosenbrock_schemes_damp_stiff_modes_at_large_steps() {
        for scheme in [
            Scheme::LinearlyImplicitEuler,
            Scheme::Ros2,
            Scheme::Ros3,
            Scheme::Rodas3,
        ] {
            let h = 0.1; // h * 100 = 10: far outside any explicit stability region
            let s = Stepper::<f64>::new(scheme, h);
            let mut y = [1.0, 1.0];
            for _ in 0..10 {
                y = s.step(&Linear, &y).unwrap();
            }
            let e = exact(1.0);
            assert!(
                (y[0] - e[0]).abs() < 0.05 && y[1].abs() < 1e-3,
                "{scheme:?}: {y:?} vs {e:?}"
            );
        }
    }
}
