//! Validated parameters, converted to the scalar type of the computation.
//!
//! The file format itself (fields, units, rules) is the `compensator-params`
//! crate, re-exported here.
//!
//! [`RawParams`] (plain `f64`, as read from a file) is checked by
//! [`RawParams::validate`]; [`Params::new`] converts a valid set to `f32`,
//! `f64` (or any [`Float`]) and checks that every value is representable
//! there. A `Params<T>` therefore always describes a physical device: every
//! function of the core may divide by its positive fields.

pub use compensator_params::{
    CORE_FIELDS, Compact, CoreFields, Correlation, ECHO_MAX, ESTIMATOR_FIELDS, Echo, EstimatorFields, Field, KELVIN,
    Kind, MACHINE_FIELDS, MAX_CORRELATIONS, MONITOR_ADC_REFERENCE, MONITOR_CURRENT_FAULT_HIGH, MONITOR_FIELDS,
    MONITOR_OUTPUTS, MONITOR_RATIOMETRIC_FAULT_HIGH, MONITOR_SENSORS, MONITOR_SPAN_LIMIT, MachineFields, MonitorFields,
    NTC_FAULT_CODES, Named, PROBE_FIELDS, ParamError, ProbeFields, Problem, Range, RawCore, RawEstimator, RawMachine,
    RawMonitor, RawParams, RawProbe, RawTolerances, SENSOR_KINDS, VISCOSITY_40C_CST,
};

use crate::fluid::Oil;
use crate::scalar::Float;
use crate::throttle::{Capillary, Orifice, Slot};

/// The plunger and its spring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plunger<T> {
    /// Diameter `D` \[m\].
    pub diameter: T,
    /// Moving mass `m` \[kg\].
    pub mass: T,
    /// Viscous friction `b` [N s/m] (the hydraulic damping comes on top).
    pub damping: T,
    /// Spring rate `c` [N/m].
    pub spring_rate: T,
    /// Initial spring compression `x0` \[m\].
    pub preload: T,
    /// Travel between the stops, `x_max` \[m\].
    pub stroke: T,
}

impl<T: Float> Plunger<T> {
    /// Plunger area `A_p = pi D^2 / 4` [m^2].
    #[inline]
    pub fn area(&self) -> T {
        T::from_f64(core::f64::consts::FRAC_PI_4) * self.diameter * self.diameter
    }

    /// Spring compliance of the force balance, `A_p / c` [m/Pa]: the
    /// displacement per unit of chamber pressure difference.
    #[inline]
    pub fn compliance(&self) -> T {
        self.area() / self.spring_rate
    }
}

/// The driven machine whose losses the compensator should cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Machine<T> {
    /// Flow the motor needs, `Q_work` [m^3/s].
    pub working_flow: T,
    /// Volumetric loss at `leakage_temperature` [m^3/s].
    pub leakage_reference: T,
    /// Reference temperature of the loss \[C\].
    pub leakage_temperature: T,
}

/// A parameter set in scalar type `T` (SI units).
///
/// [`Params::new`] builds it from a [`RawParams`] it validates first (every
/// field in its plausible range, the rules between fields). The fields are
/// public, so that sizing tools and tests can vary one (a chamber's bulk
/// modulus beyond any oil, say): a set changed by hand carries no such
/// guarantee, and the model's functions do not assume one. They return a
/// `ModelError` naming the quantity that came out not finite or out of
/// range instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params<T> {
    /// The oil.
    pub oil: Oil<T>,
    /// Laminar throttle (capillary): outlet of (a), inlet of (b).
    pub capillary: Capillary<T>,
    /// Turbulent throttle (orifice): inlet of (a), outlet of (b).
    pub orifice: Orifice<T>,
    /// Plunger and spring.
    pub plunger: Plunger<T>,
    /// Window opened by the plunger.
    pub slot: Slot<T>,
    /// Volume of chamber (a) at `x = 0` [m^3].
    pub volume_a: T,
    /// Volume of chamber (b) at `x = 0` [m^3].
    pub volume_b: T,
    /// Constant drop `dp = p_p - p_c` \[Pa\] (Eq. 10).
    pub pressure_drop: T,
    /// Outlet pressure `p_c` \[Pa\].
    pub outlet_pressure: T,
    /// The driven machine, if described.
    pub machine: Option<Machine<T>>,
}

/// Converts a validated field to `T`, rejecting values that overflow or
/// underflow to zero there (a positive value must stay positive; a zero the
/// schema allows stays zero).
fn conv<T: Float>(n: Named) -> Result<T, ParamError> {
    let v = n.value;
    let t = T::from_f64(v);
    let lost = !t.is_finite() || (v > 0.0 && !(t > T::ZERO));
    if lost {
        Err(ParamError {
            field: n.path,
            value: v,
            problem: Problem::NotRepresentable(T::NAME),
        })
    } else {
        Ok(t)
    }
}

