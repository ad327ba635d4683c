//! The condition monitor on the paper preset with a probe that does not
//! lag: a restricted capillary is detected and named from a chamber
//! pressure and from the displacement within a 5 K cooling, a relaxed
//! spring from the displacement, and a healthy device raises nothing. (The campaign over
//! seeded designs with the probe's lag and tolerance and the devices'
//! spreads is `examples/monitor_campaign.rs`.)

use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, Flags};
use compensator::monitor::{MonitorSettings, ProbeModel, Quantity};
use compensator::params::RawCore;
use compensator::sensor::SensorFault;
use compensator_reference::statics::equilibrium;
use core::ops::Range;
use host_tests::random::Rng;
use host_tests::repo_root;

/// The monitor's settings for quantity `q` on `raw`'s probe, read every
/// 10 ms with a noise of 0.1 % of the stroke or 100 Pa (returned) and a
/// class of 2.5 times that.
fn sensor(raw: &compensator::params::RawParams, q: Quantity) -> (MonitorSettings, f64) {
    let sd = if q == Quantity::Displacement {
        1e-3 * raw.core.stroke
    } else {
        100.0
    };
    let settings = MonitorSettings {
        quantity: q,
        sd_noise: sd as f32,
        sd_accuracy: (2.5 * sd) as f32,
        sample_period: 0.01,
        probe: ProbeModel::new(raw),
    };
    (settings, sd)
}

/// A zero-mean noise of unit variance (the sum of four uniforms).
fn unit_noise(rng: &mut Rng) -> f64 {
    (rng.unit() + rng.unit() + rng.unit() + rng.unit() - 2.0) * 3f64.sqrt()
}

/// Runs 60 s at 60 C, then a cooling at 0.1 C/s with the device changed by
/// `fault` from 60 s on, the second sensor's readings within `refused`
/// \[s\] refused by its own checks; `each` sees every tick's time, flags
/// and whether the estimate is published, and ends the run with `false`.
fn drive(q: Quantity, fault: fn(&mut RawCore), refused: Range<f64>, mut each: impl FnMut(f64, Flags, bool) -> bool) {
    let mut raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    raw.probe.time_constant = 0.01;
    raw.probe.well_time_constant = 0.0;
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let (settings, sd) = sensor(&raw, q);
    let mut est = Estimator::new(&p, cfg, 60.0).unwrap().with_monitor(settings).unwrap();
    let mut bad = raw.core;
    fault(&mut bad);
    let mut rng = Rng::new(7);
    for k in 0..120_000u64 {
        let t = k as f64 * 1e-3;
        let temp = if t < 60.0 { 60.0 } else { 60.0 - 0.1 * (t - 60.0) };
        let e = est.tick(Ok(k.is_multiple_of(20).then_some(temp as f32)));
        if k.is_multiple_of(10) {
            let core = if t >= 60.0 { &bad } else { &raw.core };
            let pt = equilibrium(core, temp);
            let y = match q {
                Quantity::ChamberA => pt.p_a,
                Quantity::ChamberB => pt.p_b,
                Quantity::Difference => pt.p_b - pt.p_a,
                Quantity::Displacement => pt.x,
            };
            let n = unit_noise(&mut rng);
            est.offer_second(if refused.contains(&t) {
                Err(SensorFault::Bus)
            } else {
                Ok((y + n * sd) as f32)
            });
        }
        if !each(t, e.flags, est.telemetry_due()) {
            return;
        }
    }
}

/// [`drive`] without refused readings: the first named flags and their
/// time.
fn run(q: Quantity, fault: fn(&mut RawCore)) -> Option<(f64, Flags)> {
    let names = compensator::monitor::LATCHED;
    let mut first = None;
    drive(q, fault, 0.0..0.0, |t, flags, _| {
        let named = Flags(flags.0 & names.0);
        if !named.is_empty() {
            first = Some((t, named));
            return false;
        }
        assert!(
            !(t < 60.0 && flags.contains(Flags::DEVICE_CHANGED)),
            "a change before the fault at {t}"
        );
        true
    });
    first
}

