//! The estimator's behaviour: it follows the twin and the closed form at
//! rest, rejects spikes, and turns every bad sample into a flag, never a
//! NaN.
//!
//! Most tests here drive the estimator with readings that are the oil's
//! temperature itself (steps, ramps): their subject is the twin and its
//! consistency check, so the device file's probe is made one without lag
//! ([`direct`]: 10 ms). The observer's own tests, through a probe that lags,
//! are in `model/src/estimator/observer.rs` and `tests/probe.rs`.

use compensator::Params;
use compensator::dynamics::{Twin, TwinConfig};
use compensator::equilibrium::equilibrium;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, StateEstimate};
use compensator::params::RawParams;
use compensator::sensor::SensorFault;
use host_tests::repo_root;

/// `raw` with a probe that does not lag (10 ms, read every 20 ms): the
/// readings are the oil's temperature.
fn direct(mut raw: RawParams) -> RawParams {
    raw.probe.time_constant = 0.01;
    raw.probe.well_time_constant = 0.0;
    raw
}

fn setup(initial: f32) -> (Params<f32>, EstimatorConfig, Estimator) {
    let raw = direct(compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap());
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let est = Estimator::new(&p, cfg, initial).unwrap();
    (p, cfg, est)
}

fn run(est: &mut Estimator, ticks: usize, sample: Result<Option<f32>, SensorFault>) -> StateEstimate {
    let mut last = None;
    for k in 0..ticks {
        let s = if k.is_multiple_of(20) { sample } else { Ok(None) };
        last = Some(est.tick(s));
    }
    last.unwrap()
}

#[test]
fn at_rest_the_estimate_is_the_equilibrium() {
    let (p, _, mut est) = setup(55.0);
    let e = run(&mut est, 2000, Ok(Some(55.0)));
    let eq = equilibrium(&p, 55.0).unwrap();
    assert!((e.x - eq.x).abs() <= 1e-6 * p.plunger.stroke, "{} vs {}", e.x, eq.x);
    assert!((e.p_a - eq.p_a).abs() <= 1e-5 * p.pressure_drop);
    assert!(
        (e.q_total - eq.q_total).abs() <= 1e-4 * eq.q_total,
        "{} vs {}",
        e.q_total,
        eq.q_total
    );
    assert!((e.x_equilibrium - eq.x).abs() <= 1e-6 * p.plunger.stroke);
    assert!(e.dx_dt > 0.0);
    assert_eq!(e.flags, Flags::empty());
    // The preset's [machine]: the error is the closed form's Q0 - demand.
    let c = compensator::compensation::compensation(&p, 55.0).unwrap();
    assert!(
        (e.compensation_error - c.error).abs() <= 1e-4 * c.demand,
        "{} vs {}",
        e.compensation_error,
        c.error
    );
}

#[test]
fn the_estimate_follows_the_twin_driven_directly() {
    // A 2 C/s ramp read directly: the twin of the estimator, driven by the
    // observer's oil temperature, against a twin driven by the oil's.
    let (p, _, mut est) = setup(40.0);
    let mut twin = Twin::<f32, f32>::new(&p, TwinConfig::SHIPPED, 40.0).unwrap();
    let mut worst = 0.0f32;
    for k in 0..5000u32 {
        let t = 40.0 + 2.0 * (k as f32 * 1e-3);
        let e = est.tick(if k.is_multiple_of(20) { Ok(Some(t)) } else { Ok(None) });
        twin.set_temperature(t).unwrap();
        twin.tick().unwrap();
        if k > 2000 {
            worst = worst.max((e.x - twin.state().x).abs());
        }
    }
    // The ramp is followed without lag (the observer's rate); what is left
    // is the readings' hold between samples (0.04 C) and the 5 ms refresh
    // of the fluid properties: within 0.05 C of temperature, 2 um at
    // 37 um/K.
    assert!(worst < 2e-6, "estimator and twin differ by {worst} m");
}

