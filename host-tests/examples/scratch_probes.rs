use compensator::dynamics::config::probes;
use compensator::dynamics::{Scheme, Twin, TwinConfig};
fn run(p: &compensator::Params<f64>, n: u8, from: f64, to: f64, ticks: usize) -> Vec<f64> {
    let cfg = TwinConfig {
        scheme: Scheme::Sdirk3,
        substeps: n,
        tick: 1e-3,
    };
    let mut t = Twin::<f64, f64>::new(p, cfg, from).unwrap();
    t.set_temperature(to).unwrap();
    let mut v = vec![t.state().x];
    for _ in 0..ticks {
        t.tick().unwrap();
        v.push(t.state().x);
    }
    v
}
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let raw = compensator_cli::load(std::path::Path::new(&a[1])).unwrap();
    let p = compensator::Params::<f64>::new(&raw).unwrap();
    for (from, to) in probes((26.0, 78.0)) {
        let f = run(&p, 64, from, to, 500);
        let step = (f[500] - f[0]).abs();
        let r = compensator_reference::dynamics::simulate(
            &raw.core,
            compensator_reference::dynamics::Profile::Step { from, to },
            0.5,
            1e-3,
            compensator_reference::dynamics::Method::Radau5,
            1e-10,
        )
        .unwrap();
        let reff: Vec<f64> = r.state.iter().map(|s| s[0]).collect();
        let e64 = f.iter().zip(&reff).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / step * 100.0;
        print!("{from}->{to} step {:.3} fine-vs-ref {e64:.4}: ", step / raw.core.stroke);
        for n in [1u8, 2, 4, 8, 16] {
            let c = run(&p, n, from, to, 500);
            let d = f.iter().zip(&c).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / step * 100.0;
            let e = reff.iter().zip(&c).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / step * 100.0;
            print!("n{n} est {d:.4} true {e:.4}  ");
        }
        println!();
    }
}
