//! `10^x` and `2^x` in native `f32` arithmetic.
//!
//! `libm`'s `exp10f` and `exp2f` (musl's) compute in double precision, which
//! a Cortex-M4F (single-precision FPU) runs in software: about 1,230
//! instructions per call (`cargo xtask bench`, `docs/bench.md`). Walther's
//! law needs two `10^x` per evaluation. These kernels use only `f32`
//! operations (about 95 instructions) and serve every `f32` path of the
//! crate, on the host as on the target, so the host tests check the code
//! that ships. `libm`'s other `f32` functions (`expf`, `logf`, `log1pf`,
//! `log10f`, `powf`) are native single precision and used as they are.
//!
//! Method: Cody-Waite range reduction with the reduction constant split in
//! two (the integer multiples of the high part are exact), then `e^y` on
//! `|y| <= 0.35` by its degree-7 Taylor polynomial (truncation below 6e-9
//! relative). Accuracy, checked against `f64` by the unit tests: within
//! 2 ulp.

// High part with 16 significant bits: n * HI is exact for |n| < 256.
const LOG10_2_HI: f32 = f32::from_bits(0x3e9a_2000); // 0.301025390625
const LOG10_2_LO: f32 = 4.605_039e-6;
const LN10: f32 = core::f32::consts::LN_10;
const LOG2_10: f32 = core::f32::consts::LOG2_10;
const LN2: f32 = core::f32::consts::LN_2;

/// `e^y` for `|y| <= 0.35` (degree-7 Taylor, Horner).
#[inline(always)]
fn exp_kernel(y: f32) -> f32 {
    const C: [f32; 8] = [
        1.0,
        1.0,
        0.5,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
    ];
    let mut p = C[7];
    p = p * y + C[6];
    p = p * y + C[5];
    p = p * y + C[4];
    p = p * y + C[3];
    p = p * y + C[2];
    p = p * y + C[1];
    p * y + C[0]
}

/// `v * 2^n` for the result range of the exponentials (two steps so that
/// subnormal results and 2^128 * small values come out right).
#[inline(always)]
fn scale(v: f32, n: i32) -> f32 {
    let n = n.clamp(-300, 300);
    let (n1, n2) = (n / 2, n - n / 2);
    let p = |k: i32| {
        if k < -126 {
            // 2^k as a subnormal or zero.
            if k < -149 {
                0.0
            } else {
                f32::from_bits(1u32 << (k + 149))
            }
        } else if k > 127 {
            f32::INFINITY
        } else {
            f32::from_bits(((k + 127) as u32) << 23)
        }
    };
    v * p(n1) * p(n2)
}

/// Nearest integer of `x` (|x| < 2^22), as `f32` and `i32`.
#[inline(always)]
fn round(x: f32) -> (f32, i32) {
    let n = if x >= 0.0 { (x + 0.5) as i32 } else { (x - 0.5) as i32 };
    (n as f32, n)
}

/// `2^x`.
pub fn exp2(x: f32) -> f32 {
    if x.is_nan() {
        return x;
    }
    if x > 128.5 {
        return f32::INFINITY;
    }
    if x < -151.0 {
        return 0.0;
    }
    let (nf, n) = round(x);
    scale(exp_kernel((x - nf) * LN2), n)
}

