//! What a second sensor reads of the device, as a function of the health
//! parameters: the quasi-static divider algebra of `crate::equilibrium`
//! with the parameters applied, and its derivatives (the filter's
//! measurement Jacobian).
//!
//! With `a = A(t) / sqrt(dp)` of the design (`crate::equilibrium`), a
//! device whose redistribution parameter is `A e^theta_A` (a capillary
//! whose conductance fell by `e^-theta_A`, an orifice whose area grew by
//! `e^theta_A`: both enter `A = R_l / sqrt(R_t)` alike), whose spring rate
//! is `c e^theta_k` and whose reading is offset by `delta` reads, with
//! `a' = a e^theta_A`, `q = 2 / (a' + s)`, `s = sqrt(a'^2 + 4)`:
//!
//! ```text
//! p_a   = p_p - q^2 dp            dp_a/dtheta_A  =  2 q^2 dp a'/s
//! p_b   = p_c + q^2 dp            dp_b/dtheta_A  = -2 q^2 dp a'/s
//! dp_ab = (2 q^2 - 1) dp          d(dp_ab)/dtheta_A = -4 q^2 dp a'/s
//! x     = dp_ab (A_p/c) e^-theta_k - x0 + delta      (clamped to the stops)
//!         dx/dtheta_A = (A_p/c) e^-theta_k d(dp_ab)/dtheta_A
//!         dx/dtheta_k = -dp_ab (A_p/c) e^-theta_k,   dx/ddelta = 1
//! ```
//!
//! using `dq/da' = -q / s`. A stop that holds the plunger makes every
//! derivative of `x` zero: the reading then says nothing of the
//! parameters. The chamber pressures do not depend on `x`, the spring or
//! the preload at all: the chambers are dead-ended, their pressures set by
//! each branch's divider alone.

use crate::mathf::exp2;
use crate::scalar::Real;

/// What the second sensor measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Quantity {
    /// The pressure in chamber (a), `p_a` \[Pa\].
    ChamberA,
    /// The pressure in chamber (b), `p_b` \[Pa\].
    ChamberB,
    /// The chamber pressure difference `p_b - p_a` \[Pa\].
    Difference,
    /// The plunger displacement `x` \[m\].
    Displacement,
}

impl Quantity {
    /// The device file's name of the quantity (`monitor.sensor`).
    pub const fn name(self) -> &'static str {
        match self {
            Quantity::ChamberA => "p_a",
            Quantity::ChamberB => "p_b",
            Quantity::Difference => "dp_ab",
            Quantity::Displacement => "x",
        }
    }

    /// A pressure (not the displacement).
    pub const fn is_pressure(self) -> bool {
        !matches!(self, Quantity::Displacement)
    }
}

/// The health parameters' indices in the filter's state.
pub const DIVIDER: usize = 0;
/// Index of `theta_k`, the log of the spring rate's factor.
pub const SPRING: usize = 1;
/// Index of `delta`, the reading's offset \[Pa or m\] (the preload's loss,
/// for the displacement).
pub const OFFSET: usize = 2;
/// Index of `beta`, where the oil-temperature probe sits within its
/// tolerance (`-1..1`: its error is `beta (a + b |t|)`, IEC 60751); it does
/// not enter the second sensor's reading.
pub const PROBE: usize = 3;
/// Index of `m`, the twin's own error as an offset of the reading \[Pa or
/// m\] that wanders with the oil temperature (the reading's model error, a
/// state so that the filter does not take a systematic misfit for
/// evidence).
pub const MODEL: usize = 4;
/// Health parameters the filter estimates.
pub const PARAMETERS: usize = 5;

/// The design's constants a reading needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Design {
    /// What is measured.
    pub quantity: Quantity,
    /// Pressure drop `dp = p_p - p_c` \[Pa\].
    pub dp: f32,
    /// `sqrt(dp)` [sqrt(Pa)].
    pub sqrt_dp: f32,
    /// Outlet pressure `p_c` \[Pa\].
    pub p_c: f32,
    /// `A_p / c`: displacement per unit chamber pressure difference [m/Pa].
    pub compliance: f32,
    /// Preload `x0` \[m\].
    pub preload: f32,
    /// Stroke `x_max` \[m\].
    pub stroke: f32,
}

/// A reading and its derivatives in the health parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// The reading \[Pa or m\]; for the displacement the free one, before
    /// the stops.
    pub value: f32,
    /// `d value / d theta_i` (zero where the parameter does not enter).
    pub jacobian: [f32; PARAMETERS],
}

/// `e^x` in `f32` (`mathf::exp2`: native single precision).
#[inline]
pub fn exp(x: f32) -> f32 {
    exp2(x * core::f32::consts::LOG2_E)
}

