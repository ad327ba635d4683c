//! The condition monitor's second sensor: a chamber pressure transducer
//! (`p_a`, `p_b`, or the difference `p_b - p_a`) or a plunger displacement
//! sensor (LVDT or Hall), with a ratiometric or a 4-20 mA output, read by
//! the STM32F405's 12-bit ADC (RM0090 section 13) through the same
//! register driver as the NTC ([`RegisterAdc`](super::ntc::RegisterAdc)).
//!
//! # Wiring and conversion
//!
//! ```text
//! ratiometric:  transducer OUT (0.5-4.5 V of its 5 V supply)
//!                  --- R1 ---+--- ADC input        divider = R2 / (R1 + R2)
//!                            R2                    (0.66: 5 V -> 3.3 V)
//!                            |
//!                           GND
//! current:      loop supply --- transmitter --- ADC input --- shunt --- GND
//!                                               (4-20 mA: 0.6-3.0 V on 150 ohm)
//! ```
//!
//! The ADC converts against `V_REF+` = 3.3 V: `V_adc = code V_REF / 2^N`.
//! The sensor's signal is `V_out = V_adc / divider` \[V\] or
//! `I = V_adc / shunt` \[A\] (shown in mA), and the reading
//! `range_min + (signal - low) / (high - low) (range_max - range_min)`
//! with `(low, high)` = (0.5 V, 4.5 V) or (4 mA, 20 mA) ([`Settings::reading_of_code`]).
//! The ratiometric output is proportional to the transducer's own 5 V
//! supply, taken as exactly 5 V: the ADC's reference is not that supply,
//! so its tolerance enters the reading (the error budget of
//! `docs/firmware.md`, "The monitor's transducer").
//!
//! # Fault levels ([`Limits`])
//!
//! * 4-20 mA, NAMUR NE 43 (2003): below 3.6 mA the loop is open or the
//!   transmitter signals a fault low ([`SensorFault::OpenCircuit`]),
//!   above 21.0 mA a fault high ([`SensorFault::ShortCircuit`]); 3.8 to
//!   20.5 mA is the measuring range (the transmitter saturates there for
//!   a process value beyond its range), and a current between the two
//!   bands is [`SensorFault::OutOfRange`].
//! * Ratiometric: below 0.25 V an open signal wire (pulled down) or a
//!   short to ground ([`SensorFault::OpenCircuit`]), above 4.75 V a short
//!   to the supply ([`SensorFault::ShortCircuit`]). The measuring band is
//!   0.5-4.5 V widened by NE 43's margins of the span (1.25 % below,
//!   3.125 % above: 0.45-4.625 V), so that a healthy sensor at an end of
//!   its range (the plunger on its stop, the outlet at 0 bar) does not
//!   read out of range on its noise; between the band and the fault
//!   limits: [`SensorFault::OutOfRange`].
//!
//! Each carries the ADC's code as its [`Detail::code`](super::Detail::code).
//!
//! # Stuck and noisy ([`Settings::stuck_after`], [`Settings::noise_limit`])
//!
//! A healthy reading is the true value plus Gaussian noise of standard
//! deviation `sigma` (`monitor.noise` in codes: `sigma_c`), rounded to a
//! code. The probability that a reading falls on any one code is at most
//! `p = erf(0.5 / (sigma_c sqrt 2))` (the unit interval centred on the
//! mean holds the most probability), so `N` equal codes in a row follow
//! from a reading with probability `sum_k p_k^N <= p^(N-1)`. The driver
//! reports [`SensorFault::Stuck`] after `N = 1 + ceil(ln 1e-9 / ln p)`
//! equal codes: a healthy sensor trips it less than once in 1e9 readings
//! ([`STUCK_FALSE_ALARM`]); where that `N` exceeds [`STUCK_MAX`] (noise far
//! below a code, or none) the check is off (`stuck_after` = 0).
//!
//! Over each window of [`NOISE_WINDOW`] readings the residual variance
//! `s^2 = RSS / 61` of the codes about their least-squares parabola is
//! compared with `K V_h`. The parabola takes out the process value's own
//! smooth change: a chamber pressure moves with the oil's temperature,
//! 8.4 kPa/K on the paper preset at 27 C, so a 0.5 C/s warm-up sweeps a
//! 100 Hz window over 18 codes, a spread of 26 codes^2 that the plain
//! sample variance read as a noisy sensor on every ramp of the QEMU
//! twin's replay; a line took that out, but not the bend where a 1 C/s
//! move starts or ends inside a window (0.55 codes a reading: about 6
//! codes^2 about the line, 0.3 about the parabola). `V_h = (sigma_c +
//! 0.5)^2` bounds the variance of a healthy rounded reading (the
//! rounding error, at most half a code, adds at most 0.5 to its standard
//! deviation: Minkowski), and `K = chi^2_61(1 - 1e-9) / 61 = 2.4921`
//! ([`NOISE_CHI2`]): for Gaussian readings of variance `V` about a
//! parabola, `RSS / V` is chi-square with 61 degrees of freedom (three
//! taken by the fit), which exceeds 152.02 with probability 1e-9. A
//! healthy sensor therefore raises [`SensorFault::Noisy`] in at most one
//! window in 1e9 ([`NOISE_FALSE_ALARM`]), at rest or through a change
//! whose departure from a parabola over a window is small beside the
//! noise; the fault holds until a window passes.
//!
//! Files: `driver.rs` ([`Transducer`]), `monitor.rs` (the stuck and noise
//! checks, [`Checks`]), `simulated.rs` ([`SimulatedTransducer`], the
//! register-level simulator with injectable faults).

