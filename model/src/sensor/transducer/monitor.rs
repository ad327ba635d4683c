//! The stuck and noise checks of the transducer's codes (module docs of
//! [`super`] for their derivation).

use super::{NOISE_WINDOW, Settings};
use crate::sensor::{Detail, SensorFault};

/// The running checks over a transducer's codes: the run of equal codes
/// (stuck) and the sample variance of each window of [`NOISE_WINDOW`]
/// codes (noisy), in exact integer arithmetic (a code's distance from the
/// window's first code, its square, summed in `i64`).
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

    /// The sample variance of the last complete window \[codes^2\], if one
    /// is complete.
    pub fn last_variance(&self) -> Option<f32> {
        self.variance.map(f32::from_bits)
    }

    /// Takes one code and returns the verdict on the codes so far:
    /// [`SensorFault::Stuck`] while the run of equal codes is at least
    /// [`Settings::stuck_after`] (when the check is on), else
    /// [`SensorFault::Noisy`] while the last complete window's variance
    /// exceeds [`Settings::noise_limit`]; each with the code as its detail.
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
        self.count += 1;
        if self.count >= NOISE_WINDOW {
            let w = i64::from(NOISE_WINDOW);
            // (W S2 - S1^2) / (W (W - 1)): exact numerator, >= 0.
            let numerator = (w * self.sum2 - self.sum * self.sum).max(0);
            let variance = numerator as f32 / (w * (w - 1)) as f32;
            self.variance = Some(variance.to_bits());
            self.noisy = variance > f32::from_bits(self.noise_limit);
            self.count = 0;
            self.sum = 0;
            self.sum2 = 0;
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
