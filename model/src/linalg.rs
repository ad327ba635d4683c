//! Dense `N x N` linear algebra on the stack, generic over [`Real`]:
//! LU factorisation with partial pivoting and the matching solve; and
//! [`eigen`], the eigenvalues of a real 4x4 matrix (EISPACK's `hqr`).
//!
//! Cost for `N = 4`: 4 reciprocals, 18 multiply-adds for the factorisation,
//! 16 for each solve. No iteration, no allocation; a singular pivot is
//! reported, never divided by.

// Matrix code indexes rows and columns explicitly, as the algorithms are
// written (EISPACK, Hairer & Wanner); iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

pub mod eigen;
pub mod small;

use crate::scalar::Real;

/// An LU factorisation `P A = L U` of an `N x N` matrix.
#[derive(Clone, Copy, Debug)]
pub struct Lu<T, const N: usize> {
    /// `L` (unit diagonal, below) and `U` (on and above the diagonal).
    lu: [[T; N]; N],
    /// Reciprocals of `U`'s diagonal.
    inv_diag: [T; N],
    /// Row permutation.
    perm: [usize; N],
}

impl<T: Real, const N: usize> Lu<T, N> {
    /// Factorises `a`. Returns `None` when a pivot is zero or not finite.
    pub fn new(mut a: [[T; N]; N]) -> Option<Self> {
        let mut perm = [0usize; N];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        let mut inv_diag = [T::ZERO; N];
        for k in 0..N {
            // Partial pivoting: the largest magnitude in column k.
            let mut piv = k;
            let mut best = a[k][k].abs();
            for (i, row) in a.iter().enumerate().skip(k + 1) {
                let v = row[k].abs();
                if v > best {
                    best = v;
                    piv = i;
                }
            }
            if !(best > T::ZERO) || !best.is_finite() {
                return None;
            }
            if piv != k {
                a.swap(piv, k);
                perm.swap(piv, k);
            }
            let inv = T::ONE / a[k][k];
            inv_diag[k] = inv;
            for i in k + 1..N {
                let l = a[i][k] * inv;
                a[i][k] = l;
                for j in k + 1..N {
                    let u = a[k][j];
                    a[i][j] -= l * u;
                }
            }
        }
        Some(Lu { lu: a, inv_diag, perm })
    }

    /// Solves `A x = b`.
    pub fn solve(&self, b: &[T; N]) -> [T; N] {
        let mut y = [T::ZERO; N];
        for i in 0..N {
            let mut s = b[self.perm[i]];
            for (j, yj) in y.iter().enumerate().take(i) {
                s -= self.lu[i][j] * *yj;
            }
            y[i] = s;
        }
        let mut x = [T::ZERO; N];
        for i in (0..N).rev() {
            let mut s = y[i];
            for (j, xj) in x.iter().enumerate().skip(i + 1) {
                s -= self.lu[i][j] * *xj;
            }
            x[i] = s * self.inv_diag[i];
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_system_needing_pivoting() {
        let a = [
            [0.0, 2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0, 0.0],
            [3.0, 0.0, 1.0, 2.0],
            [0.0, 1.0, 0.0, 5.0],
        ];
        let x_true = [1.0, -2.0, 0.5, 3.0];
        let mut b = [0.0f64; 4];
        for i in 0..4 {
            for j in 0..4 {
                b[i] += a[i][j] * x_true[j];
            }
        }
        let x = Lu::new(a).unwrap().solve(&b);
        for i in 0..4 {
            assert!((x[i] - x_true[i]).abs() < 1e-14);
        }
        assert!(Lu::new([[1.0, 2.0], [2.0, 4.0]]).is_none());
        assert!(Lu::<f64, 2>::new([[f64::NAN, 0.0], [0.0, 1.0]]).is_none());
    }
}
