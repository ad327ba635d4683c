//! The envelope survey at any size: `cargo run --release -p host-tests
//! --example survey -- --designs 10000 [--seed S]`. Prints the figures
//! table (`docs/dynamics.md`), the substeps chosen and every failure; exits
//! 1 when anything fails. Defaults: 1,000 designs, seed 0x5EED2026.
use clap::Parser;
use host_tests::survey::survey;

/// The envelope survey: random designs against the reference.
#[derive(Parser)]
struct Args {
    /// Random designs (count).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    designs: usize,
    /// Seed of the designs (decimal; the default is 0x5EED2026).
    #[arg(long, value_name = "S", default_value_t = 0x5EED_2026)]
    seed: u64,
}

fn main() {
    let Args { designs: count, seed } = Args::parse();
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
