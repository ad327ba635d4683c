//! The parameter file's schema and its validation, in plain `f64`.
//!
//! Units are SI, temperatures in degrees Celsius (`docs/model.md` section 8).
//!
//! Each section group is declared once, by the `schema!` list below; code
//! reaches a field by its name, never by its place in the list: its
//! description is `RawCore::FIELD.spring_rate` (`plunger.spring_rate`), its
//! value with that name `raw.named().spring_rate`. The tables
//! (`CORE_FIELDS`, ...) are for going over every field in file order.

use crate::text::Compact;
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
    /// `tolerances.section.key`: where the file gives the field's standard
    /// uncertainty, and the name errors about it use.
    pub tolerance_path: &'static str,
    /// The Rust field it fills (`"spring_rate"` of [`RawCore`]), for
    /// generated code that writes a parameter set as a struct literal.
    pub name: &'static str,
    /// Unit, for documentation and generated tables.
    pub unit: &'static str,
    /// Lowest plausible value: generous, physical bounds (a plunger of a
    /// milligram to a tonne), checked before any rule between fields, so
    /// that a value no device has is refused under its own name.
    pub min: f64,
    /// Highest plausible value.
    pub max: f64,
    /// What else the value must be (a whole number, one of a few values).
    pub kind: Kind,
    /// Value used when the key is absent; `None` means the key is required.
    pub default: Option<f64>,
    /// One-line description.
    pub doc: &'static str,
}

/// What a field's value must be besides lying in its plausible range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Any number in the range.
    Real,
    /// A whole number (a count).
    Whole,
    /// One of these values.
    OneOf(&'static [f64]),
    /// One of these names, written as a TOML string in the file; the value
    /// is the name's place in the list (0, 1, ...).
    Named(&'static [&'static str]),
    /// Zero (none: no damping, no preload, no telemetry), or a value in the
    /// range: a subnormal damping is no damping, and would not survive `f32`.
    OrZero,
}

impl Field {
    /// Checks `value` against this field's own rule, without looking at any
    /// other field: finite, within `[min, max]`, and whole or one of the
    /// listed values where [`Field::kind`] says so.
    ///
    /// # Errors
    ///
    /// A [`ParamError`] naming this field: [`Problem::NotANumber`],
    /// [`Problem::Infinite`], [`Problem::Implausible`] (with the range and
    /// unit), [`Problem::NotWhole`] or [`Problem::NotOneOf`].
    pub fn check(&self, value: f64) -> Result<f64, ParamError> {
        self.rule().check(value)
    }

    /// What [`Field::check`] needs of the field, without its description
    /// (built at compile time by the generated `check_fields`, so that a
    /// firmware image validating its parameters links no field docs).
    pub const fn rule(&self) -> Rule {
        Rule {
            path: self.path,
            unit: self.unit,
            min: self.min,
            max: self.max,
            kind: self.kind,
        }
    }

    /// The plausible range as messages and tables show it: `[1e-6, 1000] kg`,
    /// `0 or [1e-6, 1e6] N s/m` (no unit for dimensionless fields).
    pub fn range(&self) -> Range {
        Range {
            min: self.min,
            max: self.max,
            unit: self.unit,
            or_zero: self.kind == Kind::OrZero,
        }
    }
}

/// A field's rule: its name, plausible range and [`Kind`] ([`Field::rule`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    /// `section.key`.
    pub path: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Lowest plausible value.
    pub min: f64,
    /// Highest plausible value.
    pub max: f64,
    /// What else the value must be.
    pub kind: Kind,
}

impl Rule {
    /// As [`Field::check`].
    ///
    /// # Errors
    ///
    /// As [`Field::check`].
    pub fn check(&self, value: f64) -> Result<f64, ParamError> {
        let n = Named { path: self.path, value };
        let v = finite(n)?;
        let zero = self.kind == Kind::OrZero && v == 0.0;
        if !(zero || v >= self.min && v <= self.max) {
            let range = Range {
                min: self.min,
                max: self.max,
                unit: self.unit,
                or_zero: self.kind == Kind::OrZero,
            };
            return Err(err(n, Problem::Implausible(range)));
        }
        match self.kind {
            Kind::Real | Kind::OrZero => Ok(v),
            // Exact for |v| < 2^63 (the saturating cast changes any fraction).
            Kind::Whole if v as i64 as f64 == v => Ok(v),
            Kind::Whole => Err(err(n, Problem::NotWhole)),
            Kind::OneOf(values) if values.contains(&v) => Ok(v),
            Kind::OneOf(values) => Err(err(n, Problem::NotOneOf(values))),
            Kind::Named(names) if v as usize as f64 == v && (v as usize) < names.len() => Ok(v),
            Kind::Named(names) => Err(err(n, Problem::NotNamed(names))),
        }
    }
}

/// A plausible range with its unit; `Display` writes `[1e-6, 1000] kg`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Lowest plausible value.
    pub min: f64,
    /// Highest plausible value.
    pub max: f64,
    /// Unit (`"-"`: none).
    pub unit: &'static str,
    /// Zero is accepted too (below `min`).
    pub or_zero: bool,
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.or_zero {
            f.write_str("0 or ")?;
        }
        write!(f, "[{}, {}]", Compact(self.min), Compact(self.max))?;
        if self.unit != "-" {
            write!(f, " {}", self.unit)?;
        }
        Ok(())
    }
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

/// A field's [`Kind`]: [`Kind::Real`] unless the list says otherwise.
macro_rules! kind {
    () => {
        Kind::Real
    };
    ($kind:expr) => {
        $kind
    };
}

macro_rules! count {
    () => { 0usize };
    ($head:tt $($tail:tt)*) => { 1usize + count!($($tail)*) };
}

