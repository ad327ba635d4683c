//! Where the estimator's temperature comes from.
//!
//! * [`TemperatureSource`]: the one interface the estimator needs, and
//!   [`SensorFault`], why a source gave no temperature (general causes,
//!   the chip's own word inside: [`Detail`], [`Word`]).
//! * [`rtd`]: platinum RTD resistance to temperature (Callendar-Van Dusen).
//! * [`max31865`]: the MAX31865 RTD-to-digital converter over an
//!   `embedded-hal` 1.0 [`SpiDevice`](embedded_hal::spi::SpiDevice), the
//!   usual front end of a PT100 in oil, and its register-level simulator.
//! * [`ntc`]: an NTC thermistor in a voltage divider read by the
//!   STM32F405's 12-bit ADC (beta or Steinhart-Hart), over the minimal
//!   [`ntc::AdcChannel`] trait, and a register-level simulator of the
//!   STM32F4 ADC.
//! * [`transducer`]: the condition monitor's second sensor, a chamber
//!   pressure or plunger displacement transducer (ratiometric or 4-20 mA,
//!   NAMUR NE 43) on the same ADC, with its stuck and noise checks and a
//!   register-level simulator ([`transducer::SimulatedTransducer`]).
//! * [`simulated`]: what the replays need of a simulated sensor
//!   ([`simulated::SimulatedSource`]: the temperature it sees, injected
//!   faults), for either chip.
//! * [`device`]: the edge between the parameter file and the drivers (each
//!   driver has its own settings struct and imports no schema).

pub mod device;
pub mod max31865;
pub mod ntc;
pub mod rtd;
pub mod simulated;
pub mod transducer;

/// What the chip said about a fault, beyond its general cause, packed in
/// 16 bits ([`Detail::word`] unpacks it): a reading's
/// `Result<Option<f32>, SensorFault>` stays 8 bytes, as it was with
/// fieldless faults (the estimator's tick takes it by value every tick).
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct Detail(u16);

/// A [`Detail`] unpacked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Word {
    /// Nothing more (a reading that is not a number, a log's entry).
    None,
    /// The MAX31865's fault status register (D7 RTD high ... D2
    /// over/under-voltage, [`max31865::fault`]).
    Max31865Status(u8),
    /// The converter's raw code (15 bits at most): the MAX31865's RTD
    /// code, or the ADC's (mean) code of an NTC divider.
    Code(u16),
}

impl Detail {
    /// Nothing more.
    pub const NONE: Detail = Detail(0);
    /// Tag of a status byte (bits 15:8 = 0x01).
    const STATUS: u16 = 0x0100;
    /// Tag of a code (bit 15).
    const CODE: u16 = 0x8000;

    /// The MAX31865's fault status byte.
    pub const fn max31865_status(status: u8) -> Detail {
        Detail(Detail::STATUS | status as u16)
    }

    /// A converter's raw code (its 15 low bits: every code of the
    /// MAX31865's 15-bit and the STM32F4's 12-bit converters).
    pub const fn code(code: u16) -> Detail {
        Detail(Detail::CODE | (code & 0x7FFF))
    }

    /// What it says.
    pub const fn word(self) -> Word {
        if self.0 & Detail::CODE != 0 {
            Word::Code(self.0 & 0x7FFF)
        } else if self.0 & Detail::STATUS != 0 {
            Word::Max31865Status(self.0 as u8)
        } else {
            Word::None
        }
    }
}

impl core::fmt::Debug for Detail {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        core::fmt::Debug::fmt(&self.word(), f)
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Detail {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::Format::format(&self.word(), f);
    }
}

impl core::fmt::Display for Detail {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.word() {
            Word::None => Ok(()),
            Word::Max31865Status(s) => write!(f, " (MAX31865 fault status {s:#04x})"),
            Word::Code(c) => write!(f, " (code {c})"),
        }
    }
}

/// Why a sensor produced no temperature: the cause, whatever the chip, and
/// the chip's detail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensorFault {
    /// The bus transaction failed, or the answer is one no chip gives
    /// (MISO stuck high, RTD-high and RTD-low together).
    Bus,
    /// The element reads open: an RTD above the converter's high threshold,
    /// an NTC divider's code near full scale, a transducer's signal below
    /// its fault-low limit (an open loop or wire: NAMUR NE 43's 3.6 mA).
    OpenCircuit(Detail),
    /// The element reads shorted: an RTD below the low threshold, an NTC
    /// divider's code near zero, a transducer's signal above its fault-high
    /// limit (a short to the supply: NE 43's 21 mA).
    ShortCircuit(Detail),
    /// A force or reference line of the element is open or shorted, found
    /// by a diagnosis cycle (the MAX31865's REFIN-/RTDIN- comparisons):
    /// readings can look valid and are not trusted.
    Wiring(Detail),
    /// Over- or under-voltage on a converter input.
    Supply(Detail),
    /// A reading that maps to no temperature of the element's range
    /// (a saturated code, NaN, outside the range the element is rated for;
    /// a transducer's signal between its measuring band and its fault
    /// limits).
    OutOfRange(Detail),
    /// The converter gave no result where one was due (a diagnosis cycle
    /// that did not finish, a conversion that did not complete).
    Stale,
    /// The same code for longer than the sensor's specified noise allows
    /// (a frozen output or converter; [`transducer`]).
    Stuck(Detail),
    /// The readings scatter more than the sensor's specified noise allows
    /// (a loose contact, interference; [`transducer`]).
    Noisy(Detail),
}

impl SensorFault {
    /// The chip's detail, if the fault has one.
    pub fn detail(&self) -> Detail {
        match *self {
            SensorFault::OpenCircuit(d)
            | SensorFault::ShortCircuit(d)
            | SensorFault::Wiring(d)
            | SensorFault::Supply(d)
            | SensorFault::OutOfRange(d)
            | SensorFault::Stuck(d)
            | SensorFault::Noisy(d) => d,
            SensorFault::Bus | SensorFault::Stale => Detail::NONE,
        }
    }
}

impl core::fmt::Display for SensorFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            SensorFault::Bus => "the sensor's bus transaction failed",
            SensorFault::OpenCircuit(_) => "the sensing element reads open",
            SensorFault::ShortCircuit(_) => "the sensing element reads shorted",
            SensorFault::Wiring(_) => "a force or reference line of the element is open or shorted",
            SensorFault::Supply(_) => "over- or under-voltage on a converter input",
            SensorFault::OutOfRange(_) => "a reading outside the range the element is rated for",
            SensorFault::Stale => "the converter gave no result where one was due",
            SensorFault::Stuck(_) => "the same code for longer than the sensor's noise allows (stuck)",
            SensorFault::Noisy(_) => "the readings scatter more than the sensor's noise allows (noisy)",
        })?;
        write!(f, "{}", self.detail())
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
