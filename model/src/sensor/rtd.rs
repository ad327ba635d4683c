//! Platinum resistance thermometers (IEC 60751, Callendar-Van Dusen):
//!
//! ```text
//! R(t) = R0 (1 + A t + B t^2)                  t >= 0 C
//! R(t) = R0 (1 + A t + B t^2 + C (t - 100) t^3)  t < 0 C
//! IEC 60751: A = 3.9083e-3, B = -5.775e-7, C = -4.183e-12
//! ```
//!
//! [`Cvd`] holds the three coefficients: [`Cvd::IEC_60751`] for a standard
//! element, or a calibrated probe's own (the parameter file's
//! `estimator.rtd_a`, `rtd_b`, `rtd_c`). [`Cvd::temperature`] inverts the
//! curve: the quadratic's closed form above 0 C, and below it that root
//! refined by three Newton steps on the quartic (fixed cost; 1e-4 C over
//! -200..0 C). Cost (f32, Cortex-M4F): ~40 instructions, one square root.
//! The free functions [`resistance`] and [`temperature`] use IEC 60751.

/// Callendar-Van Dusen `A` of IEC 60751 [1/C].
pub const A: f32 = 3.9083e-3;
/// Callendar-Van Dusen `B` of IEC 60751 [1/C^2].
pub const B: f32 = -5.775e-7;
/// Callendar-Van Dusen `C` of IEC 60751 [1/C^4] (below 0 C only).
pub const C: f32 = -4.183e-12;
/// Lowest temperature of the IEC 60751 range [C].
pub const T_MIN: f32 = -200.0;
/// Highest temperature of the IEC 60751 range [C].
pub const T_MAX: f32 = 850.0;

/// Callendar-Van Dusen coefficients of one element.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cvd {
    /// `A` [1/C].
    pub a: f32,
    /// `B` [1/C^2].
    pub b: f32,
    /// `C` [1/C^4], used below 0 C only.
    pub c: f32,
}

impl Cvd {
    /// The standard curve of IEC 60751 (alpha = 0.00385).
    pub const IEC_60751: Cvd = Cvd { a: A, b: B, c: C };

    /// Resistance \[ohm\] of an element with `r0` \[ohm\] at 0 C, at `t` [C].
    pub fn resistance(&self, r0: f32, t: f32) -> f32 {
        let mut r = 1.0 + self.a * t + self.b * t * t;
        if t < 0.0 {
            r += self.c * (t - 100.0) * t * t * t;
        }
        r0 * r
    }

    /// Temperature [C] of an element with `r0` \[ohm\] at 0 C reading `r`
    /// \[ohm\]; `None` outside the IEC 60751 range (-200..850 C), where the
    /// curve has no root, or for a non-finite or non-positive resistance.
    pub fn temperature(&self, r0: f32, r: f32) -> Option<f32> {
        if !(r > 0.0 && r.is_finite() && r0 > 0.0 && r0.is_finite()) {
            return None;
        }
        let (a, b, c) = (self.a, self.b, self.c);
        let ratio = r / r0;
        let disc = a * a - 4.0 * b * (1.0 - ratio);
        if !(disc >= 0.0) {
            return None;
        }
        let sq = crate::scalar::Real::sqrt(disc);
        // Root of the quadratic, in the cancellation-free form.
        let mut t = 2.0 * (ratio - 1.0) / (a + sq);
        if t < 0.0 {
            for _ in 0..3 {
                let f = 1.0 + a * t + b * t * t + c * (t - 100.0) * t * t * t - ratio;
                let df = a + 2.0 * b * t + c * (4.0 * t * t * t - 300.0 * t * t);
                t -= f / df;
            }
        }
        ((T_MIN - 0.5..=T_MAX + 0.5).contains(&t) && t.is_finite()).then_some(t)
    }

    /// `dR/dt` [ohm/C] at `t` [C] of an element with `r0` \[ohm\] at 0 C.
    pub fn slope(&self, r0: f32, t: f32) -> f32 {
        let mut d = self.a + 2.0 * self.b * t;
        if t < 0.0 {
            d += self.c * (4.0 * t * t * t - 300.0 * t * t);
        }
        r0 * d
    }
}

/// Resistance \[ohm\] of an IEC 60751 RTD with `r0` \[ohm\] at 0 C, at `t` [C].
pub fn resistance(r0: f32, t: f32) -> f32 {
    Cvd::IEC_60751.resistance(r0, t)
}

/// Temperature [C] of an IEC 60751 RTD with `r0` \[ohm\] at 0 C reading `r`
/// \[ohm\] (see [`Cvd::temperature`]).
pub fn temperature(r0: f32, r: f32) -> Option<f32> {
    Cvd::IEC_60751.temperature(r0, r)
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

    #[test]
    fn a_calibrated_curve_round_trips_and_differs_from_the_standard_one() {
        // A probe 0.1 % steeper than the standard: alpha 0.003854 instead of
        // 0.003850 (the coefficients scaled by hand).
        let cal = Cvd {
            a: 3.9122e-3,
            b: -5.781e-7,
            c: -4.187e-12,
        };
        for t in [-150.0f32, -20.0, 0.0, 40.0, 80.0, 300.0] {
            let r = cal.resistance(100.0, t);
            let back = cal.temperature(100.0, r).unwrap();
            assert!((back - t).abs() < 2e-3 * (1.0 + t.abs() / 100.0), "{t} -> {back}");
        }
        // At 100 C the calibrated element reads 138.5439 ohm (worked by
        // hand: 100 (1 + 0.39122 - 0.005781)); read with the standard curve
        // it would be taken for 100.1 C.
        assert!((cal.resistance(100.0, 100.0) - 138.5439).abs() < 1e-3);
        let standard = temperature(100.0, cal.resistance(100.0, 100.0)).unwrap();
        assert!((standard - 100.1).abs() < 0.01, "{standard}");
        // The slope is dR/dt: a finite difference of the curve.
        let (t, h) = (60.0f32, 0.5f32);
        let fd = (cal.resistance(100.0, t + h) - cal.resistance(100.0, t - h)) / (2.0 * h);
        assert!(
            (cal.slope(100.0, t) - fd).abs() < 1e-4,
            "{} vs {fd}",
            cal.slope(100.0, t)
        );
    }
}