/// Declares one section group of the file from a single list of fields,
/// each with its unit, plausible range (`min ..= max`, and optionally a
/// [`Kind`]), default and description:
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
        $( $field:ident : $section:literal . $key:literal
            [$unit:literal, $min:literal ..= $max:literal $(, $kind:expr)?] = $default:expr, $doc:literal; )*
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name {
            $(
                #[doc = $doc]
                #[doc = concat!("Unit: ", $unit, "; plausible range: ", stringify!($min), " ..= ", stringify!($max), ".")]
                pub $field: f64,
            )*
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

            /// One entry per field, asked for by field in file order.
            pub fn from_fn(mut value: impl FnMut(&'static Field) -> T) -> Self {
                $fields_ty { $( $field: value(&$name::FIELD.$field), )* }
            }

            /// The entry of the field whose `section.key` is `path`.
            pub fn get(&self, path: &str) -> Option<&T> {
                $( if path == $name::FIELD.$field.path { return Some(&self.$field); } )*
                None
            }

            /// The entry of the field whose `section.key` is `path`, mutable.
            pub fn get_mut(&mut self, path: &str) -> Option<&mut T> {
                $( if path == $name::FIELD.$field.path { return Some(&mut self.$field); } )*
                None
            }
        }

        impl $fields_ty<f64> {
            /// Zero for every field.
            pub const ZERO: Self = $fields_ty { $( $field: 0.0, )* };
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
                    tolerance_path: concat!("tolerances.", $section, ".", $key),
                    name: stringify!($field),
                    unit: $unit,
                    min: $min,
                    max: $max,
                    kind: kind!($($kind)?),
                    default: $default,
                    doc: $doc,
                }, )*
            };

            /// Checks every field against its own rule ([`Field::check`]:
            /// finite, in its plausible range, whole or one of its values
            /// where it must be), in file order, without looking at any
            /// other field.
            ///
            /// # Errors
            ///
            /// The first field's [`Field::check`] error.
            pub fn check_fields(&self) -> Result<(), ParamError> {
                $( const { Self::FIELD.$field.rule() }.check(self.$field)?; )*
                Ok(())
            }

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

            /// The value of the field named `path` (`section.key`), if
            /// this section group has it: access by name, generated from the
            /// list, so that no hand-written match can fall through to the
            /// wrong field.
            pub fn value(&self, path: &str) -> Option<f64> {
                $( if path == Self::FIELD.$field.path { return Some(self.$field); } )*
                None
            }

            /// The field named `path` (`section.key`) to write to, if this
            /// section group has it (see [`Self::value`]).
            pub fn value_mut(&mut self, path: &str) -> Option<&mut f64> {
                $( if path == Self::FIELD.$field.path { return Some(&mut self.$field); } )*
                None
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

// The plausible ranges are generous: they hold every device the model is
// meant for, the presets and the test suite's random designs (scattered by
// up to 2x either way around the presets, `host-tests/src/survey.rs`) with
// room to spare, and refuse only values no such device has (a plunger of a
// picogram, a bulk modulus of 1 Pa, an outlet at 1e22 Pa). Inside them
// every quantity the model derives stays far from overflow and underflow
// in `f32` as well as `f64`. `docs/parameters.md` tabulates them.
schema! {
    /// The compensator's physical parameters (all required).
    struct RawCore, fields CoreFields, const CORE_FIELDS;
    // Real oils have a = 8..11, b = 3..4.5; fitted and scattered oils reach
    // a = 19, b = 7.5. Which (a, b) make an oil is a rule between the two
    // (the viscosity at 40 C, `RawCore::validate`).
    walther_a: "fluid"."walther_a" ["-", 0.5 ..= 40.0] = None, "Walther constant a in log10(log10(nu_cSt + 0.7)) = a - b log10(T_K).";
    walther_b: "fluid"."walther_b" ["-", 0.5 ..= 15.0] = None, "Walther slope b.";
    // Light hydrocarbons to heavy synthetic fluids.
    density_15: "fluid"."density_15" ["kg/m^3", 500.0 ..= 2000.0] = None, "Density at 15 C.";
    // rho = rho_15 / (1 + e (t - 15)) must stay positive and finite over
    // any oil temperature; 1e-2/K is ten times any hydraulic oil's.
    expansion: "fluid"."expansion" ["1/K", 1.0e-6 ..= 1.0e-2, Kind::OrZero] = None, "Volumetric thermal expansion coefficient.";
    // Oil with entrained air and soft hoses (1e7) to five times the stiffest
    // mineral oil (1e10).
    bulk_modulus: "fluid"."bulk_modulus" ["Pa", 1.0e7 ..= 1.0e10] = None, "Effective bulk modulus of oil and chamber walls.";
    laminar_diameter: "laminar_throttle"."diameter" ["m", 1.0e-5 ..= 0.1] = None, "Capillary bore.";
    laminar_length: "laminar_throttle"."length" ["m", 1.0e-4 ..= 10.0] = None, "Capillary length.";
    turbulent_diameter: "turbulent_throttle"."diameter" ["m", 1.0e-5 ..= 0.1] = None, "Orifice bore.";
    turbulent_discharge: "turbulent_throttle"."discharge_coefficient" ["-", 0.1 ..= 1.0] = None, "Orifice discharge coefficient.";
    plunger_diameter: "plunger"."diameter" ["m", 1.0e-4 ..= 1.0] = None, "Plunger diameter D.";
    mass: "plunger"."mass" ["kg", 1.0e-6 ..= 1.0e3] = None, "Moving mass.";
    damping: "plunger"."damping" ["N s/m", 1.0e-6 ..= 1.0e6, Kind::OrZero] = None, "Viscous (friction) damping b, without the hydraulic damping.";
    spring_rate: "plunger"."spring_rate" ["N/m", 0.1 ..= 1.0e9] = None, "Spring rate c.";
    preload: "plunger"."preload" ["m", 1.0e-9 ..= 1.0, Kind::OrZero] = None, "Initial spring compression x0 (at most the stroke).";
    stroke: "plunger"."stroke" ["m", 1.0e-6 ..= 1.0] = None, "Travel between the end stops, x_max.";
    slot_diameter: "slot"."diameter" ["m", 1.0e-5 ..= 1.0] = None, "Diameter d of the window opened by the plunger (area pi d x).";
    slot_discharge: "slot"."discharge_coefficient" ["-", 0.1 ..= 1.0] = None, "Discharge coefficient eta of the window.";
    volume_a: "chambers"."volume_a" ["m^3", 1.0e-10 ..= 1.0] = None, "Volume of chamber (a) at x = 0 (more than the plunger sweeps).";
    volume_b: "chambers"."volume_b" ["m^3", 1.0e-10 ..= 1.0] = None, "Volume of chamber (b) at x = 0 (more than the plunger sweeps).";
    pressure_drop: "operating"."pressure_drop" ["Pa", 1.0e3 ..= 1.0e8] = None, "Constant drop p_p - p_c (Eq. 10).";
    outlet_pressure: "operating"."outlet_pressure" ["Pa", 1.0 ..= 1.0e8, Kind::OrZero] = None, "Outlet pressure p_c.";
}

schema! {
    /// The driven machine (optional section `[machine]`; all or none).
    ///
    /// Its volumetric losses are laminar leakage, proportional to `1/mu`:
    /// `dQ_lost(t) = leakage_reference * mu(t_ref) / mu(t)`.
    struct RawMachine, fields MachineFields, const MACHINE_FIELDS;
    working_flow: "machine"."working_flow" ["m^3/s", 1.0e-12 ..= 1.0, Kind::OrZero] = None, "Flow Q_work the driven motor needs.";
    leakage_reference: "machine"."leakage_reference" ["m^3/s", 1.0e-12 ..= 1.0, Kind::OrZero] = None, "Volumetric loss at the reference temperature.";
    leakage_temperature: "machine"."leakage_temperature" ["C", -50.0 ..= 200.0] = None, "Reference temperature of the loss.";
}

schema! {
    /// Estimator and sensor settings (optional section `[estimator]`; every
    /// key has a default).
    struct RawEstimator, fields EstimatorFields, const ESTIMATOR_FIELDS;
    tick_hz: "estimator"."tick_hz" ["Hz", 1.0 ..= 100_000.0] = Some(1000.0), "Estimator tick rate.";
    // A hydraulic power unit's oil warms at 0.01-0.1 C/s; a cold-oil
    // injection or a valve switching supplies reaches about 1 C/s. The
    // observer's fast mode is tuned to follow this rate (`docs/firmware.md`).
    max_oil_rate: "estimator"."max_oil_rate" ["C/s", 1.0e-4 ..= 100.0] = Some(1.0), "Largest plausible rate of change of the oil temperature (tunes the oil-temperature observer's fast mode).";
    spike_threshold: "estimator"."spike_threshold" ["C", 1.0e-3 ..= 1.0e3] = Some(5.0), "A sample further than this from the filtered value is a spike.";
    // The counter must be able to exceed the limit in 16 bits.
    spike_limit: "estimator"."spike_limit" ["-", 0.0 ..= 65_534.0, Kind::Whole] = Some(5.0), "Consecutive agreeing out-of-band samples rejected before the next one is taken as a real step (a whole number).";
    valid_min: "estimator"."valid_min" ["C", -60.0 ..= 300.0] = Some(26.0), "Lower end of the validated temperature range (inside oil_min..oil_max).";
    valid_max: "estimator"."valid_max" ["C", -60.0 ..= 300.0] = Some(78.0), "Upper end of the validated temperature range (above valid_min, inside oil_min..oil_max).";
    oil_min: "estimator"."oil_min" ["C", -60.0 ..= 300.0] = Some(-20.0), "Lower end of the oil range the estimator and the commands accept (the oil model may end inside it: the temperature envelope, docs/parameters.md).";
    oil_max: "estimator"."oil_max" ["C", -60.0 ..= 300.0] = Some(150.0), "Upper end of the oil range (above oil_min; where the oil's viscosity falls below Walther's 2 cSt first, the oil model ends there).";
    telemetry_hz: "estimator"."telemetry_hz" ["Hz", 1.0e-3 ..= 50_000.0, Kind::OrZero] = Some(2.0), "Telemetry rate (0: none; at most tick_hz / 2).";
    // PT10 to PT10000 and beyond.
    rtd_r0: "estimator"."rtd_r0" ["ohm", 1.0 ..= 1.0e5] = Some(100.0), "RTD resistance at 0 C (PT100).";
    rtd_reference: "estimator"."rtd_reference" ["ohm", 1.0 ..= 1.0e6] = Some(430.0), "MAX31865 reference resistor (must exceed the RTD's resistance at oil_max, else the converter saturates).";
    rtd_wires: "estimator"."rtd_wires" ["-", 2.0 ..= 4.0, Kind::Whole] = Some(3.0), "RTD connection: 2, 3 or 4 wires (MAX31865 configuration bit D4).";
    mains_hz: "estimator"."mains_hz" ["Hz", 50.0 ..= 60.0, Kind::OneOf(&[50.0, 60.0])] = Some(50.0), "Mains frequency the converter's notch filter rejects: 50 or 60 (conversion every 20 or 16.7 ms).";
    // Around IEC 60751's 3.9083e-3, -5.775e-7, -4.183e-12: a calibrated
    // probe's coefficients differ in the third or fourth digit.
    rtd_a: "estimator"."rtd_a" ["1/C", 1.0e-3 ..= 1.0e-2] = Some(3.9083e-3), "Callendar-Van Dusen A of the RTD (IEC 60751 by default; a calibrated probe's own).";
    rtd_b: "estimator"."rtd_b" ["1/C^2", -1.0e-5 ..= 1.0e-5] = Some(-5.775e-7), "Callendar-Van Dusen B (IEC 60751 by default).";
    rtd_c: "estimator"."rtd_c" ["1/C^4", -1.0e-9 ..= 1.0e-9] = Some(-4.183e-12), "Callendar-Van Dusen C, below 0 C only (IEC 60751 by default).";
    // The sensor kind; the rtd_* fields above serve "rtd", the ntc_* and
    // adc_* fields below "ntc" (docs/firmware.md, "NTC thermistor").
    sensor: "estimator"."sensor" ["-", 0.0 ..= 1.0, Kind::Named(&SENSOR_KINDS)] = Some(0.0), "Temperature sensor: \"rtd\" (a platinum RTD through a MAX31865 over SPI) or \"ntc\" (an NTC thermistor in a divider read by the STM32F405's ADC).";
    // 100 ohm to 1 Mohm NTCs at 25 C (Vishay NTCLE100E3, TDK B57861S).
    ntc_r25: "estimator"."ntc_r25" ["ohm", 10.0 ..= 1.0e7] = Some(10_000.0), "NTC resistance at 25 C, R25 (datasheet; default Vishay NTCLE100E3103: 10 kohm).";
    ntc_beta: "estimator"."ntc_beta" ["K", 1000.0 ..= 10_000.0] = Some(3977.0), "NTC beta B25/85 of 1/T = 1/T25 + ln(R/R25)/B (datasheet; default NTCLE100E3103: 3977 K). Unused when ntc_sh_a, ntc_sh_b, ntc_sh_c are given.";
    // A 10 kohm NTC: a ~ 1.1e-3, b ~ 2.4e-4, c ~ 8.6e-8 (R in ohm).
    ntc_sh_a: "estimator"."ntc_sh_a" ["1/K", 1.0e-5 ..= 1.0e-2, Kind::OrZero] = Some(0.0), "Steinhart-Hart a of 1/T = a + b ln R + c (ln R)^3, R in ohm, T in K (a calibration's or the datasheet's; 0 for all three: the beta equation).";
    ntc_sh_b: "estimator"."ntc_sh_b" ["1/K", 1.0e-6 ..= 1.0e-2, Kind::OrZero] = Some(0.0), "Steinhart-Hart b (given with ntc_sh_a and ntc_sh_c, or all three 0).";
    ntc_sh_c: "estimator"."ntc_sh_c" ["1/K", 1.0e-10 ..= 1.0e-4, Kind::OrZero] = Some(0.0), "Steinhart-Hart c (given with ntc_sh_a and ntc_sh_b, or all three 0).";
    ntc_series: "estimator"."ntc_series" ["ohm", 10.0 ..= 1.0e7] = Some(10_000.0), "Series resistor of the NTC's divider, from V_REF+ to the ADC input (the NTC from the input to ground; the ADC's reference is the divider's supply, so V_REF+ cancels).";
    // The STM32F4's ADC resolutions (ADC_CR1 RES).
    adc_bits: "estimator"."adc_bits" ["-", 6.0 ..= 12.0, Kind::OneOf(&[6.0, 8.0, 10.0, 12.0])] = Some(12.0), "ADC resolution in bits: 12, 10, 8 or 6 (STM32F4 ADC_CR1 RES).";
    ntc_oversampling: "estimator"."ntc_oversampling" ["-", 1.0 ..= 64.0, Kind::Whole] = Some(4.0), "ADC conversions averaged into one NTC reading (a whole number).";
}

/// The names of `estimator.sensor`, in the order of its values.
pub const SENSOR_KINDS: [&str; 2] = ["rtd", "ntc"];

/// ADC codes at either end of the NTC divider's range that are taken for
/// an open (near full scale) or shorted (near 0) NTC: the divider must keep
/// the oil range inside them (`estimator.ntc_series`).
pub const NTC_FAULT_CODES: f64 = 8.0;

/// Absolute temperature of 0 C \[K\].
pub const KELVIN: f64 = 273.15;

schema! {
    /// The temperature probe in its well (optional section `[probe]`; every
    /// key has a default): its response, noise and tolerance, which the
    /// estimator's oil-temperature observer and its uncertainty use.
    ///
    /// The defaults describe a 6 mm sheathed PT100 insert of IEC 60751
    /// class B in a thermowell in flowing oil: Endress+Hauser's Omnigrad T
    /// TST310 datasheet gives its bare 6 mm mineral-insulated probe t0.5 =
    /// 3.5 s and t0.9 = 8 s in water at 0.4 m/s (the IEC 60751 test), and
    /// Guenther's technical information an insert after DIN 43762 t0.5 =
    /// 6-9 s, with a DIN 43772 thermowell 36-40 s; oil transfers heat
    /// less well than water. A first-order probe has `time_constant` =
    /// t0.5 / ln 2 = t0.9 / ln 10 (`docs/firmware.md`).
    struct RawProbe, fields ProbeFields, const PROBE_FIELDS;
    time_constant: "probe"."time_constant" ["s", 1.0e-3 ..= 1.0e4] = Some(8.0), "First-order time constant of the probe's response to the oil temperature, in its well (t0.5 / ln 2, t0.9 / ln 10).";
    well_time_constant: "probe"."well_time_constant" ["s", 1.0e-3 ..= 1.0e4, Kind::OrZero] = Some(0.0), "Time constant of a second, slower lag in series (the thermowell; 0: none).";
    noise: "probe"."noise" ["C", 1.0e-6 ..= 10.0, Kind::OrZero] = Some(0.02), "Standard deviation of one reading's noise, without the converter's quantization.";
    // IEC 60751 classes: AA 0.1 + 0.0017 |t|, A 0.15 + 0.002 |t|,
    // B 0.3 + 0.005 |t|, C 0.6 + 0.01 |t| (C).
    tolerance_a: "probe"."tolerance_a" ["C", 1.0e-4 ..= 10.0, Kind::OrZero] = Some(0.3), "Constant part of the probe's tolerance +-(a + b |t|) (IEC 60751 class B: 0.3 C).";
    tolerance_b: "probe"."tolerance_b" ["1/K", 1.0e-6 ..= 0.1, Kind::OrZero] = Some(0.005), "Part of the probe's tolerance proportional to |t| (IEC 60751 class B: 0.005).";
}

schema! {
    /// The condition monitor's optional second sensor (optional section
    /// `[monitor]`): one chamber pressure transducer (`p_a`, `p_b`, or the
    /// difference `p_b - p_a`) or a plunger displacement sensor (LVDT or
    /// Hall), read by the STM32F405's ADC. Without the section, or with
    /// `sensor = "none"`, nothing else of it is used (nor checked beyond its
    /// own plausible range). With a sensor, `range_min`, `range_max` and
    /// `noise` are required; their unit is the quantity's: Pa for a
    /// pressure, m for the displacement.
    struct RawMonitor, fields MonitorFields, const MONITOR_FIELDS;
    sensor: "monitor"."sensor" ["-", 0.0 ..= 4.0, Kind::Named(&MONITOR_SENSORS)] = Some(0.0), "What the second sensor measures: \"none\", \"p_a\" or \"p_b\" (a chamber pressure), \"dp_ab\" (p_b - p_a), \"x\" (the plunger's displacement).";
    output: "monitor"."output" ["-", 0.0 ..= 1.0, Kind::Named(&MONITOR_OUTPUTS)] = Some(0.0), "Its output: \"ratiometric\" (0.5-4.5 V of a 5 V supply, through a divider into the ADC) or \"current\" (4-20 mA into a shunt resistor).";
    // Pa for a pressure (vacuum to 1 GPa, either sign for a difference),
    // m for a displacement; the rules between fields (`check_rules`) tie
    // them to the device's pressures and stroke, which catches bar, MPa or
    // mm typed by mistake.
    range_min: "monitor"."range_min" ["Pa or m", -1.0e9 ..= 1.0e9] = None, "Reading at 0.5 V (ratiometric) or 4 mA (current): Pa for a pressure, m for x (required with a sensor).";
    range_max: "monitor"."range_max" ["Pa or m", -1.0e9 ..= 1.0e9] = None, "Reading at 4.5 V or 20 mA, above range_min: Pa for a pressure, m for x (required with a sensor).";
    // Accuracy classes 0.01 % to 10 % of the span.
    accuracy: "monitor"."accuracy" ["-", 1.0e-5 ..= 0.1] = Some(0.0025), "Accuracy class as a fraction of the span (0.001: class 0.1 %), a limit: its standard uncertainty is accuracy * span / sqrt(3) (GUM 4.3.7, uniform).";
    noise: "monitor"."noise" ["Pa or m", 1.0e-12 ..= 1.0e9, Kind::OrZero] = None, "Standard deviation of one reading's noise, Pa (m for x), without the ADC's quantization; below the span (required with a sensor; 0: none, which disables the stuck check).";
    sample_hz: "monitor"."sample_hz" ["Hz", 0.1 ..= 100_000.0] = Some(100.0), "Reading rate (at most estimator.tick_hz).";
    // The STM32F4's ADC resolutions (ADC_CR1 RES), as estimator.adc_bits.
    adc_bits: "monitor"."adc_bits" ["-", 6.0 ..= 12.0, Kind::OneOf(&[6.0, 8.0, 10.0, 12.0])] = Some(12.0), "ADC resolution in bits of the monitor's channel: 12, 10, 8 or 6 (STM32F4 ADC_CR1 RES).";
    divider: "monitor"."divider" ["-", 0.1 ..= 1.0] = Some(0.66), "Ratiometric output: the divider's ratio V_adc / V_out into the 3.3 V ADC (0.66: 5 V to 3.3 V); 4.75 V (the short-to-supply limit) times it must stay below 3.3 V.";
    shunt: "monitor"."shunt" ["ohm", 10.0 ..= 1000.0] = Some(150.0), "Current output: the shunt resistor the loop current flows through to ground (150 ohm: 20 mA = 3.0 V); 21 mA (NAMUR NE 43's fault-high limit) times it must stay below 3.3 V.";
}

/// The names of `monitor.sensor`, in the order of its values.
pub const MONITOR_SENSORS: [&str; 5] = ["none", "p_a", "p_b", "dp_ab", "x"];

/// The names of `monitor.output`, in the order of its values.
pub const MONITOR_OUTPUTS: [&str; 2] = ["ratiometric", "current"];

/// The STM32F405 ADC's reference voltage `V_REF+` the monitor's channel is
/// converted against \[V\] (VDDA of the board, 3.3 V).
pub const MONITOR_ADC_REFERENCE: f64 = 3.3;

/// The ratiometric output's short-to-supply limit \[V\]: above it a reading
/// is a fault (`monitor.divider` must keep it inside the ADC's range).
pub const MONITOR_RATIOMETRIC_FAULT_HIGH: f64 = 4.75;

/// NAMUR NE 43's fault-high limit of a 4-20 mA loop \[A\] (`monitor.shunt`
/// must keep it inside the ADC's range).
pub const MONITOR_CURRENT_FAULT_HIGH: f64 = 0.021;

/// The largest span a monitor's range may have, in multiples of the
/// largest reading the device gives (the supply pressure, the pressure
/// drop, the stroke): a wider range is a unit typed wrong (bar for Pa the
/// other way round, mm for m), and would leave one ADC code a sizeable
/// fraction of every reading.
pub const MONITOR_SPAN_LIMIT: f64 = 100.0;

impl RawMonitor {
    /// No second sensor (`sensor = "none"`; the other fields at their
    /// defaults, the required ones 0). What a file without `[monitor]`
    /// reads as.
    pub const NONE: RawMonitor = RawMonitor {
        range_min: 0.0,
        range_max: 0.0,
        noise: 0.0,
        ..RawMonitor::WITH_DEFAULTS
    };

    /// The same as [`RawMonitor::NONE`].
    pub const DEFAULT: RawMonitor = RawMonitor::NONE;

    /// Whether the file names a second sensor (`monitor.sensor` not
    /// `"none"`).
    pub fn has_sensor(&self) -> bool {
        self.sensor != 0.0
    }

    /// Whether the sensor measures a pressure (`p_a`, `p_b`, `dp_ab`; else
    /// none or the displacement `x`).
    pub fn is_pressure(&self) -> bool {
        self.sensor == 1.0 || self.sensor == 2.0 || self.sensor == 3.0
    }

    /// Whether the output is a 4-20 mA current loop (else ratiometric).
    pub fn is_current(&self) -> bool {
        self.output == 1.0
    }

    /// The span `range_max - range_min` \[Pa or m\].
    pub fn span(&self) -> f64 {
        self.range_max - self.range_min
    }

    /// The standard uncertainty of the accuracy class \[Pa or m\]:
    /// `accuracy * span / sqrt(3)`, the class taken as the half-width of
    /// a uniform distribution (GUM 4.3.7).
    pub fn class_uncertainty(&self) -> f64 {
        self.accuracy * self.span() / libm::sqrt(3.0)
    }

    /// Checks the monitor section on its own: every field within its
    /// plausible range, then (with a sensor) the rules that need no other
    /// section. [`RawParams::validate`] adds the rules against the device
    /// ([`RawMonitor::check_device`]).
    ///
    /// # Errors
    ///
    /// The first field's [`Field::check`] error; then, with a sensor:
    /// * `monitor.range_max`, [`Problem::Inconsistent`]: not above
    ///   `monitor.range_min`;
    /// * `monitor.noise`, [`Problem::OutOfRange`]: not below the span;
    /// * `monitor.divider`, [`Problem::OutOfRange`] (ratiometric): 4.75 V
    ///   times it reaches the ADC's 3.3 V;
    /// * `monitor.shunt`, [`Problem::OutOfRange`] (current): 21 mA times
    ///   it reaches 3.3 V.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.check_fields()?;
        self.check_rules()
    }

    /// The rules of [`RawMonitor::validate`] between this section's fields
    /// (each within its range).
    fn check_rules(&self) -> Result<(), ParamError> {
        if !self.has_sensor() {
            return Ok(());
        }
        let n = self.named();
        if !(self.range_max > self.range_min) {
            return Err(err(n.range_max, Problem::Inconsistent("not above monitor.range_min")));
        }
        if !(self.noise < self.span()) {
            return Err(err(
                n.noise,
                Problem::OutOfRange {
                    min: 0.0,
                    max: self.span(),
                    why: "below the span monitor.range_max - monitor.range_min",
                },
            ));
        }
        if self.is_current() {
            let max = MONITOR_ADC_REFERENCE / MONITOR_CURRENT_FAULT_HIGH;
            if !(self.shunt * MONITOR_CURRENT_FAULT_HIGH < MONITOR_ADC_REFERENCE) {
                return Err(err(
                    n.shunt,
                    Problem::OutOfRange {
                        min: 0.0,
                        max,
                        why: "21 mA (NAMUR NE 43 fault high) through it must stay below the ADC's 3.3 V",
                    },
                ));
            }
        } else if !(self.divider * MONITOR_RATIOMETRIC_FAULT_HIGH < MONITOR_ADC_REFERENCE) {
            return Err(err(
                n.divider,
                Problem::OutOfRange {
                    min: 0.0,
                    max: MONITOR_ADC_REFERENCE / MONITOR_RATIOMETRIC_FAULT_HIGH,
                    why: "4.75 V (the short-to-supply limit) times it must stay below the ADC's 3.3 V",
                },
            ));
        }
        Ok(())
    }

    /// The rules against the device and the estimator (with a sensor; each
    /// field within its plausible range), after `range_max` above
    /// `range_min`:
    ///
    /// * `p_a`, `p_b`: the range covers every pressure a chamber can have,
    ///   from the outlet `p_c` (`operating.outlet_pressure`) to the supply
    ///   `p_p = p_c + operating.pressure_drop`;
    /// * `dp_ab`: the range covers `-pressure_drop ..= pressure_drop`
    ///   (both chambers lie between `p_c` and `p_p`, so `|p_b - p_a|` is at
    ///   most the drop: the bound every state can reach, not only the
    ///   validated range's equilibria);
    /// * `x`: the range covers the stroke `0 ..= plunger.stroke`;
    /// * the span at most [`MONITOR_SPAN_LIMIT`] times the largest reading
    ///   (`p_p`, the drop, the stroke): a range in bar or MPa, or in mm,
    ///   typed for Pa or m is refused by the first rules or this one;
    /// * `monitor.sample_hz` at most `estimator.tick_hz`.
    ///
    /// # Errors
    ///
    /// `monitor.range_max`, [`Problem::Inconsistent`], not above
    /// `range_min`; `monitor.range_min` or `monitor.range_max`,
    /// [`Problem::OutOfRange`] with the bounds and their unit; `monitor.sample_hz`,
    /// [`Problem::OutOfRange`].
    pub fn check_device(&self, core: &RawCore, estimator: &RawEstimator) -> Result<(), ParamError> {
        if !self.has_sensor() {
            return Ok(());
        }
        let n = self.named();
        if !(self.range_max > self.range_min) {
            return Err(err(n.range_max, Problem::Inconsistent("not above monitor.range_min")));
        }
        let p_c = core.outlet_pressure;
        let p_p = core.outlet_pressure + core.pressure_drop;
        let (low, high, largest, min_why, max_why, span_why) = if self.sensor == 1.0 || self.sensor == 2.0 {
            (
                p_c,
                p_p,
                p_p,
                "monitor.sensor \"p_a\" or \"p_b\": at most the outlet pressure operating.outlet_pressure, in Pa (not bar or MPa)",
                "monitor.sensor \"p_a\" or \"p_b\": at least the supply pressure operating.outlet_pressure + operating.pressure_drop; the unit is Pa, not bar or MPa",
                "monitor.sensor \"p_a\" or \"p_b\": the span at most 100 times the supply pressure; the unit is Pa",
            )
        } else if self.sensor == 3.0 {
            (
                -core.pressure_drop,
                core.pressure_drop,
                core.pressure_drop,
                "monitor.sensor \"dp_ab\": at most -operating.pressure_drop (p_b - p_a reaches -drop..drop), in Pa (not bar or MPa)",
                "monitor.sensor \"dp_ab\": at least operating.pressure_drop (p_b - p_a reaches -drop..drop); the unit is Pa, not bar or MPa",
                "monitor.sensor \"dp_ab\": the span at most 100 times operating.pressure_drop; the unit is Pa",
            )
        } else {
            (
                0.0,
                core.stroke,
                core.stroke,
                "monitor.sensor \"x\": at most 0 (the plunger's closed stop), in m",
                "monitor.sensor \"x\": at least plunger.stroke; the unit is m, not mm",
                "monitor.sensor \"x\": the span at most 100 times plunger.stroke; the unit is m, not mm",
            )
        };
        let limit = MONITOR_SPAN_LIMIT * largest;
        if !(self.range_min <= low) {
            return Err(err(
                n.range_min,
                Problem::OutOfRange {
                    min: high - limit,
                    max: low,
                    why: min_why,
                },
            ));
        }
        if !(self.range_max >= high) {
            return Err(err(
                n.range_max,
                Problem::OutOfRange {
                    min: high,
                    max: low + limit,
                    why: max_why,
                },
            ));
        }
        if !(self.span() <= limit) {
            // Blame the end further from the device's readings.
            let blamed = if self.range_max - high >= low - self.range_min {
                n.range_max
            } else {
                n.range_min
            };
            let (min, max) = if blamed.path == n.range_max.path {
                (high, self.range_min + limit)
            } else {
                (self.range_max - limit, low)
            };
            return Err(err(
                blamed,
                Problem::OutOfRange {
                    min,
                    max,
                    why: span_why,
                },
            ));
        }
        if !(self.sample_hz <= estimator.tick_hz) {
            return Err(err(
                n.sample_hz,
                Problem::OutOfRange {
                    min: 0.1,
                    max: estimator.tick_hz,
                    why: "at most estimator.tick_hz",
                },
            ));
        }
        Ok(())
    }
}

