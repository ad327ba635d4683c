//! Small dense `f64` matrices for designing filters once, off the tick
//! path: products, the matrix exponential, Van Loan's discretisation of a
//! linear stochastic system, and the steady state of the Kalman filter's
//! Riccati equation by structure-preserving doubling.
//!
//! Used where a design is computed (the build script, host tools, the
//! estimator's construction on a host); nothing here runs per tick. No
//! allocation; every failure (a matrix that is not finite, a singular
//! step) is `None`, never a panic.

// Matrix code indexes rows and columns as the algorithms are written.
#![allow(clippy::needless_range_loop)]

use super::Lu;

/// An `N x N` matrix, row-major.
pub type Mat<const N: usize> = [[f64; N]; N];

/// The identity.
pub fn identity<const N: usize>() -> Mat<N> {
    let mut m = [[0.0; N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// `a b`.
pub fn mul<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut c = [[0.0; N]; N];
    for i in 0..N {
        for k in 0..N {
            let aik = a[i][k];
            for j in 0..N {
                c[i][j] += aik * b[k][j];
            }
        }
    }
    c
}

/// `a'`.
pub fn transpose<const N: usize>(a: &Mat<N>) -> Mat<N> {
    let mut t = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            t[j][i] = a[i][j];
        }
    }
    t
}

/// `a + b`.
pub fn add<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut c = *a;
    for i in 0..N {
        for j in 0..N {
            c[i][j] += b[i][j];
        }
    }
    c
}

/// `a^-1`, `None` when singular or not finite.
pub fn inverse<const N: usize>(a: &Mat<N>) -> Option<Mat<N>> {
    let lu = Lu::<f64, N>::new(*a)?;
    let mut inv = [[0.0; N]; N];
    for j in 0..N {
        let mut e = [0.0; N];
        e[j] = 1.0;
        let col = lu.solve(&e);
        for i in 0..N {
            inv[i][j] = col[i];
        }
    }
    Some(inv)
}

/// The largest absolute row sum (the infinity norm).
pub fn norm_inf<const N: usize>(a: &Mat<N>) -> f64 {
    a.iter()
        .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// `e^a` by scaling and squaring with a Taylor polynomial of degree 18 on
/// `a / 2^s`, `|a / 2^s| <= 1/2` (truncation below 1e-21 relative: Moler
/// and Van Loan 2003, "Nineteen dubious ways", method 3). `None` for a
/// matrix that is not finite or whose norm exceeds 2^60.
pub fn expm<const N: usize>(a: &Mat<N>) -> Option<Mat<N>> {
    let norm = norm_inf(a);
    if !norm.is_finite() || norm > 1.152_921_504_606_847e18 {
        return None;
    }
    let mut s = 0u32;
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale *= 0.5;
        s += 1;
    }
    let mut x = *a;
    for row in x.iter_mut() {
        for v in row.iter_mut() {
            *v *= scale;
        }
    }
    // Horner: I + x (I + x/2 (I + x/3 (...))).
    let mut e = identity::<N>();
    for k in (1..=18).rev() {
        let mut t = mul(&x, &e);
        for row in t.iter_mut() {
            for v in row.iter_mut() {
                *v /= k as f64;
            }
        }
        e = add(&identity::<N>(), &t);
    }
    for _ in 0..s {
        e = mul(&e, &e);
    }
    e.iter().flatten().all(|v| v.is_finite()).then_some(e)
}

/// Van Loan's discretisation (1978) of `dx = A x dt + g dw` with white
/// noise of intensity `q` (`E[dw^2] = q dt`) over `dt`: the transition
/// `Phi = e^(A dt)` and the process noise `Qd = int_0^dt e^(A s) g q g'
/// e^(A' s) ds`, from one exponential of the `2N x 2N` block matrix
/// `[[-A, g q g'], [0, A']] h` over `h = dt / 2^k`, small enough that
/// `|A| h <= 1/2` (the block's `e^(-A h)` would overflow for a stiff `A`
/// over the whole step), then doubled `k` times: `Phi(2h) = Phi(h)^2`,
/// `Qd(2h) = Qd(h) + Phi(h) Qd(h) Phi(h)'`. `M` must be `2 N`, else
/// `None`; `None` too for a step or matrix that is not finite.
pub fn van_loan<const N: usize, const M: usize>(a: &Mat<N>, g: &[f64; N], q: f64, dt: f64) -> Option<(Mat<N>, Mat<N>)> {
    if M != 2 * N || !dt.is_finite() {
        return None;
    }
    let norm = norm_inf(a);
    let mut h = dt;
    let mut k = 0u32;
    while norm * h > 0.5 && k < 200 {
        h *= 0.5;
        k += 1;
    }
    let (mut phi, mut qd) = van_loan_step::<N, M>(a, g, q, h)?;
    for _ in 0..k {
        qd = add(&qd, &mul(&mul(&phi, &qd), &transpose(&phi)));
        phi = mul(&phi, &phi);
    }
    let finite = phi.iter().chain(qd.iter()).flatten().all(|v| v.is_finite());
    finite.then_some((phi, symmetric(&qd)))
}

