//! Linearisation at an equilibrium (paper Eq. 37): `z' = M z` with `M` the
//! Jacobian of the FSI model, its eigenvalues, natural frequencies, damping
//! ratios and a stability verdict.
//!
//! * [`linearise`]: the eigenvalues of that Jacobian by
//!   [`crate::linalg::eigen`] (EISPACK's balancing, Hessenberg reduction
//!   and `hqr`; bounded cost, else [`ModelError::NoConvergence`]), with
//!   natural frequencies, damping ratios and the plunger's damping ratio.
//! * [`hurwitz_stable`]: the same stability verdict from the characteristic
//!   polynomial's Routh-Hurwitz conditions, ~100 multiplications, no
//!   iteration: what the estimator evaluates (one of its rotating jobs).
//!
//! The Jacobian is taken in the model's units (better conditioned than SI);
//! eigenvalues are invariant under the diagonal change of units, and are
//! reported in 1/s after division by the time unit.

// Matrix code indexes rows and columns explicitly, as the algorithms are
// written (EISPACK, Hairer & Wanner); iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

use super::coefficients::Model;
use super::fsi::Fsi;
use super::schemes::OdeSystem;
use super::stops::Contact;
use crate::equilibrium::{Stop, equilibrium};
use crate::error::{ModelError, finite};
pub use crate::linalg::eigen::{Complex, eigenvalues};
use crate::params::Params;
use crate::scalar::{Float, Real};

