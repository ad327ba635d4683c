//! Oil properties as functions of temperature (`docs/model.md` section 2).
//!
//! * Kinematic viscosity by Walther / ASTM D341:
//!   `log10(log10(nu_cSt + 0.7)) = a - b log10(T_K)`.
//! * Density `rho(t) = rho_15 / (1 + e (t - 15))`.
//! * Dynamic viscosity `mu = nu rho`.
//!
//! ASTM D341's two-constant form holds down to 2 cSt; below that (very hot
//! or very thin oil) the evaluation is refused with
//! [`ModelError::OutOfRange`], as it is where the double exponential
//! overflows (very cold oil).
//!
//! Cost (f32, Cortex-M4F): one `ln_1p`, two `exp10`, a handful of
//! multiplications: about 300 instructions with the derivatives
//! (`FluidPoint`, `cargo xtask bench`).

use crate::error::{ModelError, finite};
use crate::scalar::Float;

/// Offset between degrees Celsius and kelvin.
pub const KELVIN_OFFSET: f64 = 273.15;
/// Lowest kinematic viscosity for which ASTM D341's form holds \[cSt\].
pub const WALTHER_MIN_CST: f64 = 2.0;
/// Highest kinematic viscosity accepted \[cSt\] (beyond: the oil is a solid
/// for any hydraulic purpose, and `f32` loses the double exponential).
pub const WALTHER_MAX_CST: f64 = 1.0e6;

/// Reference temperature of the cancellation-free Walther form \[C\].
pub const WALTHER_REFERENCE_C: f64 = 40.0;

/// The oil's temperature laws.
///
/// Walther's `a - b log10(T_K)` subtracts two numbers near 9 to get one
/// near 0.3, which in `f32` costs about 1e-5 of relative viscosity. The
/// evaluation therefore uses `u_ref - b log10(1 + (t - t_ref) / T_ref)`
/// with `u_ref = a - b log10(T_ref)` computed once in `f64` by
/// [`Oil::new`], and `log1p` for the small logarithm: the `f32` viscosity
/// is then good to about 3e-7. Walther's constants are therefore private:
/// `u_ref` is derived from them once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oil<T> {
    /// Walther slope `b` [-].
    walther_b: T,
    /// Density at 15 C [kg/m^3].
    pub density_15: T,
    /// Volumetric expansion coefficient `e` [1/K].
    pub expansion: T,
    /// Effective bulk modulus `beta_e` \[Pa\].
    pub bulk_modulus: T,
    /// `a - b log10(T_ref)` at [`WALTHER_REFERENCE_C`], computed in `f64`.
    walther_u_ref: T,
}

/// The oil's state at one temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluidState<T> {
    /// Temperature \[C\].
    pub temperature: T,
    /// Kinematic viscosity `nu` [m^2/s].
    pub kinematic_viscosity: T,
    /// Density `rho` [kg/m^3].
    pub density: T,
    /// Dynamic viscosity `mu = nu rho` [Pa s].
    pub dynamic_viscosity: T,
}

/// The oil at one temperature with the temperature derivatives of its
/// viscosity and density, from a single Walther evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluidPoint<T> {
    /// Viscosities and density.
    pub state: FluidState<T>,
    /// `nu`, `nu'`, `nu''` [m^2/s, per K, per K^2].
    pub viscosity: Derivatives<T>,
    /// `rho`, `rho'`, `rho''` [kg/m^3, per K, per K^2].
    pub density: Derivatives<T>,
}

/// The first half of a Walther evaluation ([`Oil::walther_log`]): the
/// temperature and `w = log10(nu_cSt + 0.7)`, what [`Oil::point_from_log`]
/// ends it from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaltherLog<T> {
    /// Temperature \[C\].
    pub temperature: T,
    /// Temperature \[K\].
    kelvin: T,
    /// `w = log10(nu_cSt + 0.7)` [-].
    pub w: T,
}

/// A quantity with its first two temperature derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derivatives<T> {
    /// The value.
    pub value: T,
    /// First derivative with respect to temperature [unit/K].
    pub d1: T,
    /// Second derivative [unit/K^2].
    pub d2: T,
}

