//! Which device faults a second sensor can see at steady state, and which
//! it cannot tell apart: the observability analysis behind condition
//! monitoring (`docs/monitoring.md`).
//!
//!     cargo run --release -p host-tests --example observability -- [designs] [seed]
//!
//! Each fault is a change of the device file's fields (a capillary
//! restriction: conductance x 0.8, the bore by its fourth root; an orifice
//! worn to 1.2 times its area; an oil 1.25 times thicker at 40 C with the
//! same Walther slope; the spring rate x 0.9; the preload x 0.8; the
//! window's discharge coefficient x 1.1). Its *signature* on a sensor is
//! the change of the steady reading at 9 temperatures over the validated
//! range, from the independent reference equilibrium
//! (`compensator_reference::statics`). Per sensor (the chamber pressures
//! `p_a`, `p_b`, their difference, the displacement `x`), each fault's:
//!
//! * `snr`: the largest change over the range in standard deviations of
//!   one reading (0.1 % of the supply pressure for a pressure transducer,
//!   0.1 % of the stroke for a displacement sensor);
//! * `twin` and `|cos|`: the fault whose signature is most nearly parallel
//!   (1: the two look alike at every temperature, and no test on steady
//!   readings can tell them apart; at one temperature every pair is
//!   parallel, one reading being one number);
//! * `snr_perp`: what is left of the signature once the twin's best fit
//!   is taken out, in reading standard deviations: what an isolation test
//!   has to work with.
//!
//! Defaults: the paper preset, the model example and 20 random designs
//! (`host_tests::random::physical_params`) whose plunger travels over the
//! range, seed 1.

use clap::Parser;
use host_tests::observability::{FAULTS, Finding, SENSORS, analyse};
use host_tests::random::{Rng, physical_params};
use host_tests::reference::equilibrium;

/// Which device faults a second sensor can see at steady state, and which
/// it cannot tell apart.
#[derive(Parser)]
struct Args {
    /// Random designs beside the two presets (count).
    #[arg(value_name = "designs", default_value_t = 20)]
    designs: usize,
    /// Seed of the random designs.
    #[arg(value_name = "seed", default_value_t = 1)]
    seed: u64,
}

fn main() {
    let args = Args::parse();
    let (count, seed) = (args.designs, args.seed);
    let root = host_tests::repo_root();
    let paper = compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset");
    let example = compensator_cli::load(&root.join("presets/model-example.toml")).expect("model example");
    let mut designs = vec![("paper preset", paper), ("model example", example)];
    let mut rng = Rng::new(seed ^ 0x0B5E);
    while designs.len() < count + 2 {
        let raw = physical_params(&mut rng);
        let x = |t: f64| equilibrium(&raw.core, t).x;
        if (x(raw.estimator.valid_max - 2.0) - x(raw.estimator.valid_min + 2.0)).abs() < 0.1 * raw.core.stroke {
            continue;
        }
        designs.push(("random", raw));
    }

    for (name, raw) in designs.iter().take(2) {
        let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
        println!("\n{name}, {lo}-{hi} C: snr | twin | |cos| | snr_perp\n");
        print!("| fault |");
        for s in &SENSORS {
            print!(" {} |", s.0);
        }
        println!("\n|---|{}", "---|".repeat(SENSORS.len()));
        let per_sensor: Vec<_> = SENSORS.iter().map(|s| analyse(&raw.core, lo, hi, s)).collect();
        for (i, (fault, _)) in FAULTS.iter().enumerate() {
            print!("| {fault} |");
            for a in &per_sensor {
                let (snr, twin, cos, perp) = a[i];
                let twin = FAULTS.get(twin).map_or("-", |f| f.0.split(' ').next().unwrap_or("-"));
                print!(" {snr:.0} \\| {twin} \\| {cos:.4} \\| {perp:.1} |");
            }
            println!();
        }
    }

    // Over all designs: the median snr, and the share of designs where the
    // fault is seen (snr >= 5) and separable from every other fault
    // (snr_perp >= 5 against its nearest twin).
    println!(
        "\n{} designs (the two presets and {count} random, seed {seed}): median snr; seen (snr >= 5); separable (also snr_perp >= 5 against its twin)\n",
        designs.len()
    );
    print!("| fault |");
    for s in &SENSORS {
        print!(" {} |", s.0);
    }
    println!("\n|---|{}", "---|".repeat(SENSORS.len()));
    let all: Vec<Vec<Vec<Finding>>> = designs
        .iter()
        .map(|(_, raw)| {
            SENSORS
                .iter()
                .map(|s| analyse(&raw.core, raw.estimator.valid_min, raw.estimator.valid_max, s))
                .collect()
        })
        .collect();
    let n = designs.len() as f64;
    for (i, (fault, _)) in FAULTS.iter().enumerate() {
        print!("| {fault} |");
        for s in 0..SENSORS.len() {
            let mut snr: Vec<f64> = all.iter().map(|d| d[s][i].0).collect();
            snr.sort_by(f64::total_cmp);
            let seen = all.iter().filter(|d| d[s][i].0 >= 5.0).count() as f64;
            let sep = all.iter().filter(|d| d[s][i].0 >= 5.0 && d[s][i].3 >= 5.0).count() as f64;
            print!(
                " {:.0} \\| {:.0} % \\| {:.0} % |",
                snr[snr.len() / 2],
                100.0 * seen / n,
                100.0 * sep / n
            );
        }
        println!();
    }
}
