//! The fault-injection campaign's reference of degraded devices
//! (`host_tests::campaign`): the truth is the reference equilibrium, each
//! fault moves the readings the way the dividers' algebra says, the
//! sticking plunger follows the play operator, the probe its lag, the
//! second sensor's noise its specification, and everything is
//! deterministic per seed.

use compensator::params::{RawCore, RawParams};
use compensator_reference::dynamics::{self, Method};
use host_tests::campaign::{
    Device, Fault, Injection, Probe, Profile, Quantity, SPREAD, Scenario, SecondSensor, Truth, as_built, catalogue,
    design, free_displacement, play,
};
use host_tests::random::Rng;
use host_tests::reference::equilibrium;
use host_tests::repo_root;

fn paper() -> RawParams {
    compensator_cli::load(&repo_root().join("presets/paper.toml")).unwrap()
}

/// The paper preset and two seeded random designs.
fn designs() -> Vec<RawParams> {
    vec![paper(), design(1), design(2)]
}

/// A temperature in the range where the device's plunger sits within
/// 20-80 % of its stroke (the middle of the longest such stretch).
fn mid_stroke(core: &RawCore, lo: f64, hi: f64) -> f64 {
    let inside = |t: f64| {
        let x = equilibrium(core, t).x / core.stroke;
        (0.2..=0.8).contains(&x)
    };
    let temps: Vec<f64> = (0..=200).map(|k| lo + (hi - lo) * f64::from(k) / 200.0).collect();
    let mut best = (0usize, 0usize);
    let mut start = None;
    for (i, &t) in temps.iter().enumerate() {
        match (inside(t), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                if i - s > best.1 - best.0 {
                    best = (s, i);
                }
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start
        && temps.len() - s > best.1 - best.0
    {
        best = (s, temps.len());
    }
    assert!(best.1 > best.0, "no temperature puts the plunger mid-stroke");
    temps[(best.0 + best.1 - 1) / 2]
}

#[test]
fn the_healthy_truth_is_the_reference_equilibrium_at_the_oils_temperature() {
    for raw in designs() {
        let s = Scenario::ordinary(&raw, Quantity::X, Injection::HEALTHY, 600.0, 7);
        let mut n = 0;
        for r in s.records().unwrap() {
            let e = equilibrium(&s.device, r.t_true);
            assert_eq!(
                (r.truth.p_a, r.truth.p_b, r.truth.x),
                (e.p_a, e.p_b, e.x),
                "t = {}",
                r.t
            );
            assert_eq!(r.t_true, s.profile.temperature(r.t));
            assert!(!r.fault_active);
            n += 1;
        }
        // 600 s at 100 Hz and the 50 Hz probe on the same ticks.
        assert_eq!(n, 60_001);
    }
}

#[test]
fn the_device_is_as_built_not_nominal_and_its_spread_is_the_documented_one() {
    let nominal = paper().core;
    let mut rng = Rng::new(3);
    let n = 4000;
    let rel: Vec<[f64; 4]> = (0..n)
        .map(|_| {
            let c = as_built(&nominal, &mut rng);
            [
                c.laminar_diameter / nominal.laminar_diameter - 1.0,
                c.turbulent_diameter / nominal.turbulent_diameter - 1.0,
                c.spring_rate / nominal.spring_rate - 1.0,
                c.preload / nominal.preload - 1.0,
            ]
        })
        .collect();
    let spread = [
        SPREAD.capillary_bore,
        SPREAD.orifice_bore,
        SPREAD.spring_rate,
        SPREAD.preload,
    ];
    for (j, s) in spread.iter().enumerate() {
        let mean = rel.iter().map(|r| r[j]).sum::<f64>() / n as f64;
        let sd = (rel.iter().map(|r| (r[j] - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        // Cut at 3 sigma: the sd is 0.9865 of the normal's.
        assert!(mean.abs() < 5.0 * s / (n as f64).sqrt(), "field {j}: mean {mean}");
        assert!((sd / s - 0.9865).abs() < 0.06, "field {j}: sd {sd} for {s}");
    }
    // A scenario's device differs from the nominal design.
    let s = Scenario::ordinary(&paper(), Quantity::PA, Injection::HEALTHY, 10.0, 1);
    assert_ne!(s.device, s.nominal.core);
    assert_eq!(s.device.pressure_drop, s.nominal.core.pressure_drop);
}

#[test]
fn the_free_displacement_follows_the_references_spring_convention() {
    // The reference's spring force is c (x0 + x): x = A dp / c - x0 inside
    // the stroke.
    for raw in designs() {
        let c = raw.core;
        let t = mid_stroke(&c, raw.estimator.valid_min, raw.estimator.valid_max);
        let e = equilibrium(&c, t);
        let x_free = free_displacement(&c, &e);
        assert!((x_free - e.x).abs() <= 1e-12 * c.stroke, "{x_free} vs {}", e.x);
        let y = [e.x, 0.0, e.p_a, e.p_b];
        let (ref_y, _) = dynamics::equilibrium(&c, t);
        assert_eq!(ref_y, y);
        // The sticking force: a fraction of c (x0 + stroke / 2).
        let f = Fault::Sticking(0.05).friction(&c);
        assert_eq!(f, 0.05 * c.spring_rate * (c.preload + 0.5 * c.stroke));
    }
}

#[test]
fn the_chamber_pressures_at_rest_do_not_depend_on_the_plunger() {
    for raw in designs() {
        let c = raw.core;
        for t in [raw.estimator.valid_min, 50.0, raw.estimator.valid_max] {
            let e = equilibrium(&c, t);
            // Spring and preload move the plunger (to a stop, even), not the
            // pressures: the chambers are dead-ended.
            for (rate, preload) in [(0.5, 1.0), (2.0, 0.0), (1.0, 3.0), (0.1, 0.0)] {
                let moved = RawCore {
                    spring_rate: c.spring_rate * rate,
                    preload: (c.preload * preload).min(c.stroke),
                    ..c
                };
                let m = equilibrium(&moved, t);
                assert_eq!((m.p_a, m.p_b), (e.p_a, e.p_b), "t = {t}");
            }
        }
        // A stuck plunger: the displacement lags, the pressures are the
        // equilibrium's.
        let inj = Injection {
            fault: Fault::Sticking(0.2),
            onset: 0.0,
        };
        let mut d = Device::new(&c, inj).unwrap();
        let mut lagged = false;
        for k in 0..=100 {
            let t =
                raw.estimator.valid_min + (raw.estimator.valid_max - raw.estimator.valid_min) * f64::from(k) / 100.0;
            let truth = d.at(f64::from(k), t);
            let e = equilibrium(&c, t);
            assert_eq!((truth.p_a, truth.p_b), (e.p_a, e.p_b));
            lagged |= (truth.x - e.x).abs() > 1e-3 * c.stroke;
        }
        assert!(lagged, "the sticking plunger never lagged");
    }
}

/// The signs of the change of (p_a, p_b, dp_ab, x) a fault makes at a
/// temperature where the plunger is mid-stroke (0: none).
fn signs(core: &RawCore, fault: Fault, t: f64) -> [i32; 4] {
    let inj = Injection { fault, onset: 0.0 };
    let healthy = Device::new(core, Injection::HEALTHY).unwrap().at(0.0, t);
    let faulty = Device::new(core, inj).unwrap().at(0.0, t);
    let sign = |d: f64, scale: f64| {
        if d.abs() <= 1e-12 * scale {
            0
        } else if d > 0.0 {
            1
        } else {
            -1
        }
    };
    let dp = core.pressure_drop;
    [
        sign(faulty.p_a - healthy.p_a, dp),
        sign(faulty.p_b - healthy.p_b, dp),
        sign(faulty.value(Quantity::DPAB) - healthy.value(Quantity::DPAB), dp),
        sign(faulty.x - healthy.x, core.stroke),
    ]
}

#[test]
fn each_fault_moves_the_readings_the_way_the_dividers_say() {
    // Chamber (a): orifice from p_p, capillary to p_c,
    //   K sqrt(p_p - p_a) = G (p_a - p_c).
    // A smaller conductance G (restricted capillary) or a larger K (worn
    // orifice) needs a larger p_a - p_c: p_a rises. Chamber (b): capillary
    // from p_p, orifice to p_c, G (p_p - p_b) = K sqrt(p_b - p_c): p_b
    // falls. So dp_ab = p_b - p_a falls and the plunger (A dp_ab = c (x0 +
    // x)) moves back. A clogged orifice is the opposite. The spring and the
    // preload leave the pressures and move the plunger out when they weaken.
    for raw in designs() {
        let c = raw.core;
        let t = mid_stroke(&c, raw.estimator.valid_min, raw.estimator.valid_max);
        let e = equilibrium(&c, t);
        // The divider's balance holds at the reference's root.
        let (nu, rho) = host_tests::reference::oil(&c, t);
        let g = std::f64::consts::PI * c.laminar_diameter.powi(4) / (128.0 * nu * rho * c.laminar_length);
        let k = c.turbulent_discharge * std::f64::consts::FRAC_PI_4 * c.turbulent_diameter.powi(2) * (2.0 / rho).sqrt();
        let pp = c.outlet_pressure + c.pressure_drop;
        let q = g * (e.p_a - c.outlet_pressure);
        assert!((k * (pp - e.p_a).sqrt() - q).abs() <= 1e-9 * q);

        for (fault, want) in [
            (Fault::CapillaryRestricted(0.9), [1, -1, -1, -1]),
            (Fault::CapillaryRestricted(0.8), [1, -1, -1, -1]),
            (Fault::OrificeWorn(1.1), [1, -1, -1, -1]),
            (Fault::OrificeWorn(1.2), [1, -1, -1, -1]),
            (Fault::OrificeClogged(0.9), [-1, 1, 1, 1]),
            (Fault::SpringRelaxed(0.9), [0, 0, 0, 1]),
            (Fault::PreloadLost(0.8), [0, 0, 0, 1]),
            (Fault::Sticking(0.05), [0, 0, 0, 0]),
            (Fault::SensorOffset(0.01), [0, 0, 0, 0]),
            (Fault::None, [0, 0, 0, 0]),
        ] {
            assert_eq!(signs(&c, fault, t), want, "{fault} at {t:.1} C");
        }
        // The preload's loss moves the plunger by exactly what is lost.
        let lost = Device::new(
            &c,
            Injection {
                fault: Fault::PreloadLost(0.8),
                onset: 0.0,
            },
        )
        .unwrap()
        .at(0.0, t);
        assert!((lost.x - e.x - 0.2 * c.preload).abs() <= 1e-12 * c.stroke);
    }
}

#[test]
fn a_fault_is_a_step_at_its_onset_and_the_offset_shifts_the_reading() {
    let raw = paper();
    let onset = 30.0;
    for fault in [Fault::CapillaryRestricted(0.8), Fault::SensorOffset(0.01)] {
        let inj = Injection { fault, onset };
        let mut s = Scenario::ordinary(&raw, Quantity::PA, inj, 60.0, 4);
        s.profile = Profile::hold(50.0);
        s.sensor.noise_sd = 0.0;
        let healthy = Device::new(&s.device, Injection::HEALTHY).unwrap().at(0.0, 50.0);
        let faulty = Device::new(&s.device, Injection { fault, onset: 0.0 })
            .unwrap()
            .at(0.0, 50.0);
        for r in s.records().unwrap() {
            assert_eq!(r.fault_active, r.t >= onset);
            let want_truth = if r.t >= onset { faulty } else { healthy };
            assert_eq!(r.truth, want_truth);
            if let Some(v) = r.second {
                let extra = if r.t >= onset { fault.offset(&s.sensor) } else { 0.0 };
                let want = s.sensor.quantise(want_truth.p_a + s.sensor_offset + extra);
                assert_eq!(v, want, "{fault} at {} s", r.t);
            }
        }
    }
    // An offset of 1 % of the span is 1 % of the span.
    let sensor = SecondSensor::default_for(Quantity::PA, &raw.core);
    let span = raw.core.outlet_pressure + raw.core.pressure_drop;
    assert_eq!(sensor.span, (0.0, span));
    assert!((Fault::SensorOffset(0.01).offset(&sensor) - 0.01 * span).abs() < 1e-9 * span);
}

#[test]
fn the_sticking_plunger_follows_the_play_operator() {
    assert_eq!(play(0.5, 0.75, 0.125, 1.0), 0.625);
    assert_eq!(play(0.5, 0.5625, 0.125, 1.0), 0.5);
    assert_eq!(play(0.5, 0.25, 0.125, 1.0), 0.375);
    assert_eq!(play(0.0625, -0.5, 0.125, 1.0), 0.0);
    assert_eq!(play(0.9375, 1.5, 0.125, 1.0), 1.0);
    for raw in designs() {
        let c = raw.core;
        let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
        let inj = Injection {
            fault: Fault::Sticking(0.05),
            onset: 0.0,
        };
        let mut d = Device::new(&c, inj).unwrap();
        let band = d.friction / c.spring_rate;
        assert!(band > 0.0);
        // Up over the range, down, up again: 0.02 C a sample.
        let mut temps: Vec<f64> = Vec::new();
        let n = ((hi - lo) / 0.02) as usize;
        for k in 0..=n {
            temps.push(lo + (hi - lo) * k as f64 / n as f64);
        }
        let up = temps.clone();
        temps.extend(up.iter().rev().skip(1));
        temps.extend(up.iter().skip(1));
        let mut prev: Option<Truth> = None;
        let mut lagging = [0usize; 2];
        for (i, &t) in temps.iter().enumerate() {
            let truth = d.at(i as f64, t);
            let x_eq = truth.x_free.clamp(0.0, c.stroke);
            assert_eq!(x_eq, equilibrium(&c, t).x);
            // Within F / k of the frictionless equilibrium.
            assert!((truth.x - x_eq).abs() <= band * (1.0 + 1e-12), "{t} C");
            if let Some(p) = prev {
                let dx_free = truth.x_free - p.x_free;
                let dx = truth.x - p.x;
                // It never moves against the force, and lags in the
                // direction of motion: behind on the way out, ahead ...
                assert!(dx * dx_free >= 0.0, "moved against the force at {t} C");
                if dx != 0.0 && truth.x > 0.0 && truth.x < c.stroke {
                    if dx > 0.0 {
                        assert!((truth.x - (truth.x_free - band)).abs() <= 1e-12 * c.stroke);
                        lagging[0] += 1;
                    } else {
                        assert!((truth.x - (truth.x_free + band)).abs() <= 1e-12 * c.stroke);
                        lagging[1] += 1;
                    }
                }
            }
            prev = Some(truth);
        }
        assert!(lagging[0] > 10 && lagging[1] > 10, "{lagging:?}");
        // At the top reversal it holds until the free displacement has
        // crossed the band.
        let top = up.len() - 1;
        let mut d2 = Device::new(&c, inj).unwrap();
        let mut at_top = 0.0;
        for (i, &t) in temps.iter().enumerate().take(top + 20) {
            let truth = d2.at(i as f64, t);
            if i == top {
                at_top = truth.x;
            }
            if i > top && (truth.x_free - at_top).abs() < band && at_top < c.stroke {
                assert_eq!(truth.x, at_top, "moved within the band at {t} C");
            }
        }
    }
}

#[test]
fn the_quasi_static_truth_matches_the_reference_dynamics_on_a_slow_ramp() {
    // The frictionless faults (sticking: the next test).
    let raw = paper();
    let (from, to, rate) = (40.0, 60.0, 0.2);
    let dt = 0.1;
    for fault in [Fault::None, Fault::CapillaryRestricted(0.8), Fault::SpringRelaxed(0.9)] {
        let core = fault.degrade(&raw.core);
        let profile = dynamics::Profile::Ramp { from, to, rate };
        let t_end = (to - from) / rate + 5.0;
        let run = dynamics::simulate(&core, profile, t_end, dt, Method::Radau5, 1e-8).unwrap();
        let ours = Profile::ramp(from, to, rate, 0.0);
        let mut device = Device::new(&core, Injection::HEALTHY).unwrap();
        let mut worst = (0.0f64, 0.0f64);
        for (t, y) in run.time.iter().zip(&run.state) {
            let truth = device.at(*t, ours.temperature(*t));
            worst.0 = worst.0.max((truth.x - y[0]).abs() / core.stroke);
            worst.1 = worst
                .1
                .max((truth.p_a - y[2]).abs().max((truth.p_b - y[3]).abs()) / core.pressure_drop);
        }
        // The plunger lags the ramp by its settling time (~40 ms at 40 C):
        // 0.2 C/s is a few 1e-4 of the stroke.
        assert!(worst.0 < 1e-3 && worst.1 < 1e-3, "{fault}: {worst:?}");
    }
}

#[test]
fn the_play_operator_matches_the_reference_dynamics_with_coulomb_friction() {
    // The stiff solver with Coulomb friction (stick and slip as events) on
    // a slow ramp each way: the plunger sticks until the force imbalance
    // reaches the friction, then slides F / c behind the frictionless
    // equilibrium, and sticks where the ramp ends.
    let raw = paper();
    let c = raw.core;
    for frac in [0.02, 0.05] {
        let fault = Fault::Sticking(frac);
        let friction = fault.friction(&c);
        let band = friction / c.spring_rate;
        for (from, to) in [(40.0, 50.0), (50.0, 40.0)] {
            let rate = 0.2;
            let profile = dynamics::Profile::Ramp { from, to, rate };
            let t_end = (to - from).abs() / rate + 5.0;
            let run =
                dynamics::simulate_with_friction(&c, profile, friction, t_end, 0.05, Method::Radau5, 1e-8).unwrap();
            let ours = Profile::ramp(from, to, rate, 0.0);
            let mut device = Device::new(&c, Injection { fault, onset: 0.0 }).unwrap();
            let mut worst = 0.0f64;
            for (t, y) in run.time.iter().zip(&run.state) {
                let truth = device.at(*t, ours.temperature(*t));
                worst = worst.max((truth.x - y[0]).abs() / c.stroke);
            }
            let end = device.at(t_end, to);
            let x_eq = equilibrium(&c, to).x;
            // It ends stuck a band short of the equilibrium, in the
            // direction it came from.
            assert!((end.x - (x_eq - band * (to - from).signum())).abs() < 1e-9 * c.stroke);
            assert!(
                (run.state.last().unwrap()[0] - end.x).abs() < 1e-3 * c.stroke,
                "{fault}, {from} -> {to} C: ends at {} vs {}",
                run.state.last().unwrap()[0],
                end.x
            );
            // 5e-5 of the stroke seen (the band is 1-2.5e-2): the plunger's
            // own lag behind the ramp.
            assert!(worst < 2e-4, "{fault}, {from} -> {to} C: worst {worst} of the stroke");
            assert!(
                run.events.iter().any(|e| e.1 == dynamics::Mode::Free),
                "{fault}: the plunger never slid"
            );
        }
    }
}

#[test]
fn the_reference_without_friction_is_unchanged_by_the_friction_option() {
    let raw = paper();
    let profile = dynamics::Profile::Step { from: 30.0, to: 70.0 };
    let a = dynamics::simulate(&raw.core, profile, 0.2, 1e-3, Method::Radau5, 1e-8).unwrap();
    let b = dynamics::simulate_with_friction(&raw.core, profile, 0.0, 0.2, 1e-3, Method::Radau5, 1e-8).unwrap();
    assert_eq!(a.state, b.state);
    assert_eq!(a.events, b.events);
    assert!(dynamics::simulate_with_friction(&raw.core, profile, -1.0, 0.2, 1e-3, Method::Radau5, 1e-8).is_err());
}

#[test]
fn the_probe_lags_as_exp_minus_t_over_tau() {
    let mut raw = paper();
    let tau = raw.probe.time_constant;
    raw.probe.well_time_constant = 0.0;
    let step = Profile::step(40.0, 50.0, 0.0);
    let mut p = Probe::new(&raw, 0.0, 40.0);
    let mut t = 0.0;
    for k in 1..=400 {
        let t1 = 0.1 * f64::from(k);
        p.advance_through(&step, t, t1);
        t = t1;
        let want = 50.0 - 10.0 * (-t / tau).exp();
        assert!((p.element - want).abs() < 1e-12, "{t} s: {} vs {want}", p.element);
    }
    // A well in series: the two-lag step response.
    raw.probe.well_time_constant = 20.0;
    let tw = 20.0;
    let mut p = Probe::new(&raw, 0.0, 40.0);
    let mut t = 0.0;
    for k in 1..=200 {
        let t1 = 0.5 * f64::from(k);
        p.advance_through(&step, t, t1);
        t = t1;
        let want = 50.0 - 10.0 * (tau * (-t / tau).exp() - tw * (-t / tw).exp()) / (tau - tw);
        assert!((p.element - want).abs() < 1e-4, "{t} s: {} vs {want}", p.element);
    }
    // Through the records: noise off, the probe within its tolerance at
    // `class`, read by the MAX31865.
    let mut raw = paper();
    raw.probe.well_time_constant = 0.0;
    raw.probe.noise = 0.0;
    let mut s = Scenario::ordinary(&raw, Quantity::X, Injection::HEALTHY, 30.0, 2);
    s.profile = Profile::step(40.0, 50.0, 1.0);
    let resolution = raw.estimator.resolution(50.0);
    let mut readings = 0;
    for r in s.records().unwrap() {
        if let Some(y) = r.probe {
            let element = if r.t <= 1.0 {
                40.0
            } else {
                50.0 - 10.0 * (-(r.t - 1.0) / tau).exp()
            };
            let want = element + s.probe_class * raw.probe.tolerance_at(element);
            assert!((y - want).abs() <= 0.6 * resolution, "{} s: {y} vs {want}", r.t);
            readings += 1;
        }
    }
    // Every 20 ms (50 Hz mains).
    assert_eq!(readings, 1501);

    // An NTC on the ADC: its readings within its own resolution.
    let mut raw = host_tests::soak::paper_ntc();
    raw.probe.noise = 0.0;
    let mut s = Scenario::ordinary(&raw, Quantity::X, Injection::HEALTHY, 5.0, 2);
    s.profile = Profile::hold(50.0);
    s.probe_class = 0.0;
    let resolution = raw.estimator.resolution(50.0);
    let mut readings = 0;
    for y in s.records().unwrap().filter_map(|r| r.probe) {
        assert!((y - 50.0).abs() <= 0.6 * resolution, "{y} for 50 C");
        readings += 1;
    }
    assert!(readings > 100);
}

#[test]
fn the_second_sensors_noise_has_the_specified_mean_and_sd() {
    let raw = paper();
    for quantity in [Quantity::PA, Quantity::X] {
        let mut s = Scenario::ordinary(&raw, quantity, Injection::HEALTHY, 1000.0, 11);
        s.profile = Profile::hold(50.0);
        let truth = equilibrium(&s.device, 50.0);
        let value = match quantity {
            Quantity::PA => truth.p_a,
            _ => truth.x,
        };
        let v: Vec<f64> = s.records().unwrap().filter_map(|r| r.second).collect();
        let n = v.len() as f64;
        assert_eq!(v.len(), 100_001);
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1.0);
        // The noise and the 12-bit quantisation (Sheppard: + q^2 / 12 for a
        // noise of a few steps).
        let q = s.sensor.lsb();
        let sigma2 = s.sensor.noise_sd.powi(2) + q * q / 12.0;
        assert!(s.sensor.noise_sd > 1.5 * q);
        // The mean: the truth and the device's offset, within 5 standard
        // errors.
        let want = value + s.sensor_offset;
        assert!(
            (mean - want).abs() < 5.0 * (sigma2 / n).sqrt(),
            "{quantity:?}: mean {mean} vs {want}"
        );
        // (n - 1) s^2 / sigma^2 is chi-square with n - 1 degrees of freedom:
        // within 5 of its standard deviations sqrt(2 (n - 1)).
        let chi = (n - 1.0) * var / sigma2;
        assert!(
            (chi - (n - 1.0)).abs() < 5.0 * (2.0 * (n - 1.0)).sqrt(),
            "{quantity:?}: chi-square {chi} for {} degrees of freedom",
            n - 1.0
        );
        // The device's offset is within its class.
        assert!(s.sensor_offset.abs() <= s.sensor.accuracy * s.sensor.width());
    }
}

#[test]
fn the_histories_are_ordinary_operation_within_the_validated_range() {
    for raw in designs() {
        let range = (raw.estimator.valid_min, raw.estimator.valid_max);
        for seed in 0..20 {
            let p = Profile::ordinary(range, 4.0 * 3600.0, seed);
            let (lo, hi) = p.extent();
            assert!(
                lo >= range.0 && hi <= range.1,
                "seed {seed}: {lo}..{hi} outside {range:?}"
            );
            assert!(p.max_rate() <= 1.0 + 1e-12, "seed {seed}: {} C/s", p.max_rate());
            assert_eq!(p.end(), 4.0 * 3600.0);
            // A cold start warming at 0.01-0.1 C/s.
            let k = p.knots();
            assert!(
                k[0].1 >= range.0 && k[0].1 <= range.0.max(26.0) + 4.0 + 1e-9,
                "cold start {}",
                k[0].1
            );
            let warm = (k[2].1 - k[1].1) / (k[2].0 - k[1].0);
            assert!((0.01..=0.1).contains(&warm), "warm-up {warm} C/s");
            assert_eq!(p.warmed_up(), k[2].0);
            assert!(k[2].1 >= 0.5 * (range.0 + range.1));
            // Steps of 5 C or more after it.
            let big = k.windows(2).filter(|w| (w[1].1 - w[0].1).abs() >= 5.0).count();
            assert!(big >= 3, "seed {seed}: {big} changes of 5 C or more");
            assert_eq!(p, Profile::ordinary(range, 4.0 * 3600.0, seed));
        }
    }
    let day = Profile::day((26.0, 78.0), 5);
    assert_eq!(day.end(), 86_400.0);
    assert!(day.knots().len() > 1000);
    assert_ne!(day, Profile::day((26.0, 78.0), 6));
}

#[test]
fn the_records_are_deterministic_per_seed() {
    let raw = design(3);
    let inj = Injection {
        fault: Fault::Sticking(0.05),
        onset: 100.0,
    };
    let take = |seed: u64| {
        let s = Scenario::ordinary(&raw, Quantity::DPAB, inj, 300.0, seed);
        let r: Vec<_> = s.records().unwrap().collect();
        (s.device, s.profile.clone(), r)
    };
    let (a, b, c) = (take(9), take(9), take(10));
    assert_eq!(a, b);
    assert_ne!(a.0, c.0);
    assert_ne!(a.1, c.1);
    assert_ne!(a.2, c.2);
}

#[test]
fn a_catalogue_pairs_every_fault_on_one_device_and_history() {
    let raw = design(4);
    let runs = catalogue(&raw, Quantity::X, 3600.0, 12);
    assert_eq!(runs.len(), Fault::CATALOGUE.len());
    assert_eq!(runs[0].injection.fault, Fault::None);
    let onset = runs[0].injection.onset;
    assert!(onset > runs[0].profile.warmed_up() && onset < 3600.0);
    for r in &runs {
        assert_eq!(r.device, runs[0].device);
        assert_eq!(r.profile, runs[0].profile);
        assert_eq!(
            (r.probe_class, r.sensor_offset, r.noise_seed),
            (runs[0].probe_class, runs[0].sensor_offset, runs[0].noise_seed)
        );
        assert_eq!(r.injection.onset, onset);
    }
    // Before the onset the records of every fault are the healthy ones (the
    // first five minutes compared).
    let before = |s: &Scenario| -> Vec<_> { s.records().unwrap().take_while(|r| r.t < onset.min(300.0)).collect() };
    let healthy = before(&runs[0]);
    for r in &runs[1..] {
        assert_eq!(before(r), healthy, "{}", r.injection.fault);
    }
}

#[test]
fn the_estimated_stream_gives_one_observation_per_second_reading() {
    let raw = paper();
    let inj = Injection {
        fault: Fault::OrificeWorn(1.2),
        onset: 60.0,
    };
    let mut s = Scenario::ordinary(&raw, Quantity::PB, inj, 120.0, 8);
    s.profile = Profile::ramp(45.0, 55.0, 0.1, 10.0);
    let obs: Vec<_> = s.estimated().unwrap().collect();
    assert_eq!(obs.len(), 12_001);
    let tol = raw.probe.tolerance_at(55.0) + 0.1;
    for o in &obs {
        assert_eq!(o.fault_active, o.t >= 60.0);
        // After the observer's start-up, the estimate follows the oil
        // within the probe's tolerance and a little.
        if o.t > 30.0 {
            assert!(
                (o.t_estimated - o.t_true).abs() < tol,
                "{} s: {} vs {}",
                o.t,
                o.t_estimated,
                o.t_true
            );
        }
        assert!((o.second - o.truth.p_b).abs() < 0.01 * s.sensor.width());
    }
}

#[test]
fn faults_parse_check_and_degrade() {
    for f in Fault::CATALOGUE {
        f.check().unwrap();
        let text = match f.severity() {
            Some(v) => format!("{}:{v}", f.name()),
            None => "none".into(),
        };
        assert_eq!(Fault::parse(&text).unwrap(), f);
        Device::new(&paper().core, Injection { fault: f, onset: 0.0 }).unwrap();
    }
    for bad in [
        "capillary:1.2",
        "orifice-worn:0.9",
        "sticking:-0.1",
        "spring",
        "leak:0.5",
    ] {
        assert!(Fault::parse(bad).is_err(), "{bad}");
    }
    let c = paper().core;
    let g = |c: &RawCore| c.laminar_diameter.powi(4);
    assert!((g(&Fault::CapillaryRestricted(0.8).degrade(&c)) / g(&c) - 0.8).abs() < 1e-12);
    let a = |c: &RawCore| c.turbulent_diameter.powi(2);
    assert!((a(&Fault::OrificeWorn(1.2).degrade(&c)) / a(&c) - 1.2).abs() < 1e-12);
    assert_eq!(Quantity::parse("dp_ab"), Some(Quantity::DPAB));
}
