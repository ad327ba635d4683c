//! The MAX31865 driver over an `embedded-hal` 1.0 [`SpiDevice`], with
//! the fault-detection schedule of the module docs.

use super::registers::{
    REG_CONFIG, REG_FAULT_STATUS, REG_HIGH_FAULT_MSB, REG_RTD_MSB, WRITE, classify, code_of, config,
};
use super::{Error, Mains, Settings, Wires};
use crate::sensor::{Detail, SensorFault, TemperatureSource};
use embedded_hal::spi::{Operation, SpiDevice};

/// Where the driver is in its diagnosis schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// The chip answered with a configuration other than the one written
    /// (a reset, a stuck bus): the next call configures it again.
    Idle,
    /// Converting continuously; a detection cycle starts after this many
    /// more readings.
    Converting {
        /// Readings left before the next cycle.
        until_cycle: u32,
    },
    /// A detection cycle was started; the next call reads its result.
    Detecting {
        /// Calls that found it still running.
        polls: u8,
    },
    /// Back in automatic conversion after a cycle: the RTD registers hold
    /// the stale reading for this many more calls.
    Restarting {
        /// Calls left before the first fresh reading.
        stale: u32,
    },
}

/// A MAX31865 on an SPI device.
#[derive(Debug)]
pub struct Max31865<SPI> {
    spi: SPI,
    settings: Settings,
    phase: Phase,
    /// The fault the last detection cycle found (readings are reported as
    /// this fault until a cycle passes).
    suspect: Option<SensorFault>,
}

/// A name for an SPI error's kind (bring-up logging).
#[cfg(feature = "defmt")]
fn kind_name(kind: embedded_hal::spi::ErrorKind) -> &'static str {
    use embedded_hal::spi::ErrorKind;
    match kind {
        ErrorKind::Overrun => "overrun",
        ErrorKind::ModeFault => "mode fault",
        ErrorKind::FrameFormat => "frame format",
        ErrorKind::ChipSelectFault => "chip select",
        _ => "other",
    }
}

impl<SPI: SpiDevice> Max31865<SPI> {
    /// A driver; call [`Max31865::configure`] before reading (until then
    /// it reads the RTD registers as if the chip were converting).
    pub fn new(spi: SPI, settings: Settings) -> Self {
        Max31865 {
            spi,
            settings,
            phase: Phase::Converting {
                until_cycle: settings.diagnosis_every,
            },
            suspect: None,
        }
    }