/// Coefficients `(a3, a2, a1, a0)` of `det(s I - M) = s^4 + a3 s^3 + a2 s^2 + a1 s + a0`.
pub fn characteristic_polynomial<T: Real>(m: &[[T; 4]; 4]) -> [T; 4] {
    let det2 = |i: usize, j: usize| m[i][i] * m[j][j] - m[i][j] * m[j][i];
    let det3 = |i: usize, j: usize, k: usize| {
        m[i][i] * (m[j][j] * m[k][k] - m[j][k] * m[k][j]) - m[i][j] * (m[j][i] * m[k][k] - m[j][k] * m[k][i])
            + m[i][k] * (m[j][i] * m[k][j] - m[j][j] * m[k][i])
    };
    let trace = m[0][0] + m[1][1] + m[2][2] + m[3][3];
    let minors2 = det2(0, 1) + det2(0, 2) + det2(0, 3) + det2(1, 2) + det2(1, 3) + det2(2, 3);
    let minors3 = det3(0, 1, 2) + det3(0, 1, 3) + det3(0, 2, 3) + det3(1, 2, 3);
    // Laplace expansion of the determinant along the first row.
    let minor = |skip: usize| {
        let cols: [usize; 3] = match skip {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        let e = |r: usize, c: usize| m[r][cols[c]];
        e(1, 0) * (e(2, 1) * e(3, 2) - e(2, 2) * e(3, 1)) - e(1, 1) * (e(2, 0) * e(3, 2) - e(2, 2) * e(3, 0))
            + e(1, 2) * (e(2, 0) * e(3, 1) - e(2, 1) * e(3, 0))
    };
    let det = m[0][0] * minor(0) - m[0][1] * minor(1) + m[0][2] * minor(2) - m[0][3] * minor(3);
    [-trace, minors2, -minors3, det]
}

/// [`characteristic_polynomial`] of a Jacobian of the free plunger's
/// model ([`super::fsi::Fsi`], `Contact::Free`), from its structure: the
/// first row is `(0, a_x, 0, 0)` and each chamber's pressure row has no
/// entry in the other chamber's pressure (`m[2][3] = m[3][2] = 0`), so
/// the expansion has 26 products and sums where the general one has
/// about 100 (what a core without an FPU pays in software `f32`).
/// Other entries of the first row, and the two zeros, are not read: for
/// another matrix the result is not its polynomial.
pub fn fsi_characteristic_polynomial<T: Real>(m: &[[T; 4]; 4]) -> [T; 4] {
    let a = m[0][1];
    let (b, c, d, e) = (m[1][0], m[1][1], m[1][2], m[1][3]);
    let (f, g, h) = (m[2][0], m[2][1], m[2][2]);
    let (k, l, n) = (m[3][0], m[3][1], m[3][3]);
    let ab = a * b;
    let hn = h * n;
    let a3 = -(c + h + n);
    let a2 = c * (h + n) + hn - ab - d * g - e * l;
    let a1 = ab * (h + n) - a * (d * f + e * k) - c * hn + d * g * n + e * h * l;
    let a0 = a * (d * f * n + e * h * k - b * hn);
    [a3, a2, a1, a0]
}

/// `true` when every eigenvalue of `m` has a negative real part
/// (Routh-Hurwitz conditions for a quartic; no iteration); `false` for a
/// matrix with an entry that is not finite.
///
/// Where a coefficient of the characteristic polynomial overflows or falls
/// into the subnormals, the matrix is divided by its largest entry's
/// magnitude (which scales the eigenvalues and keeps their signs), so that
/// the coefficients are at most 4, 12, 24 and 24 in magnitude; the
/// conditions are taken in the quotient form of [`hurwitz_quartic`]: no
/// product that can overflow, on any finite matrix.
pub fn hurwitz_stable<T: Real>(m: &[[T; 4]; 4]) -> bool {
    // The usual case (the model-unit Jacobians): every coefficient finite
    // and clear of the subnormals, nothing to scale.
    let a = characteristic_polynomial(m);
    if T::SATURATES || a.iter().all(|c| c.is_finite() && c.abs() >= T::tiny()) {
        return hurwitz_quartic(&a);
    }
    let mut big = T::ZERO;
    for row in m {
        for &e in row {
            if !e.is_finite() {
                return false;
            }
            big = big.max(e.abs());
        }
    }
    if !(big > T::ZERO) {
        // A zero matrix is not stable.
        return false;
    }
    // Divided, not multiplied by 1 / big (which overflows for a subnormal
    // big): every quotient is at most one.
    let mut scaled = *m;
    for row in scaled.iter_mut() {
        for e in row.iter_mut() {
            *e = *e / big;
        }
    }
    hurwitz_quartic(&characteristic_polynomial(&scaled))
}

/// The Routh-Hurwitz conditions of the monic quartic
/// `s^4 + a3 s^3 + a2 s^2 + a1 s + a0` (coefficients `[a3, a2, a1, a0]`):
/// every root has a negative real part exactly when all four are positive
/// and `a3 a2 a1 > a1^2 + a3^2 a0`, here divided by `a3 a1 > 0`:
/// `a2 > a1 / a3 + a3 (a0 / a1)` (which implies `a3 a2 > a1`). Source:
/// Routh-Hurwitz criterion for a quartic. The quotient form has no product of
/// three coefficients: a term that overflows is one `a2` cannot exceed,
/// and the verdict stays right for coefficients anywhere in the type's
/// range. `false` when a coefficient is NaN.
pub fn hurwitz_quartic<T: Real>(a: &[T; 4]) -> bool {
    let [a3, a2, a1, a0] = *a;
    let z = T::ZERO;
    a3 > z && a2 > z && a1 > z && a0 > z && a2 > a1 / a3 + a3 * (a0 / a1)
}

/// The linearised dynamics at an equilibrium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearisation<F> {
    /// Temperature \[C\].
    pub temperature: F,
    /// Eigenvalues [1/s], real part descending.
    pub eigenvalues: [Complex<F>; 4],
    /// Natural frequencies `|lambda|` [rad/s].
    pub natural_frequency: [F; 4],
    /// Damping ratios `-Re(lambda) / |lambda|` (1 for a real stable mode).
    pub damping_ratio: [F; 4],
    /// The eigenvalue with the largest real part [1/s].
    pub dominant: Complex<F>,
    /// All real parts negative.
    pub stable: bool,
    /// Damping ratio of the plunger with the hydraulic damping of the
    /// quasi-steady chambers: `(b + b_hyd) / (2 sqrt(c m))`.
    pub plunger_damping_ratio: F,
    /// The equilibrium lies on a stop; the eigenvalues are those of the
    /// free motion there (what the plunger does once released).
    pub on_stop: bool,
}

