//! The transducer driver: ADC codes to a reading, with the level, stuck
//! and noise checks of the module docs.

use super::{Checks, Settings};
use crate::sensor::SensorFault;
use crate::sensor::ntc::AdcChannel;
use core::fmt;

/// Driver errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error<E> {
    /// The ADC's error.
    Adc(E),
    /// The code is a fault level, or the codes are stuck or noisy.
    Fault(SensorFault),
}

impl<E: fmt::Debug> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Adc(e) => write!(f, "transducer: ADC error {e:?}"),
            Error::Fault(fault) => write!(f, "transducer: {fault}"),
        }
    }
}

impl<E: fmt::Debug> core::error::Error for Error<E> {}

/// A pressure or displacement transducer on an ADC channel (any
/// [`AdcChannel`]: the board's, or [`RegisterAdc`](crate::sensor::ntc::RegisterAdc)
/// over the STM32F4's registers or the [`SimulatedTransducer`](super::SimulatedTransducer)).
#[derive(Debug)]
pub struct Transducer<ADC> {
    adc: ADC,
    settings: Settings,
    checks: Checks,
}

impl<ADC: AdcChannel> Transducer<ADC> {
    /// A driver reading `adc` with `settings`.
    pub fn new(adc: ADC, settings: Settings) -> Self {
        Transducer {
            adc,
            checks: Checks::new(&settings),
            settings,
        }
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

    /// The stuck and noise checks' state.
    pub fn checks(&self) -> &Checks {
        &self.checks
    }

    /// Reads one code and decodes it to a reading \[Pa or m\]: the level
    /// faults first ([`Settings::classify`]; one resets the checks), then
    /// the stuck and noise checks ([`Checks::update`], fed every code that
    /// is a reading).
    ///
    /// # Errors
    ///
    /// [`Error::Adc`] when the conversion fails; [`Error::Fault`] with
    /// [`SensorFault::OpenCircuit`], [`SensorFault::ShortCircuit`],
    /// [`SensorFault::OutOfRange`], [`SensorFault::Stuck`] or
    /// [`SensorFault::Noisy`] (the code as its detail).
    pub fn read_reading(&mut self) -> Result<f32, Error<ADC::Error>> {
        let code = self.adc.read_code().map_err(Error::Adc)?;
        match self.settings.classify(code) {
            Ok(reading) => {
                self.checks.update(code).map_err(Error::Fault)?;
                Ok(reading)
            }
            Err(fault) => {
                // A fault level is no sample of the noise: the checks start
                // again from the next reading (else the jump back from an
                // open loop would read as a noisy window).
                self.checks.reset();
                Err(Error::Fault(fault))
            }
        }
    }

    /// Reads one reading \[Pa or m\] (the caller paces calls to
    /// [`Settings::period`]).
    ///
    /// # Errors
    ///
    /// As [`Transducer::read_reading`], the ADC's error as its
    /// [`AdcChannel::fault`] ([`SensorFault::Stale`] for a conversion that
    /// never ended on the STM32F4's registers).
    pub fn read(&mut self) -> Result<f32, SensorFault> {
        match self.read_reading() {
            Ok(v) => Ok(v),
            Err(Error::Adc(e)) => Err(ADC::fault(&e)),
            Err(Error::Fault(f)) => Err(f),
        }
    }
}
