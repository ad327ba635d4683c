use compensator::Params;
use compensator::Real;
use compensator::dynamics::{Scheme, Twin, TwinConfig};
use compensator::scalar::Fixed;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let raw = compensator_cli::load(std::path::Path::new(&a[1])).unwrap();
    let from: f32 = a[2].parse().unwrap();
    let to: f32 = a[3].parse().unwrap();
    let n: usize = a[4].parse().unwrap();
    let every: usize = a[5].parse().unwrap();
    let p = Params::<f32>::new(&raw).unwrap();
    let cfg = TwinConfig {
        scheme: Scheme::Sdirk3,
        ..TwinConfig::SHIPPED
    };
    let mut tw = Twin::<f32, Fixed>::new(&p, cfg, from).unwrap();
    let mut tf = Twin::<f32, f64>::new(&p, cfg, from).unwrap();
    tw.set_temperature(to).unwrap();
    tf.set_temperature(to).unwrap();
    println!("{:?}", tw.coefficients());
    for k in 0..n {
        tw.tick().unwrap();
        tf.tick().unwrap();
        if k % every == 0 {
            let (x, y) = (tw.raw_state(), tf.raw_state());
            println!(
                "{k} fx {:.7} {:.7} {:.7} {:.7} | f64 {:.7} {:.7} {:.7} {:.7}",
                x[0].to_f64(),
                x[1].to_f64(),
                x[2].to_f64(),
                x[3].to_f64(),
                y[0],
                y[1],
                y[2],
                y[3]
            );
        }
    }
}
