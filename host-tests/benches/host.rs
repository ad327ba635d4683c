//! Host cost of the core's hot paths: `cargo bench -p host-tests --bench host`
//! prints wall-clock time per operation; `cargo xtask callgrind` runs the
//! same workloads under valgrind's callgrind, whose instruction counts are
//! repeatable, and compares them with `host-tests/benches/callgrind-baseline.txt`.
//!
//! `host [WORKLOAD]`: one workload (what callgrind measures), or all.

use compensator::dynamics::{Scheme, Twin, TwinConfig};
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::scalar::Fixed;
use compensator::{Params, equilibrium::equilibrium};
use std::hint::black_box;
use std::time::Instant;

use host_tests::bench::{COUNT, WORKLOADS};

fn params<T: compensator::Float>() -> (compensator::RawParams, Params<T>) {
    let raw = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).expect("preset");
    let p = Params::new(&raw).expect("valid");
    (raw, p)
}

fn twin_ticks<T: compensator::Real>(config: TwinConfig) {
    let (_, p) = params::<f32>();
    let mut twin = Twin::<f32, T>::new(&p, config, 30.0).unwrap();
    twin.set_temperature(40.0).unwrap();
    for _ in 0..COUNT {
        black_box(twin.tick().unwrap());
    }
}

fn run(name: &str) -> bool {
    let ros3 = TwinConfig::SHIPPED;
    match name {
        "twin-f32" => twin_ticks::<f32>(ros3),
        "twin-f64" => twin_ticks::<f64>(ros3),
        "twin-q12.20" => twin_ticks::<Fixed>(ros3),
        "twin-ros2-f32" => twin_ticks::<f32>(TwinConfig {
            scheme: Scheme::Ros2,
            substeps: 1,
            ..ros3
        }),
        "equilibrium-f32" => {
            let (_, p) = params::<f32>();
            for k in 0..COUNT {
                black_box(equilibrium(&p, black_box(30.0 + (k % 50) as f32)).unwrap());
            }
        }
        "fluid-f32" => {
            let (_, p) = params::<f32>();
            for k in 0..COUNT {
                black_box(p.oil.point(black_box(30.0 + (k % 50) as f32)).unwrap());
            }
        }
        "estimator-f32" => {
            let (raw, p) = params::<f32>();
            let cfg = EstimatorConfig::new(&raw).unwrap();
            let mut est = Estimator::new(&p, cfg, 30.0).unwrap();
            for k in 0..COUNT {
                black_box(est.tick(if k % 20 == 0 { Ok(Some(40.0)) } else { Ok(None) }));
            }
        }
        "setup" => {
            let _ = params::<f32>();
        }
        _ => return false,
    }
    true
}

fn main() {
    // `cargo bench` passes `--bench`; a workload name selects one.
    let arg = std::env::args().skip(1).find(|a| !a.starts_with("--"));
    match arg {
        // For `cargo xtask callgrind`: the operation count and the workloads.
        Some(list) if list == "list" => {
            println!("count {COUNT}");
            for name in WORKLOADS {
                println!("workload {name}");
            }
        }
        Some(name) => {
            if !run(&name) {
                eprintln!("unknown workload {name}");
                std::process::exit(2);
            }
        }
        None => {
            for name in WORKLOADS {
                let t0 = Instant::now();
                run(name);
                let per = t0.elapsed().as_secs_f64() / COUNT as f64;
                println!(
                    "{name:16} {:8.1} ns per operation (wall clock; see `cargo xtask callgrind` for counts)",
                    per * 1e9
                );
            }
        }
    }
}
