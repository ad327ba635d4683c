//! The stability of the linearisation from its characteristic polynomial:
//! the Routh-Hurwitz test and a bound of the slowest mode's decay rate (the
//! estimator's Stability job, which sizes the consistency check's settling
//! window).

/// The Routh-Hurwitz conditions of `s^4 + a3 s^3 + a2 s^2 + a1 s + a0`
/// (coefficients `[a3, a2, a1, a0]`, as
/// [`characteristic_polynomial`](crate::dynamics::linear::characteristic_polynomial)
/// returns them): `true` when every root has a negative real part. The
/// same verdict as `dynamics::linear::hurwitz_stable`, from coefficients
/// already at hand.
///
/// In the quotient form of
/// [`hurwitz_quartic`](crate::dynamics::linear::hurwitz_quartic): no
/// product of three coefficients, which overflowed `f32` from
/// coefficients of ~1e13 on.
#[inline]
pub fn quartic_hurwitz(a: &[f32; 4]) -> bool {
    crate::dynamics::linear::hurwitz_quartic(a)
}

/// Coefficients of `p(s - sigma)` for the monic quartic `p` with
/// coefficients `[a3, a2, a1, a0]`: the characteristic polynomial of
/// `M + sigma I` when `p` is `M`'s. Taylor shift by four passes of
/// synthetic division at `-sigma` (ten multiply-adds).
fn shifted(a: &[f32; 4], sigma: f32) -> [f32; 4] {
    let r = -sigma;
    let [mut c3, mut c2, mut c1, mut c0] = *a;
    c3 += r;
    c2 += r * c3;
    c1 += r * c2;
    c0 += r * c1;
    c3 += r;
    c2 += r * c3;
    c1 += r * c2;
    c3 += r;
    c2 += r * c3;
    c3 += r;
    [c3, c2, c1, c0]
}

/// A lower bound, within 25 %, of the smallest decay rate
/// `min(-Re(lambda))` over the roots of the monic quartic `[a3, a2, a1, a0]`
/// (in the polynomial's time unit), or 0 when the polynomial is not Hurwitz
/// or the rate is below `a3 / 4 * 2^-32`.
///
/// `M + sigma I` is Hurwitz exactly when `sigma` is below that rate, and the
/// rate is at most the mean `a3 / 4`: a binary search over `sigma =
/// a3 / 4 * 2^-k` (`k` = 0..32, five Routh-Hurwitz tests) brackets it
/// within a factor two, two bisections within 25 %; the stable end is
/// returned. Eight tests of ~30 flops: no eigenvalue iteration, bounded
/// cost, and exact for complex modes too (underdamped designs).
///
/// `hint` (a previous result, or 0) is tried first: when `hint` is still
/// below the rate and `1.25 hint` is not, `hint` is the answer (two tests,
/// the usual case at a steady temperature); otherwise the search runs.
pub fn slowest_decay_rate(a: &[f32; 4], hint: f32) -> f32 {
    let stable = |sigma: f32| quartic_hurwitz(&shifted(a, sigma));
    if hint > 0.0 && stable(hint) && !stable(1.25 * hint) {
        return hint;
    }
    let top = 0.25 * a[0];
    // 2^-k, exactly, for k in 0..=32.
    let scaled = |k: u32| top * f32::from_bits((127 - k) << 23);
    if !(top > 0.0) || !stable(scaled(32)) {
        return 0.0;
    }
    // Invariant: sigma(lo) is not below the rate (or lo = 0, the mean),
    // sigma(hi) is.
    let (mut lo, mut hi) = (0u32, 32u32);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if stable(scaled(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let (mut below, mut above) = (scaled(hi), scaled(lo));
    for _ in 0..2 {
        let mid = 0.5 * (below + above);
        if stable(mid) {
            below = mid;
        } else {
            above = mid;
        }
    }
    below
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The monic quartic with the roots `-r` (coefficients `[a3, a2, a1, a0]`).
    fn with_roots(r: [f32; 4]) -> [f32; 4] {
        // Expand (s + r0)(s + r1)(s + r2)(s + r3).
        let mut c = [1.0f32, 0.0, 0.0, 0.0, 0.0];
        for (n, ri) in r.iter().enumerate() {
            for k in (1..=n + 1).rev() {
                c[k] += ri * c[k - 1];
            }
        }
        [c[1], c[2], c[3], c[4]]
    }

    #[test]
    fn the_decay_rate_is_a_lower_bound_within_a_quarter() {
        for roots in [[0.5, 1.0, 2.0, 4.0], [0.01, 1.0, 3.0, 10.0], [0.3, 0.5, 2.0, 2.5]] {
            let a = with_roots(roots);
            assert!(quartic_hurwitz(&a), "{roots:?}");
            let slowest = roots[0];
            let rate = slowest_decay_rate(&a, 0.0);
            assert!(rate <= slowest * 1.0001 && rate >= 0.75 * slowest, "{roots:?}: {rate}");
            // Its own result as the hint: the same answer, from two tests.
            assert_eq!(slowest_decay_rate(&a, rate), rate);
        }
        let unstable = with_roots([-0.5, 1.0, 2.0, 3.0]);
        assert!(!quartic_hurwitz(&unstable));
        assert_eq!(slowest_decay_rate(&unstable, 0.0), 0.0);
    }
}
