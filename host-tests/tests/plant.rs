//! The plant observer (`compensator::estimator::Plant`): the twin, its
//! jobs and the publication of an estimate, driven by an oil temperature
//! and port pressures (what the FMU runs) rather than by probe samples.
//! Checked against the independent f64 reference equilibrium at the
//! applied ports, and against the estimator, which drives the same plant
//! through its observer.

use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, Plant};
use compensator::params::RawParams;
use host_tests::{reference, repo_root};

fn paper() -> RawParams {
    let mut raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    // A probe without lag: the estimator's temperature is the reading.
    raw.probe.time_constant = 0.01;
    raw.probe.well_time_constant = 0.0;
    raw
}

/// Distance of `(x, p_a, p_b)` from the reference equilibrium of `raw` at
/// `t` [C]: x in strokes, the larger pressure error in the drop.
fn off_reference(raw: &RawParams, t: f32, e: &compensator::estimator::StateEstimate) -> (f64, f64) {
    let r = reference::equilibrium(&raw.core, f64::from(t));
    let c = &raw.core;
    let dx = (f64::from(e.x) - r.x).abs() / c.stroke;
    let dp = (f64::from(e.p_a) - r.p_a).abs().max((f64::from(e.p_b) - r.p_b).abs()) / c.pressure_drop;
    (dx, dp)
}

#[test]
fn at_other_ports_the_plant_settles_on_the_reference_there() {
    let raw = paper();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let mut plant = Plant::<f32>::new(&p, &cfg, 50.0, 0.0).unwrap();
    // The drop raised by half and the outlet moved: the reference at the
    // same ports is the design with that drop and outlet.
    let (drop, outlet) = (1.5 * raw.core.pressure_drop, raw.core.outlet_pressure + 1.0e5);
    let mut at_ports = raw;
    at_ports.core.pressure_drop = drop;
    at_ports.core.outlet_pressure = outlet;
    plant.set_ports((drop + outlet) as f32, outlet as f32).unwrap();
    for t in [50.0f32, 35.0, 65.0] {
        plant.refresh(&cfg, t, 0.0).unwrap();
        let mut flags = Flags::empty();
        for _ in 0..20_000 {
            plant.advance(&mut flags).unwrap();
        }
        assert!(!flags.contains(Flags::DEGRADED), "{t} C: {flags:?}");
        let e = plant.estimate(t, plant.flags_at(&cfg, t));
        let (dx, dp) = off_reference(&at_ports, t, &e);
        assert!(
            dx <= 1e-5 && dp <= 1e-5,
            "{t} C: {dx:e} of the stroke, {dp:e} of the drop"
        );
        let r = reference::equilibrium(&at_ports.core, f64::from(t));
        let dq = (f64::from(e.q_total) - r.q_total).abs() / r.q_total;
        assert!(dq <= 1e-3, "{t} C: total flow {} against {}", e.q_total, r.q_total);
        let x_eq = (f64::from(e.x_equilibrium) - r.x).abs() / raw.core.stroke;
        assert!(x_eq <= 1e-5, "{t} C: closed form {x_eq:e} of the stroke off");
        assert_eq!(Flags(e.flags.0 & !Flags::AT_STOP.0), Flags::empty(), "{t} C");
    }
}

#[test]
fn a_drop_outside_the_schemas_range_is_out_of_range_and_changes_nothing_else() {
    let raw = paper();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let mut plant = Plant::<f32>::new(&p, &cfg, 50.0, 0.0).unwrap();
    assert_eq!(plant.flags_at(&cfg, 50.0), Flags::empty());
    // 500 Pa: below `operating.pressure_drop`'s plausible 1 kPa.
    let outlet = raw.core.outlet_pressure as f32;
    plant.set_ports(outlet + 500.0, outlet).unwrap();
    assert_eq!(plant.flags_at(&cfg, 50.0), Flags::OUT_OF_RANGE);
    // Outside the validated temperatures too: the same flag.
    plant.set_ports(p.pressure_drop + outlet, outlet).unwrap();
    assert_eq!(plant.flags_at(&cfg, cfg.valid.max + 1.0), Flags::OUT_OF_RANGE);
    assert_eq!(plant.flags_at(&cfg, 50.0), Flags::empty());
}

#[test]
fn the_estimator_publishes_its_plants_estimate() {
    let raw = paper();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let mut est = Estimator::new(&p, cfg, 45.0).unwrap();
    let mut last = None;
    for k in 0..3000 {
        let sample = if k % 20 == 0 {
            Ok(Some(45.0 + 0.002 * k as f32))
        } else {
            Ok(None)
        };
        last = Some(est.tick(sample));
    }
    let e = last.unwrap();
    // The plant's estimate at the estimator's temperature and flags is the
    // estimator's, but for the fields the estimator owns.
    let mut from_plant = est.plant().estimate(e.temperature, e.flags);
    from_plant.tick = e.tick;
    from_plant.t_probe = e.t_probe;
    from_plant.deadline_misses = e.deadline_misses;
    from_plant.lost_ticks = e.lost_ticks;
    // Compared as printed: without a monitor the health estimate is NaN,
    // which never equals itself.
    assert!(e.health.divider.is_nan() && e.health.flags.is_empty());
    assert_eq!(format!("{from_plant:?}"), format!("{e:?}"));
    assert!(e.x.is_finite() && e.q_total > 0.0, "{e:?}");
}
