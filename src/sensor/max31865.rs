//! MAX31865 RTD-to-digital converter (Maxim/Analog Devices datasheet
//! 19-6478), over an `embedded-hal` 1.0 [`SpiDevice`] (SPI mode 1 or 3,
//! up to 5 MHz; the device handles chip select).
//!
//! Register map (read address; write address = read | 0x80):
//!
//! | addr | register | notes |
//! |---|---|---|
//! | 0x00 | configuration | D7 V_BIAS, D6 auto conversion, D5 1-shot, D4 3-wire, D3:D2 fault detection, D1 fault clear, D0 50 Hz filter |
//! | 0x01, 0x02 | RTD MSB, LSB | 15-bit code in D15:D1, D0 = fault |
//! | 0x03, 0x04 | high fault threshold MSB, LSB | |
//! | 0x05, 0x06 | low fault threshold MSB, LSB | |
//! | 0x07 | fault status | D7 RTD high, D6 RTD low, D5 REFIN- > 0.85 V_BIAS, D4 REFIN- < 0.85 V_BIAS (FORCE- open), D3 RTDIN- < 0.85 V_BIAS (FORCE- open), D2 over/under-voltage |
//!
//! `R_RTD = code * R_REF / 2^15`. In automatic conversion mode a new
//! reading is ready every 20 ms (50 Hz filter) or 16.7 ms (60 Hz).
//!
//! No maintained crate speaks `embedded-hal` 1.0 for this chip (the `max31865`
//! crate targets 0.2 and has no fault decoding), hence this small driver.

use super::{SensorFault, TemperatureSource, rtd};
use embedded_hal::spi::{Operation, SpiDevice};

/// Configuration register.
pub const REG_CONFIG: u8 = 0x00;
/// RTD code, most significant byte (the LSB follows).
pub const REG_RTD_MSB: u8 = 0x01;
/// High fault threshold, MSB.
pub const REG_HIGH_FAULT_MSB: u8 = 0x03;
/// Fault status register.
pub const REG_FAULT_STATUS: u8 = 0x07;
/// Added to a register address to write it.
pub const WRITE: u8 = 0x80;

/// Configuration bits.
pub mod config {
    /// Bias voltage on.
    pub const V_BIAS: u8 = 0x80;
    /// Automatic conversion (continuous).
    pub const AUTO: u8 = 0x40;
    /// One-shot conversion.
    pub const ONE_SHOT: u8 = 0x20;
    /// 3-wire RTD (clear for 2- and 4-wire).
    pub const THREE_WIRE: u8 = 0x10;
    /// Clear the fault status (self-clearing).
    pub const FAULT_CLEAR: u8 = 0x02;
    /// 50 Hz notch filter (clear: 60 Hz).
    pub const FILTER_50HZ: u8 = 0x01;
}

/// Fault status bits.
pub mod fault {
    /// RTD code above the high threshold.
    pub const RTD_HIGH: u8 = 0x80;
    /// RTD code below the low threshold.
    pub const RTD_LOW: u8 = 0x40;
    /// REFIN- above 0.85 V_BIAS.
    pub const REFIN_HIGH: u8 = 0x20;
    /// REFIN- below 0.85 V_BIAS (FORCE- open).
    pub const REFIN_LOW: u8 = 0x10;
    /// RTDIN- below 0.85 V_BIAS (FORCE- open).
    pub const RTDIN_LOW: u8 = 0x08;
    /// Over- or under-voltage.
    pub const VOLTAGE: u8 = 0x04;
}

/// RTD wiring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Wires {
    /// 2- or 4-wire.
    TwoOrFour,
    /// 3-wire.
    Three,
}

/// Mains filter of the converter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mains {
    /// 50 Hz rejection (conversion every 20 ms).
    Hz50,
    /// 60 Hz rejection (conversion every 16.7 ms).
    Hz60,
}

impl Mains {
    /// Time between two readings in automatic conversion mode [s].
    pub fn conversion_period(self) -> f32 {
        match self {
            Mains::Hz50 => 1.0 / 50.0,
            Mains::Hz60 => 1.0 / 60.0,
        }
    }
}

/// Driver errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error<E> {
    /// SPI error.
    Spi(E),
    /// The converter reported a fault; the status register's value.
    Fault(u8),
    /// The code maps to no temperature of the RTD's range.
    Implausible(u16),
}

/// The converter's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// RTD resistance at 0 C [ohm] (100 for a PT100).
    pub r0: f32,
    /// Reference resistor [ohm] (430 on the usual PT100 boards).
    pub reference: f32,
    /// Wiring.
    pub wires: Wires,
    /// Mains filter.
    pub mains: Mains,
    /// Temperatures outside which the converter flags a fault [C]
    /// (its high and low thresholds).
    pub fault_band: (f32, f32),
}

/// A MAX31865 on an SPI device.
#[derive(Debug)]
pub struct Max31865<SPI> {
    spi: SPI,
    settings: Settings,
}