/// `(m + m') / 2`.
fn symmetric<const N: usize>(m: &Mat<N>) -> Mat<N> {
    let mut s = *m;
    for i in 0..N {
        for j in 0..N {
            s[i][j] = 0.5 * (m[i][j] + m[j][i]);
        }
    }
    s
}

/// One Van Loan exponential over `dt` (see [`van_loan`]).
fn van_loan_step<const N: usize, const M: usize>(
    a: &Mat<N>,
    g: &[f64; N],
    q: f64,
    dt: f64,
) -> Option<(Mat<N>, Mat<N>)> {
    let mut big = [[0.0; M]; M];
    for i in 0..N {
        for j in 0..N {
            big[i][j] = -a[i][j] * dt;
            big[i][N + j] = g[i] * q * g[j] * dt;
            big[N + i][N + j] = a[j][i] * dt;
        }
    }
    let e = expm(&big)?;
    // e = [[F11, F12], [0, F22]]: Phi = F22', Qd = Phi F12.
    let mut phi = [[0.0; N]; N];
    let mut f12 = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            phi[i][j] = e[N + j][N + i];
            f12[i][j] = e[i][N + j];
        }
    }
    // Symmetric by construction; rounding is made symmetric too.
    Some((phi, symmetric(&mul(&phi, &f12))))
}

