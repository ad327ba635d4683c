//! Where the estimator's temperature comes from.
//!
//! * [`TemperatureSource`]: the one interface the estimator needs.
//! * [`rtd`]: platinum RTD resistance to temperature (Callendar-Van Dusen).
//! * [`max31865`]: the MAX31865 RTD-to-digital converter over an
//!   `embedded-hal` 1.0 [`SpiDevice`](embedded_hal::spi::SpiDevice), the
//!   usual front end of a PT100 in oil.

pub mod max31865;
pub mod rtd;
pub mod simulated;

/// Why a sensor produced no temperature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensorFault {
    /// The bus transaction failed.
    Bus,
    /// The converter flagged the RTD reading above its high threshold
    /// (typically an open RTD).
    RtdHigh,
    /// The converter flagged the RTD reading below its low threshold
    /// (typically a shorted RTD).
    RtdLow,
    /// A force or reference line is open or shorted (REFIN-/RTDIN- faults).
    Wiring,
    /// Over- or under-voltage on an input.
    Voltage,
    /// A reading that no RTD can produce (saturated code, NaN,
    /// outside the element's range).
    Implausible,
}

impl core::fmt::Display for SensorFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            SensorFault::Bus => "the sensor's bus transaction failed",
            SensorFault::RtdHigh => "RTD reading above the high threshold (open RTD?)",
            SensorFault::RtdLow => "RTD reading below the low threshold (shorted RTD?)",
            SensorFault::Wiring => "a force or reference line of the RTD is open or shorted",
            SensorFault::Voltage => "over- or under-voltage on a converter input",
            SensorFault::Implausible => "a reading no RTD can produce",
        })
    }
}

impl core::error::Error for SensorFault {}

/// A source of oil temperature samples \[C\].
///
/// `Ok(Some(t))`: a new sample; `Ok(None)`: nothing new since the last call
/// (the estimator keeps its filtered value); `Err(fault)`: the sample is
/// missing and why. Implementations must not block for long: the estimator
/// calls this once per tick.
pub trait TemperatureSource {
    /// Polls for a new sample.
    fn read(&mut self) -> Result<Option<f32>, SensorFault>;
}

impl<S: TemperatureSource + ?Sized> TemperatureSource for &mut S {
    fn read(&mut self) -> Result<Option<f32>, SensorFault> {
        (**self).read()
    }
}
