//! Nothing in the core panics, returns NaN where it promised a number, or
//! hangs, whatever the input: corrupted parameter files, special floating
//! values as temperatures and samples, garbage for fixed point.

use compensator::asymptotic::{Expansion, Reading, monotonicity, sensitivity};
use compensator::compensation::compensation;
use compensator::dynamics::linear::linearise;
use compensator::dynamics::{Twin, TwinConfig};
use compensator::equilibrium::{balance_temperature, equilibrium};
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::params::{CORE_FIELDS, RawParams};
use compensator::scalar::{Fixed, Q16_16};
use compensator::sensor::SensorFault;
use compensator::{Float, Params, Real};
use host_tests::random::{Rng, physical_params};

/// Values that break naive code.
const SPECIAL: [f64; 14] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    1e-300,
    1e300,
    -1e300,
    -1.0,
    1e9,
    -273.15,
    1e-12,
];

fn pick(rng: &mut Rng) -> f64 {
    if rng.unit() < 0.5 {
        SPECIAL[(rng.unit() * SPECIAL.len() as f64) as usize % SPECIAL.len()]
    } else {
        rng.uniform(-400.0, 400.0)
    }
}

/// Every evaluation of the core at temperature `t`, in scalar `F`.
fn exercise<F: Float>(p: &Params<F>, t: F) {
    if let Ok(e) = equilibrium(p, t) {
        assert!(e.x.is_finite() && e.p_a.is_finite() && e.q_total.is_finite(), "{e:?}");
    }
    let _ = sensitivity(p, t);
    if let Ok(exp) = Expansion::new(p, t, Reading::Temperature) {
        let _ = exp.at(t);
        let _ = exp.at(F::from_f64(50.0));
    }
    let _ = Expansion::new(p, F::from_f64(45.0), Reading::Property).map(|e| e.at(t));
    let _ = compensation(p, t);
    let _ = balance_temperature(p, t, F::from_f64(80.0));
    let _ = monotonicity(p, t, F::from_f64(80.0), 10);
    let _ = linearise(p, t);
}

#[test]
fn corrupted_parameter_sets_give_errors_not_panics() {
    let mut rng = Rng::new(1);
    for _ in 0..3000 {
        let mut raw = physical_params(&mut rng);
        let fields = &CORE_FIELDS;
        let target = fields[(rng.unit() * fields.len() as f64) as usize % fields.len()].path;
        let bad = pick(&mut rng);
        raw.core = raw.core.map(|n| if n.path == target { bad } else { n.value });
        if raw.validate().is_err() {
            assert!(Params::<f64>::new(&raw).is_err());
            continue;
        }
        // Valid but extreme: everything evaluates or refuses, in both types.
        if let Ok(p) = Params::<f64>::new(&raw) {
            exercise(&p, rng.uniform(20.0, 90.0));
        }
        if let Ok(p) = Params::<f32>::new(&raw) {
            exercise(&p, rng.uniform(20.0, 90.0) as f32);
        }
    }
}

#[test]
fn special_temperatures_give_errors_not_panics() {
    let mut rng = Rng::new(2);
    for _ in 0..100 {
        let raw = physical_params(&mut rng);
        let p64 = Params::<f64>::new(&raw).unwrap();
        let p32 = Params::<f32>::new(&raw).unwrap();
        for t in SPECIAL {
            exercise(&p64, t);
            exercise(&p32, t as f32);
            assert!(equilibrium(&p64, t).is_err() || (t > -100.0 && t < 300.0));
        }
    }
}

#[test]
fn twins_and_estimators_survive_any_sequence_of_inputs() {
    let mut rng = Rng::new(3);
    for _ in 0..30 {
        let raw: RawParams = physical_params(&mut rng);
        let p = Params::<f32>::new(&raw).unwrap();
        let cfg = EstimatorConfig::new(&raw).unwrap();
        assert!(Estimator::new(&p, cfg, f32::NAN).is_err());
        let mut est = Estimator::new(&p, cfg, 40.0).unwrap();
        let mut twin = Twin::<f32, f32>::new(&p, TwinConfig::SHIPPED, 40.0).unwrap();
        let mut fixed = Twin::<f32, Fixed>::new(&p, TwinConfig::SHIPPED, 40.0).unwrap();
        for _ in 0..300 {
            let v = pick(&mut rng) as f32;
            let sample = match (rng.unit() * 4.0) as u32 {
                0 => Err(SensorFault::Bus),
                1 => Ok(None),
                _ => Ok(Some(v)),
            };
            let e = est.tick(sample);
            assert!(
                e.x.is_finite() && e.p_a.is_finite() && e.q_total.is_finite(),
                "{sample:?}: {e:?}"
            );
            // A refused temperature keeps the previous coefficients.
            let _ = twin.set_temperature(v);
            let _ = fixed.set_temperature(v);
            if twin.tick().is_ok() {
                let s = twin.state();
                assert!(s.x.is_finite() && s.p_b.is_finite());
                assert!(s.x >= 0.0 && s.x <= p.plunger.stroke);
            }
            let _ = fixed.tick();
        }
    }
    // A bad configuration is refused, not run.
    let raw = physical_params(&mut Rng::new(4));
    let p = Params::<f64>::new(&raw).unwrap();
    for bad in [
        TwinConfig {
            substeps: 0,
            ..TwinConfig::SHIPPED
        },
        TwinConfig {
            tick: f64::NAN,
            ..TwinConfig::SHIPPED
        },
    ] {
        assert!(Twin::<f64, f64>::new(&p, bad, 40.0).is_err());
    }
}

#[test]
fn fixed_point_arithmetic_is_total() {
    let mut rng = Rng::new(5);
    for _ in 0..100_000 {
        let (a, b) = (Q16_16::from_f64(pick(&mut rng)), Q16_16::from_f64(pick(&mut rng)));
        let _ = (a + b, a - b, a * b, a / b, -a, a.sqrt(), a.abs());
        let (c, d) = (Fixed::from_f64(pick(&mut rng)), Fixed::from_f64(pick(&mut rng)));
        let _ = (c + d, c - d, c * d, c / d, -c, c.sqrt(), c.abs());
    }
}

#[test]
fn garbage_parameter_files_are_errors() {
    let mut rng = Rng::new(6);
    let preset = std::fs::read_to_string(host_tests::repo_root().join("presets/paper.toml")).unwrap();
    for _ in 0..2000 {
        // Cut the file at a random byte and splice in random bytes.
        let cut = (rng.unit() * preset.len() as f64) as usize;
        let mut bytes = preset.as_bytes()[..cut].to_vec();
        for _ in 0..(rng.unit() * 8.0) as usize {
            const ALPHABET: &[u8] = b" =[]\n.\"0e-x9aZ#";
            bytes.push(ALPHABET[(rng.unit() * ALPHABET.len() as f64) as usize % ALPHABET.len()]);
        }
        bytes.extend_from_slice(&preset.as_bytes()[cut..]);
        let _ = compensator_cli::parse(&String::from_utf8_lossy(&bytes));
    }
}
