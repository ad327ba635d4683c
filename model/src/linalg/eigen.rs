//! Eigenvalues of a real 4x4 matrix: balancing, reduction to Hessenberg
//! form and the shifted (Francis double-step) QR algorithm of EISPACK's
//! `hqr`. Bounded cost: at most 30 QR sweeps per eigenvalue (120 in all),
//! else [`ModelError::NoConvergence`]. No allocation; generic over
//! [`Float`] (the linearisation of [`crate::dynamics::linear`] runs it in
//! the parameters' float type).

// Matrix code indexes rows and columns explicitly, as the algorithms are
// written (EISPACK); iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

use crate::error::{ModelError, finite};
use crate::scalar::{Float, Real};

/// A complex number.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Complex<T> {
    /// Real part.
    pub re: T,
    /// Imaginary part.
    pub im: T,
}

impl<T: Float> Complex<T> {
    /// Modulus `sqrt(re^2 + im^2)`, scaled by the larger part as C's
    /// `hypot` is, so that it neither overflows (parts beyond ~1e154 in
    /// `f64`, ~1e19 in `f32`) nor loses precision in the subnormals: finite
    /// for finite parts up to `MAX / sqrt(2)`, within 2 ulp of the exact
    /// modulus; infinite for an infinite part, NaN for a NaN one. Not
    /// inlined: `linearise` calls it per eigenvalue, and four inlined
    /// copies cost the QEMU twin image ~0.5 KiB of its 64 KiB.
    #[inline(never)]
    pub fn abs(self) -> T {
        let (a, b) = (self.re.abs(), self.im.abs());
        let (big, small) = if a >= b { (a, b) } else { (b, a) };
        if !(big > T::ZERO) || !big.is_finite() || !small.is_finite() {
            // Zero, an infinite or NaN part: the plain formula's answer.
            return big + small;
        }
        let r = small / big;
        big * (T::ONE + r * r).sqrt()
    }
}

/// `|a|` with the sign of `b` (Fortran's SIGN).
#[inline]
fn sign<T: Real>(a: T, b: T) -> T {
    if b >= T::ZERO { a.abs() } else { -a.abs() }
}

/// Eigenvalues of a real 4x4 matrix, sorted by real part, largest first
/// (ties: larger imaginary part first).
///
/// # Errors
///
/// `NonFinite("Jacobian")` when an entry of `m` is not finite;
/// `NoConvergence("eigenvalues")` when the QR iteration needs more than 30
/// sweeps for one eigenvalue.
pub fn eigenvalues<T: Float>(m: &[[T; 4]; 4]) -> Result<[Complex<T>; 4], ModelError> {
    const N: usize = 4;
    // 1-based working copy, as in EISPACK.
    let mut a = [[T::ZERO; N + 1]; N + 1];
    for i in 0..N {
        for j in 0..N {
            a[i + 1][j + 1] = finite(m[i][j], "Jacobian")?;
        }
    }
    balance(&mut a);
    hessenberg(&mut a);
    let mut wr = [T::ZERO; N + 1];
    let mut wi = [T::ZERO; N + 1];
    hqr(&mut a, &mut wr, &mut wi)?;
    let mut out = [Complex {
        re: T::ZERO,
        im: T::ZERO,
    }; N];
    for i in 0..N {
        out[i] = Complex {
            re: wr[i + 1],
            im: wi[i + 1],
        };
    }
    // Insertion sort: real part descending, then imaginary descending.
    for i in 1..N {
        let mut j = i;
        while j > 0 && (out[j].re > out[j - 1].re || (out[j].re == out[j - 1].re && out[j].im > out[j - 1].im)) {
            out.swap(j, j - 1);
            j -= 1;
        }
    }
    Ok(out)
}

/// Parlett-Reinsch balancing by powers of two (at most 16 sweeps).
fn balance<T: Float>(a: &mut [[T; 5]; 5]) {
    let n = 4;
    let radix = T::from_f64(2.0);
    let sqrdx = radix * radix;
    for _ in 0..16 {
        let mut done = true;
        for i in 1..=n {
            let (mut r, mut c) = (T::ZERO, T::ZERO);
            for j in 1..=n {
                if j != i {
                    c += a[j][i].abs();
                    r += a[i][j].abs();
                }
            }
            if c > T::ZERO && r > T::ZERO {
                let mut g = r / radix;
                let mut f = T::ONE;
                let s = c + r;
                let mut guard = 0;
                while c < g && guard < 64 {
                    f *= radix;
                    c *= sqrdx;
                    guard += 1;
                }
                g = r * radix;
                while c > g && guard < 128 {
                    f = f / radix;
                    c = c / sqrdx;
                    guard += 1;
                }
                if (c + r) / f < T::from_f64(0.95) * s {
                    done = false;
                    let g = T::ONE / f;
                    for j in 1..=n {
                        a[i][j] *= g;
                    }
                    for j in 1..=n {
                        a[j][i] *= f;
                    }
                }
            }
        }
        if done {
            break;
        }
    }
}