/// Converts a validated temperature [C] to `T`: a value that underflows is
/// 0 C there, harmless (temperatures are never divided by; the plausible
/// range keeps them finite).
fn conv_temperature<T: Float>(n: Named) -> Result<T, ParamError> {
    let t = T::from_f64(n.value);
    if t.is_finite() {
        Ok(t)
    } else {
        Err(ParamError {
            field: n.path,
            value: n.value,
            problem: Problem::NotRepresentable(T::NAME),
        })
    }
}

impl<T: Float> Params<T> {
    /// Validates `raw` and converts it to `T`.
    ///
    /// Errors name the offending field (`section.key`).
    pub fn new(raw: &RawParams) -> Result<Self, ParamError> {
        // Every field's own range first, in every section, then the rules
        // between fields (`RawParams::validate`): the blame lands on the
        // field that is wrong.
        raw.validate()?;
        Self::from_core(&raw.core, raw.machine.as_ref())
    }

    /// As [`Params::new`], from the sections separately.
    pub fn from_core(core: &RawCore, machine: Option<&RawMachine>) -> Result<Self, ParamError> {
        core.validate()?;
        let n = core.named();
        let params: Self = Params {
            oil: {
                for field in [n.walther_a, n.walther_b, n.density_15, n.expansion, n.bulk_modulus] {
                    conv::<T>(field)?;
                }
                Oil::new(
                    core.walther_a,
                    core.walther_b,
                    core.density_15,
                    core.expansion,
                    core.bulk_modulus,
                )
            },
            capillary: Capillary {
                diameter: conv(n.laminar_diameter)?,
                length: conv(n.laminar_length)?,
            },
            orifice: Orifice {
                diameter: conv(n.turbulent_diameter)?,
                discharge_coefficient: conv(n.turbulent_discharge)?,
            },
            plunger: Plunger {
                diameter: conv(n.plunger_diameter)?,
                mass: conv(n.mass)?,
                damping: conv(n.damping)?,
                spring_rate: conv(n.spring_rate)?,
                preload: conv(n.preload)?,
                stroke: conv(n.stroke)?,
            },
            slot: Slot {
                diameter: conv(n.slot_diameter)?,
                discharge_coefficient: conv(n.slot_discharge)?,
            },
            volume_a: conv(n.volume_a)?,
            volume_b: conv(n.volume_b)?,
            pressure_drop: conv(n.pressure_drop)?,
            outlet_pressure: conv(n.outlet_pressure)?,
            machine: match machine {
                None => None,
                Some(m) => {
                    m.validate()?;
                    let n = m.named();
                    Some(Machine {
                        working_flow: conv(n.working_flow)?,
                        leakage_reference: conv(n.leakage_reference)?,
                        leakage_temperature: conv_temperature(n.leakage_temperature)?,
                    })
                }
            },
        };
        // Derived quantities the model divides by must be representable too.
        let f = &RawCore::FIELD;
        let derived = [
            (f.plunger_diameter.path, params.plunger.area()),
            (f.turbulent_diameter.path, params.orifice.area()),
            (f.laminar_diameter.path, params.capillary.bore_term()),
            (f.stroke.path, params.plunger.area() * params.plunger.stroke),
        ];
        for (field, value) in derived {
            if !(value.is_finite() && value > T::ZERO) {
                return Err(ParamError {
                    field,
                    value: value.to_f64(),
                    problem: Problem::NotRepresentable(T::NAME),
                });
            }
        }
        Ok(params)
    }

    /// Inlet pressure `p_p = p_c + dp` \[Pa\].
    #[inline]
    pub fn inlet_pressure(&self) -> T {
        self.outlet_pressure + self.pressure_drop
    }

