//! The reference of degraded devices for a fault-injection campaign: what
//! the *true* device reads over a long temperature history, with a fault
//! injected at a time, and what the firmware's two sensors report (the oil
//! temperature probe and one second sensor: a chamber pressure, their
//! difference, or the plunger's displacement). The condition monitor's
//! campaign (`docs/monitoring.md`, "Fault-injection data") consumes it.
//!
//! Independent of the core's model: the device's state is the reference
//! equilibrium [`compensator_reference::statics::equilibrium`] (bisection on
//! each chamber's flow balance, no code shared with `model/`), the faults
//! are changes of the device's [`RawCore`] fields as in
//! [`crate::observability`]. The core enters only where the firmware does:
//! its sensor drivers' converters quantise the probe's reading, and
//! [`Estimated`] runs the record stream through the firmware's
//! [`Estimator`] built for the *nominal* design.
//!
//! # Assumptions
//!
//! * **Quasi-static device.** The plunger's and the chambers' time
//!   constants are milliseconds (`compensator indicators`: settling in
//!   5-45 ms on the paper preset), the oil's temperature moves over seconds
//!   (at most 1 C/s here): the device is at its equilibrium at the oil's
//!   temperature at every sample. `tests/campaign_data.rs` checks this
//!   against the reference's stiff solver ([`compensator_reference::dynamics`])
//!   on a slow ramp.
//! * **Pressures do not depend on the plunger's position at rest.** The
//!   chambers are dead-ended: at rest no oil flows into or out of them
//!   through the plunger, each chamber's pressure is set by its divider
//!   (chamber (a): the orifice from `p_p`, the capillary to `p_c`; chamber
//!   (b): the capillary from `p_p`, the orifice to `p_c`) alone. A stuck
//!   plunger changes the displacement, not the pressures (tested against
//!   `equilibrium` with the spring changed).
//! * **Sticking** is Coulomb friction `F` with equal static and kinetic
//!   coefficients, quasi-static: the plunger moves only when the force
//!   imbalance `c (x_free - x)` exceeds `F`, where `x_free = A (p_b - p_a) /
//!   c - x0` is the frictionless, unclamped displacement (the reference's
//!   spring force is `c (x0 + x)`), and then sits at the edge of the band:
//!   the play (backlash) operator [`play`], clamped to the stops. Applied at
//!   every sample: exact for a displacement monotone between samples (the
//!   play operator is rate-independent). Checked against the reference's
//!   stiff solver with the same friction
//!   ([`compensator_reference::dynamics::simulate_with_friction`]: stick
//!   and slip as events) on slow ramps each way: within 2e-4 of the stroke
//!   (5e-5 seen on the paper preset, against bands of 1-2.5 % of it).
//! * **A fault is a step** at its onset time: the healthy device before, the
//!   degraded one from then on.
//! * **The probe** is the device file's `[probe]`: first-order lag with its
//!   `time_constant` (and its `well_time_constant` in series), simulated
//!   exactly for the piecewise-linear oil temperature (as
//!   [`crate::tracking`] does, [`crate::tracking::lag_step`]); its
//!   tolerance a fixed per-device error `u (a + b |T|)`, `u` uniform in
//!   `[-1, 1]` (the tolerance model of [`crate::coverage`]; IEC 60751 class
//!   B by default: `a` = 0.3 C, `b` = 0.005); its white noise `probe.noise`;
//!   the converter's quantisation (the MAX31865's 15-bit code through the
//!   file's Callendar-Van Dusen curve, or one conversion of the NTC's ADC).
//!   Read every [`reading_period`] (20 ms at 50 Hz mains).
//! * **The second sensor** ([`SecondSensor`]): truth, plus a fixed
//!   per-device offset uniform within its accuracy class, plus white
//!   Gaussian noise, quantised by a 12-bit ADC over its span (saturating at
//!   its ends).
//! * **The device is as built** ([`as_built`]): its capillary, orifice,
//!   spring and preload deviate from the nominal design the estimator is
//!   given, by the spreads of [`SPREAD`].
//!
//! Everything is deterministic per seed; each part (the device, the
//! history, the probe's and the second sensor's draws, their noises) has
//! its own stream, derived from the seed ([`Scenario::new`]).

use crate::coverage::normal;
use crate::random::{Rng, physical_params};
use crate::reference::{Point, equilibrium};
use crate::tracking::lag_step;
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, StateEstimate, reading_period};
use compensator::params::{RawCore, RawEstimator, RawParams, RawProbe};
use compensator::sensor::device::SensorKind;
use compensator::sensor::{max31865, ntc};
use std::f64::consts::PI;
use std::fmt;

/// A device fault and its severity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fault {
    /// Healthy throughout.
    None,
    /// The capillary's conductance times the factor (< 1: restricted by
    /// deposits; the bore times the factor's fourth root, Hagen-Poiseuille).
    CapillaryRestricted(f64),
    /// The orifice's area times the factor (> 1: worn by erosion; the bore
    /// times its square root).
    OrificeWorn(f64),
    /// The orifice's area times the factor (< 1: clogged).
    OrificeClogged(f64),
    /// The spring rate times the factor (< 1: relaxed).
    SpringRelaxed(f64),
    /// The preload times the factor (< 1: lost, e.g. a settled spring seat).
    PreloadLost(f64),
    /// Coulomb friction on the plunger, as a fraction of the spring force
    /// at mid-stroke: `F = frac c (x0 + stroke / 2)` \[N\] (the as-built
    /// device's `c`, `x0`).
    Sticking(f64),
    /// The second sensor's reading offset by this fraction of its span (a
    /// drifted transducer; the device itself healthy).
    SensorOffset(f64),
}

