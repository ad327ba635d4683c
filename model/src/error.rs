//! The core's error type for model evaluation (parameter errors are
//! [`crate::params::ParamError`]).

/// Why a model evaluation produced no value.
///
/// The payload names the quantity, so that a log line says what went wrong
/// without formatting machinery.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelError {
    /// An input or intermediate result is NaN or infinite.
    NonFinite(&'static str),
    /// An input lies outside the range where the model holds (for example a
    /// temperature where Walther's viscosity law is not valid).
    OutOfRange(&'static str),
    /// A bounded iteration did not converge within its budget.
    NoConvergence(&'static str),
    /// A finite value the scalar type cannot hold (fixed-point saturation).
    NotRepresentable(&'static str),
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::NonFinite(what) => write!(f, "{what} is not finite"),
            ModelError::OutOfRange(what) => write!(f, "{what} is out of the model's range"),
            ModelError::NoConvergence(what) => write!(f, "{what} did not converge"),
            ModelError::NotRepresentable(what) => write!(f, "{what} does not fit the scalar type"),
        }
    }
}

/// A model error is a plain value (no source): `?` turns it into any
/// `Box<dyn Error>` or error-reporting type on the host.
impl core::error::Error for ModelError {}

/// `Ok(v)` if `v` is finite, else `NonFinite(what)`.
#[inline]
pub(crate) fn finite<T: crate::Real>(v: T, what: &'static str) -> Result<T, ModelError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ModelError::NonFinite(what))
    }
}

/// `v` converted to `T`: `NonFinite(what)` if either side is not finite,
/// `NotRepresentable(what)` if `T` saturated it (the round trip is off by
/// more than 1e-3 relative plus `T`'s resolution).
#[inline]
pub(crate) fn represent<S: crate::Float, T: crate::Real>(v: S, what: &'static str) -> Result<T, ModelError> {
    let t: T = v.to_real();
    if !(v.is_finite() && t.is_finite()) {
        return Err(ModelError::NonFinite(what));
    }
    let tolerance = S::from_f64(1e-3) * v.abs() + S::from_real(T::tiny());
    if (S::from_real(t) - v).abs() <= tolerance {
        Ok(t)
    } else {
        Err(ModelError::NotRepresentable(what))
    }
}