    /// The same parameters with another pressure drop (for sweeps over the
    /// paper's 4, 5 and 6 bar). Returns an error for a non-positive drop.
    pub fn with_pressure_drop(&self, dp: T) -> Result<Self, ParamError> {
        if !(dp.is_finite() && dp > T::ZERO) {
            return Err(ParamError {
                field: RawCore::FIELD.pressure_drop.path,
                value: dp.to_f64(),
                problem: Problem::NotPositive,
            });
        }
        Ok(Params {
            pressure_drop: dp,
            ..*self
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid design whose values all differ, so that a field converted
    /// into another's place shows. No preload: the stroke may then shrink
    /// to nothing without breaking a rule.
    const CORE: RawCore = RawCore {
        walther_a: 9.5,
        walther_b: 3.75,
        density_15: 871.0,
        expansion: 6.5e-4,
        bulk_modulus: 1.6e9,
        laminar_diameter: 8.1e-4,
        laminar_length: 0.0242,
        turbulent_diameter: 7.2e-4,
        turbulent_discharge: 0.61,
        plunger_diameter: 0.0101,
        mass: 0.021,
        damping: 2.2,
        spring_rate: 25600.0,
        preload: 0.0,
        stroke: 0.0015,
        slot_diameter: 0.0021,
        slot_discharge: 0.63,
        volume_a: 2.1e-6,
        volume_b: 2.3e-6,
        pressure_drop: 410_000.0,
        outlet_pressure: 1500.0,
    };

    const MACHINE: RawMachine = RawMachine {
        working_flow: 3.6e-7,
        leakage_reference: 3.5e-5,
        leakage_temperature: 41.0,
    };

    type Get = fn(&Params<f64>) -> f64;

    fn machine(p: &Params<f64>) -> Machine<f64> {
        p.machine.expect("a machine was given")
    }

    /// Where each field of the file must land in `Params`, written by hand
    /// (the oil's Walther constants are private: the oil is compared whole).
    const LANDS: &[(&str, Get)] = &[
        ("fluid.density_15", |p| p.oil.density_15),
        ("fluid.expansion", |p| p.oil.expansion),
        ("fluid.bulk_modulus", |p| p.oil.bulk_modulus),
        ("laminar_throttle.diameter", |p| p.capillary.diameter),
        ("laminar_throttle.length", |p| p.capillary.length),
        ("turbulent_throttle.diameter", |p| p.orifice.diameter),
        ("turbulent_throttle.discharge_coefficient", |p| {
            p.orifice.discharge_coefficient
        }),
        ("plunger.diameter", |p| p.plunger.diameter),
        ("plunger.mass", |p| p.plunger.mass),
        ("plunger.damping", |p| p.plunger.damping),
        ("plunger.spring_rate", |p| p.plunger.spring_rate),
        ("plunger.preload", |p| p.plunger.preload),
        ("plunger.stroke", |p| p.plunger.stroke),
        ("slot.diameter", |p| p.slot.diameter),
        ("slot.discharge_coefficient", |p| p.slot.discharge_coefficient),
        ("chambers.volume_a", |p| p.volume_a),
        ("chambers.volume_b", |p| p.volume_b),
        ("operating.pressure_drop", |p| p.pressure_drop),
        ("operating.outlet_pressure", |p| p.outlet_pressure),
        ("machine.working_flow", |p| machine(p).working_flow),
        ("machine.leakage_reference", |p| machine(p).leakage_reference),
        ("machine.leakage_temperature", |p| machine(p).leakage_temperature),
    ];

    fn every_value() -> impl Iterator<Item = Named> {
        CORE.named()
            .into_array()
            .into_iter()
            .chain(MACHINE.named().into_array())
    }

    #[test]
    fn every_field_lands_in_the_params_field_of_its_name() {
        let values: Vec<Named> = every_value().collect();
        for (i, a) in values.iter().enumerate() {
            for b in &values[i + 1..] {
                assert_ne!(
                    a.value, b.value,
                    "{} and {} are alike: a swap would go unseen",
                    a.path, b.path
                );
            }
        }
        let p = Params::<f64>::from_core(&CORE, Some(&MACHINE)).unwrap();
        let walther = ["fluid.walther_a", "fluid.walther_b"];
        for n in &values {
            match LANDS.iter().find(|(path, _)| *path == n.path) {
                Some((_, get)) => assert_eq!(get(&p), n.value, "{} is not in its own field", n.path),
                None => assert!(walther.contains(&n.path), "{}: where does it land?", n.path),
            }
        }
        assert_eq!(LANDS.len() + walther.len(), values.len());
        let oil = Oil::new(
            CORE.walther_a,
            CORE.walther_b,
            CORE.density_15,
            CORE.expansion,
            CORE.bulk_modulus,
        );
        assert_eq!(p.oil, oil);
        assert_ne!(
            p.oil,
            Oil::new(
                CORE.walther_b,
                CORE.walther_a,
                CORE.density_15,
                CORE.expansion,
                CORE.bulk_modulus
            ),
            "the comparison sees swapped Walther constants"
        );
    }

    /// Every value the schema's plausible ranges admit fits `f32`, the
    /// derived quantities too: each field at either end of its range (the
    /// others as in [`CORE`]), where the rules between fields accept it,
    /// converts.
    #[test]
    fn every_plausible_value_fits_f32() {
        for field in CORE_FIELDS.iter().chain(MACHINE_FIELDS.iter()) {
            for end in [field.min, field.max] {
                let with = |n: Named| if n.path == field.path { end } else { n.value };
                let (core, machine) = (CORE.map(with), MACHINE.map(with));
                if core.validate().and(machine.validate()).is_err() {
                    continue;
                }
                let p = Params::<f32>::from_core(&core, Some(&machine));
                assert!(p.is_ok(), "{} = {end}: {p:?}", field.path);
            }
        }
    }

    /// A value `f32` loses (to zero or infinity) is reported under the name
    /// of the field it was in (the ranges keep file values clear of it;
    /// the conversion checks anyway).
    #[test]
    fn a_value_f32_cannot_hold_names_its_own_field() {
        for field in CORE_FIELDS.iter().chain(MACHINE_FIELDS.iter()) {
            for lost in [1e-60, 1e60] {
                let e = conv::<f32>(Named {
                    path: field.path,
                    value: lost,
                })
                .unwrap_err();
                assert_eq!(
                    (e.field, e.value, e.problem),
                    (field.path, lost, Problem::NotRepresentable("f32"))
                );
            }
        }
        // The same values in `f64` are fine.
        assert_eq!(
            conv::<f64>(Named {
                path: "x",
                value: 1e-60
            }),
            Ok(1e-60)
        );
        assert!(Params::<f64>::from_core(&CORE, Some(&MACHINE)).is_ok());
    }
}