/// Reduction to upper Hessenberg form by stabilised elementary similarity
/// transformations (EISPACK `elmhes`).
fn hessenberg<T: Float>(a: &mut [[T; 5]; 5]) {
    let n = 4;
    for m in 2..n {
        let mut x = T::ZERO;
        let mut i = m;
        for j in m..=n {
            if a[j][m - 1].abs() > x.abs() {
                x = a[j][m - 1];
                i = j;
            }
        }
        if i != m {
            for j in (m - 1)..=n {
                let t = a[i][j];
                a[i][j] = a[m][j];
                a[m][j] = t;
            }
            for row in a.iter_mut().skip(1) {
                row.swap(i, m);
            }
        }
        if x != T::ZERO {
            for i in (m + 1)..=n {
                let mut y = a[i][m - 1];
                if y != T::ZERO {
                    y = y / x;
                    a[i][m - 1] = y;
                    for j in m..=n {
                        let t = a[m][j];
                        a[i][j] -= y * t;
                    }
                    for row in a.iter_mut().skip(1) {
                        let t = row[i];
                        row[m] += y * t;
                    }
                }
            }
        }
    }
}

/// Eigenvalues of an upper Hessenberg matrix (EISPACK `hqr`).
fn hqr<T: Float>(a: &mut [[T; 5]; 5], wr: &mut [T; 5], wi: &mut [T; 5]) -> Result<(), ModelError> {
    let n: usize = 4;
    let mut anorm = T::ZERO;
    for i in 1..=n {
        for j in (if i > 1 { i - 1 } else { 1 })..=n {
            anorm += a[i][j].abs();
        }
    }
    let (c075, c04375, half) = (T::from_f64(0.75), T::from_f64(-0.4375), T::from_f64(0.5));
    let mut nn = n;
    let mut t = T::ZERO;
    while nn >= 1 {
        let mut its = 0;
        loop {
            // Look for a single small subdiagonal element.
            let mut l = nn;
            while l >= 2 {
                let mut s = a[l - 1][l - 1].abs() + a[l][l].abs();
                if s == T::ZERO {
                    s = anorm;
                }
                if a[l][l - 1].abs() + s == s {
                    a[l][l - 1] = T::ZERO;
                    break;
                }
                l -= 1;
            }
            let mut x = a[nn][nn];
            if l == nn {
                // One root found.
                wr[nn] = x + t;
                wi[nn] = T::ZERO;
                nn -= 1;
                break;
            }
            let mut y = a[nn - 1][nn - 1];
            let mut w = a[nn][nn - 1] * a[nn - 1][nn];
            if l == nn - 1 {
                // Two roots found.
                let p = half * (y - x);
                let q = p * p + w;
                let z = q.abs().sqrt();
                x += t;
                if q >= T::ZERO {
                    let z = p + sign(z, p);
                    wr[nn - 1] = x + z;
                    wr[nn] = if z != T::ZERO { x - w / z } else { x + z };
                    wi[nn - 1] = T::ZERO;
                    wi[nn] = T::ZERO;
                } else {
                    wr[nn - 1] = x + p;
                    wr[nn] = x + p;
                    wi[nn - 1] = -z;
                    wi[nn] = z;
                }
                nn -= 2;
                break;
            }
            if its == 30 {
                return Err(ModelError::NoConvergence("eigenvalues"));
            }
            if its == 10 || its == 20 {
                // Exceptional shift.
                t += x;
                for i in 1..=nn {
                    a[i][i] -= x;
                }
                let s = a[nn][nn - 1].abs() + a[nn - 1][nn - 2].abs();
                x = c075 * s;
                y = x;
                w = c04375 * s * s;
            }
            its += 1;
            // Form the shift and look for two consecutive small subdiagonals.
            let mut m = nn - 2;
            let (mut p, mut q, mut r);
            loop {
                let z = a[m][m];
                let r1 = x - z;
                let s1 = y - z;
                p = (r1 * s1 - w) / a[m + 1][m] + a[m][m + 1];
                q = a[m + 1][m + 1] - z - r1 - s1;
                r = a[m + 2][m + 1];
                let s = p.abs() + q.abs() + r.abs();
                p = p / s;
                q = q / s;
                r = r / s;
                if m == l {
                    break;
                }
                let u = a[m][m - 1].abs() * (q.abs() + r.abs());
                let v = p.abs() * (a[m - 1][m - 1].abs() + z.abs() + a[m + 1][m + 1].abs());
                if u + v == v {
                    break;
                }
                m -= 1;
            }
            for i in (m + 2)..=nn {
                a[i][i - 2] = T::ZERO;
                if i != m + 2 {
                    a[i][i - 3] = T::ZERO;
                }
            }
            // Double QR step on rows l..nn and columns m..nn.
            let mut k = m;
            while k < nn {
                if k != m {
                    p = a[k][k - 1];
                    q = a[k + 1][k - 1];
                    r = if k != nn - 1 { a[k + 2][k - 1] } else { T::ZERO };
                    x = p.abs() + q.abs() + r.abs();
                    if x != T::ZERO {
                        p = p / x;
                        q = q / x;
                        r = r / x;
                    }
                }
                let s = sign((p * p + q * q + r * r).sqrt(), p);
                if s != T::ZERO {
                    if k == m {
                        if l != m {
                            a[k][k - 1] = -a[k][k - 1];
                        }
                    } else {
                        a[k][k - 1] = -s * x;
                    }
                    p += s;
                    x = p / s;
                    y = q / s;
                    let z = r / s;
                    q = q / p;
                    r = r / p;
                    for j in k..=nn {
                        let mut pp = a[k][j] + q * a[k + 1][j];
                        if k != nn - 1 {
                            pp += r * a[k + 2][j];
                            a[k + 2][j] -= pp * z;
                        }
                        a[k + 1][j] -= pp * y;
                        a[k][j] -= pp * x;
                    }
                    let mmin = if nn < k + 3 { nn } else { k + 3 };
                    for i in l..=mmin {
                        let mut pp = x * a[i][k] + y * a[i][k + 1];
                        if k != nn - 1 {
                            pp += z * a[i][k + 2];
                            a[i][k + 2] -= pp * r;
                        }
                        a[i][k + 1] -= pp * q;
                        a[i][k] -= pp;
                    }
                }
                k += 1;
            }
            if l >= nn - 1 {
                break;
            }
        }
    }
    for i in 1..=n {
        finite(wr[i], "eigenvalue")?;
        finite(wi[i], "eigenvalue")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn companion_matrix_roots() {
        // (s + 1)(s + 2)(s^2 + 2 s + 5): roots -1, -2, -1 +- 2i.
        // Expanded: s^4 + 5 s^3 + 13 s^2 + 19 s + 10.
        let m = [
            [-5.0, -13.0, -19.0, -10.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        let ev = eigenvalues(&m).unwrap();
        let expect = [(-1.0, 2.0), (-1.0, 0.0), (-1.0, -2.0), (-2.0, 0.0)];
        for (e, (re, im)) in ev.iter().zip(expect) {
            assert!((e.re - re).abs() < 1e-12 && (e.im - im).abs() < 1e-12, "{ev:?}");
        }
        assert!(eigenvalues(&[[f64::NAN; 4]; 4]).is_err());
    }

    /// F1 (docs/fuzzing.md): the modulus squared its parts, overflowing
    /// beyond ~1e154 (an infinite natural frequency, a damping ratio of 0)
    /// and rounding in the subnormals below ~1e-154 (a damping ratio of
    /// 1.02). Against libm's `hypot` over the whole exponent range, both
    /// types, within 2 ulp.
    #[test]
    fn the_modulus_is_right_over_the_whole_range() {
        for e in (-320..=307).step_by(7) {
            for (p, q) in [(1.0, 0.0), (3.0, 4.0), (-1.0, 1e-3), (0.5, -0.75), (1e-30, 1.0)] {
                let (re, im) = (p * 10f64.powi(e), q * 10f64.powi(e));
                let want = libm::hypot(re, im);
                let got = Complex { re, im }.abs();
                assert!(
                    (got - want).abs() <= 2.0 * f64::EPSILON * want,
                    "{re} {im}: {got} vs {want}"
                );
                let (re, im) = (re as f32, im as f32);
                if !(re.is_finite() && im.is_finite()) {
                    continue;
                }
                let want = libm::hypotf(re, im);
                let got = Complex { re, im }.abs();
                assert!(
                    (got - want).abs() <= 2.0 * f32::EPSILON * want,
                    "{re} {im}: {got} vs {want}"
                );
            }
        }
        // The damping ratio a huge or tiny eigenvalue used to break.
        for scale in [1e-300, 1e-160, 1.0, 1e160, 1e300] {
            let l = Complex {
                re: -0.6 * scale,
                im: 0.8 * scale,
            };
            assert!((-l.re / l.abs() - 0.6).abs() < 1e-15, "{scale}");
        }
        let big = Complex {
            re: f64::MAX,
            im: f64::MAX,
        };
        assert_eq!(big.abs(), f64::INFINITY);
        assert_eq!(Complex { re: f64::MAX, im: 1.0 }.abs(), f64::MAX);
        assert_eq!(Complex { re: 0.0f64, im: -0.0 }.abs(), 0.0);
        assert!(Complex { re: f64::NAN, im: 1.0 }.abs().is_nan());
        assert_eq!(
            Complex {
                re: f64::NEG_INFINITY,
                im: 1.0
            }
            .abs(),
            f64::INFINITY
        );
    }
}
