//! Elementary functions in native `f32` arithmetic.
//!
//! `libm`'s `expf`, `exp2f`, `exp10f`, `logf` and `powf` (ports of musl and
//! Arm's optimized-routines) compute in double precision internally, which
//! a Cortex-M4F (single-precision FPU) runs as software: ~1,000 instructions
//! per call. These kernels use only `f32` operations (~30-40 instructions,
//! one division for the logarithms) and are used by every `f32` path of the
//! crate, on the host as on the target, so the host tests check the code
//! that ships.
//!
//! Method: Cody-Waite range reduction with the reduction constant split in
//! two (the integer multiples of the high part are exact), then
//! * `e^y` on `|y| <= 0.35` by its degree-7 Taylor polynomial (truncation
//!   below 6e-9 relative);
//! * `ln(m)` on `m in [sqrt(1/2), sqrt(2))` as `2 atanh(s)`,
//!   `s = (m - 1) / (m + 1)`, `|s| <= 0.172`, to `s^11`, arranged as in
//!   fdlibm so that the exact `m - 1` leads.
//!
//! Accuracy (checked against `f64` on a dense sweep by the unit tests):
//! `exp`, `exp2`, `exp10`, `ln`, `log2`, `log10`, `ln_1p` within 2 ulp;
//! `powf` within 2 ulp plus `|p log2 x|` ulp (it goes through `exp2`).

// High parts with 16 significant bits: n * HI is exact for |n| < 256.
const LN2_HI: f32 = f32::from_bits(0x3f31_7200); // 0.693145751953125
const LN2_LO: f32 = 1.428_606_8e-6;
const LOG2_E: f32 = core::f32::consts::LOG2_E;
const LOG10_2_HI: f32 = f32::from_bits(0x3e9a_2000); // 0.301025390625
const LOG10_2_LO: f32 = 4.605_039e-6;
const LN10: f32 = core::f32::consts::LN_10;
const LOG2_10: f32 = core::f32::consts::LOG2_10;
const LN2: f32 = core::f32::consts::LN_2;
const LOG10_E: f32 = core::f32::consts::LOG10_E;
const SQRT_2: f32 = core::f32::consts::SQRT_2;

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

