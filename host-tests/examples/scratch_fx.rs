use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::Precision;
use host_tests::random::Rng;
use host_tests::survey::{Solved, designs, steps};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let want: usize = a[1].parse().unwrap();
    let kind: usize = a[2].parse().unwrap();
    let mut rng = Rng::new(7);
    let ds = designs(want + 1, 0xD5);
    let mut st = None;
    for (i, raw) in ds.iter().enumerate() {
        let s = steps(raw, &mut rng);
        if i == want {
            st = Some(s[kind]);
        }
    }
    let raw = ds[want];
    let s = Solved::new(&raw, st.unwrap()).unwrap();
    for n in [2u8, 4, 8, 16, 32] {
        let cfg = TwinConfig {
            scheme: Scheme::Sdirk3,
            substeps: n,
            ..TwinConfig::SHIPPED
        };
        let e: Vec<String> = [
            Precision::F64,
            Precision::F32,
            Precision::Fixed,
            Precision::FixedQ16,
            Precision::FixedQ24,
        ]
        .iter()
        .map(|p| {
            s.outcome(*p, cfg)
                .map(|o| {
                    format!(
                        "{:.4}/{:.1e}",
                        o.trajectory_pct.unwrap_or(f64::NAN),
                        o.x_end.max(o.p_end)
                    )
                })
                .unwrap_or("err".into())
        })
        .collect();
        println!("n{n}: {e:?}");
    }
}
