//! The sweep's settling time from the `f64` twin against the reference
//! solver over many variants: the figures docs/sweep.md quotes.
//!
//! ```sh
//! cargo run --release -p host-tests --example sweep_twin -- [VARIANTS [SEED]]
//! ```
//!
//! (default 400 variants, seed 1; `host_tests::sweep_twin`). The 40 -> 50 C
//! step (the sweep's default; a wider one of `STEPS` for a variant it does
//! not move) sampled every 1e-4 s over 0.2 s (the sweep's defaults). Prints the
//! variants where the twin's response is more than 0.1 % of the step off
//! the reference or the settling times disagree, then the totals: the
//! largest and the 99th-percentile error, the settling times equal, within
//! their allowance, or not.

use clap::Parser;
use compensator_cli::params_file;
use host_tests::sweep_twin::{Compared, compare_first, variant};

/// The sweep's settling time from the `f64` twin against the reference
/// solver over many variants.
#[derive(Parser)]
struct Args {
    /// Variants of the paper preset (count).
    #[arg(value_name = "VARIANTS", default_value_t = 400)]
    variants: u64,
    /// Seed of the variants.
    #[arg(value_name = "SEED", default_value_t = 1)]
    seed: u64,
}

fn main() {
    let Args { variants: n, seed } = Args::parse();
    let paper = params_file::parse(compensator_cli::input::PAPER_PRESET).expect("the built-in preset");
    let mut done: Vec<Compared> = Vec::new();
    let mut skipped = 0;
    for i in 0..n {
        let raw = variant(seed, i, &paper);
        let (step, c) = match compare_first(&raw, 1e-4, 0.2) {
            Ok(c) => c,
            Err(e) => {
                if std::env::var_os("VERBOSE").is_some() {
                    println!("variant {i} skipped: {e}");
                }
                skipped += 1;
                continue;
            }
        };
        if c.max_error_pct > 0.1 && std::env::var_os("VERBOSE").is_some() {
            let p = compensator::Params::<f64>::new(&raw).expect("valid");
            let lin = compensator::dynamics::linear::linearise(&p, step.1).expect("linearised");
            println!("variant {i}: eigenvalues {:?}", lin.eigenvalues.map(|l| (l.re, l.im)));
        }
        if c.max_error_pct > 0.1 || !c.settling_agrees() {
            println!(
                "variant {i} ({step:?}): error {:.4} % of the step at {:.4} s, settling {} s (twin) vs {} s (reference), allowed {:.2e} s, \
                 plan {:?}, {} ticks",
                c.max_error_pct, c.max_error_at, c.settling_twin, c.settling_reference, c.allowed, c.plan, c.ticks
            );
        }
        done.push(c);
    }
    let mut errors: Vec<f64> = done.iter().map(|c| c.max_error_pct).collect();
    errors.sort_by(f64::total_cmp);
    let pct = |q: f64| {
        errors
            .get(((errors.len() as f64 - 1.0) * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    let equal = done.iter().filter(|c| c.settling_twin == c.settling_reference).count();
    let agree = done.iter().filter(|c| c.settling_agrees()).count();
    let ticks: f64 = done.iter().map(|c| c.ticks as f64).sum::<f64>() / done.len().max(1) as f64;
    let fine = done.iter().filter(|c| c.fine).count();
    println!(
        "{} variants ({skipped} skipped: no step or no reference): twin error in % of the step: max {:.4}, 99th \
         percentile {:.4}, median {:.5}; settling times equal in {equal}, within the allowance in {agree}; \
         mean twin ticks {ticks:.0} (reference: 2000 samples); {fine} runs met a stop and ran at the sample interval",
        done.len(),
        pct(1.0),
        pct(0.99),
        pct(0.5)
    );
}