impl Fault {
    /// The faults of a campaign at typical severities.
    pub const CATALOGUE: [Fault; 15] = [
        Fault::None,
        Fault::CapillaryRestricted(0.9),
        Fault::CapillaryRestricted(0.8),
        Fault::OrificeWorn(1.1),
        Fault::OrificeWorn(1.2),
        Fault::OrificeClogged(0.9),
        Fault::OrificeClogged(0.8),
        Fault::SpringRelaxed(0.9),
        Fault::PreloadLost(0.8),
        Fault::PreloadLost(0.5),
        Fault::Sticking(0.02),
        Fault::Sticking(0.05),
        Fault::Sticking(0.1),
        Fault::SensorOffset(0.002),
        Fault::SensorOffset(0.005),
    ];

    /// The fault's short name (`capillary`, `orifice-worn`, ...; what
    /// [`Fault::parse`] reads).
    pub fn name(&self) -> &'static str {
        match self {
            Fault::None => "none",
            Fault::CapillaryRestricted(_) => "capillary",
            Fault::OrificeWorn(_) => "orifice-worn",
            Fault::OrificeClogged(_) => "orifice-clogged",
            Fault::SpringRelaxed(_) => "spring",
            Fault::PreloadLost(_) => "preload",
            Fault::Sticking(_) => "sticking",
            Fault::SensorOffset(_) => "sensor-offset",
        }
    }

    /// The severity (a factor, a fraction; `None` for [`Fault::None`]).
    pub fn severity(&self) -> Option<f64> {
        match *self {
            Fault::None => None,
            Fault::CapillaryRestricted(f)
            | Fault::OrificeWorn(f)
            | Fault::OrificeClogged(f)
            | Fault::SpringRelaxed(f)
            | Fault::PreloadLost(f)
            | Fault::Sticking(f)
            | Fault::SensorOffset(f) => Some(f),
        }
    }

    /// `name:severity` (`capillary:0.8`, `sticking:0.05`, `none`).
    ///
    /// # Errors
    ///
    /// An unknown name, a missing or unreadable severity, or one
    /// [`Fault::check`] refuses.
    pub fn parse(s: &str) -> Result<Fault, String> {
        if s == "none" {
            return Ok(Fault::None);
        }
        let (name, value) = s
            .split_once(':')
            .ok_or_else(|| format!("`{s}`: a fault is name:severity (e.g. capillary:0.8) or none"))?;
        let v: f64 = value.parse().map_err(|_| format!("`{value}`: not a number"))?;
        let f = match name {
            "capillary" => Fault::CapillaryRestricted(v),
            "orifice-worn" => Fault::OrificeWorn(v),
            "orifice-clogged" => Fault::OrificeClogged(v),
            "spring" => Fault::SpringRelaxed(v),
            "preload" => Fault::PreloadLost(v),
            "sticking" => Fault::Sticking(v),
            "sensor-offset" => Fault::SensorOffset(v),
            _ => {
                return Err(format!(
                    "`{name}`: faults are capillary, orifice-worn, orifice-clogged, spring, preload, sticking, \
                     sensor-offset, none"
                ));
            }
        };
        f.check()?;
        Ok(f)
    }

    /// Whether the severity is one the fault can have: a factor positive
    /// and on its side of 1 (a worn orifice above, the others below), a
    /// friction fraction in `[0, 1)`, an offset finite.
    ///
    /// # Errors
    ///
    /// The fault and why.
    pub fn check(&self) -> Result<(), String> {
        let ok = match *self {
            Fault::None => true,
            Fault::OrificeWorn(f) => f >= 1.0 && f.is_finite(),
            Fault::CapillaryRestricted(f) | Fault::OrificeClogged(f) | Fault::SpringRelaxed(f) => f > 0.0 && f <= 1.0,
            Fault::PreloadLost(f) => (0.0..=1.0).contains(&f),
            Fault::Sticking(f) => (0.0..1.0).contains(&f),
            Fault::SensorOffset(f) => f.is_finite(),
        };
        if ok {
            Ok(())
        } else {
            Err(format!("{self}: severity out of range"))
        }
    }

    /// The device `core` with the fault (the friction and the sensor offset
    /// leave the fields unchanged: [`Fault::friction`], [`Fault::offset`]).
    pub fn degrade(&self, core: &RawCore) -> RawCore {
        let mut c = *core;
        match *self {
            Fault::CapillaryRestricted(f) => c.laminar_diameter *= f.powf(0.25),
            Fault::OrificeWorn(f) | Fault::OrificeClogged(f) => c.turbulent_diameter *= f.sqrt(),
            Fault::SpringRelaxed(f) => c.spring_rate *= f,
            Fault::PreloadLost(f) => c.preload *= f,
            Fault::None | Fault::Sticking(_) | Fault::SensorOffset(_) => {}
        }
        c
    }

    /// The Coulomb friction force on the plunger of `core` \[N\]: `frac c (x0
    /// + stroke / 2)` for [`Fault::Sticking`], 0 otherwise.
    pub fn friction(&self, core: &RawCore) -> f64 {
        match *self {
            Fault::Sticking(frac) => frac * core.spring_rate * (core.preload + 0.5 * core.stroke),
            _ => 0.0,
        }
    }

    /// The offset of `sensor`'s reading \[its unit\]: `frac (max - min)` for
    /// [`Fault::SensorOffset`], 0 otherwise.
    pub fn offset(&self, sensor: &SecondSensor) -> f64 {
        match *self {
            Fault::SensorOffset(frac) => frac * sensor.width(),
            _ => 0.0,
        }
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Fault::None => write!(f, "none"),
            Fault::CapillaryRestricted(v) => write!(f, "capillary restricted (conductance x {v})"),
            Fault::OrificeWorn(v) => write!(f, "orifice worn (area x {v})"),
            Fault::OrificeClogged(v) => write!(f, "orifice clogged (area x {v})"),
            Fault::SpringRelaxed(v) => write!(f, "spring relaxed (rate x {v})"),
            Fault::PreloadLost(v) => write!(f, "preload lost (x {v})"),
            Fault::Sticking(v) => write!(f, "sticking (friction {v} of the mid-stroke spring force)"),
            Fault::SensorOffset(v) => write!(f, "sensor offset ({v} of the span)"),
        }
    }
}