#[test]
fn the_estimate_carries_the_reading_and_its_uncertainty() {
    let (_, cfg, mut est) = setup(50.0);
    let e = run(&mut est, 2000, Ok(Some(50.5)));
    assert_eq!(e.t_probe, 50.5);
    assert!((e.temperature - 50.5).abs() < 1e-3, "{}", e.temperature);
    // Class B at 50.5 C: (0.3 + 0.005 * 50.5) / sqrt(3) = 0.319 C, the
    // dominant term; the observer and the quantization add little.
    let u = e.uncertainty;
    assert!(u.t_oil > 0.3185 && u.t_oil < 0.33, "{u:?}");
    // The preset declares no tolerances: the displacement's uncertainty is
    // the temperature's through dx/dt, here Eq. (31)'s from the
    // Equilibrium job (the table's slope is a difference quotient of the
    // f64 closed form, interpolated between the table's 17 temperatures:
    // within 3 %, docs/firmware.md).
    let through = e.dx_dt.abs() * u.t_oil;
    assert!((u.x / through - 1.0).abs() < 0.03, "{u:?}: {} m/K", e.dx_dt);
    assert!(u.p_a > 0.0 && u.p_b > 0.0 && u.q_total > 0.0, "{u:?}");
    let _ = cfg;
}

#[test]
fn spikes_are_rejected_until_enough_samples_agree() {
    let (_, _, mut est) = setup(50.0);
    run(&mut est, 100, Ok(Some(50.0)));
    let e = est.tick(Ok(Some(90.0)));
    assert!(e.flags.contains(Flags::SPIKE));
    assert!((e.temperature - 50.0).abs() < 1e-3);
    // Five consecutive samples (the default spike_limit) agree: a real step.
    for _ in 0..5 {
        assert!(est.tick(Ok(Some(70.0))).flags.contains(Flags::SPIKE));
    }
    let e = est.tick(Ok(Some(70.0)));
    assert!(!e.flags.contains(Flags::SPIKE));
    assert!(
        (e.temperature - 70.0).abs() < 1e-3,
        "filter reset to the new level: {}",
        e.temperature
    );
}

#[test]
fn bad_samples_are_flags_and_never_numbers() {
    let (_, cfg, mut est) = setup(45.0);
    let garbage = [
        Err(SensorFault::Bus),
        Err(SensorFault::OpenCircuit(compensator::sensor::Detail::max31865_status(
            0x80,
        ))),
        Ok(Some(f32::NAN)),
        Ok(Some(f32::INFINITY)),
        Ok(Some(-1e30)),
        Ok(Some(400.0)),
    ];
    for s in garbage {
        let e = est.tick(s);
        assert!(e.flags.contains(Flags::SENSOR_FAULT), "{s:?}");
        assert!(e.is_finite(), "{s:?}: {e:?}");
    }
    // Half a second without a usable sample: degraded, then recovered.
    let e = run(&mut est, cfg.stale_after as usize + 10, Err(SensorFault::Bus));
    assert!(e.flags.contains(Flags::DEGRADED) && e.is_finite());
    let e = run(&mut est, 40, Ok(Some(45.0)));
    assert!(!e.flags.contains(Flags::DEGRADED));
}

#[test]
fn range_and_stop_flags() {
    let (_, _, mut est) = setup(28.0);
    let e = run(&mut est, 200, Ok(Some(28.0)));
    assert!(e.flags.contains(Flags::AT_STOP));
    assert_eq!(e.x, 0.0);
    let (_, _, mut est) = setup(85.0);
    let e = run(&mut est, 200, Ok(Some(85.0)));
    assert!(e.flags.contains(Flags::OUT_OF_RANGE));
    assert!(!e.flags.contains(Flags::NOT_UNIQUE) && !e.flags.contains(Flags::UNSTABLE));
}

