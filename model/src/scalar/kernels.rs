//! The integer kernels behind the fixed-point type ([`super::Fix`]):
//! product, quotient and square root of the raw 32-bit words, each
//! rounded to nearest and total (no input panics), in the form that is
//! cheapest on the core the code is built for.
//!
//! What the cores have (Arm, *ARMv7-M* and *ARMv6-M Architecture
//! Reference Manuals*): the Cortex-M3/M4 (ARMv7-M) multiply 32 x 32 -> 64
//! in one instruction (`SMULL`, `UMULL`), divide 32 / 32 in one (`UDIV`,
//! 2-12 cycles) and count leading zeros in one (`CLZ`); the Cortex-M0/M0+
//! (ARMv6-M) have only `MULS` (32 x 32 -> low 32 bits): a 64-bit product
//! is four of them and the carries, and every division, `CLZ` included,
//! is software. Measured by `cargo xtask bench` ("Fixed-point
//! operations", `docs/bench.md`): the general 64-bit division of the
//! former quotient (`compiler_builtins`' `__aeabi_ldivmod`) cost 216
//! instructions on the Cortex-M3 and 543 on the Cortex-M0.
//!
//! * [`mul_wide`]: `SMULL` where there is one; on ARMv6-M four 16 x 16
//!   partial products (the `i64` product would call `__aeabi_lmul`, a
//!   64 x 64 multiply).
//! * [`div_round`]: with a hardware divide, Knuth's algorithm D for a
//!   64-bit numerator and a 32-bit divisor in two 16-bit digits (Hacker's
//!   Delight, 2nd ed., section 9-4, `divlu`): two `UDIV`s and their
//!   corrections. Without one, restoring binary division of the
//!   remainder in 32 bits, one quotient bit per step, only as many steps
//!   as the quotient can have bits.
//! * [`sqrt_round`]: the digit-by-digit (two bits per step) square root
//!   of `x 2^F`, in 32-bit words throughout, starting at the operand's
//!   first nonzero pair.
//!
//! Which kernel a target gets is decided by `target_has_atomic = "32"`:
//! ARMv6-M is the one Arm profile without the exclusive load/store
//! (`LDREX`/`STREX`) that 32-bit atomics need, and the same profile lacks
//! the divide and long multiply (stable Rust does not expose Arm target
//! features to `cfg`). Every kernel is compiled and tested on the host
//! whatever the target, against exact wide-integer arithmetic
//! (`tests` below).

// The kernels of the other core class are compiled (and tested) here too.
#![allow(dead_code)]

/// `a b` exactly.
#[inline(always)]
pub fn mul_wide(a: i32, b: i32) -> i64 {
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    {
        mul_wide_16(a, b)
    }
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    {
        a as i64 * b as i64
    }
}

/// `a b` from four 16 x 16 -> 32 products (ARMv6-M's `MULS`): `a = a_h
/// 2^16 + a_l` with `a_h` signed, `a_l` unsigned; each partial product
/// fits 32 bits (`|a_h b_l| < 2^31`).
#[inline(always)]
pub fn mul_wide_16(a: i32, b: i32) -> i64 {
    let (ah, al) = (a >> 16, a & 0xFFFF);
    let (bh, bl) = (b >> 16, b & 0xFFFF);
    let high = ah * bh;
    let cross = (ah * bl) as i64 + (al * bh) as i64;
    let low = (al as u32).wrapping_mul(bl as u32);
    ((high as i64) << 32) + (cross << 16) + low as i64
}