/// A fault and when it starts: the healthy device before `onset`, the
/// degraded one from `onset` on \[s\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Injection {
    /// The fault.
    pub fault: Fault,
    /// Its onset `t_fault` \[s\].
    pub onset: f64,
}

impl Injection {
    /// No fault.
    pub const HEALTHY: Injection = Injection {
        fault: Fault::None,
        onset: f64::INFINITY,
    };

    /// Whether the fault is present at `t` \[s\] (never for [`Fault::None`]).
    pub fn active(&self, t: f64) -> bool {
        self.fault != Fault::None && t >= self.onset
    }
}

/// The true state of the device at a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Chamber (a) pressure \[Pa\].
    pub p_a: f64,
    /// Chamber (b) pressure \[Pa\].
    pub p_b: f64,
    /// Plunger displacement, within the stops \[m\].
    pub x: f64,
    /// The frictionless displacement `A (p_b - p_a) / c - x0`, not clamped
    /// to the stops \[m\].
    pub x_free: f64,
}

impl Truth {
    /// The value `quantity` measures \[Pa or m\].
    pub fn value(&self, quantity: Quantity) -> f64 {
        match quantity {
            Quantity::PA => self.p_a,
            Quantity::PB => self.p_b,
            Quantity::DPAB => self.p_b - self.p_a,
            Quantity::X => self.x,
        }
    }
}

/// The frictionless displacement of `core` at the equilibrium pressures of
/// `point`, not clamped to the stops: `A (p_b - p_a) / c - x0` \[m\] (the
/// reference's spring force is `c (x0 + x)`).
pub fn free_displacement(core: &RawCore, point: &Point) -> f64 {
    // As the reference writes it (the same rounding: `x_free` clamped is
    // `equilibrium`'s `x` to the bit).
    let area = PI * core.plunger_diameter.powi(2) / 4.0;
    (point.p_b - point.p_a) * area / core.spring_rate - core.preload
}

/// The quasi-static Coulomb friction law: the play (backlash) operator of
/// half-width `band = F / c` \[m\] on the frictionless displacement `x_free`
/// \[m\], from the plunger's last position `x_prev` \[m\], clamped to the
/// stops `[0, stroke]`.
pub fn play(x_prev: f64, x_free: f64, band: f64, stroke: f64) -> f64 {
    x_prev.clamp(x_free - band, x_free + band).clamp(0.0, stroke)
}

/// The true device through an injection: healthy (`healthy`) before the
/// onset, degraded after; the plunger's position remembered for the
/// friction law.
#[derive(Clone, Debug)]
pub struct Device {
    /// The healthy (as-built) device.
    pub healthy: RawCore,
    /// The device with the fault.
    pub faulty: RawCore,
    /// The injection.
    pub injection: Injection,
    /// The Coulomb friction with the fault \[N\].
    pub friction: f64,
    x: Option<f64>,
}

impl Device {
    /// The device `healthy` through `injection`.
    ///
    /// # Errors
    ///
    /// A severity [`Fault::check`] refuses, or a degraded device the
    /// parameter file would refuse.
    pub fn new(healthy: &RawCore, injection: Injection) -> Result<Device, String> {
        injection.fault.check()?;
        let faulty = injection.fault.degrade(healthy);
        faulty
            .validate()
            .map_err(|e| format!("{}: the degraded device is invalid: {e}", injection.fault))?;
        Ok(Device {
            healthy: *healthy,
            faulty,
            injection,
            friction: injection.fault.friction(healthy),
            x: None,
        })
    }

    /// The device's fields at `t` \[s\].
    pub fn core_at(&self, t: f64) -> &RawCore {
        if self.injection.active(t) {
            &self.faulty
        } else {
            &self.healthy
        }
    }

    /// The state at `t` \[s\] with the oil at `t_oil` \[C\]: the reference
    /// equilibrium of the device at `t`, the displacement through the
    /// friction law from the last call's (calls in time order).
    pub fn at(&mut self, t: f64, t_oil: f64) -> Truth {
        let active = self.injection.active(t);
        let core = *self.core_at(t);
        let e = equilibrium(&core, t_oil);
        let x_free = free_displacement(&core, &e);
        let band = if active { self.friction / core.spring_rate } else { 0.0 };
        let x = match self.x {
            Some(prev) if band > 0.0 => play(prev, x_free, band, core.stroke),
            _ => e.x,
        };
        self.x = Some(x);
        Truth {
            p_a: e.p_a,
            p_b: e.p_b,
            x,
            x_free,
        }
    }
}

/// 1-sigma manufacturing spreads of a device around its nominal design
/// (relative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    /// Capillary bore (its conductance goes with the fourth power).
    pub capillary_bore: f64,
    /// Orifice bore (its area with the square).
    pub orifice_bore: f64,
    /// Spring rate.
    pub spring_rate: f64,
    /// Preload (the spring's installed compression).
    pub preload: f64,
}

/// The spreads [`as_built`] draws: capillary bore 0.5 %, orifice bore 1 %,
/// spring rate 2 %, preload 5 % (1 sigma). Assumptions of this generator
/// for a drawn capillary, a drilled orifice, a coil spring of a good
/// commercial grade and a preload set by the stack-up of the spring seat:
/// not measured values. The other fields are nominal.
pub const SPREAD: Spread = Spread {
    capillary_bore: 0.005,
    orifice_bore: 0.01,
    spring_rate: 0.02,
    preload: 0.05,
};

