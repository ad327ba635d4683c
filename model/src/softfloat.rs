//! Single-precision multiply and add for cores without an FPU, in the form
//! that is cheap where the core has no long multiply (ARMv6-M: the
//! Cortex-M0/M0+): the common case only, normal operands with a normal
//! result, rounded to nearest, ties to even, bit for bit IEEE 754's
//! `binary32` result; `None` for everything else (a zero, subnormal,
//! infinite or NaN operand, a result that overflows or is subnormal), which
//! the caller hands to the full routine.
//!
//! Why: on ARMv6-M, `compiler_builtins`' `__mulsf3` forms the 48-bit
//! product of the mantissas as a 64 x 64 multiply (`__aeabi_lmul`, 43
//! instructions), about 113 instructions a product in all (`cargo xtask
//! bench`, "Fixed-point operations", `f32-mul`), and its generic addition
//! is written for every format. Here the product is four 16 x 16 -> 32
//! `MULS` (the mantissas' high halves are 8 bits), and the sum shifts
//! 32-bit words only. The estimator's own arithmetic (the observer, the
//! jobs, the flows) is `f32`; on the Cortex-M0 it is software, and these
//! fast paths are what the images link as `__aeabi_fmul`, `__aeabi_fadd`
//! and `__aeabi_fsub` (`src/softfloat.rs` of the firmware; measured in
//! `docs/bench.md`). Those are Thumb-1 assembly, step for step this
//! module's functions; the twin and bench images of that core compare
//! them with `compiler_builtins`' routines at start-up, and the host
//! tests below compare this module with the host's FPU on millions of
//! operand pairs of every magnitude.
//!
//! Nothing here is `unsafe`, and nothing panics.

/// The sign bit of a `binary32` word.
const SIGN: u32 = 0x8000_0000;
/// The fraction field.
const FRACTION: u32 = 0x007F_FFFF;
/// The implicit leading bit of a normal number's significand.
const IMPLICIT: u32 = 0x0080_0000;
/// The magnitude of an infinity (larger ones are NaNs).
const INFINITY: u32 = 0x7F80_0000;

/// The biased exponent of a normal number (`1..=254`), `None` otherwise.
#[inline(always)]
fn normal_exponent(w: u32) -> Option<u32> {
    let e = (w >> 23) & 0xFF;
    if e.wrapping_sub(1) < 254 { Some(e) } else { None }
}

/// `a b` for the words of two `f32`: the correctly rounded product where
/// both are normal and so is the product; `0` of the product's sign where
/// one is a zero and the other finite; `None` otherwise.
#[inline(always)]
pub fn mul(a: u32, b: u32) -> Option<u32> {
    let sign = (a ^ b) & SIGN;
    let (ea, eb) = match (normal_exponent(a), normal_exponent(b)) {
        (Some(ea), Some(eb)) => (ea, eb),
        // A zero times a finite number: a zero of the product's sign.
        _ if (a & !SIGN == 0 && b & !SIGN < INFINITY) || (b & !SIGN == 0 && a & !SIGN < INFINITY) => {
            return Some(sign);
        }
        _ => return None,
    };
    let ma = (a & FRACTION) | IMPLICIT;
    let mb = (b & FRACTION) | IMPLICIT;
    // The 48-bit product from 16-bit halves (the high halves have 8 bits):
    // P = hi 2^32 + mid 2^16 + lo, each partial product one `MULS`.
    let (ah, al) = (ma >> 16, ma & 0xFFFF);
    let (bh, bl) = (mb >> 16, mb & 0xFFFF);
    let lo = al * bl;
    // < 2^25 + 2^16: no overflow.
    let mid = ah * bl + al * bh + (lo >> 16);
    // floor(P / 2^16), below 2^32 (P < 2^48); what is left below is sticky.
    let top = ((ah * bh) << 16) + mid;
    let low_sticky = lo & 0xFFFF != 0;
    // P in [2^46, 2^48): the significand is top's 24 bits below bit 31 or
    // 32, the bits under it round.
    let mut e = (ea + eb) as i32 - 127;
    let (mut m, rest, half) = if top >= SIGN {
        e += 1;
        (top >> 8, top & 0xFF, 0x80)
    } else {
        (top >> 7, top & 0x7F, 0x40)
    };
    if rest > half || (rest == half && (low_sticky || m & 1 != 0)) {
        m += 1;
        if m == 2 * IMPLICIT {
            m >>= 1;
            e += 1;
        }
    }
    if !(1..=254).contains(&e) {
        return None;
    }
    Some(sign | ((e as u32) << 23) | (m & FRACTION))
}

