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
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::NonFinite(what) => write!(f, "{what} is not finite"),
            ModelError::OutOfRange(what) => write!(f, "{what} is out of the model's range"),
            ModelError::NoConvergence(what) => write!(f, "{what} did not converge"),
        }
    }
}

/// `Ok(v)` if `v` is finite, else `NonFinite(what)`.
#[inline]
pub(crate) fn finite<T: crate::Real>(v: T, what: &'static str) -> Result<T, ModelError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ModelError::NonFinite(what))
    }
}
