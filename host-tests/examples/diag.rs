//! scratch diagnostics (not committed)
use compensator::Params;
use compensator::dynamics::{Model, Twin, TwinConfig};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let raw = compensator_cli::load(std::path::Path::new(&a[1])).unwrap();
    let from: f64 = a[2].parse().unwrap();
    let to: f64 = a[3].parse().unwrap();
    let n: usize = a[4].parse().unwrap();
    let sub: u8 = a.get(5).map(|s| s.parse().unwrap()).unwrap_or(2);
    let p = Params::<f64>::new(&raw).unwrap();
    let m = Model::new(&p).unwrap();
    println!("scales {:?}", m.scales);
    let c: compensator::dynamics::fsi::Coefficients<f64> = m.coefficients(&p.oil.state(to).unwrap()).unwrap();
    println!("coef {:?}", c);
    let scheme = compensator::dynamics::Scheme::from_name(&a.get(6).cloned().unwrap_or("sdirk3".into())).unwrap();
    let cfg = TwinConfig {
        substeps: sub,
        scheme,
        ..TwinConfig::SHIPPED
    };
    let mut tw = Twin::<f64, f64>::new(&p, cfg, from).unwrap();
    tw.set_temperature(to).unwrap();
    for k in 0..n {
        let r = tw.tick();
        println!("{k} {:?} {:?}", tw.raw_state(), r);
    }
}