/// The model-unit Jacobian of the free motion at the equilibrium of `t` \[C\].
///
/// # Errors
///
/// As [`crate::equilibrium::equilibrium`] at `t` and
/// [`Model::coefficients`] for its fluid state.
pub fn jacobian_at_equilibrium<F: Float>(model: &Model<F>, t: F) -> Result<[[F; 4]; 4], ModelError> {
    let p = model.params();
    let eq = equilibrium(p, t)?;
    let c = model.coefficients::<F>(&eq.fluid)?;
    let y: [F; 4] = model.equilibrium_state(&eq);
    Ok(Fsi {
        coefficients: &c,
        contact: Contact::Free,
    }
    .jacobian(&y))
}

/// Linearises the FSI model at the equilibrium of `t` \[C\].
///
/// # Errors
///
/// As [`Model::new`], [`jacobian_at_equilibrium`] and [`eigenvalues`];
/// `NonFinite("eigenvalues")` or `NonFinite("natural frequency")` when an
/// eigenvalue or its modulus in 1/s is not finite (never on the parameter
/// schema's plausible ranges: `tests` and host-tests' `dynamics`).
pub fn linearise<F: Float>(params: &Params<F>, t: F) -> Result<Linearisation<F>, ModelError> {
    let model = Model::new(params)?;
    let jac = jacobian_at_equilibrium(&model, t)?;
    let scale = F::ONE / model.scales.time;
    let mut ev = eigenvalues(&jac)?;
    for e in ev.iter_mut() {
        // In 1/s: a model-unit eigenvalue times 1 / time unit can overflow
        // (a time unit in the subnormals), refused rather than returned.
        e.re = finite(e.re * scale, "eigenvalues")?;
        e.im = finite(e.im * scale, "eigenvalues")?;
    }
    let mut wn = [F::ZERO; 4];
    let mut zeta = [F::ZERO; 4];
    for i in 0..4 {
        wn[i] = finite(ev[i].abs(), "natural frequency")?;
        // |re| <= |lambda|; the clamp only absorbs rounding.
        zeta[i] = if wn[i] > F::ZERO {
            (-ev[i].re / wn[i]).clamp_to(-F::ONE, F::ONE)
        } else {
            F::ONE
        };
    }
    let eq = equilibrium(params, t)?;
    let c = model.coefficients::<F>(&eq.fluid)?;
    let (s, ds) = c.quasi_steady(F::ZERO);
    // w' = ... - (2 zeta - 4 s ds phi / a_x) w: the plunger's total damping.
    let two_zeta_total = c.two_zeta - F::from_f64(4.0) * s * ds * c.phi_over_a_x;
    Ok(Linearisation {
        temperature: t,
        eigenvalues: ev,
        natural_frequency: wn,
        damping_ratio: zeta,
        dominant: ev[0],
        stable: ev.iter().all(|e| e.re < F::ZERO),
        plunger_damping_ratio: F::from_f64(0.5) * two_zeta_total,
        on_stop: eq.stop != Stop::Free,
    })
}

#[cfg(test)]
mod tests {

