//! An NTC thermistor in a voltage divider, read by the STM32F405's 12-bit
//! successive-approximation ADC (RM0090 section 13).
//!
//! # Wiring and conversion
//!
//! ```text
//! V_REF+ (= VDDA, 3.3 V) --- R_series ---+--- ADC input (PA1, ADC1_IN1)
//!                                        |
//!                                       NTC
//!                                        |
//!                                   V_REF- (GND)
//! ```
//!
//! The NTC sits between the input and ground, the series resistor between
//! the input and the ADC's own reference, so the conversion is ratiometric:
//! `V_in / V_REF+ = R / (R + R_series)` and the code
//! `code = 2^N R / (R + R_series)` (rounded; `N` = 12 on the STM32F4, or 10,
//! 8, 6) holds whatever `V_REF+` is. Inverted:
//! `R = R_series code / (2^N - code)`.
//!
//! A hot NTC has a low resistance: low codes are hot oil, high codes cold.
//!
//! # Resistance to temperature ([`Curve`])
//!
//! * The beta equation (datasheet form, Vishay NTCLE100E3 "B25/85"):
//!   `1/T = 1/T25 + ln(R / R25) / B`, `T25` = 298.15 K.
//! * Steinhart-Hart (Steinhart and Hart, Deep-Sea Research 15, 1968):
//!   `1/T = a + b ln R + c (ln R)^3`, R in ohm, T in K, from a
//!   calibration or the datasheet's R/T table; its inverse for the
//!   simulator is Cardano's root ([`Curve::resistance`]).
//!
//! # Faults ([`SensorFault`](super::SensorFault))
//!
//! An open NTC pulls the input to `V_REF+` (code at full scale), a shorted
//! one to ground (code 0): a mean code within [`Settings::fault_codes`] of
//! full scale is [`OpenCircuit`](super::SensorFault::OpenCircuit), within
//! it of 0 [`ShortCircuit`](super::SensorFault::ShortCircuit); a
//! temperature outside [`Settings::band`] (the element's rated range) is
//! [`OutOfRange`](super::SensorFault::OutOfRange); a conversion that does
//! not end is [`Stale`](super::SensorFault::Stale), an ADC error
//! [`Bus`](super::SensorFault::Bus). Each carries the mean code as its
//! [`Detail::code`](super::Detail::code).
//!
//! # The ADC
//!
//! `embedded-hal` 1.0 has no ADC trait: [`AdcChannel`] is the one method
//! the driver needs. The board implements it with `stm32f4xx-hal`'s ADC
//! (`src/bin/board.rs`); [`RegisterAdc`] implements it over the STM32F4
//! ADC's registers (SR, CR2 SWSTART, DR: [`AdcRegisters`]), which the
//! register-level simulator [`SimulatedStm32Adc`] provides for the QEMU
//! replay and the host tests.
//!
//! Files: `driver.rs` ([`Ntc`], [`AdcChannel`]), `stm32_adc.rs` (the
//! register map, [`RegisterAdc`], [`SimulatedStm32Adc`]).

mod driver;
mod stm32_adc;

pub use driver::{AdcChannel, Error, Ntc};
pub use stm32_adc::{AdcRegisters, EOC_POLLS, RegisterAdc, SimulatedStm32Adc, Stm32AdcState, Timeout, reg};

/// `T25` of the beta equation \[K\].
pub const T25: f32 = 298.15;
/// 0 C \[K\].
pub const KELVIN: f32 = 273.15;

/// The thermistor's resistance-temperature curve.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Curve {
    /// `1/T = 1/T25 + ln(R / R25) / B`.
    Beta {
        /// Resistance at 25 C \[ohm\].
        r25: f32,
        /// B25/85 \[K\].
        beta: f32,
    },
    /// `1/T = a + b ln R + c (ln R)^3`, R in ohm.
    SteinhartHart {
        /// `a` \[1/K\].
        a: f32,
        /// `b` \[1/K\].
        b: f32,
        /// `c` \[1/K\].
        c: f32,
    },
}

impl Curve {
    /// Vishay NTCLE100E3103 (10 kohm, B25/85 = 3977 K).
    pub const NTCLE100E3103: Curve = Curve::Beta {
        r25: 10_000.0,
        beta: 3977.0,
    };