/// `e^x`.
pub fn exp(x: f32) -> f32 {
    if x.is_nan() {
        return x;
    }
    if x > 88.8 {
        return f32::INFINITY;
    }
    if x < -104.0 {
        return 0.0;
    }
    let (nf, n) = round(x * LOG2_E);
    let r = (x - nf * LN2_HI) - nf * LN2_LO;
    scale(exp_kernel(r), n)
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

/// `(exponent, ln(m))` with `x = m 2^exponent`, `m in [sqrt(1/2), sqrt(2))`,
/// for positive, finite, normal or subnormal `x`.
#[inline(always)]
fn log_parts(x: f32) -> (f32, f32) {
    let mut bits = x.to_bits();
    let mut e = 0i32;
    if bits < 0x0080_0000 {
        // Subnormal: scale by 2^23.
        bits = (x * 8_388_608.0).to_bits();
        e -= 23;
    }
    e += ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    (e as f32, ln_kernel(m - 1.0))
}

/// `ln(1 + f)` for `f in [sqrt(1/2) - 1, sqrt(2) - 1]` (fdlibm's form):
/// with `s = f / (2 + f)`, `ln(1 + f) = 2 atanh(s) = f - f^2/2 + s (f^2/2 + R(s^2))`,
/// `R(z) = 2z/3 + 2z^2/5 + ... + 2z^5/11`. The leading `f` is exact, so the
/// rounding of the small correction terms stays below one ulp of the result.
#[inline(always)]
fn ln_kernel(f: f32) -> f32 {
    let s = f / (2.0 + f);
    let z = s * s;
    let r = z * (2.0 / 3.0 + z * (2.0 / 5.0 + z * (2.0 / 7.0 + z * (2.0 / 9.0 + z * (2.0 / 11.0)))));
    let hfsq = 0.5 * f * f;
    f - (hfsq - s * (hfsq + r))
}

/// Special cases of the logarithms: `Some(result)` for NaN, zero, negative
/// and infinite `x`.
#[inline(always)]
fn log_special(x: f32) -> Option<f32> {
    if x.is_nan() || x < 0.0 {
        Some(f32::NAN)
    } else if x == 0.0 {
        Some(f32::NEG_INFINITY)
    } else if x == f32::INFINITY {
        Some(f32::INFINITY)
    } else {
        None
    }
}

/// Natural logarithm.
pub fn ln(x: f32) -> f32 {
    if let Some(v) = log_special(x) {
        return v;
    }
    let (e, l) = log_parts(x);
    e * LN2_HI + (l + e * LN2_LO)
}

/// Base-2 logarithm.
pub fn log2(x: f32) -> f32 {
    if let Some(v) = log_special(x) {
        return v;
    }
    let (e, l) = log_parts(x);
    e + l * LOG2_E
}

/// Base-10 logarithm.
pub fn log10(x: f32) -> f32 {
    if let Some(v) = log_special(x) {
        return v;
    }
    let (e, l) = log_parts(x);
    e * LOG10_2_HI + (l * LOG10_E + e * LOG10_2_LO)
}

/// `ln(1 + x)`, accurate for small `x`.
pub fn ln_1p(x: f32) -> f32 {
    if x.is_nan() || x < -1.0 {
        return f32::NAN;
    }
    if x == -1.0 {
        return f32::NEG_INFINITY;
    }
    if x > -0.29 && x < 0.41 {
        // The kernel's argument is x itself: no rounding of 1 + x.
        return ln_kernel(x);
    }
    ln(1.0 + x)
}

/// `x^p` (through `2^(p log2 x)`; `x < 0` gives NaN, as `f32::powf` does
/// for non-integer `p`).
pub fn powf(x: f32, p: f32) -> f32 {
    if p == 0.0 {
        return 1.0;
    }
    if x == 1.0 {
        return 1.0;
    }
    exp2(p * log2(x))
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

    fn sweep(lo: f32, hi: f32, n: usize) -> impl Iterator<Item = f32> {
        (0..=n).map(move |i| lo + (hi - lo) * (i as f32 / n as f32))
    }

    fn worst(f: impl Fn(f32) -> f32, exact: impl Fn(f64) -> f64, xs: impl Iterator<Item = f32>) -> (f64, f32) {
        xs.map(|x| (ulps(f(x), exact(x as f64)), x))
            .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
    }

    #[test]
    fn exponentials_within_two_ulp() {
        let (e, x) = worst(exp, f64::exp, sweep(-87.0, 88.0, 200_000));
        assert!(e <= 2.0, "exp: {e} ulp at {x}");
        let (e, x) = worst(exp2, f64::exp2, sweep(-125.0, 127.0, 200_000));
        assert!(e <= 2.0, "exp2: {e} ulp at {x}");
        let (e, x) = worst(exp10, |v| 10f64.powf(v), sweep(-37.0, 38.0, 200_000));
        assert!(e <= 2.0, "exp10: {e} ulp at {x}");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp2(10.0), 1024.0);
        assert_eq!(exp10(2.0), 100.0);
        assert!(exp(f32::NAN).is_nan());
        assert_eq!(exp(1000.0), f32::INFINITY);
        assert_eq!(exp(-1000.0), 0.0);
        assert!(exp2(-140.0) > 0.0, "subnormal results");
    }

    #[test]
    fn logarithms_within_two_ulp() {
        let xs = || {
            sweep(1e-3, 50.0, 200_000)
                .chain(sweep(0.5, 2.0, 100_000))
                .chain([1e-40f32, 1e-30, 3e38])
        };
        let (e, x) = worst(ln, f64::ln, xs());
        assert!(e <= 2.0, "ln: {e} ulp at {x}");
        let (e, x) = worst(log2, f64::log2, xs());
        assert!(e <= 2.0, "log2: {e} ulp at {x}");
        let (e, x) = worst(log10, f64::log10, xs());
        assert!(e <= 2.0, "log10: {e} ulp at {x}");
        let (e, x) = worst(
            ln_1p,
            f64::ln_1p,
            sweep(-0.9, 10.0, 200_000).chain(sweep(-1e-4, 1e-4, 10_000)),
        );
        assert!(e <= 2.0, "ln_1p: {e} ulp at {x}");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(log2(8.0), 3.0);
        assert!(ln(-1.0).is_nan());
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
        assert_eq!(ln(f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn power() {
        let mut worst_ulp = 0.0f64;
        for x in sweep(0.01, 100.0, 2_000) {
            for p in [-2.5f32, -0.5, 0.25, 1.5, 3.0] {
                let exact = (x as f64).powf(p as f64);
                let allowed = 2.0 + (p as f64 * (x as f64).log2()).abs();
                let e = ulps(powf(x, p), exact);
                worst_ulp = worst_ulp.max(e);
                assert!(e <= allowed, "powf({x}, {p}): {e} ulp");
            }
        }
        assert_eq!(powf(2.0, 0.0), 1.0);
    }
}