/// A device as built from `nominal`: capillary bore, orifice bore, spring
/// rate and preload each times `1 + s z`, `s` of [`SPREAD`], `z` standard
/// normal cut at 3 sigma; the preload kept within the stroke. Drawn again
/// (at most 100 times) while the device is one the parameter file refuses;
/// then nominal.
pub fn as_built(nominal: &RawCore, rng: &mut Rng) -> RawCore {
    for _ in 0..100 {
        let mut z = || normal(rng).clamp(-3.0, 3.0);
        let mut c = *nominal;
        c.laminar_diameter *= 1.0 + SPREAD.capillary_bore * z();
        c.turbulent_diameter *= 1.0 + SPREAD.orifice_bore * z();
        c.spring_rate *= 1.0 + SPREAD.spring_rate * z();
        c.preload = (c.preload * (1.0 + SPREAD.preload * z())).clamp(0.0, c.stroke);
        if c.validate().is_ok() {
            return c;
        }
    }
    *nominal
}

/// What the second sensor measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Chamber (a) pressure \[Pa\].
    PA,
    /// Chamber (b) pressure \[Pa\].
    PB,
    /// `p_b - p_a` \[Pa\] (a differential transducer).
    DPAB,
    /// Plunger displacement \[m\] (an LVDT or an eddy-current sensor).
    X,
}

impl Quantity {
    /// Every quantity.
    pub const ALL: [Quantity; 4] = [Quantity::PA, Quantity::PB, Quantity::DPAB, Quantity::X];

    /// Its name (`p_a`, `p_b`, `dp_ab`, `x`).
    pub fn name(self) -> &'static str {
        match self {
            Quantity::PA => "p_a",
            Quantity::PB => "p_b",
            Quantity::DPAB => "dp_ab",
            Quantity::X => "x",
        }
    }

    /// Its SI unit.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::X => "m",
            _ => "Pa",
        }
    }

    /// The quantity named `s` (as [`Quantity::name`]).
    pub fn parse(s: &str) -> Option<Quantity> {
        Quantity::ALL.into_iter().find(|q| q.name() == s)
    }
}

/// The second sensor's specification.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondSensor {
    /// What it measures.
    pub quantity: Quantity,
    /// Standard deviation of one reading's white noise \[Pa or m\].
    pub noise_sd: f64,
    /// Accuracy class: the fixed error's limit, as a fraction of the span
    /// (0.001: class 0.1); each device's offset is uniform within it.
    pub accuracy: f64,
    /// Measuring range `(min, max)` \[Pa or m\]: the ADC's span.
    pub span: (f64, f64),
    /// Readings per second \[Hz\] (rounded to a whole number of estimator
    /// ticks between readings).
    pub rate_hz: f64,
}

impl SecondSensor {
    /// Bits of the ADC that digitises the sensor over its span.
    pub const ADC_BITS: u32 = 12;

    /// The defaults for `quantity` on `core`: a chamber pressure over `0 ..
    /// p_c + dp` (the supply), the differential `p_b - p_a` over `-dp ..
    /// dp`, the displacement over `0 .. 1.2 stroke`; accuracy class 0.1
    /// (0.1 % of the span), noise 0.05 % of the span (1 sigma), 100 Hz.
    pub fn default_for(quantity: Quantity, core: &RawCore) -> SecondSensor {
        let dp = core.pressure_drop;
        let span = match quantity {
            Quantity::PA | Quantity::PB => (0.0, core.outlet_pressure + dp),
            Quantity::DPAB => (-dp, dp),
            Quantity::X => (0.0, 1.2 * core.stroke),
        };
        SecondSensor {
            quantity,
            noise_sd: 5e-4 * (span.1 - span.0),
            accuracy: 1e-3,
            span,
            rate_hz: 100.0,
        }
    }

    /// `max - min` \[Pa or m\].
    pub fn width(&self) -> f64 {
        self.span.1 - self.span.0
    }

    /// One ADC step \[Pa or m\]: the span over `2^12 - 1` steps.
    pub fn lsb(&self) -> f64 {
        self.width() / f64::from((1u32 << Self::ADC_BITS) - 1)
    }

    /// `v` \[Pa or m\] as the ADC reports it: rounded to the nearest code,
    /// saturated at the span's ends.
    pub fn quantise(&self, v: f64) -> f64 {
        let full = f64::from((1u32 << Self::ADC_BITS) - 1);
        let code = ((v - self.span.0) / self.lsb()).round().clamp(0.0, full);
        self.span.0 + code * self.lsb()
    }
}

/// The probe's converter, as the firmware's driver quantises.
#[derive(Clone, Copy, Debug)]
pub enum Converter {
    /// A platinum RTD through the MAX31865 (15-bit ratio to the reference
    /// resistor, the file's Callendar-Van Dusen curve both ways).
    Rtd(max31865::Settings),
    /// An NTC in a divider on the STM32F4's ADC (one conversion a reading:
    /// the oversampling's averaging of noise is not modelled).
    Ntc(ntc::Settings),
}

impl Converter {
    /// The converter of the file's `estimator.sensor`.
    pub fn of(raw: &RawEstimator) -> Converter {
        match SensorKind::of(raw) {
            SensorKind::Rtd => Converter::Rtd(max31865::Settings::from_params(raw)),
            SensorKind::Ntc => Converter::Ntc(ntc::Settings::from_params(raw)),
        }
    }

    /// The reading \[C\] of an element at `t` \[C\] (NaN where the curve has
    /// none).
    pub fn quantise(&self, t: f64) -> f64 {
        let r = match self {
            Converter::Rtd(s) => {
                let code = max31865::code_of(s, s.cvd.resistance(s.r0, t as f32));
                s.cvd.temperature(s.r0, f32::from(code) * s.reference / 32768.0)
            }
            Converter::Ntc(s) => s.temperature_of(f32::from(s.code_of(t as f32))),
        };
        r.map_or(f64::NAN, f64::from)
    }
}

/// The oil temperature probe in its well: lag, tolerance, noise and
/// converter (the module's assumptions).
#[derive(Clone, Debug)]
pub struct Probe {
    /// The probe's `[probe]` section.
    pub spec: RawProbe,
    /// Where within its tolerance this probe sits: its error is `class
    /// (a + b |T|)`, `class` in `[-1, 1]`.
    pub class: f64,
    /// The converter.
    pub converter: Converter,
    /// The well's temperature \[C\] (the oil's without a well).
    pub well: f64,
    /// The element's temperature \[C\].
    pub element: f64,
}