impl RawProbe {
    /// The defaults of the `[probe]` section (a class B PT100 insert in a
    /// thermowell).
    pub const DEFAULT: RawProbe = RawProbe::WITH_DEFAULTS;

    /// Checks the probe section: every field within its plausible range (no
    /// rule ties them together).
    ///
    /// # Errors
    ///
    /// The first field's [`Field::check`] error.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.check_fields()
    }

    /// Half-width of the probe's tolerance at `t` \[C\]: `a + b |t|` \[C\]
    /// (IEC 60751's class limits).
    pub fn tolerance_at(&self, t: f64) -> f64 {
        self.tolerance_a + self.tolerance_b * t.abs()
    }
}

/// Most correlations a parameter file may declare (every pair of eight
/// fields: what `compensator calibrate` writes for its largest fits).
pub const MAX_CORRELATIONS: usize = 28;

/// A correlation coefficient between the uncertainties of two fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Correlation {
    /// `section.key` of the first field.
    pub a: &'static str,
    /// `section.key` of the second field.
    pub b: &'static str,
    /// Correlation coefficient r, in [-1, 1].
    pub coefficient: f64,
}

/// The standard uncertainties of the device's parameters (GUM: one
/// standard deviation each, in the field's unit; 0: exactly known), from
/// the optional `[tolerances]` section keyed like the fields
/// (`laminar_throttle.diameter = 5.8e-6`), and their correlations from the
/// `[[correlation]]` tables. Only the compensator's and the machine's fields
/// have them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawTolerances {
    /// Of the compensator's fields [their units].
    pub core: CoreFields<f64>,
    /// Of the machine's fields [their units].
    pub machine: MachineFields<f64>,
    /// The declared correlations, `correlations[..count]`.
    pub correlations: [Correlation; MAX_CORRELATIONS],
    /// How many of `correlations` are declared.
    pub count: usize,
}

