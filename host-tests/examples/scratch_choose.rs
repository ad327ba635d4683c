fn main() {
    let a: Vec<String> = std::env::args().collect();
    let raw = compensator_cli::load(std::path::Path::new(&a[1])).unwrap();
    let p = compensator::Params::<f64>::new(&raw).unwrap();
    let t = std::time::Instant::now();
    let ch =
        compensator::dynamics::config::choose(&p, 1e-3, (raw.estimator.valid_min, raw.estimator.valid_max)).unwrap();
    println!("{ch:?} in {:?}", t.elapsed());
}
