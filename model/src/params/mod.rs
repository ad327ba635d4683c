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
    CORE_FIELDS, ESTIMATOR_FIELDS, Field, MACHINE_FIELDS, ParamError, Problem, RawCore, RawEstimator, RawMachine,
    RawParams,
};

use crate::fluid::Oil;
use crate::scalar::Float;
use crate::throttle::{Capillary, Orifice, Slot};

/// The plunger and its spring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plunger<T> {
    /// Diameter `D` [m].
    pub diameter: T,
    /// Moving mass `m` [kg].
    pub mass: T,
    /// Viscous friction `b` [N s/m] (the hydraulic damping comes on top).
    pub damping: T,
    /// Spring rate `c` [N/m].
    pub spring_rate: T,
    /// Initial spring compression `x0` [m].
    pub preload: T,
    /// Travel between the stops, `x_max` [m].
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
    /// Reference temperature of the loss [C].
    pub leakage_temperature: T,
}

/// A validated parameter set in scalar type `T`.
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
    /// Constant drop `dp = p_p - p_c` [Pa] (Eq. 10).
    pub pressure_drop: T,
    /// Outlet pressure `p_c` [Pa].
    pub outlet_pressure: T,
    /// The driven machine, if described.
    pub machine: Option<Machine<T>>,
}

/// Converts a validated `f64` to `T`, rejecting values that overflow or
/// underflow to zero there (a positive value must stay positive; a zero the
/// schema allows stays zero).
fn conv<T: Float>(field: &'static str, v: f64) -> Result<T, ParamError> {
    let t = T::from_f64(v);
    let lost = !t.is_finite() || (v > 0.0 && !(t > T::ZERO));
    if lost {
        Err(ParamError {
            field,
            value: v,
            problem: Problem::NotRepresentable(T::NAME),
        })
    } else {
        Ok(t)
    }
}

impl<T: Float> Params<T> {
    /// Validates `raw` and converts it to `T`.
    ///
    /// Errors name the offending field (`section.key`).
    pub fn new(raw: &RawParams) -> Result<Self, ParamError> {
        // `from_core` validates the core and machine sections.
        let params = Self::from_core(&raw.core, raw.machine.as_ref())?;
        raw.estimator.validate()?;
        Ok(params)
    }

    /// As [`Params::new`], from the sections separately.
    pub fn from_core(core: &RawCore, machine: Option<&RawMachine>) -> Result<Self, ParamError> {
        core.validate()?;
        let f = &CORE_FIELDS;
        let v = core.to_array();
        let c = |i: usize| conv::<T>(f[i].path, v[i]);
        let params = Params {
            oil: {
                for i in 0..5 {
                    c(i)?;
                }
                Oil::new(v[0], v[1], v[2], v[3], v[4])
            },
            capillary: Capillary {
                diameter: c(5)?,
                length: c(6)?,
            },
            orifice: Orifice {
                diameter: c(7)?,
                discharge_coefficient: c(8)?,
            },
            plunger: Plunger {
                diameter: c(9)?,
                mass: c(10)?,
                damping: c(11)?,
                spring_rate: c(12)?,
                preload: c(13)?,
                stroke: c(14)?,
            },
            slot: Slot {
                diameter: c(15)?,
                discharge_coefficient: c(16)?,
            },
            volume_a: c(17)?,
            volume_b: c(18)?,
            pressure_drop: c(19)?,
            outlet_pressure: c(20)?,
            machine: match machine {
                None => None,
                Some(m) => {
                    m.validate()?;
                    let mf = &MACHINE_FIELDS;
                    Some(Machine {
                        working_flow: conv(mf[0].path, m.working_flow)?,
                        leakage_reference: conv(mf[1].path, m.leakage_reference)?,
                        leakage_temperature: conv(mf[2].path, m.leakage_temperature)?,
                    })
                }
            },
        };
        // Derived quantities the model divides by must be representable too.
        let derived = [
            (f[9].path, params.plunger.area()),
            (f[7].path, params.orifice.area()),
            (f[5].path, params.capillary.bore_term()),
            (f[14].path, params.plunger.area() * params.plunger.stroke),
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

    /// Inlet pressure `p_p = p_c + dp` [Pa].
    #[inline]
    pub fn inlet_pressure(&self) -> T {
        self.outlet_pressure + self.pressure_drop
    }

    /// The same parameters with another pressure drop (for sweeps over the
    /// paper's 4, 5 and 6 bar). Returns an error for a non-positive drop.
    pub fn with_pressure_drop(&self, dp: T) -> Result<Self, ParamError> {
        if !(dp.is_finite() && dp > T::ZERO) {
            return Err(ParamError {
                field: CORE_FIELDS[19].path,
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