const NO_CORRELATION: Correlation = Correlation {
    a: "",
    b: "",
    coefficient: 0.0,
};

impl RawTolerances {
    /// Every parameter exactly known, no correlation.
    pub const NONE: RawTolerances = RawTolerances {
        core: CoreFields::ZERO,
        machine: MachineFields::ZERO,
        correlations: [NO_CORRELATION; MAX_CORRELATIONS],
        count: 0,
    };

    /// The standard uncertainty of the field at `path` (`section.key`), if
    /// the field can have one.
    pub fn get(&self, path: &str) -> Option<f64> {
        self.core.get(path).or_else(|| self.machine.get(path)).copied()
    }

    /// The standard uncertainty of the field at `path`, mutable.
    pub fn get_mut(&mut self, path: &str) -> Option<&mut f64> {
        match self.core.get_mut(path) {
            Some(v) => Some(v),
            None => self.machine.get_mut(path),
        }
    }

    /// The declared correlations.
    pub fn correlations(&self) -> &[Correlation] {
        &self.correlations[..self.count.min(MAX_CORRELATIONS)]
    }

    /// The correlation coefficient between the fields at `a` and `b` (1 for
    /// a field with itself, 0 when none is declared).
    pub fn correlation(&self, a: &str, b: &str) -> f64 {
        if a == b {
            return 1.0;
        }
        self.correlations()
            .iter()
            .find(|c| (c.a == a && c.b == b) || (c.a == b && c.b == a))
            .map_or(0.0, |c| c.coefficient)
    }