mod driver;
mod monitor;
mod simulated;

pub use driver::{Error, Transducer};
pub use monitor::Checks;
pub use simulated::{SimulatedMonitor, SimulatedTransducer, TransducerFault, simulated};

use super::SensorFault;
use crate::params::{MONITOR_ADC_REFERENCE, ParamError, RawMonitor};

/// Readings a stuck verdict may need at most: beyond it the noise is too
/// small against a code for the check to mean anything, and it is off.
pub const STUCK_MAX: u32 = 10_000;

/// The false-alarm probability per reading the stuck check is designed
/// for (at most).
pub const STUCK_FALSE_ALARM: f64 = 1.0e-9;

/// Readings in one window of the noise check.
pub const NOISE_WINDOW: u32 = 64;

/// `chi^2` with `NOISE_WINDOW - 3` = 61 degrees of freedom (the window's
/// residuals about its parabola) exceeds this with probability
/// [`NOISE_FALSE_ALARM`] (regularised upper incomplete gamma `Q(30.5,
/// 152.0161 / 2)` = 1e-9; `host-tests/tests/transducer.rs` recomputes it).
pub const NOISE_CHI2: f32 = 152.0161;

/// The false-alarm probability per window the noise check is designed for.
pub const NOISE_FALSE_ALARM: f64 = 1.0e-9;

/// What the sensor measures (`monitor.sensor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Quantity {
    /// Chamber (a)'s pressure `p_a` \[Pa\] (`"p_a"`).
    PressureA,
    /// Chamber (b)'s pressure `p_b` \[Pa\] (`"p_b"`).
    PressureB,
    /// The difference `p_b - p_a` \[Pa\] (`"dp_ab"`).
    PressureDifference,
    /// The plunger's displacement `x` \[m\] (`"x"`).
    Displacement,
}

impl Quantity {
    /// The name the parameter file uses.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::PressureA => "p_a",
            Quantity::PressureB => "p_b",
            Quantity::PressureDifference => "dp_ab",
            Quantity::Displacement => "x",
        }
    }

    /// The reading's SI unit (`"Pa"`, `"m"`).
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Displacement => "m",
            _ => "Pa",
        }
    }

    /// The quantity of `monitor.sensor`'s value (`None` for `"none"` or
    /// any value that is not a quantity's).
    pub fn of(sensor: f64) -> Option<Quantity> {
        if sensor == 1.0 {
            Some(Quantity::PressureA)
        } else if sensor == 2.0 {
            Some(Quantity::PressureB)
        } else if sensor == 3.0 {
            Some(Quantity::PressureDifference)
        } else if sensor == 4.0 {
            Some(Quantity::Displacement)
        } else {
            None
        }
    }
}

