//! The parameter file's schema and its validation, in plain `f64`.
//!
//! Units are SI, temperatures in degrees Celsius (MODEL.md section 8).

use core::fmt;

/// One numeric field of the parameter file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Field {
    /// TOML section (`"plunger"`).
    pub section: &'static str,
    /// Key inside the section (`"spring_rate"`).
    pub key: &'static str,
    /// `section.key`, the name used in error messages.
    pub path: &'static str,
    /// Unit, for documentation and generated tables.
    pub unit: &'static str,
    /// Value used when the key is absent; `None` means the key is required.
    pub default: Option<f64>,
    /// One-line description.
    pub doc: &'static str,
}

macro_rules! count {
    () => { 0usize };
    ($head:tt $($tail:tt)*) => { 1usize + count!($($tail)*) };
}

macro_rules! schema {
    (
        $(#[$meta:meta])*
        struct $name:ident, const $fields:ident;
        $( $field:ident : $section:literal . $key:literal [$unit:literal] = $default:expr, $doc:literal; )*
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name {
            $( #[doc = $doc] #[doc = concat!("Unit: ", $unit, ".")] pub $field: f64, )*
        }

        #[doc = concat!("The fields of [`", stringify!($name), "`], in declaration order.")]
        pub const $fields: [Field; count!($($field)*)] = [
            $( Field {
                section: $section,
                key: $key,
                path: concat!($section, ".", $key),
                unit: $unit,
                default: $default,
                doc: $doc,
            }, )*
        ];

        impl $name {
            /// Builds the struct from values in the order of the field table.
            pub const fn from_array(values: [f64; count!($($field)*)]) -> Self {
                let [$($field),*] = values;
                Self { $($field),* }
            }
            /// The values in the order of the field table.
            pub const fn to_array(&self) -> [f64; count!($($field)*)] {
                [$(self.$field),*]
            }
        }
    };
}

schema! {
    /// The compensator's physical parameters (all required).
    struct RawCore, const CORE_FIELDS;
    walther_a: "fluid"."walther_a" ["-"] = None, "Walther constant a in log10(log10(nu_cSt + 0.7)) = a - b log10(T_K).";
    walther_b: "fluid"."walther_b" ["-"] = None, "Walther slope b.";
    density_15: "fluid"."density_15" ["kg/m^3"] = None, "Density at 15 C.";
    expansion: "fluid"."expansion" ["1/K"] = None, "Volumetric thermal expansion coefficient.";
    bulk_modulus: "fluid"."bulk_modulus" ["Pa"] = None, "Effective bulk modulus of oil and chamber walls.";
    laminar_diameter: "laminar_throttle"."diameter" ["m"] = None, "Capillary bore.";
    laminar_length: "laminar_throttle"."length" ["m"] = None, "Capillary length.";
    turbulent_diameter: "turbulent_throttle"."diameter" ["m"] = None, "Orifice bore.";
    turbulent_discharge: "turbulent_throttle"."discharge_coefficient" ["-"] = None, "Orifice discharge coefficient.";
    plunger_diameter: "plunger"."diameter" ["m"] = None, "Plunger diameter D.";
    mass: "plunger"."mass" ["kg"] = None, "Moving mass.";
    damping: "plunger"."damping" ["N s/m"] = None, "Viscous (friction) damping b, without the hydraulic damping.";
    spring_rate: "plunger"."spring_rate" ["N/m"] = None, "Spring rate c.";
    preload: "plunger"."preload" ["m"] = None, "Initial spring compression x0.";
    stroke: "plunger"."stroke" ["m"] = None, "Travel between the end stops, x_max.";
    slot_diameter: "slot"."diameter" ["m"] = None, "Diameter d of the window opened by the plunger (area pi d x).";
    slot_discharge: "slot"."discharge_coefficient" ["-"] = None, "Discharge coefficient eta of the window.";
    volume_a: "chambers"."volume_a" ["m^3"] = None, "Volume of chamber (a) at x = 0.";
    volume_b: "chambers"."volume_b" ["m^3"] = None, "Volume of chamber (b) at x = 0.";
    pressure_drop: "operating"."pressure_drop" ["Pa"] = None, "Constant drop p_p - p_c (Eq. 10).";
    outlet_pressure: "operating"."outlet_pressure" ["Pa"] = None, "Outlet pressure p_c.";
}

schema! {
    /// The driven machine (optional section `[machine]`; all or none).
    ///
    /// Its volumetric losses are laminar leakage, proportional to `1/mu`:
    /// `dQ_lost(t) = leakage_reference * mu(t_ref) / mu(t)`.
    struct RawMachine, const MACHINE_FIELDS;
    working_flow: "machine"."working_flow" ["m^3/s"] = None, "Flow Q_work the driven motor needs.";
    leakage_reference: "machine"."leakage_reference" ["m^3/s"] = None, "Volumetric loss at the reference temperature.";
    leakage_temperature: "machine"."leakage_temperature" ["C"] = None, "Reference temperature of the loss.";
}

schema! {
    /// Estimator and sensor settings (optional section `[estimator]`; every
    /// key has a default).
    struct RawEstimator, const ESTIMATOR_FIELDS;
    tick_hz: "estimator"."tick_hz" ["Hz"] = Some(1000.0), "Estimator tick rate.";
    filter_time_constant: "estimator"."filter_time_constant" ["s"] = Some(0.2), "First-order temperature filter time constant.";
    spike_threshold: "estimator"."spike_threshold" ["C"] = Some(5.0), "A sample further than this from the filtered value is a spike.";
    spike_limit: "estimator"."spike_limit" ["-"] = Some(5.0), "Consecutive agreeing out-of-band samples rejected before the next one is taken as a real step (a whole number, at most 65534).";
    valid_min: "estimator"."valid_min" ["C"] = Some(26.0), "Lower end of the validated temperature range.";
    valid_max: "estimator"."valid_max" ["C"] = Some(78.0), "Upper end of the validated temperature range.";
    oil_min: "estimator"."oil_min" ["C"] = Some(-20.0), "Coldest temperature the fluid model accepts.";
    oil_max: "estimator"."oil_max" ["C"] = Some(150.0), "Hottest temperature the fluid model accepts.";
    telemetry_hz: "estimator"."telemetry_hz" ["Hz"] = Some(2.0), "Telemetry rate (0: none; at most tick_hz / 2).";
    rtd_r0: "estimator"."rtd_r0" ["ohm"] = Some(100.0), "RTD resistance at 0 C (PT100).";
    rtd_reference: "estimator"."rtd_reference" ["ohm"] = Some(430.0), "MAX31865 reference resistor (must exceed the RTD's resistance at oil_max, else the converter saturates).";
    rtd_wires: "estimator"."rtd_wires" ["-"] = Some(3.0), "RTD connection: 2, 3 or 4 wires (MAX31865 configuration bit D4).";
    mains_hz: "estimator"."mains_hz" ["Hz"] = Some(50.0), "Mains frequency the converter's notch filter rejects: 50 or 60 (conversion every 20 or 16.7 ms).";
    rtd_a: "estimator"."rtd_a" ["1/C"] = Some(3.9083e-3), "Callendar-Van Dusen A of the RTD (IEC 60751 by default; a calibrated probe's own).";
    rtd_b: "estimator"."rtd_b" ["1/C^2"] = Some(-5.775e-7), "Callendar-Van Dusen B (IEC 60751 by default).";
    rtd_c: "estimator"."rtd_c" ["1/C^4"] = Some(-4.183e-12), "Callendar-Van Dusen C, below 0 C only (IEC 60751 by default).";
}

/// A complete, unvalidated parameter set as read from a file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawParams {
    /// The compensator (MODEL.md section 8).
    pub core: RawCore,
    /// The driven machine, if the file has a `[machine]` section.
    pub machine: Option<RawMachine>,
    /// Estimator settings (defaults where the file is silent).
    pub estimator: RawEstimator,
}

/// What is wrong with a field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Problem {
    /// The key is absent and has no default.
    Missing,
    /// NaN.
    NotANumber,
    /// +-infinity.
    Infinite,
    /// Zero or negative where physics needs a positive value.
    NotPositive,
    /// Negative where zero is allowed.
    Negative,
    /// Outside `[min, max]`.
    OutOfRange {
        /// Lowest accepted value.
        min: f64,
        /// Highest accepted value.
        max: f64,
    },
    /// Inconsistent with another field; the text says which and why.
    Inconsistent(&'static str),
    /// Must exceed a bound computed from other fields; the text says which.
    NotAbove {
        /// The value the field must exceed.
        bound: f64,
        /// Where the bound comes from.
        why: &'static str,
    },
    /// Not one of the accepted values (listed in the text).
    NotOneOf(&'static str),
    /// Representable in `f64` but not in the scalar type asked for.
    NotRepresentable(&'static str),
    /// A fraction where a count is needed.
    NotWhole,
}

/// A rejected parameter: which field (`section.key`), its value, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamError {
    /// `section.key` of the offending field.
    pub field: &'static str,
    /// The value found (NaN when missing).
    pub value: f64,
    /// The rule it breaks.
    pub problem: Problem,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.problem {
            Problem::Missing => write!(f, "{}: missing", self.field),
            Problem::NotANumber => write!(f, "{}: is NaN", self.field),
            Problem::Infinite => write!(f, "{} = {}: must be finite", self.field, self.value),
            Problem::NotPositive => write!(f, "{} = {}: must be positive", self.field, self.value),
            Problem::Negative => write!(f, "{} = {}: must not be negative", self.field, self.value),
            Problem::OutOfRange { min, max } => {
                write!(f, "{} = {}: must lie in [{}, {}]", self.field, self.value, min, max)
            }
            Problem::Inconsistent(why) => write!(f, "{} = {}: {}", self.field, self.value, why),
            Problem::NotAbove { bound, why } => {
                write!(f, "{} = {}: must exceed {} ({})", self.field, self.value, bound, why)
            }
            Problem::NotOneOf(values) => write!(f, "{} = {}: must be {}", self.field, self.value, values),
            Problem::NotRepresentable(ty) => {
                write!(f, "{} = {}: not representable as {}", self.field, self.value, ty)
            }
            Problem::NotWhole => write!(f, "{} = {}: must be a whole number", self.field, self.value),
        }
    }
}

fn err(field: &'static str, value: f64, problem: Problem) -> ParamError {
    ParamError { field, value, problem }
}

/// Finite, else the matching error.
fn finite(field: &'static str, v: f64) -> Result<f64, ParamError> {
    if v.is_nan() {
        Err(err(field, v, Problem::NotANumber))
    } else if v.is_infinite() {
        Err(err(field, v, Problem::Infinite))
    } else {
        Ok(v)
    }
}

fn positive(field: &'static str, v: f64) -> Result<f64, ParamError> {
    let v = finite(field, v)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(err(field, v, Problem::NotPositive))
    }
}