    /// Declares the correlation `coefficient` between the fields `a` and
    /// `b` (paths of the schema's fields; checked by [`RawParams::validate`]).
    ///
    /// # Errors
    ///
    /// [`Problem::OutOfRange`] on `a` when [`MAX_CORRELATIONS`] are declared
    /// already.
    pub fn push_correlation(&mut self, a: &'static str, b: &'static str, coefficient: f64) -> Result<(), ParamError> {
        if self.count >= MAX_CORRELATIONS {
            return Err(ParamError {
                field: a,
                value: coefficient,
                problem: Problem::OutOfRange {
                    min: 0.0,
                    max: MAX_CORRELATIONS as f64,
                    why: "correlations a file may declare",
                },
            });
        }
        self.correlations[self.count] = Correlation { a, b, coefficient };
        self.count += 1;
        Ok(())
    }

    /// Whether any parameter is uncertain.
    pub fn any(&self) -> bool {
        self.core
            .into_array()
            .iter()
            .chain(self.machine.into_array().iter())
            .any(|&s| s != 0.0)
    }

    /// Checks each standard uncertainty against its field's value in `raw`
    /// and each correlation (the matrix's positive semi-definiteness is the
    /// reader's check, `file::parse`, and the uncertainty's).
    ///
    /// # Errors
    ///
    /// On the field's tolerance path (`tolerances.plunger.spring_rate`):
    /// [`Problem::NotANumber`], [`Problem::Infinite`], [`Problem::NotPositive`]
    /// for a negative one, [`Problem::OutOfRange`] for one above a third of
    /// the field's value (a device three standard deviations away would
    /// change the sign of a physical quantity) or on a machine field without
    /// a `[machine]` section ([`Problem::Inconsistent`]). On a correlation's
    /// first field: [`Problem::Correlation`].
    pub fn validate(&self, core: &RawCore, machine: Option<&RawMachine>) -> Result<(), ParamError> {
        let core_sigmas = CORE_FIELDS
            .iter()
            .zip(self.core.into_array())
            .zip(core.named().into_array());
        for ((field, sigma), named) in core_sigmas {
            check_sigma(field, sigma, named.value)?;
        }
        for (field, sigma) in MACHINE_FIELDS.iter().zip(self.machine.into_array()) {
            match machine {
                Some(m) => {
                    let value = m
                        .named()
                        .into_array()
                        .iter()
                        .find(|n| n.path == field.path)
                        .map_or(0.0, |n| n.value);
                    check_sigma(field, sigma, value)?;
                }
                None if sigma != 0.0 => {
                    return Err(ParamError {
                        field: field.tolerance_path,
                        value: sigma,
                        problem: Problem::Inconsistent("a tolerance of the machine needs the [machine] section"),
                    });
                }
                None => {}
            }
        }
        for (i, c) in self.correlations().iter().enumerate() {
            let bad = |why: &'static str| ParamError {
                field: c.a,
                value: c.coefficient,
                problem: Problem::Correlation { with: c.b, why },
            };
            if !c.coefficient.is_finite() || c.coefficient.abs() > 1.0 {
                return Err(bad("a correlation coefficient must lie in [-1, 1]"));
            }
            if c.a == c.b {
                return Err(bad("a field is not correlated with itself"));
            }
            if self.get(c.a).is_none() || self.get(c.b).is_none() {
                return Err(bad("only the compensator's and the machine's fields have tolerances"));
            }
            if self.get(c.a) == Some(0.0) || self.get(c.b) == Some(0.0) {
                return Err(bad("both fields need a tolerance in [tolerances]"));
            }
            let repeated = self.correlations()[..i]
                .iter()
                .any(|d| (d.a == c.a && d.b == c.b) || (d.a == c.b && d.b == c.a));
            if repeated {
                return Err(bad("declared twice"));
            }
        }
        Ok(())
    }
}