/// `round(p 2^-f)` of an exact product `|p| <= 2^62`, saturated to 32
/// bits (ties up). The result fits when the bits above it are all equal
/// to its sign, a test on the high word alone (`t >> (f + 31)` is `hi >>
/// (f - 1)`), so the common case is the product, the rounding add and
/// two shifts; a 64-bit clamp cost eight instructions more per product
/// on the Cortex-M3 (`cargo xtask profile`).
#[inline(always)]
pub fn round_shift(p: i64, f: u32) -> i32 {
    if f == 0 || f >= 32 {
        let half = if f > 0 { 1i64 << (f - 1) } else { 0 };
        return (p.saturating_add(half) >> f).clamp(i32::MIN as i64, i32::MAX as i64) as i32;
    }
    let t = p.wrapping_add(1i64 << (f - 1));
    let top = ((t >> 32) as i32) >> (f - 1);
    if top != top >> 31 {
        return saturated(t < 0);
    }
    (t >> f) as i32
}

/// The saturated word of a result too large for 32 bits (out of line: the
/// tick never takes it).
#[cold]
#[inline(never)]
pub fn saturated(negative: bool) -> i32 {
    if negative { i32::MIN } else { i32::MAX }
}

/// `a + b` saturated: the overflow test is the add's own flag, and the
/// saturated value out of line.
#[inline(always)]
pub fn add_saturating(a: i32, b: i32) -> i32 {
    match a.overflowing_add(b) {
        (s, false) => s,
        // Overflow: the true sum has the sign of both operands.
        (_, true) => saturated(a < 0),
    }
}

/// `a - b` saturated (see [`add_saturating`]).
#[inline(always)]
pub fn sub_saturating(a: i32, b: i32) -> i32 {
    match a.overflowing_sub(b) {
        (s, false) => s,
        // Overflow: the true difference has the sign of `a`.
        (_, true) => saturated(a < 0),
    }
}

/// `round(n 2^f / d)` of raw words (half away from zero), saturated to 32
/// bits; `n / 0` is the saturated value with the sign of `n` (zero for
/// `0 / 0`). Requires `f <= 30`.
#[inline]
pub fn div_round(n: i32, d: i32, f: u32) -> i32 {
    if d == 0 {
        return match n {
            0 => 0,
            n if n > 0 => i32::MAX,
            _ => i32::MIN,
        };
    }
    let negative = (n < 0) != (d < 0);
    let (u, v) = (n.unsigned_abs(), d.unsigned_abs());
    // floor(u 2^f / v) >= 2^31: saturated whatever the rounding.
    if (u >> (31 - f)) >= v {
        return if negative { i32::MIN } else { i32::MAX };
    }
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    let (q, r) = thumb1::div_shift_subtract(u, v, f);
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    let (q, r) = div_two_digits(u, v, f);
    // Half away from zero: up when 2 r >= v (r < v, so v - r cannot wrap).
    let q = q + u32::from(r >= v - r);
    if negative {
        // q <= 2^31: -2^31 is i32::MIN exactly.
        (q as i32).wrapping_neg()
    } else {
        q.min(i32::MAX as u32) as i32
    }
}

/// `(floor(u 2^f / v), remainder)` for `v > 0` and a quotient below
/// `2^31`, by algorithm D in two 16-bit digits with the hardware's 32-bit
/// divide (`divlu`, Hacker's Delight 9-4): the divisor is normalised
/// (its top bit set), each digit estimated from the divisor's top half
/// and corrected at most twice.
#[inline]
pub fn div_two_digits(u: u32, v: u32, f: u32) -> (u32, u32) {
    const B: u32 = 1 << 16;
    let s = v.leading_zeros();
    let v = v << s;
    // u 2^(f+s) < v 2^31 2^s <= 2^63: fits (the quotient is below 2^31).
    let n = (u as u64) << (f + s);
    let (un32, un10) = ((n >> 32) as u32, n as u32);
    let (vn1, vn0) = (v >> 16, v & 0xFFFF);
    // vn1 >= 2^15 (normalised): never zero.
    let Some(divisor) = core::num::NonZeroU32::new(vn1) else {
        return (0, 0);
    };
    let (un1, un0) = (un10 >> 16, un10 & 0xFFFF);
    let mut q1 = un32 / divisor;
    let mut rhat = un32 - q1 * vn1;
    while q1 >= B || q1 * vn0 > (rhat << 16) + un1 {
        q1 -= 1;
        rhat += vn1;
        if rhat >= B {
            break;
        }
    }
    let un21 = (un32 << 16).wrapping_add(un1).wrapping_sub(q1.wrapping_mul(v));
    let mut q0 = un21 / divisor;
    let mut rhat = un21 - q0 * vn1;
    while q0 >= B || q0 * vn0 > (rhat << 16) + un0 {
        q0 -= 1;
        rhat += vn1;
        if rhat >= B {
            break;
        }
    }
    let r = (un21 << 16).wrapping_add(un0).wrapping_sub(q0.wrapping_mul(v)) >> s;
    ((q1 << 16) | q0, r)
}

