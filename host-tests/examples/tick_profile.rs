//! What a Q12.20 twin tick is made of: `cargo run --release -p host-tests
//! --example tick_profile -- [--params F] [--substeps N]`.
//!
//! Runs the bench's workload (the twin built for the file, 200 ticks of the
//! 30 -> 40 C step from the closed stop; `cargo xtask bench`) with
//! [`Probe`] scalars over Q12.20 and prints, per tick after the graded
//! first one, how many operations of each kind the tick executes (all
//! arithmetic of the tick path, by kind) and the ten busiest sites. With
//! the per-operation costs `cargo xtask bench` measures on each core
//! (`docs/bench.md`, "Fixed-point operations"), this is the tick's profile.
use clap::Parser;
use compensator::Params;
use compensator::dynamics::{Scheme, Twin, TwinConfig};
use compensator::scalar::Fixed;
use host_tests::probe::{Op, Probe, Recording, source_line};
use std::collections::BTreeMap;

/// What a Q12.20 twin tick is made of: operations per tick, by kind and by
/// site.
#[derive(Parser)]
struct Args {
    /// The parameter file (default: presets/paper.toml).
    #[arg(long, value_name = "F")]
    params: Option<String>,
    /// SDIRK3 steps per 1 ms tick (count).
    #[arg(long, value_name = "N", default_value_t = 1)]
    substeps: u8,
}

fn main() {
    let args = Args::parse();
    let file = args
        .params
        .unwrap_or_else(|| host_tests::repo_root().join("presets/paper.toml").display().to_string());
    let raw = compensator_cli::load(std::path::Path::new(&file)).expect("parameter file");
    let params = Params::<f32>::new(&raw).expect("valid parameters");
    let substeps = args.substeps;
    let config = TwinConfig {
        scheme: Scheme::Sdirk3,
        tick: 1e-3,
        substeps,
    };
    let mut twin = Twin::<f32, Probe<Fixed>>::new(&params, config, 30.0).expect("twin");
    twin.set_temperature(40.0).expect("40 C");
    twin.tick().expect("graded tick");
    let ticks = 199;
    let rec = Recording::start();
    for _ in 0..ticks {
        twin.tick().expect("tick");
    }
    let ranges = rec.finish();
    let mut by_op: BTreeMap<Op, u64> = BTreeMap::new();
    for (site, r) in &ranges {
        if site.op != Op::Divisor {
            *by_op.entry(site.op).or_default() += r.count;
        }
    }
    println!("{file}: sdirk3 x{substeps}, Q12.20, operations per tick (mean of {ticks} ticks after the graded one)\n");
    println!("| operation | per tick |\n| --- | --- |");
    for (op, n) in &by_op {
        println!("| {op:?} | {:.1} |", *n as f64 / ticks as f64);
    }
    let mut sites: Vec<_> = ranges
        .iter()
        .filter(|(s, _)| matches!(s.op, Op::Div | Op::Sqrt | Op::Mul))
        .collect();
    sites.sort_by_key(|(s, r)| (std::cmp::Reverse(r.count), **s));
    println!("\n| site | operation | per tick | source |\n| --- | --- | --- | --- |");
    for (s, r) in sites.iter().take(40) {
        println!(
            "| {}:{}:{} | {:?} | {:.1} | `{}` |",
            s.file,
            s.line,
            s.column,
            s.op,
            r.count as f64 / ticks as f64,
            source_line(s)
        );
    }
}
