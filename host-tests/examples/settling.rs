//! How many of the linearisation's slowest time constants the twin needs to
//! come to rest on the closed form after an abrupt temperature step, over
//! seeded random designs: the figure docs/firmware.md quotes for the
//! consistency check's settling window.
//!
//! `cargo run --release -p host-tests --example settling [-- DESIGNS [SEED]]`
//! (default 300 designs, seed 1)
//!
//! Designs: half `host_tests::random::physical_params` (sized springs),
//! half the paper preset with every core field scaled by 4^u, u uniform in
//! [-1, 1] (valid sets only; stiff, soft, switch-like). Steps, abrupt
//! (`Twin::set_temperature` once), from rest at the first temperature:
//! cold onto the closed stop (40 -> 0, 60 -> -20, 40 -> -40 C), hot onto
//! the open stop (40 -> 150, 26 -> 110 C), and across the validated range
//! (26 -> 78, 78 -> 26 C). The twin is the estimator's: `Twin<f32, f32>`,
//! the shipped configuration (SDIRK3, one step per 1 ms tick). The time
//! constant is `1 / min(-Re lambda)` of `linearise` at the final
//! temperature (free motion at the clamped equilibrium, as the estimator's
//! Stability job bounds it). Settled: from then on within `tol` of the
//! stroke and of `dp` of the closed form, for `tol` = 1e-2 (the
//! consistency check's X_TOLERANCE / P_TOLERANCE) and 1e-3 (the twin's
//! accuracy goal). Each run lasts 400 time constants or 2 s, whichever is
//! longer (designs slower than 0.5 s are left out).
//!
//! Then the same steps through the estimator (its defaults, the oil's
//! range widened to -45..160 C; the sensor's 50 Hz samples, the first
//! temperature for 2 s, then the second for 400 time constants or 3 s):
//! how many steps its consistency check answers with a re-seat, which it
//! should never do to a correct twin (the estimator slews its twin's oil
//! rather than stepping it, docs/firmware.md).

use clap::Parser;
use compensator::dynamics::linear::linearise;
use compensator::dynamics::{Twin, TwinConfig};
use compensator::equilibrium::{Stop, equilibrium};
use compensator::params::RawParams;
use compensator::{Params, Real};
use host_tests::settling::{self, STEPS};

const TOLERANCES: [f64; 2] = [1e-2, 1e-3];

/// Per stop at the end: every settling time and the worst (value, case),
/// per tolerance.
type ByStop = (Stop, [Vec<f64>; 2], [(f64, String); 2]);

/// One step's settling times in time constants (per tolerance), or `None`
/// when the design or the step is out of the model's reach.
fn settle(raw: &RawParams, from: f64, to: f64) -> Option<([f64; 2], Stop, f64)> {
    let p32 = Params::<f32>::new(raw).ok()?;
    let p64 = Params::<f64>::new(raw).ok()?;
    let lin = linearise(&p64, to).ok()?;
    let rate = lin.eigenvalues.iter().map(|l| -l.re).fold(f64::INFINITY, f64::min);
    if !(rate > 2.0) {
        return None;
    }
    let tau = 1.0 / rate;
    let eq = equilibrium(&p32, to as f32).ok()?;
    let mut twin = Twin::<f32, f32>::new(&p32, TwinConfig::SHIPPED, from as f32).ok()?;
    twin.set_temperature(to as f32).ok()?;
    let tick = TwinConfig::SHIPPED.tick;
    let ticks = ((400.0 * tau).max(2.0) / tick) as usize;
    let (stroke, dp) = (raw.core.stroke, raw.core.pressure_drop);
    // The last tick at which the state was outside each tolerance.
    let mut last_out = [0usize; 2];
    for k in 1..=ticks {
        twin.tick().ok()?;
        let s = twin.state();
        let off = ((s.x.to_f64() - eq.x.to_f64()).abs() / stroke)
            .max((s.p_a.to_f64() - eq.p_a.to_f64()).abs() / dp)
            .max((s.p_b.to_f64() - eq.p_b.to_f64()).abs() / dp);
        for (i, tol) in TOLERANCES.iter().enumerate() {
            if !(off <= *tol) {
                last_out[i] = k;
            }
        }
    }
    if last_out.contains(&ticks) {
        // Never settled: a finding, not a figure.
        eprintln!("not settled within {ticks} ticks: {from} -> {to} C, tau {tau:.4} s, {raw:?}");
        return Some(([f64::INFINITY; 2], eq.stop, tau));
    }
    Some((last_out.map(|k| k as f64 * tick / tau), eq.stop, tau))
}

/// How many of the linearisation's slowest time constants the twin needs
/// to come to rest on the closed form after an abrupt temperature step.
#[derive(Parser)]
struct Args {
    /// Designs (count): half random, half the paper preset scaled.
    #[arg(value_name = "DESIGNS", default_value_t = 300)]
    designs: usize,
    /// Seed of the designs.
    #[arg(value_name = "SEED", default_value_t = 1)]
    seed: u64,
}

fn main() {
    let Args { designs: count, seed } = Args::parse();
    let paper = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).expect("paper preset");
    // Per (stop at the end, tolerance): every settling time, and the worst.
    let mut by_stop: Vec<ByStop> = Vec::new();
    let (mut est_steps, mut est_reseated, mut est_worst) = (0, 0, String::new());
    for (used, raw) in settling::designs(seed, paper).take(count) {
        for (from, to) in STEPS {
            if let Some(r) = settling::estimator_reseats(&raw, from, to) {
                est_steps += 1;
                if r > 0 {
                    est_reseated += 1;
                    est_worst = format!("design {used}, {from} -> {to} C: {r} re-seat(s)");
                    eprintln!("re-seated: {est_worst}: {raw:?}");
                }
            }
            let Some((n, stop, tau)) = settle(&raw, from, to) else {
                continue;
            };
            let entry = match by_stop.iter_mut().find(|e| e.0 == stop) {
                Some(e) => e,
                None => {
                    by_stop.push((
                        stop,
                        [Vec::new(), Vec::new()],
                        [(0.0, String::new()), (0.0, String::new())],
                    ));
                    by_stop.last_mut().unwrap()
                }
            };
            for (i, &ni) in n.iter().enumerate() {
                entry.1[i].push(ni);
                if ni > entry.2[i].0 {
                    entry.2[i] = (ni, format!("design {used}, {from} -> {to} C, tau {:.1} ms", tau * 1e3));
                }
            }
        }
    }
    println!(
        "{count} designs (seed {seed}), abrupt steps, Twin<f32, f32> SHIPPED; settling time in slowest time constants"
    );
    println!("| ends | tolerance | steps | median | 99 % | max | worst case |");
    println!("|---|---:|---:|---:|---:|---:|---|");
    by_stop.sort_by_key(|e| e.0 as u8);
    for (stop, times, worst) in &mut by_stop {
        for (i, tol) in TOLERANCES.iter().enumerate() {
            let v = &mut times[i];
            v.sort_by(f64::total_cmp);
            let q = |f: f64| v[((v.len() - 1) as f64 * f) as usize];
            println!(
                "| {stop:?} | {tol:.0e} | {} | {:.1} | {:.1} | {:.1} | {} |",
                v.len(),
                q(0.5),
                q(0.99),
                q(1.0),
                worst[i].1
            );
        }
    }
    println!(
        "estimator (its defaults, oil -45..160 C, 50 Hz samples): {est_reseated} of {est_steps} steps re-seated its twin{}",
        if est_worst.is_empty() {
            String::new()
        } else {
            format!(" (last: {est_worst})")
        }
    );
}
