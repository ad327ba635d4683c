//! The identification campaign: `compensator identify`'s default fit on
//! seeded random underdamped and overdamped designs, each record simulated
//! by the independent reference solver (Radau5) with noise on the
//! displacement only; the figures docs/calibration.md quotes.
//!
//! ```sh
//! cargo run --release -p host-tests --example identify_campaign -- \
//!     [UNDERDAMPED [OVERDAMPED [SEED [FIGURE.svg]]]]
//! ```
//!
//! (default 200 and 100 designs, seed 1, no figure). Designs, records and
//! base files: `host_tests::identify_study`. Prints one line per design
//! and the totals: the designs whose damping is identified within 5 % of
//! the truth (the goal: at least 95 % of the underdamped ones), the mass
//! and damping estimates whose 95 % interval lies within +-5 % and how
//! many of them are within 5 % of the truth, and how many 95 % intervals
//! (every identified parameter) hold the truth. The figure: each
//! identified mass and damping's error against the design's damping ratio.
//! `identify_campaign show under|over INDEX [SEED [NOISE [NOISE_SEED]]]` prints one
//! design, its base file and the command's notes (NOISE scales the noise).
//! Runs on all cores (rayon; `RAYON_NUM_THREADS=N` limits them).

use clap::{Parser, Subcommand, ValueEnum};
use compensator_cli::plot::{Figure, Panel, Series, write};
use host_tests::identify_study::{self, Class, Outcome, Summary};
use rayon::prelude::*;
use std::path::PathBuf;