/// The 15-bit code of resistance `r` [ohm] (rounded to the nearest code,
/// as the converter's ADC does), saturated to the code range.
pub fn code_of(settings: &Settings, r: f32) -> u16 {
    let c = r / settings.reference * 32768.0 + 0.5;
    if c >= 32767.0 {
        32767
    } else if c > 0.0 {
        c as u16
    } else {
        0
    }
}

impl<SPI: SpiDevice> Max31865<SPI> {
    /// A driver; call [`Max31865::configure`] before reading.
    pub fn new(spi: SPI, settings: Settings) -> Self {
        Max31865 { spi, settings }
    }

    /// Releases the SPI device.
    pub fn release(self) -> SPI {
        self.spi
    }

    /// The SPI device (for a simulated converter: to drive the simulation).
    pub fn device_mut(&mut self) -> &mut SPI {
        &mut self.spi
    }

    /// The configuration byte for continuous conversion.
    pub fn config_byte(&self) -> u8 {
        let mut c = config::V_BIAS | config::AUTO;
        if self.settings.wires == Wires::Three {
            c |= config::THREE_WIRE;
        }
        if self.settings.mains == Mains::Hz50 {
            c |= config::FILTER_50HZ;
        }
        c
    }

    /// Writes the fault thresholds and starts continuous conversion
    /// (clearing any latched fault).
    pub fn configure(&mut self) -> Result<(), Error<SPI::Error>> {
        let (lo, hi) = self.settings.fault_band;
        let hi = code_of(&self.settings, rtd::resistance(self.settings.r0, hi)) << 1;
        let lo = code_of(&self.settings, rtd::resistance(self.settings.r0, lo)) << 1;
        let thresholds = [
            REG_HIGH_FAULT_MSB | WRITE,
            (hi >> 8) as u8,
            hi as u8,
            (lo >> 8) as u8,
            lo as u8,
        ];
        self.spi.write(&thresholds).map_err(Error::Spi)?;
        self.spi
            .write(&[REG_CONFIG | WRITE, self.config_byte() | config::FAULT_CLEAR])
            .map_err(Error::Spi)
    }

    /// Reads the fault status register.
    pub fn fault_status(&mut self) -> Result<u8, Error<SPI::Error>> {
        let mut status = [0u8];
        self.spi
            .transaction(&mut [Operation::Write(&[REG_FAULT_STATUS]), Operation::Read(&mut status)])
            .map_err(Error::Spi)?;
        Ok(status[0])
    }

    /// Clears latched faults (keeps the conversion running).
    pub fn clear_faults(&mut self) -> Result<(), Error<SPI::Error>> {
        self.spi
            .write(&[REG_CONFIG | WRITE, self.config_byte() | config::FAULT_CLEAR])
            .map_err(Error::Spi)
    }

    /// Reads the 15-bit RTD code. A set fault bit makes this read the
    /// status, clear it and return [`Error::Fault`].
    pub fn read_code(&mut self) -> Result<u16, Error<SPI::Error>> {
        let mut raw = [0u8; 2];
        self.spi
            .transaction(&mut [Operation::Write(&[REG_RTD_MSB]), Operation::Read(&mut raw)])
            .map_err(Error::Spi)?;
        let word = u16::from_be_bytes(raw);
        if word & 1 != 0 {
            let status = self.fault_status()?;
            self.clear_faults()?;
            return Err(Error::Fault(status));
        }
        Ok(word >> 1)
    }

    /// Reads the temperature [C].
    pub fn read_temperature(&mut self) -> Result<f32, Error<SPI::Error>> {
        let code = self.read_code()?;
        let r = code as f32 * self.settings.reference / 32768.0;
        if code == 0 || code == 0x7FFF {
            return Err(Error::Implausible(code));
        }
        rtd::temperature(self.settings.r0, r).ok_or(Error::Implausible(code))
    }
}

/// The fault a status byte stands for (the most specific bit first).
pub fn classify(status: u8) -> SensorFault {
    if status & (fault::REFIN_HIGH | fault::REFIN_LOW | fault::RTDIN_LOW) != 0 {
        SensorFault::Wiring
    } else if status & fault::VOLTAGE != 0 {
        SensorFault::Voltage
    } else if status & fault::RTD_HIGH != 0 {
        SensorFault::RtdHigh
    } else if status & fault::RTD_LOW != 0 {
        SensorFault::RtdLow
    } else {
        SensorFault::Implausible
    }
}

impl<SPI: SpiDevice> TemperatureSource for Max31865<SPI> {
    /// Reads the latest conversion. The converter runs continuously, so
    /// every call yields a sample (the caller paces calls to the
    /// conversion rate).
    fn read(&mut self) -> Result<Option<f32>, SensorFault> {
        match self.read_temperature() {
            Ok(t) => Ok(Some(t)),
            Err(Error::Spi(_)) => Err(SensorFault::Bus),
            Err(Error::Fault(status)) => Err(classify(status)),
            Err(Error::Implausible(_)) => Err(SensorFault::Implausible),
        }
    }
}
