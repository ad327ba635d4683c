//! The estimator's behaviour: it follows the twin and the closed form at
//! rest, filters and rejects spikes, and turns every bad sample into a
//! flag, never a NaN.

use compensator::Params;
use compensator::dynamics::{Twin, TwinConfig};
use compensator::equilibrium::equilibrium;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, StateEstimate};
use compensator::sensor::SensorFault;
use host_tests::repo_root;

fn setup(initial: f32) -> (Params<f32>, EstimatorConfig, Estimator) {
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw.estimator).unwrap();
    let est = Estimator::new(&p, cfg, initial).unwrap();
    (p, cfg, est)
}

fn run(est: &mut Estimator, ticks: usize, sample: Result<Option<f32>, SensorFault>) -> StateEstimate {
    let mut last = None;
    for k in 0..ticks {
        let s = if k % 20 == 0 { sample } else { Ok(None) };
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
    // A slow ramp: the estimator's filtered temperature lags by tau * rate.
    let (p, cfg, mut est) = setup(40.0);
    let mut twin = Twin::<f32, f32>::new(&p, TwinConfig::SHIPPED, 40.0).unwrap();
    let tau = 0.2;
    let mut worst = 0.0f32;
    for k in 0..5000 {
        let t = 40.0 + 2.0 * (k as f32 * 1e-3);
        let e = est.tick(if k % 20 == 0 { Ok(Some(t)) } else { Ok(None) });
        twin.set_temperature(t - 2.0 * tau).unwrap();
        twin.tick().unwrap();
        if k > 2000 {
            worst = worst.max((e.x - twin.state().x).abs());
        }
    }
    // Lag of the filter, sample-and-hold and the 4 ms refresh of the fluid
    // properties: within 0.1 C of temperature, about 4 um at 37 um/K.
    assert!(worst < 5e-6, "estimator and twin differ by {worst} m");
    let _ = cfg;
}

#[test]
fn the_filter_has_the_configured_time_constant() {
    let (_, cfg, mut est) = setup(50.0);
    // A 4 C step (below the 5 C spike threshold): 63 % after tau = 0.2 s.
    let ticks = (0.2 / cfg.tick()).round() as usize;
    let e = run(&mut est, ticks, Ok(Some(54.0)));
    let frac = (e.temperature - 50.0) / 4.0;
    assert!((frac - 0.632).abs() < 0.01, "{frac}");
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
        Err(SensorFault::RtdHigh),
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
    let mut settings = raw.estimator;
    settings.tick_hz = 250.0;
    let cfg = EstimatorConfig::new(&settings).unwrap();
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
