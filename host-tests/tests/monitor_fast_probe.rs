//! The condition monitor with a fast oil-temperature probe: when the
//! probe's time constant is comparable with the second sensor's period,
//! the lag no longer averages the second sensor's noise away, and what
//! the lag passes of it is a noise of the probe's innovation as large as
//! the probe's own, correlated from one probe reading to the next. The
//! monitor carries it as a state of its filter (`compensator::monitor`'s
//! `filter`): over seeded healthy histories (`host_tests::campaign`) the
//! innovations stay white and of unit variance for probes from 0.01 s to
//! 20 s, a healthy device raises nothing over ten minutes at a constant
//! temperature and over a cooling, and the capillary restricted at 60 s of
//! `tests/cli_monitor.rs`'s scenario is named, its divider estimated within
//! 5 % of 1.25.

use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, Flags};
use compensator::monitor::{HealthEstimate, LATCHED, MonitorSettings};
use compensator::params::RawParams;
use host_tests::campaign::{Fault, Injection, Profile, Quantity, Scenario, SecondSensor};
use host_tests::monitor_campaign::{ALARMS, run, settings};

/// The paper preset with its chamber (a) transducer and the probe's time
/// constant `tau` \[s\].
fn preset(tau: f64) -> RawParams {
    let text = include_str!("../../presets/paper-monitor.toml");
    let text = text.replace("time_constant = 6.0    # s", &format!("time_constant = {tau}    # s"));
    assert!(text.contains(&format!("time_constant = {tau}    # s")));
    compensator_cli::parse(&text).unwrap()
}

/// 60 C held, or from 60 s on a cooling at 0.1 C/s to 40 C.
fn profile(ramp: bool) -> Profile {
    if ramp {
        Profile::ramp(60.0, 40.0, 0.1, 60.0)
    } else {
        Profile::hold(60.0)
    }
}

/// What a run of the firmware's estimator with its monitor saw.
struct Trace {
    /// The standardised innovations after the first minute, one per probe
    /// reading tested, until the first alarm.
    innovations: Vec<f64>,
    /// The first alarm (`DEVICE_CHANGED` or a named fault): time \[s\], flags.
    alarm: Option<(f64, Flags)>,
    /// The first named fault: time \[s\], flags.
    named: Option<(f64, Flags)>,
    /// The health estimate at the end.
    last: HealthEstimate,
}

/// `scenario`'s records through the estimator of its nominal design with a
/// monitor of `settings`, each reading on its tick (as
/// `host_tests::monitor_campaign::run` does), to the end.
fn trace(scenario: &Scenario, settings: MonitorSettings) -> Trace {
    let p32 = Params::<f32>::new(&scenario.nominal).unwrap();
    let config = EstimatorConfig::new(&scenario.nominal).unwrap();
    let mut records = scenario.records().unwrap().peekable();
    let first = records.peek().and_then(|s| s.probe).unwrap();
    let mut est = Estimator::new(&p32, config, first as f32)
        .unwrap()
        .with_monitor(settings)
        .unwrap();
    let mut out = Trace {
        innovations: Vec::new(),
        alarm: None,
        named: None,
        last: HealthEstimate::NONE,
    };
    let mut tick = 0u64;
    let mut last = f32::NAN;
    for s in records {
        while tick < s.tick {
            est.tick(Ok(None));
            tick += 1;
        }
        if let Some(y) = s.second {
            est.offer_second(Ok(y as f32));
        }
        let e = est.tick(Ok(s.probe.map(|v| v as f32)));
        tick += 1;
        let z = e.health.innovation;
        if z.is_finite() && z.to_bits() != last.to_bits() && s.t > 60.0 && out.alarm.is_none() {
            out.innovations.push(f64::from(z));
        }
        last = z;
        let alarm = Flags(e.flags.0 & ALARMS.0);
        if !alarm.is_empty() && out.alarm.is_none() {
            out.alarm = Some((s.t, alarm));
        }
        let named = Flags(e.flags.0 & LATCHED.0);
        if !named.is_empty() && out.named.is_none() {
            out.named = Some((s.t, named));
        }
        out.last = e.health;
    }
    out
}

/// Mean, variance and lag-1 correlation of `z`.
fn moments(z: &[f64]) -> (f64, f64, f64) {
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let var = z.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
    let lag1 = z.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum::<f64>() / (n * var);
    (mean, var, lag1)
}

