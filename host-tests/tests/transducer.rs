//! The condition monitor's second sensor: the transducer driver's code to
//! reading conversion for both outputs (hand-computed points), its fault
//! levels (NAMUR NE 43 for 4-20 mA, the ratiometric limits), the stuck and
//! noise checks against an independent computation of their bounds (the
//! Gaussian's probability of one code, the chi-square tail), the
//! register-level simulator with each injected fault and a healthy sensor
//! over 1e6 readings, and the `[monitor]` section of the device file (each
//! bad field refused naming it).

use compensator::params::{Problem, RawMonitor};
use compensator::sensor::device::monitor_settings;
use compensator::sensor::ntc::{AdcChannel, RegisterAdc};
use compensator::sensor::transducer::{
    self, Limits, NOISE_CHI2, NOISE_WINDOW, Output, Quantity, STUCK_MAX, Settings, SimulatedTransducer, Transducer,
    TransducerFault,
};
use compensator::sensor::{Detail, SensorFault};
use compensator_cli::{LoadError, params_file};
use host_tests::repo_root;

// ---------------------------------------------------------------------
// Settings by hand.

/// A 0-5 bar (0 to 5e5 Pa) transducer, 100 Pa of noise, class 0.1 %, 12
/// bits, 100 Hz, on either output: ratiometric through 0.66 (so that
/// `V_out = code 3.3 / 4096 / 0.66 = code 5 / 4096` V) or 4-20 mA into 150
/// ohm (`I = code 3.3 / 4096 / 150 A = code 22 / 4096` mA).
fn pressure(output: Output) -> Settings {
    Settings::new(Quantity::PressureA, output, (0.0, 5.0e5), 100.0, 0.001, 12, 100.0).unwrap()
}

const RATIOMETRIC: Output = Output::Ratiometric { divider: 0.66 };
const CURRENT: Output = Output::Current { shunt: 150.0 };

/// An ADC that returns these codes, last first; an error when none is left.
struct Codes(Vec<u16>);
impl AdcChannel for Codes {
    type Error = ();
    fn read_code(&mut self) -> Result<u16, ()> {
        self.0.pop().ok_or(())
    }
}

fn close(a: f32, b: f64, tol: f64) -> bool {
    (f64::from(a) - b).abs() <= tol
}

#[test]
fn ratiometric_codes_read_as_their_pressure() {
    let s = pressure(RATIOMETRIC);
    // V = code 5 / 4096; p = (V - 0.5) / 4 * 5e5.
    for (code, p) in [
        (1024u16, 93_750.0),    // 1.25 V
        (2048, 250_000.0),      // 2.5 V
        (3072, 406_250.0),      // 3.75 V
        (410, 61.035_156_25),   // 0.500 488 V: just above range_min
        (3686, 499_938.964_84), // 4.499 51 V: just below range_max
    ] {
        let r = s.classify(code).unwrap();
        assert!(close(r, p, 0.1), "{code}: {r} vs {p}");
        assert!(close(s.reading_of_code(f32::from(code)), p, 0.1));
    }
    // One code is 5 / 4096 V of 4 V over 5e5 Pa: 152.59 Pa.
    assert!(close(s.units_per_code(), 5.0e5 * 5.0 / 4096.0 / 4.0, 1e-3));
    // Class 0.1 % of 5e5 Pa: +-500 Pa, standard uncertainty 500 / sqrt 3.
    assert!(close(s.class_uncertainty(), 500.0 / 3f64.sqrt(), 1e-3));
    // The simulator's inverse: the code of a reading is the nearest.
    assert_eq!(s.code_of(250_000.0), 2048);
    assert_eq!(s.code_of(93_750.0 + 70.0), 1024);
}

#[test]
fn current_loop_codes_read_as_their_pressure() {
    let s = pressure(CURRENT);
    // I = code 22 / 4096 mA; p = (I - 4) / 16 * 5e5.
    for (code, p) in [
        (1024u16, 46_875.0), // 5.5 mA
        (2048, 218_750.0),   // 11 mA
        (3072, 390_625.0),   // 16.5 mA
        (745, 45.776_367),   // 4.001 46 mA
    ] {
        let r = s.classify(code).unwrap();
        assert!(close(r, p, 0.05), "{code}: {r} vs {p}");
    }
    // 16 mA over 150 ohm is 2.4 V, 2978.9 codes over 5e5 Pa.
    assert!(close(s.units_per_code(), 5.0e5 / (2.4 / 3.3 * 4096.0), 1e-3));
}

