//! The fault-injection campaign of the condition monitor
//! (`docs/monitoring.md`): per seeded design and second sensor, every fault
//! of `host_tests::campaign::Fault::CATALOGUE` on the same as-built device,
//! history, offsets and noises (ordinary operation: a warm-up, holds,
//! steps), the fault a step shortly before the history first moves the oil
//! by 5 C within a minute (ten minutes or more after the warm-up); the
//! records through the firmware's `f32` estimator with its monitor.
//!
//!     cargo run --release -p host-tests --example monitor_campaign -- [designs] [seed] [hours] [sensors] [healthy_hours] [faults]
//!
//! `designs` seeded designs (`host_tests::campaign::design`, after the
//! paper preset; default 4), `seed` (1), `hours` per faulty run (1.5),
//! `sensors` a comma list of `p_a`, `p_b`, `dp_ab`, `x` (`p_a,x`),
//! `healthy_hours` per design of the healthy run that counts false alarms
//! (`hours`; 24 gives a simulated day per design), `faults` a comma list
//! of the catalogue's faults to run (`capillary:0.8,sticking:0.1`; `all`,
//! the default): the healthy baseline always runs. The runs are spread
//! over the host's cores (`COMPENSATOR_JOBS` sets how many threads); the
//! table does not depend on how many. `COMPENSATOR_VERBOSE=1` prints each
//! run's outcome too (design, fault, onset, delays), to find the designs
//! behind a figure.
//!
//! Per sensor and fault: runs; detected (any alarm after the onset); named
//! right (the first named fault is the right flag, of the runs where the
//! sensor can see the fault) and wrong; the delay from the onset to the
//! name, median and worst; the goal's share: a divider's fault at 0.8 (1.2)
//! named within 60 s of the onset, of the runs whose oil spanned 5 C within
//! those 60 s, at 0.9 (1.1) within 10 minutes; sticking named within 10 s
//! of the plunger being held back by half its play band. Then the false
//! alarms per simulated 24 h of healthy operation and the isolation (named
//! right of all named).

use host_tests::campaign::{Fault, Quantity, Scenario, catalogue_before_move, design};
use host_tests::monitor_campaign::{Outcome, expected, run};

