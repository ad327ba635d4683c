//! An instrumented scalar for the fixed-point audit: [`Probe<T>`]
//! computes exactly as `T` does and records, for every arithmetic
//! operation of the code it runs, the range of the values that operation
//! produces, keyed by the operation's place in the source (`#[track_caller]`
//! on every operator and [`Real`] method: the site of `a * b` in
//! `model/src/dynamics/dirk.rs` is that expression's line and column).
//!
//! `Twin<f64, Probe<f64>>` measures what the algorithm needs (the ranges
//! in exact-enough arithmetic); `Twin<f32, Probe<Fixed>>` what the shipped
//! fixed-point twin actually computes, saturation and underflow included.
//! Recording is per thread and only while a [`Recording`] is alive.

use compensator::Real;
use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
use std::panic::Location;

/// What produced a recorded value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Op {
    /// `a + b`, `a += b`.
    Add,
    /// `a - b`, `a -= b`.
    Sub,
    /// `a * b`, `a *= b`, `a.sq()`.
    Mul,
    /// `a / b` (the quotient).
    Div,
    /// The divisor of `a / b`.
    Divisor,
    /// `-a`.
    Neg,
    /// `a.sqrt()`, and the root of `Real::sqrt_sum_products` and
    /// `Real::sqrt_recip_sum_products`.
    Sqrt,
    /// The reciprocal `Real::sqrt_recip_sum_products` returns beside the
    /// root (no division where the core multiplies 32 x 32 -> 64).
    Reciprocal,
    /// `a.abs()`.
    Abs,
    /// `max`, `min`, `clamp_to`.
    Select,
    /// `T::from_f64`, `T::from_f32` (coefficients and constants).
    Convert,
    /// The product `a b` of `x.mul_add_compensated(a, b, carry)` (of
    /// `x.dot_add_compensated`: `a sum_j b_j c_j`, exact; the products
    /// `b_j c_j` as the format rounds them are recorded as `Mul`, their
    /// underflows counted although the sum keeps them in fixed point).
    Increment,
    /// The sum of `x.mul_add_compensated(a, b, carry)`.
    Accumulate,
}

/// A place in the source and the operation there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Site {
    /// Source file, as the compiler names it (relative to the workspace).
    pub file: &'static str,
    /// Line (1-based).
    pub line: u32,
    /// Column (1-based) of the expression.
    pub column: u32,
    /// The operation.
    pub op: Op,
}

/// The values one site produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Values recorded.
    pub count: u64,
    /// Largest `|v|`.
    pub max_abs: f64,
    /// Smallest nonzero `|v|` (`inf` if every value was zero).
    pub min_nonzero: f64,
    /// Products, quotients and roots of nonzero operands that came out
    /// exactly zero: a value lost below the format's resolution.
    pub underflows: u64,
}

impl Default for Range {
    fn default() -> Self {
        Range {
            count: 0,
            max_abs: 0.0,
            min_nonzero: f64::INFINITY,
            underflows: 0,
        }
    }
}

impl Range {
    fn add(&mut self, v: f64, underflow: bool) {
        self.count += 1;
        let a = v.abs();
        if a > self.max_abs || a.is_nan() {
            self.max_abs = if a.is_nan() { f64::INFINITY } else { a };
        }
        if a > 0.0 && a < self.min_nonzero {
            self.min_nonzero = a;
        }
        self.underflows += u64::from(underflow);
    }

    /// Merges another site's range into this one.
    pub fn merge(&mut self, o: &Range) {
        self.count += o.count;
        self.max_abs = self.max_abs.max(o.max_abs);
        self.min_nonzero = self.min_nonzero.min(o.min_nonzero);
        self.underflows += o.underflows;
    }
}

/// Every site's range.
pub type Ranges = HashMap<Site, Range>;

thread_local! {
    static RECORD: RefCell<Option<Ranges>> = const { RefCell::new(None) };
}

/// Recording on this thread while alive; [`Recording::finish`] returns what
/// was recorded.
pub struct Recording(());