/// The sensor's output and its front end into the ADC.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Output {
    /// 0.5-4.5 V of a 5 V supply, into the ADC through a divider of this
    /// ratio `V_adc / V_out` (0.66 for 5 V to 3.3 V).
    Ratiometric {
        /// `V_adc / V_out` (-).
        divider: f32,
    },
    /// 4-20 mA through a shunt of this resistance to ground, the ADC at
    /// its top.
    Current {
        /// The shunt \[ohm\].
        shunt: f32,
    },
}

/// The signal levels of an output, in its own unit (V for ratiometric, mA
/// for current): the fault limits outside, the measuring band inside, the
/// range's ends (where the reading is `range_min`, `range_max`) within it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Limits {
    /// Below it: open loop or wire, short to ground, fault low.
    pub fault_low: f32,
    /// Below it (and not below `fault_low`): under the measuring band.
    pub measure_low: f32,
    /// The signal at `range_min` (0.5 V, 4 mA).
    pub low: f32,
    /// The signal at `range_max` (4.5 V, 20 mA).
    pub high: f32,
    /// Above it (and not above `fault_high`): over the measuring band.
    pub measure_high: f32,
    /// Above it: short to the supply, fault high.
    pub fault_high: f32,
}

impl Limits {
    /// NAMUR NE 43's levels of a 4-20 mA loop \[mA\]: fault below 3.6 and
    /// above 21.0, measuring 3.8 to 20.5.
    pub const NAMUR_NE43: Limits = Limits {
        fault_low: 3.6,
        measure_low: 3.8,
        low: 4.0,
        high: 20.0,
        measure_high: 20.5,
        fault_high: 21.0,
    };

    /// A 0.5-4.5 V ratiometric output \[V\]: fault below 0.25 and above
    /// 4.75, measuring 0.45 to 4.625 (NE 43's margins, 1.25 % and 3.125 %
    /// of the span).
    pub const RATIOMETRIC: Limits = Limits {
        fault_low: 0.25,
        measure_low: 0.45,
        low: 0.5,
        high: 4.5,
        measure_high: 4.625,
        fault_high: 4.75,
    };
}

impl Output {
    /// The output's signal levels.
    pub fn limits(self) -> Limits {
        match self {
            Output::Ratiometric { .. } => Limits::RATIOMETRIC,
            Output::Current { .. } => Limits::NAMUR_NE43,
        }
    }

    /// The signal (V or mA) of `v_adc` \[V\] at the ADC's input.
    pub fn signal_of_voltage(self, v_adc: f32) -> f32 {
        match self {
            Output::Ratiometric { divider } => v_adc / divider,
            Output::Current { shunt } => v_adc / shunt * 1000.0,
        }
    }

    /// The voltage at the ADC's input \[V\] of a signal (V or mA).
    pub fn voltage_of_signal(self, signal: f32) -> f32 {
        match self {
            Output::Ratiometric { divider } => signal * divider,
            Output::Current { shunt } => signal * 1.0e-3 * shunt,
        }
    }
}

/// Why the settings cannot be built from a `[monitor]` section.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SettingsError {
    /// `monitor.sensor` is `"none"`: there is no second sensor to read.
    NoSensor,
    /// A field breaks its rule (the error names it).
    Param(#[cfg_attr(feature = "defmt", defmt(Debug2Format))] ParamError),
}

impl SettingsError {
    /// The field (`section.key`) the error is about.
    pub fn field(&self) -> &'static str {
        match self {
            SettingsError::NoSensor => "monitor.sensor",
            SettingsError::Param(e) => e.field,
        }
    }
}

impl From<ParamError> for SettingsError {
    fn from(e: ParamError) -> Self {
        SettingsError::Param(e)
    }
}

