//! The scalar types the core is generic over.
//!
//! * [`Real`]: what the fixed-step dynamics needs (ring operations, division,
//!   square root, comparisons). Implemented for `f32`, `f64` and the
//!   saturating fixed-point newtype [`Fix`].
//! * [`Float`]: adds the transcendental functions the fluid-property laws need
//!   (Walther's double exponential). Implemented for `f32` and `f64` only;
//!   fluid properties are evaluated in floating point at the sensor rate and
//!   handed to the fixed-point integrator as dimensionless coefficients.
//!
//! Cost notes (Cortex-M4F, measured by `cargo xtask bench`): `f32` square
//! roots use the FPU's `VSQRT.F32` through inline assembly (five
//! instructions); `libm::sqrtf` would be a software routine. `expf`,
//! `logf`, `log1pf`, `log10f` come from `libm` (60-80 instructions);
//! `10^x` from [`crate::mathf`] (~95), because `libm::exp10f` computes in
//! double precision (~1,230). `micromath`'s approximations are not used for
//! the fluid laws: Walther's double exponential amplifies their ~1e-4
//! relative error about tenfold (`mathf` tests).

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Arithmetic needed by the fixed-step integrator and the closed forms.
///
/// Every operation is total: no implementation panics on any input. For the
/// floating-point types non-finite values propagate and are caught by the
/// callers' checks; the fixed-point type saturates.
pub trait Real:
    Copy
    + Debug
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Additive identity.
    const ZERO: Self;
    /// Multiplicative identity.
    const ONE: Self;
    /// One half (a constant, so that fixed point never divides for it).
    const HALF: Self;
    /// Two.
    const TWO: Self;
    /// A short name for reports and errors, one per type: `"f32"`, `"f64"`,
    /// and `"Q<integer bits>.<fraction bits>"` for fixed point (`"Q12.20"`).
    const NAME: &'static str;
    /// The type saturates beyond a small range (fixed point): the few
    /// expressions whose value can exceed it on some designs take a
    /// scaled form instead (never in floating point, where the plain
    /// form is cheaper and exact enough).
    const SATURATES: bool = false;

    /// Conversion from a double (rounds; saturates for fixed point).
    fn from_f64(v: f64) -> Self;
    /// Conversion from a single (exact for the floats; rounds and
    /// saturates for fixed point).
    fn from_f32(v: f32) -> Self;
    /// Conversion to a double (exact for all implementations).
    fn to_f64(self) -> f64;
    /// Conversion to a single (exact for `f32`; rounds otherwise).
    fn to_f32(self) -> f32;
    /// Square root; returns zero for negative input (and NaN for NaN in
    /// floating point).
    fn sqrt(self) -> Self;
    /// `sqrt(a b + c d)` (zero where the sum is negative), for a sum that
    /// may exceed the range of a saturating type while its root does not:
    /// fixed point sums the exact products in 64 bits.
    #[inline]
    fn sqrt_sum_products(a: Self, b: Self, c: Self, d: Self) -> Self {
        (a * b + c * d).sqrt()
    }
    /// `(sqrt(a b + c d), 1 / sqrt(a b + c d))`: the root as
    /// [`Real::sqrt_sum_products`] and its reciprocal, or zero in place of
    /// a reciprocal the type cannot hold (a root below `1 / 2048` in
    /// Q12.20, or zero; the floats' is finite for any root: that of
    /// [`Real::tiny`] for zero), where the caller divides instead. Fixed
    /// point takes the reciprocal from the root's own Newton iteration
    /// where the core multiplies 32 x 32 -> 64 in one instruction (within
    /// `2^-29` relative, not rounded exactly), saving a division.
    #[inline]
    fn sqrt_recip_sum_products(a: Self, b: Self, c: Self, d: Self) -> (Self, Self) {
        let r = Self::sqrt_sum_products(a, b, c, d);
        (r, Self::ONE / r.max(Self::tiny()))
    }
    /// Absolute value.
    fn abs(self) -> Self;
    /// `false` for NaN and infinities; always `true` for fixed point.
    fn is_finite(self) -> bool;
    /// The smallest positive value that can be used as a divisor safely
    /// (the resolution for fixed point, `MIN_POSITIVE` for floats).
    fn tiny() -> Self;

    /// Larger of two values (the first one if they compare unordered).
    #[inline]
    fn max(self, other: Self) -> Self {
        if other > self { other } else { self }
    }
    /// Smaller of two values (the first one if they compare unordered).
    #[inline]
    fn min(self, other: Self) -> Self {
        if other < self { other } else { self }
    }
    /// `self` limited to `[lo, hi]`.
    #[inline]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        self.max(lo).min(hi)
    }
    /// Square.
    #[inline]
    fn sq(self) -> Self {
        self * self
    }
    /// `self + a b`, with what rounding loses kept in `carry` and added
    /// back by the next call: a state advanced by many increments below
    /// its resolution still moves by their sum (compensated summation;
    /// Kahan's for floating point, the product's low bits for fixed point).
    /// `carry` starts at zero and belongs to one accumulated quantity.
    #[inline]
    fn mul_add_compensated(self, a: Self, b: Self, carry: &mut Self) -> Self {
        let d = a * b + *carry;
        let s = self + d;
        *carry = d - (s - self);
        s
    }
    /// `self + a (b_0 c_0 + b_1 c_1 + ...)` (pairs of `b`, `c`),
    /// compensated as [`Real::mul_add_compensated`]: the products of the
    /// sum round for floating point (what `mul_add_compensated` of the
    /// rounded sum gives), not at all for fixed point, where a sum of
    /// products each below the resolution (a plunger creeping over short
    /// steps) would otherwise round to zero step after step.
    #[inline]
    fn dot_add_compensated(self, a: Self, b: &[Self], c: &[Self], carry: &mut Self) -> Self {
        let mut sum = Self::ZERO;
        for (bj, cj) in b.iter().zip(c) {
            sum += *bj * *cj;
        }
        self.mul_add_compensated(a, sum, carry)
    }
}