#[test]
fn a_temperature_the_oil_model_refuses_degrades_without_nan() {
    // 140 C is inside the default oil range but this light oil is below
    // 2 cSt there (Walther's validity): the model refuses it.
    let (p, _, mut est) = setup(70.0);
    assert!(p.oil.state(140.0f32).is_err());
    let mut e = est.tick(Ok(Some(70.0)));
    for _ in 0..6 {
        e = est.tick(Ok(Some(140.0)));
    }
    let e2 = run(&mut est, 500, Ok(Some(140.0)));
    assert!(e2.flags.contains(Flags::DEGRADED), "{:?}", e2.flags);
    assert!(e2.is_finite() && e.is_finite());
}

#[test]
fn the_twin_steps_at_the_configured_tick() {
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    let mut raw = raw;
    raw.estimator.tick_hz = 250.0;
    let cfg = EstimatorConfig::new(&raw).unwrap();
    assert_eq!(cfg.tick(), 0.004);
    assert_eq!(cfg.ticks_per(0.02), 5);
    let est = Estimator::new(&p, cfg, 40.0).unwrap();
    assert_eq!(est.twin().config().tick, 0.004);
    assert_eq!(est.twin().config().scheme, TwinConfig::SHIPPED.scheme);
}

#[test]
fn telemetry_cadence_follows_the_configuration() {
    let (_, cfg, mut est) = setup(50.0);
    let mut due = 0;
    for _ in 0..(cfg.telemetry_every * 10) {
        est.tick(Ok(None));
        due += usize::from(est.telemetry_due());
    }
    assert_eq!(due, 10);
}

// ---------------------------------------------------------------------
// The consistency check (TWIN_RESEATED): a settled twin must sit on the
// closed-form equilibrium, here judged by the independent f64 reference.

use compensator::dynamics::fsi::{DynamicState, Model};
use compensator::dynamics::linear::jacobian_at_equilibrium;
use compensator::estimator::{P_TOLERANCE, X_TOLERANCE, slowest_decay_rate};
use host_tests::random::{Rng, physical_params};
use host_tests::reference;

fn paper_raw() -> RawParams {
    direct(compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap())
}

fn estimator_for(raw: &RawParams, initial: f32) -> Estimator {
    let raw = &direct(*raw);
    let p = Params::<f32>::new(raw).unwrap();
    let cfg = EstimatorConfig::new(raw).unwrap();
    Estimator::new(&p, cfg, initial).unwrap()
}

/// Distance of a state from the reference equilibrium at `t` [C]: (x in
/// strokes, the larger pressure error in `dp`).
fn off_reference(raw: &RawParams, t: f32, x: f32, p_a: f32, p_b: f32) -> (f64, f64) {
    let r = reference::equilibrium(&raw.core, f64::from(t));
    let c = &raw.core;
    let dx = (f64::from(x) - r.x).abs() / c.stroke;
    let dp = (f64::from(p_a) - r.p_a).abs().max((f64::from(p_b) - r.p_b).abs()) / c.pressure_drop;
    (dx, dp)
}

/// A state far from the equilibrium at `t`: the plunger at the stop
/// farther from it, the chamber pressures swapped.
fn wrong_state(raw: &RawParams, t: f32) -> DynamicState<f32> {
    let r = reference::equilibrium(&raw.core, f64::from(t));
    let c = &raw.core;
    let x = if r.x > 0.5 * c.stroke { 0.0 } else { c.stroke };
    DynamicState {
        x: x as f32,
        v: 0.0,
        p_a: r.p_b as f32,
        p_b: r.p_a as f32,
    }
}

