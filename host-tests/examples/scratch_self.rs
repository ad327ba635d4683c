use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::{Precision, simulate};
use compensator_reference::dynamics::Profile;
use host_tests::random::Rng;
use host_tests::survey::{Solved, designs, steps};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let nd: usize = a[1].parse().unwrap();
    let mut rng = Rng::new(7);
    let mut under = 0;
    let mut total = 0;
    for (i, raw) in designs(nd, 0xD5).iter().enumerate() {
        for st in steps(raw, &mut rng) {
            let s = Solved::new(raw, st).unwrap();
            let moved = (s.x_ref[s.ticks] - s.x_ref[0]).abs();
            if moved < 0.01 * raw.core.stroke {
                continue;
            }
            let prof = Profile::Step {
                from: st.from,
                to: st.to,
            };
            let xs = |n: u8| -> Vec<f64> {
                simulate(
                    raw,
                    Precision::F64,
                    TwinConfig {
                        scheme: Scheme::Sdirk3,
                        substeps: n,
                        ..TwinConfig::SHIPPED
                    },
                    &prof,
                    s.ticks,
                )
                .unwrap()
                .state
                .iter()
                .map(|s| s.x)
                .collect()
            };
            let ladder = [1u8, 2, 4, 8, 16, 32, 64];
            let runs: Vec<Vec<f64>> = ladder.iter().map(|&n| xs(n)).collect();
            let mut line = format!("d{i} {:?} ", st.kind);
            for k in 0..ladder.len() - 1 {
                let e = runs[k]
                    .iter()
                    .zip(&s.x_ref)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / moved
                    * 100.0;
                let est = runs[k]
                    .iter()
                    .zip(&runs[k + 1])
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / moved
                    * 100.0;
                total += 1;
                if e > 0.05 && e > 1.5 * est {
                    under += 1;
                    line += &format!(" [n{} true {e:.3} est {est:.3}]", ladder[k]);
                }
            }
            if line.contains('[') {
                println!("{line}");
            }
        }
    }
    println!("underestimates {under} of {total}");
}
