//! Independent `f64` reference of the quasi-static equilibrium.
//!
//! Each chamber's pressure is the root of its flow balance, found by
//! bisection on `[p_c, p_p]` down to adjacent doubles: no closed form, no
//! `A(t)`, no shared code with the core beyond reading the same parameter
//! values.

use compensator_params::RawCore;
use std::f64::consts::PI;

/// Oil properties at `t` [C]: (kinematic viscosity [m^2/s], density [kg/m^3]).
pub fn oil(p: &RawCore, t: f64) -> (f64, f64) {
    let log_log = p.walther_a - p.walther_b * (t + 273.15).log10();
    let nu_cst = 10f64.powf(10f64.powf(log_log)) - 0.7;
    let rho = p.density_15 / (1.0 + p.expansion * (t - 15.0));
    (nu_cst * 1e-6, rho)
}

/// The reference operating point.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    /// Chamber pressures [Pa].
    pub p_a: f64,
    /// Chamber (b) [Pa].
    pub p_b: f64,
    /// Plunger displacement, clamped to the stops [m].
    pub x: f64,
    /// Flow through chamber (a)'s branch [m^3/s].
    pub q_a: f64,
    /// Flow through chamber (b)'s branch [m^3/s].
    pub q_b: f64,
    /// Flow through the window [m^3/s].
    pub q_throt: f64,
    /// Total flow [m^3/s].
    pub q_total: f64,
}

/// Root of a decreasing function on `[lo, hi]` by bisection to adjacent doubles.
pub fn bisect_decreasing(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(f(lo) >= 0.0 && f(hi) <= 0.0, "not bracketed");
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return mid;
        }
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

/// Flow through the window opened by `x` [m] at `t` [C] (Eq. 7) [m^3/s].
pub fn window_flow(p: &RawCore, t: f64, x: f64) -> f64 {
    let (_, rho) = oil(p, t);
    p.slot_discharge * PI * p.slot_diameter * x * (2.0 * p.pressure_drop / rho).sqrt()
}

/// The equilibrium at `t` [C] by root finding on each chamber.
pub fn equilibrium(p: &RawCore, t: f64) -> Point {
    let (nu, rho) = oil(p, t);
    let mu = nu * rho;
    let r_lam = 128.0 * mu * p.laminar_length / (PI * p.laminar_diameter.powi(4));
    let orifice =
        |dp: f64| p.turbulent_discharge * PI * p.turbulent_diameter.powi(2) / 4.0 * (2.0 * dp.max(0.0) / rho).sqrt();
    let (pc, pp) = (p.outlet_pressure, p.outlet_pressure + p.pressure_drop);
    // (a): orifice in from p_p, capillary out to p_c.
    let p_a = bisect_decreasing(|pa| orifice(pp - pa) - (pa - pc) / r_lam, pc, pp);
    // (b): capillary in from p_p, orifice out to p_c.
    let p_b = bisect_decreasing(|pb| (pp - pb) / r_lam - orifice(pb - pc), pc, pp);
    let area = PI * p.plunger_diameter.powi(2) / 4.0;
    let x = ((p_b - p_a) * area / p.spring_rate - p.preload).clamp(0.0, p.stroke);
    let q_a = (p_a - pc) / r_lam;
    let q_b = (pp - p_b) / r_lam;
    let q_throt = window_flow(p, t, x);
    Point {
        p_a,
        p_b,
        x,
        q_a,
        q_b,
        q_throt,
        q_total: q_a + q_b + q_throt,
    }
}