/// The monitor runs in a job's place, never on a telemetry tick, and a
/// reading without a probe reading beside it runs no test: the flags its
/// estimate raised were on that tick's estimate alone, so that the
/// telemetry never showed `DEVICE_CHANGED` between a change's detection
/// and its name, nor a refused reading's `SECOND_SENSOR_FAULT`. Every
/// published estimate from the detection to the name now says
/// `DEVICE_CHANGED`, and the first published after refused readings
/// says `SECOND_SENSOR_FAULT`.
#[test]
fn the_published_estimates_carry_the_monitors_flags() {
    let mut published = Vec::new();
    let mut named = None;
    drive(
        Quantity::ChamberA,
        |c| c.laminar_diameter *= 0.8f64.powf(0.25),
        30.0..30.05,
        |t, flags, due| {
            if flags.contains(Flags::CAPILLARY_RESTRICTED) {
                named = Some(t);
                return false;
            }
            if due {
                published.push((t, flags));
            }
            true
        },
    );
    let named = named.expect("the restriction is not named");
    let refused: Vec<f64> = published
        .iter()
        .filter(|(_, f)| f.contains(Flags::SECOND_SENSOR_FAULT))
        .map(|(t, _)| *t)
        .collect();
    // The telemetry's 2 Hz: the first published after 30 s, and only it.
    assert!(
        refused.len() == 1 && (30.0..30.5).contains(&refused[0]),
        "published with SECOND_SENSOR_FAULT at {refused:?} s"
    );
    let detected = published
        .iter()
        .position(|(_, f)| f.contains(Flags::DEVICE_CHANGED))
        .expect("no published estimate says DEVICE_CHANGED");
    // Every published estimate from the detection to the name (the run
    // ends there).
    let changed = &published[detected..];
    assert!(
        changed.len() >= 10,
        "DEVICE_CHANGED from {} s, named at {named} s",
        published[detected].0
    );
    for (t, f) in changed {
        assert!(
            f.contains(Flags::DEVICE_CHANGED),
            "{t} s: {f:?} before the change is named"
        );
    }
    assert!(published[detected].0 >= 60.0, "detected at {} s", published[detected].0);
}

#[test]
fn a_restricted_capillary_is_named_from_either_sensor() {
    for q in [Quantity::ChamberA, Quantity::Displacement] {
        let (t, f) = run(q, |c| c.laminar_diameter *= 0.8f64.powf(0.25)).expect("named");
        assert_eq!(f, Flags::CAPILLARY_RESTRICTED, "{q:?}");
        // Detected at once; named once the cooling has spread the
        // signatures of a restriction and of the sensor's offset apart by
        // more than the model's error (a few kelvin), before 5 K (50 s).
        assert!((60.0..110.0).contains(&t), "{q:?} at {t}");
    }
}

#[test]
fn a_relaxed_spring_is_named_from_the_displacement_only() {
    let (_, f) = run(Quantity::Displacement, |c| c.spring_rate *= 0.9).expect("named");
    assert_eq!(f, Flags::SPRING_RELAXED);
    assert_eq!(run(Quantity::ChamberA, |c| c.spring_rate *= 0.9), None);
}

#[test]
fn a_healthy_device_raises_nothing() {
    assert_eq!(run(Quantity::ChamberA, |_| {}), None);
    assert_eq!(run(Quantity::Displacement, |_| {}), None);
}