/// `a + b` for the words of two `f32`: the correctly rounded sum where
/// both are normal and so is the sum (an exact zero is `+0`, as IEEE 754
/// rounds to nearest); the other operand where one is a zero and the other
/// normal; for two zeros `+0` unless both are `-0`; `None` otherwise.
#[inline(always)]
pub fn add(a: u32, b: u32) -> Option<u32> {
    let (ea, eb) = match (normal_exponent(a), normal_exponent(b)) {
        (Some(ea), Some(eb)) => (ea, eb),
        // x + 0 = x for a normal x, whatever the zero's sign.
        (None, Some(_)) if a & !SIGN == 0 => return Some(b),
        (Some(_), None) if b & !SIGN == 0 => return Some(a),
        // Two zeros: +0 unless both are -0.
        _ if (a | b) & !SIGN == 0 => return Some(a & b),
        _ => return None,
    };
    // The larger magnitude first (its sign is the sum's).
    let (big, small, mut e, es) = if a & !SIGN >= b & !SIGN {
        (a, b, ea, eb)
    } else {
        (b, a, eb, ea)
    };
    // Significands with three bits below for rounding (27 bits).
    let mb = ((big & FRACTION) | IMPLICIT) << 3;
    let ms = ((small & FRACTION) | IMPLICIT) << 3;
    let d = e - es;
    // The smaller one aligned, the bits shifted out kept as a sticky bit.
    let ms = if d == 0 {
        ms
    } else if d < 27 {
        (ms >> d) | u32::from(ms << (32 - d) != 0)
    } else {
        1
    };
    let mut m = if (a ^ b) & SIGN == 0 {
        let m = mb + ms;
        if m >= 1 << 27 {
            e += 1;
            (m >> 1) | (m & 1)
        } else {
            m
        }
    } else {
        let m = mb - ms;
        if m == 0 {
            return Some(0);
        }
        // Cancellation: renormalised (exact where it is more than a bit:
        // then the operands were within a binade and nothing was shifted
        // out). A subnormal result goes to the full routine.
        let shift = m.leading_zeros() - 5;
        if shift >= e {
            return None;
        }
        e -= shift;
        m << shift
    };
    let rest = m & 7;
    m >>= 3;
    if rest > 4 || (rest == 4 && m & 1 != 0) {
        m += 1;
        if m == 2 * IMPLICIT {
            m >>= 1;
            e += 1;
        }
    }
    if e > 254 {
        return None;
    }
    Some((big & SIGN) | (e << 23) | (m & FRACTION))
}

