use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::Precision;
use host_tests::random::Rng;
use host_tests::survey::{Solved, designs, steps};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let auto = a[1] == "auto";
    let scheme = Scheme::from_name(if auto { "sdirk3" } else { &a[1] }).unwrap();
    let substeps: u8 = a[2].parse().unwrap();
    let n: usize = a[3].parse().unwrap();
    let verbose = a.get(4).is_some();
    let cfg = TwinConfig {
        scheme,
        substeps,
        ..TwinConfig::SHIPPED
    };
    let ps = [Precision::F64, Precision::F32, Precision::Fixed];
    let goals = [0.1, 0.5, 1.0];
    let mut rng = Rng::new(7);
    let (mut end_fail, mut traj_fail, mut cases, mut ref_fail) = ([0; 3], [0; 3], 0, 0);
    let mut worst_end = [0.0f64; 3];
    let mut worst_traj = [0.0f64; 3];
    let mut hist = std::collections::BTreeMap::new();
    let t0 = std::time::Instant::now();
    for (i, raw) in designs(n, 0xD5).iter().enumerate() {
        let cfg = if auto {
            let p = compensator::Params::<f64>::new(raw).unwrap();
            let ch =
                compensator::dynamics::config::choose(&p, 1e-3, (raw.estimator.valid_min, raw.estimator.valid_max))
                    .unwrap();
            *hist.entry(ch.config.substeps).or_insert(0) += 1;
            if !ch.goal_met || verbose {
                println!(
                    "design {i}: chose {} est {:.4} met {}",
                    ch.config.substeps, ch.estimated_error_pct, ch.goal_met
                );
            }
            ch.config
        } else {
            cfg
        };
        for st in steps(raw, &mut rng) {
            let s = match Solved::new(raw, st) {
                Ok(s) => s,
                Err(e) => {
                    ref_fail += 1;
                    println!("design {i} {st:?}: reference failed {e}");
                    continue;
                }
            };
            cases += 1;
            for k in 0..3 {
                match s.outcome(ps[k], cfg) {
                    Err(e) => {
                        end_fail[k] += 1;
                        println!("design {i} {st:?} {:?}: ERROR {e}", ps[k]);
                    }
                    Ok(o) => {
                        let e = o.x_end.max(o.p_end);
                        worst_end[k] = worst_end[k].max(e);
                        if e > 1e-3 {
                            end_fail[k] += 1;
                            println!("design {i} {st:?} {:?}: end x {:.2e} p {:.2e}", ps[k], o.x_end, o.p_end);
                        }
                        if let Some(t) = o.trajectory_pct {
                            worst_traj[k] = worst_traj[k].max(t);
                            if t > goals[k] {
                                traj_fail[k] += 1;
                                if verbose {
                                    println!("design {i} {st:?} {:?}: traj {t:.3} %", ps[k]);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    println!("chosen {hist:?} in {:?}", t0.elapsed());
    println!(
        "cases {cases} (reference failures {ref_fail}); end failures {end_fail:?} worst {worst_end:?}; trajectory failures {traj_fail:?} worst {worst_traj:.3?}"
    );
}
