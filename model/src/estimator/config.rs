//! The estimator's settings: the `[estimator]` section's, the observer's
//! design from the `[probe]` section, and the uncertainty table from the
//! `[tolerances]`; the condition monitor's from the `[monitor]` section
//! ([`MonitorSettings::from_raw`]).

use super::observer::{DesignError, ObserverDesign, ObserverSettings};
use super::spike::SpikeSettings;
use crate::dynamics::TwinConfig;
use crate::monitor::{MonitorSettings, ProbeModel, Quantity};
use crate::params::{ParamError, RawEstimator, RawParams};
use crate::sensor::transducer::{self, SettingsError};
use crate::uncertainty::{UncertaintyError, UncertaintyTable};
use core::borrow::Borrow;

/// A closed range of temperatures \[C\], `min..=max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemperatureRange {
    /// Lower end \[C\].
    pub min: f32,
    /// Upper end \[C\].
    pub max: f32,
}

impl TemperatureRange {
    /// `min..=max` \[C\].
    pub const fn new(min: f32, max: f32) -> Self {
        TemperatureRange { min, max }
    }

    /// `t` \[C\] lies within the range, ends included (`false` for NaN).
    #[inline]
    pub fn contains(self, t: f32) -> bool {
        t >= self.min && t <= self.max
    }
}

/// Why an estimator's settings cannot be built from a parameter set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConfigError {
    /// A field is refused (named).
    Params(ParamError),
    /// No observer for the probe's settings.
    Observer(DesignError),
    /// No uncertainty table for the device's tolerances.
    Uncertainty(UncertaintyError),
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ConfigError::Params(e) => write!(f, "{e}"),
            ConfigError::Observer(e) => write!(f, "probe: {e}"),
            ConfigError::Uncertainty(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for ConfigError {}

impl From<ParamError> for ConfigError {
    fn from(e: ParamError) -> Self {
        ConfigError::Params(e)
    }
}

/// Estimator settings in `f32`, with the uncertainty table held as `U` and
/// the observer's design as `O`: each the value itself (the defaults,
/// [`EstimatorConfig::new`]), or a reference to one in flash (`&'static
/// UncertaintyTable`, `&'static ObserverDesign`: the firmware's, which then
/// keeps 0.75 KiB and 0.9 KiB off its stack per copy;
/// [`EstimatorConfig::from_parts`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimatorConfig<U = UncertaintyTable, O = ObserverDesign> {
    /// The twin's integrator. Its tick is the estimator's (`1 / tick_hz`);
    /// scheme and steps per tick are [`TwinConfig::SHIPPED`]'s unless
    /// changed before [`Estimator::new`](super::Estimator::new).
    pub twin: TwinConfig,
    /// The oil-temperature observer's design (or a reference to it).
    pub observer: O,
    /// The spike gate in front of it.
    pub spikes: SpikeSettings,
    /// The uncertainty table over the oil range (or a reference to it).
    pub uncertainty: U,
    /// Validated temperature range \[C\].
    pub valid: TemperatureRange,
    /// Range where the oil model is used at all \[C\].
    pub oil: TemperatureRange,
    /// Ticks between telemetry records (0: never).
    pub telemetry_every: u32,
    /// Ticks without an accepted sample after which the estimate is degraded.
    pub stale_after: u32,
}

impl EstimatorConfig<UncertaintyTable> {
    /// The settings for the parameter set `raw`, the probe read through the
    /// file's sensor (its sample period and resolution): the observer
    /// designed and the uncertainty table built here, in `f64` (a few
    /// milliseconds on a host; the firmware gets both from its build
    /// script and calls [`EstimatorConfig::from_parts`]).
    ///
    /// # Errors
    ///
    /// [`ConfigError::Params`] naming the first refused field,
    /// [`ConfigError::Observer`] or [`ConfigError::Uncertainty`] when the
    /// observer or the table cannot be built.
    pub fn new(raw: &RawParams) -> Result<Self, ConfigError> {
        Self::with_sample_period(raw, reading_period(&raw.estimator))
    }

    /// As [`EstimatorConfig::new`], for readings every `sample_period` \[s\]
    /// (a recorded log's rate).
    ///
    /// # Errors
    ///
    /// As [`EstimatorConfig::new`].
    pub fn with_sample_period(raw: &RawParams, sample_period: f64) -> Result<Self, ConfigError> {
        raw.validate()?;
        let e = &raw.estimator;
        let observer = ObserverDesign::new(&observer_settings(raw, sample_period)).map_err(ConfigError::Observer)?;
        let uncertainty =
            UncertaintyTable::new(raw, e.oil_min, e.oil_max, |t| e.resolution(t)).map_err(ConfigError::Uncertainty)?;
        Ok(Self::from_parts(e, observer, uncertainty)?)
    }
}

impl<U: Borrow<UncertaintyTable> + Copy> EstimatorConfig<U, ObserverDesign> {
    /// The settings for `raw` with an uncertainty table built beforehand
    /// (by a build script: the table does not depend on the tick), the
    /// observer designed here for `raw`'s tick and the MAX31865's
    /// conversion period ([`reading_period`]), in `f64`: what a firmware
    /// that sets its own tick rate calls.
    ///
    /// # Errors
    ///
    /// [`ConfigError::Params`] naming the first refused field,
    /// [`ConfigError::Observer`] when the observer cannot be designed.
    pub fn with_table(raw: &RawParams, uncertainty: U) -> Result<Self, ConfigError> {
        raw.validate()?;
        let observer = ObserverDesign::new(&observer_settings(raw, reading_period(&raw.estimator)))
            .map_err(ConfigError::Observer)?;
        Ok(Self::from_parts(&raw.estimator, observer, uncertainty)?)
    }
}