impl Probe {
    /// A probe settled at `t` \[C\].
    pub fn new(raw: &RawParams, class: f64, t: f64) -> Probe {
        Probe {
            spec: raw.probe,
            class,
            converter: Converter::of(&raw.estimator),
            well: t,
            element: t,
        }
    }

    /// Advances the lags by `dt` \[s\] with the oil linear over it, `oil0 +
    /// slope t` \[C, C/s\]: exact without a well; with one, the well's output
    /// is taken linear over steps of at most a hundredth of the shorter
    /// time constant.
    pub fn advance(&mut self, oil0: f64, slope: f64, dt: f64) {
        let (tau, tau_w) = (self.spec.time_constant, self.spec.well_time_constant);
        if dt <= 0.0 {
            return;
        }
        if tau_w > 0.0 {
            let n = (dt / (0.01 * tau.min(tau_w))).ceil().max(1.0);
            let h = dt / n;
            for k in 0..n as u32 {
                let u = oil0 + slope * h * f64::from(k);
                let w0 = self.well;
                self.well = lag_step(w0, u, slope, tau_w, h);
                self.element = lag_step(self.element, w0, (self.well - w0) / h, tau, h);
            }
        } else {
            self.element = lag_step(self.element, oil0, slope, tau, dt);
            self.well = oil0 + slope * dt;
        }
    }

    /// Advances the lags from `t0` to `t1` \[s\] through `profile`, piece by
    /// piece of its piecewise-linear history.
    pub fn advance_through(&mut self, profile: &Profile, t0: f64, t1: f64) {
        let mut s = t0;
        while s < t1 {
            let (u0, slope, end) = profile.piece(s);
            let e = end.min(t1);
            self.advance(u0, slope, e - s);
            s = e;
        }
    }

    /// The element's temperature with this probe's fixed error \[C\].
    pub fn biased(&self) -> f64 {
        self.element + self.class * self.spec.tolerance_at(self.element)
    }

    /// One reading \[C\]: the element, its fixed error, noise, the converter.
    pub fn read(&self, rng: &mut Rng) -> f64 {
        self.converter.quantise(self.biased() + self.spec.noise * normal(rng))
    }
}

/// A piecewise-linear oil temperature history: knots `(t [s], T [C])` in
/// time order (two at one time: a jump), held before the first and after
/// the last.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    knots: Vec<(f64, f64)>,
    warmed_up: f64,
}

/// Amplitude of the wander of a hold around its level \[C\].
pub const WANDER: f64 = 0.5;

impl Profile {
    /// The history through `knots` (sorted by time; `warmed_up` 0).
    ///
    /// # Errors
    ///
    /// No knot, a knot not finite, or times out of order.
    pub fn from_knots(knots: Vec<(f64, f64)>) -> Result<Profile, String> {
        if knots.is_empty() {
            return Err("a profile needs a knot".into());
        }
        if knots.iter().any(|k| !(k.0.is_finite() && k.1.is_finite())) {
            return Err("a knot is not finite".into());
        }
        if knots.windows(2).any(|w| w[1].0 < w[0].0) {
            return Err("knots out of time order".into());
        }
        Ok(Profile { knots, warmed_up: 0.0 })
    }

    /// The oil held at `t` \[C\].
    pub fn hold(t: f64) -> Profile {
        Profile {
            knots: vec![(0.0, t)],
            warmed_up: 0.0,
        }
    }

    /// At `from` until `t0`, then at `to` \[C, s\].
    pub fn step(from: f64, to: f64, t0: f64) -> Profile {
        Profile {
            knots: vec![(0.0, from), (t0, from), (t0, to)],
            warmed_up: 0.0,
        }
    }

    /// At `from` until `t0`, then ramping at `rate` \[C/s\] to `to`.
    pub fn ramp(from: f64, to: f64, rate: f64, t0: f64) -> Profile {
        Profile {
            knots: vec![(0.0, from), (t0, from), (t0 + (to - from).abs() / rate, to)],
            warmed_up: 0.0,
        }
    }

