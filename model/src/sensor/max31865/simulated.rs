//! A register-level model of a MAX31865 with a PT100 in oil, as an
//! `embedded-hal` 1.0 [`SpiDevice`]: the QEMU firmware reads it through the
//! real [`Max31865`](super::Max31865) driver, so the replayed
//! profiles exercise the same code path as the board.
//!
//! The model keeps the register file of the datasheet (auto-incrementing
//! reads and writes, write address = read | 0x80), converts the oil
//! temperature to the RTD code by Callendar-Van Dusen (the settings'
//! coefficients), and injects faults: a persistent fault cause (status
//! bits; RTD high/low and over/under-voltage are latched by every
//! conversion read, the REFIN-/RTDIN- wiring bits only by a fault-detection
//! cycle; the latch sets the RTD word's fault bit until cleared, and
//! clearing only clears the latch), a forced code, a failing bus, or a
//! MISO line stuck high (every byte reads 0xFF).
//!
//! Timing is not modelled: a fault-detection cycle (configuration bits
//! D3:D2 set to 01) completes at once (D3:D2 read back 00), and the RTD
//! registers hold their last value while automatic conversion is off.

use super::{REG_CONFIG, REG_FAULT_STATUS, REG_RTD_MSB, Settings, code_of, config, fault};
use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};

/// The simulated bus failure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BusError;

impl core::fmt::Display for BusError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("simulated SPI bus failure")
    }
}

impl core::error::Error for BusError {}

impl embedded_hal::spi::Error for BusError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// The simulated converter and its RTD.
#[derive(Clone, Copy, Debug)]
pub struct SimulatedMax31865 {
    settings: Settings,
    /// Oil temperature at the RTD \[C\].
    pub temperature: f32,
    /// Fault cause present (status bits, 0 = none).
    pub fault: u8,
    /// Code reported instead of the RTD's (a broken converter).
    pub forced_code: Option<u16>,
    /// Every transaction fails.
    pub bus_error: bool,
    /// MISO stuck high (no chip): every byte read is 0xFF.
    pub miso_stuck_high: bool,
    /// Fault-detection cycles run so far.
    pub detection_cycles: u32,
    registers: [u8; 8],
    latched: u8,
    /// The last converted RTD word (held while conversion is off).
    word: u16,
}

impl SimulatedMax31865 {
    /// A converter with `settings` and its RTD at `temperature` \[C\].
    pub fn new(settings: Settings, temperature: f32) -> Self {
        SimulatedMax31865 {
            settings,
            temperature,
            fault: 0,
            forced_code: None,
            bus_error: false,
            miso_stuck_high: false,
            detection_cycles: 0,
            registers: [0; 8],
            latched: 0,
            word: 0,
        }
    }

    /// The configuration register as last written.
    pub fn config(&self) -> u8 {
        self.registers[REG_CONFIG as usize]
    }

    fn register(&mut self, addr: u8) -> u8 {
        if self.miso_stuck_high {
            return 0xFF;
        }
        let addr = addr & 0x07;
        if addr == REG_RTD_MSB || addr == REG_RTD_MSB + 1 {
            if self.registers[REG_CONFIG as usize] & config::AUTO != 0 {
                // Converting: the code of the RTD now; conversion faults latch.
                self.latched |= self.fault & (fault::RTD_HIGH | fault::RTD_LOW | fault::VOLTAGE);
                let code = self.forced_code.unwrap_or_else(|| {
                    code_of(
                        &self.settings,
                        self.settings.cvd.resistance(self.settings.r0, self.temperature),
                    )
                });
                self.word = code << 1;
            }
            let word = (self.word & !1) | u16::from(self.latched != 0);
            return if addr == REG_RTD_MSB {
                (word >> 8) as u8
            } else {
                word as u8
            };
        }
        if addr == REG_FAULT_STATUS {
            return self.latched;
        }
        self.registers[addr as usize]
    }

    fn write_register(&mut self, addr: u8, value: u8) {
        let addr = addr & 0x07;
        match addr {
            REG_CONFIG => {
                if value & config::FAULT_CLEAR != 0 {
                    self.latched = 0;
                }
                if value & config::FAULT_CYCLE == config::FAULT_CYCLE_AUTO && value & config::V_BIAS != 0 {
                    // The detection cycle: the REFIN-/RTDIN- comparisons
                    // (and over/under-voltage) latch; done at once.
                    self.detection_cycles += 1;
                    self.latched |= self.fault & (fault::WIRING | fault::VOLTAGE);
                }
                // Fault clear and the automatic cycle self-clear.
                self.registers[0] = value & !(config::FAULT_CLEAR | config::FAULT_CYCLE);
            }
            0x03..=0x06 => self.registers[addr as usize] = value,
            _ => {} // read-only
        }
    }
}

impl ErrorType for SimulatedMax31865 {
    type Error = BusError;
}

impl SpiDevice for SimulatedMax31865 {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), BusError> {
        if self.bus_error {
            return Err(BusError);
        }
        // The first byte written is the address; the rest of the
        // transaction reads or writes from there, auto-incrementing.
        let mut addr: Option<u8> = None;
        for op in operations.iter_mut() {
            match op {
                Operation::Write(bytes) => {
                    for &b in bytes.iter() {
                        match addr {
                            None => addr = Some(b),
                            Some(a) => {
                                if a & 0x80 != 0 {
                                    self.write_register(a, b);
                                }
                                addr = Some((a & 0x80) | (a.wrapping_add(1) & 0x07));
                            }
                        }
                    }
                }
                Operation::Read(buf) => {
                    for byte in buf.iter_mut() {
                        let a = addr.unwrap_or(0);
                        *byte = self.register(a);
                        addr = Some(a.wrapping_add(1) & 0x07);
                    }
                }
                Operation::Transfer(_, _) | Operation::TransferInPlace(_) => return Err(BusError),
                Operation::DelayNs(_) => {}
            }
        }
        Ok(())
    }
}
