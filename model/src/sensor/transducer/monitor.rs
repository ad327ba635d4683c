//! The stuck and noise checks of the transducer's codes (module docs of
//! [`super`] for their derivation).

use super::{NOISE_WINDOW, Settings};
use crate::sensor::{Detail, SensorFault};

/// The running checks over a transducer's codes: the run of equal codes
/// (stuck) and the residual variance of each window of [`NOISE_WINDOW`]
/// codes about its least-squares line (noisy: a process value moving at a
/// steady rate, a chamber pressure through a temperature ramp, is no
/// noise), in exact integer arithmetic (a code's distance from the
/// window's first code, its square and its product with its place in the
/// window, summed in `i64`).
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
    /// `sum i d_i` over the window's places `i = 0..`.
    sumx: i64,
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
    /// least-squares line \[codes^2\] (`RSS / (W - 2)`), if one is complete.
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
        self.sumx += i64::from(self.count) * d;
        self.count += 1;
        if self.count >= NOISE_WINDOW {
            let variance = residual_variance(self.sum, self.sum2, self.sumx);
            self.variance = Some(variance.to_bits());
            self.noisy = variance > f32::from_bits(self.noise_limit);
            self.count = 0;
            self.sum = 0;
            self.sum2 = 0;
            self.sumx = 0;
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

/// The residual variance about the least-squares line of a window of
/// [`NOISE_WINDOW`] codes \[codes^2\], from `s1 = sum d_i`, `s2 = sum
/// d_i^2`, `sx = sum i d_i` (`d_i` the `i`-th code's distance from the
/// first): with `W Syy = W s2 - s1^2`, `W Sxy = W sx - (sum i) s1` and
/// `W Sxx = W^2 (W^2 - 1) / 12`, `RSS = (W Syy W Sxx - (W Sxy)^2) / (W W
/// Sxx)`, the numerator exact in `i64` (at most about 1e17 for 12-bit
/// codes; not negative, by Cauchy-Schwarz), over `W - 2` degrees of
/// freedom.
fn residual_variance(s1: i64, s2: i64, sx: i64) -> f32 {
    let w = i64::from(NOISE_WINDOW);
    let sum_i = w * (w - 1) / 2;
    let w_sxx = w * w * (w * w - 1) / 12;
    let w_syy = w * s2 - s1 * s1;
    let w_sxy = w * sx - sum_i * s1;
    let numerator = (w_syy * w_sxx - w_sxy * w_sxy).max(0);
    numerator as f32 / (w * w_sxx) as f32 / (w - 2) as f32
}