fn non_negative(field: &'static str, v: f64) -> Result<f64, ParamError> {
    let v = finite(field, v)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(err(field, v, Problem::Negative))
    }
}

fn within(field: &'static str, v: f64, min: f64, max: f64) -> Result<f64, ParamError> {
    let v = finite(field, v)?;
    if v >= min && v <= max {
        Ok(v)
    } else {
        Err(err(field, v, Problem::OutOfRange { min, max }))
    }
}

/// A whole number (counts).
fn whole(field: &'static str, v: f64) -> Result<f64, ParamError> {
    let v = finite(field, v)?;
    // Exact for |v| < 2^63 (the saturating cast changes any fraction).
    if v as i64 as f64 == v {
        Ok(v)
    } else {
        Err(err(field, v, Problem::NotWhole))
    }
}

/// Discharge coefficients live in (0, 1].
fn discharge(field: &'static str, v: f64) -> Result<f64, ParamError> {
    let v = positive(field, v)?;
    if v <= 1.0 {
        Ok(v)
    } else {
        Err(err(field, v, Problem::OutOfRange { min: 0.0, max: 1.0 }))
    }
}

const PI: f64 = core::f64::consts::PI;

impl RawCore {
    /// Checks every field against its physical rule, in file order, and the
    /// rules that tie fields together. The first violation is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        let f = &CORE_FIELDS;
        let p = |i: usize| f[i].path;
        positive(p(0), self.walther_a)?;
        positive(p(1), self.walther_b)?;
        positive(p(2), self.density_15)?;
        // rho = rho_15 / (1 + e (t - 15)) must stay positive and finite over
        // any oil temperature; 1e-2/K is ten times any hydraulic oil's.
        within(p(3), self.expansion, 0.0, 1.0e-2)?;
        positive(p(4), self.bulk_modulus)?;
        positive(p(5), self.laminar_diameter)?;
        positive(p(6), self.laminar_length)?;
        positive(p(7), self.turbulent_diameter)?;
        discharge(p(8), self.turbulent_discharge)?;
        positive(p(9), self.plunger_diameter)?;
        positive(p(10), self.mass)?;
        non_negative(p(11), self.damping)?;
        positive(p(12), self.spring_rate)?;
        non_negative(p(13), self.preload)?;
        positive(p(14), self.stroke)?;
        positive(p(15), self.slot_diameter)?;
        discharge(p(16), self.slot_discharge)?;
        positive(p(17), self.volume_a)?;
        positive(p(18), self.volume_b)?;
        positive(p(19), self.pressure_drop)?;
        non_negative(p(20), self.outlet_pressure)?;