impl Recording {
    /// Starts recording on this thread (a recording already running is
    /// discarded).
    pub fn start() -> Recording {
        RECORD.with(|r| *r.borrow_mut() = Some(HashMap::new()));
        Recording(())
    }

    /// Stops recording and returns the ranges.
    pub fn finish(self) -> Ranges {
        RECORD.with(|r| r.borrow_mut().take()).unwrap_or_default()
    }
}

impl Drop for Recording {
    fn drop(&mut self) {
        RECORD.with(|r| r.borrow_mut().take());
    }
}

#[inline]
fn record(loc: &'static Location<'static>, op: Op, v: f64, underflow: bool) {
    RECORD.with(|r| {
        if let Some(map) = r.borrow_mut().as_mut() {
            map.entry(Site {
                file: loc.file(),
                line: loc.line(),
                column: loc.column(),
                op,
            })
            .or_default()
            .add(v, underflow);
        }
    });
}

/// A scalar computing as `T`, recording every result (see the module).
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Probe<T>(pub T);

impl<T: Real> Probe<T> {
    #[track_caller]
    #[inline]
    fn out(op: Op, v: T, underflow: bool) -> Self {
        record(Location::caller(), op, v.to_f64(), underflow);
        Probe(v)
    }
}

/// `true` when `a` and `b` are nonzero and `r` is zero.
#[inline]
fn lost<T: Real>(a: T, b: T, r: T) -> bool {
    a != T::ZERO && b != T::ZERO && r == T::ZERO
}

impl<T: Real> Add for Probe<T> {
    type Output = Self;
    #[track_caller]
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::out(Op::Add, self.0 + o.0, false)
    }
}
impl<T: Real> Sub for Probe<T> {
    type Output = Self;
    #[track_caller]
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::out(Op::Sub, self.0 - o.0, false)
    }
}
impl<T: Real> Mul for Probe<T> {
    type Output = Self;
    #[track_caller]
    #[inline]
    fn mul(self, o: Self) -> Self {
        let r = self.0 * o.0;
        Self::out(Op::Mul, r, lost(self.0, o.0, r))
    }
}
impl<T: Real> Div for Probe<T> {
    type Output = Self;
    #[track_caller]
    #[inline]
    fn div(self, o: Self) -> Self {
        record(Location::caller(), Op::Divisor, o.0.to_f64(), false);
        let r = self.0 / o.0;
        Self::out(Op::Div, r, lost(self.0, o.0, r))
    }
}
impl<T: Real> Neg for Probe<T> {
    type Output = Self;
    #[track_caller]
    #[inline]
    fn neg(self) -> Self {
        Self::out(Op::Neg, -self.0, false)
    }
}
impl<T: Real> AddAssign for Probe<T> {
    #[track_caller]
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = Self::out(Op::Add, self.0 + o.0, false);
    }
}
impl<T: Real> SubAssign for Probe<T> {
    #[track_caller]
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        *self = Self::out(Op::Sub, self.0 - o.0, false);
    }
}
impl<T: Real> MulAssign for Probe<T> {
    #[track_caller]
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        let r = self.0 * o.0;
        *self = Self::out(Op::Mul, r, lost(self.0, o.0, r));
    }
}

impl<T: Real> Real for Probe<T> {
    const ZERO: Self = Probe(T::ZERO);
    const ONE: Self = Probe(T::ONE);
    const HALF: Self = Probe(T::HALF);
    const TWO: Self = Probe(T::TWO);
    const NAME: &'static str = "probe";
    /// Always the fixed-point code path: `Probe<f64>` measures what that
    /// path needs in exact-enough arithmetic.
    const SATURATES: bool = true;