/// `(floor(u 2^f / v), remainder)` for `v > 0` and a quotient below
/// `2^31`, by restoring binary division: the partial remainder stays
/// below `v < 2^31`, so every step is 32-bit. A dividend below the
/// divisor (the common case: quotients of order one) has no integer bits
/// and takes `f` steps, any other `31`.
#[inline]
pub fn div_shift_subtract(u: u32, v: u32, f: u32) -> (u32, u32) {
    let (mut r, mut bits, steps) = if u < v {
        (u, 0u32, f)
    } else {
        // The first partial remainder, u 2^f / 2^31 < v; the bits of u
        // below it follow, then f zeros.
        (u >> (31 - f), u << (f + 1), 31)
    };
    let mut q = 0u32;
    for _ in 0..steps {
        r = (r << 1) | (bits >> 31);
        bits <<= 1;
        q <<= 1;
        if r >= v {
            r -= v;
            q |= 1;
        }
    }
    (q, r)
}

/// `round(sqrt(n))`, the square root of a 64-bit integer rounded to
/// nearest (at most `2^32`). The root of a raw word `x` in the format with
/// `f` fraction bits is that of `n = x 2^f`; the root of a sum of raw
/// products (`a b + c d`, units `2^-2f`) that of the sum itself, which
/// may exceed the 32-bit format while its root does not.
#[inline]
pub fn isqrt_round(n: u64) -> u64 {
    if n == 0 {
        return 0;
    }
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    {
        thumb1::isqrt_digits(n)
    }
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    {
        isqrt_newton(n)
    }
}

