//! The transducer on the STM32F4's ADC at register level, for the host
//! tests and the QEMU replay: the registers are the NTC simulator's
//! ([`Stm32AdcState`]), the input a transducer with seeded Gaussian noise
//! and injectable faults.

use super::{Settings, Transducer};
use crate::sensor::ntc::{AdcRegisters, RegisterAdc, Stm32AdcState};

/// The transducer driver over the simulated STM32F4 ADC's registers.
pub type SimulatedMonitor = Transducer<RegisterAdc<SimulatedTransducer>>;

/// The driver of `settings` over its simulator reading `reading` \[Pa or
/// m\], its noise drawn from `seed` (the ADC set to the settings' bits).
pub fn simulated(settings: Settings, reading: f32, seed: u64) -> SimulatedMonitor {
    let adc = RegisterAdc::new(SimulatedTransducer::new(settings, reading, seed), settings.bits);
    Transducer::new(adc, settings)
}

/// A fault injected into the simulated transducer.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TransducerFault {
    /// The loop or the signal wire open: no current, the input pulled to
    /// ground (code 0).
    OpenLoop,
    /// The signal shorted to the supply (the input at its top: full scale).
    Shorted,
    /// The output frozen at the last code converted before the fault.
    Stuck,
    /// The noise this many times the specified one.
    Noisy(f32),
    /// An offset growing by this much \[Pa or m\] every conversion (a
    /// drifting zero; it stays when the fault is cleared, as a drift does,
    /// until [`SimulatedTransducer::clear_offset`]).
    OffsetDrift(f32),
    /// The converter no longer ends its conversions (EOC never set).
    AdcStuck,
}

/// Marsaglia's xorshift64 (deterministic, no dependency, the same sequence
/// on the host and the Cortex-M4F) and Box-Muller's normal deviates.
#[derive(Clone, Copy, Debug)]
struct Normal {
    state: u64,
    spare: Option<f32>,
}

impl Normal {
    fn new(seed: u64) -> Normal {
        let s = seed ^ 0x9E37_79B9_7F4A_7C15;
        Normal {
            state: if s == 0 { 1 } else { s },
            spare: None,
        }
    }

    fn next_u64(&mut self) -> u64 {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.state = x;
        x
    }

    /// Uniform in (0, 1], 24 bits.
    fn unit(&mut self) -> f32 {
        ((self.next_u64() >> 40) + 1) as f32 * (1.0 / 16_777_216.0)
    }

    /// A standard normal deviate (Box-Muller, both deviates used).
    fn sample(&mut self) -> f32 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let r = libm::sqrtf(-2.0 * libm::logf(self.unit()));
        let phi = 2.0 * core::f32::consts::PI * self.unit();
        self.spare = Some(r * libm::sinf(phi));
        r * libm::cosf(phi)
    }
}

/// The STM32F4 ADC with a transducer at its input, at register level: each
/// conversion (SWSTART with ADON, [`Stm32AdcState`]) is the code of
/// [`SimulatedTransducer::reading`] plus the offset and
/// [`Settings::noise`] times a normal deviate (seeded, deterministic),
/// through the output and its front end, rounded to the nearest code at
/// CR1's resolution and saturated ([`Settings::code_of`]). The simulated
/// output does not saturate at the measuring band's ends: a reading
/// beyond the range reads out of range.
#[derive(Clone, Copy, Debug)]
pub struct SimulatedTransducer {
    settings: Settings,
    /// The true reading at the sensor \[Pa or m\].
    pub reading: f32,
    /// The injected fault (`None`: healthy).
    pub fault: Option<TransducerFault>,
    /// Code converted instead of the input's (a test's forced code).
    pub forced_code: Option<u16>,
    /// Conversions run so far.
    pub conversions: u32,
    offset: f32,
    last_code: u16,
    noise: Normal,
    regs: Stm32AdcState,
}

impl SimulatedTransducer {
    /// An ADC at reset (off, 12 bits) with the transducer of `settings` at
    /// its input reading `reading` \[Pa or m\], its noise drawn from `seed`.
    pub fn new(settings: Settings, reading: f32, seed: u64) -> Self {
        SimulatedTransducer {
            settings,
            reading,
            fault: None,
            forced_code: None,
            conversions: 0,
            offset: 0.0,
            last_code: 0,
            noise: Normal::new(seed),
            regs: Stm32AdcState::RESET,
        }
    }

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The offset the drift has accumulated \[Pa or m\].
    pub fn offset(&self) -> f32 {
        self.offset
    }

    /// Removes the accumulated offset (a re-zeroed sensor).
    pub fn clear_offset(&mut self) {
        self.offset = 0.0;
    }

    /// The code of one conversion at `bits` of resolution.
    fn convert(&mut self, bits: u8) -> u16 {
        let s = Settings { bits, ..self.settings };
        if let Some(c) = self.forced_code {
            return c & (s.full_scale() - 1);
        }
        let mut sigma = s.noise;
        match self.fault {
            Some(TransducerFault::OpenLoop) => return 0,
            Some(TransducerFault::Shorted) => return s.full_scale() - 1,
            Some(TransducerFault::Stuck) => return self.last_code,
            Some(TransducerFault::Noisy(k)) => sigma *= k,
            Some(TransducerFault::OffsetDrift(rate)) => self.offset += rate,
            Some(TransducerFault::AdcStuck) | None => {}
        }
        let code = s.code_of(self.reading + self.offset + sigma * self.noise.sample());
        self.last_code = code;
        code
    }
}

impl AdcRegisters for SimulatedTransducer {
    fn read(&mut self, offset: u32) -> u32 {
        self.regs.read(offset)
    }

    fn write(&mut self, offset: u32, value: u32) {
        let stuck = self.fault == Some(TransducerFault::AdcStuck);
        let mut regs = self.regs;
        if regs.write(offset, value, stuck, |bits| self.convert(bits)) {
            self.conversions = self.conversions.wrapping_add(1);
        }
        self.regs = regs;
    }
}