    /// Temperature \[C\] of the thermistor reading `r` \[ohm\]; `None` for a
    /// non-positive or non-finite resistance, or one the curve maps to no
    /// positive absolute temperature. Cost: one `logf`, one division.
    pub fn temperature(&self, r: f32) -> Option<f32> {
        if !(r > 0.0 && r.is_finite()) {
            return None;
        }
        let inv_t = match *self {
            Curve::Beta { r25, beta } => 1.0 / T25 + libm::logf(r / r25) / beta,
            Curve::SteinhartHart { a, b, c } => {
                let l = libm::logf(r);
                a + b * l + c * l * l * l
            }
        };
        let t = 1.0 / inv_t - KELVIN;
        (inv_t > 0.0 && t.is_finite()).then_some(t)
    }

    /// Resistance \[ohm\] at `t` \[C\] (the simulator's; Steinhart-Hart
    /// inverted by Cardano: `x = (a - 1/T) / c`,
    /// `y = sqrt((b / 3c)^3 + x^2 / 4)`, `ln R = cbrt(y - x/2) - cbrt(y + x/2)`).
    pub fn resistance(&self, t: f32) -> f32 {
        let inv_t = 1.0 / (t + KELVIN);
        match *self {
            Curve::Beta { r25, beta } => r25 * libm::expf(beta * (inv_t - 1.0 / T25)),
            Curve::SteinhartHart { a, b, c } => {
                let x = (a - inv_t) / c;
                let b3c = b / (3.0 * c);
                let y = libm::sqrtf(b3c * b3c * b3c + x * x / 4.0);
                libm::expf(libm::cbrtf(y - x / 2.0) - libm::cbrtf(y + x / 2.0))
            }
        }
    }
}

/// The NTC channel's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Settings {
    /// The thermistor's curve.
    pub curve: Curve,
    /// Series resistor from `V_REF+` to the input \[ohm\].
    pub series: f32,
    /// ADC resolution \[bits\]: 12, 10, 8 or 6.
    pub bits: u8,
    /// Conversions averaged into one reading (at least 1).
    pub oversampling: u8,
    /// Codes at either end of the range read as an open (full scale) or a
    /// shorted (0) NTC.
    pub fault_codes: u16,
    /// The element's range \[C\]: a reading outside it is out of range.
    pub band: (f32, f32),
    /// Time between two readings \[s\] (the caller paces them).
    pub period: f32,
}

impl Settings {
    /// A 10 kohm NTCLE100E3103 with a 10 kohm series resistor on the 12-bit
    /// ADC, four conversions a reading, 8 codes of open and short bands,
    /// -40..125 C (the element's rated range), read every 20 ms.
    pub const NTC10K: Settings = Settings {
        curve: Curve::NTCLE100E3103,
        series: 10_000.0,
        bits: 12,
        oversampling: 4,
        fault_codes: 8,
        band: (-40.0, 125.0),
        period: 0.02,
    };

    /// `2^bits` (the code's full range; the largest code is one less).
    pub fn full_scale(&self) -> u16 {
        1u16 << self.bits.min(15)
    }

    /// The code at `t` \[C\], rounded to the nearest and saturated to
    /// `0..=2^bits - 1` (as the ADC does).
    pub fn code_of(&self, t: f32) -> u16 {
        self.code_of_resistance(self.curve.resistance(t))
    }

    /// The code of an NTC reading `r` \[ohm\] (an infinite `r`, an open
    /// NTC, is full scale; 0, a short, is 0).
    pub fn code_of_resistance(&self, r: f32) -> u16 {
        let full = self.full_scale();
        let c = if r.is_finite() {
            f32::from(full) * r / (r + self.series) + 0.5
        } else {
            f32::from(full)
        };
        if c >= f32::from(full - 1) {
            full - 1
        } else if c > 0.0 {
            c as u16
        } else {
            0
        }
    }

    /// The NTC's resistance \[ohm\] at a (mean) code; infinite at full scale.
    pub fn resistance_of(&self, code: f32) -> f32 {
        self.series * code / (f32::from(self.full_scale()) - code)
    }

    /// The temperature \[C\] at a (mean) code (`None` where the curve has
    /// none).
    pub fn temperature_of(&self, code: f32) -> Option<f32> {
        self.curve.temperature(self.resistance_of(code))
    }
}