/// What a fault's goal asks: the time \[s\] to name it in, counted from the
/// onset (`false`) or from the plunger being held (`true`), and the span
/// the oil must have moved within it (from the onset; `None`: any).
fn goal(fault: Fault) -> Option<(f64, bool)> {
    match fault {
        Fault::CapillaryRestricted(f) | Fault::OrificeClogged(f) if f <= 0.85 => Some((60.0, false)),
        Fault::OrificeWorn(f) if f >= 1.15 => Some((60.0, false)),
        Fault::CapillaryRestricted(_) | Fault::OrificeClogged(_) | Fault::OrificeWorn(_) => Some((600.0, false)),
        Fault::Sticking(_) => Some((10.0, true)),
        _ => None,
    }
}

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
    let healthy_hours: f64 = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(hours);
    let root = host_tests::repo_root();
    let paper = compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset");
    let mut nominals = vec![paper];
    nominals.extend((0..designs).map(|i| design(seed.wrapping_mul(1000) + i as u64)));
    println!(
        "{} designs (the paper preset and {designs} seeded, seed {seed}), {hours} h per faulty run, {healthy_hours} h healthy per design\n",
        nominals.len()
    );
    let faults: Vec<bool> = match args.get(5).map(String::as_str) {
        None | Some("all") => vec![true; Fault::CATALOGUE.len()],
        Some(list) => {
            let chosen: Vec<Fault> = list
                .split(',')
                .map(|f| Fault::parse(f).unwrap_or_else(|e| panic!("faults: {e}")))
                .collect();
            for f in &chosen {
                assert!(Fault::CATALOGUE.contains(f), "faults: {f} is not in the catalogue");
            }
            Fault::CATALOGUE
                .iter()
                .enumerate()
                .map(|(i, f)| i == 0 || chosen.contains(f))
                .collect()
        }
    };
    let threads = std::env::var("COMPENSATOR_JOBS")
        .ok()
        .and_then(|j| j.parse::<usize>().ok())
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let verbose = std::env::var("COMPENSATOR_VERBOSE").is_ok_and(|v| v == "1");
    for &q in &sensors {
        println!("sensor {}:\n", q.name());
        println!(
            "| fault | runs | detected | named right | named wrong | named after median / worst [s] | goal | met |"
        );
        println!("|---|---|---|---|---|---|---|---|");
        // Every (design, catalogue index) run, the healthy baseline over its
        // own length.
        let mut jobs: Vec<(usize, usize, Scenario)> = Vec::new();
        for (d, nominal) in nominals.iter().enumerate() {
            let lead = ((seed * 7 + d as u64) % 21) as f64;
            let runs = catalogue_before_move(nominal, q, hours * 3600.0, seed + d as u64, lead);
            for (i, s) in runs.into_iter().enumerate().filter(|(i, _)| faults[*i]) {
                let s = if i == 0 {
                    let mut h = Scenario::ordinary(nominal, q, s.injection, healthy_hours * 3600.0, seed + d as u64);
                    h.sensor = s.sensor;
                    h
                } else {
                    s
                };
                jobs.push((d, i, s));
            }
        }
        let next = std::sync::atomic::AtomicUsize::new(0);
        let done: Vec<(usize, usize, Result<Outcome, String>)> = std::thread::scope(|scope| {
            let workers: Vec<_> = (0..threads)
                .map(|_| {
                    scope.spawn(|| {
                        let mut mine = Vec::new();
                        loop {
                            let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            let Some((d, i, s)) = jobs.get(k) else { break };
                            mine.push((*d, *i, run(s)));
                        }
                        mine
                    })
                })
                .collect();
            workers
                .into_iter()
                .flat_map(|w| w.join().expect("a campaign thread panicked"))
                .collect()
        });
        let mut done = done;
        done.sort_by_key(|(d, i, _)| (*d, *i));
        let mut per_fault: Vec<Vec<Outcome>> = vec![Vec::new(); Fault::CATALOGUE.len()];
        let (mut false_alarms, mut healthy) = (0u32, 0.0f64);
        for (d, i, result) in done {
            match result {
                Ok(o) => {
                    if verbose {
                        eprintln!("design {d} {}: {o:?}", Fault::CATALOGUE[i]);
                    }
                    if i == 0 {
                        healthy += o.healthy_time;
                        false_alarms += o.false_alarms;
                    }
                    per_fault[i].push(o);
                }
                Err(e) => eprintln!("design {d} {}: {e}", Fault::CATALOGUE[i]),
            }
        }
        let (mut right_all, mut named_all) = (0usize, 0usize);
        for (i, fault) in Fault::CATALOGUE.iter().enumerate().skip(1).filter(|(i, _)| faults[*i]) {
            let runs = &per_fault[i];
            let valid: Vec<&Outcome> = runs.iter().filter(|o| o.false_alarm.is_none()).collect();
            let n = valid.len().max(1) as f64;
            let detected = valid.iter().filter(|o| o.detected.is_some()).count();
            let want = expected(*fault, q);
            let is_right = |o: &Outcome| o.named.is_some_and(|(_, f)| want.is_some_and(|w| f.0 & w.0 != 0));
            let right: Vec<&&Outcome> = valid.iter().filter(|o| is_right(o)).collect();
            let wrong = valid.iter().filter(|o| o.named.is_some() && !is_right(o)).count();
            right_all += right.len();
            named_all += right.len() + wrong;
            let mut delays: Vec<f64> = right.iter().filter_map(|o| o.named.map(|(t, _)| t)).collect();
            delays.sort_by(f64::total_cmp);
            let median = delays.get(delays.len() / 2).map_or("-".into(), |x| format!("{x:.1}"));
            let worst = delays.last().map_or("-".into(), |x| format!("{x:.1}"));
            let (goal_text, met) = match (goal(*fault), want) {
                (Some((within, from_held)), Some(_)) => {
                    let eligible: Vec<&&Outcome> = valid
                        .iter()
                        .filter(|o| {
                            if from_held {
                                o.held.is_some()
                            } else {
                                o.spanned.is_some_and(|t| t <= within)
                            }
                        })
                        .collect();
                    let ok = eligible
                        .iter()
                        .filter(|o| {
                            is_right(o)
                                && o.named.is_some_and(|(t, _)| {
                                    t <= within + if from_held { o.held.unwrap_or(0.0) } else { 0.0 }
                                })
                        })
                        .count();
                    let text = if from_held {
                        format!("named <= {within:.0} s after held")
                    } else {
                        format!("named <= {within:.0} s, 5 C in it")
                    };
                    (
                        text,
                        format!(
                            "{ok} / {} ({:.0} %)",
                            eligible.len(),
                            100.0 * ok as f64 / eligible.len().max(1) as f64
                        ),
                    )
                }
                _ => ("-".into(), "-".into()),
            };
            println!(
                "| {fault} | {} | {:.0} % | {} | {wrong} | {median} / {worst} | {goal_text} | {met} |",
                valid.len(),
                100.0 * detected as f64 / n,
                if want.is_some() {
                    format!("{:.0} %", 100.0 * right.len() as f64 / n)
                } else {
                    "not observable".into()
                },
            );
        }
        println!(
            "\nfalse alarms: {false_alarms} in {:.1} h of healthy operation ({:.2} per 24 h); isolation: {right_all} of {named_all} named right ({:.1} %)\n",
            healthy / 3600.0,
            f64::from(false_alarms) / (healthy / 86_400.0),
            100.0 * right_all as f64 / named_all.max(1) as f64
        );
    }
}