/// The identification campaign: `compensator identify`'s default fit on
/// seeded random underdamped and overdamped designs.
#[derive(Parser)]
#[command(args_conflicts_with_subcommands = true, disable_help_subcommand = true)]
struct Args {
    #[command(subcommand)]
    show: Option<Show>,
    /// Underdamped designs (count).
    #[arg(value_name = "UNDERDAMPED", default_value_t = 200)]
    under: u64,
    /// Overdamped designs (count).
    #[arg(value_name = "OVERDAMPED", default_value_t = 100)]
    over: u64,
    /// Seed of the designs and their records.
    #[arg(value_name = "SEED", default_value_t = 1)]
    seed: u64,
    /// Write the figure (SVG) of the mass and damping errors against the
    /// damping ratio to this file (default: none).
    #[arg(value_name = "FIGURE.svg")]
    figure: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Show {
    /// One design: its truth, base file and the command's notes.
    ///
    /// With BULK_TRUTH set, the base file's bulk modulus is the truth's;
    /// with PROFILE_TRUTH set, the misfit with the bulk modulus held at the
    /// truth follows.
    Show {
        /// The design's class.
        #[arg(value_name = "CLASS", value_enum, default_value_t = Damping::Under)]
        class: Damping,
        /// The design's index in its class (from 0).
        #[arg(value_name = "INDEX", default_value_t = 0)]
        index: u64,
        /// Seed of the designs (the campaign's SEED).
        #[arg(value_name = "SEED", default_value_t = 1)]
        seed: u64,
        /// The record's noise, in multiples of the design's own.
        #[arg(value_name = "NOISE", default_value_t = 1.0)]
        noise: f64,
        /// Mixed into the record's noise seed.
        #[arg(value_name = "NOISE_SEED", default_value_t = 0)]
        noise_seed: u64,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Damping {
    /// An underdamped design.
    Under,
    /// An overdamped design.
    Over,
}

fn main() {
    let args = Args::parse();
    if let Some(Show::Show {
        class,
        index,
        seed,
        noise,
        noise_seed,
    }) = args.show
    {
        // `show under|over INDEX [SEED [NOISE [NOISE_SEED]]]`: one design's
        // truth, base file and the command's notes.
        let class = match class {
            Damping::Under => Class::Underdamped,
            Damping::Over => Class::Overdamped,
        };
        show(class, seed, index, noise, noise_seed);
        return;
    }
    let (under, over, seed, figure) = (args.under, args.over, args.seed, args.figure);
    let threads = rayon::current_num_threads();
    let jobs: Vec<(Class, u64)> = (0..under)
        .map(|i| (Class::Underdamped, i))
        .chain((0..over).map(|i| (Class::Overdamped, i)))
        .collect();
    let start = std::time::Instant::now();
    // Each outcome printed as it comes (the campaign takes minutes).
    let ran: Vec<Option<Outcome>> = jobs
        .par_iter()
        .map(|&(class, i)| {
            let o = identify_study::run(class, seed, i);
            if let Some(o) = &o {
                println!("{}", line(o));
            }
            o
        })
        .collect();
    let skipped = ran.iter().filter(|o| o.is_none()).count();
    let mut outcomes: Vec<Outcome> = ran.into_iter().flatten().collect();
    outcomes.sort_by_key(|o| (o.class == Class::Overdamped, o.index));
    println!(
        "{} designs in {:.0} s on {threads} threads ({} skipped: the reference solver could not record them)",
        outcomes.len(),
        start.elapsed().as_secs_f64(),
        skipped
    );
    for (class, name) in [(Class::Underdamped, "underdamped"), (Class::Overdamped, "overdamped")] {
        let of: Vec<Outcome> = outcomes.iter().filter(|o| o.class == class).cloned().collect();
        let s = Summary::of(&of);
        let pct = |a: usize, b: usize| if b == 0 { f64::NAN } else { 100.0 * a as f64 / b as f64 };
        println!(
            "{name}: {} designs, {} failed; damping within 5 %: {} ({:.1} %); estimates with their 95 % interval \
             within +-5 %: {}, of which within 5 % of the truth: {} ({:.1} %); 95 % intervals holding the truth: \
             {} of {} ({:.1} %)",
            s.designs,
            s.failed,
            s.damping_within_5,
            pct(s.damping_within_5, s.designs),
            s.claimed_5,
            s.claimed_5_held,
            pct(s.claimed_5_held, s.claimed_5),
            s.covered,
            s.intervals,
            pct(s.covered, s.intervals)
        );
        for (path, (n, c)) in compensator_cli::identify::DEFAULT_FIT.iter().zip(s.by_parameter) {
            println!(
                "  {path}: identified in {n}, interval holds the truth in {c} ({:.1} %)",
                pct(c, n)
            );
        }
    }
    if let Some(path) = figure {
        write(&path, &plot(&outcomes)).expect("the figure is written");
        println!("figure: {}", path.display());
    }
}

fn line(o: &Outcome) -> String {
    let name = if o.class == Class::Underdamped { "under" } else { "over" };
    match &o.result {
        Err(e) => format!("{name} {:3} zeta {:.2}: FAILED {e}", o.index, o.zeta),
        Ok(scored) => {
            let parts: Vec<String> = scored
                .iter()
                .map(|s| match (s.estimate, s.rel_error()) {
                    (Some(e), Some(err)) => {
                        format!(
                            "{} {:+.2} % (se {:.2} %{})",
                            s.path.split('.').nth(1).unwrap_or(s.path),
                            100.0 * (e.value - s.truth) / s.truth,
                            100.0 * e.std_error / e.value,
                            if s.covered() == Some(false) {
                                ", interval misses"
                            } else {
                                ""
                            }
                        ) + if err > 0.05 { " >5%" } else { "" }
                    }
                    _ => format!("{} not identified", s.path.split('.').nth(1).unwrap_or(s.path)),
                })
                .collect();
            format!(
                "{name} {:3} zeta {:.2}: {}; rms/noise {:.2}",
                o.index,
                o.zeta,
                parts.join(", "),
                o.rms_over_noise
            )
        }
    }
}

/// Each identified mass and damping's error [%] against the design's
/// dominant damping ratio, underdamped and overdamped designs apart, with
/// the +-5 % band.
fn plot(outcomes: &[Outcome]) -> Figure {
    let zetas = outcomes.iter().map(|o| o.zeta);
    let (lo, hi) = zetas.fold((f64::INFINITY, 0.0f64), |(a, b), z| (a.min(z), b.max(z)));
    let panel = |path: &str, what: &str| {
        let mut series = Vec::new();
        for (class, name) in [(Class::Underdamped, "underdamped"), (Class::Overdamped, "overdamped")] {
            let pts: Vec<(f64, f64)> = outcomes
                .iter()
                .filter(|o| o.class == class)
                .filter_map(|o| {
                    let s = o.get(path)?;
                    let e = s.estimate?;
                    Some((o.zeta, 100.0 * (e.value - s.truth) / s.truth))
                })
                .collect();
            series.push(Series::points(format!("{name} ({} identified)", pts.len()), pts));
        }
        for band in [5.0, -5.0] {
            let mut s = Series::line(if band > 0.0 { "+-5 %" } else { "" }, vec![(lo, band), (hi, band)]);
            s.dashed = true;
            s.color = Some(2);
            series.push(s);
        }
        Panel {
            y_desc: format!("{what} error [%]"),
            log_y: false,
            legend: true,
            series,
        }
    };
    Figure {
        title: "identify (default fit), x-only records of the reference solver".into(),
        x_desc: "dominant damping ratio at 55 C".into(),
        panels: vec![panel("plunger.damping", "damping"), panel("plunger.mass", "mass")],
    }
}

fn show(class: Class, seed: u64, index: u64, noise: f64, noise_seed: u64) {
    let (mut d, _, mut base) = identify_study::case(class, seed, index).expect("the reference records the design");
    if std::env::var_os("BULK_TRUTH").is_some() {
        base.core.bulk_modulus = d.truth.core.bulk_modulus;
    }
    d.sigma_x *= noise;
    let data = identify_study::record(&d, seed ^ (index << 20) ^ 0x5EED ^ (noise_seed << 40)).expect("recorded");
    println!(
        "# truth (zeta {:.3}, dt {:e} s, {} samples, noise {:e} m)",
        d.zeta,
        d.dt,
        data.x_m.len(),
        d.sigma_x
    );
    println!("{}", compensator_cli::params_file::to_toml(&d.truth));
    println!(
        "# base: mass {:e}, damping {:e}, bulk_modulus {:e}",
        base.core.mass, base.core.damping, base.core.bulk_modulus
    );
    match compensator_cli::identify::identify_params(&base, &data, &compensator_cli::identify::DEFAULT_FIT) {
        Ok(id) => {
            for n in id.notes() {
                println!("{n}");
            }
            print!("{}", id.table());
        }
        Err(e) => println!("error: {e}"),
    }
    if std::env::var_os("PROFILE_TRUTH").is_some() {
        // The misfit with the bulk modulus held at the truth, mass and
        // damping fitted (the profile at the truth).
        let mut b = base;
        b.core.bulk_modulus = d.truth.core.bulk_modulus;
        let full =
            compensator_cli::identify::identify_params(&base, &data, &compensator_cli::identify::DEFAULT_FIT).unwrap();
        let sub = compensator_cli::identify::identify_params(&b, &data, &["plunger.mass", "plunger.damping"]).unwrap();
        let n = data.x_m.len() as f64;
        let rss = |rms: f64| rms * rms * n;
        let s2 = rss(full.rms_x) / full.dof as f64;
        println!(
            "profile at the true bulk modulus: misfit up by {:.2} s^2 (full rms {:e}, held {:e})",
            (rss(sub.rms_x) - rss(full.rms_x)) / s2,
            full.rms_x,
            sub.rms_x
        );
    }
}
