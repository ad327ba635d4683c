//! The invariants every target checks on what the core accepts.
//!
//! * finite: every number the core returns as a result;
//! * the stroke: `0 <= x <= x_max`, exactly (the twin clamps to its stops,
//!   the closed form clamps to them);
//! * the pressures: the closed form within `[p_c, p_p]` (up to the
//!   rounding of `p_c + dp` in the scalar type); the twin within
//!   [`PRESSURE_MARGIN`] `dp` of `[p_c, p_p]`, its divergence guard: a
//!   state beyond it must be refused by `Twin::tick` with an error, never
//!   returned;
//! * at rest (the temperature held for long enough): the closed-form
//!   equilibrium within [`AT_REST`] of the stroke and of `dp`.

use compensator::dynamics::twin::PRESSURE_MARGIN;
use compensator::dynamics::{DynamicState, Twin};
use compensator::equilibrium::{Equilibrium, Stop};
use compensator::{Float, Params, Real};

/// Agreement at rest with the closed form, as a fraction of the stroke
/// (displacement) and of `dp` (each chamber pressure): the twin's goal in
/// every precision (docs/dynamics.md, fixed point included).
pub const AT_REST: f64 = 1e-3;

/// Relative rounding allowed on `p_c + dp`-sized sums in scalar `F`
/// (eight units in the last place).
pub fn rounding<F: Real>() -> f64 {
    if F::NAME == "f32" {
        8.0 * f64::from(f32::EPSILON)
    } else {
        8.0 * f64::EPSILON
    }
}

/// `p` within `[lo - margin dp, hi + margin dp]`, with the rounding of `F`
/// on `|p_c| + dp`.
fn pressure_within<F: Float>(p: &Params<F>, value: f64, margin: f64) -> bool {
    let (pc, dp) = (p.outlet_pressure.to_f64(), p.pressure_drop.to_f64());
    let slack = rounding::<F>() * (pc.abs() + dp);
    value >= pc - margin * dp - slack && value <= pc + dp + margin * dp + slack
}

/// The closed-form equilibrium's promises.
pub fn equilibrium<F: Float>(p: &Params<F>, e: &Equilibrium<F>, what: &dyn Fn() -> String) {
    let values = [
        ("a", e.a),
        ("p_a", e.p_a),
        ("p_b", e.p_b),
        ("dp_ab", e.dp_ab),
        ("x", e.x),
        ("x_free", e.x_free),
        ("q_branch", e.q_branch),
        ("q_throt", e.q_throt),
        ("q_total", e.q_total),
        ("density", e.fluid.density),
        ("kinematic viscosity", e.fluid.kinematic_viscosity),
        ("dynamic viscosity", e.fluid.dynamic_viscosity),
    ];
    for (name, v) in values {
        assert!(
            v.is_finite(),
            "{}: equilibrium {name} = {v:?} is not finite: {e:?}",
            what()
        );
    }
    let stroke = p.plunger.stroke;
    assert!(
        e.x >= F::ZERO && e.x <= stroke,
        "{}: equilibrium x = {:?} outside [0, {:?}]",
        what(),
        e.x,
        stroke
    );
    let stop_ok = match e.stop {
        Stop::Closed => e.x == F::ZERO && e.x_free <= F::ZERO,
        Stop::Open => e.x == stroke && e.x_free >= stroke,
        Stop::Free => e.x == e.x_free && e.x > F::ZERO && e.x < stroke,
    };
    assert!(
        stop_ok,
        "{}: stop {:?} with x = {:?}, x_free = {:?}",
        what(),
        e.stop,
        e.x,
        e.x_free
    );
    for (name, v) in [("p_a", e.p_a), ("p_b", e.p_b)] {
        assert!(
            pressure_within(p, v.to_f64(), 0.0),
            "{}: equilibrium {name} = {v:?} outside [p_c, p_p] = [{:?}, {:?}]",
            what(),
            p.outlet_pressure,
            p.inlet_pressure()
        );
    }
    assert!(
        e.q_branch >= F::ZERO && e.q_throt >= F::ZERO && e.q_total >= F::ZERO,
        "{}: flows q_branch {:?}, q_throt {:?}, q_total {:?}",
        what(),
        e.q_branch,
        e.q_throt,
        e.q_total
    );
}

/// A twin's state: finite, on or between the stops, pressures within the
/// divergence guard, in model units (exact) and in SI.
pub fn twin_state<F: Float, T: Real>(twin: &Twin<F, T>, p: &Params<F>, what: &dyn Fn() -> String) {
    let y = twin.raw_state();
    assert!(y.iter().all(|v| v.is_finite()), "{}: state {y:?} not finite", what());
    let [xi, _, pi_a, pi_b] = y.map(Real::to_f64);
    assert!((0.0..=1.0).contains(&xi), "{}: xi = {xi} outside [0, 1]", what());
    for (name, pi) in [("pi_a", pi_a), ("pi_b", pi_b)] {
        assert!(
            (-PRESSURE_MARGIN..=1.0 + PRESSURE_MARGIN).contains(&pi),
            "{}: {name} = {pi} beyond the divergence guard [-{PRESSURE_MARGIN}, 1 + {PRESSURE_MARGIN}]",
            what()
        );
    }
    si_state(&twin.state(), p, PRESSURE_MARGIN, what);
}

/// An SI state `s`: finite, `0 <= x <= stroke`, pressures within `margin`
/// `dp` of `[p_c, p_p]`.
pub fn si_state<F: Float>(s: &DynamicState<F>, p: &Params<F>, margin: f64, what: &dyn Fn() -> String) {
    let values = [s.x, s.v, s.p_a, s.p_b];
    assert!(
        values.iter().all(|v| v.is_finite()),
        "{}: SI state {s:?} not finite",
        what()
    );
    assert!(
        s.x >= F::ZERO && s.x <= p.plunger.stroke,
        "{}: x = {:?} outside [0, {:?}]",
        what(),
        s.x,
        p.plunger.stroke
    );
    for (name, v) in [("p_a", s.p_a), ("p_b", s.p_b)] {
        assert!(
            pressure_within(p, v.to_f64(), margin),
            "{}: {name} = {v:?} more than {margin} dp outside [p_c, p_p] = [{:?}, {:?}]",
            what(),
            p.outlet_pressure,
            p.inlet_pressure()
        );
    }
}

/// The largest deviation of `s` from the closed form `e`: displacement in
/// strokes, pressures in `dp`.
pub fn off_rest<F: Float>(s: &DynamicState<F>, e: &Equilibrium<F>, p: &Params<F>) -> f64 {
    let (stroke, dp) = (p.plunger.stroke.to_f64(), p.pressure_drop.to_f64());
    let dx = (s.x.to_f64() - e.x.to_f64()).abs() / stroke;
    let da = (s.p_a.to_f64() - e.p_a.to_f64()).abs() / dp;
    let db = (s.p_b.to_f64() - e.p_b.to_f64()).abs() / dp;
    // NaN compares false: a NaN state is infinitely far.
    if dx.is_nan() || da.is_nan() || db.is_nan() {
        f64::INFINITY
    } else {
        dx.max(da).max(db)
    }
}