/// `isqrt(2^37 / (2 i + 1))` for `i` in 16..64: `2^15 / sqrt(mu)` at the
/// middle of the 48 intervals `[i/64, (i+1)/64)` that a normalised
/// mantissa `mu` in `[1/4, 1)` falls in, the seed of [`isqrt_newton`]
/// (relative error below `2^-6`).
const RSQRT_SEED: [u16; 48] = {
    let mut t = [0u16; 48];
    let mut i = 0;
    while i < 48 {
        let n = (1u64 << 37) / (2 * (i as u64 + 16) + 1);
        // Integer square root by bisection (compile time only).
        let (mut lo, mut hi) = (0u64, 1u64 << 19);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if mid * mid <= n {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        t[i] = lo as u16;
        i += 1;
    }
    t
};

/// [`isqrt_round`] by Newton's iteration for the reciprocal square root in
/// 32-bit fixed point ([`rsqrt_mantissa`]), `sqrt(mu) = mu y`, then the
/// root corrected to the exact floor by its square and rounded.
#[inline]
pub fn isqrt_newton(n: u64) -> u64 {
    if n == 0 {
        return 0;
    }
    let (m, y, shift) = rsqrt_mantissa(n);
    exact_root(n, m, y, shift)
}

/// `n > 0` normalised by an even shift to a mantissa `mu = m 2^-32` in
/// `[1/4, 1)` (`n 2^shift = m 2^32 + low`), and `y = 1 / sqrt(mu)` in
/// `(1, 2]` as Q2.30, by Newton's iteration `y <- y (3 - mu y^2) / 2`
/// (products by `UMULL`, no division) from a 48-entry seed: three
/// iterations (`2^-6` -> `2^-11` -> `2^-22` -> `2^-30`, the words'
/// resolution).
#[inline(always)]
fn rsqrt_mantissa(n: u64) -> (u32, u32, u32) {
    let shift = n.leading_zeros() & !1;
    let m = ((n << shift) >> 32) as u32;
    let seed = RSQRT_SEED
        .get(((m >> 26) as usize).wrapping_sub(16))
        .copied()
        .unwrap_or(1 << 15);
    let mut y = (seed as u32) << 15;
    for _ in 0..3 {
        // mu y and mu y^2 in Q2.30 (about one), then y (3 - mu y^2) / 2.
        let my = ((m as u64 * y as u64) >> 32) as u32;
        let myy = ((my as u64 * y as u64) >> 30) as u32;
        y = ((y as u64 * (0xC000_0000u32.wrapping_sub(myy)) as u64) >> 31) as u32;
    }
    (m, y, shift)
}

/// `round(sqrt(n))` from [`rsqrt_mantissa`]'s `sqrt(n 2^shift) = sqrt(mu)
/// 2^32 = mu y 2^32` (within a few units; the mantissa's dropped low word
/// adds less than one), corrected to the exact floor by its square.
#[inline(always)]
fn exact_root(n: u64, m: u32, y: u32, shift: u32) -> u64 {
    let mut root = ((m as u64 * y as u64) >> 30).min(u32::MAX as u64) >> (shift / 2);
    while root * root > n {
        root -= 1;
    }
    let mut rem = n - root * root;
    while rem > 2 * root {
        rem -= 2 * root + 1;
        root += 1;
    }
    // (root + 1/2)^2 = root^2 + root + 1/4: up when the remainder
    // exceeds root.
    root + u64::from(rem > root)
}

/// `(round(sqrt(n)), 2^(2f) / sqrt(n))`: the root of a raw sum of
/// products (units `2^-2f`) in the format with `f` fraction bits, and its
/// reciprocal in the same format, or zero where the reciprocal does not
/// fit 32 bits (also for `n = 0`; the caller divides instead). The
/// reciprocal is Newton's `y` shifted, not a division: within `2^-29`
/// relative (`y`'s `2^-30` and the mantissa's dropped low word) and half
/// a unit of rounding, not rounded exactly: a unit where it is below
/// `2^28` units (256 in Q12.20). Where the core has no long multiply
/// (ARMv6-M), the root is taken digit by digit and the reciprocal is that
/// of the rounded root, divided.
#[inline]
pub fn sqrt_and_recip(n: u64, f: u32) -> (i32, i32) {
    if n == 0 {
        return (0, 0);
    }
    #[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
    {
        let root = thumb1::isqrt_digits(n).min(i32::MAX as u64) as i32;
        let recip = if f <= 30 { div_round(1 << f, root, f) } else { i32::MAX };
        (root, if recip == i32::MAX { 0 } else { recip })
    }
    #[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
    {
        sqrt_and_recip_newton(n, f)
    }
}

/// [`sqrt_and_recip`] from one [`rsqrt_mantissa`]: `2^(2f) / sqrt(n) = y
/// 2^(2f - 62 + shift/2)` (Q2.30 `y`).
#[inline]
pub fn sqrt_and_recip_newton(n: u64, f: u32) -> (i32, i32) {
    if n == 0 {
        return (0, 0);
    }
    let (m, y, shift) = rsqrt_mantissa(n);
    let root = exact_root(n, m, y, shift).min(i32::MAX as u64) as i32;
    let e = (2 * f + shift / 2) as i32 - 62;
    let recip = if e >= 0 {
        if e >= 32 || (y as u64) << e > i32::MAX as u64 {
            0
        } else {
            (y << e) as i32
        }
    } else if e <= -33 {
        0
    } else {
        let k = (-e) as u32;
        let r = ((y as u64) + (1u64 << (k - 1))) >> k;
        if r > i32::MAX as u64 { 0 } else { r as i32 }
    };
    (root, recip)
}

/// [`isqrt_round`] digit by digit (two bits of `n` per step): the root and
/// the remainder in 32-bit words for `n < 2^58` (root below `2^29`,
/// remainder below `2^30`), starting at `n`'s first nonzero pair; larger
/// `n` (roots beyond 512 in Q12.20) in 64-bit words.
#[inline]
pub fn isqrt_digits(n: u64) -> u64 {
    if n >= 1 << 58 {
        let (mut root, mut rem) = (0u64, 0u64);
        for k in (0..32).rev() {
            rem = (rem << 2) | ((n >> (2 * k)) & 3);
            let trial = (root << 2) | 1;
            root <<= 1;
            if rem >= trial {
                rem -= trial;
                root |= 1;
            }
        }
        return root + u64::from(rem > root);
    }
    let (hi, lo) = ((n >> 32) as u32, n as u32);
    let (mut root, mut rem) = (0u32, 0u32);
    let mut step = |pair: u32| {
        rem = (rem << 2) | pair;
        let trial = (root << 2) | 1;
        root <<= 1;
        if rem >= trial {
            rem -= trial;
            root |= 1;
        }
    };
    // The pairs from the first nonzero one (n > 0).
    let (first, pairs) = if hi != 0 {
        (hi, 16 - hi.leading_zeros() / 2)
    } else {
        (lo, 16 - lo.leading_zeros() / 2)
    };
    for k in (0..pairs).rev() {
        step((first >> (2 * k)) & 3);
    }
    if hi != 0 {
        for k in (0..16).rev() {
            step((lo >> (2 * k)) & 3);
        }
    }
    (root + u32::from(rem > root)) as u64
}

/// The restoring division and the digit-by-digit root in Thumb-1
/// assembly, for ARMv6-M: one quotient bit in four to six instructions
/// (`adds`/`adcs` shift the dividend's next bit into the remainder, `cmp`
/// sets the carry to the bit), one root digit in ten to twelve. The Rust
/// loops ([`div_shift_subtract`], [`isqrt_digits`], which they replace
/// step for step and which the host tests check) compiled to thirteen and
/// seventeen on the Cortex-M0 (`cargo xtask profile`). The start-up
/// self-check of the Cortex-M0 images compares both with the Rust loops
/// on the emulated core.
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
pub mod thumb1 {
    /// [`super::div_shift_subtract`] in assembly.
    #[inline(always)]
    pub fn div_shift_subtract(u: u32, v: u32, f: u32) -> (u32, u32) {
        let (mut r, mut n, steps) = if u < v {
            (u, 0u32, f)
        } else {
            (u >> (31 - f), u << (f + 1), 31)
        };
        if steps == 0 {
            return (n, r);
        }
        // SAFETY: registers only; `steps > 0`, so the loop ends.
        unsafe {
            core::arch::asm!(
                "2:",
                "adds {n}, {n}, {n}",
                "adcs {r}, {r}",
                "cmp {r}, {v}",
                "bcc 3f",
                "subs {r}, {r}, {v}",
                "adds {n}, #1",
                "3:",
                "subs {k}, #1",
                "bne 2b",
                n = inout(reg) n,
                r = inout(reg) r,
                v = in(reg) v,
                k = inout(reg) steps => _,
                options(pure, nomem, nostack),
            );
        }
        (n, r)
    }

    /// `count` digits of the root from the pairs of `w`, its first at the
    /// top (bits 31..30).
    #[inline(always)]
    fn digits(root: &mut u32, rem: &mut u32, w: u32, count: u32) {
        if count == 0 {
            return;
        }
        // SAFETY: registers only; `count > 0`, so the loop ends.
        unsafe {
            core::arch::asm!(
                "2:",
                "adds {w}, {w}, {w}",
                "adcs {rem}, {rem}",
                "adds {w}, {w}, {w}",
                "adcs {rem}, {rem}",
                "lsls {t}, {root}, #2",
                "adds {t}, #1",
                "lsls {root}, {root}, #1",
                "cmp {rem}, {t}",
                "bcc 3f",
                "subs {rem}, {rem}, {t}",
                "adds {root}, #1",
                "3:",
                "subs {k}, #1",
                "bne 2b",
                w = inout(reg) w => _,
                rem = inout(reg) *rem,
                root = inout(reg) *root,
                t = out(reg) _,
                k = inout(reg) count => _,
                options(pure, nomem, nostack),
            );
        }
    }

    /// [`super::isqrt_digits`] with its 32-bit steps in assembly.
    #[inline]
    pub fn isqrt_digits(n: u64) -> u64 {
        if n >= 1 << 58 || n == 0 {
            return super::isqrt_digits(n);
        }
        let (hi, lo) = ((n >> 32) as u32, n as u32);
        let (mut root, mut rem) = (0u32, 0u32);
        if hi != 0 {
            let pairs = 16 - hi.leading_zeros() / 2;
            digits(&mut root, &mut rem, hi << (32 - 2 * pairs), pairs);
            digits(&mut root, &mut rem, lo, 16);
        } else {
            let pairs = 16 - lo.leading_zeros() / 2;
            digits(&mut root, &mut rem, lo << (32 - 2 * pairs), pairs);
        }
        (root + u32::from(rem > root)) as u64
    }
}

/// A kernel's answer that differs from the plain wide-integer arithmetic
/// it replaces: which kernel, its operands, what it returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KernelMismatch {
    /// `"mul"`, `"div"` or `"sqrt"`.
    pub kernel: &'static str,
    /// The operands (the root's `n` split into words for `sqrt`).
    pub operands: (i64, i64),
    /// What the kernel returned.
    pub got: i64,
}

