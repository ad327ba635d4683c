use compensator::Params;
use compensator::dynamics::{Scheme, Twin, TwinConfig};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let scheme = Scheme::from_name(&a[1]).unwrap();
    let sub: u8 = a[2].parse().unwrap();
    let n: usize = a[3].parse().unwrap();
    let from: f32 = a[4].parse().unwrap();
    let to: f32 = a[5].parse().unwrap();
    let raw = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = TwinConfig {
        scheme,
        substeps: sub,
        ..TwinConfig::SHIPPED
    };
    let mut tw = Twin::<f32, f32>::new(&p, cfg, from).unwrap();
    tw.set_temperature(to).unwrap();
    for _ in 0..n {
        std::hint::black_box(tw.tick().unwrap());
    }
    println!("{:?}", tw.raw_state());
}
