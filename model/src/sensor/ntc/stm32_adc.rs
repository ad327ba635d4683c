//! The STM32F4 ADC at register level (RM0090 rev 19, section 13.13): the
//! registers a single software-triggered regular conversion uses, a
//! driver over them ([`RegisterAdc`]), and a simulator of them with an NTC
//! divider at its input ([`SimulatedStm32Adc`]).
//!
//! | offset | register | bits used |
//! |---|---|---|
//! | 0x00 | ADC_SR | 1 EOC (end of conversion; cleared by reading DR), 4 STRT (a regular conversion started), 5 OVR |
//! | 0x04 | ADC_CR1 | 25:24 RES (00: 12, 01: 10, 10: 8, 11: 6 bits) |
//! | 0x08 | ADC_CR2 | 0 ADON, 30 SWSTART (starts a regular conversion; cleared by hardware when it starts) |
//! | 0x4C | ADC_DR | 15:0 the regular conversion's code, right-aligned |

use super::{AdcChannel, Settings};
use crate::sensor::SensorFault;

/// Register offsets and bits.
pub mod reg {
    /// Status register.
    pub const SR: u32 = 0x00;
    /// Control register 1.
    pub const CR1: u32 = 0x04;
    /// Control register 2.
    pub const CR2: u32 = 0x08;
    /// Regular data register.
    pub const DR: u32 = 0x4C;
    /// SR: end of conversion.
    pub const SR_EOC: u32 = 1 << 1;
    /// SR: regular conversion started.
    pub const SR_STRT: u32 = 1 << 4;
    /// SR: overrun.
    pub const SR_OVR: u32 = 1 << 5;
    /// CR1: resolution field's shift (2 bits).
    pub const CR1_RES_SHIFT: u32 = 24;
    /// CR2: A/D converter on.
    pub const CR2_ADON: u32 = 1 << 0;
    /// CR2: start conversion of the regular channels.
    pub const CR2_SWSTART: u32 = 1 << 30;

    /// CR1's RES field for `bits` (12, 10, 8, 6; anything else 12).
    pub fn res(bits: u8) -> u32 {
        let code = match bits {
            10 => 1,
            8 => 2,
            6 => 3,
            _ => 0,
        };
        code << CR1_RES_SHIFT
    }

    /// The bits of a RES field.
    pub fn bits_of(cr1: u32) -> u8 {
        match (cr1 >> CR1_RES_SHIFT) & 3 {
            1 => 10,
            2 => 8,
            3 => 6,
            _ => 12,
        }
    }
}

/// Status register polls before a conversion counts as not ended: the
/// board's 12-bit conversion (84 sampling cycles + 12) takes 96 ADC clocks,
/// 4.6 us at 21 MHz, some 770 core cycles at 168 MHz, and a poll (an APB2
/// read and a branch) several core cycles, so that 1024 polls outlast a
/// few conversions; the simulator converts at once.
pub const EOC_POLLS: u32 = 1024;

/// Word access to an ADC's registers (offsets of [`reg`]).
pub trait AdcRegisters {
    /// Reads the register at `offset`.
    fn read(&mut self, offset: u32) -> u32;
    /// Writes `value` to the register at `offset`.
    fn write(&mut self, offset: u32, value: u32);
}

/// The conversion did not end within [`EOC_POLLS`] polls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Timeout;

/// A single-channel, software-triggered ADC over its registers: RES and
/// ADON set by [`RegisterAdc::new`], each code by SWSTART, a bounded poll of
/// EOC, and a read of DR (which clears EOC).
#[derive(Clone, Copy, Debug)]
pub struct RegisterAdc<R> {
    regs: R,
    mask: u16,
}

impl<R: AdcRegisters> RegisterAdc<R> {
    /// Sets the resolution (`bits`: 12, 10, 8 or 6) and powers the ADC on.
    pub fn new(mut regs: R, bits: u8) -> Self {
        regs.write(reg::CR1, reg::res(bits));
        regs.write(reg::CR2, reg::CR2_ADON);
        let bits = reg::bits_of(reg::res(bits));
        RegisterAdc {
            regs,
            mask: ((1u32 << bits) - 1) as u16,
        }
    }

    /// The registers (for a simulator: to drive the simulation).
    pub fn registers_mut(&mut self) -> &mut R {
        &mut self.regs
    }
}

impl<R: AdcRegisters> AdcChannel for RegisterAdc<R> {
    type Error = Timeout;

    fn read_code(&mut self) -> Result<u16, Timeout> {
        let cr2 = self.regs.read(reg::CR2);
        self.regs.write(reg::CR2, cr2 | reg::CR2_ADON | reg::CR2_SWSTART);
        for _ in 0..EOC_POLLS {
            if self.regs.read(reg::SR) & reg::SR_EOC != 0 {
                return Ok(self.regs.read(reg::DR) as u16 & self.mask);
            }
        }
        Err(Timeout)
    }

    fn fault(_: &Timeout) -> SensorFault {
        SensorFault::Stale
    }
}