/// Checks one standard uncertainty `sigma` of `field`, whose value is
/// `value`.
fn check_sigma(field: &Field, sigma: f64, value: f64) -> Result<(), ParamError> {
    let n = Named {
        path: field.tolerance_path,
        value: sigma,
    };
    finite(n)?;
    if sigma < 0.0 {
        return Err(err(n, Problem::NotPositive));
    }
    // Every field with a tolerance is a physical magnitude of one sign
    // (Walther's constants included); three standard deviations must not
    // reach zero.
    if sigma > value.abs() / 3.0 {
        return Err(err(
            n,
            Problem::OutOfRange {
                min: 0.0,
                max: value.abs() / 3.0,
                why: "at most a third of the field's value",
            },
        ));
    }
    Ok(())
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
    /// The temperature probe (defaults where the file is silent).
    pub probe: RawProbe,
    /// The condition monitor's second sensor ([`RawMonitor::NONE`] where
    /// the file has no `[monitor]` section).
    pub monitor: RawMonitor,
    /// The parameters' standard uncertainties (none where the file is
    /// silent).
    pub tolerances: RawTolerances,
}

/// Every field of the file in file order: core, `[machine]`, `[estimator]`,
/// `[probe]`, `[monitor]`.
pub fn all_fields() -> impl Iterator<Item = &'static Field> {
    CORE_FIELDS
        .iter()
        .chain(MACHINE_FIELDS.iter())
        .chain(ESTIMATOR_FIELDS.iter())
        .chain(PROBE_FIELDS.iter())
        .chain(MONITOR_FIELDS.iter())
}

/// The field named `path` (`section.key`, as in messages and `docs/parameters.md`).
pub fn field_by_path(path: &str) -> Option<&'static Field> {
    all_fields().find(|f| f.path == path)
}

/// Why a field could not be reached by its name ([`RawParams::get`],
/// [`RawParams::set`]). `Display` is one line naming the path; with the
/// `toml` feature (host builds) it adds the nearest valid name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathError<'a> {
    /// The name asked for, as given.
    pub path: &'a str,
    /// What is wrong with it.
    pub problem: PathProblem,
}

/// What [`PathError`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathProblem {
    /// No field of the file has this `section.key`.
    Unknown,
    /// A `[machine]` field, and the parameter set has no `[machine]` section.
    NoMachineSection,
}

impl fmt::Display for PathError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let path = crate::Echo::head(self.path);
        match self.problem {
            PathProblem::Unknown => {
                write!(f, "unknown parameter '{path}' (a section.key of docs/parameters.md)")?;
                #[cfg(feature = "toml")]
                if let Some(near) = crate::file::nearest_path(self.path) {
                    write!(f, "; did you mean {near}?")?;
                }
                Ok(())
            }
            PathProblem::NoMachineSection => write!(f, "{path}: the parameter file has no [machine] section"),
        }
    }
}

impl core::error::Error for PathError<'_> {}

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
    /// Outside the field's own plausible range ([`Field::range`]).
    Implausible(Range),
    /// A quantity computed from this field and others lies outside its
    /// plausible range.
    DerivedImplausible {
        /// What the quantity is, naming the fields it comes from.
        quantity: &'static str,
        /// Its plausible range.
        range: Range,
    },
    /// Outside `[min, max]`, bounds that come from other fields.
    OutOfRange {
        /// Lowest accepted value.
        min: f64,
        /// Highest accepted value.
        max: f64,
        /// Where the bounds come from.
        why: &'static str,
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
    /// Not one of the accepted values.
    NotOneOf(&'static [f64]),
    /// Not the place of one of the accepted names.
    NotNamed(&'static [&'static str]),
    /// Representable in `f64` but not in the scalar type asked for.
    NotRepresentable(&'static str),
    /// A fraction where a count is needed.
    NotWhole,
    /// A declared correlation between this field and `with` is wrong.
    Correlation {
        /// `section.key` of the other field.
        with: &'static str,
        /// What is wrong.
        why: &'static str,
    },
}

/// A rejected parameter: which field (`section.key`), its value, and why.
///
/// `Display` is one line of bounded length: numbers in their shortest
/// form ([`Compact`]), every text from the schema.
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
        let (field, v) = (self.field, Compact(self.value));
        match self.problem {
            Problem::Missing => write!(f, "{field}: missing"),
            Problem::NotANumber => write!(f, "{field}: is NaN"),
            Problem::Infinite => write!(f, "{field} = {v}: must be finite"),
            Problem::NotPositive => write!(f, "{field} = {v}: must be positive"),
            Problem::Implausible(range) if range.or_zero => {
                write!(f, "{field} = {v}: must be {range} (plausible range)")
            }
            Problem::Implausible(range) => write!(f, "{field} = {v}: must lie in {range} (plausible range)"),
            Problem::DerivedImplausible { quantity, range } => {
                write!(f, "{field} = {v}: {quantity} must lie in {range} (plausible range)")
            }
            Problem::OutOfRange { min, max, why } => {
                write!(
                    f,
                    "{field} = {v}: must lie in [{}, {}] ({why})",
                    Compact(min),
                    Compact(max)
                )
            }
            Problem::Inconsistent(why) => write!(f, "{field} = {v}: {why}"),
            Problem::NotAbove { bound, why } => write!(f, "{field} = {v}: must exceed {} ({why})", Compact(bound)),
            Problem::NotOneOf(values) => {
                write!(f, "{field} = {v}: must be ")?;
                for (i, x) in values.iter().enumerate() {
                    match i {
                        0 => {}
                        i if i + 1 == values.len() => f.write_str(" or ")?,
                        _ => f.write_str(", ")?,
                    }
                    write!(f, "{}", Compact(*x))?;
                }
                Ok(())
            }
            Problem::NotNamed(names) => {
                write!(f, "{field} = {v}: must be ")?;
                for (i, x) in names.iter().enumerate() {
                    match i {
                        0 => {}
                        i if i + 1 == names.len() => f.write_str(" or ")?,
                        _ => f.write_str(", ")?,
                    }
                    write!(f, "\"{x}\"")?;
                }
                Ok(())
            }
            Problem::NotRepresentable(ty) => write!(f, "{field} = {v}: not representable as {ty}"),
            Problem::NotWhole => write!(f, "{field} = {v}: must be a whole number"),
            Problem::Correlation { with, why } => write!(f, "correlation of {field} and {with} = {v}: {why}"),
        }
    }
}

