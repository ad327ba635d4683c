//! MAX31865 RTD-to-digital converter (Maxim/Analog Devices datasheet
//! 19-6478), over an `embedded-hal` 1.0 [`SpiDevice`] (SPI mode 1 or 3,
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
//! spread over [`TemperatureSource::read`] calls so that no call makes more
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
//! No maintained crate speaks `embedded-hal` 1.0 for this chip (the `max31865`
//! crate targets 0.2 and has no fault decoding), hence this small driver.

use super::rtd::Cvd;
use super::{SensorFault, TemperatureSource};
use crate::params::RawEstimator;
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

/// Time between two fault-detection cycles after the one at start-up \[s\]
/// (what [`Settings::from_params`] sets).
pub const DIAGNOSIS_INTERVAL: f32 = 10.0;
/// Longest conversion after a return to automatic conversion \[s\]: the
/// datasheet's single-conversion time with the 50 Hz filter (66 ms max;
/// 55 ms at 60 Hz).
pub const FIRST_CONVERSION: f32 = 0.066;

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
    /// Fault-detection cycle control, D3:D2 (00: none or done).
    pub const FAULT_CYCLE: u8 = 0x0C;
    /// Fault detection with automatic delay (D3:D2 = 01).
    pub const FAULT_CYCLE_AUTO: u8 = 0x04;
    /// Clear the fault status (self-clearing; written with D5, D3, D2 = 0).
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
    /// D1:D0 are not used and read 0.
    pub const UNUSED: u8 = 0x03;
    /// The bits only the fault-detection cycle sets.
    pub const WIRING: u8 = REFIN_HIGH | REFIN_LOW | RTDIN_LOW;
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
    Implausible(u16),
}

impl<E: core::fmt::Debug> core::fmt::Display for Error<E> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::Spi(e) => write!(f, "MAX31865: SPI error {e:?}"),
            Error::Fault(status) => write!(f, "MAX31865: fault status {status:#04x} ({})", classify(*status)),
            Error::Implausible(code) => write!(f, "MAX31865: RTD code {code:#06x} maps to no temperature"),
        }
    }
}

impl<E: core::fmt::Debug> core::error::Error for Error<E> {}

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

    /// From the parameter file's `[estimator]` section (validated: wire
    /// count 2/3/4 and mains 50/60 Hz; anything else falls back to 3 wires
    /// and 50 Hz): the element, the reference, the filter, the
    /// Callendar-Van Dusen coefficients, the oil's range as the fault band,
    /// and a detection cycle every [`DIAGNOSIS_INTERVAL`].
    pub fn from_params(raw: &RawEstimator) -> Settings {
        let mains = Mains::from_hz(raw.mains_hz).unwrap_or(Mains::Hz50);
        let per = DIAGNOSIS_INTERVAL / mains.conversion_period() + 0.5;
        Settings {
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

    /// Readings (calls a conversion period apart) after a detection cycle
    /// that still return the RTD registers' stale value: [`FIRST_CONVERSION`]
    /// rounded up to whole periods, plus one.
    pub fn restart_readings(&self) -> u32 {
        let n = FIRST_CONVERSION / self.mains.conversion_period();
        let whole = n as u32;
        (if (whole as f32) < n { whole + 1 } else { whole }) + 1
    }
}

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

/// The converter's resolution at `t` [C per code]: one code, `R_ref /
/// 2^15` ohm, over the RTD's slope `dR/dt` there (0.033 C at 40 C for a
/// PT100 with 430 ohm), for the parameter file's `[estimator]` section.
pub fn resolution(raw: &RawEstimator, t: f64) -> f64 {
    raw.rtd_reference / 32768.0 / raw.rtd_slope(t)
}

/// The 15-bit code of resistance `r` \[ohm\] (rounded to the nearest code,
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

/// A status byte no MAX31865 can answer: unused bits set (0xFF is MISO
/// stuck high, no chip), or RTD-high and RTD-low together.
pub fn is_chip_answer(status: u8) -> bool {
    status & fault::UNUSED == 0 && status & (fault::RTD_HIGH | fault::RTD_LOW) != fault::RTD_HIGH | fault::RTD_LOW
}

/// The fault a status byte stands for (the most specific bit first); a
/// byte no chip can answer is a bus fault.
pub fn classify(status: u8) -> SensorFault {
    if !is_chip_answer(status) {
        SensorFault::Bus
    } else if status & fault::WIRING != 0 {
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
    /// As [`Max31865::read_code`], and [`Error::Implausible`] for a code
    /// of zero or full scale, or one whose resistance no RTD temperature
    /// has ([`super::rtd::Cvd::temperature`]).
    pub fn read_temperature(&mut self) -> Result<f32, Error<SPI::Error>> {
        let code = self.read_code()?;
        let r = code as f32 * self.settings.reference / 32768.0;
        if code == 0 || code == 0x7FFF {
            return Err(Error::Implausible(code));
        }
        self.settings
            .cvd
            .temperature(self.settings.r0, r)
            .ok_or(Error::Implausible(code))
    }

    /// One reading, as the estimator wants it.
    fn sample(&mut self) -> Result<Option<f32>, SensorFault> {
        let reading = match self.read_temperature() {
            Ok(t) => Ok(Some(t)),
            Err(Error::Spi(_)) => Err(SensorFault::Bus),
            Err(Error::Fault(status)) => Err(classify(status)),
            Err(Error::Implausible(_)) => Err(SensorFault::Implausible),
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
            return Err(SensorFault::Implausible);
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
            SensorFault::Wiring | SensorFault::Voltage | SensorFault::Bus => Some(f),
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
