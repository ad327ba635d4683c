//! The end stops of the dynamic models: inelastic. On a stop, with the net
//! static force pushing into it and no velocity away from it, the plunger is
//! held (`xi' = w' = 0`, [`contact_for`]); a step that crosses a stop ends on
//! it with `w = 0` ([`apply_stops`]; the full twin locates the impact inside
//! the step instead, [`super::twin::Twin::tick`]).
//!
//! The stop state is one type for every level of the model: [`Contact`] is
//! [`crate::equilibrium::Stop`], the stop a quasi-static equilibrium rests
//! on, under the name the dynamics use for it (held by a stop during a step).

use super::coefficients::Coefficients;
use crate::scalar::Real;

/// Whether the plunger is held by a stop during a step: `Free` (moving
/// freely), `Closed` (held at `x = 0`), `Open` (held at `x = x_max`). The
/// same type as the equilibrium's [`crate::equilibrium::Stop`].
pub use crate::equilibrium::Stop as Contact;

/// The contact state of a plunger at `xi` moving at `w` under net static
/// force `force` (positive opens): held by a stop when on it, not moving
/// away from it, and pushed into it.
#[inline]
pub fn contact_for<T: Real>(xi: T, w: T, force: T) -> Contact {
    if xi <= T::ZERO && w <= T::ZERO && force <= T::ZERO {
        Contact::Closed
    } else if xi >= T::ONE && w >= T::ZERO && force >= T::ZERO {
        Contact::Open
    } else {
        Contact::Free
    }
}

/// Applies the inelastic stops after a step: a plunger beyond a stop (or
/// on it and moving into it) is put on it at rest. Returns `true` when the
/// state was changed (an impact).
#[inline]
pub fn apply_stops<T: Real>(xi: &mut T, w: &mut T) -> bool {
    let (stop, hit) = if *xi < T::ZERO || (*xi == T::ZERO && *w < T::ZERO) {
        (T::ZERO, true)
    } else if *xi > T::ONE || (*xi == T::ONE && *w > T::ZERO) {
        (T::ONE, true)
    } else {
        (*xi, false)
    };
    if hit {
        *xi = stop;
        *w = T::ZERO;
    }
    hit
}

/// The static force on a plunger held at `held`'s stop, positive when it
/// pulls the plunger off the stop.
#[inline]
pub(crate) fn away_from<T: Real>(c: &Coefficients<T>, held: Contact, y: &[T; 4]) -> T {
    match held {
        Contact::Open => -c.static_force(y),
        _ => c.static_force(y),
    }
}

impl<T: Real> Coefficients<T> {
    /// The contact state for `y` (see [`contact_for`]).
    #[inline]
    pub fn contact(&self, y: &[T; 4]) -> Contact {
        contact_for(y[0], y[1], self.static_force(y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::equilibrium::Stop;

    #[test]
    fn contact_is_the_equilibrium_stop() {
        // One type: a stop found by the equilibrium is a contact state.
        let stop: Stop = contact_for(0.0, 0.0, -1.0);
        assert_eq!(stop, Contact::Closed);
        assert_eq!(contact_for(1.0, 0.0, 1.0), Stop::Open);
        assert_eq!(contact_for(1.0, -0.1, 1.0), Contact::Free);
        let (mut xi, mut w) = (1.2, 0.3);
        assert!(apply_stops(&mut xi, &mut w));
        assert_eq!((xi, w), (1.0, 0.0));
        let (mut xi, mut w) = (0.5, -0.3);
        assert!(!apply_stops(&mut xi, &mut w));
        assert_eq!((xi, w), (0.5, -0.3));
    }
}