    /// Releases the SPI device.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// The SPI device (for a simulated converter: to drive the simulation).
    pub fn device_mut(&mut self) -> &mut SPI {
        &mut self.spi
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Where the diagnosis schedule stands.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The base configuration byte: V_BIAS, wiring, filter.
    fn base(&self) -> u8 {
        let mut c = config::V_BIAS;
        if self.settings.wires == Wires::Three {
            c |= config::THREE_WIRE;
        }
        if self.settings.mains == Mains::Hz50 {
            c |= config::FILTER_50HZ;
        }
        c
    }

    /// The configuration byte for continuous conversion.
    pub fn config_byte(&self) -> u8 {
        self.base() | config::AUTO
    }

    fn spi_error(e: SPI::Error) -> Error<SPI::Error> {
        #[cfg(feature = "defmt")]
        defmt::debug!(
            "MAX31865 SPI error: {=str}",
            kind_name(embedded_hal::spi::Error::kind(&e))
        );
        Error::Spi(e)
    }

    fn write_config(&mut self, value: u8) -> Result<(), Error<SPI::Error>> {
        self.spi.write(&[REG_CONFIG | WRITE, value]).map_err(Self::spi_error)
    }

    /// Writes the fault thresholds, clears the fault status with the bias
    /// on, and starts the start-up fault-detection cycle (its result is
    /// read by the next [`TemperatureSource::read`]; continuous conversion
    /// resumes after it).
    ///
    /// # Errors
    ///
    /// [`Error::Spi`] when a transaction fails; the diagnosis [`Phase`] is
    /// then unchanged.
    pub fn configure(&mut self) -> Result<(), Error<SPI::Error>> {
        let (lo, hi) = self.settings.fault_band;
        let cvd = self.settings.cvd;
        let hi = code_of(&self.settings, cvd.resistance(self.settings.r0, hi)) << 1;
        let lo = code_of(&self.settings, cvd.resistance(self.settings.r0, lo)) << 1;
        let thresholds = [
            REG_HIGH_FAULT_MSB | WRITE,
            (hi >> 8) as u8,
            hi as u8,
            (lo >> 8) as u8,
            lo as u8,
        ];
        self.spi.write(&thresholds).map_err(Self::spi_error)?;
        // The clear is written with D5, D3, D2 = 0 (datasheet), so apart
        // from the cycle's start.
        self.write_config(self.base() | config::FAULT_CLEAR)?;
        self.start_cycle()
    }

    /// Starts an automatic fault-detection cycle: `100X010Xb`.
    fn start_cycle(&mut self) -> Result<(), Error<SPI::Error>> {
        self.write_config(self.base() | config::FAULT_CYCLE_AUTO)?;
        self.phase = Phase::Detecting { polls: 0 };
        Ok(())
    }

    fn read_register(&mut self, reg: u8) -> Result<u8, Error<SPI::Error>> {
        let mut value = [0u8];
        self.spi
            .transaction(&mut [Operation::Write(&[reg]), Operation::Read(&mut value)])
            .map_err(Self::spi_error)?;
        Ok(value[0])
    }

    /// Reads the fault status register.
    ///
    /// # Errors
    ///
    /// [`Error::Spi`] when the transaction fails.
    pub fn fault_status(&mut self) -> Result<u8, Error<SPI::Error>> {
        let status = self.read_register(REG_FAULT_STATUS)?;
        #[cfg(feature = "defmt")]
        defmt::debug!("MAX31865 fault status {=u8:#04x}", status);
        Ok(status)
    }

    /// Clears latched faults (keeps the conversion running).
    ///
    /// # Errors
    ///
    /// [`Error::Spi`] when the transaction fails.
    pub fn clear_faults(&mut self) -> Result<(), Error<SPI::Error>> {
        self.write_config(self.config_byte() | config::FAULT_CLEAR)
    }

    /// Reads the 15-bit RTD code. A set fault bit makes this read the
    /// status, clear it and return [`Error::Fault`].
    ///
    /// # Errors
    ///
    /// [`Error::Fault`] with the status register when the code's fault bit
    /// is set; [`Error::Spi`] when a transaction fails.
    pub fn read_code(&mut self) -> Result<u16, Error<SPI::Error>> {
        let mut raw = [0u8; 2];
        self.spi
            .transaction(&mut [Operation::Write(&[REG_RTD_MSB]), Operation::Read(&mut raw)])
            .map_err(Self::spi_error)?;
        let word = u16::from_be_bytes(raw);
        #[cfg(feature = "defmt")]
        defmt::trace!("MAX31865 RTD word {=u16:#06x}", word);
        if word & 1 != 0 {
            let status = self.fault_status()?;
            self.clear_faults()?;
            return Err(Error::Fault(status));
        }
        Ok(word >> 1)
    }

    /// Reads the temperature \[C\] of the latest conversion.
    ///
    /// # Errors
    ///
    /// As [`Max31865::read_code`], and [`Error::OutOfRange`] for a code
    /// of zero or full scale, or one whose resistance no RTD temperature
    /// has ([`crate::sensor::rtd::Cvd::temperature`]).
    pub fn read_temperature(&mut self) -> Result<f32, Error<SPI::Error>> {
        let code = self.read_code()?;
        let r = code as f32 * self.settings.reference / 32768.0;
        if code == 0 || code == 0x7FFF {
            return Err(Error::OutOfRange(code));
        }
        self.settings
            .cvd
            .temperature(self.settings.r0, r)
            .ok_or(Error::OutOfRange(code))
    }

    /// One reading, as the estimator wants it.
    fn sample(&mut self) -> Result<Option<f32>, SensorFault> {
        let reading = match self.read_temperature() {
            Ok(t) => Ok(Some(t)),
            Err(Error::Spi(_)) => Err(SensorFault::Bus),
            Err(Error::Fault(status)) => Err(classify(status)),
            Err(Error::OutOfRange(code)) => Err(SensorFault::OutOfRange(Detail::code(code))),
        };
        match (self.suspect, reading) {
            // A wiring fault makes readings look valid: not one is trusted.
            (Some(f), Ok(_)) => Err(f),
            (_, r) => r,
        }
    }

    /// The result of the running detection cycle: reads the configuration
    /// and the status, and returns to continuous conversion.
    fn finish_cycle(&mut self, polls: u8) -> Result<Option<f32>, SensorFault> {
        let cfg = self.read_register(REG_CONFIG).map_err(|_| SensorFault::Bus)?;
        #[cfg(feature = "defmt")]
        defmt::debug!("MAX31865 configuration {=u8:#04x} after the detection cycle", cfg);
        if cfg & !config::FAULT_CYCLE != self.base() {
            // Not what was written (0xFF: MISO stuck high; 0x00: stuck low
            // or a chip reset by a supply glitch): configure again.
            self.phase = Phase::Idle;
            return Err(SensorFault::Bus);
        }
        if cfg & config::FAULT_CYCLE != 0 {
            // Still running: it needs a few hundred microseconds, a call
            // is a conversion period later. Give it two more calls, then
            // restart.
            if polls < 2 {
                self.phase = Phase::Detecting { polls: polls + 1 };
                return Ok(None);
            }
            let _ = self.start_cycle();
            return Err(SensorFault::Stale);
        }
        let status = self.fault_status().map_err(|_| SensorFault::Bus)?;
        self.write_config(self.config_byte() | config::FAULT_CLEAR)
            .map_err(|_| SensorFault::Bus)?;
        self.phase = Phase::Restarting {
            stale: self.settings.restart_readings(),
        };
        if status == 0 {
            self.suspect = None;
            return Ok(None);
        }
        let f = classify(status);
        // Conversion faults (RTD high/low) show in every reading anyway;
        // the rest persist until a cycle passes.
        self.suspect = match f {
            SensorFault::Wiring(_) | SensorFault::Supply(_) | SensorFault::Bus => Some(f),
            _ => None,
        };
        Err(f)
    }
}

impl<SPI: SpiDevice> TemperatureSource for Max31865<SPI> {
    /// Reads the latest conversion and advances the diagnosis schedule
    /// (see the module docs); the caller paces calls to the conversion
    /// rate. Before [`Max31865::configure`] succeeded (or after the chip
    /// was found unconfigured), a call configures it again.
    fn read(&mut self) -> Result<Option<f32>, SensorFault> {
        match self.phase {
            Phase::Idle => match self.configure() {
                Ok(()) => Ok(None),
                Err(_) => Err(SensorFault::Bus),
            },
            Phase::Converting { until_cycle } => {
                let reading = self.sample();
                if self.settings.diagnosis_every > 0 && until_cycle <= 1 {
                    // The cycle stops the conversions: after this reading.
                    if self.start_cycle().is_err() {
                        self.phase = Phase::Converting { until_cycle: 1 };
                        return Err(SensorFault::Bus);
                    }
                } else {
                    self.phase = Phase::Converting {
                        until_cycle: until_cycle.saturating_sub(1),
                    };
                }
                reading
            }
            Phase::Detecting { polls } => self.finish_cycle(polls),
            Phase::Restarting { stale } => {
                if stale > 1 {
                    self.phase = Phase::Restarting { stale: stale - 1 };
                    return Ok(None);
                }
                // A fault found: check again right after this reading.
                let until_cycle = if self.suspect.is_some() {
                    1
                } else {
                    self.settings.diagnosis_every
                };
                self.phase = Phase::Converting { until_cycle };
                let reading = self.sample();
                if until_cycle == 1 && self.start_cycle().is_err() {
                    return Err(SensorFault::Bus);
                }
                reading
            }
        }
    }
}