    /// Seeded "ordinary operation" within `range` = (`valid_min`,
    /// `valid_max`) \[C\] for `duration` \[s\]:
    ///
    /// * a cold start at 20-30 C (raised to the range's bottom, uniform in
    ///   `max(20, lo) .. max(30, lo + 4)`), held 10-60 s, warming at
    ///   0.01-0.1 C/s to a working temperature uniform in the upper half of
    ///   the range;
    /// * then events, repeated: a hold of 2-15 minutes with a slow wander
    ///   (a knot every 20-60 s, within +-[`WANDER`] of its level); then a
    ///   step of 5-15 C either way at 0.5-1 C/s (30 %: a cooler switching),
    ///   a ramp of 5-15 C at 0.02-0.5 C/s (a load change, 38 %), a return
    ///   to the working temperature at 0.05-0.5 C/s (30 %), or a shutdown
    ///   (2 %): cooling at 0.01-0.03 C/s to a cold level, standing 10-60
    ///   minutes, warming up again.
    ///
    /// Levels stay [`WANDER`] + 0.5 C inside the range (a step that would
    /// leave it goes the other way, or is cut); the history ends at
    /// `duration`.
    pub fn ordinary(range: (f64, f64), duration: f64, seed: u64) -> Profile {
        let (lo, hi) = range;
        let mut rng = Rng::new(seed);
        let margin = (WANDER + 0.5).min(0.25 * (hi - lo));
        let (a, b) = (lo + margin, hi - margin);
        let cold_level = |rng: &mut Rng| rng.uniform(lo.max(20.0), (lo + 4.0).max(30.0)).clamp(lo, b);
        let cold = cold_level(&mut rng);
        let work = rng.uniform(0.5 * (a + b), b);
        let mut knots = vec![(0.0, cold)];
        let mut t = rng.uniform(10.0, 60.0);
        knots.push((t, cold));
        t += (work - cold).abs() / rng.uniform(0.01, 0.1);
        knots.push((t, work));
        let warmed_up = t;
        let mut level = work;
        let span = |rng: &mut Rng, level: f64| {
            let d = rng.uniform(5.0, 15.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
            let to = if (a..=b).contains(&(level + d)) {
                level + d
            } else {
                level - d
            };
            to.clamp(a, b)
        };
        while t < duration {
            let end = t + rng.uniform(120.0, 900.0);
            loop {
                let dt = rng.uniform(20.0, 60.0);
                // The last wander knot 20 s or more before the hold's end.
                if t + dt + 20.0 > end {
                    break;
                }
                t += dt;
                knots.push((t, (level + rng.uniform(-WANDER, WANDER)).clamp(lo, hi)));
            }
            t = end;
            knots.push((t, level));
            let r = rng.unit();
            let (to, rate) = if r < 0.02 {
                let c = cold_level(&mut rng);
                t += (level - c).abs() / rng.uniform(0.01, 0.03);
                knots.push((t, c));
                t += rng.uniform(600.0, 3600.0);
                knots.push((t, c));
                level = c;
                (work, rng.uniform(0.01, 0.1))
            } else if r < 0.32 {
                (span(&mut rng, level), rng.uniform(0.5, 1.0))
            } else if r < 0.7 {
                (span(&mut rng, level), rng.uniform(0.02, 0.5))
            } else {
                (work, rng.uniform(0.05, 0.5))
            };
            if to != level {
                t += (to - level).abs() / rate;
                knots.push((t, to));
                level = to;
            }
        }
        let mut p = Profile { knots, warmed_up };
        p.truncate(duration);
        p
    }

    /// [`Profile::ordinary`] over 24 hours: the healthy history a
    /// false-alarm count runs through.
    pub fn day(range: (f64, f64), seed: u64) -> Profile {
        Profile::ordinary(range, 86_400.0, seed)
    }

    /// Cuts the history at `t_end` \[s\] (a knot there).
    fn truncate(&mut self, t_end: f64) {
        let v = self.temperature(t_end);
        self.knots.retain(|k| k.0 < t_end);
        self.knots.push((t_end, v));
    }

    /// The knots.
    pub fn knots(&self) -> &[(f64, f64)] {
        &self.knots
    }

    /// When the first warm-up reaches the working temperature \[s\] (0 for a
    /// history without one); a campaign's onsets come after it.
    pub fn warmed_up(&self) -> f64 {
        self.warmed_up
    }

    /// The last knot's time \[s\].
    pub fn end(&self) -> f64 {
        self.knots.last().map_or(0.0, |k| k.0)
    }

    /// The lowest and highest temperature \[C\].
    pub fn extent(&self) -> (f64, f64) {
        self.knots
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), k| (l.min(k.1), h.max(k.1)))
    }

    /// The largest rate of change \[C/s\] (jumps left out).
    pub fn max_rate(&self) -> f64 {
        self.knots
            .windows(2)
            .filter(|w| w[1].0 > w[0].0)
            .map(|w| ((w[1].1 - w[0].1) / (w[1].0 - w[0].0)).abs())
            .fold(0.0, f64::max)
    }

    /// The temperature at `t` \[s\] \[C\] (after a jump at `t`: the new value).
    pub fn temperature(&self, t: f64) -> f64 {
        self.piece(t).0
    }

    /// The piece in force at `t` \[s\]: the temperature there \[C\], its slope
    /// \[C/s\], and the time the piece ends \[s\] (infinite after the last knot).
    pub fn piece(&self, t: f64) -> (f64, f64, f64) {
        let k = &self.knots;
        let i = k.partition_point(|q| q.0 <= t);
        if i == 0 {
            (k[0].1, 0.0, k[0].0)
        } else if i == k.len() {
            (k[i - 1].1, 0.0, f64::INFINITY)
        } else {
            let ((t0, v0), (t1, v1)) = (k[i - 1], k[i]);
            let slope = (v1 - v0) / (t1 - t0);
            (v0 + slope * (t - t0), slope, t1)
        }
    }
}

/// One record: what the device and its sensors did at tick `tick`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// The estimator tick it falls on (`t = tick / estimator.tick_hz`).
    pub tick: u64,
    /// Time \[s\].
    pub t: f64,
    /// The oil's true temperature \[C\].
    pub t_true: f64,
    /// The probe's reading \[C\], on the ticks it is due (NaN: a value the
    /// converter cannot report).
    pub probe: Option<f64>,
    /// The second sensor's reading \[Pa or m\], on the ticks it is due.
    pub second: Option<f64>,
    /// The device's true state.
    pub truth: Truth,
    /// Whether the fault is present.
    pub fault_active: bool,
}

/// A campaign run: the nominal design (what the estimator is given), the
/// true device, the fault, the history, the sensors and the per-device
/// draws. Built by [`Scenario::new`]; every field may be changed before
/// [`Scenario::records`].
#[derive(Clone, Debug)]
pub struct Scenario {
    /// The nominal design: the estimator's parameter file, the probe's.
    pub nominal: RawParams,
    /// The healthy device as built ([`as_built`] of the nominal).
    pub device: RawCore,
    /// The fault and its onset.
    pub injection: Injection,
    /// The oil temperature history.
    pub profile: Profile,
    /// How long the records run \[s\].
    pub duration: f64,
    /// The second sensor.
    pub sensor: SecondSensor,
    /// The probe within its tolerance, `[-1, 1]` ([`Probe::class`]).
    pub probe_class: f64,
    /// The second sensor's fixed offset \[Pa or m\], within its accuracy.
    pub sensor_offset: f64,
    /// The seeds of the probe's and the second sensor's noise.
    pub noise_seed: (u64, u64),
}