#[test]
fn the_slowest_decay_rate_is_bounded_within_a_quarter() {
    // Polynomials with known roots, [a3, a2, a1, a0].
    // (s + 1)(s + 2)(s^2 + 2 s + 5): slowest rate 1 (real and complex).
    let cases: [([f32; 4], f32); 3] = [
        ([5.0, 13.0, 19.0, 10.0], 1.0),
        // (s^2 + 0.2 s + 1)(s + 10)(s + 100): an underdamped pair, rate 0.1.
        ([110.2, 1023.0, 310.0, 1000.0], 0.1),
        // (s + 1e-3)(s + 1)(s + 1e3)(s + 1e4): stiff, rate 1e-3.
        ([11001.001, 10_011_011.0, 10_010_011.0, 1.0e4], 1e-3),
    ];
    for (poly, rate) in cases {
        // Without a hint, and with hints right, too high, too low, absurd:
        // the same guarantee.
        for hint in [0.0, 0.9 * rate, 2.0 * rate, 0.3 * rate, 1e30, -1.0, f32::NAN] {
            let got = slowest_decay_rate(&poly, hint);
            assert!(
                got <= rate * 1.0001 && got >= 0.75 * rate,
                "{poly:?}, hint {hint}: {got} vs {rate}"
            );
        }
        // A hint within the answer's precision is kept.
        assert_eq!(slowest_decay_rate(&poly, 0.9 * rate), 0.9 * rate);
    }
    // Not Hurwitz: (s - 1)(s + 1)(s + 2)(s + 3) = s^4 + 5 s^3 + 5 s^2 - 5 s - 6.
    for hint in [0.0, 0.5, 1.0] {
        assert_eq!(slowest_decay_rate(&[5.0, 5.0, -5.0, -6.0], hint), 0.0);
    }
}

