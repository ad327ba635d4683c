//! Throughput of `compensator sweep`: variants evaluated per second on this
//! machine, for the figure quoted in docs/sweep.md.
//!
//! ```sh
//! cargo run --release -p compensator-cli --example sweep_rate -- [VARIANTS] [THREADS]
//! ```
//!
//! Runs a Monte Carlo tolerance study of `presets/paper.toml` (plunger
//! diameter and spring rate within +-2 %, seed 1) with every metric of
//! `sweep` at its defaults (three displacements, the Eq. 32 verdict, the
//! 40 -> 50 C step's settling time and dominant eigenvalue with the
//! reference solver, the compensation error RMS), on THREADS threads
//! (default: all cores), and prints variants per second. A benchmark, not
//! a test: nothing is asserted.

use compensator_cli::{input, params_file, sweep};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(400);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(0);
    let base = params_file::parse(input::PAPER_PRESET).expect("the built-in preset");
    let s = sweep::build(
        base,
        &[],
        &["plunger.diameter=2%".into(), "plunger.spring_rate=2%".into()],
        Some(n),
        1,
        "30,50,80",
        "40:50",
        1e-4,
        0.2,
    )
    .expect("a valid sweep");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let start = Instant::now();
    let out = pool.install(|| sweep::run(&s)).expect("the sweep runs");
    let secs = start.elapsed().as_secs_f64();
    let rows = out.lines().count() - 1;
    println!(
        "{rows} variants on {} threads in {secs:.2} s: {:.0} variants/s",
        pool.current_num_threads(),
        rows as f64 / secs
    );
}
