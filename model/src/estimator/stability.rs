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

/// Where a [`DecaySearch`] is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// Testing the hint (`hint` below the rate?).
    Hint(f32),
    /// The hint is below the rate: is `1.25 hint` not?
    HintAbove(f32),
    /// Testing the search's floor, `a3 / 4 * 2^-32`.
    Floor,
    /// Bracketing by powers of two: `sigma(lo)` not below the rate (or
    /// `lo = 0`), `sigma(hi)` below it.
    Bracket { lo: u32, hi: u32 },
    /// Bisecting the bracket `[below, above]`, `left` bisections to go.
    Refine { below: f32, above: f32, left: u8 },
    /// The result.
    Done(f32),
}

/// [`slowest_decay_rate`] in steps of one Routh-Hurwitz test each, so that
/// a core without an FPU (each test costs about 3,500 software-float
/// instructions on a Cortex-M0) can spread the search over several ticks:
/// run to its end it returns what [`slowest_decay_rate`] returns for the
/// same polynomial and hint, test for test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecaySearch {
    a: [f32; 4],
    phase: Phase,
}

impl DecaySearch {
    /// A search of the monic quartic `[a3, a2, a1, a0]` with `hint` (a
    /// previous result, or 0), as [`slowest_decay_rate`].
    pub fn new(a: &[f32; 4], hint: f32) -> Self {
        DecaySearch {
            a: *a,
            phase: if hint > 0.0 { Phase::Hint(hint) } else { Phase::Floor },
        }
    }

    /// The result once the search has ended.
    pub fn result(&self) -> Option<f32> {
        match self.phase {
            Phase::Done(sigma) => Some(sigma),
            _ => None,
        }
    }

    /// The next step: at most one Routh-Hurwitz test. `Some` with the
    /// result when the search has ended (then every later call too).
    pub fn step(&mut self) -> Option<f32> {
        let a = &self.a;
        let stable = |sigma: f32| quartic_hurwitz(&shifted(a, sigma));
        let top = 0.25 * a[0];
        let scaled = |k: u32| top * f32::from_bits((127 - k) << 23);
        self.phase = match self.phase {
            Phase::Hint(h) => {
                if stable(h) {
                    Phase::HintAbove(h)
                } else {
                    Phase::Floor
                }
            }
            Phase::HintAbove(h) => {
                if stable(1.25 * h) {
                    Phase::Floor
                } else {
                    Phase::Done(h)
                }
            }
            Phase::Floor => {
                if !(top > 0.0) || !stable(scaled(32)) {
                    Phase::Done(0.0)
                } else {
                    Phase::Bracket { lo: 0, hi: 32 }
                }
            }
            Phase::Bracket { lo, hi } => {
                let mid = (lo + hi) / 2;
                let (lo, hi) = if stable(scaled(mid)) { (lo, mid) } else { (mid, hi) };
                if hi - lo > 1 {
                    Phase::Bracket { lo, hi }
                } else {
                    Phase::Refine {
                        below: scaled(hi),
                        above: scaled(lo),
                        left: 2,
                    }
                }
            }
            Phase::Refine { below, above, left } => {
                let mid = 0.5 * (below + above);
                let (below, above) = if stable(mid) { (mid, above) } else { (below, mid) };
                if left > 1 {
                    Phase::Refine {
                        below,
                        above,
                        left: left - 1,
                    }
                } else {
                    Phase::Done(below)
                }
            }
            done @ Phase::Done(_) => done,
        };
        self.result()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A [`DecaySearch`] run to its end, and its steps.
    fn stepped(a: &[f32; 4], hint: f32) -> (f32, u32) {
        let mut search = DecaySearch::new(a, hint);
        for n in 1..=16 {
            if let Some(sigma) = search.step() {
                return (sigma, n);
            }
        }
        panic!("no result after 16 steps");
    }

    #[test]
    fn the_stepped_search_is_the_search() {
        for roots in [
            [0.5, 1.0, 2.0, 4.0],
            [0.01, 1.0, 3.0, 10.0],
            [0.3, 0.5, 2.0, 2.5],
            [-0.5, 1.0, 2.0, 3.0],
            [1e-3, 50.0, 400.0, 9e3],
            [2.0, 2.0, 2.0, 2.0],
        ] {
            let a = with_roots(roots);
            for hint in [0.0, 0.2, 0.4, 0.75 * roots[0], roots[0], 3.0] {
                let (sigma, steps) = stepped(&a, hint);
                assert_eq!(
                    sigma.to_bits(),
                    slowest_decay_rate(&a, hint).to_bits(),
                    "{roots:?} {hint}"
                );
                assert!(steps <= 10, "{roots:?} {hint}: {steps}");
            }
        }
        assert_eq!(stepped(&[f32::NAN; 4], 1.0).0, slowest_decay_rate(&[f32::NAN; 4], 1.0));
    }

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