impl core::error::Error for ParamError {}

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

/// `log10(313.15)`: Walther's temperature term at 40 C.
pub(crate) const LOG10_T40: f64 = 2.495752416037327;

/// Plausible kinematic viscosity of the oil at 40 C \[cSt\] (the ISO 3448
/// grades' reference temperature): from the thinnest oil Walther's law
/// describes (2 cSt) to far beyond the heaviest gear oils (ISO VG 3200).
pub const VISCOSITY_40C_CST: (f64, f64) = (2.0, 1.0e5);

/// [`VISCOSITY_40C_CST`] as Walther's `log10(log10(nu_cSt + 0.7))` (the
/// crate computes without `log10`: it is `no_std`; a test checks them).
pub(crate) const WALTHER_40C: (f64, f64) = (-0.3651563397312923, 0.6989702683913901);

impl RawCore {
    /// Checks every field against its own plausible range, in file order
    /// ([`RawCore::check_fields`]), then the rules that tie fields together:
    /// a field that is wrong on its own is named before any rule could
    /// blame another field for it. The first violation is returned.
    ///
    /// # Errors
    ///
    /// The [`ParamError`] of the first field that breaks its own rule, else
    /// of the first rule between fields that fails:
    /// * `fluid.walther_a`, [`Problem::DerivedImplausible`]: the oil's
    ///   viscosity at 40 C outside [`VISCOSITY_40C_CST`];
    /// * `plunger.preload`, [`Problem::Inconsistent`]: beyond the stroke;
    /// * `chambers.volume_a` / `volume_b`, [`Problem::NotAbove`]: not larger
    ///   than the volume the plunger sweeps over its stroke.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.check_fields()?;
        self.check_rules()
    }

    /// The rules between fields (each field within its range).
    fn check_rules(&self) -> Result<(), ParamError> {
        let n = self.named();
        let u40 = self.walther_a - self.walther_b * LOG10_T40;
        if !(u40 >= WALTHER_40C.0 && u40 <= WALTHER_40C.1) {
            return Err(err(
                n.walther_a,
                Problem::DerivedImplausible {
                    quantity: "the oil's viscosity at 40 C (fluid.walther_a, fluid.walther_b)",
                    range: Range {
                        min: VISCOSITY_40C_CST.0,
                        max: VISCOSITY_40C_CST.1,
                        unit: "cSt",
                        or_zero: false,
                    },
                },
            ));
        }
        if self.preload > self.stroke {
            return Err(err(n.preload, Problem::Inconsistent("beyond plunger.stroke")));
        }
        // Chamber (a) shrinks by the swept volume at full stroke, so it must
        // be larger. Chamber (b) grows; the same rule is applied to it so
        // that a mirrored design (and the file format) stays symmetric.
        let swept = PI * self.plunger_diameter * self.plunger_diameter / 4.0 * self.stroke;
        for volume in [n.volume_a, n.volume_b] {
            if !(volume.value > swept) {
                return Err(err(
                    volume,
                    Problem::NotAbove {
                        bound: swept,
                        why: "the volume the plunger sweeps, pi/4 plunger.diameter^2 plunger.stroke",
                    },
                ));
            }
        }
        Ok(())
    }
}

const PI: f64 = core::f64::consts::PI;

impl RawMachine {
    /// Checks the machine section: every field within its plausible range
    /// (no rule ties them together).
    ///
    /// # Errors
    ///
    /// The first field's [`Field::check`] error.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.check_fields()
    }
}

impl RawEstimator {
    /// The defaults of the `[estimator]` section.
    pub const DEFAULT: RawEstimator = RawEstimator::WITH_DEFAULTS;

    /// Checks the estimator section: every field against its own plausible
    /// range first ([`RawEstimator::check_fields`]), then the rules between
    /// fields.
    ///
    /// # Errors
    ///
    /// The [`ParamError`] of the first field that breaks its own rule, else
    /// of the first rule between fields that fails:
    /// * `estimator.oil_max` not above `oil_min`, `valid_max` not above
    ///   `valid_min`, `oil_min` above `valid_min`, `oil_max` below
    ///   `valid_max` ([`Problem::Inconsistent`]);
    /// * `estimator.telemetry_hz` above half the tick rate
    ///   ([`Problem::OutOfRange`]);
    /// * `estimator.rtd_b`, [`Problem::Inconsistent`]: the RTD's resistance
    ///   does not rise over the oil range;
    /// * `estimator.rtd_reference`, [`Problem::NotAbove`]: not above the
    ///   RTD's resistance at `oil_max` (the converter would saturate);
    /// * with `estimator.sensor = "ntc"`: `estimator.ntc_sh_a`, `ntc_sh_b`
    ///   or `ntc_sh_c`, [`Problem::Inconsistent`], zero while another is
    ///   given; `estimator.ntc_series`, [`Problem::Inconsistent`]: the
    ///   divider's codes over `oil_min..oil_max` reach the open or short
    ///   band ([`NTC_FAULT_CODES`] at either end of the ADC's range).
    pub fn validate(&self) -> Result<(), ParamError> {
        self.check_fields()?;
        self.check_rules()
    }