/// `a - b` (the sum with `b`'s sign flipped: see [`add`]).
#[inline(always)]
pub fn sub(a: u32, b: u32) -> Option<u32> {
    add(a, b ^ SIGN)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Words of every magnitude and sign, with the exponents biased
    /// towards each other (sums that cancel) now and then.
    fn words(count: usize, seed: u64) -> impl Iterator<Item = (u32, u32)> {
        let mut s = seed;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        (0..count).map(move |_| {
            let (x, y) = (next(), next());
            let a = x as u32;
            let b = match y & 3 {
                // Any word.
                0 => (y >> 32) as u32,
                // Within a few binades of a (sums that cancel, carries).
                1 => {
                    let shift = ((y >> 8) & 7) as u32;
                    (a & 0xFF80_0000).wrapping_add(((y >> 32) as u32) >> (9 + shift)) ^ ((y as u32 >> 4) & SIGN)
                }
                // a nudged by a few units in the last place.
                2 => a.wrapping_add((y >> 40) as u32 & 0xF) ^ ((y as u32) & SIGN),
                // An exponent near the ends of the range.
                _ => {
                    ((y >> 32) as u32 & 0x807F_FFFF)
                        | (((y >> 16) as u32 % 24 + if y & 16 != 0 { 0 } else { 230 }) << 23)
                }
            };
            (a, b)
        })
    }

    const EDGES: [u32; 16] = [
        0,
        SIGN,
        1,
        0x007F_FFFF,
        0x0080_0000,
        0x0080_0001,
        0x3F80_0000,
        0xBF80_0000,
        0x3F80_0001,
        0x3F7F_FFFF,
        0x7F7F_FFFF,
        0xFF7F_FFFF,
        0x7F80_0000,
        0xFF80_0000,
        0x7FC0_0000,
        0x0000_0003,
    ];

    fn check(a: u32, b: u32) {
        let (x, y) = (f32::from_bits(a), f32::from_bits(b));
        if let Some(p) = mul(a, b) {
            assert_eq!(p, (x * y).to_bits(), "{x:e} * {y:e} ({a:#x}, {b:#x})");
        } else {
            let p = x * y;
            let e = (p.to_bits() >> 23) & 0xFF;
            let normal_in = normal_exponent(a).is_some() && normal_exponent(b).is_some();
            // Refused only where the full routine is needed: a product
            // at the subnormals' edge (rounded up to the smallest normal
            // or not) or beyond the range.
            assert!(!normal_in || e <= 1 || e == 255, "mul refused {x:e} * {y:e}");
        }
        for (got, want, what) in [(add(a, b), x + y, "+"), (sub(a, b), x - y, "-")] {
            if let Some(s) = got {
                assert_eq!(s, want.to_bits(), "{x:e} {what} {y:e} ({a:#x}, {b:#x})");
            } else {
                let e = (want.to_bits() >> 23) & 0xFF;
                let normal_in = normal_exponent(a).is_some() && normal_exponent(b).is_some();
                assert!(!normal_in || e <= 1 || e == 255, "{what} refused {x:e} {y:e}");
            }
        }
    }

    #[test]
    fn fast_paths_round_as_ieee_754_does() {
        for (a, b) in words(3_000_000, 0x9E37_79B9_7F4A_7C15) {
            check(a, b);
            check(b, a);
        }
        for &a in &EDGES {
            for &b in &EDGES {
                check(a, b);
            }
        }
    }

    #[test]
    fn fast_paths_take_the_common_cases() {
        // What the estimator's arithmetic meets must not fall back.
        for (x, y) in [
            (1.5f32, 2.25f32),
            (-3.0e-5, 7.0e3),
            (1.0, -1.0 + f32::EPSILON),
            (0.0, 4.0),
            (-0.0, 4.0),
        ] {
            assert!(mul(x.to_bits(), y.to_bits()).is_some(), "{x} * {y}");
            assert!(add(x.to_bits(), y.to_bits()).is_some(), "{x} + {y}");
            assert!(sub(x.to_bits(), y.to_bits()).is_some(), "{x} - {y}");
        }
        for (x, y) in [(0.0f32, -0.0f32), (-0.0, -0.0), (0.0, 1e-40), (-0.0, f32::MAX)] {
            assert!(mul(x.to_bits(), y.to_bits()).is_some(), "{x} * {y}");
        }
        for (x, y) in [(0.0f32, -0.0f32), (-0.0, -0.0), (0.0, 0.0)] {
            assert!(add(x.to_bits(), y.to_bits()).is_some(), "{x} + {y}");
        }
        // x - x is +0, to nearest.
        assert_eq!(sub(2.5f32.to_bits(), 2.5f32.to_bits()), Some(0));
        assert_eq!(add((-2.5f32).to_bits(), 2.5f32.to_bits()), Some(0));
        // Overflow, underflow and NaN go to the full routine.
        assert_eq!(mul(f32::MAX.to_bits(), 2.0f32.to_bits()), None);
        assert_eq!(mul(f32::MIN_POSITIVE.to_bits(), 0.5f32.to_bits()), None);
        assert_eq!(add(f32::MAX.to_bits(), f32::MAX.to_bits()), None);
        assert_eq!(add(f32::NAN.to_bits(), 1.0f32.to_bits()), None);
        assert_eq!(mul(0.0f32.to_bits(), f32::INFINITY.to_bits()), None);
    }
}
