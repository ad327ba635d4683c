use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::Precision;
use host_tests::random::Rng;
use host_tests::survey::{Solved, designs, steps};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let want: usize = a[1].parse().unwrap();
    let n: usize = want + 1;
    let mut rng = Rng::new(7);
    let ds = designs(n, 0xD5);
    for (i, raw) in ds.iter().enumerate() {
        let sts = steps(raw, &mut rng);
        if i != want {
            continue;
        }
        let p = compensator::Params::<f64>::new(raw).unwrap();
        for t in [26.0, 52.0, 78.0, -20.0] {
            let l = compensator::dynamics::linear::linearise(&p, t).unwrap();
            println!(
                "eig at {t}: {:?}",
                l.eigenvalues.iter().map(|e| (e.re, e.im)).collect::<Vec<_>>()
            );
        }
        for st in sts {
            let s = Solved::new(raw, st).unwrap();
            print!("{:?} {:.1}->{:.1}: ", st.kind, st.from, st.to);
            for sub in [1u8, 2, 4, 8, 16, 32, 64] {
                let cfg = TwinConfig {
                    scheme: Scheme::Sdirk3,
                    substeps: sub,
                    ..TwinConfig::SHIPPED
                };
                let o = s.outcome(Precision::F64, cfg).unwrap();
                print!("{sub}:{:.4} ", o.trajectory_pct.unwrap_or(f64::NAN));
            }
            println!();
        }
    }
}