impl core::fmt::Display for SettingsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SettingsError::NoSensor => f.write_str("monitor.sensor = \"none\": no second sensor to read"),
            SettingsError::Param(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for SettingsError {}

/// The transducer channel's settings (the driver's own: built from the
/// file's `[monitor]` section by `TryFrom<&RawMonitor>`, or by hand).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Settings {
    /// What it measures.
    pub quantity: Quantity,
    /// Its output and front end.
    pub output: Output,
    /// The readings at the low and the high end of the signal (0.5 V and
    /// 4.5 V, or 4 and 20 mA) \[Pa or m\].
    pub range: (f32, f32),
    /// Standard deviation of one reading's noise \[Pa or m\].
    pub noise: f32,
    /// Accuracy class, a fraction of the span (a limit, -).
    pub accuracy: f32,
    /// ADC resolution \[bits\]: 12, 10, 8 or 6.
    pub bits: u8,
    /// The ADC's reference `V_REF+` \[V\].
    pub reference: f32,
    /// Time between two readings \[s\] (the caller paces them).
    pub period: f32,
    /// Equal codes in a row that read as a stuck sensor (0: the check is
    /// off; the module docs derive it).
    pub stuck_after: u32,
    /// Residual variance over a window of [`NOISE_WINDOW`] codes (about
    /// its least-squares parabola) above which the sensor is noisy
    /// \[codes^2\] (the module docs derive it).
    pub noise_limit: f32,
}

