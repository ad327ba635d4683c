//! One case of `random_cases` in detail: coefficients and trajectories.
//! `cargo run --release -p host-tests --example case_dump -- INDEX`
//! (default 0, the first case).
use clap::Parser;
use compensator::dynamics::TwinConfig;
use compensator_cli::dynamics::Precision;
use host_tests::accuracy::random_cases;

/// One case of `random_cases` in detail: coefficients and trajectories.
#[derive(Parser)]
struct Args {
    /// The case's index among `random_cases` (from 0).
    #[arg(value_name = "INDEX", default_value_t = 0)]
    index: usize,
}

fn main() {
    let want = Args::parse().index;
    let c = random_cases(want + 1).pop().unwrap();
    let p = compensator::Params::<f64>::new(&c.raw).unwrap();
    let m = compensator::dynamics::Model::new(&p).unwrap();
    println!("{:?}\nscales {:?}", c.profile, m.scales);
    for t in [c.profile.start(), c.profile.end()] {
        let coef: compensator::dynamics::fsi::Coefficients<f64> = m.coefficients(&p.oil.state(t).unwrap()).unwrap();
        println!("coefficients at {t}: {coef:?}");
    }
    let x64 = c.twin(Precision::F64, TwinConfig::SHIPPED);
    let xf = c.twin(Precision::Fixed, TwinConfig::SHIPPED);
    let step = (c.ticks / 30).max(1);
    for k in (0..c.ticks).step_by(step) {
        println!(
            "{:.3} ref {:.6e} f64 {:.6e} q12.20 {:.6e}",
            k as f64 * 1e-3,
            c.x_ref[k],
            x64[k],
            xf[k]
        );
    }
}
