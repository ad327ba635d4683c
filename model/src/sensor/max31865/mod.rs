//! MAX31865 RTD-to-digital converter (Maxim/Analog Devices datasheet
//! 19-6478), over an `embedded-hal` 1.0 [`SpiDevice`](embedded_hal::spi::SpiDevice) (SPI mode 1 or 3,
//! up to 5 MHz; the device handles chip select).
//!
//! Register map (read address; write address = read | 0x80):
//!
//! | addr | register | notes |
//! |---|---|---|
//! | 0x00 | configuration | D7 V_BIAS, D6 auto conversion, D5 1-shot, D4 3-wire, D3:D2 fault detection cycle, D1 fault clear, D0 50 Hz filter |
//! | 0x01, 0x02 | RTD MSB, LSB | 15-bit code in D15:D1, D0 = fault |
//! | 0x03, 0x04 | high fault threshold MSB, LSB | |
//! | 0x05, 0x06 | low fault threshold MSB, LSB | |
//! | 0x07 | fault status | D7 RTD high, D6 RTD low, D5 REFIN- > 0.85 V_BIAS, D4 REFIN- < 0.85 V_BIAS (FORCE- open), D3 RTDIN- < 0.85 V_BIAS (FORCE- open), D2 over/under-voltage; D1:D0 unused (read 0) |
//!
//! `R_RTD = code * R_REF / 2^15`. In automatic conversion mode a new
//! reading is ready every 20 ms (50 Hz filter) or 16.7 ms (60 Hz).
//!
//! # Fault diagnosis
//!
//! Every conversion compares the code with the thresholds (RTD high/low:
//! an open or shorted element). The REFIN-/RTDIN- comparisons (FORCE- open,
//! a line shorted: faults whose readings can *appear valid*) are only made
//! by the fault-detection cycle, which the driver runs at start-up
//! ([`Max31865::configure`]) and then every [`Settings::diagnosis_every`]
//! readings ([`DIAGNOSIS_INTERVAL`], 10 s, on the boards of this project),
//! spread over [`TemperatureSource::read`](crate::sensor::TemperatureSource::read) calls so that no call makes more
//! than three short SPI transactions (tick budget):
//!
//! 1. after a reading, write `100X010Xb` (V_BIAS on, normally-off, D3:D2 =
//!    01: automatic delay; the datasheet's cycle inserts 100 us delays,
//!    well inside one conversion period);
//! 2. at the next call (a conversion period later), read the configuration
//!    (D3:D2 self-clear to 00 when the cycle is done), read the fault
//!    status, and write the configuration back to automatic conversion,
//!    clearing the status;
//! 3. the RTD registers hold the reading from before the cycle until the
//!    first new conversion is done: the next [`Settings::restart_readings`]
//!    calls return `Ok(None)` (66 ms, the datasheet's longest single
//!    conversion, plus one conversion period).
//!
//! A cycle that finds a wiring or voltage fault reports it, and every
//! reading is reported as that fault (such readings can look valid) until
//! a later cycle, run right after the next fresh reading, passes.
//!
//! A status byte with its unused bits set (0xFF: MISO stuck high, no chip)
//! or RTD-high and RTD-low together is not a chip's answer: a bus fault.
//!
//! With the `defmt` feature, `trace!`/`debug!` log the raw RTD words,
//! status bytes and SPI errors for sensor bring-up; the default filter
//! (`DEFMT_LOG=info`) compiles them out (enable with
//! `DEFMT_LOG=info,compensator::sensor=trace`).
//!
//! The driver imports nothing of the parameter file: [`Settings`] is its
//! own, and [`crate::sensor::device`] fills it from the file's
//! `[estimator]` section.
//!
//! Files: `registers.rs` (the register map, bits, the status decoding
//! [`classify`]), `driver.rs` ([`Max31865`]), `simulated.rs`
//! ([`SimulatedMax31865`], the register-level simulator).
//!
//! No maintained crate speaks `embedded-hal` 1.0 for this chip (the `max31865`
//! crate targets 0.2 and has no fault decoding), hence this small driver.

mod driver;
mod registers;
mod simulated;

pub use driver::{Max31865, Phase};
pub use registers::*;
pub use simulated::{BusError, SimulatedMax31865};

use super::rtd::Cvd;
use core::fmt;

/// RTD wiring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Wires {
    /// 2- or 4-wire.
    TwoOrFour,
    /// 3-wire.
    Three,
}

impl Wires {
    /// From the parameter file's wire count (2, 3 or 4); `None` for any
    /// other count.
    pub fn from_count(n: f64) -> Option<Wires> {
        match n {
            2.0 | 4.0 => Some(Wires::TwoOrFour),
            3.0 => Some(Wires::Three),
            _ => None,
        }
    }
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
    /// From the parameter file's mains frequency (50 or 60 Hz); `None` for
    /// any other frequency.
    pub fn from_hz(hz: f64) -> Option<Mains> {
        match hz {
            50.0 => Some(Mains::Hz50),
            60.0 => Some(Mains::Hz60),
            _ => None,
        }
    }

    /// Time between two readings in automatic conversion mode \[s\].
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
    OutOfRange(u16),
}

impl<E: fmt::Debug> fmt::Display for Error<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Spi(e) => write!(f, "MAX31865: SPI error {e:?}"),
            Error::Fault(status) => write!(f, "MAX31865: fault status {status:#04x} ({})", classify(*status)),
            Error::OutOfRange(code) => write!(f, "MAX31865: RTD code {code:#06x} maps to no temperature"),
        }
    }
}

impl<E: fmt::Debug> core::error::Error for Error<E> {}

/// The converter's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// RTD resistance at 0 C \[ohm\] (100 for a PT100).
    pub r0: f32,
    /// Reference resistor \[ohm\] (430 on the usual PT100 boards).
    pub reference: f32,
    /// Wiring.
    pub wires: Wires,
    /// Mains filter.
    pub mains: Mains,
    /// Callendar-Van Dusen coefficients of the element.
    pub cvd: Cvd,
    /// Temperatures outside which the converter flags a fault \[C\]
    /// (its high and low thresholds).
    pub fault_band: (f32, f32),
    /// Readings between two fault-detection cycles after the one at
    /// start-up (0: at start-up only).
    pub diagnosis_every: u32,
}

impl Settings {
    /// The usual breakout: PT100, 430 ohm, 3 wires, 50 Hz, IEC 60751, fault
    /// band -60..250 C, a detection cycle every [`DIAGNOSIS_INTERVAL`].
    pub const PT100_430: Settings = Settings {
        r0: 100.0,
        reference: 430.0,
        wires: Wires::Three,
        mains: Mains::Hz50,
        cvd: Cvd::IEC_60751,
        fault_band: (-60.0, 250.0),
        diagnosis_every: 500,
    };

    /// Readings (calls a conversion period apart) after a detection cycle
    /// that still return the RTD registers' stale value: [`FIRST_CONVERSION`]
    /// rounded up to whole periods, plus one.
    pub fn restart_readings(&self) -> u32 {
        let n = FIRST_CONVERSION / self.mains.conversion_period();
        let whole = n as u32;
        (if (whole as f32) < n { whole + 1 } else { whole }) + 1
    }
}
