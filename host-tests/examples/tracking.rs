//! How closely the estimate follows a warm-up through a lagging probe
//! (`host_tests::tracking`): the paper preset with an 8 s probe, then random
//! designs whose plunger travels over the validated range (a tenth of the
//! stroke at least) with random probes (time constant log-uniform over 2-30 s, one in
//! four with a well lag of 0.5-2 times it, noise 0.02 C), each at 0.5 and
//! 0.05 C/s over the validated range.
//!
//!     cargo run --release -p host-tests --example tracking -- [DESIGNS] [SEED] [PROBES]
//!
//! Defaults: 40 random designs, seed 1, random probes. `PROBES` = `8s`
//! gives every design the goals' probe instead: an 8 s time constant, no
//! well lag, noise 0.02 C. Goals: once two probe time constants have
//! passed, |x - x_ref| <= 0.5 % of the stroke at 0.5 C/s and 0.15 % at
//! 0.05 C/s.

use clap::{Parser, ValueEnum};
use host_tests::random::{Rng, physical_params};
use host_tests::tracking::{Run, run};
use std::time::Instant;

/// How closely the estimate follows a warm-up through a lagging probe.
#[derive(Parser)]
struct Args {
    /// Random designs beside the paper preset (count).
    #[arg(value_name = "DESIGNS", default_value_t = 40)]
    designs: usize,
    /// Seed of the designs, their probes and the probes' noise.
    #[arg(value_name = "SEED", default_value_t = 1)]
    seed: u64,
    /// The random designs' probes.
    #[arg(value_name = "PROBES", value_enum, default_value_t = Probes::Random)]
    probes: Probes,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum Probes {
    /// Random probes: time constant log-uniform over 2-30 s, one in four
    /// with a well lag of 0.5-2 times it.
    Random,
    /// The goals' probe: an 8 s time constant, no well lag.
    #[value(name = "8s")]
    EightSeconds,
}

fn main() {
    let args = Args::parse();
    let (count, seed) = (args.designs, args.seed);
    let fixed_probe = args.probes == Probes::EightSeconds;
    let mut paper = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).expect("paper preset");
    paper.probe.time_constant = 8.0;
    paper.probe.well_time_constant = 0.0;
    paper.probe.noise = 0.02;
    let mut designs = vec![paper];
    let mut rng = Rng::new(seed ^ 0x7A4C);
    while designs.len() < count + 1 {
        let mut raw = physical_params(&mut rng);
        // Designs whose plunger travels over the range (a tenth of the
        // stroke at least): one on a stop throughout is exact.
        let x = |t: f64| host_tests::reference::equilibrium(&raw.core, t).x;
        if (x(raw.estimator.valid_max - 2.0) - x(raw.estimator.valid_min + 2.0)).abs() < 0.1 * raw.core.stroke {
            continue;
        }
        raw.probe.time_constant = rng.log_uniform(2.0, 30.0);
        raw.probe.well_time_constant = if rng.unit() < 0.25 {
            raw.probe.time_constant * rng.uniform(0.5, 2.0)
        } else {
            0.0
        };
        if fixed_probe {
            raw.probe.time_constant = 8.0;
            raw.probe.well_time_constant = 0.0;
        }
        raw.probe.noise = 0.02;
        designs.push(raw);
    }
    let started = Instant::now();
    for (rate, goal) in [(0.5, 0.005), (0.05, 0.0015)] {
        let mut runs: Vec<(usize, Run)> = Vec::new();
        for (i, raw) in designs.iter().enumerate() {
            let (lo, hi) = (raw.estimator.valid_min + 2.0, raw.estimator.valid_max - 2.0);
            match run(raw, lo, hi, rate, seed + i as u64) {
                Ok(r) => runs.push((i, r)),
                Err(e) => eprintln!("design {i}: {e}"),
            }
        }
        let within = runs.iter().filter(|(_, r)| r.ramp <= goal).count();
        let worst = runs.iter().map(|(_, r)| r.ramp).fold(0.0, f64::max);
        println!(
            "{rate} C/s: {within} of {} runs within {:.2} % of the stroke once two probe time constants have passed (worst {:.3} %; paper preset {:.3} %)",
            runs.len(),
            100.0 * goal,
            100.0 * worst,
            100.0 * runs[0].1.ramp
        );
        println!(
            "| design | tau [s] | well [s] | ramp [% stroke] | first 2 tau | after the ramp | reading's lag as x |"
        );
        println!("|---:|---:|---:|---:|---:|---:|---:|");
        for (i, r) in &runs {
            println!(
                "| {i} | {:.1} | {:.1} | {:.3} | {:.3} | {:.3} | {:.2} |",
                r.lag.0,
                r.lag.1,
                100.0 * r.ramp,
                100.0 * r.onset,
                100.0 * r.after,
                100.0 * r.reading_lag
            );
        }
        println!();
    }
    eprintln!("{:.0} s", started.elapsed().as_secs_f64());
}
