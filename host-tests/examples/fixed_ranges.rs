//! The fixed-point audit's tables (`docs/dynamics.md`, "Fixed-point
//! ranges"): `cargo run --release -p host-tests --example fixed_ranges --
//! [--designs N] [--seed S] [--ticks T] [--all] [--scheme NAME]`.
//!
//! Without `--all` the designs are the two presets and, from N survey
//! designs, those at the ends of each coefficient's range
//! ([`host_tests::fixed_audit::extremes`]); with `--all`, every one of the
//! N designs. Each is driven through the audit's scenarios (holds at both
//! ends of the oil range, abrupt steps across the validated range and into
//! and out of cold and hot oil) with the configuration the chooser picks.
//! Prints the coefficients' ranges, then every arithmetic site of the tick
//! path with the range of its results in `f64` and in Q12.20, and how far
//! the Q12.20 twin strays from the `f64` one. `--scheme ros3` (any name of
//! the CLI's `--scheme`) audits another scheme than the shipped SDIRK3.
use clap::Parser;
use compensator::dynamics::{Scheme, TwinConfig};
use host_tests::fixed_audit::{COEFFICIENTS, Measured, Q12_20_LSB, coefficient_table, extremes, probe_design};
use host_tests::probe::{Site, source_line};
use host_tests::survey::{chosen as chosen_config, designs};
use rayon::prelude::*;

/// The fixed-point audit's tables: every arithmetic site's range in `f64`
/// and in Q12.20.
#[derive(Parser)]
struct Args {
    /// Survey designs drawn (count).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    designs: usize,
    /// Seed of the survey designs (decimal; the default is 0x5EED2026).
    #[arg(long, value_name = "S", default_value_t = 0x5EED_2026)]
    seed: u64,
    /// Each scenario's length [twin ticks].
    #[arg(long, value_name = "T", default_value_t = 1000)]
    ticks: usize,
    /// Audit every one of the N designs, not only the presets and the
    /// extremes.
    #[arg(long)]
    all: bool,
    /// Audit another scheme than the shipped SDIRK3 (the CLI's --scheme
    /// names), same substeps.
    #[arg(long, value_name = "NAME", value_parser = scheme_parser())]
    scheme: Option<Scheme>,
}

/// The core's one-step schemes, by name (as the CLI's `--scheme`).
fn scheme_parser() -> impl clap::builder::TypedValueParser<Value = Scheme> {
    use clap::builder::{PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(Scheme::ALL.map(Scheme::name))
        .try_map(|name| Scheme::from_name(&name).ok_or("unknown scheme"))
}

fn main() {
    let args = Args::parse();
    let (count, seed, ticks, all) = (args.designs, args.seed, args.ticks, args.all);
    // Another scheme than the shipped SDIRK3 (the generic Rosenbrock and
    // Runge-Kutta schemes of `--scheme` in the CLI), same substeps.
    let scheme = args.scheme;
    let t = std::time::Instant::now();
    let chosen = if all {
        designs(count, seed)
    } else {
        extremes(count, seed)
    };
    println!(
        "{} designs ({}), seed {seed:#x}, {ticks} ticks per scenario\n",
        chosen.len(),
        if all { "all surveyed" } else { "presets and extremes" }
    );
    let surveyed = if all { chosen.clone() } else { designs(count, seed) };
    let (valid, oil) = (coefficient_table(&surveyed, false), coefficient_table(&surveyed, true));
    println!("coefficients of the {} surveyed designs (|value|)\n", surveyed.len());
    println!("| coefficient | validated range: min | max | oil range: min | max |\n| --- | --- | --- | --- | --- |");
    for ((name, (vl, vh)), (ol, oh)) in COEFFICIENTS.iter().zip(valid).zip(oil) {
        println!("| {name} | {vl:.3e} | {vh:.3e} | {ol:.3e} | {oh:.3e} |");
    }
    let total = chosen
        .par_iter()
        .enumerate()
        .map(|(i, raw)| {
            let config = scheme.and_then(|scheme| chosen_config(raw).ok().map(|c| TwinConfig { scheme, ..c.config }));
            let mut d = probe_design(raw, config, ticks);
            for f in &mut d.failures {
                *f = format!("design {i}: {f}");
            }
            d
        })
        .reduce(Measured::default, |mut a, b| {
            a.merge(&b);
            a
        });
    let mut sites: Vec<&Site> = total.exact.keys().chain(total.fixed.keys()).collect();
    sites.sort();
    sites.dedup();
    println!(
        "\n| site | op | max f64 | min nonzero f64 | max Q12.20 | min nonzero Q12.20 (LSB) | underflows | source |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    for site in sites {
        let (e, f) = (
            total.exact.get(site).copied().unwrap_or_default(),
            total.fixed.get(site).copied().unwrap_or_default(),
        );
        println!(
            "| {}:{}:{} | {:?} | {:.3e} | {:.3e} | {:.3e} | {:.0} | {} | `{}` |",
            site.file.trim_start_matches("model/src/"),
            site.line,
            site.column,
            site.op,
            e.max_abs,
            e.min_nonzero,
            f.max_abs,
            f.min_nonzero / Q12_20_LSB,
            f.underflows,
            source_line(site)
        );
    }
    println!(
        "\nQ12.20 twin against the f64 twin, every tick of every scenario: xi within {:.1e} of the stroke, \
         pressures within {:.1e} of dp; end states within {:.1e}",
        total.worst_xi, total.worst_pi, total.worst_end
    );
    println!("\n{:.0} s", t.elapsed().as_secs_f64());
    for f in &total.failures {
        println!("FAIL {f}");
    }
}
