//! The parameter file's schema and its validation, in plain `f64`.
//!
//! Units are SI, temperatures in degrees Celsius (`docs/model.md` section 8).
//!
//! Each section group is declared once, by the `schema!` list below; code
//! reaches a field by its name, never by its place in the list: its
//! description is `RawCore::FIELD.spring_rate` (`plunger.spring_rate`), its
//! value with that name `raw.named().spring_rate`. The tables
//! (`CORE_FIELDS`, ...) are for going over every field in file order.

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
    /// The Rust field it fills (`"spring_rate"` of [`RawCore`]), for
    /// generated code that writes a parameter set as a struct literal.
    pub name: &'static str,
    /// Unit, for documentation and generated tables.
    pub unit: &'static str,
    /// Value used when the key is absent; `None` means the key is required.
    pub default: Option<f64>,
    /// One-line description.
    pub doc: &'static str,
}

/// A field's value together with its name: what a rule needs to check the
/// value and to name the field when it rejects it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Named {
    /// `section.key` of the field.
    pub path: &'static str,
    /// Its value.
    pub value: f64,
}

macro_rules! count {
    () => { 0usize };
    ($head:tt $($tail:tt)*) => { 1usize + count!($($tail)*) };
}

/// Declares one section group of the file from a single list of fields:
///
/// * the struct of values (`RawCore`, one `f64` per field);
/// * a struct with the same field names over any `T` (`CoreFields<T>`):
///   `RawCore::FIELD` (a `CoreFields<Field>`) is the named handle of every
///   field, `RawCore::named()` (a `CoreFields<Named>`) every value with its
///   field's `section.key`;
/// * the table of the fields in file order (`CORE_FIELDS`), for code that
///   goes over all of them (reading, writing, listing).
///
/// Code that needs one particular field names it (`FIELD.spring_rate`,
/// `named().spring_rate`); nothing outside this macro depends on the
/// position of a field in the list, so inserting a field shifts nothing.
macro_rules! schema {
    (
        $(#[$meta:meta])*
        struct $name:ident, fields $fields_ty:ident, const $fields:ident;
        $( $field:ident : $section:literal . $key:literal [$unit:literal] = $default:expr, $doc:literal; )*
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name {
            $( #[doc = $doc] #[doc = concat!("Unit: ", $unit, ".")] pub $field: f64, )*
        }

        #[doc = concat!("One `T` per field of [`", stringify!($name), "`], under the same names: [`",
            stringify!($name), "::FIELD`] holds each field's description, [`", stringify!($name),
            "::named`] each value with its field's name.")]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $fields_ty<T> {
            $( #[doc = concat!("`", $section, ".", $key, "`: ", $doc)] pub $field: T, )*
        }

        impl<T> $fields_ty<T> {
            /// The entries in file order (the order of the field table).
            pub fn into_array(self) -> [T; count!($($field)*)] {
                [$(self.$field),*]
            }

            /// Pairs the entries of `self` and `other` by field name.
            pub fn zip<U>(self, other: $fields_ty<U>) -> $fields_ty<(T, U)> {
                $fields_ty { $( $field: (self.$field, other.$field), )* }
            }
        }

        #[doc = concat!("The fields of [`", stringify!($name), "`], in file order (the entries of [`",
            stringify!($name), "::FIELD`]).")]
        pub const $fields: [Field; count!($($field)*)] = [$($name::FIELD.$field),*];

        impl $name {
            /// Each field's description (section, key, unit, default), by name.
            pub const FIELD: $fields_ty<Field> = $fields_ty {
                $( $field: Field {
                    section: $section,
                    key: $key,
                    path: concat!($section, ".", $key),
                    name: stringify!($field),
                    unit: $unit,
                    default: $default,
                    doc: $doc,
                }, )*
            };

            /// Every value together with its field's `section.key`.
            pub const fn named(&self) -> $fields_ty<Named> {
                $fields_ty {
                    $( $field: Named { path: Self::FIELD.$field.path, value: self.$field }, )*
                }
            }

            /// Builds the struct from one value per field, asked for by
            /// field in file order; the first error is returned.
            pub fn try_from_fields<E>(
                mut value: impl FnMut(&'static Field) -> Result<f64, E>,
            ) -> Result<Self, E> {
                Ok(Self { $( $field: value(&Self::FIELD.$field)?, )* })
            }

            /// Builds the struct from one value per field, asked for by
            /// field in file order.
            pub fn from_fields(mut value: impl FnMut(&'static Field) -> f64) -> Self {
                Self { $( $field: value(&Self::FIELD.$field), )* }
            }

            /// The same set with every value passed through `f`, which
            /// sees it with its field's name.
            pub fn map(&self, mut f: impl FnMut(Named) -> f64) -> Self {
                let named = self.named();
                Self { $( $field: f(named.$field), )* }
            }

            /// Every field at its default, NaN where the key is required.
            #[allow(dead_code, reason = "only a section whose every key has a default uses it")]
            const WITH_DEFAULTS: Self = Self {
                $( $field: match Self::FIELD.$field.default {
                    Some(v) => v,
                    None => f64::NAN,
                }, )*
            };
        }
    };
}

schema! {
    /// The compensator's physical parameters (all required).
    struct RawCore, fields CoreFields, const CORE_FIELDS;
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
    struct RawMachine, fields MachineFields, const MACHINE_FIELDS;
    working_flow: "machine"."working_flow" ["m^3/s"] = None, "Flow Q_work the driven motor needs.";
    leakage_reference: "machine"."leakage_reference" ["m^3/s"] = None, "Volumetric loss at the reference temperature.";
    leakage_temperature: "machine"."leakage_temperature" ["C"] = None, "Reference temperature of the loss.";
}

schema! {
    /// Estimator and sensor settings (optional section `[estimator]`; every
    /// key has a default).
    struct RawEstimator, fields EstimatorFields, const ESTIMATOR_FIELDS;
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
    /// The compensator (`docs/model.md` section 8).
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

/// The error naming the field `n` and its value.
fn err(n: Named, problem: Problem) -> ParamError {
    ParamError {
        field: n.path,
        value: n.value,
        problem,
    }
}

/// Finite, else the matching error.
fn finite(n: Named) -> Result<f64, ParamError> {
    if n.value.is_nan() {
        Err(err(n, Problem::NotANumber))
    } else if n.value.is_infinite() {
        Err(err(n, Problem::Infinite))
    } else {
        Ok(n.value)
    }
}

fn positive(n: Named) -> Result<f64, ParamError> {
    let v = finite(n)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(err(n, Problem::NotPositive))
    }
}

fn non_negative(n: Named) -> Result<f64, ParamError> {
    let v = finite(n)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(err(n, Problem::Negative))
    }
}