/// Transcendental functions for the fluid-property laws (floating point only).
pub trait Float: Real {
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// Base-10 logarithm.
    fn log10(self) -> Self;
    /// `ln(1 + self)`, accurate for small `self`.
    fn ln_1p(self) -> Self;
    /// `e^self`.
    fn exp(self) -> Self;
    /// `10^self`.
    fn exp10(self) -> Self;
    /// `self^p`.
    fn powf(self, p: Self) -> Self;
    /// Not-a-number (to report "no value" in flagged outputs).
    fn nan() -> Self;
    /// `true` for NaN.
    fn is_nan(self) -> bool;
    /// The magnitude of `self` with the sign of `sign` (IEEE 754
    /// `copySign`: a bit operation, also for zeros and NaN).
    fn copysign(self, sign: Self) -> Self;
    /// Conversion to another scalar type without a detour through `f64`
    /// where the source is `f32` (no soft-double code on a Cortex-M4F).
    fn to_real<T: Real>(self) -> T;
    /// Conversion from another scalar type, through `f32` when `Self` is
    /// `f32` (no soft-double code on a Cortex-M4F).
    fn from_real<T: Real>(v: T) -> Self;
}

/// Hardware square root on the Cortex-M4F FPU.
///
/// Stable Rust rejects the `sreg` register class on `thumbv7em-none-eabihf`
/// (it needs the unstable `vfp2` target feature), so the operand travels
/// through a core register and `s15` is saved and restored around the
/// `VSQRT.F32`: five instructions, against ~40 for `libm::sqrtf`.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[inline(always)]
fn sqrt_f32(x: f32) -> f32 {
    let r: u32;
    // SAFETY: only s15 and the named core registers are touched, and s15 is
    // restored before the block ends.
    unsafe {
        core::arch::asm!(
            "vmov {t}, s15",
            "vmov s15, {x}",
            "vsqrt.f32 s15, s15",
            "vmov {r}, s15",
            "vmov s15, {t}",
            x = in(reg) x.to_bits(),
            r = lateout(reg) r,
            t = out(reg) _,
            options(pure, nomem, nostack, preserves_flags),
        );
    }
    f32::from_bits(r)
}