        if self.preload > self.stroke {
            return Err(err(
                p(13),
                self.preload,
                Problem::Inconsistent("preload beyond the stroke"),
            ));
        }
        let swept = PI * self.plunger_diameter * self.plunger_diameter / 4.0 * self.stroke;
        if !(swept.is_finite() && swept > 0.0) {
            return Err(err(
                p(14),
                self.stroke,
                Problem::Inconsistent("swept volume A_p * stroke is not finite"),
            ));
        }
        // Chamber (a) shrinks by the swept volume at full stroke, so it must
        // be larger. Chamber (b) grows; the same rule is applied to it so
        // that a mirrored design (and the file format) stays symmetric.
        if self.volume_a <= swept {
            return Err(err(
                p(17),
                self.volume_a,
                Problem::Inconsistent("not larger than the swept volume A_p * stroke"),
            ));
        }
        if self.volume_b <= swept {
            return Err(err(
                p(18),
                self.volume_b,
                Problem::Inconsistent("not larger than the swept volume A_p * stroke"),
            ));
        }
        Ok(())
    }
}

impl RawMachine {
    /// Checks the machine section.
    pub fn validate(&self) -> Result<(), ParamError> {
        let p = |i: usize| MACHINE_FIELDS[i].path;
        non_negative(p(0), self.working_flow)?;
        non_negative(p(1), self.leakage_reference)?;
        within(p(2), self.leakage_temperature, -50.0, 200.0)?;
        Ok(())
    }
}