impl Scenario {
    /// The run of `nominal` with the second sensor `sensor`, `injection`,
    /// the history `profile` for `duration` \[s\], from `seed`: the device
    /// drawn as built, the probe's place within its tolerance, the sensor's
    /// offset within its class, the seeds of the two noises, each from its
    /// own stream of `seed`.
    pub fn new(
        nominal: &RawParams,
        sensor: SecondSensor,
        injection: Injection,
        profile: Profile,
        duration: f64,
        seed: u64,
    ) -> Scenario {
        let s = streams(seed);
        let device = as_built(&nominal.core, &mut Rng::new(s[0]));
        let mut draws = Rng::new(s[2]);
        let probe_class = draws.uniform(-1.0, 1.0);
        let sensor_offset = draws.uniform(-1.0, 1.0) * sensor.accuracy * sensor.width();
        Scenario {
            nominal: *nominal,
            device,
            injection,
            profile,
            duration,
            sensor,
            probe_class,
            sensor_offset,
            noise_seed: (s[3], s[4]),
        }
    }

    /// [`Scenario::new`] with the default sensor for `quantity` and
    /// ordinary operation ([`Profile::ordinary`] over the nominal's
    /// validated range) for `duration` \[s\], from `seed`.
    pub fn ordinary(
        nominal: &RawParams,
        quantity: Quantity,
        injection: Injection,
        duration: f64,
        seed: u64,
    ) -> Scenario {
        let range = (nominal.estimator.valid_min, nominal.estimator.valid_max);
        let profile = Profile::ordinary(range, duration, streams(seed)[1]);
        let sensor = SecondSensor::default_for(quantity, &nominal.core);
        Scenario::new(nominal, sensor, injection, profile, duration, seed)
    }

    /// The record stream.
    ///
    /// # Errors
    ///
    /// A fault the device cannot have ([`Device::new`]).
    pub fn records(&self) -> Result<Records, String> {
        let e = &self.nominal.estimator;
        let tick = 1.0 / e.tick_hz;
        let probe_every = (reading_period(e) * e.tick_hz).round().max(1.0) as u64;
        let second_every = (e.tick_hz / self.sensor.rate_hz).round().max(1.0) as u64;
        let t0 = self.profile.temperature(0.0);
        Ok(Records {
            profile: self.profile.clone(),
            device: Device::new(&self.device, self.injection)?,
            probe: Probe::new(&self.nominal, self.probe_class, t0),
            sensor: self.sensor,
            offset: self.sensor_offset,
            fault_offset: self.injection.fault.offset(&self.sensor),
            probe_noise: Rng::new(self.noise_seed.0),
            sensor_noise: Rng::new(self.noise_seed.1),
            tick,
            probe_every,
            second_every,
            next: 0,
            end: (self.duration / tick).round() as u64,
            last_t: 0.0,
        })
    }

    /// The record stream through the firmware's estimator of the nominal
    /// design ([`Estimated`]).
    ///
    /// # Errors
    ///
    /// As [`Scenario::records`]; a nominal design the estimator refuses.
    pub fn estimated(&self) -> Result<Estimated, String> {
        Estimated::new(&self.nominal, self.records()?)
    }
}

/// An onset after the history's warm-up: ten minutes after it reaches the
/// working temperature, or half-way through a run too short for that \[s\].
pub fn onset_after_warm_up(profile: &Profile, duration: f64) -> f64 {
    let t = profile.warmed_up() + 600.0;
    if t < duration { t } else { 0.5 * duration }
}

/// Oil temperature span \[K\] over which a fault of the divider is to be
/// named, and the time \[s\] it is to take ([`onset_before_move`]).
pub const MOVE: (f64, f64) = (5.0, 60.0);

/// An onset just before the history moves the oil by [`MOVE`]'s span within
/// its time: the first time `t` from `after` on (every second) where the
/// oil's temperature starts moving and spans `MOVE.0` over `[t, t +
/// MOVE.1]`, less `lead` \[s\]; `None` when no such move follows.
pub fn onset_before_move(profile: &Profile, after: f64, lead: f64) -> Option<f64> {
    let (span, within) = MOVE;
    let end = profile.end() - within;
    let mut t = after.max(0.0);
    while t < end {
        let moving = (profile.temperature(t + 1.0) - profile.temperature(t)).abs() > 0.05;
        if moving {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut u = t;
            while u <= t + within {
                let v = profile.temperature(u);
                lo = lo.min(v);
                hi = hi.max(v);
                u += 0.5;
            }
            if hi - lo >= span {
                return Some((t - lead).max(after));
            }
        }
        t += 1.0;
    }
    None
}

/// As [`catalogue`], the onset [`onset_before_move`] (ten minutes after
/// the warm-up, `lead` before the move) where the history has such a move,
/// else [`onset_after_warm_up`].
pub fn catalogue_before_move(
    nominal: &RawParams,
    quantity: Quantity,
    duration: f64,
    seed: u64,
    lead: f64,
) -> Vec<Scenario> {
    let mut runs = catalogue(nominal, quantity, duration, seed);
    let profile = &runs[0].profile;
    if let Some(onset) = onset_before_move(profile, profile.warmed_up() + 600.0, lead) {
        for s in &mut runs {
            s.injection.onset = onset;
        }
    }
    runs
}

/// One scenario per fault of [`Fault::CATALOGUE`] for `nominal` with the
/// default second sensor for `quantity`, ordinary operation for `duration`
/// \[s\], the onset [`onset_after_warm_up`], all from `seed`: the same
/// device, history, offsets and noises in each, only the fault differs (a
/// paired comparison; [`Fault::None`] first, the false-alarm baseline).
pub fn catalogue(nominal: &RawParams, quantity: Quantity, duration: f64, seed: u64) -> Vec<Scenario> {
    let base = Scenario::ordinary(nominal, quantity, Injection::HEALTHY, duration, seed);
    let onset = onset_after_warm_up(&base.profile, duration);
    Fault::CATALOGUE
        .iter()
        .map(|&fault| Scenario {
            injection: Injection { fault, onset },
            ..base.clone()
        })
        .collect()
}

