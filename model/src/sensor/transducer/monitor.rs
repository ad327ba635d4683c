//! The stuck and noise checks of the transducer's codes (module docs of
//! [`super`] for their derivation).

use super::{NOISE_WINDOW, Settings};
use crate::sensor::{Detail, SensorFault};

/// The running checks over a transducer's codes: the run of equal codes
/// (stuck) and the residual variance of each window of [`NOISE_WINDOW`]
/// codes about its least-squares parabola (noisy: a process value moving
/// smoothly, a chamber pressure through a temperature ramp and into or
/// out of it, is no noise), in exact integer arithmetic (a code's
/// distance `d` from the window's first code, `d^2`, and `d` times the
/// window's odd place `j = 2 i - 63` and `j^2`, summed in `i64`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Checks {
    stuck_after: u32,
    /// The variance limit's bits (an `f32`, kept as bits so that the
    /// checks compare as values).
    noise_limit: u32,
    last: Option<u16>,
    run: u32,
    first: u16,
    count: u32,
    sum: i64,
    sum2: i64,
    /// `sum j d` and `sum j^2 d` over the window's places `j = 2 i - (W -
    /// 1)`.
    sumx: i64,
    sumxx: i64,
    noisy: bool,
    variance: Option<u32>,
}

impl Checks {
    /// The checks of `settings` ([`Settings::stuck_after`],
    /// [`Settings::noise_limit`]), with no code seen.
    pub fn new(settings: &Settings) -> Checks {
        Checks::fresh(settings.stuck_after, settings.noise_limit.to_bits())
    }

    const fn fresh(stuck_after: u32, noise_limit: u32) -> Checks {
        Checks {
            stuck_after,
            noise_limit,
            last: None,
            run: 0,
            first: 0,
            count: 0,
            sum: 0,
            sum2: 0,
            sumx: 0,
            sumxx: 0,
            noisy: false,
            variance: None,
        }
    }

    /// Forgets every code seen (after a fault was cleared, a restart).
    pub fn reset(&mut self) {
        *self = Checks::fresh(self.stuck_after, self.noise_limit);
    }

    /// Equal codes in a row up to the last one.
    pub fn run_length(&self) -> u32 {
        self.run
    }

    /// The residual variance of the last complete window about its
    /// least-squares parabola \[codes^2\] (`RSS / (W - 3)`), if one is
    /// complete.
    pub fn last_variance(&self) -> Option<f32> {
        self.variance.map(f32::from_bits)
    }

    /// Takes one code and returns the verdict on the codes so far:
    /// [`SensorFault::Stuck`] while the run of equal codes is at least
    /// [`Settings::stuck_after`] (when the check is on), else
    /// [`SensorFault::Noisy`] while the last complete window's residual
    /// variance exceeds [`Settings::noise_limit`]; each with the code as
    /// its detail.
    ///
    /// # Errors
    ///
    /// The fault, as above.
    pub fn update(&mut self, code: u16) -> Result<(), SensorFault> {
        self.run = if self.last == Some(code) {
            self.run.saturating_add(1)
        } else {
            1
        };
        self.last = Some(code);
        if self.count == 0 {
            self.first = code;
        }
        let d = i64::from(code) - i64::from(self.first);
        self.sum += d;
        self.sum2 += d * d;
        let j = 2 * i64::from(self.count) - (i64::from(NOISE_WINDOW) - 1);
        self.sumx += j * d;
        self.sumxx += j * j * d;
        self.count += 1;
        if self.count >= NOISE_WINDOW {
            let variance = residual_variance(self.sum, self.sum2, self.sumx, self.sumxx);
            self.variance = Some(variance.to_bits());
            self.noisy = variance > f32::from_bits(self.noise_limit);
            self.count = 0;
            self.sum = 0;
            self.sum2 = 0;
            self.sumx = 0;
            self.sumxx = 0;
        }
        if self.stuck_after > 0 && self.run >= self.stuck_after {
            Err(SensorFault::Stuck(Detail::code(code)))
        } else if self.noisy {
            Err(SensorFault::Noisy(Detail::code(code)))
        } else {
            Ok(())
        }
    }
}

/// `sum j^2` and `sum j^4` over a window's places `j = 2 i - (W - 1)`.
const fn place_moments() -> (i128, i128) {
    let w = NOISE_WINDOW as i128;
    let (mut j2, mut j4) = (0, 0);
    let mut i = 0;
    while i < w {
        let j = 2 * i - (w - 1);
        j2 += j * j;
        j4 += j * j * j * j;
        i += 1;
    }
    (j2, j4)
}

/// The residual variance about the least-squares parabola of a window of
/// [`NOISE_WINDOW`] codes \[codes^2\], from `s0 = sum d`, `sdd = sum d^2`,
/// `s1 = sum j d`, `s2 = sum j^2 d` (`d` a code's distance from the
/// window's first, `j = 2 i - (W - 1)` its odd place). On the orthogonal
/// polynomials `1`, `j`, `W j^2 - J2` (`J2 = sum j^2`, `J4 = sum j^4`):
///
/// ```text
/// RSS = sdd - s0^2 / W - s1^2 / J2 - (W s2 - J2 s0)^2 / (W (W J4 - J2^2))
/// ```
///
/// over the common denominator `W J2 (W J4 - J2^2)` exactly in `i128` (at
/// most about 1e26 for 12-bit codes; not negative: the residual's sum of
/// squares), then divided, over `W - 3` degrees of freedom.
fn residual_variance(s0: i64, sdd: i64, s1: i64, s2: i64) -> f32 {
    let w = i128::from(NOISE_WINDOW);
    let (j2, j4) = place_moments();
    let q = w * j4 - j2 * j2;
    let (s0, sdd, s1, s2) = (i128::from(s0), i128::from(sdd), i128::from(s1), i128::from(s2));
    let p2 = w * s2 - j2 * s0;
    let numerator = ((w * sdd - s0 * s0) * j2 * q - w * q * s1 * s1 - j2 * p2 * p2).max(0);
    numerator as f32 / (w * j2 * q) as f32 / (w - 3) as f32
}