impl<U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy> EstimatorConfig<U, O> {
    /// The uncertainty table.
    #[inline]
    pub fn table(&self) -> &UncertaintyTable {
        self.uncertainty.borrow()
    }

    /// The oil-temperature observer's design.
    #[inline]
    pub fn observer_design(&self) -> &ObserverDesign {
        self.observer.borrow()
    }

    /// From the `[estimator]` section and an observer and uncertainty table
    /// designed for it (by [`EstimatorConfig::new`] on a host, or a build
    /// script).
    ///
    /// # Errors
    ///
    /// A [`ParamError`] naming the first field of `raw` that breaks its
    /// rule (`RawEstimator::validate`).
    pub fn from_parts(raw: &RawEstimator, observer: O, uncertainty: U) -> Result<Self, ParamError> {
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
            observer,
            spikes: SpikeSettings {
                threshold: raw.spike_threshold as f32,
                // A whole number of at most 65,534 (validated).
                limit: raw.spike_limit as u32,
            },
            uncertainty,
            valid: TemperatureRange::new(raw.valid_min as f32, raw.valid_max as f32),
            oil: TemperatureRange::new(raw.oil_min as f32, raw.oil_max as f32),
            telemetry_every,
            // Half a second without a usable sample (at least ten ticks).
            stale_after: (libm::round(raw.tick_hz * 0.5) as u32).max(10),
        })
    }

    /// Tick \[s\].
    pub fn tick(&self) -> f32 {
        self.twin.tick as f32
    }

    /// The period of the readings the observer is designed for \[s\].
    pub fn sample_period(&self) -> f64 {
        f64::from(self.observer_design().sample_period)
    }

    /// Ticks between samples of a source that delivers one every `period`
    /// \[s\] (at least one).
    pub fn ticks_per(&self, period: f32) -> u32 {
        let n = period / self.tick() + 0.5;
        if n >= 1.0 { n as u32 } else { 1 }
    }
}

/// The period of the sensor's readings at the estimator's tick \[s\]: its
/// conversion period for the mains filter, rounded to a whole number of
/// ticks (at least one; the converter is read on the tick its reading is
/// due).
pub fn reading_period(e: &RawEstimator) -> f64 {
    let period = crate::sensor::device::sample_period(e) as f64;
    let ticks = libm::round(period * e.tick_hz).max(1.0);
    ticks / e.tick_hz
}

/// The observer's settings for the parameter set `raw` with readings every
/// `sample_period` \[s\] through the file's sensor (its resolution at the middle of
/// the validated range).
pub fn observer_settings(raw: &RawParams, sample_period: f64) -> ObserverSettings {
    let e = &raw.estimator;
    let mid = 0.5 * (e.valid_min + e.valid_max);
    ObserverSettings {
        time_constant: raw.probe.time_constant,
        well_time_constant: raw.probe.well_time_constant,
        noise: raw.probe.noise,
        resolution: e.resolution(mid),
        max_rate: e.max_oil_rate,
        tick: 1.0 / e.tick_hz,
        sample_period,
        span: e.oil_max - e.oil_min,
    }
}

/// The condition monitor's settings ([`MonitorSettings`]) from a parameter
/// file, one function for every consumer (the CLI, the FMU, the firmware's
/// build): what the estimator's monitor needs of the `[monitor]` section's
/// sensor.
impl MonitorSettings {
    /// The monitor's settings for the validated parameter set `raw`:
    /// `None` without a second sensor (no `[monitor]` section, or
    /// `monitor.sensor = "none"`), else [`MonitorSettings::of_transducer`]
    /// of its transducer ([`crate::sensor::device::monitor_settings`]).
    ///
    /// # Errors
    ///
    /// [`SettingsError::Param`] naming the field of `raw` its validation
    /// or the transducer's settings refuse (`monitor.range_max`,
    /// `monitor.noise`, ...).
    pub fn from_raw(raw: &RawParams) -> Result<Option<MonitorSettings>, SettingsError> {
        let probe = ProbeModel::new(raw);
        Ok(crate::sensor::device::monitor_settings(raw)?.map(|s| MonitorSettings::of_transducer(&s, probe)))
    }

    /// The monitor's settings for a transducer channel (the driver's
    /// settings, built from the file or by hand):
    ///
    /// * `sd_noise` \[Pa or m\]: the reading's noise combined with the
    ///   ADC's quantisation, `sqrt(noise^2 + lsb^2 / 12)`, `lsb` one code
    ///   in the reading's unit ([`transducer::Settings::units_per_code`]:
    ///   the sensor's span over the codes its signal band covers at
    ///   `monitor.adc_bits`);
    /// * `sd_accuracy` \[Pa or m\]: the class as a standard uncertainty,
    ///   `accuracy * span / sqrt(3)` (GUM 4.3.7, a uniform limit);
    /// * `sample_period` \[s\]: `1 / monitor.sample_hz`;
    /// * `probe`: the oil-temperature probe the monitor tests the device
    ///   with ([`ProbeModel::new`] of the file).
    pub fn of_transducer(s: &transducer::Settings, probe: ProbeModel) -> MonitorSettings {
        let quantity = match s.quantity {
            transducer::Quantity::PressureA => Quantity::ChamberA,
            transducer::Quantity::PressureB => Quantity::ChamberB,
            transducer::Quantity::PressureDifference => Quantity::Difference,
            transducer::Quantity::Displacement => Quantity::Displacement,
        };
        let lsb = s.units_per_code();
        MonitorSettings {
            quantity,
            sd_noise: libm::sqrtf(s.noise * s.noise + lsb * lsb / 12.0),
            sd_accuracy: s.class_uncertainty(),
            sample_period: s.period,
            probe,
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