#[test]
fn a_displacement_sensor_reads_metres() {
    let s = Settings::new(
        Quantity::Displacement,
        RATIOMETRIC,
        (0.0, 0.002),
        1.0e-6,
        0.005,
        12,
        100.0,
    )
    .unwrap();
    assert_eq!(s.quantity.unit(), "m");
    assert!(close(s.classify(2048).unwrap(), 0.001, 1e-9));
    assert!(close(s.classify(1024).unwrap(), 0.000_375, 1e-9));
}

#[test]
fn ratiometric_fault_levels() {
    let s = pressure(RATIOMETRIC);
    let code = Detail::code;
    // 0.25 V is code 204.8, 0.45 V 368.64, 4.625 V 3788.8, 4.75 V 3891.2.
    assert_eq!(s.classify(0), Err(SensorFault::OpenCircuit(code(0))));
    assert_eq!(s.classify(204), Err(SensorFault::OpenCircuit(code(204))));
    assert_eq!(s.classify(205), Err(SensorFault::OutOfRange(code(205))));
    assert_eq!(s.classify(368), Err(SensorFault::OutOfRange(code(368))));
    assert!(s.classify(369).is_ok());
    assert!(s.classify(3788).is_ok());
    assert_eq!(s.classify(3789), Err(SensorFault::OutOfRange(code(3789))));
    assert_eq!(s.classify(3891), Err(SensorFault::OutOfRange(code(3891))));
    assert_eq!(s.classify(3892), Err(SensorFault::ShortCircuit(code(3892))));
    assert_eq!(s.classify(4095), Err(SensorFault::ShortCircuit(code(4095))));
    // Just below range_min (0.45-0.5 V) is a reading, a little negative.
    assert!(s.classify(400).unwrap() < 0.0);
}

#[test]
fn current_loop_fault_levels_are_namur_ne43() {
    let s = pressure(CURRENT);
    assert_eq!(s.output.limits(), Limits::NAMUR_NE43);
    let code = Detail::code;
    // 3.6 mA is code 670.25, 3.8 mA 707.5, 20.5 mA 3816.7, 21 mA 3909.8.
    assert_eq!(s.classify(0), Err(SensorFault::OpenCircuit(code(0))));
    assert_eq!(s.classify(670), Err(SensorFault::OpenCircuit(code(670))));
    assert_eq!(s.classify(671), Err(SensorFault::OutOfRange(code(671))));
    assert_eq!(s.classify(707), Err(SensorFault::OutOfRange(code(707))));
    assert!(s.classify(708).is_ok());
    assert!(s.classify(3816).is_ok());
    assert_eq!(s.classify(3817), Err(SensorFault::OutOfRange(code(3817))));
    assert_eq!(s.classify(3909), Err(SensorFault::OutOfRange(code(3909))));
    assert_eq!(s.classify(3910), Err(SensorFault::ShortCircuit(code(3910))));
    assert_eq!(s.classify(4095), Err(SensorFault::ShortCircuit(code(4095))));
}

#[test]
fn the_driver_reads_codes_from_any_adc_channel() {
    let s = pressure(RATIOMETRIC);
    let mut drv = Transducer::new(Codes(vec![0, 2048, 1024]), s);
    assert!(close(drv.read().unwrap(), 93_750.0, 0.05));
    assert!(close(drv.read().unwrap(), 250_000.0, 0.05));
    assert_eq!(drv.read(), Err(SensorFault::OpenCircuit(Detail::code(0))));
    // The ADC's error: Bus, as the channel says.
    assert_eq!(drv.read(), Err(SensorFault::Bus));
    assert_eq!(drv.read_reading(), Err(transducer::Error::Adc(())));
}

