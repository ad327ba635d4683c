//! The envelope survey at any size: `cargo run --release -p host-tests
//! --example survey -- --designs 10000 [--seed S]`. Prints the figures
//! table (`docs/dynamics.md`), the substeps chosen and every failure; exits
//! 1 when anything fails.
use host_tests::survey::survey;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |name: &str, default: u64| -> u64 {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .map(|v| v.parse().unwrap_or_else(|_| panic!("{name}: not a number: {v}")))
            .unwrap_or(default)
    };
    let (count, seed) = (value("--designs", 1000) as usize, value("--seed", 0x5EED_2026));
    let t = std::time::Instant::now();
    let r = survey(count, seed);
    println!(
        "{} designs, seed {seed:#x}, {:.0} s\n",
        r.designs,
        t.elapsed().as_secs_f64()
    );
    print!("{}", r.table());
    println!("\nsubsteps per tick chosen (substeps, designs): {:?}", r.substeps);
    println!("chooser estimate above its target: {} designs", r.chooser_misses);
    for f in &r.failures {
        println!("FAIL {f}");
    }
    std::process::exit(i32::from(!r.failures.is_empty()));
}
