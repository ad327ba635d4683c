//! The NTC driver: oversampled ADC codes to a temperature, with the fault
//! decoding of the module docs.

use super::Settings;
use crate::sensor::{Detail, SensorFault, TemperatureSource};
use core::fmt;

/// One ADC channel, as the NTC driver needs it (`embedded-hal` 1.0 has no
/// ADC trait).
pub trait AdcChannel {
    /// Why a conversion failed.
    type Error: fmt::Debug;

    /// Runs one conversion and returns its right-aligned code
    /// (`0..2^bits`).
    ///
    /// # Errors
    ///
    /// The ADC's, when the conversion did not give a code.
    fn read_code(&mut self) -> Result<u16, Self::Error>;

    /// The [`SensorFault`] an error stands for ([`SensorFault::Bus`]
    /// unless the channel knows better: a conversion that never ended is
    /// [`SensorFault::Stale`]).
    fn fault(error: &Self::Error) -> SensorFault {
        let _ = error;
        SensorFault::Bus
    }
}

impl<A: AdcChannel + ?Sized> AdcChannel for &mut A {
    type Error = A::Error;

    fn read_code(&mut self) -> Result<u16, A::Error> {
        (**self).read_code()
    }

    fn fault(error: &A::Error) -> SensorFault {
        A::fault(error)
    }
}

/// Driver errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error<E> {
    /// The ADC's error.
    Adc(E),
    /// The mean code is within the open band of full scale.
    Open(u16),
    /// The mean code is within the short band of 0.
    Short(u16),
    /// The mean code maps to no temperature of the element's range.
    OutOfRange(u16),
}

impl<E: fmt::Debug> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Adc(e) => write!(f, "NTC: ADC error {e:?}"),
            Error::Open(c) => write!(f, "NTC: code {c} near full scale (open NTC)"),
            Error::Short(c) => write!(f, "NTC: code {c} near 0 (shorted NTC)"),
            Error::OutOfRange(c) => write!(f, "NTC: code {c} maps to no temperature of the element's range"),
        }
    }
}

impl<E: fmt::Debug> core::error::Error for Error<E> {}

/// An NTC thermistor in a divider on an ADC channel.
#[derive(Debug)]
pub struct Ntc<ADC> {
    adc: ADC,
    settings: Settings,
}

impl<ADC: AdcChannel> Ntc<ADC> {
    /// A driver reading `adc` with `settings`.
    pub fn new(adc: ADC, settings: Settings) -> Self {
        Ntc { adc, settings }
    }

    /// Releases the ADC channel.
    pub fn release(self) -> ADC {
        self.adc
    }

    /// The ADC channel (for a simulated ADC: to drive the simulation).
    pub fn device_mut(&mut self) -> &mut ADC {
        &mut self.adc
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The mean of [`Settings::oversampling`] conversions (at least one)
    /// \[codes\].
    ///
    /// # Errors
    ///
    /// [`Error::Adc`] at the first conversion that fails.
    pub fn mean_code(&mut self) -> Result<f32, Error<ADC::Error>> {
        let n = self.settings.oversampling.max(1);
        let mut sum = 0u32;
        for _ in 0..n {
            sum += u32::from(self.adc.read_code().map_err(Error::Adc)?);
        }
        Ok(sum as f32 / f32::from(n))
    }

    /// Reads the temperature \[C\].
    ///
    /// # Errors
    ///
    /// As [`Ntc::mean_code`]; [`Error::Open`], [`Error::Short`] for a mean
    /// code in the open or short band, [`Error::OutOfRange`] for a
    /// temperature outside [`Settings::band`].
    pub fn read_temperature(&mut self) -> Result<f32, Error<ADC::Error>> {
        let mean = self.mean_code()?;
        let s = &self.settings;
        let full = f32::from(s.full_scale());
        let band = f32::from(s.fault_codes);
        // The mean as a code for the error's detail (0..2^bits, exact).
        let code = (mean + 0.5) as u16;
        if mean >= full - 1.0 - band {
            return Err(Error::Open(code));
        }
        if mean <= band {
            return Err(Error::Short(code));
        }
        match s.temperature_of(mean) {
            Some(t) if t >= s.band.0 && t <= s.band.1 => Ok(t),
            _ => Err(Error::OutOfRange(code)),
        }
    }
}

impl<ADC: AdcChannel> TemperatureSource for Ntc<ADC> {
    /// A new sample every call (the caller paces calls to
    /// [`Settings::period`]).
    fn read(&mut self) -> Result<Option<f32>, SensorFault> {
        match self.read_temperature() {
            Ok(t) => Ok(Some(t)),
            Err(Error::Adc(e)) => Err(ADC::fault(&e)),
            Err(Error::Open(c)) => Err(SensorFault::OpenCircuit(Detail::code(c))),
            Err(Error::Short(c)) => Err(SensorFault::ShortCircuit(Detail::code(c))),
            Err(Error::OutOfRange(c)) => Err(SensorFault::OutOfRange(Detail::code(c))),
        }
    }
}
