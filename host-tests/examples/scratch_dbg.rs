use compensator::dynamics::{Scheme, Twin, TwinConfig};
use host_tests::random::Rng;
use host_tests::survey::{designs, steps};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let want: usize = a[1].parse().unwrap();
    let kind: usize = a[2].parse().unwrap();
    let n: usize = a[3].parse().unwrap();
    let mut rng = Rng::new(7);
    let ds = designs(want + 1, 0xD5);
    let mut st = None;
    for (i, raw) in ds.iter().enumerate() {
        let s = steps(raw, &mut rng);
        if i == want {
            st = Some(s[kind]);
        }
    }
    let st = st.unwrap();
    let raw = ds[want];
    let p = compensator::Params::<f64>::new(&raw).unwrap();
    let cfg = TwinConfig {
        scheme: Scheme::Sdirk3,
        substeps: 2,
        ..TwinConfig::SHIPPED
    };
    let mut tw = Twin::<f64, f64>::new(&p, cfg, st.from).unwrap();
    tw.set_temperature(st.to).unwrap();
    for k in 0..n {
        let r = tw.tick();
        let y = tw.raw_state();
        let c = tw.coefficients();
        println!(
            "{k} {:?} force {:.4} qs {:.4} {:?}",
            y,
            c.static_force(&y),
            c.quasi_steady_force(y[0]),
            r
        );
    }
}
