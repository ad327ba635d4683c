//! The fault-injection campaign of the condition monitor
//! (`docs/monitoring.md`): per seeded design and second sensor, every fault
//! of `host_tests::campaign::Fault::CATALOGUE` on the same as-built device,
//! history, offsets and noises (ordinary operation: a warm-up, holds,
//! steps), the fault a step at ten minutes after the warm-up; the records
//! through the firmware's `f32` estimator with its monitor.
//!
//!     cargo run --release -p host-tests --example monitor_campaign -- [designs] [seed] [hours] [sensors]
//!
//! `designs` seeded designs (`host_tests::campaign::design`, after the
//! paper preset; default 4), `seed` (1), `hours` per run (1.5), `sensors`
//! a comma list of `p_a`, `p_b`, `dp_ab`, `x` (`p_a,x`). Per sensor and
//! fault: runs; detected (any alarm after the onset); median and worst
//! delay to the first alarm; named right (the first named fault is the
//! right flag, of the runs where the sensor can see the fault), median
//! delay to it; named wrong. The healthy time before each onset and the
//! healthy runs count the false alarms per 24 h.

use host_tests::campaign::{Fault, Quantity, catalogue, design};
use host_tests::monitor_campaign::{expected, run};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let designs: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(4);
    let seed: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1);
    let hours: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1.5);
    let sensors: Vec<Quantity> = args
        .get(3)
        .map_or("p_a,x", String::as_str)
        .split(',')
        .map(|s| Quantity::parse(s).unwrap_or_else(|| panic!("unknown sensor {s}")))
        .collect();
    let root = host_tests::repo_root();
    let paper = compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset");
    let mut nominals = vec![paper];
    nominals.extend((0..designs).map(|i| design(seed.wrapping_mul(1000) + i as u64)));
    println!(
        "{} designs (the paper preset and {designs} seeded, seed {seed}), {hours} h each\n",
        nominals.len()
    );
    for &q in &sensors {
        println!("sensor {}:\n", q.name());
        println!(
            "| fault | runs | detected | delay median / worst [s] | named right | named median [s] | named wrong |"
        );
        println!("|---|---|---|---|---|---|---|");
        let mut per_fault: Vec<Vec<_>> = vec![Vec::new(); Fault::CATALOGUE.len()];
        let (mut false_alarms, mut healthy) = (0usize, 0.0f64);
        for (d, nominal) in nominals.iter().enumerate() {
            for (i, s) in catalogue(nominal, q, hours * 3600.0, seed + d as u64)
                .iter()
                .enumerate()
            {
                match run(s) {
                    Ok(o) => {
                        healthy += o.healthy_time;
                        false_alarms += usize::from(o.false_alarm.is_some());
                        per_fault[i].push(o);
                    }
                    Err(e) => eprintln!("design {d} {}: {e}", s.injection.fault),
                }
            }
        }
        for (i, fault) in Fault::CATALOGUE.iter().enumerate().skip(1) {
            let runs = &per_fault[i];
            let valid: Vec<_> = runs.iter().filter(|o| o.false_alarm.is_none()).collect();
            let mut delays: Vec<f64> = valid.iter().filter_map(|o| o.detected).collect();
            delays.sort_by(f64::total_cmp);
            let want = expected(*fault, q);
            let right: Vec<f64> = valid
                .iter()
                .filter_map(|o| {
                    o.named
                        .filter(|(_, f)| want.is_some_and(|w| f.0 & w.0 != 0))
                        .map(|(t, _)| t)
                })
                .collect();
            let mut right_sorted = right.clone();
            right_sorted.sort_by(f64::total_cmp);
            let wrong = valid
                .iter()
                .filter(|o| o.named.is_some_and(|(_, f)| want.is_none_or(|w| f.0 & w.0 == 0)))
                .count();
            let median = |v: &[f64]| v.get(v.len() / 2).map_or("-".into(), |x| format!("{x:.1}"));
            let n = valid.len().max(1) as f64;
            println!(
                "| {fault} | {} | {:.0} % | {} / {} | {} | {} | {wrong} |",
                runs.len(),
                100.0 * delays.len() as f64 / n,
                median(&delays),
                delays.last().map_or("-".into(), |x| format!("{x:.1}")),
                if want.is_some() {
                    format!("{:.0} %", 100.0 * right.len() as f64 / n)
                } else {
                    "not observable".into()
                },
                median(&right_sorted),
            );
        }
        println!(
            "\nfalse alarms: {false_alarms} in {:.1} h of healthy operation ({:.2} per 24 h)\n",
            healthy / 3600.0,
            false_alarms as f64 / (healthy / 86_400.0)
        );
    }
}
