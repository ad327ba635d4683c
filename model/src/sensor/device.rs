//! The edge between the parameter file and the drivers: the drivers
//! (`max31865`, `ntc`) each take their own settings struct and import
//! nothing of the file's schema; this module fills those structs from the
//! file's `[estimator]` section and says which sensor the file chose, and
//! the monitor's transducer settings from its `[monitor]` section
//! ([`monitor_settings`]).

use super::max31865::{self, DIAGNOSIS_INTERVAL, Mains, Wires};
use super::ntc::{self, Curve};
use super::rtd::Cvd;
use super::transducer::{self, SettingsError};
use crate::params::{RawEstimator, RawParams};

/// The sensor a parameter file chose (`estimator.sensor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensorKind {
    /// A platinum RTD through a MAX31865 (`"rtd"`, the default).
    Rtd,
    /// An NTC thermistor in a divider on the STM32F405's ADC (`"ntc"`).
    Ntc,
}

impl SensorKind {
    /// The kind `raw` names.
    pub fn of(raw: &RawEstimator) -> SensorKind {
        if raw.is_ntc() { SensorKind::Ntc } else { SensorKind::Rtd }
    }

    /// The name the parameter file uses.
    pub fn name(self) -> &'static str {
        match self {
            SensorKind::Rtd => "rtd",
            SensorKind::Ntc => "ntc",
        }
    }
}

/// The mains filter of the file (`estimator.mains_hz`; 50 Hz for anything
/// validation would refuse).
pub fn mains(raw: &RawEstimator) -> Mains {
    Mains::from_hz(raw.mains_hz).unwrap_or(Mains::Hz50)
}

/// Time between two sensor readings \[s\], either kind: the MAX31865's
/// conversion period with its mains filter; the NTC is read at the same
/// rate (one mains period: its oversampled conversions are a burst, and
/// the estimator's observer is tuned to the one sample period).
pub fn sample_period(raw: &RawEstimator) -> f32 {
    mains(raw).conversion_period()
}

impl max31865::Settings {
    /// From the parameter file's `[estimator]` section (validated: wire
    /// count 2/3/4 and mains 50/60 Hz; anything else falls back to 3 wires
    /// and 50 Hz): the element, the reference, the filter, the
    /// Callendar-Van Dusen coefficients, the oil's range as the fault band,
    /// and a detection cycle every [`DIAGNOSIS_INTERVAL`].
    pub fn from_params(raw: &RawEstimator) -> max31865::Settings {
        let mains = mains(raw);
        let per = DIAGNOSIS_INTERVAL / mains.conversion_period() + 0.5;
        max31865::Settings {
            r0: raw.rtd_r0 as f32,
            reference: raw.rtd_reference as f32,
            wires: Wires::from_count(raw.rtd_wires).unwrap_or(Wires::Three),
            mains,
            cvd: Cvd {
                a: raw.rtd_a as f32,
                b: raw.rtd_b as f32,
                c: raw.rtd_c as f32,
            },
            fault_band: (raw.oil_min as f32, raw.oil_max as f32),
            diagnosis_every: per as u32,
        }
    }
}

impl ntc::Settings {
    /// From the parameter file's `[estimator]` section (validated): the
    /// curve (Steinhart-Hart where `ntc_sh_a`, `ntc_sh_b`, `ntc_sh_c` are
    /// given, else the beta equation with `ntc_r25`, `ntc_beta`), the
    /// divider's series resistor, the ADC's bits and oversampling, the open
    /// and short bands ([`crate::params::NTC_FAULT_CODES`]), the oil's range
    /// as the element's range, and the sample period ([`sample_period`]).
    pub fn from_params(raw: &RawEstimator) -> ntc::Settings {
        let curve = if raw.ntc_steinhart_hart() {
            Curve::SteinhartHart {
                a: raw.ntc_sh_a as f32,
                b: raw.ntc_sh_b as f32,
                c: raw.ntc_sh_c as f32,
            }
        } else {
            Curve::Beta {
                r25: raw.ntc_r25 as f32,
                beta: raw.ntc_beta as f32,
            }
        };
        let bits = raw.adc_bits as u8;
        ntc::Settings {
            curve,
            series: raw.ntc_series as f32,
            bits: if (6..=12).contains(&bits) { bits } else { 12 },
            oversampling: (raw.ntc_oversampling as u8).max(1),
            fault_codes: crate::params::NTC_FAULT_CODES as u16,
            band: (raw.oil_min as f32, raw.oil_max as f32),
            period: sample_period(raw),
        }
    }
}

/// The condition monitor's second sensor of a parameter set: `None`
/// without one (no `[monitor]` section, or `sensor = "none"`), else its
/// transducer settings (`TryFrom<&RawMonitor>`), the set validated first
/// (the monitor's rules against the device: its range covers the
/// chambers' pressures or the stroke, its rate at most the tick's).
///
/// # Errors
///
/// [`SettingsError::Param`] naming the field the set's validation or the
/// settings refuse.
pub fn monitor_settings(raw: &RawParams) -> Result<Option<transducer::Settings>, SettingsError> {
    if !raw.monitor.has_sensor() {
        return Ok(None);
    }
    raw.validate()?;
    transducer::Settings::try_from(&raw.monitor).map(Some)
}