fn within(n: Named, min: f64, max: f64) -> Result<f64, ParamError> {
    let v = finite(n)?;
    if v >= min && v <= max {
        Ok(v)
    } else {
        Err(err(n, Problem::OutOfRange { min, max }))
    }
}

/// A whole number (counts).
fn whole(n: Named) -> Result<f64, ParamError> {
    let v = finite(n)?;
    // Exact for |v| < 2^63 (the saturating cast changes any fraction).
    if v as i64 as f64 == v {
        Ok(v)
    } else {
        Err(err(n, Problem::NotWhole))
    }
}

/// Discharge coefficients live in (0, 1].
fn discharge(n: Named) -> Result<f64, ParamError> {
    let v = positive(n)?;
    if v <= 1.0 {
        Ok(v)
    } else {
        Err(err(n, Problem::OutOfRange { min: 0.0, max: 1.0 }))
    }
}

const PI: f64 = core::f64::consts::PI;

impl RawCore {
    /// Checks every field against its physical rule, in file order, and the
    /// rules that tie fields together. The first violation is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        let n = self.named();
        positive(n.walther_a)?;
        positive(n.walther_b)?;
        positive(n.density_15)?;
        // rho = rho_15 / (1 + e (t - 15)) must stay positive and finite over
        // any oil temperature; 1e-2/K is ten times any hydraulic oil's.
        within(n.expansion, 0.0, 1.0e-2)?;
        positive(n.bulk_modulus)?;
        positive(n.laminar_diameter)?;
        positive(n.laminar_length)?;
        positive(n.turbulent_diameter)?;
        discharge(n.turbulent_discharge)?;
        positive(n.plunger_diameter)?;
        positive(n.mass)?;
        non_negative(n.damping)?;
        positive(n.spring_rate)?;
        non_negative(n.preload)?;
        positive(n.stroke)?;
        positive(n.slot_diameter)?;
        discharge(n.slot_discharge)?;
        positive(n.volume_a)?;
        positive(n.volume_b)?;
        positive(n.pressure_drop)?;
        non_negative(n.outlet_pressure)?;

