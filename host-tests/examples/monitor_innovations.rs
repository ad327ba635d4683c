//! The monitor's standardised innovations over healthy histories: how close
//! to white unit normal they are (their moments, tails, autocorrelation),
//! and the largest value two-sided CUSUMs of several drifts reach on them:
//! what the CUSUM's drift and threshold are chosen from
//! (`docs/monitoring.md`).
//!
//!     cargo run --release -p host-tests --example monitor_innovations -- [designs] [seed] [hours] [sensors]
use host_tests::campaign::Injection;
use host_tests::campaign::{Quantity, Scenario, design};
use host_tests::monitor_campaign::Replay;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let designs: u64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(4);
    let seed: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1);
    let hours: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1.5);
    let sensors: Vec<Quantity> = args
        .get(3)
        .map_or("p_a,x", String::as_str)
        .split(',')
        .filter_map(Quantity::parse)
        .collect();
    let drifts = [0.5f64, 1.0, 1.5, 2.0, 3.0];
    let root = host_tests::repo_root();
    for &q in &sensors {
        let mut hist = [0u64; 9];
        let (mut n, mut s1, mut s2, mut lag1, mut lag50) = (0u64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut worst = vec![0.0f64; drifts.len()];
        for d in 0..=designs {
            let nominal = if d == 0 {
                compensator_cli::load(&root.join("presets/paper.toml")).unwrap()
            } else {
                design(seed.wrapping_mul(1000) + d - 1)
            };
            let s = Scenario::ordinary(&nominal, q, Injection::HEALTHY, hours * 3600.0, seed + d);
            let mut replay = Replay::new(&s).unwrap();
            let mut zs: Vec<f64> = Vec::new();
            let mut last = f32::NAN;
            while let Some((r, _)) = replay.next_fed() {
                let est = &mut replay.estimator;
                let z = est.health().innovation;
                if z.is_finite() && z.to_bits() != last.to_bits() && r.t > 300.0 {
                    zs.push(f64::from(z));
                }
                last = z;
            }
            let mut dmax = vec![0.0f64; drifts.len()];
            for (i, k) in drifts.iter().enumerate() {
                let (mut up, mut dn) = (0.0f64, 0.0f64);
                for z in &zs {
                    let zc = z.clamp(-8.0, 8.0);
                    up = (up + zc - k).max(0.0);
                    dn = (dn - zc - k).max(0.0);
                    dmax[i] = dmax[i].max(up).max(dn);
                }
                worst[i] = worst[i].max(dmax[i]);
            }
            for (i, z) in zs.iter().enumerate() {
                n += 1;
                s1 += z;
                s2 += z * z;
                hist[(z.abs().floor() as usize).min(8)] += 1;
                if i >= 1 {
                    lag1 += z * zs[i - 1];
                }
                if i >= 50 {
                    lag50 += z * zs[i - 50];
                }
            }
            println!(
                "{} design {d}: readings {} largest CUSUM by drift {drifts:?}: {:?}",
                q.name(),
                zs.len(),
                dmax.iter().map(|v| (v * 10.0).round() / 10.0).collect::<Vec<_>>()
            );
        }
        let nf = n as f64;
        let var = s2 / nf - (s1 / nf).powi(2);
        println!(
            "{}: n {n}, mean {:.3}, variance {:.3}, lag-1 corr {:.3}, lag-50 corr {:.3}",
            q.name(),
            s1 / nf,
            var,
            lag1 / s2,
            lag50 / s2
        );
        println!("|z| in [k, k+1): {hist:?}");
        println!(
            "largest CUSUM over all designs by drift {drifts:?}: {:?}\n",
            worst.iter().map(|v| (v * 10.0).round() / 10.0).collect::<Vec<_>>()
        );
    }
}