/// Over ten minutes of a healthy device, held at 60 C or cooled to 40 C,
/// the probe's innovations are white and of unit variance whatever the
/// probe's time constant: the CUSUM's false-alarm rate holds for each.
#[test]
fn innovations_are_white_for_every_probe() {
    for tau in [0.01, 0.05, 0.5, 6.0, 20.0] {
        for ramp in [false, true] {
            let raw = preset(tau);
            let sensor = SecondSensor::default_for(Quantity::PA, &raw.core);
            let s = Scenario::new(&raw, sensor, Injection::HEALTHY, profile(ramp), 600.0, 3);
            let t = trace(&s, settings(&s.sensor, &raw));
            let (mean, var, lag1) = moments(&t.innovations);
            let what = format!("tau {tau} s, ramp {ramp}: mean {mean:.3} variance {var:.3} lag-1 {lag1:.3}");
            assert!(t.innovations.len() > 20_000, "{what}: {}", t.innovations.len());
            assert!(t.alarm.is_none(), "{what}: {:?}", t.alarm);
            assert!(mean.abs() < 0.05, "{what}");
            assert!((0.85..1.15).contains(&var), "{what}");
            // A positive correlation lengthens the CUSUM's runs (the
            // variance of a sum of n innovations is about n (1 + 2 lag-1));
            // a negative one shortens them, and only a large one would
            // say the innovation's variance is modelled wrong.
            assert!((-0.15..0.08).contains(&lag1), "{what}");
        }
    }
}

/// A healthy device with a fast probe raises no alarm over ten minutes,
/// at a constant temperature and over a cooling, on several seeds (the
/// campaign's run: its monitor reset after any alarm, each counted).
#[test]
fn a_healthy_device_with_a_fast_probe_raises_nothing() {
    for tau in [0.01, 0.5] {
        for ramp in [false, true] {
            for seed in [1, 11] {
                let raw = preset(tau);
                let sensor = SecondSensor::default_for(Quantity::PA, &raw.core);
                let s = Scenario::new(&raw, sensor, Injection::HEALTHY, profile(ramp), 600.0, seed);
                let out = run(&s).unwrap();
                assert_eq!(
                    out.false_alarms, 0,
                    "tau {tau} s, ramp {ramp}, seed {seed}: first at {:?}",
                    out.false_alarm
                );
            }
        }
    }
}

/// `tests/cli_monitor.rs`'s scenario (a capillary restricted to 0.8 of its
/// conductance at 60 s, then a cooling) with a fast probe: nothing before
/// the onset, the restriction named within a minute of it, the divider at
/// the end within 5 % of 1 / 0.8, the probe's bias within its tolerance.
/// With the monitor's settings from the campaign's sensor, and from the
/// device file with the scenario's transducer as the file describes it
/// (`monitor.noise`).
#[test]
fn the_restriction_is_named_and_sized_with_a_fast_probe() {
    for tau in [0.01, 0.5] {
        let raw = preset(tau);
        let injection = Injection {
            fault: Fault::CapillaryRestricted(0.8),
            onset: 60.0,
        };
        let campaign = SecondSensor::default_for(Quantity::PA, &raw.core);
        let file = SecondSensor {
            noise_sd: raw.monitor.noise,
            ..campaign
        };
        let from_file = MonitorSettings::from_raw(&raw).unwrap().unwrap();
        for (sensor, with_file) in [(campaign, false), (file, true)] {
            let s = Scenario::new(&raw, sensor, injection, profile(true), 150.0, 11);
            let m = if with_file {
                from_file
            } else {
                settings(&s.sensor, &raw)
            };
            let t = trace(&s, m);
            let what = format!("tau {tau} s, the file's settings {with_file}");
            let (at, _) = t.alarm.expect("an alarm");
            assert!(at >= 60.0, "{what}: an alarm at {at} s");
            let (named_at, flags) = t.named.expect("named");
            assert_eq!(flags, Flags::CAPILLARY_RESTRICTED, "{what}");
            assert!((60.0..120.0).contains(&named_at), "{what}: named at {named_at} s");
            assert!(
                (f64::from(t.last.divider) - 1.25).abs() < 0.05 * 1.25,
                "{what}: divider {}",
                t.last.divider
            );
            assert!(
                f64::from(t.last.probe_bias.abs()) < raw.probe.tolerance_at(40.0),
                "{what}: probe bias {}",
                t.last.probe_bias
            );
        }
    }
}