/// The steady-state a priori covariance `P` of the Kalman filter of `x+ =
/// Phi x + w` (`E[w w'] = Qd`) measured by `y = h x + v` (`E[v^2] = r`):
/// the stabilising solution of `P = Phi (P - P h' (h P h' + r)^-1 h P)
/// Phi' + Qd`, by the structure-preserving doubling algorithm (Chu, Fan,
/// Lin, Wang 2004, "Structure-preserving algorithms for periodic discrete-
/// time algebraic Riccati equations", Algorithm SDA), which converges
/// quadratically where the plain recursion needs thousands of steps for a
/// slow filter. `None` when a step is singular, the result not finite, or
/// 64 doublings do not converge to 1e-13 relative.
pub fn dare_filter<const N: usize>(phi: &Mat<N>, qd: &Mat<N>, h: &[f64; N], r: f64) -> Option<Mat<N>> {
    if !(r > 0.0) {
        return None;
    }
    // Control form X = A' X (I + G X)^-1 A + H with A = Phi', G = h' h / r,
    // H = Qd; X is the a priori covariance.
    let mut a = transpose(phi);
    let mut g = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            g[i][j] = h[i] * h[j] / r;
        }
    }
    let mut x = *qd;
    for _ in 0..64 {
        // W = I + G X; A1 = A W^-1 A; G1 = G + A W^-1 G A'; X1 = X + A' X W^-1 A.
        let w = add(&identity::<N>(), &mul(&g, &x));
        let wi = inverse(&w)?;
        let a_wi = mul(&a, &wi);
        let a1 = mul(&a_wi, &a);
        let g1 = add(&g, &mul(&mul(&a_wi, &g), &transpose(&a)));
        let x1 = add(&x, &mul(&mul(&mul(&transpose(&a), &x), &wi), &a));
        let change = norm_inf(&add(&x1, &x.map(|row| row.map(|v| -v))));
        let size = norm_inf(&x1);
        a = a1;
        g = g1;
        x = x1;
        if !size.is_finite() {
            return None;
        }
        if change <= 1e-13 * size {
            let mut sym = x;
            for i in 0..N {
                for j in 0..N {
                    sym[i][j] = 0.5 * (x[i][j] + x[j][i]);
                }
            }
            return Some(sym);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exponential_of_a_rotation_and_a_decay() {
        let w: f64 = 3.0;
        let e = expm(&[[0.0, w], [-w, 0.0]]).unwrap();
        let want = [[w.cos(), w.sin()], [-w.sin(), w.cos()]];
        for i in 0..2 {
            for j in 0..2 {
                assert!((e[i][j] - want[i][j]).abs() < 1e-14, "{e:?}");
            }
        }
        let e = expm(&[[-50.0]]).unwrap();
        assert!((e[0][0] / (-50.0f64).exp() - 1.0).abs() < 1e-12);
        assert!(expm(&[[f64::NAN]]).is_none());
    }

    /// Integrated random walk (position, velocity), intensity q: Qd is
    /// q [[dt^3/3, dt^2/2], [dt^2/2, dt]] (Bar-Shalom et al. 2001, 6.2.2).
    #[test]
    fn van_loan_gives_the_integrated_random_walk() {
        let (q, dt) = (0.7, 0.02);
        let (phi, qd) = van_loan::<2, 4>(&[[0.0, 1.0], [0.0, 0.0]], &[0.0, 1.0], q, dt).unwrap();
        assert_eq!(phi, [[1.0, dt], [0.0, 1.0]]);
        let want = [[dt * dt * dt / 3.0, dt * dt / 2.0], [dt * dt / 2.0, dt]];
        for i in 0..2 {
            for j in 0..2 {
                assert!((qd[i][j] / (q * want[i][j]) - 1.0).abs() < 1e-12, "{qd:?}");
            }
        }
        assert!(van_loan::<2, 3>(&[[0.0; 2]; 2], &[0.0, 1.0], q, dt).is_none());
    }

    /// A stiff lag (rate 1000/s over 1 s, where `e^(A dt)` of the block
    /// matrix would overflow): the scalar Ornstein-Uhlenbeck process's
    /// `Phi = e^(-a dt)` and `Qd = q (1 - e^(-2 a dt)) / (2 a)`.
    #[test]
    fn van_loan_takes_a_stiff_system_by_doubling() {
        let (a, q, dt) = (1000.0, 3.0, 1.0);
        let (phi, qd) = van_loan::<1, 2>(&[[-a]], &[1.0], q, dt).unwrap();
        assert!(phi[0][0].abs() < 1e-300);
        let want = q * (1.0 - (-2.0 * a * dt).exp()) / (2.0 * a);
        assert!((qd[0][0] / want - 1.0).abs() < 1e-12, "{qd:?} vs {want}");
        let (phi, qd) = van_loan::<1, 2>(&[[-2.0]], &[1.0], q, 0.3).unwrap();
        assert!((phi[0][0] / (-0.6f64).exp() - 1.0).abs() < 1e-14);
        let want = q * (1.0 - (-1.2f64).exp()) / 4.0;
        assert!((qd[0][0] / want - 1.0).abs() < 1e-13, "{qd:?} vs {want}");
    }

    /// The scalar random walk measured directly has the closed form
    /// P = (q + sqrt(q^2 + 4 q r)) / 2; the doubling's solution also
    /// satisfies the Riccati equation of a two-state filter.
    #[test]
    fn the_doubling_solves_the_riccati_equation() {
        let (q, r) = (1e-6, 4e-4);
        let p = dare_filter(&[[1.0]], &[[q]], &[1.0], r).unwrap()[0][0];
        let want = (q + (q * q + 4.0 * q * r).sqrt()) / 2.0;
        assert!((p / want - 1.0).abs() < 1e-12, "{p} {want}");
        let (phi, qd) = van_loan::<2, 4>(&[[0.0, 1.0], [0.0, 0.0]], &[0.0, 1.0], 1e-7, 0.02).unwrap();
        let h = [1.0, 0.0];
        let p = dare_filter(&phi, &qd, &h, r).unwrap();
        let s = p[0][0] + r;
        let mut post = p;
        for i in 0..2 {
            for j in 0..2 {
                post[i][j] = p[i][j] - p[i][0] * p[0][j] / s;
            }
        }
        let next = add(&mul(&mul(&phi, &post), &transpose(&phi)), &qd);
        for i in 0..2 {
            for j in 0..2 {
                assert!((next[i][j] - p[i][j]).abs() <= 1e-12 * p[i][i].abs().max(p[j][j].abs()));
            }
        }
        assert!(dare_filter(&[[1.0]], &[[q]], &[1.0], 0.0).is_none());
    }
}