/// A reset (an inspection found the device healthy) in the middle of a
/// warming at 0.3 C/s, read through the preset's 6 s probe: the probe
/// trails the oil by 1.8 K there, which the monitor's lag still holds
/// after the reset, so the healthy device raises nothing before or after
/// it, and the innovations right after it are those of a healthy device.
#[test]
fn a_reset_in_a_ramp_raises_nothing() {
    let raw = compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap();
    let tau = raw.probe.time_constant;
    assert!(
        raw.probe.well_time_constant == 0.0 && tau >= 5.0,
        "a lagging probe without a well"
    );
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    for q in [Quantity::ChamberA, Quantity::Displacement] {
        let (settings, sd) = sensor(&raw, q);
        let mut est = Estimator::new(&p, cfg, 40.0).unwrap().with_monitor(settings).unwrap();
        let mut rng = Rng::new(13);
        // 120 s at 40 C, 60 s of warming at 0.3 C/s, 60 s at 58 C; the
        // probe's first-order lag in closed form; the reset at 150 s.
        let (t0, t1, rate) = (120.0f64, 180.0f64, 0.3f64);
        let oil = |t: f64| 40.0 + rate * (t.clamp(t0, t1) - t0);
        let probe = |t: f64| {
            let trail = rate * tau * (1.0 - (-(t.clamp(t0, t1) - t0) / tau).exp());
            oil(t) - trail * (-(t - t1).max(0.0) / tau).exp()
        };
        let (mut largest, mut reset) = (0.0f32, false);
        for k in 0..240_000u64 {
            let t = k as f64 * 1e-3;
            if !reset && t >= 150.0 {
                est.reset_monitor();
                reset = true;
            }
            let e = est.tick(Ok(k.is_multiple_of(20).then_some(probe(t) as f32)));
            if k.is_multiple_of(10) {
                let pt = equilibrium(&raw.core, oil(t));
                let y = match q {
                    Quantity::ChamberA => pt.p_a,
                    _ => pt.x,
                };
                let n = unit_noise(&mut rng);
                est.offer_second(Ok((y + n * sd) as f32));
            }
            let alarm = e.flags.0 & (Flags::DEVICE_CHANGED.0 | compensator::monitor::LATCHED.0);
            assert_eq!(alarm, 0, "{q:?}: {:?} at {t} s", Flags(alarm));
            if (150.0..155.0).contains(&t) && est.health().innovation.is_finite() {
                largest = largest.max(est.health().innovation.abs());
            }
        }
        // Without the lag kept, the first innovations after the reset are
        // the probe's 1.8 K trail over a few hundredths of a kelvin.
        assert!(largest < 4.0, "{q:?}: |z| up to {largest} in the 5 s after the reset");
    }
}

/// The monitor's stages run one per call (`begin`, then `advance` until it
/// returns the estimate) give `update`'s estimates bit for bit: the
/// estimator spreads a reading over its job ticks without changing what
/// the monitor computes.
#[test]
fn the_staged_update_is_the_update() {
    use compensator::monitor::{HealthEstimate, Monitor, PlantView, ProbeSample};
    let raw = compensator_cli::load(&repo_root().join("presets/paper-monitor.toml")).unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    let settings = MonitorSettings::from_raw(&raw).unwrap().expect("a second sensor");
    let mut whole = Monitor::new(&p, settings).unwrap();
    let mut staged = whole;
    let mut bad = raw.core;
    bad.laminar_diameter *= 0.8f64.powf(0.25);
    let mut rng = Rng::new(11);
    let bits = |e: &HealthEstimate| {
        [
            e.divider,
            e.sd_divider,
            e.spring,
            e.offset,
            e.sd_offset,
            e.probe_bias,
            e.oil,
            e.predicted,
            e.innovation,
            e.cusum,
        ]
        .map(f32::to_bits)
    };
    let (mut probe, mut named) = (60.0f64, false);
    for k in 0..6000u32 {
        let t = f64::from(k) * 0.01;
        let temp = if t < 20.0 { 60.0 } else { 60.0 - 0.1 * (t - 20.0) };
        probe += (temp - probe) * 0.01 / (6.0 + 0.01);
        let core = if t >= 20.0 { &bad } else { &raw.core };
        let pt = equilibrium(&raw.core, temp);
        let view = PlantView {
            oil: p.oil.point(temp as f32).unwrap(),
            x: pt.x as f32,
            p_a: pt.p_a as f32,
            p_b: pt.p_b as f32,
            dt: if k == 0 { 0.0 } else { 0.01 },
            probe: k.is_multiple_of(2).then_some(ProbeSample {
                value: probe as f32,
                age: 0.0,
            }),
        };
        let y = equilibrium(core, temp).p_a + 100.0 * (rng.unit() - 0.5) * 12f64.sqrt();
        let want = whole.update(&p, &view, Ok::<f32, ()>(y as f32));
        staged.begin(&p, &view, Ok::<f32, ()>(y as f32));
        let mut got = None;
        for _ in 0..3 {
            got = staged.advance();
            if got.is_some() {
                break;
            }
        }
        let got = got.expect("done within three stages");
        assert!(!staged.pending());
        assert_eq!(bits(&got), bits(&want), "reading {k}");
        assert_eq!(got.flags, want.flags, "reading {k}");
        named |= got.flags.contains(Flags::CAPILLARY_RESTRICTED);
    }
    // The run took every stage: the change was watched and named.
    assert!(named, "the restriction is named");
}