impl RawEstimator {
    /// The defaults of the `[estimator]` section.
    pub const DEFAULT: RawEstimator = {
        let mut values = [0.0; ESTIMATOR_FIELDS.len()];
        let mut i = 0;
        while i < values.len() {
            values[i] = match ESTIMATOR_FIELDS[i].default {
                Some(v) => v,
                None => f64::NAN,
            };
            i += 1;
        }
        RawEstimator::from_array(values)
    };

    /// Checks the estimator section.
    pub fn validate(&self) -> Result<(), ParamError> {
        let p = |i: usize| ESTIMATOR_FIELDS[i].path;
        within(p(0), self.tick_hz, 1.0, 100_000.0)?;
        positive(p(1), self.filter_time_constant)?;
        positive(p(2), self.spike_threshold)?;
        within(p(3), self.spike_limit, 0.0, 65_534.0)?;
        whole(p(3), self.spike_limit)?;
        within(p(6), self.oil_min, -60.0, 300.0)?;
        within(p(7), self.oil_max, -60.0, 300.0)?;
        if self.oil_max <= self.oil_min {
            return Err(err(
                p(7),
                self.oil_max,
                Problem::Inconsistent("not above estimator.oil_min"),
            ));
        }
        within(p(4), self.valid_min, self.oil_min, self.oil_max)?;
        within(p(5), self.valid_max, self.oil_min, self.oil_max)?;
        if self.valid_max <= self.valid_min {
            return Err(err(
                p(5),
                self.valid_max,
                Problem::Inconsistent("not above estimator.valid_min"),
            ));
        }
        // A telemetry tick runs none of the estimator's rotating jobs: at
        // most every second tick, so that they keep being refreshed.
        within(p(8), self.telemetry_hz, 0.0, self.tick_hz / 2.0)?;
        positive(p(9), self.rtd_r0)?;
        positive(p(10), self.rtd_reference)?;
        let wires = within(p(11), self.rtd_wires, 2.0, 4.0)?;
        whole(p(11), wires)?;
        let mains = finite(p(12), self.mains_hz)?;
        if mains != 50.0 && mains != 60.0 {
            return Err(err(p(12), mains, Problem::NotOneOf("50 or 60")));
        }
        // Around IEC 60751's 3.9083e-3, -5.775e-7, -4.183e-12: a calibrated
        // probe's coefficients differ in the third or fourth digit.
        within(p(13), self.rtd_a, 1.0e-3, 1.0e-2)?;
        within(p(14), self.rtd_b, -1.0e-5, 1.0e-5)?;
        within(p(15), self.rtd_c, -1.0e-9, 1.0e-9)?;
        // The converter inverts R(t): it must rise over the oil's range.
        let mut t = self.oil_min;
        for i in 0..=64 {
            let slope = self.rtd_slope(t);
            if !(slope > 0.0) {
                return Err(err(
                    p(14),
                    self.rtd_b,
                    Problem::Inconsistent(
                        "the RTD's resistance must rise with temperature over estimator.oil_min..oil_max",
                    ),
                ));
            }
            t = self.oil_min + (self.oil_max - self.oil_min) * f64::from(i + 1) / 64.0;
        }
        // The MAX31865's 15-bit code is R / R_ref * 2^15: the hottest oil
        // must stay below full scale (two codes of margin), else every
        // reading saturates at 32767 and reads as a sensor fault.
        let bound = self.rtd_resistance(self.oil_max) * 32768.0 / 32766.0;
        if !(self.rtd_reference > bound) {
            return Err(err(
                p(10),
                self.rtd_reference,
                Problem::NotAbove {
                    bound,
                    why: "the RTD's resistance at estimator.oil_max: the converter would saturate",
                },
            ));
        }
        Ok(())
    }