        if self.preload > self.stroke {
            return Err(err(n.preload, Problem::Inconsistent("preload beyond the stroke")));
        }
        let swept = PI * self.plunger_diameter * self.plunger_diameter / 4.0 * self.stroke;
        if !(swept.is_finite() && swept > 0.0) {
            return Err(err(
                n.stroke,
                Problem::Inconsistent("swept volume A_p * stroke is not finite"),
            ));
        }
        // Chamber (a) shrinks by the swept volume at full stroke, so it must
        // be larger. Chamber (b) grows; the same rule is applied to it so
        // that a mirrored design (and the file format) stays symmetric.
        if self.volume_a <= swept {
            return Err(err(
                n.volume_a,
                Problem::Inconsistent("not larger than the swept volume A_p * stroke"),
            ));
        }
        if self.volume_b <= swept {
            return Err(err(
                n.volume_b,
                Problem::Inconsistent("not larger than the swept volume A_p * stroke"),
            ));
        }
        Ok(())
    }
}

impl RawMachine {
    /// Checks the machine section.
    pub fn validate(&self) -> Result<(), ParamError> {
        let n = self.named();
        non_negative(n.working_flow)?;
        non_negative(n.leakage_reference)?;
        within(n.leakage_temperature, -50.0, 200.0)?;
        Ok(())
    }
}

impl RawEstimator {
    /// The defaults of the `[estimator]` section.
    pub const DEFAULT: RawEstimator = RawEstimator::WITH_DEFAULTS;

    /// Checks the estimator section.
    pub fn validate(&self) -> Result<(), ParamError> {
        let n = self.named();
        within(n.tick_hz, 1.0, 100_000.0)?;
        positive(n.filter_time_constant)?;
        positive(n.spike_threshold)?;
        within(n.spike_limit, 0.0, 65_534.0)?;
        whole(n.spike_limit)?;
        within(n.oil_min, -60.0, 300.0)?;
        within(n.oil_max, -60.0, 300.0)?;
        if self.oil_max <= self.oil_min {
            return Err(err(n.oil_max, Problem::Inconsistent("not above estimator.oil_min")));
        }
        within(n.valid_min, self.oil_min, self.oil_max)?;
        within(n.valid_max, self.oil_min, self.oil_max)?;
        if self.valid_max <= self.valid_min {
            return Err(err(n.valid_max, Problem::Inconsistent("not above estimator.valid_min")));
        }
        // A telemetry tick runs none of the estimator's rotating jobs: at
        // most every second tick, so that they keep being refreshed.
        within(n.telemetry_hz, 0.0, self.tick_hz / 2.0)?;
        positive(n.rtd_r0)?;
        positive(n.rtd_reference)?;
        within(n.rtd_wires, 2.0, 4.0)?;
        whole(n.rtd_wires)?;
        let mains = finite(n.mains_hz)?;
        if mains != 50.0 && mains != 60.0 {
            return Err(err(n.mains_hz, Problem::NotOneOf("50 or 60")));
        }
        // Around IEC 60751's 3.9083e-3, -5.775e-7, -4.183e-12: a calibrated
        // probe's coefficients differ in the third or fourth digit.
        within(n.rtd_a, 1.0e-3, 1.0e-2)?;
        within(n.rtd_b, -1.0e-5, 1.0e-5)?;
        within(n.rtd_c, -1.0e-9, 1.0e-9)?;
        // The converter inverts R(t): it must rise over the oil's range.
        let mut t = self.oil_min;
        for i in 0..=64 {
            let slope = self.rtd_slope(t);
            if !(slope > 0.0) {
                return Err(err(
                    n.rtd_b,
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
                n.rtd_reference,
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
        let missing = |field: &Field| ParamError {
            field: field.path,
            value: f64::NAN,
            problem: Problem::Missing,
        };
        let core = RawCore::try_from_fields(|field| {
            get(field.section, field.key)
                .or(field.default)
                .ok_or_else(|| missing(field))
        })?;
        let mut present = 0;
        let mut first_missing = None;
        let machine = RawMachine::from_fields(|field| match get(field.section, field.key) {
            Some(v) => {
                present += 1;
                v
            }
            None => {
                first_missing.get_or_insert(field);
                f64::NAN
            }
        });
        let machine = match (present, first_missing) {
            (0, _) => None,
            (_, None) => Some(machine),
            (_, Some(field)) => return Err(missing(field)),
        };
        let estimator =
            RawEstimator::from_fields(|field| get(field.section, field.key).or(field.default).unwrap_or(f64::NAN));
        let raw = RawParams {
            core,
            machine,
            estimator,
        };
        raw.validate()?;
        Ok(raw)
    }
}