impl<T: Float> Oil<T> {
    /// An oil from its constants (Walther `a`, `b` [-], density at 15 C
    /// [kg/m^3], expansion [1/K], bulk modulus \[Pa\]), given in `f64` so that
    /// the reference term of the Walther form is exact to `f64` precision.
    pub fn new(walther_a: f64, walther_b: f64, density_15: f64, expansion: f64, bulk_modulus: f64) -> Self {
        let u_ref = walther_a - walther_b * libm::log10(WALTHER_REFERENCE_C + KELVIN_OFFSET);
        Oil {
            walther_b: T::from_f64(walther_b),
            density_15: T::from_f64(density_15),
            expansion: T::from_f64(expansion),
            bulk_modulus: T::from_f64(bulk_modulus),
            walther_u_ref: T::from_f64(u_ref),
        }
    }

    /// Walther's inner variables at `t` [C]: `(Z = nu_cSt + 0.7, w = log10 Z, T_K)`.
    fn walther(&self, t: T) -> Result<(T, T, T), ModelError> {
        let log = self.walther_log(t)?;
        Ok((Self::walther_z(log.w)?, log.w, log.kelvin))
    }

    /// The first half of a Walther evaluation at `t` \[C\]: `w = log10(nu_cSt
    /// + 0.7)` (one `ln_1p`, one `exp10`). [`Oil::point_from_log`] ends it
    /// (one `exp10`, the derivatives and the density), so that a core
    /// without an FPU can spread one evaluation over two ticks; the two
    /// halves give [`Oil::point`]'s result bit for bit.
    ///
    /// # Errors
    ///
    /// [`ModelError::NonFinite`] for a temperature that is not finite;
    /// [`ModelError::OutOfRange`] at or below absolute zero (the viscosity's
    /// range is [`Oil::point_from_log`]'s to check).
    pub fn walther_log(&self, t: T) -> Result<WaltherLog<T>, ModelError> {
        let t = finite(t, "temperature")?;
        let tk = t + T::from_f64(KELVIN_OFFSET);
        if !(tk > T::ZERO) {
            return Err(ModelError::OutOfRange("temperature"));
        }
        let t_ref = T::from_f64(WALTHER_REFERENCE_C + KELVIN_OFFSET);
        let delta = (t - T::from_f64(WALTHER_REFERENCE_C)) / t_ref;
        let u = self.walther_u_ref - self.walther_b * delta.ln_1p() * T::from_f64(core::f64::consts::LOG10_E);
        Ok(WaltherLog {
            temperature: t,
            kelvin: tk,
            w: u.exp10(),
        })
    }

    /// `Z = 10^w = nu_cSt + 0.7`, inside Walther's range.
    fn walther_z(w: T) -> Result<T, ModelError> {
        let z = w.exp10();
        if !z.is_finite() || z > T::from_f64(WALTHER_MAX_CST + 0.7) {
            return Err(ModelError::OutOfRange(
                "temperature (viscosity above the Walther range)",
            ));
        }
        if !(z >= T::from_f64(WALTHER_MIN_CST + 0.7)) {
            return Err(ModelError::OutOfRange("temperature (viscosity below 2 cSt)"));
        }
        Ok(z)
    }

    /// Kinematic viscosity `nu(t)` [m^2/s].
    ///
    /// # Errors
    ///
    /// [`ModelError::NonFinite`] for a temperature that is not finite;
    /// [`ModelError::OutOfRange`] at or below absolute zero, and where the
    /// viscosity leaves Walther's range: below [`WALTHER_MIN_CST`] (oil too
    /// hot or too thin) or above [`WALTHER_MAX_CST`] (too cold).
    pub fn kinematic_viscosity(&self, t: T) -> Result<T, ModelError> {
        let (z, _, _) = self.walther(t)?;
        Ok((z - T::from_f64(0.7)) * T::from_f64(1e-6))
    }

    /// `nu`, `dnu/dt`, `d2nu/dt2` [m^2/s, m^2/(s K), m^2/(s K^2)], closed form:
    /// with `Z = nu_cSt + 0.7`, `w = log10 Z`,
    /// `nu' = -b ln10 Z w / T_K`, `nu'' = -b ln10 w (nu'/T_K - Z (b + 1) / T_K^2)`.
    ///
    /// # Errors
    ///
    /// As [`Oil::kinematic_viscosity`].
    pub fn kinematic_viscosity_derivatives(&self, t: T) -> Result<Derivatives<T>, ModelError> {
        let (z, w, tk) = self.walther(t)?;
        Ok(self.viscosity_derivatives(z, w, tk))
    }

