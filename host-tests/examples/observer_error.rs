//! Study: the oil-temperature observer's error beyond the probe's fixed tolerance over the
//! campaign's healthy histories, binned by the observer's own standard deviation and rate.
//!
//!     cargo run --release -p host-tests --example observer_error -- [DESIGNS] [HOURS]
//!
//! Defaults: the paper preset and 4 random designs (`host_tests::campaign::design`,
//! seeds from 1000), 1.5 h histories.
use clap::Parser;
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig};
use host_tests::campaign::{Quantity, catalogue, design};

/// The oil-temperature observer's error beyond the probe's fixed tolerance
/// over the campaign's healthy histories.
#[derive(Parser)]
struct Args {
    /// Random designs beside the paper preset (count).
    #[arg(value_name = "DESIGNS", default_value_t = 4)]
    designs: u64,
    /// Each history's length [hours].
    #[arg(value_name = "HOURS", default_value_t = 1.5)]
    hours: f64,
}

fn main() {
    let Args { designs, hours } = Args::parse();
    let root = host_tests::repo_root();
    let mut bins = vec![(0usize, 0.0f64, 0.0f64); 12];
    let mut ratio_hist = vec![0usize; 12];
    for d in 0..=designs {
        let nominal = if d == 0 {
            compensator_cli::load(&root.join("presets/paper.toml")).unwrap()
        } else {
            design(1000 + d - 1)
        };
        let s = &catalogue(&nominal, Quantity::PA, hours * 3600.0, 1 + d)[0];
        let p32 = Params::<f32>::new(&s.nominal).unwrap();
        let config = EstimatorConfig::new(&s.nominal).unwrap();
        let (ta, tb) = (s.nominal.probe.tolerance_a, s.nominal.probe.tolerance_b);
        let mut records = s.records().unwrap().peekable();
        let first = records.peek().and_then(|r| r.probe).unwrap();
        let mut est = Estimator::new(&p32, config, first as f32).unwrap();
        let mut tick = 0u64;
        let mut worst = (0.0f64, 0.0, 0.0, 0.0);
        for r in records {
            while tick < r.tick {
                est.tick(Ok(None));
                tick += 1;
            }
            let e = est.tick(Ok(r.probe.map(|v| v as f32)));
            tick += 1;
            if r.second.is_none() || r.t < 60.0 {
                continue;
            }
            let bias = s.probe_class * (ta + tb * r.t_true.abs());
            let err = f64::from(e.temperature) - r.t_true - bias;
            let sd = f64::from(est.observer().variance(est.config().observer_design())).sqrt();
            let rate = f64::from(est.observer().rate()).abs();
            let b = ((rate / 0.1).floor() as usize).min(11);
            bins[b].0 += 1;
            bins[b].1 += err * err;
            bins[b].2 = bins[b].2.max(err.abs());
            let k = ((err.abs() / sd).floor() as usize).min(11);
            ratio_hist[k] += 1;
            if err.abs() > worst.0 {
                worst = (err.abs(), r.t, rate, sd);
            }
        }
        println!(
            "design {d}: tau {} well {} worst |e| {:.3} K at t {:.1} s (rate {:.3}, sd {:.3})",
            s.nominal.probe.time_constant, s.nominal.probe.well_time_constant, worst.0, worst.1, worst.2, worst.3
        );
    }
    println!("|rate| bin [C/s]  n  rms  max");
    for (i, (n, ss, mx)) in bins.iter().enumerate() {
        if *n > 0 {
            println!(
                "{:.1}-{:.1} {n} {:.4} {:.4}",
                i as f64 * 0.1,
                (i + 1) as f64 * 0.1,
                (ss / *n as f64).sqrt(),
                mx
            );
        }
    }
    println!("|e|/sd histogram: {ratio_hist:?}");
}
