//! The pressure ports against the independent reference solver driven by
//! the same port-pressure history: the FMU (FMI 3.0 interface, the f32
//! twin) between a supply and an outlet whose pressures change during the
//! run, each communication step's inputs the history's value at the step's
//! midpoint (held over the step), the reference (Radau5, `reference/`)
//! following the history exactly.

mod common;

use common::Inst;
use compensator::RawParams;
use compensator_fmu::variables::{VR_FIRST_OUTPUT, VR_P_OUTLET, VR_P_SUPPLY, VR_T_OIL};
use compensator_reference::dynamics::{Method, Ports, Profile, simulate_with};
use std::path::PathBuf;

/// A resources folder with the paper preset, one per run: the tests run
/// in parallel, and a copy over a file another instance is reading would
/// hand it a truncated file.
fn resources() -> PathBuf {
    static RUN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = RUN.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("fmu-pressure/{n}/resources"));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    std::fs::copy(root().join("presets/paper.toml"), dir.join("params.toml")).expect("params.toml");
    dir
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn paper() -> RawParams {
    compensator_params::file::load(&root().join("presets/paper.toml")).expect("preset")
}

/// A port history: `(p_supply, p_outlet)` [Pa] at time `t` [s], piecewise
/// linear through `points` `(t, p_supply, p_outlet)`, held outside.
fn at(points: &[(f64, f64, f64)], t: f64) -> (f64, f64) {
    let lerp = |a: &(f64, f64, f64), b: &(f64, f64, f64)| {
        let f = (t - a.0) / (b.0 - a.0);
        (a.1 + f * (b.1 - a.1), a.2 + f * (b.2 - a.2))
    };
    match points.iter().position(|p| p.0 > t) {
        Some(0) => (points[0].1, points[0].2),
        Some(k) => lerp(&points[k - 1], &points[k]),
        None => points.last().map(|p| (p.1, p.2)).expect("points"),
    }
}

/// Worst deviations of the FMU from the reference over a run: `x` in % of
/// the reference's displacement change, `p_a`, `p_b` in % of the design's
/// drop, `Q0` in % of the reference's largest `Q0`.
#[derive(Debug)]
struct Deviation {
    x_pct: f64,
    p_pct: f64,
    q_pct: f64,
    step: f64,
}

/// The FMU from rest at `from` C and the history's start, the oil at `to`
/// from t = 0, `duration` s in steps of `h`, against the reference.
fn run(from: f64, to: f64, points: &[(f64, f64, f64)], duration: f64, h: f64) -> Deviation {
    let raw = paper();
    let i = Inst::new(&resources());
    let (ps0, po0) = at(points, 0.0);
    i.set(VR_T_OIL, from);
    i.set(VR_P_SUPPLY, ps0);
    i.set(VR_P_OUTLET, po0);
    i.initialise();
    let n = (duration / h).round() as usize;
    let reference = simulate_with(
        &raw.core,
        Profile::Step { from, to },
        &Ports::Given(points.to_vec()),
        n as f64 * h,
        h,
        Method::Radau5,
        1e-10,
    )
    .expect("reference");
    assert_eq!(reference.time.len(), n + 1);
    let xs: Vec<f64> = reference.state.iter().map(|s| s[0]).collect();
    let step = xs.iter().copied().fold(f64::MIN, f64::max) - xs.iter().copied().fold(f64::MAX, f64::min);
    let q_max = reference.outflow.iter().copied().fold(0.0, f64::max);
    let dp = raw.core.pressure_drop;
    let mut d = Deviation {
        x_pct: 0.0,
        p_pct: 0.0,
        q_pct: 0.0,
        step,
    };
    for k in 0..n {
        let (ps, po) = at(points, (k as f64 + 0.5) * h);
        i.set(VR_T_OIL, to);
        i.set(VR_P_SUPPLY, ps);
        i.set(VR_P_OUTLET, po);
        i.step(k as f64 * h, h);
        let [x, _, pa, pb] = [0, 1, 2, 3].map(|o| i.get(VR_FIRST_OUTPUT + o));
        let q0 = i.get(VR_FIRST_OUTPUT + 7);
        let r = &reference.state[k + 1];
        d.x_pct = d.x_pct.max((x - r[0]).abs() / step * 100.0);
        d.p_pct = d.p_pct.max((pa - r[2]).abs().max((pb - r[3]).abs()) / dp * 100.0);
        d.q_pct = d.q_pct.max((q0 - reference.outflow[k + 1]).abs() / q_max * 100.0);
    }
    d
}

#[test]
fn a_temperature_step_with_a_supply_ramp_follows_the_reference() {
    // 30 -> 50 C at t = 0 with the supply ramped 3 -> 6 bar over 0.2 s
    // (the paper preset's design drop is 4 bar), the outlet at 0.
    let points = [(0.0, 3e5, 0.0), (0.2, 6e5, 0.0)];
    let d = run(30.0, 50.0, &points, 0.4, 1e-3);
    eprintln!("30 -> 50 C, supply 3 -> 6 bar, 1 ms steps: {d:?}");
    assert!(d.step > 1e-4, "the plunger moves: {d:?}");
    assert!(d.x_pct <= 0.5, "{d:?}");
    assert!(d.p_pct <= 0.5 && d.q_pct <= 0.5, "{d:?}");
}

#[test]
fn a_rising_outlet_and_a_supply_jump_follow_the_reference() {
    // The outlet ramps 0 -> 2 bar while the supply holds 6 bar, then the
    // supply drops to 5 bar at once (a graded tick): the drop goes 6 -> 4
    // -> 3 bar, at 70 C then 40 C, in 0.5 ms steps.
    let points = [
        (0.0, 6e5, 0.0),
        (0.15, 6e5, 2e5),
        (0.25, 6e5, 2e5),
        (0.25, 5e5, 2e5),
        (0.4, 5e5, 2e5),
    ];
    let d = run(70.0, 40.0, &points, 0.4, 5e-4);
    eprintln!("70 -> 40 C, outlet 0 -> 2 bar, supply 6 -> 5 bar, 0.5 ms steps: {d:?}");
    assert!(d.step > 1e-4, "the plunger moves: {d:?}");
    assert!(d.x_pct <= 0.5, "{d:?}");
    assert!(d.p_pct <= 0.5 && d.q_pct <= 0.5, "{d:?}");
}
