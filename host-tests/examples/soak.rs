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
//! any check failed.
use host_tests::soak::{SEED, drift, moving_designs, paper, run};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |name: &str, default: u64| -> u64 {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .map(|v| v.parse().unwrap_or_else(|_| panic!("{name}: not a number: {v}")))
            .unwrap_or(default)
    };
    let ticks = value("--ticks", 10_000_000) as u32;
    let seed = value("--seed", SEED);
    let count = value("--designs", 4) as usize;
    let design_ticks = value("--design-ticks", u64::from(ticks / 10)) as u32;
    let drift_ticks = value("--drift-ticks", u64::from(ticks)) as u32;
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