    /// Resistance [ohm] of the RTD at `t` [C] by Callendar-Van Dusen with
    /// this section's `rtd_r0`, `rtd_a`, `rtd_b`, `rtd_c` (IEC 60751 form:
    /// the `C` term below 0 C only).
    pub fn rtd_resistance(&self, t: f64) -> f64 {
        let mut r = 1.0 + self.rtd_a * t + self.rtd_b * t * t;
        if t < 0.0 {
            r += self.rtd_c * (t - 100.0) * t * t * t;
        }
        self.rtd_r0 * r
    }

    /// `dR/dt` of the RTD at `t` [ohm/C] (see [`RawEstimator::rtd_resistance`]).
    pub fn rtd_slope(&self, t: f64) -> f64 {
        let mut d = self.rtd_a + 2.0 * self.rtd_b * t;
        if t < 0.0 {
            d += self.rtd_c * (4.0 * t * t * t - 300.0 * t * t);
        }
        self.rtd_r0 * d
    }
}

impl RawParams {
    /// Validates every section.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.core.validate()?;
        if let Some(m) = &self.machine {
            m.validate()?;
        }
        self.estimator.validate()
    }

    /// Assembles a parameter set from a lookup `get(section, key)`, applying
    /// defaults and the all-or-none rule of optional sections; then validates.
    pub fn from_lookup(mut get: impl FnMut(&str, &str) -> Option<f64>) -> Result<Self, ParamError> {
        let mut core = [0.0; CORE_FIELDS.len()];
        for (slot, field) in core.iter_mut().zip(CORE_FIELDS.iter()) {
            *slot = get(field.section, field.key).or(field.default).ok_or(ParamError {
                field: field.path,
                value: f64::NAN,
                problem: Problem::Missing,
            })?;
        }
        let mut machine = [0.0; MACHINE_FIELDS.len()];
        let mut present = 0;
        let mut first_missing = None;
        for (slot, field) in machine.iter_mut().zip(MACHINE_FIELDS.iter()) {
            match get(field.section, field.key) {
                Some(v) => {
                    *slot = v;
                    present += 1;
                }
                None => {
                    if first_missing.is_none() {
                        first_missing = Some(field.path);
                    }
                }
            }
        }
        let machine = match (present, first_missing) {
            (0, _) => None,
            (_, None) => Some(RawMachine::from_array(machine)),
            (_, Some(path)) => {
                return Err(ParamError {
                    field: path,
                    value: f64::NAN,
                    problem: Problem::Missing,
                });
            }
        };
        let mut estimator = RawEstimator::DEFAULT.to_array();
        for (slot, field) in estimator.iter_mut().zip(ESTIMATOR_FIELDS.iter()) {
            if let Some(v) = get(field.section, field.key) {
                *slot = v;
            }
        }
        let raw = RawParams {
            core: RawCore::from_array(core),
            machine,
            estimator: RawEstimator::from_array(estimator),
        };
        raw.validate()?;
        Ok(raw)
    }
}