impl Settings {
    /// The settings of a sensor with these properties; [`Settings::stuck_after`]
    /// and [`Settings::noise_limit`] are derived from the noise and the
    /// code size (module docs).
    ///
    /// * `range`: the readings at 0.5 V / 4 mA and 4.5 V / 20 mA \[Pa or m\];
    /// * `noise`: one reading's standard deviation \[Pa or m\] (0: none);
    /// * `accuracy`: the class, a fraction of the span;
    /// * `bits`: 12, 10, 8 or 6; `sample_hz`: the reading rate \[Hz\].
    ///
    /// # Errors
    ///
    /// [`SettingsError::Param`] naming the field: `monitor.range_max`
    /// ([`crate::params::Problem::Inconsistent`]) not above `range_min` or
    /// not finite; `monitor.noise` negative, not finite or not below the
    /// span; `monitor.accuracy` outside (0, 0.1]; `monitor.adc_bits` not 12,
    /// 10, 8 or 6; `monitor.sample_hz` not positive; `monitor.divider` or
    /// `monitor.shunt` not positive, or such that a saturated ADC code is
    /// not beyond the fault-high limit (the fault would go unseen).
    pub fn new(
        quantity: Quantity,
        output: Output,
        range: (f32, f32),
        noise: f32,
        accuracy: f32,
        bits: u8,
        sample_hz: f32,
    ) -> Result<Settings, SettingsError> {
        use crate::params::Problem;
        let fail = |field: &'static str, value: f32, problem: Problem| {
            Err(SettingsError::Param(ParamError {
                field,
                value: f64::from(value),
                problem,
            }))
        };
        let span = range.1 - range.0;
        if !(range.0.is_finite() && range.1.is_finite() && span > 0.0 && span.is_finite()) {
            return fail(
                "monitor.range_max",
                range.1,
                Problem::Inconsistent("not above monitor.range_min (both finite)"),
            );
        }
        if !(noise >= 0.0 && noise < span) {
            let why = "below the span monitor.range_max - monitor.range_min";
            return fail(
                "monitor.noise",
                noise,
                Problem::OutOfRange {
                    min: 0.0,
                    max: f64::from(span),
                    why,
                },
            );
        }
        if !(accuracy > 0.0 && accuracy <= 0.1) {
            let why = "an accuracy class, a fraction of the span";
            return fail(
                "monitor.accuracy",
                accuracy,
                Problem::OutOfRange {
                    min: 0.0,
                    max: 0.1,
                    why,
                },
            );
        }
        if !matches!(bits, 6 | 8 | 10 | 12) {
            return fail(
                "monitor.adc_bits",
                f32::from(bits),
                Problem::NotOneOf(&[6.0, 8.0, 10.0, 12.0]),
            );
        }
        if !(sample_hz > 0.0 && sample_hz.is_finite()) {
            return fail("monitor.sample_hz", sample_hz, Problem::NotPositive);
        }
        let (field, value) = match output {
            Output::Ratiometric { divider } => ("monitor.divider", divider),
            Output::Current { shunt } => ("monitor.shunt", shunt),
        };
        if !(value > 0.0 && value.is_finite()) {
            return fail(field, value, Problem::NotPositive);
        }
        let reference = MONITOR_ADC_REFERENCE as f32;
        let mut s = Settings {
            quantity,
            output,
            range,
            noise,
            accuracy,
            bits,
            reference,
            period: 1.0 / sample_hz,
            stuck_after: 0,
            noise_limit: f32::INFINITY,
        };
        // The saturated code must read as a fault high, else a short to
        // the supply would read as a (wrong) value.
        let full = s.signal_of_code(f32::from(s.full_scale() - 1));
        if !(full > output.limits().fault_high) {
            let max = f64::from(reference * (1.0 - 1.0 / f32::from(s.full_scale())));
            let bound = max / f64::from(output.limits().fault_high);
            let (bound, why) = match output {
                Output::Ratiometric { .. } => (bound, "4.75 V times it must stay below the ADC's full scale"),
                Output::Current { .. } => (bound * 1000.0, "21 mA times it must stay below the ADC's full scale"),
            };
            return fail(
                field,
                value,
                Problem::OutOfRange {
                    min: 0.0,
                    max: bound,
                    why,
                },
            );
        }
        let sigma = f64::from(s.noise / s.units_per_code());
        s.stuck_after = stuck_after(sigma);
        s.noise_limit = (NOISE_CHI2 / (NOISE_WINDOW - 3) as f32) * (sigma as f32 + 0.5) * (sigma as f32 + 0.5);
        Ok(s)
    }

    /// `2^bits` (the code's full range; the largest code is one less).
    pub fn full_scale(&self) -> u16 {
        1u16 << self.bits.min(15)
    }

    /// The range's span `range_max - range_min` \[Pa or m\].
    pub fn span(&self) -> f32 {
        self.range.1 - self.range.0
    }

    /// One ADC code in the reading's unit \[Pa or m per code\].
    pub fn units_per_code(&self) -> f32 {
        let l = self.output.limits();
        let codes = self.output.voltage_of_signal(l.high - l.low) / self.reference * f32::from(self.full_scale());
        self.span() / codes
    }

    /// The standard uncertainty of the accuracy class \[Pa or m\]:
    /// `accuracy * span / sqrt(3)` (GUM 4.3.7: the class as the half-width
    /// of a uniform distribution).
    pub fn class_uncertainty(&self) -> f32 {
        self.accuracy * self.span() / libm::sqrtf(3.0)
    }

    /// The signal (V or mA) of a (mean) code: `code V_REF / 2^bits` at the
    /// ADC, through the divider or the shunt.
    pub fn signal_of_code(&self, code: f32) -> f32 {
        self.output
            .signal_of_voltage(code * self.reference / f32::from(self.full_scale()))
    }

    /// The reading \[Pa or m\] of a signal (V or mA), linear between the
    /// range's ends.
    pub fn reading_of_signal(&self, signal: f32) -> f32 {
        let l = self.output.limits();
        self.range.0 + (signal - l.low) / (l.high - l.low) * self.span()
    }

    /// The reading \[Pa or m\] of a (mean) code, whatever its level (no
    /// fault decoding: [`Settings::classify`]).
    pub fn reading_of_code(&self, code: f32) -> f32 {
        self.reading_of_signal(self.signal_of_code(code))
    }

    /// The signal (V or mA) the sensor gives at `reading` \[Pa or m\]
    /// (unclamped; the simulator's).
    pub fn signal_of_reading(&self, reading: f32) -> f32 {
        let l = self.output.limits();
        l.low + (reading - self.range.0) / self.span() * (l.high - l.low)
    }

    /// The code of a signal (V or mA), rounded to the nearest and
    /// saturated to `0..=2^bits - 1` (as the ADC does; NaN reads 0).
    pub fn code_of_signal(&self, signal: f32) -> u16 {
        let full = self.full_scale();
        let c = self.output.voltage_of_signal(signal) / self.reference * f32::from(full) + 0.5;
        if c >= f32::from(full - 1) {
            full - 1
        } else if c > 0.0 {
            c as u16
        } else {
            0
        }
    }

    /// The code at `reading` \[Pa or m\] of a healthy, noiseless sensor.
    pub fn code_of(&self, reading: f32) -> u16 {
        self.code_of_signal(self.signal_of_reading(reading))
    }

    /// The reading of one code, or the level fault it stands for (module
    /// docs): [`SensorFault::OpenCircuit`] below the fault-low limit,
    /// [`SensorFault::ShortCircuit`] above fault high,
    /// [`SensorFault::OutOfRange`] outside the measuring band; each with
    /// the code as its detail.
    ///
    /// # Errors
    ///
    /// The fault, as above.
    pub fn classify(&self, code: u16) -> Result<f32, SensorFault> {
        let detail = super::Detail::code(code);
        let l = self.output.limits();
        let signal = self.signal_of_code(f32::from(code));
        if !(signal >= l.fault_low) {
            Err(SensorFault::OpenCircuit(detail))
        } else if signal > l.fault_high {
            Err(SensorFault::ShortCircuit(detail))
        } else if signal < l.measure_low || signal > l.measure_high {
            Err(SensorFault::OutOfRange(detail))
        } else {
            Ok(self.reading_of_signal(signal))
        }
    }
}