#[test]
fn the_register_level_simulator_converts_forced_codes_like_the_mock() {
    for output in [RATIOMETRIC, CURRENT] {
        let s = pressure(output);
        let mut drv = transducer::simulated(s, 0.0, 1);
        for code in [0u16, 205, 1024, 2048, 3072, 3789, 4095] {
            drv.device_mut().registers_mut().forced_code = Some(code);
            assert_eq!(drv.read(), s.classify(code), "{output:?} {code}");
        }
        // At 10 bits the register driver masks and the settings follow.
        let s10 = Settings::new(Quantity::PressureA, output, (0.0, 5.0e5), 100.0, 0.001, 10, 100.0).unwrap();
        let mut drv = transducer::simulated(s10, 0.0, 1);
        drv.device_mut().registers_mut().forced_code = Some(512);
        assert_eq!(drv.read(), s10.classify(512));
        assert!(close(
            s10.classify(512).unwrap(),
            s.classify(2048).unwrap().into(),
            1e-3
        ));
    }
}

// ---------------------------------------------------------------------
// The stuck and noise checks' bounds, computed independently.

/// P(|n| < 0.5) for a normal n of standard deviation `sigma`, by Simpson's
/// rule over its density (no erf).
fn within_half_code(sigma: f64) -> f64 {
    let n = 20_000;
    let h = 1.0 / f64::from(n);
    let pdf = |x: f64| (-(x * x) / (2.0 * sigma * sigma)).exp() / (sigma * (2.0 * std::f64::consts::PI).sqrt());
    let mut s = pdf(-0.5) + pdf(0.5);
    for i in 1..n {
        let x = -0.5 + f64::from(i) * h;
        s += pdf(x) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

#[test]
fn the_stuck_count_keeps_a_healthy_sensor_below_1e9() {
    for sigma in [0.2, 0.35, 0.5, 0.655, 1.0, 2.0, 5.0, 30.0] {
        let p = within_half_code(sigma);
        let n = transducer::stuck_after(sigma);
        assert!(n >= 2, "{sigma}");
        // The chance that n codes in a row agree is at most p^(n-1).
        assert!(p.powi(n as i32 - 1) <= 1.0e-9 * (1.0 + 1e-6), "{sigma}: {n}");
        assert!(p.powi(n as i32 - 2) > 1.0e-9, "{sigma}: {n} is not the smallest");
    }
    // No noise, or far below a code: the check is off.
    assert_eq!(transducer::stuck_after(0.0), 0);
    assert_eq!(transducer::stuck_after(0.02), 0);
    const { assert!(STUCK_MAX >= 1000) };
    // The preset's transducer: 100 Pa of noise, 152.6 Pa a code.
    let s = pressure(RATIOMETRIC);
    assert_eq!(
        s.stuck_after,
        transducer::stuck_after(f64::from(100.0 / s.units_per_code()))
    );
    assert_eq!(s.stuck_after, 37);
}

/// The regularised upper incomplete gamma Q(a, x) (continued fraction,
/// Lentz; x > a + 1 here).
fn upper_gamma_q(a: f64, x: f64) -> f64 {
    let ln_gamma = |z: f64| {
        // Lanczos (g = 7, n = 9).
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let z = z - 1.0;
        let mut s = C[0];
        for (i, c) in C.iter().enumerate().skip(1) {
            s += c / (z + i as f64);
        }
        let t = z + 7.5;
        0.5 * (2.0 * std::f64::consts::PI).ln() + (z + 0.5) * t.ln() - t + s.ln()
    };
    let tiny = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..10_000 {
        let an = -f64::from(i) * (f64::from(i) - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < tiny {
            d = tiny;
        }
        c = b + an / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-15 {
            break;
        }
    }
    (-x + a * x.ln() - ln_gamma(a)).exp() * h
}

#[test]
fn the_noise_limit_is_the_chi_square_quantile_of_1e9() {
    // The window's residuals about its least-squares parabola: three
    // degrees of freedom fewer than its codes.
    let dof = f64::from(NOISE_WINDOW - 3);
    let q = upper_gamma_q(dof / 2.0, f64::from(NOISE_CHI2) / 2.0);
    assert!((q / 1.0e-9 - 1.0).abs() < 1e-3, "{q}");
    // The check's limit: K (sigma_c + 0.5)^2.
    let s = pressure(RATIOMETRIC);
    let sigma = f64::from(100.0 / s.units_per_code());
    let limit = f64::from(NOISE_CHI2) / dof * (sigma + 0.5).powi(2);
    assert!((f64::from(s.noise_limit) / limit - 1.0).abs() < 1e-5);
}

/// The residual variance about the least-squares parabola of `codes`,
/// fitted in `f64` by the normal equations on `x = i - (n - 1) / 2`
/// (solved by Cramer's rule: the reference for the driver's integer sums).
fn residual_variance(codes: &[u16]) -> f64 {
    let n = codes.len();
    let x = |i: usize| i as f64 - (n as f64 - 1.0) / 2.0;
    let (mut m, mut b) = ([[0.0f64; 3]; 3], [0.0f64; 3]);
    for (i, &c) in codes.iter().enumerate() {
        let p = [1.0, x(i), x(i) * x(i)];
        for r in 0..3 {
            b[r] += p[r] * f64::from(c);
            for k in 0..3 {
                m[r][k] += p[r] * p[k];
            }
        }
    }
    let det = |a: &[[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(&m);
    let coef: Vec<f64> = (0..3)
        .map(|k| {
            let mut a = m;
            for r in 0..3 {
                a[r][k] = b[r];
            }
            det(&a) / d
        })
        .collect();
    let rss: f64 = codes
        .iter()
        .enumerate()
        .map(|(i, &c)| (f64::from(c) - coef[0] - coef[1] * x(i) - coef[2] * x(i) * x(i)).powi(2))
        .sum();
    rss / (n as f64 - 3.0)
}

#[test]
fn the_noise_check_is_the_residual_variance_about_the_windows_parabola() {
    let s = pressure(RATIOMETRIC);
    // Windows of random codes, ramps, bends and noise against the f64 fit.
    let mut rng = host_tests::random::Rng::new(3);
    for case in 0..200 {
        let slope = rng.unit() * 40.0 - 20.0;
        let bend = rng.unit() * 1.0 - 0.5;
        let noise = rng.unit() * if case % 2 == 0 { 3.0 } else { 300.0 };
        let codes: Vec<u16> = (0..NOISE_WINDOW)
            .map(|i| {
                let i = f64::from(i);
                let v = 2048.0 + slope * i + bend * (i - 32.0).powi(2) + noise * (rng.unit() - 0.5);
                v.round().clamp(0.0, 4095.0) as u16
            })
            .collect();
        let mut checks = transducer::Checks::new(&s);
        for &c in &codes {
            let _ = checks.update(c);
        }
        let got = f64::from(checks.last_variance().expect("a complete window"));
        let want = residual_variance(&codes);
        assert!(
            (got - want).abs() <= 1e-5 * want.max(1.0),
            "case {case}: {got} against {want}"
        );
    }
}

#[test]
fn a_healthy_sensor_through_a_ramp_is_not_noisy() {
    // The paper preset's p_a through a 1 C/s move at 27 C: 8.4 kPa/s, 84
    // Pa (0.55 codes) a reading at 100 Hz, 35 codes a window: the plain
    // sample variance of a window would be 35^2 / 12 = 102 codes^2, thirty
    // times the limit; a bend into and out of the move, about a line, 6.
    // Thirty holds at 4e5 Pa, each followed by such a ramp down to 1.5e5
    // Pa, then a hold there, the bends at every phase of the window.
    for output in [RATIOMETRIC, CURRENT] {
        let s = pressure(output);
        assert!(s.noise_limit < 4.0, "{}", s.noise_limit);
        for seed in 0..30 {
            let mut drv = transducer::simulated(s, 4.0e5, seed);
            let hold = 100 + 2 * seed as u32;
            for k in 0..hold + 2976 + 200 {
                let ramp = k.saturating_sub(hold).min(2976);
                drv.device_mut().registers_mut().reading = 4.0e5 - 84.0 * ramp as f32;
                assert_eq!(drv.read().err(), None, "{output:?}, ramp {seed}, reading {k}");
            }
        }
    }
}

// ---------------------------------------------------------------------
// The simulator's faults and a healthy sensor.

/// Reads until the first error, at most `n` readings: the error and the
/// readings it took.
fn first_fault(drv: &mut transducer::SimulatedMonitor, n: u32) -> Option<(SensorFault, u32)> {
    (1..=n).find_map(|i| drv.read().err().map(|e| (e, i)))
}

#[test]
fn each_injected_fault_is_detected() {
    for output in [RATIOMETRIC, CURRENT] {
        let s = pressure(output);
        let sim = |fault| {
            let mut drv = transducer::simulated(s, 250_000.0, 7);
            for _ in 0..100 {
                assert!(drv.read().is_ok());
            }
            drv.device_mut().registers_mut().fault = fault;
            drv
        };
        let mut drv = sim(Some(TransducerFault::OpenLoop));
        assert_eq!(drv.read(), Err(SensorFault::OpenCircuit(Detail::code(0))));
        let mut drv = sim(Some(TransducerFault::Shorted));
        assert_eq!(drv.read(), Err(SensorFault::ShortCircuit(Detail::code(4095))));
        // Stuck: within stuck_after readings of the freeze.
        let mut drv = sim(Some(TransducerFault::Stuck));
        let (fault, after) = first_fault(&mut drv, 1000).expect("stuck detected");
        assert!(matches!(fault, SensorFault::Stuck(_)), "{fault:?}");
        assert!(after <= s.stuck_after, "{after}");
        assert!(drv.checks().run_length() >= s.stuck_after);
        // Noisy: ten times the noise, within two windows.
        let mut drv = sim(Some(TransducerFault::Noisy(10.0)));
        let (fault, after) = first_fault(&mut drv, 1000).expect("noisy detected");
        assert!(matches!(fault, SensorFault::Noisy(_)), "{fault:?}");
        assert!(after <= 2 * NOISE_WINDOW, "{after}");
        // A drift of 10 Pa a reading (slow: a fast one scatters a window's
        // codes and reads as noisy): out of range past 515 625 Pa (the
        // band's 3.125 % above 5e5 Pa), after 26 562 readings.
        let mut drv = sim(Some(TransducerFault::OffsetDrift(10.0)));
        let (fault, after) = first_fault(&mut drv, 30_000).expect("drift detected");
        assert!(matches!(fault, SensorFault::OutOfRange(_)), "{fault:?}");
        assert!((26_400..=26_700).contains(&after), "{after}");
        assert!(close(
            drv.device_mut().registers_mut().offset(),
            f64::from(after) * 10.0,
            1.0
        ));
        // A converter that no longer ends its conversions: stale.
        let mut drv = sim(Some(TransducerFault::AdcStuck));
        assert_eq!(drv.read(), Err(SensorFault::Stale));
        // Cleared: healthy again (the stuck run and the window restart).
        let mut drv = sim(Some(TransducerFault::OpenLoop));
        assert!(drv.read().is_err());
        drv.device_mut().registers_mut().fault = None;
        assert!(close(drv.read().unwrap(), 250_000.0, 1000.0));
        // An open loop for a while, then healthy: no stuck or noisy verdict
        // from the jump (a fault level restarts the checks).
        for episode in [1, 10, 100] {
            drv.device_mut().registers_mut().fault = Some(TransducerFault::OpenLoop);
            for _ in 0..episode {
                assert!(matches!(drv.read(), Err(SensorFault::OpenCircuit(_))));
            }
            drv.device_mut().registers_mut().fault = None;
            assert_eq!(first_fault(&mut drv, 1000), None, "{output:?} after {episode}");
        }
    }
}

#[test]
fn a_reading_beyond_the_range_is_out_of_range() {
    let s = pressure(CURRENT);
    let mut drv = transducer::simulated(s, 5.3e5, 3);
    assert!(matches!(drv.read(), Err(SensorFault::OutOfRange(_))));
    drv.device_mut().registers_mut().reading = -0.1e5;
    assert!(matches!(drv.read(), Err(SensorFault::OutOfRange(_))));
}

/// Readings of a healthy simulated sensor at `reading`: how many raised a
/// fault, and the readings' mean and standard deviation.
fn healthy(s: Settings, reading: f32, n: u32, seed: u64) -> (u32, f64, f64) {
    let mut drv = transducer::simulated(s, reading, seed);
    let (mut faults, mut sum, mut sum2) = (0, 0.0, 0.0);
    for _ in 0..n {
        match drv.read() {
            Ok(v) => {
                sum += f64::from(v);
                sum2 += f64::from(v) * f64::from(v);
            }
            Err(_) => faults += 1,
        }
    }
    let mean = sum / f64::from(n);
    (faults, mean, (sum2 / f64::from(n) - mean * mean).max(0.0).sqrt())
}

#[test]
fn a_healthy_sensor_raises_no_fault_over_a_million_readings() {
    // The preset's transducer at mid-range, on a code's centre (the worst
    // case for the stuck check: one code is the likeliest there).
    let s = pressure(RATIOMETRIC);
    let centre = s.reading_of_code(2048.0);
    let (faults, mean, sd) = healthy(s, centre, 1_000_000, 11);
    assert_eq!(faults, 0);
    assert!((mean - f64::from(centre)).abs() < 1.0, "{mean}");
    // 100 Pa of noise and the rounding's 152.6 / sqrt 12 = 44 Pa.
    assert!(
        (sd - (100.0f64.powi(2) + 152.6f64.powi(2) / 12.0).sqrt()).abs() < 3.0,
        "{sd}"
    );
    // A displacement sensor on a 4-20 mA loop with the plunger on its
    // closed stop (x = 0, at 4 mA exactly: the noise goes below it).
    let x = Settings::new(Quantity::Displacement, CURRENT, (0.0, 0.0015), 2.0e-6, 0.005, 12, 100.0).unwrap();
    let (faults, _, _) = healthy(x, 0.0, 1_000_000, 12);
    assert_eq!(faults, 0);
}

#[test]
fn the_simulator_is_deterministic_in_its_seed() {
    let s = pressure(RATIOMETRIC);
    let codes = |seed| {
        let mut adc = RegisterAdc::new(SimulatedTransducer::new(s, 2.0e5, seed), 12);
        (0..64).map(|_| adc.read_code().unwrap()).collect::<Vec<_>>()
    };
    assert_eq!(codes(5), codes(5));
    assert_ne!(codes(5), codes(6));
}

// ---------------------------------------------------------------------
// The device file's [monitor] section.

fn monitor_preset() -> String {
    std::fs::read_to_string(repo_root().join("presets/paper-monitor.toml")).unwrap()
}

/// The monitor preset with `[monitor] key` set to `value` (or removed).
fn edited(text: &str, key: &str, value: Option<&str>) -> String {
    let mut out = String::new();
    let mut section = String::new();
    let mut hit = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            if section == "monitor" && !hit {
                if let Some(v) = value {
                    out.push_str(&format!("{key} = {v}\n"));
                }
                hit = true;
            }
            section = t.trim_matches(|c| c == '[' || c == ']').to_string();
        }
        if section == "monitor" && t.split('=').next().map(str::trim) == Some(key) {
            hit = true;
            if let Some(v) = value {
                out.push_str(&format!("{key} = {v}\n"));
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    if !hit && let Some(v) = value {
        out.push_str(&format!("{key} = {v}\n"));
    }
    out
}

fn refused(text: &str) -> LoadError {
    params_file::parse(text).expect_err("refused")
}

#[test]
fn the_monitor_preset_reads_as_its_transducer() {
    let raw = params_file::parse(&monitor_preset()).unwrap();
    let m = raw.monitor;
    assert!(m.has_sensor() && m.is_pressure() && !m.is_current());
    assert_eq!(
        (m.range_min, m.range_max, m.accuracy, m.noise),
        (0.0, 5.0e5, 0.001, 100.0)
    );
    let s = monitor_settings(&raw).unwrap().expect("a sensor");
    assert_eq!(s, pressure(RATIOMETRIC));
    assert_eq!(Settings::try_from(&m).unwrap(), s);
    // The writer keeps the section; read back, the same set.
    let back = params_file::parse(&params_file::to_toml(&raw)).unwrap();
    assert_eq!(back, raw);
}

#[test]
fn without_the_section_there_is_no_second_sensor() {
    let text = std::fs::read_to_string(repo_root().join("presets/paper.toml")).unwrap();
    let raw = params_file::parse(&text).unwrap();
    assert_eq!(raw.monitor, RawMonitor::NONE);
    assert_eq!(monitor_settings(&raw), Ok(None));
    assert_eq!(
        Settings::try_from(&raw.monitor),
        Err(transducer::SettingsError::NoSensor)
    );
    assert!(!params_file::to_toml(&raw).contains("[monitor]"));
    // sensor = "none" with nothing else: the same.
    let none = params_file::parse(&format!("{text}\n[monitor]\nsensor = \"none\"\n")).unwrap();
    assert_eq!(none, raw);
}

/// The error of the monitor preset with `key = value`: its field, its
/// message.
fn bad(key: &str, value: Option<&str>) -> (Option<&'static str>, String) {
    let e = refused(&edited(&monitor_preset(), key, value));
    (e.field(), e.to_string())
}

#[test]
fn each_bad_monitor_field_is_refused_naming_it() {
    // A range in bar (6 for 6 bar) or MPa (0.5): below the supply pressure,
    // and the message says the unit is Pa.
    for v in ["6.0", "0.5", "5.0"] {
        let (field, msg) = bad("range_max", Some(v));
        assert_eq!(field, Some("monitor.range_max"), "{msg}");
        assert!(msg.contains("the unit is Pa"), "{msg}");
    }
    // Not above range_min.
    let (field, msg) = bad("range_min", Some("6e5"));
    assert_eq!(field, Some("monitor.range_max"), "{msg}");
    // A range_min above the outlet pressure (the chamber reads below it).
    let (field, msg) = bad("range_min", Some("1e5"));
    assert_eq!(field, Some("monitor.range_min"), "{msg}");
    // A span of more than 100 supply pressures.
    let (field, msg) = bad("range_max", Some("5e8"));
    assert_eq!(field, Some("monitor.range_max"), "{msg}");
    // Required with a sensor.
    for key in ["range_min", "range_max", "noise"] {
        let e = refused(&edited(&monitor_preset(), key, None));
        assert_eq!(
            e.field(),
            Some(Box::leak(format!("monitor.{key}").into_boxed_str()) as &str)
        );
        assert!(matches!(e, LoadError::Param(p) if p.problem == Problem::Missing), "{e}");
    }
    // Noise not below the span; accuracy outside (0, 0.1].
    assert_eq!(bad("noise", Some("5e5")).0, Some("monitor.noise"));
    assert_eq!(bad("noise", Some("-1.0")).0, Some("monitor.noise"));
    for v in ["0.0", "0.2", "-0.001"] {
        assert_eq!(bad("accuracy", Some(v)).0, Some("monitor.accuracy"), "{v}");
    }
    // A rate above the estimator's tick (1000 Hz by default).
    assert_eq!(bad("sample_hz", Some("2000.0")).0, Some("monitor.sample_hz"));
    // A divider that lets 4.75 V reach 3.3 V; a shunt that lets 21 mA do.
    assert_eq!(bad("divider", Some("0.7")).0, Some("monitor.divider"));
    let current = edited(&monitor_preset(), "output", Some("\"current\""));
    let e = refused(&edited(&current, "shunt", Some("160.0")));
    assert_eq!(e.field(), Some("monitor.shunt"), "{e}");
    assert!(params_file::parse(&edited(&current, "shunt", Some("150.0"))).is_ok());
    // Names.
    assert_eq!(bad("sensor", Some("\"p_c\"")).0, Some("monitor.sensor"));
    assert_eq!(bad("output", Some("\"4-20\"")).0, Some("monitor.output"));
    assert_eq!(bad("adc_bits", Some("11")).0, Some("monitor.adc_bits"));
}

#[test]
fn a_displacement_range_in_mm_is_refused_naming_it() {
    // The paper's stroke is 1.5 mm = 0.0015 m.
    let x = edited(&monitor_preset(), "sensor", Some("\"x\""));
    let x = edited(&x, "noise", Some("1e-6"));
    let ok = edited(&x, "range_max", Some("0.002"));
    let raw = params_file::parse(&ok).unwrap();
    assert_eq!(
        monitor_settings(&raw).unwrap().unwrap().quantity,
        Quantity::Displacement
    );
    // 2 (mm) typed for m: more than 100 strokes.
    let e = refused(&edited(&x, "range_max", Some("2.0")));
    assert_eq!(e.field(), Some("monitor.range_max"), "{e}");
    assert!(e.to_string().contains("the unit is m"), "{e}");
    // 1 (mm) for m: 1 m is also more than 100 strokes... and 0.001 (m)
    // does not reach the stroke.
    let e = refused(&edited(&x, "range_max", Some("0.001")));
    assert_eq!(e.field(), Some("monitor.range_max"), "{e}");
    // A range_min above 0 (the closed stop).
    let e = refused(&edited(
        &edited(&x, "range_max", Some("0.002")),
        "range_min",
        Some("0.0005"),
    ));
    assert_eq!(e.field(), Some("monitor.range_min"), "{e}");
}

#[test]
fn a_differential_range_covers_minus_to_plus_the_drop() {
    // The paper's drop is 4e5 Pa: 0 to 5e5 misses p_b - p_a < 0.
    let dp = edited(&monitor_preset(), "sensor", Some("\"dp_ab\""));
    let e = refused(&dp);
    assert_eq!(e.field(), Some("monitor.range_min"), "{e}");
    let ok = edited(&dp, "range_min", Some("-5e5"));
    let raw = params_file::parse(&ok).unwrap();
    assert_eq!(
        monitor_settings(&raw).unwrap().unwrap().quantity,
        Quantity::PressureDifference
    );
    // -4 to 4 (bar typed for Pa): refused naming range_min first, as Pa.
    let bar = edited(&edited(&dp, "range_min", Some("-4.0")), "range_max", Some("4.0"));
    let e = refused(&bar);
    assert_eq!(e.field(), Some("monitor.range_min"), "{e}");
    assert!(e.to_string().contains("Pa"), "{e}");
}

#[test]
fn the_settings_refuse_bad_values_naming_the_field() {
    let new = |range: (f32, f32), noise: f32, accuracy: f32, bits: u8, hz: f32, output: Output| {
        Settings::new(Quantity::PressureA, output, range, noise, accuracy, bits, hz)
            .map_err(|e| e.field())
            .err()
    };
    let ok = ((0.0, 5.0e5), 100.0, 0.001, 12, 100.0, RATIOMETRIC);
    assert_eq!(new(ok.0, ok.1, ok.2, ok.3, ok.4, ok.5), None);
    assert_eq!(
        new((1.0, 1.0), 1.0, 0.001, 12, 100.0, RATIOMETRIC),
        Some("monitor.range_max")
    );
    assert_eq!(
        new((0.0, f32::NAN), 1.0, 0.001, 12, 100.0, RATIOMETRIC),
        Some("monitor.range_max")
    );
    assert_eq!(
        new(ok.0, f32::NAN, 0.001, 12, 100.0, RATIOMETRIC),
        Some("monitor.noise")
    );
    assert_eq!(new(ok.0, 6.0e5, 0.001, 12, 100.0, RATIOMETRIC), Some("monitor.noise"));
    assert_eq!(new(ok.0, 1.0, 0.0, 12, 100.0, RATIOMETRIC), Some("monitor.accuracy"));
    assert_eq!(new(ok.0, 1.0, 0.001, 11, 100.0, RATIOMETRIC), Some("monitor.adc_bits"));
    assert_eq!(new(ok.0, 1.0, 0.001, 12, 0.0, RATIOMETRIC), Some("monitor.sample_hz"));
    let div = |d| Output::Ratiometric { divider: d };
    let shunt = |r| Output::Current { shunt: r };
    assert_eq!(new(ok.0, 1.0, 0.001, 12, 100.0, div(0.7)), Some("monitor.divider"));
    assert_eq!(new(ok.0, 1.0, 0.001, 12, 100.0, div(-1.0)), Some("monitor.divider"));
    assert_eq!(new(ok.0, 1.0, 0.001, 12, 100.0, shunt(160.0)), Some("monitor.shunt"));
    assert_eq!(
        new(ok.0, 1.0, 0.001, 12, 100.0, shunt(f32::INFINITY)),
        Some("monitor.shunt")
    );
    assert_eq!(new(ok.0, 1.0, 0.001, 12, 100.0, shunt(150.0)), None);
}

#[test]
fn no_code_and_no_setting_panics() {
    // Every code of every resolution, both outputs, and extreme settings.
    for output in [RATIOMETRIC, CURRENT] {
        for bits in [6u8, 8, 10, 12] {
            let s = Settings::new(Quantity::PressureB, output, (-1.0e9, 1.0e9), 0.0, 0.1, bits, 1.0e5).unwrap();
            let mut drv = Transducer::new(Codes((0..=u16::MAX).collect()), s);
            for _ in 0..=u16::MAX {
                let _ = drv.read();
            }
            assert_eq!(s.stuck_after, 0);
        }
    }
    // A simulated reading of NaN or infinity reads as a code, never a panic.
    let s = pressure(RATIOMETRIC);
    for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX] {
        let mut drv = transducer::simulated(s, v, 1);
        let _ = drv.read();
    }
}