/// `10^x`.
pub fn exp10(x: f32) -> f32 {
    if x.is_nan() {
        return x;
    }
    if x > 38.6 {
        return f32::INFINITY;
    }
    if x < -45.5 {
        return 0.0;
    }
    let (nf, n) = round(x * LOG2_10);
    let r = (x - nf * LOG10_2_HI) - nf * LOG10_2_LO;
    scale(exp_kernel(r * LN10), n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between an f32 result and the
    /// exact value (f64).
    fn ulps(actual: f32, exact: f64) -> f64 {
        if actual as f64 == exact || (actual.is_nan() && exact.is_nan()) {
            return 0.0;
        }
        let e32 = exact as f32;
        let ulp = (f32::from_bits(e32.abs().to_bits() + 1) - e32.abs()) as f64;
        ((actual as f64) - exact).abs() / ulp
    }

    fn worst(f: impl Fn(f32) -> f32, exact: impl Fn(f64) -> f64, lo: f32, hi: f32) -> (f64, f32) {
        (0..=200_000)
            .map(|i| lo + (hi - lo) * (i as f32 / 200_000.0))
            .map(|x| (ulps(f(x), exact(x as f64)), x))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
    }

    #[test]
    fn exponentials_within_two_ulp() {
        let (e, x) = worst(exp2, f64::exp2, -125.0, 127.0);
        assert!(e <= 2.0, "exp2: {e} ulp at {x}");
        let (e, x) = worst(exp10, |v| 10f64.powf(v), -37.0, 38.0);
        assert!(e <= 2.0, "exp10: {e} ulp at {x}");
        assert_eq!(exp2(10.0), 1024.0);
        assert_eq!(exp10(2.0), 100.0);
        assert!(exp10(f32::NAN).is_nan());
        assert_eq!(exp10(1000.0), f32::INFINITY);
        assert_eq!(exp10(-1000.0), 0.0);
        assert!(exp2(-140.0) > 0.0, "subnormal results");
    }

    /// Why not `micromath`'s approximations (the crate the product names
    /// for cheap `f32` math): through Walther's double exponential an error
    /// in `exp`/`log` reaches the viscosity amplified about tenfold, so
    /// `micromath`'s error would dominate the `f32` equilibrium's budget of
    /// 1e-5 of the stroke. (`F32Ext` is called explicitly: on a std host
    /// `f32`'s own methods would shadow it.)
    #[test]
    fn micromath_is_too_coarse_for_walther() {
        use micromath::F32Ext;
        let rel = |a: f32, e: f64| ((a as f64) - e).abs() / e.abs();
        let (mut ours, mut theirs) = (0.0f64, 0.0f64);
        for i in 1..2000 {
            let x = i as f32 * 0.01;
            ours = ours
                .max(rel(libm::expf(x), (x as f64).exp()))
                .max(rel(libm::logf(x + 1.0), ((x + 1.0) as f64).ln()));
            theirs = theirs
                .max(rel(F32Ext::exp(x), (x as f64).exp()))
                .max(rel(F32Ext::ln(x + 1.0), ((x + 1.0) as f64).ln()));
        }
        assert!(
            ours < 2e-7 && theirs > 1e-5,
            "exp/ln: libm {ours:e}, micromath {theirs:e}"
        );
        // Walther's viscosity at 30-80 C for the paper's oil (a = 13.41,
        // b = 5.34): 10^(10^(a - b log10 T)) - 0.7 with each set of kernels.
        let walther = |e10: &dyn Fn(f32) -> f32, l10: &dyn Fn(f32) -> f32, t: f32| {
            e10(e10(13.406 - 5.3405 * l10(t + 273.15))) - 0.7
        };
        let mut worst = (0.0f64, 0.0f64);
        for t in (30..=80).map(|t| t as f32) {
            let exact = 10f64.powf(10f64.powf(13.406 - 5.3405 * ((t + 273.15) as f64).log10())) - 0.7;
            let ours = walther(&exp10, &libm::log10f, t) as f64;
            let theirs = walther(&|x| F32Ext::exp(x * core::f32::consts::LN_10), &F32Ext::log10, t) as f64;
            worst = (
                worst.0.max((ours - exact).abs() / exact),
                worst.1.max((theirs - exact).abs() / exact),
            );
        }
        assert!(
            worst.0 < 2e-5 && worst.1 > 10.0 * worst.0,
            "viscosity: ours {:e}, micromath {:e}",
            worst.0,
            worst.1
        );
    }
}