    #[track_caller]
    fn from_f64(v: f64) -> Self {
        Self::out(Op::Convert, T::from_f64(v), false)
    }
    #[track_caller]
    fn from_f32(v: f32) -> Self {
        Self::out(Op::Convert, T::from_f32(v), false)
    }
    fn to_f64(self) -> f64 {
        self.0.to_f64()
    }
    fn to_f32(self) -> f32 {
        self.0.to_f32()
    }
    #[track_caller]
    fn sqrt(self) -> Self {
        let r = self.0.sqrt();
        Self::out(Op::Sqrt, r, self.0 > T::ZERO && r == T::ZERO)
    }
    #[track_caller]
    fn sqrt_sum_products(a: Self, b: Self, c: Self, d: Self) -> Self {
        let r = T::sqrt_sum_products(a.0, b.0, c.0, d.0);
        Self::out(Op::Sqrt, r, false)
    }
    #[track_caller]
    fn sqrt_recip_sum_products(a: Self, b: Self, c: Self, d: Self) -> (Self, Self) {
        let loc = Location::caller();
        let (r, inv) = T::sqrt_recip_sum_products(a.0, b.0, c.0, d.0);
        record(loc, Op::Sqrt, r.to_f64(), false);
        record(loc, Op::Reciprocal, inv.to_f64(), false);
        (Probe(r), Probe(inv))
    }
    #[track_caller]
    fn abs(self) -> Self {
        Self::out(Op::Abs, self.0.abs(), false)
    }
    fn is_finite(self) -> bool {
        self.0.is_finite()
    }
    fn tiny() -> Self {
        Probe(T::tiny())
    }
    #[track_caller]
    fn max(self, other: Self) -> Self {
        Self::out(Op::Select, self.0.max(other.0), false)
    }
    #[track_caller]
    fn min(self, other: Self) -> Self {
        Self::out(Op::Select, self.0.min(other.0), false)
    }
    #[track_caller]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        Self::out(Op::Select, self.0.clamp_to(lo.0, hi.0), false)
    }
    #[track_caller]
    fn sq(self) -> Self {
        let r = self.0.sq();
        Self::out(Op::Mul, r, lost(self.0, self.0, r))
    }
    #[track_caller]
    fn mul_add_compensated(self, a: Self, b: Self, carry: &mut Self) -> Self {
        let loc = Location::caller();
        let p = a.0 * b.0;
        record(loc, Op::Increment, p.to_f64(), false);
        let mut c = carry.0;
        let s = self.0.mul_add_compensated(a.0, b.0, &mut c);
        *carry = Probe(c);
        record(loc, Op::Accumulate, s.to_f64(), false);
        Probe(s)
    }
    #[track_caller]
    fn dot_add_compensated(self, a: Self, b: &[Self], c: &[Self], carry: &mut Self) -> Self {
        let loc = Location::caller();
        let (b, c): (Vec<T>, Vec<T>) = (b.iter().map(|v| v.0).collect(), c.iter().map(|v| v.0).collect());
        for (bj, cj) in b.iter().zip(&c) {
            let p = *bj * *cj;
            record(loc, Op::Mul, p.to_f64(), lost(*bj, *cj, p));
        }
        let exact: f64 = b.iter().zip(&c).map(|(x, y)| x.to_f64() * y.to_f64()).sum();
        record(loc, Op::Increment, a.0.to_f64() * exact, false);
        let mut k = carry.0;
        let s = self.0.dot_add_compensated(a.0, &b, &c, &mut k);
        *carry = Probe(k);
        record(loc, Op::Accumulate, s.to_f64(), false);
        Probe(s)
    }
}

/// The ranges of `a` and `b` together.
pub fn merge(a: &mut Ranges, b: &Ranges) {
    for (site, r) in b {
        a.entry(*site).or_default().merge(r);
    }
}

/// The source text of a site's line (trimmed), for reports; read from the
/// workspace.
pub fn source_line(site: &Site) -> String {
    let path = crate::repo_root().join(site.file);
    std::fs::read_to_string(path)
        .ok()
        .and_then(|s| s.lines().nth(site.line as usize - 1).map(|l| l.trim().to_string()))
        .unwrap_or_default()
}
