//! The long soak: `cargo run --release -p host-tests --example soak --
//! --ticks 10000000 [--seed S] [--designs N] [--design-ticks T]
//! [--drift-ticks T]`.
//!
//! * The estimator soak with faults on the paper preset for `--ticks` ticks
//!   (the full table), and on `--designs` random designs whose plunger
//!   travels (`host_tests::soak::moving_designs`) for `--design-ticks` each
//!   (default: a tenth of `--ticks`; one line each).
//! * The `f32`-against-`f64` twin drift on the paper preset and the same
//!   designs for `--drift-ticks` ticks each (default: `--ticks`).
//!
//! Runs on all cores; prints the figures of `docs/soak.md`; exits 1 when
//! any check failed. Defaults: 1e7 ticks, `host_tests::soak::SEED`, 4
//! designs.
use clap::Parser;
use host_tests::soak::{SEED, drift, moving_designs, paper, run};

/// The long soak: the estimator with faults, and the `f32` twin against the
/// `f64` one.
#[derive(Parser)]
struct Args {
    /// The paper preset's estimator soak [estimator ticks, 1 ms each].
    #[arg(long, value_name = "T", default_value_t = 10_000_000)]
    ticks: u32,
    /// Seed of the walks, the faults and the random designs.
    #[arg(long, value_name = "S", default_value_t = SEED)]
    seed: u64,
    /// Random designs whose plunger travels (count).
    #[arg(long, value_name = "N", default_value_t = 4)]
    designs: usize,
    /// Each random design's estimator soak [estimator ticks] (default: a
    /// tenth of --ticks).
    #[arg(long, value_name = "T")]
    design_ticks: Option<u32>,
    /// Each design's twin drift run [twin ticks] (default: --ticks).
    #[arg(long, value_name = "T")]
    drift_ticks: Option<u32>,
}

fn main() {
    let args = Args::parse();
    let (ticks, seed, count) = (args.ticks, args.seed, args.designs);
    let design_ticks = args.design_ticks.unwrap_or(ticks / 10);
    let drift_ticks = args.drift_ticks.unwrap_or(ticks);
    let mut runs = vec![("paper preset".to_string(), paper())];
    for (i, d) in moving_designs(count, seed).into_iter().enumerate() {
        runs.push((format!("random design {i} (moving_designs seed {seed})"), d));
    }
    let mut failed = false;
    std::thread::scope(|scope| {
        let soaks: Vec<_> = runs
            .iter()
            .enumerate()
            .map(|(i, (name, r))| {
                let n = if i == 0 { ticks } else { design_ticks };
                (name, scope.spawn(move || run(r, n, seed)))
            })
            .collect();
        let drifts: Vec<_> = runs
            .iter()
            .map(|(name, r)| (name, scope.spawn(move || drift(r, drift_ticks, seed))))
            .collect();
        println!("## Estimator soak with faults, seed {seed}\n");
        for (i, (name, h)) in soaks.into_iter().enumerate() {
            match h.join().expect("a soak thread") {
                Ok(r) if i == 0 => {
                    println!("### {name}\n");
                    print!("{}", r.table());
                    println!();
                    failed |= r.violations() > 0;
                }
                Ok(r) => {
                    println!("- {name}: {}", r.line());
                    if r.violations() > 0 {
                        print!("{}", r.table());
                        failed = true;
                    }
                }
                Err(e) => {
                    println!("- {name}: {e}");
                    failed = true;
                }
            }
        }
        println!("\n## f32 twin against f64 twin, seed {seed}\n");
        for (name, h) in drifts {
            match h.join().expect("a drift thread") {
                Ok(d) => {
                    println!("- {name}: {}", d.line());
                    for p in d.problems() {
                        println!("  FAIL {p}");
                        failed = true;
                    }
                }
                Err(e) => {
                    println!("- {name}: {e}");
                    failed = true;
                }
            }
        }
    });
    std::process::exit(i32::from(failed));
}
