//! The MAX31865's register map, its configuration and fault-status bits,
//! and the decoding of a status byte into a [`SensorFault`] (datasheet
//! 19-6478, tables 1, 2 and 8).

use super::Settings;
use crate::sensor::{Detail, SensorFault};

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
/// (what `Settings::from_params`, in `crate::sensor::device`, sets).
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

/// The fault a status byte stands for (the most specific bit first), with
/// the byte as its [`Detail::max31865_status`]; a byte no chip can answer is
/// a bus fault, a byte without a fault bit a reading out of range.
pub fn classify(status: u8) -> SensorFault {
    let d = Detail::max31865_status(status);
    if !is_chip_answer(status) {
        SensorFault::Bus
    } else if status & fault::WIRING != 0 {
        SensorFault::Wiring(d)
    } else if status & fault::VOLTAGE != 0 {
        SensorFault::Supply(d)
    } else if status & fault::RTD_HIGH != 0 {
        SensorFault::OpenCircuit(d)
    } else if status & fault::RTD_LOW != 0 {
        SensorFault::ShortCircuit(d)
    } else {
        SensorFault::OutOfRange(d)
    }
}
