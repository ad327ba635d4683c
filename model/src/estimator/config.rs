//! The estimator's settings, from the parameter file's `[estimator]`
//! section.

use super::filter::FilterSettings;
use crate::dynamics::TwinConfig;
use crate::params::{ParamError, RawEstimator};

/// A closed range of temperatures [C], `min..=max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemperatureRange {
    /// Lower end [C].
    pub min: f32,
    /// Upper end [C].
    pub max: f32,
}

impl TemperatureRange {
    /// `min..=max` [C].
    pub const fn new(min: f32, max: f32) -> Self {
        TemperatureRange { min, max }
    }

    /// `t` [C] lies within the range, ends included (`false` for NaN).
    #[inline]
    pub fn contains(self, t: f32) -> bool {
        t >= self.min && t <= self.max
    }
}

/// Estimator settings in `f32` (from the `[estimator]` section).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig {
    /// The twin's integrator. Its tick is the estimator's (`1 / tick_hz`);
    /// scheme and steps per tick are [`TwinConfig::SHIPPED`]'s unless
    /// changed before [`Estimator::new`](super::Estimator::new).
    pub twin: TwinConfig,
    /// Filter gain per tick, `1 - exp(-tick / tau)`.
    pub filter_gain: f32,
    /// Spike threshold [C].
    pub spike_threshold: f32,
    /// Consecutive rejected samples accepted as a real step.
    pub spike_limit: u32,
    /// Validated temperature range [C].
    pub valid: TemperatureRange,
    /// Range where the oil model is used at all [C].
    pub oil: TemperatureRange,
    /// Ticks between telemetry records (0: never).
    pub telemetry_every: u32,
    /// Ticks without an accepted sample after which the estimate is degraded.
    pub stale_after: u32,
}

impl EstimatorConfig {
    /// From the parameter file's `[estimator]` section (validated).
    ///
    /// # Errors
    ///
    /// A [`ParamError`] naming the first field of `raw` that breaks its
    /// rule (`RawEstimator::validate`).
    pub fn new(raw: &RawEstimator) -> Result<Self, ParamError> {
        raw.validate()?;
        let tick = 1.0 / raw.tick_hz;
        let telemetry_every = if raw.telemetry_hz > 0.0 {
            libm::round(raw.tick_hz / raw.telemetry_hz).max(1.0) as u32
        } else {
            0
        };
        Ok(EstimatorConfig {
            twin: TwinConfig {
                tick,
                ..TwinConfig::SHIPPED
            },
            filter_gain: FilterSettings::gain(tick, raw.filter_time_constant),
            spike_threshold: raw.spike_threshold as f32,
            // A whole number of at most 65,534 (validated).
            spike_limit: raw.spike_limit as u32,
            valid: TemperatureRange::new(raw.valid_min as f32, raw.valid_max as f32),
            oil: TemperatureRange::new(raw.oil_min as f32, raw.oil_max as f32),
            telemetry_every,
            // Half a second without a usable sample (at least ten ticks).
            stale_after: (libm::round(raw.tick_hz * 0.5) as u32).max(10),
        })
    }

    /// Tick [s].
    pub fn tick(&self) -> f32 {
        self.twin.tick as f32
    }

    /// Ticks between samples of a source that delivers one every `period`
    /// [s] (at least one).
    pub fn ticks_per(&self, period: f32) -> u32 {
        let n = period / self.tick() + 0.5;
        if n >= 1.0 { n as u32 } else { 1 }
    }

    /// The temperature filter's settings.
    #[inline]
    pub fn filter(&self) -> FilterSettings {
        FilterSettings {
            gain: self.filter_gain,
            threshold: self.spike_threshold,
            limit: self.spike_limit,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_hold_their_ends_and_refuse_nan() {
        let r = TemperatureRange::new(26.0, 78.0);
        assert!(r.contains(26.0) && r.contains(78.0) && r.contains(50.0));
        assert!(!r.contains(25.999) && !r.contains(78.001));
        assert!(!r.contains(f32::NAN) && !r.contains(f32::INFINITY) && !r.contains(f32::NEG_INFINITY));
    }
}