/// The registers of a simulated STM32F4 ADC (SR, CR1, CR2, DR) and what
/// a software-triggered regular conversion does to them, whatever is at
/// the input: the simulators of each input ([`SimulatedStm32Adc`] with its
/// NTC divider, the monitor's transducer) hold one and give it the code of
/// each conversion.
///
/// SWSTART written with ADON converts at once: the input's code, at the
/// resolution CR1 holds, goes to DR, EOC and STRT are set; reading DR
/// clears EOC; a conversion whose result was not read sets OVR. SR's bits
/// are rc_w0 (writing 0 clears, 1 keeps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stm32AdcState {
    sr: u32,
    cr1: u32,
    cr2: u32,
    dr: u32,
}

impl Stm32AdcState {
    /// The registers at reset (ADC off, 12 bits).
    pub const RESET: Stm32AdcState = Stm32AdcState {
        sr: 0,
        cr1: 0,
        cr2: 0,
        dr: 0,
    };

    /// The resolution CR1 holds \[bits\].
    pub fn bits(&self) -> u8 {
        reg::bits_of(self.cr1)
    }

    /// Reads the register at `offset` (reading DR clears EOC; unknown
    /// offsets read 0).
    pub fn read(&mut self, offset: u32) -> u32 {
        match offset {
            reg::SR => self.sr,
            reg::CR1 => self.cr1,
            reg::CR2 => self.cr2,
            reg::DR => {
                self.sr &= !reg::SR_EOC;
                self.dr
            }
            _ => 0,
        }
    }

    /// Writes `value` to the register at `offset`. A write of SWSTART with
    /// ADON starts a conversion unless `stuck` (a converter that no longer
    /// ends its conversions): `convert` gets CR1's resolution \[bits\] and
    /// returns the input's code, which is masked to it. Returns whether a
    /// conversion ran.
    pub fn write(&mut self, offset: u32, value: u32, stuck: bool, convert: impl FnOnce(u8) -> u16) -> bool {
        match offset {
            reg::SR => self.sr &= value,
            reg::CR1 => self.cr1 = value,
            reg::CR2 => {
                self.cr2 = value & !reg::CR2_SWSTART;
                if value & reg::CR2_SWSTART != 0 && value & reg::CR2_ADON != 0 && !stuck {
                    if self.sr & reg::SR_EOC != 0 {
                        self.sr |= reg::SR_OVR;
                    }
                    let bits = self.bits();
                    let mask = ((1u32 << bits) - 1) as u16;
                    self.dr = u32::from(convert(bits) & mask);
                    self.sr |= reg::SR_EOC | reg::SR_STRT;
                    return true;
                }
            }
            _ => {}
        }
        false
    }
}

/// The STM32F4 ADC with an NTC divider at its input, at register level
/// ([`Stm32AdcState`]): each conversion is the code of the divider at
/// [`SimulatedStm32Adc::temperature`] rounded to the nearest
/// ([`Settings::code_of`]) at the resolution CR1 holds.
///
/// Injected faults: an open or a shorted NTC (full scale, 0), a forced
/// code, and a converter that no longer ends its conversions (EOC never
/// set: a stuck ADC).
#[derive(Clone, Copy, Debug)]
pub struct SimulatedStm32Adc {
    settings: Settings,
    /// Temperature at the NTC \[C\].
    pub temperature: f32,
    /// The NTC is open (the input at `V_REF+`).
    pub open: bool,
    /// The NTC is shorted (the input at ground).
    pub short: bool,
    /// Code converted instead of the divider's (a broken converter).
    pub forced_code: Option<u16>,
    /// Conversions never end.
    pub stuck: bool,
    /// Conversions run so far.
    pub conversions: u32,
    regs: Stm32AdcState,
}

impl SimulatedStm32Adc {
    /// An ADC at reset (ADC off, 12 bits) with the divider of `settings`,
    /// its NTC at `temperature` \[C\].
    pub fn new(settings: Settings, temperature: f32) -> Self {
        SimulatedStm32Adc {
            settings,
            temperature,
            open: false,
            short: false,
            forced_code: None,
            stuck: false,
            conversions: 0,
            regs: Stm32AdcState::RESET,
        }
    }

    /// The code the divider gives now, at `bits` of resolution.
    fn convert(&self, bits: u8) -> u16 {
        let s = Settings { bits, ..self.settings };
        if let Some(c) = self.forced_code {
            return c & (s.full_scale() - 1);
        }
        if self.short {
            0
        } else if self.open {
            s.full_scale() - 1
        } else {
            s.code_of(self.temperature)
        }
    }
}

impl AdcRegisters for SimulatedStm32Adc {
    fn read(&mut self, offset: u32) -> u32 {
        self.regs.read(offset)
    }

    fn write(&mut self, offset: u32, value: u32) {
        let this = *self;
        if self.regs.write(offset, value, self.stuck, |bits| this.convert(bits)) {
            self.conversions = self.conversions.wrapping_add(1);
        }
    }
}

impl<R: AdcRegisters + ?Sized> AdcRegisters for &mut R {
    fn read(&mut self, offset: u32) -> u32 {
        (**self).read(offset)
    }

    fn write(&mut self, offset: u32, value: u32) {
        (**self).write(offset, value);
    }
}
