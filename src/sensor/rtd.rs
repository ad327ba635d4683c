//! Platinum resistance thermometers (IEC 60751, Callendar-Van Dusen):
//!
//! ```text
//! R(t) = R0 (1 + A t + B t^2)                  t >= 0 C
//! R(t) = R0 (1 + A t + B t^2 + C (t - 100) t^3)  t < 0 C
//! A = 3.9083e-3, B = -5.775e-7, C = -4.183e-12
//! ```
//!
//! [`temperature`] inverts it: the quadratic's closed form above 0 C, and
//! below it that root refined by three Newton steps on the quartic
//! (fixed cost; 1e-4 C over -200..0 C). Cost (f32, Cortex-M4F): ~40
//! instructions, one square root.

/// Callendar-Van Dusen `A` [1/C].
pub const A: f32 = 3.9083e-3;
/// Callendar-Van Dusen `B` [1/C^2].
pub const B: f32 = -5.775e-7;
/// Callendar-Van Dusen `C` [1/C^4] (below 0 C only).
pub const C: f32 = -4.183e-12;
/// Lowest temperature of the IEC 60751 range [C].
pub const T_MIN: f32 = -200.0;
/// Highest temperature of the IEC 60751 range [C].
pub const T_MAX: f32 = 850.0;

/// Resistance [ohm] of an RTD with `r0` [ohm] at 0 C, at `t` [C].
pub fn resistance(r0: f32, t: f32) -> f32 {
    let mut r = 1.0 + A * t + B * t * t;
    if t < 0.0 {
        r += C * (t - 100.0) * t * t * t;
    }
    r0 * r
}

/// Temperature [C] of an RTD with `r0` [ohm] at 0 C reading `r` [ohm];
/// `None` outside the IEC 60751 range (-200..850 C) or for a non-finite
/// or non-positive resistance.
pub fn temperature(r0: f32, r: f32) -> Option<f32> {
    if !(r > 0.0 && r.is_finite() && r0 > 0.0 && r0.is_finite()) {
        return None;
    }
    let ratio = r / r0;
    let disc = A * A - 4.0 * B * (1.0 - ratio);
    if !(disc >= 0.0) {
        return None;
    }
    let sq = crate::scalar::Real::sqrt(disc);
    // Root of the quadratic, in the cancellation-free form.
    let mut t = 2.0 * (ratio - 1.0) / (A + sq);
    if t < 0.0 {
        for _ in 0..3 {
            let f = 1.0 + A * t + B * t * t + C * (t - 100.0) * t * t * t - ratio;
            let df = A + 2.0 * B * t + C * (4.0 * t * t * t - 300.0 * t * t);
            t -= f / df;
        }
    }
    ((T_MIN - 0.5..=T_MAX + 0.5).contains(&t) && t.is_finite()).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_over_the_standard_range() {
        let mut t = -200.0f32;
        while t <= 850.0 {
            let back = temperature(100.0, resistance(100.0, t)).unwrap();
            assert!((back - t).abs() < 2e-3 * (1.0 + t.abs() / 100.0), "{t} -> {back}");
            t += 0.5;
        }
        // IEC 60751 table values for a PT100.
        assert!((resistance(100.0, 100.0) - 138.5055).abs() < 1e-3);
        assert!((resistance(100.0, -100.0) - 60.2558).abs() < 1e-3);
        assert_eq!(temperature(100.0, 0.0), None);
        assert_eq!(temperature(100.0, f32::NAN), None);
        assert_eq!(temperature(100.0, 1000.0), None);
    }
}