/// The kernels of this core against plain 64/128-bit integer arithmetic
/// (`compiler_builtins`' routines, independent of them) on `cases` operand
/// pairs of every magnitude, in Q12.20: what a firmware image runs at
/// start-up on its core (the host tests cover the host's build).
pub fn self_check(cases: u32) -> Result<(), KernelMismatch> {
    const F: u32 = 20;
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let w = (s >> 32) as u32 >> ((s & 31) as u32);
        if s & (1 << 40) != 0 {
            (w as i32).wrapping_neg()
        } else {
            w as i32
        }
    };
    for _ in 0..cases {
        let (a, b) = (next(), next());
        let p = a as i64 * b as i64;
        let got = round_shift(mul_wide(a, b), F);
        let want = ((p as i128 + (1 << (F - 1))) >> F).clamp(i32::MIN as i128, i32::MAX as i128) as i32;
        if got != want {
            return Err(KernelMismatch {
                kernel: "mul",
                operands: (a as i64, b as i64),
                got: got as i64,
            });
        }
        let got = div_round(a, b, F);
        let want = if b == 0 {
            if a == 0 {
                0
            } else if a > 0 {
                i32::MAX
            } else {
                i32::MIN
            }
        } else {
            let n = (a as i64) << F;
            let (q, r) = (n / b as i64, n % b as i64);
            let q = if 2 * r.unsigned_abs() >= (b as i64).unsigned_abs() {
                if (n < 0) == (b < 0) { q + 1 } else { q - 1 }
            } else {
                q
            };
            q.clamp(i32::MIN as i64, i32::MAX as i64) as i32
        };
        if got != want {
            return Err(KernelMismatch {
                kernel: "div",
                operands: (a as i64, b as i64),
                got: got as i64,
            });
        }
        let n = ((a.unsigned_abs() as u64) << 32 | b.unsigned_abs() as u64) >> (b as u32 & 63);
        let r = isqrt_round(n) as u128;
        let n4 = 4 * n as u128;
        if n > 0 && !((2 * r).saturating_sub(1).pow(2) <= n4 && n4 < (2 * r + 1).pow(2)) {
            return Err(KernelMismatch {
                kernel: "sqrt",
                operands: ((n >> 32) as i64, (n & 0xFFFF_FFFF) as i64),
                got: r as i64,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic stream of words covering every magnitude.
    fn words(count: usize) -> impl Iterator<Item = i32> {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        (0..count).map(move |_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // A random magnitude: shift a random word right by 0..31.
            let w = (s >> 32) as u32 >> ((s & 31) as u32);
            if s & (1 << 40) != 0 {
                (w as i32).wrapping_neg()
            } else {
                w as i32
            }
        })
    }

    const EDGES: [i32; 11] = [
        0,
        1,
        -1,
        2,
        3,
        1 << 20,
        -(1 << 20),
        i32::MAX,
        i32::MIN,
        i32::MAX - 1,
        i32::MIN + 1,
    ];

    /// round(n 2^f / d), half away from zero, saturated: in 128 bits.
    fn div_reference(n: i32, d: i32, f: u32) -> i32 {
        if d == 0 {
            return if n == 0 {
                0
            } else if n > 0 {
                i32::MAX
            } else {
                i32::MIN
            };
        }
        let num = (n as i128) << f;
        let (q, r) = (num / d as i128, num % d as i128);
        let q = if 2 * r.abs() >= (d as i128).abs() {
            if (num < 0) == (d < 0) { q + 1 } else { q - 1 }
        } else {
            q
        };
        q.clamp(i32::MIN as i128, i32::MAX as i128) as i32
    }

    #[test]
    fn rounded_products_and_sums_saturate() {
        let all: Vec<i32> = words(20_000).chain(EDGES).collect();
        for f in [0, 1, 16, 20, 24, 30, 31] {
            for (a, b) in all.iter().zip(all.iter().skip(3)) {
                let p = *a as i64 * *b as i64;
                let exact = ((p as i128 + if f > 0 { 1i128 << (f - 1) } else { 0 }) >> f)
                    .clamp(i32::MIN as i128, i32::MAX as i128) as i32;
                assert_eq!(round_shift(p, f), exact, "{a} * {b} >> {f}");
            }
        }
        for &a in all.iter().chain(&EDGES) {
            for &b in &EDGES {
                assert_eq!(add_saturating(a, b), a.saturating_add(b), "{a} + {b}");
                assert_eq!(sub_saturating(a, b), a.saturating_sub(b), "{a} - {b}");
                assert_eq!(add_saturating(b, a), b.saturating_add(a), "{b} + {a}");
                assert_eq!(sub_saturating(b, a), b.saturating_sub(a), "{b} - {a}");
            }
        }
    }

    #[test]
    fn the_start_up_self_check_passes_on_the_host() {
        assert_eq!(self_check(200_000), Ok(()));
    }

    #[test]
    fn products_are_exact() {
        let all: Vec<i32> = words(20_000).chain(EDGES).collect();
        for (a, b) in all.iter().zip(all.iter().rev()) {
            assert_eq!(mul_wide_16(*a, *b), *a as i64 * *b as i64, "{a} * {b}");
            assert_eq!(mul_wide(*a, *b), *a as i64 * *b as i64, "{a} * {b}");
        }
        for &a in &EDGES {
            for &b in &EDGES {
                assert_eq!(mul_wide_16(a, b), a as i64 * b as i64, "{a} * {b}");
            }
        }
    }

    #[test]
    fn quotients_are_rounded_to_nearest_and_saturate() {
        let all: Vec<i32> = words(40_000).chain(EDGES).collect();
        for f in [0, 1, 16, 20, 24, 30] {
            let check = |n: i32, d: i32| {
                assert_eq!(div_round(n, d, f), div_reference(n, d, f), "{n} / {d}, f = {f}");
                if d != 0 {
                    let (u, v) = (n.unsigned_abs(), d.unsigned_abs());
                    if (u >> (31 - f)) < v {
                        let exact = ((u as u64) << f) / v as u64;
                        let rem = ((u as u64) << f) % v as u64;
                        assert_eq!(
                            div_two_digits(u, v, f),
                            (exact as u32, rem as u32),
                            "{u} / {v}, f = {f}"
                        );
                        assert_eq!(
                            div_shift_subtract(u, v, f),
                            (exact as u32, rem as u32),
                            "{u} / {v}, f = {f}"
                        );
                    }
                }
            };
            for (n, d) in all.iter().zip(all.iter().skip(7)) {
                check(*n, *d);
            }
            for &n in &EDGES {
                for &d in &EDGES {
                    check(n, d);
                }
            }
        }
    }

    #[test]
    fn square_roots_are_rounded_to_nearest() {
        // round(sqrt(n)) = r <=> (r - 1/2)^2 <= n < (r + 1/2)^2, i.e.
        // 4n in [(2r - 1)^2, (2r + 1)^2).
        let check = |n: u64, r: u64, what: &str| {
            let (n4, r) = (4 * n as u128, r as u128);
            assert!(
                (2 * r).saturating_sub(1).pow(2) <= n4 && n4 < (2 * r + 1).pow(2),
                "{what}: sqrt({n}) -> {r}"
            );
        };
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut operands: Vec<u64> = (0..60_000)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                s >> (s & 63)
            })
            .collect();
        operands.extend([
            1,
            2,
            3,
            4,
            5,
            1 << 58,
            (1 << 58) - 1,
            u64::MAX,
            u64::MAX - 1,
            1 << 62,
            1 << 63,
        ]);
        operands.extend((0..64).map(|k| 1u64 << k).chain((1..64).map(|k| (1u64 << k) - 1)));
        for n in operands {
            if n == 0 {
                continue;
            }
            check(n, isqrt_newton(n), "newton");
            check(n, isqrt_digits(n), "digits");
            check(n, isqrt_round(n), "chosen");
        }
        assert_eq!((isqrt_newton(0), isqrt_digits(0), isqrt_round(0)), (0, 0, 0));
        // The reciprocal beside the root: within one unit and 2^-28 of
        // 2^(2f) / sqrt(n) (or saturated), for the formats' f.
        let mut s = 0x1234_5678_9ABC_DEF1u64;
        for _ in 0..60_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let n = s >> (s & 63);
            for f in [16u32, 20, 24] {
                for (root, recip) in [sqrt_and_recip_newton(n, f), sqrt_and_recip(n, f)] {
                    if n == 0 {
                        assert_eq!((root, recip), (0, 0));
                        continue;
                    }
                    let full = isqrt_newton(n);
                    assert_eq!(root as u64, full.min(i32::MAX as u64), "root of {n}");
                    let exact = (1u128 << (2 * f)) as f64 / (n as f64).sqrt();
                    if recip == 0 {
                        assert!(
                            exact >= i32::MAX as f64 - 4.0,
                            "recip of sqrt({n}), f = {f}: 0 vs {exact}"
                        );
                        continue;
                    }
                    assert!(
                        (recip as f64 - exact).abs() <= 1.0 + exact / (1u64 << 28) as f64,
                        "recip of sqrt({n}), f = {f}: {recip} vs {exact}"
                    );
                }
            }
        }
        // The seed table: 2^15 / sqrt(mu) at each interval's middle.
        for (i, t) in RSQRT_SEED.iter().enumerate() {
            let exact = 32768.0 / ((i as f64 + 16.5) / 64.0).sqrt();
            assert!((*t as f64 - exact).abs() <= 1.0, "seed {i}: {t} vs {exact}");
        }
    }
}
