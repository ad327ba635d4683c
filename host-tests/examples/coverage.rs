//! The uncertainty's coverage (`host_tests::coverage`): devices and probes
//! drawn from the declared uncertainties, the reference's truth against the
//! `f32` estimator's band, on the paper preset and random designs, each with
//! a design office's tolerances (`drawing_tolerances`).
//!
//!     cargo run --release -p host-tests --example coverage -- [DEVICES] [DESIGNS] [TEMPERATURES] [SEED]
//!
//! Defaults: 1,000 devices of the paper preset and of each of 4 random
//! designs, 2 temperatures each, seed 1. Prints the coverage table.

use clap::Parser;
use host_tests::coverage::{drawing_tolerances, study, table};
use host_tests::random::{Rng, physical_params};
use std::time::Instant;

/// The uncertainty's coverage: devices drawn from the declared
/// uncertainties, the reference's truth against the `f32` estimator's band.
#[derive(Parser)]
struct Args {
    /// Devices drawn per design (count).
    #[arg(value_name = "DEVICES", default_value_t = 1000)]
    devices: u64,
    /// Random designs beside the paper preset (count).
    #[arg(value_name = "DESIGNS", default_value_t = 4)]
    designs: u64,
    /// Temperatures drawn per device (count).
    #[arg(value_name = "TEMPERATURES", default_value_t = 2)]
    temperatures: u64,
    /// Seed of the designs, devices and temperatures.
    #[arg(value_name = "SEED", default_value_t = 1)]
    seed: u64,
}

fn main() {
    let args = Args::parse();
    let (devices, count, temps, seed) = (args.devices, args.designs, args.temperatures, args.seed);
    let mut paper = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).expect("paper preset");
    paper.tolerances = drawing_tolerances(&paper);
    let mut designs = vec![paper];
    let mut rng = Rng::new(seed ^ 0xC0FE);
    for _ in 0..count {
        let mut raw = physical_params(&mut rng);
        raw.tolerances = drawing_tolerances(&raw);
        designs.push(raw);
    }
    let started = Instant::now();
    let samples = study(&designs, devices as usize, temps as usize, seed).expect("the study runs");
    println!(
        "{} designs x {devices} devices x {temps} temperatures ({} samples) in {:.0} s, seed {seed}\n",
        designs.len(),
        samples.len(),
        started.elapsed().as_secs_f64()
    );
    println!("{}", table(&samples));
    for d in 0..designs.len() {
        let of: Vec<_> = samples.iter().filter(|s| s.design == d).copied().collect();
        println!("design {d}:\n{}", table(&of));
    }
}