impl Design {
    /// The reading of a device with health parameters `theta` whose
    /// oil gives the design the redistribution parameter `a` \[sqrt(Pa)\]
    /// (`crate::equilibrium::a_parameter`). For the displacement `value` is
    /// the free displacement (before the stops), its Jacobian that of the
    /// free displacement.
    pub fn reading(&self, a: f32, theta: &[f32; PARAMETERS]) -> Reading {
        let a_dev = a / self.sqrt_dp * exp(theta[DIVIDER]);
        let s = <f32 as Real>::sqrt(a_dev * a_dev + 4.0);
        let q = 2.0 / (a_dev + s);
        let q2dp = q * q * self.dp;
        // d(q^2 dp)/dtheta_A = 2 q dq/da' a' dp = -2 q^2 dp a'/s.
        let dq2dp = -2.0 * q2dp * a_dev / s;
        let mut jacobian = [0.0; PARAMETERS];
        jacobian[OFFSET] = 1.0;
        let value = match self.quantity {
            Quantity::ChamberA => {
                jacobian[DIVIDER] = -dq2dp;
                self.p_c + self.dp - q2dp
            }
            Quantity::ChamberB => {
                jacobian[DIVIDER] = dq2dp;
                self.p_c + q2dp
            }
            Quantity::Difference => {
                jacobian[DIVIDER] = 2.0 * dq2dp;
                2.0 * q2dp - self.dp
            }
            Quantity::Displacement => {
                let c = self.compliance * exp(-theta[SPRING]);
                let dp_ab = 2.0 * q2dp - self.dp;
                jacobian[DIVIDER] = c * 2.0 * dq2dp;
                jacobian[SPRING] = -dp_ab * c;
                dp_ab * c - self.preload
            }
        };
        jacobian[MODEL] = 1.0;
        Reading {
            value: value + theta[OFFSET] + theta[MODEL],
            jacobian,
        }
    }
}

/// The play (backlash) operator: a plunger held by Coulomb friction worth
/// `half_width` of displacement (`F / c`) stays where it is until the
/// frictionless position moves further than that from it, then is dragged
/// along at that distance. Exact for quasi-static motion (the force balance
/// `c (x_eq - x) = +-F` at the edges, `|c (x_eq - x)| < F` inside).
#[inline]
pub fn play(held: f32, target: f32, half_width: f32) -> f32 {
    crate::estimator::clamp(held, target - half_width, target + half_width)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn design(quantity: Quantity) -> Design {
        Design {
            quantity,
            dp: 4.0e5,
            sqrt_dp: 632.455_5,
            p_c: 1.0e5,
            compliance: 3.0e-9,
            preload: 1.0e-4,
            stroke: 1.5e-3,
        }
    }

    /// The Jacobian is the derivative of the reading (central differences
    /// in `f64` of the same algebra written out again).
    #[test]
    fn the_jacobian_is_the_reading_s_derivative() {
        let reference = |q: Quantity, a: f64, th: [f64; PARAMETERS]| -> f64 {
            let (dp, pc, c, x0) = (4.0e5, 1.0e5, 3.0e-9, 1.0e-4);
            let ad = a / dp.sqrt() * th[0].exp();
            let qq = 2.0 / (ad + (ad * ad + 4.0).sqrt());
            let (pa, pb) = (pc + dp - qq * qq * dp, pc + qq * qq * dp);
            th[2]
                + th[4]
                + match q {
                    Quantity::ChamberA => pa,
                    Quantity::ChamberB => pb,
                    Quantity::Difference => pb - pa,
                    Quantity::Displacement => (pb - pa) * c * (-th[1]).exp() - x0,
                }
        };
        for q in [
            Quantity::ChamberA,
            Quantity::ChamberB,
            Quantity::Difference,
            Quantity::Displacement,
        ] {
            for a in [100.0f32, 447.2, 2000.0] {
                for th in [[0.0f32, 0.0, 0.0, 0.0, 0.0], [0.2, -0.1, 0.0, 0.5, 0.0]] {
                    let r = design(q).reading(a, &th);
                    let th64 = th.map(f64::from);
                    let v = reference(q, f64::from(a), th64);
                    let scale = if q.is_pressure() { 4.0e5 } else { 1.5e-3 };
                    assert!((f64::from(r.value) - v).abs() < 1e-5 * scale, "{q:?} {a} {th:?}");
                    for i in 0..PARAMETERS {
                        let h = 1e-5;
                        let (mut up, mut down) = (th64, th64);
                        up[i] += h;
                        down[i] -= h;
                        let d = (reference(q, f64::from(a), up) - reference(q, f64::from(a), down)) / (2.0 * h);
                        let tol = 1e-4 * (d.abs() + scale);
                        assert!(
                            (f64::from(r.jacobian[i]) - d).abs() < tol,
                            "{q:?} {i} {}",
                            r.jacobian[i]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn play_holds_then_drags() {
        assert_eq!(play(1.0, 1.125, 0.25), 1.0);
        assert_eq!(play(1.0, 1.5, 0.25), 1.25);
        assert_eq!(play(1.0, 0.5, 0.25), 0.75);
        assert_eq!(play(1.0, 1.5, 0.0), 1.5);
    }
}
