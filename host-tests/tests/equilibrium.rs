//! The core's closed-form equilibrium against the independent root-finding
//! reference, on 1,000 random physical parameter sets, in `f64` and `f32`.

use compensator::Params;
use compensator::equilibrium::{Stop, equilibrium};
use host_tests::random::{Rng, physical_params};
use host_tests::{isclose, reference};

const SETS: usize = 1000;
const TEMPS_PER_SET: usize = 8;

#[test]
fn f64_path_agrees_with_root_finding_to_1e_12() {
    let mut rng = Rng::new(0xC0FFEE);
    let mut interior = 0;
    for set in 0..SETS {
        let raw = physical_params(&mut rng);
        let p = Params::<f64>::new(&raw).unwrap();
        let (dp, stroke) = (raw.core.pressure_drop, raw.core.stroke);
        for _ in 0..TEMPS_PER_SET {
            let t = rng.uniform(20.0, 90.0);
            let r = reference::equilibrium(&raw.core, t);
            let e = equilibrium(&p, t).unwrap_or_else(|err| panic!("set {set}, t {t}: {err}"));
            let ctx = || format!("set {set}, t = {t} C");
            // 1e-12 relative to the quantity, with the device's scale (dp,
            // stroke, flow) as the floor for values near zero.
            assert!(
                isclose(e.p_a, r.p_a, 1e-12, 1e-12 * dp),
                "p_a {} vs {} ({})",
                e.p_a,
                r.p_a,
                ctx()
            );
            assert!(
                isclose(e.p_b, r.p_b, 1e-12, 1e-12 * dp),
                "p_b {} vs {} ({})",
                e.p_b,
                r.p_b,
                ctx()
            );
            assert!(isclose(e.dp_ab, r.p_b - r.p_a, 1e-12, 1e-12 * dp), "dp_ab ({})", ctx());
            assert!(
                isclose(e.x, r.x, 1e-12, 1e-12 * stroke),
                "x {} vs {} ({})",
                e.x,
                r.x,
                ctx()
            );
            assert!(
                isclose(e.q_branch, r.q_a, 1e-12, 0.0),
                "Q_a {} vs {} ({})",
                e.q_branch,
                r.q_a,
                ctx()
            );
            assert!(
                isclose(e.q_branch, r.q_b, 1e-12, 0.0),
                "Q_b {} vs {} ({})",
                e.q_branch,
                r.q_b,
                ctx()
            );
            let full_window = reference::window_flow(&raw.core, t, stroke);
            assert!(
                isclose(e.q_throt, r.q_throt, 1e-12, 1e-12 * full_window),
                "Q_throt ({})",
                ctx()
            );
            assert!(
                isclose(e.q_total, r.q_total, 1e-12, 1e-12 * full_window),
                "Q0 ({})",
                ctx()
            );
            if e.stop == Stop::Free {
                interior += 1;
            }
        }
    }
    // The random sets must exercise the interior branch, not only the stops.
    assert!(interior > SETS * TEMPS_PER_SET / 10, "only {interior} interior points");
}

#[test]
fn f32_path_agrees_to_1e_5_of_stroke_and_drop() {
    let mut rng = Rng::new(0xBADC0DE);
    let mut worst_x = 0.0f64;
    let mut worst_p = 0.0f64;
    for set in 0..SETS {
        let raw = physical_params(&mut rng);
        let p = Params::<f32>::new(&raw).unwrap();
        let (dp, stroke) = (raw.core.pressure_drop, raw.core.stroke);
        for _ in 0..TEMPS_PER_SET {
            // The reference is evaluated at the temperature the f32 path
            // sees (the input rounded to f32).
            let t = rng.uniform(20.0, 90.0) as f32 as f64;
            let r = reference::equilibrium(&raw.core, t);
            let e = equilibrium(&p, t as f32).unwrap_or_else(|err| panic!("set {set}, t {t}: {err}"));
            let ex = (e.x as f64 - r.x).abs() / stroke;
            let ep = ((e.p_a as f64 - r.p_a).abs()).max((e.p_b as f64 - r.p_b).abs()) / dp;
            worst_x = worst_x.max(ex);
            worst_p = worst_p.max(ep);
            assert!(ex <= 1e-5, "x off by {ex:.2e} of the stroke (set {set}, t {t})");
            assert!(ep <= 1e-5, "pressure off by {ep:.2e} of dp (set {set}, t {t})");
            // Flows inherit the displacement's error through the window:
            // 1e-5 of the flow plus 1e-5 of the fully open window's flow.
            let full_window = reference::window_flow(&raw.core, t, stroke);
            assert!(
                isclose(e.q_total as f64, r.q_total, 1e-5, 1e-5 * full_window),
                "Q0 {} vs {} (set {set}, t {t})",
                e.q_total,
                r.q_total
            );
        }
    }
    eprintln!("f32 worst: x {worst_x:.2e} of stroke, pressures {worst_p:.2e} of dp");
}

#[test]
fn stops_hold_the_plunger() {
    // A stiff spring with a large preload keeps the window closed; a soft
    // spring without preload drives the plunger to the far stop when hot.
    let mut rng = Rng::new(7);
    let mut raw = physical_params(&mut rng);
    raw.core.preload = raw.core.stroke;
    let p = Params::<f64>::new(&raw).unwrap();
    let cold = equilibrium(&p, 25.0).unwrap();
    assert_eq!((cold.x, cold.stop), (0.0, Stop::Closed));
    assert_eq!(cold.q_throt, 0.0);
    raw.core.preload = 0.0;
    raw.core.spring_rate = 1.0;
    let p = Params::<f64>::new(&raw).unwrap();
    let hot = equilibrium(&p, 90.0).unwrap();
    assert_eq!((hot.x, hot.stop), (raw.core.stroke, Stop::Open));
}