#[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
#[inline(always)]
fn sqrt_f32(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// `Real` and `Float` for a binary floating-point type, from its `libm`
/// routines: the two impls differ only in the routine names, so one macro
/// writes both and they cannot drift apart.
macro_rules! float_impls {
    (
        $t:ident, $name:literal, to_real: $to_real:ident, from_real: $from_real:ident,
        sqrt: $sqrt:path, fabs: $fabs:path,
        ln: $ln:path, log10: $log10:path, ln_1p: $ln_1p:path, exp: $exp:path,
        exp10: $exp10:path, powf: $powf:path, copysign: $copysign:path
    ) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const HALF: Self = 0.5;
            const TWO: Self = 2.0;
            const NAME: &'static str = $name;
            #[inline]
            #[allow(clippy::unnecessary_cast)]
            fn from_f64(v: f64) -> Self {
                v as $t
            }
            #[inline]
            #[allow(clippy::unnecessary_cast)]
            fn from_f32(v: f32) -> Self {
                v as $t
            }
            #[inline]
            #[allow(clippy::unnecessary_cast)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            #[allow(clippy::unnecessary_cast)]
            fn to_f32(self) -> f32 {
                self as f32
            }
            #[inline]
            fn sqrt(self) -> Self {
                if self > 0.0 {
                    $sqrt(self)
                } else if self.is_nan() {
                    self
                } else {
                    0.0
                }
            }
            #[inline]
            fn abs(self) -> Self {
                $fabs(self)
            }
            #[inline]
            fn is_finite(self) -> bool {
                $t::is_finite(self)
            }
            #[inline]
            fn tiny() -> Self {
                $t::MIN_POSITIVE
            }
        }

        impl Float for $t {
            #[inline]
            fn ln(self) -> Self {
                $ln(self)
            }
            #[inline]
            fn log10(self) -> Self {
                $log10(self)
            }
            #[inline]
            fn ln_1p(self) -> Self {
                $ln_1p(self)
            }
            #[inline]
            fn exp(self) -> Self {
                $exp(self)
            }
            #[inline]
            fn exp10(self) -> Self {
                $exp10(self)
            }
            #[inline]
            fn powf(self, p: Self) -> Self {
                $powf(self, p)
            }
            #[inline]
            fn nan() -> Self {
                $t::NAN
            }
            #[inline]
            fn is_nan(self) -> bool {
                $t::is_nan(self)
            }
            #[inline]
            fn copysign(self, sign: Self) -> Self {
                $copysign(self, sign)
            }
            #[inline]
            fn to_real<T: Real>(self) -> T {
                T::$to_real(self)
            }
            #[inline]
            fn from_real<T: Real>(v: T) -> Self {
                v.$from_real()
            }
        }
    };
}

// `f32` transcendentals from `libm` (native single precision), except
// `10^x` from [`crate::mathf`]: `libm::exp10f` computes in double
// precision, ~1,230 instructions on a Cortex-M4F against ~95.
float_impls!(
    f32, "f32", to_real: from_f32, from_real: to_f32, sqrt: sqrt_f32, fabs: libm::fabsf,
    ln: libm::logf, log10: libm::log10f, ln_1p: libm::log1pf, exp: libm::expf,
    exp10: crate::mathf::exp10, powf: libm::powf, copysign: libm::copysignf
);
float_impls!(
    f64, "f64", to_real: from_f64, from_real: to_f64, sqrt: libm::sqrt, fabs: libm::fabs,
    ln: libm::log, log10: libm::log10, ln_1p: libm::log1p, exp: libm::exp,
    exp10: libm::exp10, powf: libm::pow, copysign: libm::copysign
);

pub use fixed_point::{Fix, Q8_24, Q12_20, Q16_16};

mod kernels;
pub use kernels::{KernelMismatch, self_check as check_kernels};

/// The fixed-point format the project ships: Q12.20 (range +-2048,
/// resolution 9.5e-7). With the FSI model's row-scaled stage equations
/// every intermediate stays within +-2048 on the paper preset and on 50
/// random designs, and the resolution keeps slow designs (time constants
/// of seconds) moving to within ~1e-6 of the stroke; Q16.16 stalls up to
/// 14 % of a step short on those, Q8.24 overflows on stiff designs
/// (`docs/dynamics.md`, `cargo run --release -p host-tests --example accuracy_survey`).
pub type Fixed = Q12_20;

mod fixed_point {
    use super::kernels;
    use super::*;
    use fixed::FixedI32;
    use fixed::types::extra::LeEqU32;

