//! The fuzzers' findings (docs/fuzzing.md), each reproduced in a few lines
//! of the core's public API, without libFuzzer:
//!
//! `cargo run --release --manifest-path fuzz/Cargo.toml --example findings`
//!
//! Each prints what the core returns and what it promised; the exit
//! status is 0 either way (the findings are reported, not fixed, here).

use compensator::dynamics::Model;
use compensator::dynamics::linear::{hurwitz_stable, jacobian_at_equilibrium, linearise};
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::{Params, RawParams};
use compensator_fuzz::input::presets;

fn paper() -> RawParams {
    presets()[0]
}

fn example() -> RawParams {
    presets()[1]
}

fn main() {
    // F1: Complex::abs squares the parts.
    let mut raw = paper();
    raw.core.bulk_modulus = 4.73599073514869e174;
    raw.validate().expect("validation accepts it");
    let p = Params::<f64>::new(&raw).unwrap();
    let lin = linearise(&p, -9.377289377289372).unwrap();
    println!(
        "F1 (bulk modulus 4.7e174 Pa, -9.38 C): eigenvalues {:?}\n   natural frequencies {:?}, damping ratios {:?}",
        lin.eigenvalues, lin.natural_frequency, lin.damping_ratio
    );
    let mut raw = paper();
    raw.core.volume_b = 2.5863284608296165e161;
    let p = Params::<f64>::new(&raw).unwrap();
    let lin = linearise(&p, -15.91575091575092).unwrap();
    println!(
        "F1 (chamber b of 2.6e161 m^3, -15.9 C): eigenvalue {:?}: natural frequency {:e}, damping ratio {}",
        lin.eigenvalues[0], lin.natural_frequency[0], lin.damping_ratio[0]
    );

    // F2: the f32 low-pass filter stalls short of a constant input.
    let mut raw = paper();
    raw.estimator.tick_hz = 100_000.0;
    raw.estimator.filter_time_constant = 1.0;
    raw.validate().expect("validation accepts it");
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw.estimator).unwrap();
    let mut est = Estimator::new(&p, cfg, 100.0).unwrap();
    let mut last = None;
    // 30 filter time constants of a 104 C sample every tick.
    for _ in 0..3_000_000 {
        last = Some(est.tick(Ok(Some(104.0))));
    }
    let e = last.unwrap();
    println!(
        "F2 (tick 100 kHz, filter 1 s, 100 -> 104 C held 30 s): filtered {} C, {:.3} C short (gain {:e})",
        e.temperature,
        104.0 - e.temperature,
        cfg.filter_gain
    );

    // F3: linearise returns infinite eigenvalues.
    let mut raw = example();
    raw.core.mass = 2.399904e-318;
    let p = Params::<f64>::new(&raw).unwrap();
    let lin = linearise(&p, 104.8840048840049).unwrap();
    println!("F3 (mass 2.4e-318 kg, 104.9 C): Ok, eigenvalues {:?}", lin.eigenvalues);
    let mut raw = example();
    raw.core.density_15 = 4.641327459062115e-303;
    raw.core.volume_a = 2.1094012579938076e301;
    let p = Params::<f64>::new(&raw).unwrap();
    let lin = linearise(&p, 51.874236874236885).unwrap();
    println!(
        "F3 (oil of 4.6e-303 kg/m^3, chamber a of 2.1e301 m^3, 51.9 C): Ok, eigenvalues {:?}",
        lin.eigenvalues
    );

    // F4: Routh-Hurwitz overflows to "unstable".
    let mut raw = example();
    raw.core.spring_rate = 2.23137064562084e-106;
    raw.core.outlet_pressure = 4.183097312812741e93;
    let p = Params::<f64>::new(&raw).unwrap();
    let t = 162.93040293040292;
    let lin = linearise(&p, t).unwrap();
    let jac = jacobian_at_equilibrium(&Model::new(&p).unwrap(), t).unwrap();
    println!(
        "F4 (spring 2.2e-106 N/m, p_c 4.2e93 Pa, 162.9 C): eigenvalues {:?} (stable: {}), hurwitz_stable: {}",
        lin.eigenvalues,
        lin.stable,
        hurwitz_stable(&jac)
    );
}