    /// `nu`, `nu'`, `nu''` from Walther's inner variables `Z`, `w`, `T_K`.
    fn viscosity_derivatives(&self, z: T, w: T, tk: T) -> Derivatives<T> {
        let ln10 = T::from_f64(core::f64::consts::LN_10);
        let b = self.walther_b;
        let d1 = -b * ln10 * z * w / tk;
        let d2 = -b * ln10 * w * (d1 / tk - z * (b + T::ONE) / (tk * tk));
        let cst = T::from_f64(1e-6);
        Derivatives {
            value: (z - T::from_f64(0.7)) * cst,
            d1: d1 * cst,
            d2: d2 * cst,
        }
    }

    /// The factor `1 + e (t - 15)`; positive for every validated parameter
    /// set and temperature above -85 C.
    fn expansion_factor(&self, t: T) -> Result<T, ModelError> {
        let f = T::ONE + self.expansion * (t - T::from_f64(15.0));
        if f > T::ZERO {
            Ok(f)
        } else {
            Err(ModelError::OutOfRange("temperature (density law)"))
        }
    }

    /// Density `rho(t)` [kg/m^3].
    ///
    /// # Errors
    ///
    /// [`ModelError::NonFinite`] for a temperature that is not finite;
    /// [`ModelError::OutOfRange`] where `1 + e (t - 15)` is not positive
    /// (only at -85 C or colder, for any validated parameter set).
    pub fn density(&self, t: T) -> Result<T, ModelError> {
        let t = finite(t, "temperature")?;
        Ok(self.density_15 / self.expansion_factor(t)?)
    }

    /// `rho`, `drho/dt`, `d2rho/dt2`: `rho' = -e rho / f`, `rho'' = 2 e^2 rho / f^2`
    /// with `f = 1 + e (t - 15)`.
    ///
    /// # Errors
    ///
    /// As [`Oil::density`].
    pub fn density_derivatives(&self, t: T) -> Result<Derivatives<T>, ModelError> {
        let t = finite(t, "temperature")?;
        let f = self.expansion_factor(t)?;
        let rho = self.density_15 / f;
        let r = self.expansion / f;
        Ok(Derivatives {
            value: rho,
            d1: -r * rho,
            d2: T::from_f64(2.0) * r * r * rho,
        })
    }

    /// State and derivatives at `t` \[C\] (one Walther evaluation).
    ///
    /// # Errors
    ///
    /// As [`Oil::kinematic_viscosity`] and [`Oil::density`], and
    /// `NonFinite("dynamic viscosity")` if `nu rho` overflows.
    pub fn point(&self, t: T) -> Result<FluidPoint<T>, ModelError> {
        self.point_from_log(self.walther_log(t)?)
    }

    /// [`Oil::point`] from the first half of its Walther evaluation
    /// ([`Oil::walther_log`]).
    ///
    /// # Errors
    ///
    /// As [`Oil::point`] (the viscosity's range, the density law,
    /// `NonFinite("dynamic viscosity")`).
    pub fn point_from_log(&self, log: WaltherLog<T>) -> Result<FluidPoint<T>, ModelError> {
        let z = Self::walther_z(log.w)?;
        let nu = self.viscosity_derivatives(z, log.w, log.kelvin);
        let rho = self.density_derivatives(log.temperature)?;
        Ok(FluidPoint {
            state: FluidState {
                temperature: log.temperature,
                kinematic_viscosity: nu.value,
                density: rho.value,
                dynamic_viscosity: finite(nu.value * rho.value, "dynamic viscosity")?,
            },
            viscosity: nu,
            density: rho,
        })
    }

    /// Viscosity, density and dynamic viscosity at `t` \[C\].
    ///
    /// # Errors
    ///
    /// As [`Oil::point`].
    pub fn state(&self, t: T) -> Result<FluidState<T>, ModelError> {
        let nu = self.kinematic_viscosity(t)?;
        let rho = self.density(t)?;
        Ok(FluidState {
            temperature: t,
            kinematic_viscosity: nu,
            density: rho,
            dynamic_viscosity: finite(nu * rho, "dynamic viscosity")?,
        })
    }
}