    #[test]
    fn the_fsi_polynomial_is_the_general_one_on_its_structure() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..1000 {
            let mut m = [[0.0f64; 4]; 4];
            m[0][1] = next();
            for r in 1..4 {
                for col in 0..4 {
                    m[r][col] = next();
                }
            }
            m[2][3] = 0.0;
            m[3][2] = 0.0;
            let (general, fsi) = (
                super::characteristic_polynomial(&m),
                super::fsi_characteristic_polynomial(&m),
            );
            for i in 0..4 {
                assert!(
                    (general[i] - fsi[i]).abs() <= 1e-12 * (1.0 + general[i].abs()),
                    "{m:?}: a{} {} against {}",
                    3 - i,
                    fsi[i],
                    general[i]
                );
            }
        }
    }
    use super::*;

    #[test]
    fn companion_matrix_polynomial_and_stability() {
        // (s + 1)(s + 2)(s^2 + 2 s + 5): roots -1, -2, -1 +- 2i.
        // Expanded: s^4 + 5 s^3 + 13 s^2 + 19 s + 10.
        let m = [
            [-5.0, -13.0, -19.0, -10.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        assert_eq!(characteristic_polynomial(&m), [5.0, 13.0, 19.0, 10.0]);
        assert!(hurwitz_stable(&m));
        let unstable = [
            [1.0, -13.0, -19.0, -10.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        assert!(!hurwitz_stable(&unstable));
    }

    /// F4 (docs/fuzzing.md): the Routh-Hurwitz products overflowed (a
    /// spring of 2.2e-106 N/m under 4.2e93 Pa gave "unstable" for four
    /// negative eigenvalues). The same matrices scaled by 2^-1000..2^1000
    /// (exactly), in `f64`, and by 2^-60..2^60 in `f32`, keep their
    /// verdicts; so do polynomials with roots spread over 1e-30..1e30.
    #[test]
    fn the_verdict_survives_any_scale() {
        let stable = [
            [-5.0, -13.0, -19.0, -10.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        // (s - 0.5)(s + 2)(s^2 + 2 s + 5) = s^4 + 3.5 s^3 + 8 s^2 + 8.5 s - 5:
        // one positive root, all coefficients but a0 positive; and
        // s^4 + s^3 + 4 s^2 + 5 s + 6, all positive, two roots at
        // Re > 0 (a3 a2 a1 = 20 < a1^2 + a3^2 a0 = 31).
        let one_positive = [
            [-3.5, -8.0, -8.5, 5.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        let oscillating = [
            [-1.0, -4.0, -5.0, -6.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        for k in (-1000..=1000).step_by(25) {
            let s = 2f64.powi(k);
            let scaled = |m: [[f64; 4]; 4]| m.map(|r| r.map(|e| e * s));
            assert!(hurwitz_stable(&scaled(stable)), "2^{k}");
            assert!(!hurwitz_stable(&scaled(one_positive)), "2^{k}");
            assert!(!hurwitz_stable(&scaled(oscillating)), "2^{k}");
            if k.abs() <= 60 {
                let scaled = |m: [[f64; 4]; 4]| m.map(|r| r.map(|e| (e * s) as f32));
                assert!(hurwitz_stable(&scaled(stable)), "f32 2^{k}");
                assert!(!hurwitz_stable(&scaled(one_positive)), "f32 2^{k}");
                assert!(!hurwitz_stable(&scaled(oscillating)), "f32 2^{k}");
            }
        }
        // Roots -r spread over many decades: products of three coefficients
        // reach 1e120 (beyond f32 from 1e13).
        let with_roots = |r: [f64; 4]| {
            let mut c = [1.0f64, 0.0, 0.0, 0.0, 0.0];
            for (n, ri) in r.iter().enumerate() {
                for k in (1..=n + 1).rev() {
                    c[k] += ri * c[k - 1];
                }
            }
            [c[1], c[2], c[3], c[4]]
        };
        for roots in [
            [1e-30, 1.0, 1e10, 1e30],
            [1e-3, 1e-2, 1e5, 1e10],
            [2.0, 3.0, 5e12, 7e12],
        ] {
            let a = with_roots(roots);
            assert!(hurwitz_quartic(&a), "{roots:?}");
            let a32 = a.map(|c| c as f32);
            if a32.iter().all(|c| c.is_finite() && *c > 0.0) {
                assert!(hurwitz_quartic(&a32), "f32 {roots:?}");
            }
            let mut flipped = roots;
            flipped[1] = -flipped[1];
            assert!(!hurwitz_quartic(&with_roots(flipped)), "{flipped:?}");
        }
        // Not finite: no verdict of stability.
        let mut nan = stable;
        nan[2][1] = f64::NAN;
        assert!(!hurwitz_stable(&nan));
        nan[2][1] = f64::INFINITY;
        assert!(!hurwitz_stable(&nan));
        assert!(!hurwitz_quartic(&[f64::NAN, 1.0, 1.0, 1.0]));
    }
}