    /// Saturating, panic-free fixed-point scalar on 32 bits with `F`
    /// fractional bits (`fixed::FixedI32<F>` underneath).
    ///
    /// Every operation saturates at the type's range instead of panicking or
    /// wrapping: division by zero gives the saturated value with the sign of
    /// the dividend (zero for `0/0`), the square root of a negative is zero.
    #[repr(transparent)]
    pub struct Fix<F: LeEqU32>(pub FixedI32<F>);

    // Manual impls: derives would demand the same traits of the marker `F`.
    impl<F: LeEqU32> Clone for Fix<F> {
        #[inline]
        fn clone(&self) -> Self {
            *self
        }
    }
    impl<F: LeEqU32> Copy for Fix<F> {}
    impl<F: LeEqU32> Default for Fix<F> {
        #[inline]
        fn default() -> Self {
            Fix(FixedI32::<F>::ZERO)
        }
    }
    impl<F: LeEqU32> PartialEq for Fix<F> {
        #[inline]
        fn eq(&self, other: &Self) -> bool {
            self.0 == other.0
        }
    }
    impl<F: LeEqU32> PartialOrd for Fix<F> {
        #[inline]
        fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
            Some(self.0.cmp(&other.0))
        }
    }

    /// 16 integer bits, 16 fractional bits: range +-32768, resolution 1.5e-5.
    pub type Q16_16 = Fix<fixed::types::extra::U16>;
    /// 12 integer bits, 20 fractional bits: range +-2048, resolution 9.5e-7.
    pub type Q12_20 = Fix<fixed::types::extra::U20>;
    /// 8 integer bits, 24 fractional bits: range +-128, resolution 6.0e-8.
    pub type Q8_24 = Fix<fixed::types::extra::U24>;

    impl<F: LeEqU32> Debug for Fix<F> {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            Debug::fmt(&self.0, f)
        }
    }

    impl<F: LeEqU32> Add for Fix<F> {
        type Output = Self;
        #[inline]
        fn add(self, rhs: Self) -> Self {
            Fix(FixedI32::<F>::from_bits(kernels::add_saturating(
                self.0.to_bits(),
                rhs.0.to_bits(),
            )))
        }
    }
    impl<F: LeEqU32> Sub for Fix<F> {
        type Output = Self;
        #[inline]
        fn sub(self, rhs: Self) -> Self {
            Fix(FixedI32::<F>::from_bits(kernels::sub_saturating(
                self.0.to_bits(),
                rhs.0.to_bits(),
            )))
        }
    }
    /// A 64-bit intermediate saturated to the 32-bit format.
    #[inline]
    fn saturate<F: LeEqU32>(v: i64) -> Fix<F> {
        Fix(FixedI32::<F>::from_bits(
            v.clamp(i32::MIN as i64, i32::MAX as i64) as i32
        ))
    }

    /// Rounded to nearest (ties up), saturating. `fixed`'s own product
    /// rounds down: a bias of half an LSB per product, which a fixed-step
    /// integrator accumulates into a drift of its equilibrium (measured:
    /// 0.07 % of the stroke on the paper preset).
    impl<F: LeEqU32> Mul for Fix<F> {
        type Output = Self;
        #[inline]
        fn mul(self, rhs: Self) -> Self {
            let p = kernels::mul_wide(self.0.to_bits(), rhs.0.to_bits());
            Fix(FixedI32::<F>::from_bits(kernels::round_shift(p, F::U32)))
        }
    }
    /// Rounded to nearest, saturating; `x / 0` is the saturated value with
    /// the sign of `x` (zero for `0 / 0`). `fixed`'s own quotient truncates
    /// towards zero (a bias of up to one LSB).
    impl<F: LeEqU32> Div for Fix<F> {
        type Output = Self;
        #[inline]
        fn div(self, rhs: Self) -> Self {
            if F::U32 <= 30 {
                return Fix(FixedI32::<F>::from_bits(kernels::div_round(
                    self.0.to_bits(),
                    rhs.0.to_bits(),
                    F::U32,
                )));
            }
            let (n, d) = ((self.0.to_bits() as i64) << F::U32, rhs.0.to_bits() as i64);
            if d == 0 {
                return match n {
                    0 => Fix(FixedI32::<F>::ZERO),
                    n if n > 0 => Fix(FixedI32::<F>::MAX),
                    _ => Fix(FixedI32::<F>::MIN),
                };
            }
            // |n| < 2^63 and d != 0: neither overflows (i64::MIN / -1 cannot occur).
            let (q, r) = (n / d, n % d);
            let up = 2 * r.unsigned_abs() >= d.unsigned_abs();
            let q = if up {
                if (n < 0) == (d < 0) { q + 1 } else { q - 1 }
            } else {
                q
            };
            saturate(q)
        }
    }
    impl<F: LeEqU32> Neg for Fix<F> {
        type Output = Self;
        #[inline]
        fn neg(self) -> Self {
            Fix(self.0.saturating_neg())
        }
    }
    impl<F: LeEqU32> AddAssign for Fix<F> {
        #[inline]
        fn add_assign(&mut self, rhs: Self) {
            *self = *self + rhs;
        }
    }
    impl<F: LeEqU32> SubAssign for Fix<F> {
        #[inline]
        fn sub_assign(&mut self, rhs: Self) {
            *self = *self - rhs;
        }
    }
    impl<F: LeEqU32> MulAssign for Fix<F> {
        #[inline]
        fn mul_assign(&mut self, rhs: Self) {
            *self = *self * rhs;
        }
    }

    /// `Q<integer bits>.<fraction bits>` of the 32-bit format with `f`
    /// fraction bits, at index `f` (what [`Fix`]'s [`Real::NAME`] reads).
    pub(super) const FIXED_NAMES: [&str; 33] = [
        "Q32.0", "Q31.1", "Q30.2", "Q29.3", "Q28.4", "Q27.5", "Q26.6", "Q25.7", "Q24.8", "Q23.9", "Q22.10", "Q21.11",
        "Q20.12", "Q19.13", "Q18.14", "Q17.15", "Q16.16", "Q15.17", "Q14.18", "Q13.19", "Q12.20", "Q11.21", "Q10.22",
        "Q9.23", "Q8.24", "Q7.25", "Q6.26", "Q5.27", "Q4.28", "Q3.29", "Q2.30", "Q1.31", "Q0.32",
    ];

    impl<F: LeEqU32> Real for Fix<F> {
        const ZERO: Self = Fix(FixedI32::<F>::ZERO);
        const ONE: Self = {
            assert!(F::U32 <= 30, "fixed-point formats need at least two integer bits");
            Fix(FixedI32::<F>::from_bits(1i32 << F::U32))
        };
        const HALF: Self = {
            assert!(
                F::U32 >= 1 && F::U32 <= 29,
                "fixed-point formats need a fractional bit and three integer bits"
            );
            Fix(FixedI32::<F>::from_bits(1i32 << (F::U32 - 1)))
        };
        const TWO: Self = {
            assert!(F::U32 <= 29, "fixed-point formats need three integer bits to hold 2");
            Fix(FixedI32::<F>::from_bits(2i32 << F::U32))
        };
        const NAME: &'static str = FIXED_NAMES[F::USIZE];
        const SATURATES: bool = true;

        #[inline]
        fn from_f64(v: f64) -> Self {
            // `saturating_from_num` maps NaN to zero and +-inf to MAX/MIN.
            if v.is_nan() {
                Self::ZERO
            } else {
                Fix(FixedI32::<F>::saturating_from_num(v))
            }
        }
        #[inline]
        fn from_f32(v: f32) -> Self {
            if v.is_nan() {
                Self::ZERO
            } else {
                Fix(FixedI32::<F>::saturating_from_num(v))
            }
        }
        #[inline]
        fn to_f64(self) -> f64 {
            self.0.to_num::<f64>()
        }
        #[inline]
        fn to_f32(self) -> f32 {
            self.0.to_num::<f32>()
        }
        #[inline]
        fn sqrt(self) -> Self {
            let x = self.0.to_bits();
            if x <= 0 {
                return Self::ZERO;
            }
            let root = kernels::isqrt_round((x as u64) << F::U32);
            Fix(FixedI32::<F>::from_bits(root.min(i32::MAX as u64) as i32))
        }
        #[inline]
        fn sqrt_recip_sum_products(a: Self, b: Self, c: Self, d: Self) -> (Self, Self) {
            let ab = kernels::mul_wide(a.0.to_bits(), b.0.to_bits());
            let cd = kernels::mul_wide(c.0.to_bits(), d.0.to_bits());
            let n = ab.saturating_add(cd).max(0) as u64;
            let (root, recip) = kernels::sqrt_and_recip(n, F::U32);
            (
                Fix(FixedI32::<F>::from_bits(root)),
                Fix(FixedI32::<F>::from_bits(recip)),
            )
        }
        /// The exact products summed in 64 bits, then the root: the sum
        /// may exceed the format's range where its root does not.
        #[inline]
        fn sqrt_sum_products(a: Self, b: Self, c: Self, d: Self) -> Self {
            let ab = kernels::mul_wide(a.0.to_bits(), b.0.to_bits());
            let cd = kernels::mul_wide(c.0.to_bits(), d.0.to_bits());
            let n = ab.saturating_add(cd);
            if n <= 0 {
                return Self::ZERO;
            }
            let root = kernels::isqrt_round(n as u64);
            Fix(FixedI32::<F>::from_bits(root.min(i32::MAX as u64) as i32))
        }
        #[inline]
        fn abs(self) -> Self {
            Fix(self.0.saturating_abs())
        }
        #[inline]
        fn is_finite(self) -> bool {
            true
        }
        #[inline]
        fn tiny() -> Self {
            Fix(FixedI32::<F>::DELTA)
        }
        /// The exact 64-bit product plus the carried remainder, rounded to
        /// the format; the remainder (in units of `2^-2F`, below half an
        /// LSB) goes back into `carry`'s bits.
        #[inline]
        fn mul_add_compensated(self, a: Self, b: Self, carry: &mut Self) -> Self {
            let p = kernels::mul_wide(a.0.to_bits(), b.0.to_bits()) + carry.0.to_bits() as i64;
            let half = if F::U32 > 0 { 1i64 << (F::U32 - 1) } else { 0 };
            let q = (p + half) >> F::U32;
            *carry = Fix(FixedI32::<F>::from_bits((p - (q << F::U32)) as i32));
            saturate(self.0.to_bits() as i64 + q)
        }
        /// The sum of the exact products (units of `2^-2F`), times `a`
        /// (`2^-3F`), plus the carry, rounded to the format; the remainder
        /// (below half an LSB, kept to `2^-2F`) back into `carry`.
        /// Saturating throughout (no input panics). The sum is split as
        /// `s_hi 2^F + s_lo` so that `a s` is two 32 x 32 products where
        /// `s_hi` fits 32 bits (every tick: `|h b_i| < 1`, `|w| < 2048`),
        /// and formed in 128 bits only beyond.
        #[inline]
        fn dot_add_compensated(self, a: Self, b: &[Self], c: &[Self], carry: &mut Self) -> Self {
            let f = F::U32;
            let mut sum: i64 = 0;
            for (bj, cj) in b.iter().zip(c) {
                sum = sum.saturating_add(kernels::mul_wide(bj.0.to_bits(), cj.0.to_bits()));
            }
            let (a, k) = (a.0.to_bits(), carry.0.to_bits() as i64);
            let s_hi = sum >> f;
            // `p` rounded to `2^-2F`: a s_hi + carry + round(a s_lo 2^-F).
            let t = if s_hi == (s_hi as i32) as i64 && f > 0 {
                let s_lo = (sum - (s_hi << f)) as i32;
                let low = (kernels::mul_wide(a, s_lo) + (1i64 << (f - 1))) >> f;
                kernels::mul_wide(a, s_hi as i32) + k + low
            } else {
                let p = (a as i128).saturating_mul(sum as i128).saturating_add((k as i128) << f);
                let half = if f > 0 { 1i128 << (f - 1) } else { 0 };
                (p.saturating_add(half) >> f).clamp(i64::MIN as i128 / 2, i64::MAX as i128 / 2) as i64
            };
            let half = if f > 0 { 1i64 << (f - 1) } else { 0 };
            let q = (t + half) >> f;
            // |t - q 2^F| <= 2^(F-1): the carry, in units of 2^-2F.
            *carry = Fix(FixedI32::<F>::from_bits((t - (q << f)) as i32));
            let q = q.clamp(-(1i64 << 33), 1i64 << 33);
            saturate(self.0.to_bits() as i64 + q)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_point_never_panics() {
        let big = Q16_16::from_f64(1e9);
        let small = Q16_16::from_f64(-1e9);
        let z = Q16_16::ZERO;
        assert_eq!((big * big).to_f64(), 32768.0 - 1.0 / 65536.0);
        assert_eq!((big / z).to_f64(), 32768.0 - 1.0 / 65536.0);
        assert_eq!((small / z).to_f64(), -32768.0);
        assert_eq!((z / z).to_f64(), 0.0);
        assert_eq!(small.sqrt().to_f64(), 0.0);
        assert_eq!((-small).to_f64(), 32768.0 - 1.0 / 65536.0);
        assert_eq!(Q16_16::from_f64(f64::NAN).to_f64(), 0.0);
        assert_eq!(Q16_16::ONE.to_f64(), 1.0);
        assert_eq!(Q12_20::ONE.to_f64(), 1.0);
        assert!((Q16_16::from_f64(2.0).sqrt().to_f64() - 2f64.sqrt()).abs() < 2e-5);
    }

    #[test]
    fn products_below_the_resolution_still_add_up() {
        // A plunger creeping at w = 31 LSB over steps of h b = 0.015: each
        // product is 0.47 LSB, which rounds to zero; summed exactly and
        // carried, 10,000 steps of a = 0.1 advance by their true total.
        let (a, hb, w) = (
            0.1,
            [0.015, 0.012],
            [31.0 / (1u64 << 20) as f64, 29.0 / (1u64 << 20) as f64],
        );
        let exact = 10_000.0 * a * (hb[0] * w[0] + hb[1] * w[1]);
        let (qa, qb, qw) = (
            Q12_20::from_f64(a),
            [Q12_20::from_f64(hb[0]), Q12_20::from_f64(hb[1])],
            [Q12_20::from_f64(w[0]), Q12_20::from_f64(w[1])],
        );
        let (mut x, mut carry) = (Q12_20::ZERO, Q12_20::ZERO);
        let (mut rounded, mut c2) = (Q12_20::ZERO, Q12_20::ZERO);
        for _ in 0..10_000 {
            x = x.dot_add_compensated(qa, &qb, &qw, &mut carry);
            rounded = rounded.mul_add_compensated(qa, qb[0] * qw[0] + qb[1] * qw[1], &mut c2);
        }
        let lsb = 1.0 / (1u64 << 20) as f64;
        // The inputs as Q12.20 holds them differ by 1e-4 relative at most.
        assert!(
            (x.to_f64() - exact).abs() <= 2.0 * lsb + 2e-4 * exact,
            "{x:?} vs {exact}"
        );
        assert!(
            rounded.to_f64() < 0.5 * exact,
            "the rounded products were expected to vanish"
        );
        // Floats: the plain sum of products, compensated.
        let (mut y, mut c) = (0.0f64, 0.0f64);
        for _ in 0..10_000 {
            y = y.dot_add_compensated(a, &hb, &w, &mut c);
        }
        assert!((y - exact).abs() <= 1e-15);
        // Saturating, never panicking, on extreme inputs.
        let big = Q12_20::from_f64(2047.0);
        let mut k = Q12_20::from_f64(-0.5);
        let z = Q12_20::ZERO.dot_add_compensated(big, &[big, big, big], &[big, big, big], &mut k);
        assert_eq!(z.to_f64(), 2048.0 - lsb);
    }

    #[test]
    fn fixed_point_formats_are_named_by_their_bits() {
        assert_eq!(Q12_20::NAME, "Q12.20");
        assert_eq!(Q16_16::NAME, "Q16.16");
        assert_eq!(Q8_24::NAME, "Q8.24");
        assert_eq!(Fixed::NAME, "Q12.20");
        for (f, name) in fixed_point::FIXED_NAMES.iter().enumerate() {
            assert_eq!(*name, format!("Q{}.{f}", 32 - f));
        }
        assert_eq!((f32::NAME, f64::NAME), ("f32", "f64"));
    }

    #[test]
    fn float_sqrt_is_total() {
        assert_eq!(Real::sqrt(-4.0f32), 0.0);
        assert_eq!(Real::sqrt(-4.0f64), 0.0);
        assert!(Real::sqrt(f32::NAN).is_nan());
        assert_eq!(Real::sqrt(9.0f32), 3.0);
    }
}