/// Independent seeds of a scenario's parts, from `seed`: device, history,
/// per-device draws, probe noise, sensor noise.
fn streams(seed: u64) -> [u64; 5] {
    let mut r = Rng::new(seed ^ 0xCA4D_A7A0_0000_0000);
    [r.next_u64(), r.next_u64(), r.next_u64(), r.next_u64(), r.next_u64()]
}

/// The records of a [`Scenario`], in time order, one on each estimator
/// tick where the probe's or the second sensor's reading is due (both on
/// tick 0), through `duration` (inclusive).
#[derive(Clone, Debug)]
pub struct Records {
    profile: Profile,
    device: Device,
    probe: Probe,
    sensor: SecondSensor,
    offset: f64,
    fault_offset: f64,
    probe_noise: Rng,
    sensor_noise: Rng,
    tick: f64,
    probe_every: u64,
    second_every: u64,
    next: u64,
    end: u64,
    last_t: f64,
}

impl Records {
    /// The estimator's tick \[s\].
    pub fn tick(&self) -> f64 {
        self.tick
    }

    /// Ticks between the probe's readings and between the second
    /// sensor's.
    pub fn every(&self) -> (u64, u64) {
        (self.probe_every, self.second_every)
    }

    /// The second sensor's reading of `truth` at `t` \[s\].
    fn read_second(&mut self, truth: &Truth, t: f64) -> f64 {
        let fault = if self.device.injection.active(t) {
            self.fault_offset
        } else {
            0.0
        };
        let v = truth.value(self.sensor.quantity)
            + self.offset
            + fault
            + self.sensor.noise_sd * normal(&mut self.sensor_noise);
        self.sensor.quantise(v)
    }
}

impl Iterator for Records {
    type Item = Sample;

    fn next(&mut self) -> Option<Sample> {
        let k = self.next;
        if k > self.end {
            return None;
        }
        let up = |k: u64, n: u64| (k / n + 1) * n;
        self.next = up(k, self.probe_every).min(up(k, self.second_every));
        let t = k as f64 * self.tick;
        self.probe.advance_through(&self.profile, self.last_t, t);
        self.last_t = t;
        let t_true = self.profile.temperature(t);
        let truth = self.device.at(t, t_true);
        let probe = k
            .is_multiple_of(self.probe_every)
            .then(|| self.probe.read(&mut self.probe_noise));
        let second = k.is_multiple_of(self.second_every).then(|| self.read_second(&truth, t));
        Some(Sample {
            tick: k,
            t,
            t_true,
            probe,
            second,
            truth,
            fault_active: self.device.injection.active(t),
        })
    }
}

/// What the monitor consumes per second-sensor reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    /// Time \[s\].
    pub t: f64,
    /// The oil's true temperature \[C\].
    pub t_true: f64,
    /// The estimator's oil temperature after this tick \[C\].
    pub t_estimated: f64,
    /// The second sensor's reading \[Pa or m\].
    pub second: f64,
    /// The device's true state.
    pub truth: Truth,
    /// Whether the fault is present.
    pub fault_active: bool,
    /// The estimator's whole estimate after this tick (its twin's `x`,
    /// `p_a`, `p_b` of the nominal design: what a residual compares the
    /// reading with).
    pub estimate: StateEstimate,
}

/// A record stream run through the firmware's `f32` [`Estimator`] of the
/// nominal design, every tick (the probe's readings on their ticks,
/// nothing between), yielding one [`Observation`] per second-sensor
/// reading. A probe reading the converter cannot report is a tick
/// without a sample.
pub struct Estimated {
    records: Records,
    estimator: Estimator,
    tick: u64,
}

impl Estimated {
    /// `records` through the estimator of `nominal`, started at the first
    /// record's probe reading.
    ///
    /// # Errors
    ///
    /// A design the estimator refuses; a first record without a probe
    /// reading.
    pub fn new(nominal: &RawParams, records: Records) -> Result<Estimated, String> {
        let p32 = Params::<f32>::new(nominal).map_err(|e| e.to_string())?;
        let config = EstimatorConfig::new(nominal).map_err(|e| e.to_string())?;
        let first = records
            .clone()
            .next()
            .and_then(|s| s.probe)
            .filter(|v| v.is_finite())
            .ok_or("the first record has no probe reading")?;
        let estimator = Estimator::new(&p32, config, first as f32).map_err(|e| e.to_string())?;
        Ok(Estimated {
            records,
            estimator,
            tick: 0,
        })
    }

    /// The estimator.
    pub fn estimator(&self) -> &Estimator {
        &self.estimator
    }
}

impl Iterator for Estimated {
    type Item = Observation;

    fn next(&mut self) -> Option<Observation> {
        loop {
            let s = self.records.next()?;
            while self.tick < s.tick {
                self.estimator.tick(Ok(None));
                self.tick += 1;
            }
            let reading = s.probe.filter(|v| v.is_finite()).map(|v| v as f32);
            let e = self.estimator.tick(Ok(reading));
            self.tick += 1;
            if let Some(second) = s.second {
                return Some(Observation {
                    t: s.t,
                    t_true: s.t_true,
                    t_estimated: f64::from(e.temperature),
                    second,
                    truth: s.truth,
                    fault_active: s.fault_active,
                    estimate: e,
                });
            }
        }
    }
}

/// A seeded design whose plunger travels over its validated range (the
/// first [`physical_params`] of `seed`'s stream whose reference
/// displacement 2 C inside the range's ends differs by a tenth of the
/// stroke or more, as `examples/observability.rs` picks them): a design on
/// one stop throughout shows no displacement fault.
pub fn design(seed: u64) -> RawParams {
    let mut rng = Rng::new(seed ^ 0x0B5E);
    loop {
        let raw = physical_params(&mut rng);
        let x = |t: f64| equilibrium(&raw.core, t).x;
        let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
        if (x(hi - 2.0) - x(lo + 2.0)).abs() >= 0.1 * raw.core.stroke {
            return raw;
        }
    }
}