/// Equal codes in a row that a healthy sensor whose noise is `sigma`
/// \[codes\] gives with probability at most [`STUCK_FALSE_ALARM`]:
/// `1 + ceil(ln 1e-9 / ln p)`, `p = erf(0.5 / (sigma sqrt 2))`; 0 (off)
/// where that exceeds [`STUCK_MAX`] or `sigma` is 0.
pub fn stuck_after(sigma: f64) -> u32 {
    if !(sigma > 0.0 && sigma.is_finite()) {
        return 0;
    }
    let p = libm::erf(0.5 / (sigma * core::f64::consts::SQRT_2));
    if !(p < 1.0) {
        return 0;
    }
    let n = 1.0 + libm::ceil(libm::log(STUCK_FALSE_ALARM) / libm::log(p));
    if n.is_finite() && n <= f64::from(STUCK_MAX) {
        (n as u32).max(2)
    } else {
        0
    }
}

impl TryFrom<&RawMonitor> for Settings {
    type Error = SettingsError;

    /// From the parameter file's `[monitor]` section: validated on its own
    /// first ([`RawMonitor::validate`]; the rules against the device are
    /// [`crate::params::RawParams::validate`]'s), then converted with
    /// [`Settings::new`].
    ///
    /// # Errors
    ///
    /// [`SettingsError::NoSensor`] for `sensor = "none"`, else the first
    /// [`ParamError`] (naming the field) of the validation or of
    /// [`Settings::new`].
    fn try_from(raw: &RawMonitor) -> Result<Settings, SettingsError> {
        raw.validate()?;
        let quantity = Quantity::of(raw.sensor).ok_or(SettingsError::NoSensor)?;
        let output = if raw.is_current() {
            Output::Current {
                shunt: raw.shunt as f32,
            }
        } else {
            Output::Ratiometric {
                divider: raw.divider as f32,
            }
        };
        Settings::new(
            quantity,
            output,
            (raw.range_min as f32, raw.range_max as f32),
            raw.noise as f32,
            raw.accuracy as f32,
            raw.adc_bits as u8,
            raw.sample_hz as f32,
        )
    }
}
