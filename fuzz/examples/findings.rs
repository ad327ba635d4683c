//! The fuzzers' findings (docs/fuzzing.md), each replayed in a few lines
//! of the core's public API, without libFuzzer, printing what the core
//! answers now:
//!
//! `cargo run --release --manifest-path fuzz/Cargo.toml --example findings`
//!
//! F1, F3 and F4 were found on magnitudes the parameter schema now refuses
//! (it bounds every field); the functions are also fixed for any input
//! (the model's unit tests). F2 is fixed in the estimator's low-pass.

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

/// Validation's verdict, and the linearisation at `t` where `Params`
/// takes the set (validation aside: what the formulas do on it).
fn replay(what: &str, raw: &RawParams, t: f64) {
    println!("{what}: validation: {:?}", raw.validate().err().map(|e| e.to_string()));
    match Params::<f64>::new(raw) {
        Err(e) => println!("   Params::<f64>::new refuses it: {e}"),
        Ok(p) => {
            println!("   linearise: {:?}", linearise(&p, t));
            if let Ok(jac) = Model::new(&p).and_then(|m| jacobian_at_equilibrium(&m, t)) {
                println!("   hurwitz_stable: {}", hurwitz_stable(&jac));
            }
        }
    }
}

fn main() {
    let mut raw = paper();
    raw.core.bulk_modulus = 4.73599073514869e174;
    replay("F1 (bulk modulus 4.7e174 Pa, -9.38 C)", &raw, -9.377289377289372);
    let mut raw = paper();
    raw.core.volume_b = 2.5863284608296165e161;
    replay("F1 (chamber b of 2.6e161 m^3, -15.9 C)", &raw, -15.91575091575092);

    // F2: the f32 low-pass filter stalled short of a constant input; the
    // observer that replaced it sums its increments the same compensated
    // way (a probe of 0.1 s read at every tick of 100 kHz).
    let mut raw = paper();
    raw.estimator.tick_hz = 100_000.0;
    raw.probe.time_constant = 0.1;
    raw.validate().expect("validation accepts it");
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = EstimatorConfig::new(&raw).unwrap();
    let mut est = Estimator::new(&p, cfg, 100.0).unwrap();
    let mut last = None;
    // A 104 C reading held 30 s (the first agreeing readings beyond the
    // observer's gate restart it there).
    for _ in 0..3_000_000 {
        last = Some(est.tick(Ok(Some(104.0))));
    }
    let e = last.unwrap();
    println!(
        "F2 (tick 100 kHz, probe 0.1 s, 100 -> 104 C held 30 s): estimated {} C, {:e} C short (the low-pass ended at 103.6185 C)",
        e.temperature,
        104.0 - e.temperature
    );

    let mut raw = example();
    raw.core.mass = 2.399904e-318;
    replay("F3 (mass 2.4e-318 kg, 104.9 C)", &raw, 104.8840048840049);
    let mut raw = example();
    raw.core.density_15 = 4.641327459062115e-303;
    raw.core.volume_a = 2.1094012579938076e301;
    replay(
        "F3 (oil of 4.6e-303 kg/m^3, chamber a of 2.1e301 m^3, 51.9 C)",
        &raw,
        51.874236874236885,
    );

    let mut raw = example();
    raw.core.spring_rate = 2.23137064562084e-106;
    raw.core.outlet_pressure = 4.183097312812741e93;
    replay(
        "F4 (spring 2.2e-106 N/m, p_c 4.2e93 Pa, 162.9 C)",
        &raw,
        162.93040293040292,
    );
}