    /// The rules between fields (each field within its range).
    fn check_rules(&self) -> Result<(), ParamError> {
        let n = self.named();
        if self.oil_max <= self.oil_min {
            return Err(err(n.oil_max, Problem::Inconsistent("not above estimator.oil_min")));
        }
        if self.valid_max <= self.valid_min {
            return Err(err(n.valid_max, Problem::Inconsistent("not above estimator.valid_min")));
        }
        // The oil range must hold the validated range. Each is a sound
        // range by now; the oil range's end is blamed (the validated range
        // is what the device promises; the oil model must cover it).
        if self.oil_min > self.valid_min {
            return Err(err(
                n.oil_min,
                Problem::Inconsistent("above estimator.valid_min: the oil range must hold the validated range"),
            ));
        }
        if self.oil_max < self.valid_max {
            return Err(err(
                n.oil_max,
                Problem::Inconsistent("below estimator.valid_max: the oil range must hold the validated range"),
            ));
        }
        // A telemetry tick runs none of the estimator's rotating jobs: at
        // most every second tick, so that they keep being refreshed.
        if self.telemetry_hz > self.tick_hz / 2.0 {
            return Err(err(
                n.telemetry_hz,
                Problem::OutOfRange {
                    min: 0.0,
                    max: self.tick_hz / 2.0,
                    why: "at most half of estimator.tick_hz",
                },
            ));
        }
        // The converter inverts R(t): it must rise over the oil's range.
        let mut t = self.oil_min;
        for i in 0..=64 {
            let slope = self.rtd_slope(t);
            if !(slope > 0.0) {
                return Err(err(
                    n.rtd_b,
                    Problem::Inconsistent(
                        "the RTD's resistance (estimator.rtd_a, estimator.rtd_b, estimator.rtd_c) must rise with temperature over estimator.oil_min..estimator.oil_max",
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
                    why: "the resistance of the RTD (estimator.rtd_r0, estimator.rtd_a, estimator.rtd_b) at estimator.oil_max: the converter would saturate",
                },
            ));
        }
        if self.is_ntc() {
            self.check_ntc()?;
        }
        Ok(())
    }

    /// Whether `estimator.sensor` is `"ntc"` (else `"rtd"`).
    pub fn is_ntc(&self) -> bool {
        self.sensor == 1.0
    }

    /// Whether the NTC is described by Steinhart-Hart (`ntc_sh_a`, `ntc_sh_b`,
    /// `ntc_sh_c` given) rather than by its beta.
    pub fn ntc_steinhart_hart(&self) -> bool {
        self.ntc_sh_a != 0.0 || self.ntc_sh_b != 0.0 || self.ntc_sh_c != 0.0
    }

    /// Resistance \[ohm\] of the NTC at `t` \[C\]: the beta equation
    /// `R = R25 exp(B (1/T - 1/T25))`, or Steinhart-Hart's
    /// `1/T = a + b ln R + c (ln R)^3` solved for `ln R` (Cardano: with
    /// `x = (a - 1/T) / c`, `y = sqrt((b / 3c)^3 + x^2 / 4)`,
    /// `ln R = cbrt(y - x/2) - cbrt(y + x/2)`); T in K.
    pub fn ntc_resistance(&self, t: f64) -> f64 {
        let inv_t = 1.0 / (t + KELVIN);
        if self.ntc_steinhart_hart() {
            let (a, b, c) = (self.ntc_sh_a, self.ntc_sh_b, self.ntc_sh_c);
            let x = (a - inv_t) / c;
            let b3c = b / (3.0 * c);
            let y = libm::sqrt(b3c * b3c * b3c + x * x / 4.0);
            libm::exp(libm::cbrt(y - x / 2.0) - libm::cbrt(y + x / 2.0))
        } else {
            self.ntc_r25 * libm::exp(self.ntc_beta * (inv_t - 1.0 / (25.0 + KELVIN)))
        }
    }

    /// The NTC divider's ideal ADC code at `t` \[C\] (not rounded):
    /// `2^bits R / (R + R_series)`, the NTC from the input to ground, the
    /// series resistor to `V_REF+`.
    pub fn ntc_code(&self, t: f64) -> f64 {
        let r = self.ntc_resistance(t);
        libm::exp2(self.adc_bits) * r / (r + self.ntc_series)
    }

    /// The sensor's resolution at `t` \[C per code\]: for the RTD one
    /// MAX31865 code, `R_ref / 2^15` ohm, over the RTD's slope `dR/dt` there
    /// (0.033 C at 40 C for a PT100 with 430 ohm); for the NTC one ADC code
    /// over the divider's `|d code / dt|` (central difference over 0.01 C;
    /// 0.035 C at 52 C for the default 10 kohm NTC and resistor, 12 bits).
    pub fn resolution(&self, t: f64) -> f64 {
        if self.is_ntc() {
            let h = 0.005;
            2.0 * h / (self.ntc_code(t - h) - self.ntc_code(t + h)).abs()
        } else {
            self.rtd_reference / 32768.0 / self.rtd_slope(t)
        }
    }

    /// The NTC rules ([`RawEstimator::validate`]).
    fn check_ntc(&self) -> Result<(), ParamError> {
        let n = self.named();
        // Steinhart-Hart: all three coefficients, or none (the beta).
        if self.ntc_steinhart_hart() {
            for c in [n.ntc_sh_a, n.ntc_sh_b, n.ntc_sh_c] {
                if c.value == 0.0 {
                    return Err(err(
                        c,
                        Problem::Inconsistent(
                            "estimator.ntc_sh_a, estimator.ntc_sh_b and estimator.ntc_sh_c are given together (or all 0: the beta equation)",
                        ),
                    ));
                }
            }
        }
        // The divider must keep the oil range's codes away from both ends,
        // where a code reads as an open (full scale) or a shorted (0) NTC.
        let full = libm::exp2(self.adc_bits);
        let (cold, hot) = (self.ntc_code(self.oil_min), self.ntc_code(self.oil_max));
        let inside = |c: f64| c.is_finite() && c > NTC_FAULT_CODES && c < full - NTC_FAULT_CODES;
        if !(inside(cold) && inside(hot) && cold > hot) {
            return Err(err(
                n.ntc_series,
                Problem::Inconsistent(
                    "the NTC divider (estimator.ntc_r25, ntc_beta or ntc_sh_*, ntc_series, adc_bits) saturates the ADC within estimator.oil_min..oil_max: the codes there must lie inside the open and short bands (8 codes at either end)",
                ),
            ));
        }
        Ok(())
    }

    /// Resistance \[ohm\] of the RTD at `t` \[C\] by Callendar-Van Dusen with
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
    /// Validates every section: first every field of the file against its
    /// own plausible range (core, machine, estimator, probe, in file order),
    /// then the rules between fields, so that the blame lands on the field
    /// that is wrong rather than on one a rule compares it with. The
    /// tolerances are checked where they are used
    /// ([`RawTolerances::validate`]: by the file reader and the uncertainty
    /// table), not here: a firmware image validating its parameters at
    /// start needs neither them nor the `f64` arithmetic of their rule.
    ///
    /// # Errors
    ///
    /// The first [`ParamError`] in that order (see [`RawCore::validate`],
    /// [`RawEstimator::validate`], [`RawMonitor::validate`] and
    /// [`RawMonitor::check_device`] for the rules;
    /// `machine.leakage_temperature` outside the oil range).
    pub fn validate(&self) -> Result<(), ParamError> {
        self.core.check_fields()?;
        if let Some(m) = &self.machine {
            m.check_fields()?;
        }
        self.estimator.check_fields()?;
        self.probe.check_fields()?;
        self.monitor.check_fields()?;
        self.core.check_rules()?;
        self.estimator.check_rules()?;
        // The device's rules first: a range in the wrong unit is named
        // before the noise it makes too wide.
        self.monitor.check_device(&self.core, &self.estimator)?;
        self.monitor.check_rules()?;
        if let Some(m) = &self.machine {
            // The losses are scaled by the viscosity at the reference
            // temperature: the oil model must be used there.
            let (lo, hi) = (self.estimator.oil_min, self.estimator.oil_max);
            if !(m.leakage_temperature >= lo && m.leakage_temperature <= hi) {
                return Err(err(
                    m.named().leakage_temperature,
                    Problem::OutOfRange {
                        min: lo,
                        max: hi,
                        why: "the oil range, estimator.oil_min..estimator.oil_max",
                    },
                ));
            }
        }
        Ok(())
    }

    /// The value of the field named `path` (`section.key`), generated from
    /// the schema (`plunger.mass` is `self.core.mass`).
    ///
    /// # Errors
    ///
    /// [`PathProblem::Unknown`] for a name no field has,
    /// [`PathProblem::NoMachineSection`] for a `[machine]` field of a set
    /// without that section.
    pub fn get<'a>(&self, path: &'a str) -> Result<f64, PathError<'a>> {
        let err = |problem| PathError { path, problem };
        if let Some(v) = self
            .core
            .value(path)
            .or_else(|| self.estimator.value(path))
            .or_else(|| self.probe.value(path))
            .or_else(|| self.monitor.value(path))
        {
            return Ok(v);
        }
        match &self.machine {
            Some(m) => m.value(path).ok_or(err(PathProblem::Unknown)),
            None if MACHINE_FIELDS.iter().any(|f| f.path == path) => Err(err(PathProblem::NoMachineSection)),
            None => Err(err(PathProblem::Unknown)),
        }
    }

    /// Sets the field named `path` (`section.key`) to `value`, without
    /// validating (call [`RawParams::validate`] after the last change).
    ///
    /// # Errors
    ///
    /// As [`RawParams::get`]; nothing is changed then.
    pub fn set<'a>(&mut self, path: &'a str, value: f64) -> Result<(), PathError<'a>> {
        let err = |problem| PathError { path, problem };
        let slot = match self.core.value_mut(path) {
            Some(slot) => Some(slot),
            None => match self.estimator.value_mut(path) {
                Some(slot) => Some(slot),
                None => match self.probe.value_mut(path) {
                    Some(slot) => Some(slot),
                    None => self.monitor.value_mut(path),
                },
            },
        };
        if let Some(slot) = slot {
            *slot = value;
            return Ok(());
        }
        match &mut self.machine {
            Some(m) => m
                .value_mut(path)
                .map(|slot| *slot = value)
                .ok_or(err(PathProblem::Unknown)),
            None if MACHINE_FIELDS.iter().any(|f| f.path == path) => Err(err(PathProblem::NoMachineSection)),
            None => Err(err(PathProblem::Unknown)),
        }
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
        let probe = RawProbe::from_fields(|field| get(field.section, field.key).or(field.default).unwrap_or(f64::NAN));
        // The monitor: its sensor first; without one, the keys it needs
        // are not needed (0 where absent), with one they are required.
        let sensor = get("monitor", "sensor").unwrap_or(0.0);
        let monitor = RawMonitor::try_from_fields(|field| match (get(field.section, field.key), field.default) {
            (Some(v), _) => Ok(v),
            (None, Some(d)) => Ok(d),
            (None, None) if sensor == 0.0 => Ok(0.0),
            (None, None) => Err(ParamError {
                field: field.path,
                value: f64::NAN,
                problem: Problem::Missing,
            }),
        })?;
        let raw = RawParams {
            core,
            machine,
            estimator,
            probe,
            monitor,
            tolerances: RawTolerances::NONE,
        };
        raw.validate()?;
        Ok(raw)
    }
}