#[test]
fn the_settling_window_follows_the_slowest_eigenvalue() {
    // The estimator's time constant against nalgebra's eigenvalues of the
    // f64 Jacobian at the same equilibrium: never shorter than the slowest
    // mode's (a conservative window), at most a third longer.
    let mut rng = Rng::new(71);
    let mut designs = vec![paper_raw()];
    for _ in 0..20 {
        designs.push(physical_params(&mut rng));
    }
    let mut checked = 0;
    for raw in &designs {
        let p64 = Params::<f64>::new(raw).unwrap();
        let model = Model::new(&p64).unwrap();
        for t in [-10.0, 10.0, 30.0, 55.0, 80.0] {
            let est = estimator_for(raw, t as f32);
            let j = jacobian_at_equilibrium(&model, t).unwrap();
            let na = nalgebra::Matrix4::from_fn(|i, k| j[i][k]).complex_eigenvalues();
            let slowest = na.iter().map(|c| -c.re).fold(f64::INFINITY, f64::min);
            if slowest <= 0.0 {
                assert_eq!(est.settle_ticks(), u32::MAX, "unstable: no check");
                continue;
            }
            let tau_true = model.scales.time / slowest;
            let tau = f64::from(est.slowest_time_constant());
            assert!(
                tau >= tau_true * (1.0 - 1e-4) && tau <= 1.34 * tau_true,
                "t = {t}: {tau} s vs {tau_true} s"
            );
            let ticks = tau * 10.0 / f64::from(est.config().tick());
            assert!(f64::from(est.settle_ticks()) >= ticks.min(16.0));
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked} stable points");
}

/// Steady at `t`, then a wrong state forced into the twin: the next
/// Equilibrium job (within one round of jobs) re-seats it on the reference
/// equilibrium, flags it, counts it; the flag clears at the next check.
fn reseat_case(raw: &RawParams, t: f32, what: &str) {
    let mut est = estimator_for(raw, t);
    let window = est.settle_ticks() as usize;
    assert!(window < 20_000, "{what}: a settling window of {window} ticks");
    let mut e = run(&mut est, window + 100, Ok(Some(t)));
    assert_eq!(e.reseats, 0, "{what}: a correct twin at rest");
    let wrong = wrong_state(raw, t);
    est.twin_mut().set_state(&wrong);
    let mut k = 0;
    // One round is five jobs, and a telemetry tick may come between.
    while e.reseats == 0 && k < 7 {
        e = est.tick(Ok(None));
        k += 1;
    }
    assert_eq!(e.reseats, 1, "{what}: re-seated within one round of jobs");
    assert!(e.flags.contains(Flags::TWIN_RESEATED), "{what}: {:?}", e.flags);
    let (dx, dp) = off_reference(raw, e.temperature, e.x, e.p_a, e.p_b);
    assert!(
        dx <= 1e-3 && dp <= 1e-3,
        "{what}: re-seated {dx:e} strokes, {dp:e} dp off"
    );
    // The flag stays until the next check, one settling window on, finds
    // the twin in agreement; the count stays.
    for _ in 0..window.saturating_sub(10) {
        e = est.tick(Ok(None));
        assert!(e.flags.contains(Flags::TWIN_RESEATED), "{what}");
    }
    // The window counts ticks that run a job: telemetry ticks (one in 500)
    // and the wait for the next Equilibrium job come on top.
    for _ in 0..window / 100 + 50 {
        e = est.tick(Ok(None));
        if !e.flags.contains(Flags::TWIN_RESEATED) {
            break;
        }
    }
    assert!(!e.flags.contains(Flags::TWIN_RESEATED), "{what}: {:?}", e.flags);
    assert_eq!(e.reseats, 1, "{what}");
    let (dx, dp) = off_reference(raw, e.temperature, e.x, e.p_a, e.p_b);
    assert!(dx <= 1e-3 && dp <= 1e-3, "{what}: {dx:e} strokes, {dp:e} dp off");
}

#[test]
fn a_forced_wrong_state_is_reseated_on_the_closed_form() {
    let raw = paper_raw();
    reseat_case(&raw, 55.0, "paper, free at 55 C");
    reseat_case(&raw, 28.0, "paper, closed stop at 28 C");
    reseat_case(&raw, 10.0, "paper, closed stop at 10 C (out of range)");
    // A design that reaches the open stop at 78 C.
    let mut rng = Rng::new(5);
    let open = (0..200)
        .map(|_| physical_params(&mut rng))
        .find(|r| reference::equilibrium(&r.core, 78.0).x >= r.core.stroke)
        .expect("a random design on the open stop at 78 C");
    reseat_case(&open, 78.0, "random design, open stop at 78 C");
    let mut rng = Rng::new(6);
    for i in 0..4 {
        let raw = physical_params(&mut rng);
        reseat_case(&raw, 45.0, &format!("random design {i} at 45 C"));
    }
}

#[test]
fn the_check_holds_its_fire_while_the_temperature_moves() {
    // A wrong state forced as a 4 C step starts (below the spike
    // threshold: the filter approaches it over ~1 s): the twin finds its
    // way back by itself, and the check, waiting for a steady temperature,
    // never touches it. The same state at a steady temperature is
    // re-seated at once (a_forced_wrong_state_is_reseated_on_the_closed_form).
    let raw = paper_raw();
    let mut est = estimator_for(&raw, 50.0);
    run(&mut est, 1000, Ok(Some(50.0)));
    est.twin_mut().set_state(&wrong_state(&raw, 50.0));
    let mut worst = (0.0f64, 0.0f64);
    for k in 0..3000u32 {
        let e = est.tick(if k.is_multiple_of(20) { Ok(Some(54.0)) } else { Ok(None) });
        assert_eq!(e.reseats, 0, "tick {k}, filtered {} C", e.temperature);
        assert!(!e.flags.contains(Flags::TWIN_RESEATED));
        if k == 3 {
            worst = off_reference(&raw, e.temperature, e.x, e.p_a, e.p_b);
        }
    }
    // The state really was wrong when the check could have fired.
    assert!(
        worst.0 > f64::from(X_TOLERANCE) && worst.1 > f64::from(P_TOLERANCE),
        "{worst:?}"
    );

    // A real step (accepted by the spike filter, which moves the filter at
    // once): the twin is in transit, far from the new equilibrium, for
    // tens of milliseconds, and the check waits for the settling window.
    let mut est = estimator_for(&raw, 40.0);
    run(&mut est, 1000, Ok(Some(40.0)));
    let mut in_transit = 0;
    for k in 0..2000u32 {
        let e = est.tick(if k.is_multiple_of(20) { Ok(Some(60.0)) } else { Ok(None) });
        assert_eq!(e.reseats, 0, "tick {k}");
        if (e.temperature - 60.0).abs() < 0.01 {
            let (dx, _) = off_reference(&raw, e.temperature, e.x, e.p_a, e.p_b);
            in_transit += usize::from(dx > f64::from(X_TOLERANCE));
        }
    }
    assert!(in_transit >= 10, "the twin was in transit for {in_transit} ticks");
}

/// Drives an estimator through `legs` (from C, to C, seconds; a ramp when
/// from != to, else a step to the level, held for at least the settling
/// window and 1.5 s more (the filter settling on
/// a small step) so that the check runs), a sample every 20 ticks;
/// returns the re-seats. Each re-seat must be deserved: the state the
/// check saw (the previous estimate's) was off the reference equilibrium
/// by most of a tolerance. Every hold ends at the reference equilibrium.
fn drive(raw: &RawParams, name: &str, legs: &[(f32, f32, f32)]) -> u32 {
    let mut est = estimator_for(raw, legs[0].0);
    let mut prev = est.tick(Ok(Some(legs[0].0)));
    let mut k = 0u32;
    for &(from, to, secs) in legs {
        let mut n = (secs * 1000.0) as u32;
        if from == to {
            let window = estimator_for(raw, to).settle_ticks();
            assert!(
                window <= 100_000,
                "{name}: a settling window of {window} ticks at {to} C"
            );
            n = n.max(window + 1500);
        }
        let checks = est.consistency_checks();
        for j in 0..n {
            let t = from + (to - from) * j as f32 / n as f32;
            let e = est.tick(if k.is_multiple_of(20) { Ok(Some(t)) } else { Ok(None) });
            k += 1;
            if e.reseats > prev.reseats {
                let (dx, dp) = off_reference(raw, e.temperature, prev.x, prev.p_a, prev.p_b);
                assert!(
                    dx > 0.9 * f64::from(X_TOLERANCE) || dp > 0.9 * f64::from(P_TOLERANCE),
                    "{name}: re-seated a right twin at {} C ({dx:e} strokes, {dp:e} dp off)",
                    e.temperature
                );
                eprintln!(
                    "{name}: leg {from}->{to} C: re-seated a twin {dx:.3} strokes, {dp:.3} dp off at {} C",
                    e.temperature
                );
            }
            prev = e;
        }
        if from == to {
            assert!(
                est.consistency_checks() > checks,
                "{name}: no check during the {to} C hold"
            );
            let (dx, dp) = off_reference(raw, prev.temperature, prev.x, prev.p_a, prev.p_b);
            assert!(
                dx <= 1e-3 && dp <= 1e-3,
                "{name}: the {to} C hold ends {dx:e} strokes, {dp:e} dp off"
            );
        }
    }
    prev.reseats
}

/// Holds, real steps (beyond the spike threshold), small steps (through
/// the filter) and 1 C/s ramps across 26-78 C.
const ENVELOPE: [(f32, f32, f32); 12] = [
    (26.0, 26.0, 1.0),
    (26.0, 78.0, 52.0),
    (78.0, 78.0, 1.5),
    (60.0, 60.0, 1.5),
    (40.0, 40.0, 1.5),
    (43.0, 43.0, 1.5),
    (30.0, 30.0, 1.5),
    (70.0, 70.0, 1.5),
    (26.0, 26.0, 1.5),
    (26.0, 50.0, 24.0),
    (50.0, 50.0, 1.5),
    (34.0, 34.0, 2.0),
];

/// Random designs of the envelope test: 4, or `COMPENSATOR_ENVELOPE_DESIGNS`
/// for a longer run.
fn envelope_designs() -> usize {
    std::env::var("COMPENSATOR_ENVELOPE_DESIGNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4)
}

#[test]
fn a_correct_twin_is_never_reseated_across_the_envelope() {
    let mut runs = vec![("paper".to_string(), paper_raw())];
    let mut rng = Rng::new(2024);
    for i in 0..envelope_designs() {
        runs.push((format!("random design {i}"), physical_params(&mut rng)));
    }
    for (name, raw) in &runs {
        let reseats = drive(raw, name, &ENVELOPE);
        assert_eq!(reseats, 0, "{name}");
    }
}

#[test]
fn a_cooling_step_onto_the_closed_stop_ends_on_the_reference() {
    // Cooling steps onto the closed stop: the estimate ends at the reference
    // equilibrium, whether the twin gets there by itself or, on a false
    // equilibrium, the check puts it there (today's twin needs it).
    let raw = paper_raw();
    let n = drive(&raw, "paper 40 -> 0 C", &[(40.0, 40.0, 1.0), (0.0, 0.0, 1.5)]);
    eprintln!("paper 40 -> 0 C: {n} re-seats");
    let n = drive(
        &raw,
        "paper 80 -> 10 -> 30 C",
        &[(80.0, 80.0, 1.0), (10.0, 10.0, 1.5), (30.0, 30.0, 1.5)],
    );
    eprintln!("paper 80 -> 10 -> 30 C: {n} re-seats");
    let n = drive(
        &closed_stop_case(),
        "closed-stop case",
        &[(38.78, 38.78, 1.0), (33.32, 33.32, 3.0)],
    );
    eprintln!("closed-stop case 38.78 -> 33.32 C: {n} re-seats");
}

/// `host-tests/cases/twin/closed-stop-false-equilibrium.toml` (a design within 0.2
/// decade of `presets/model-example.toml`; its cooling step 38.78 ->
/// 33.32 C ends on the closed stop at p_a = 301,365 Pa, p_b = 447 Pa).
fn closed_stop_case() -> RawParams {
    let core = compensator::params::RawCore {
        walther_a: 10.182421501506951,
        walther_b: 3.937623044584095,
        density_15: 873.8952196723637,
        expansion: 0.0006243412265191042,
        bulk_modulus: 1639542698.7925673,
        laminar_diameter: 0.000682730641439646,
        laminar_length: 0.022669259161198094,
        turbulent_diameter: 0.000777626818713266,
        turbulent_discharge: 0.5823678415613631,
        plunger_diameter: 0.012674004206128192,
        mass: 0.026177033127791374,
        damping: 1.6665525111790152,
        spring_rate: 18562.900418224486,
        preload: 0.0005541414218884826,
        stroke: 0.0012995489321873813,
        slot_diameter: 0.0015174185781674683,
        slot_discharge: 0.5455998517417313,
        volume_a: 1.7343165151790212e-06,
        volume_b: 2.9857204710616753e-06,
        pressure_drop: 301811.90324398904,
        outlet_pressure: 0.0,
    };
    let raw = RawParams {
        core,
        machine: None,
        estimator: compensator::params::RawEstimator::DEFAULT,
        probe: compensator::params::RawProbe::DEFAULT,
        monitor: compensator::params::RawMonitor::NONE,
        tolerances: compensator::params::RawTolerances::NONE,
    };
    raw.validate().unwrap();
    raw
}

#[test]
fn flag_names_follow_the_bit_order() {
    let flags = [
        (Flags::AT_STOP, "AT_STOP"),
        (Flags::OUT_OF_RANGE, "OUT_OF_RANGE"),
        (Flags::NOT_UNIQUE, "NOT_UNIQUE"),
        (Flags::UNSTABLE, "UNSTABLE"),
        (Flags::SENSOR_FAULT, "SENSOR_FAULT"),
        (Flags::SPIKE, "SPIKE"),
        (Flags::DEGRADED, "DEGRADED"),
        (Flags::TWIN_RESEATED, "TWIN_RESEATED"),
        (Flags::DEADLINE_MISSED, "DEADLINE_MISSED"),
        (Flags::WATCHDOG_RESET, "WATCHDOG_RESET"),
        (Flags::DEVICE_CHANGED, "DEVICE_CHANGED"),
        (Flags::CAPILLARY_RESTRICTED, "CAPILLARY_RESTRICTED"),
        (Flags::ORIFICE_CLOGGED, "ORIFICE_CLOGGED"),
        (Flags::SPRING_RELAXED, "SPRING_RELAXED"),
        (Flags::PRELOAD_LOST, "PRELOAD_LOST"),
        (Flags::PLUNGER_STICKING, "PLUNGER_STICKING"),
        (Flags::SENSOR_OFFSET, "SENSOR_OFFSET"),
        (Flags::SECOND_SENSOR_FAULT, "SECOND_SENSOR_FAULT"),
        (Flags::INNOVATION_REJECTED, "INNOVATION_REJECTED"),
    ];
    assert_eq!(Flags::NAMES.len(), flags.len());
    for (f, name) in flags {
        assert_eq!(f.0.count_ones(), 1, "{name}");
        assert_eq!(Flags::NAMES[f.0.trailing_zeros() as usize], name);
    }
}

/// The three abrupt cold steps onto the closed stop on which the settling
/// study (`cargo run --release -p host-tests --example settling -- 1000`)
/// saw the check re-seat a correct twin still travelling onto the stop
/// (a 10-time-constant window there): none re-seats now.
#[test]
fn a_correct_twin_travelling_onto_the_closed_stop_is_not_reseated() {
    use host_tests::settling::{designs, estimator_reseats};
    let cases = [(243, 40.0, -40.0), (510, 60.0, -20.0), (956, 40.0, -40.0)];
    let all: Vec<_> = designs(1, paper_raw()).take(956).collect();
    for (n, from, to) in cases {
        let (used, raw) = &all[n - 1];
        assert_eq!(*used, n);
        let reseats = estimator_reseats(raw, from, to).expect("within the model's reach");
        assert_eq!(reseats, 0, "design {n}, {from} -> {to} C");
    }
}

/// A design whose plunger, resting on the closed stop where the force
/// crosses zero, has an event (a release and a stop) every tick of a slow
/// warm-up: the estimator deferred every job on event ticks, so the twin's
/// oil froze and the plunger stayed on the stop while the reference left
/// it at 42 C (found by `cargo run --release -p host-tests --example
/// tracking`: 100 % of the stroke off). Jobs now run after `MAX_DEFERRED`
/// event ticks in a row.
#[test]
fn a_plunger_chattering_on_a_stop_leaves_it_in_a_warm_up() {
    let core = compensator::params::RawCore {
        walther_a: 7.165868034959745,
        walther_b: 2.7615560760237954,
        density_15: 899.9608256476797,
        expansion: 0.0006187733984042582,
        bulk_modulus: 903423740.3941056,
        laminar_diameter: 0.001487883848699213,
        laminar_length: 0.0537543482976892,
        turbulent_diameter: 0.0007094165123192144,
        turbulent_discharge: 0.5581163286792694,
        plunger_diameter: 0.012348679762961692,
        mass: 0.09239848126756801,
        damping: 13.019756611835707,
        spring_rate: 16574.29403986476,
        preload: 0.00022933083204152262,
        stroke: 0.0006377643297784106,
        slot_diameter: 0.0032139607026166923,
        slot_discharge: 0.7045020886289786,
        volume_a: 1.9039102542670302e-7,
        volume_b: 5.32232601943027e-7,
        pressure_drop: 241773.96052757077,
        outlet_pressure: 387348.2942209978,
    };
    let raw = RawParams {
        core,
        machine: None,
        estimator: compensator::params::RawEstimator::DEFAULT,
        probe: compensator::params::RawProbe::DEFAULT,
        monitor: compensator::params::RawMonitor::NONE,
        tolerances: compensator::params::RawTolerances::NONE,
    };
    // Through the probe it was found with (27.8 s), as the tracking study
    // runs it.
    let raw = RawParams {
        probe: compensator::params::RawProbe {
            time_constant: 27.760172118403226,
            ..compensator::params::RawProbe::DEFAULT
        },
        ..raw
    };
    let r = host_tests::tracking::run(&raw, 28.0, 76.0, 0.5, 38).unwrap();
    assert!(r.ramp < 5e-3 && r.after < 5e-3, "{r:?}");
}
