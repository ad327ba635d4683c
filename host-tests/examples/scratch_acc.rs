use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::{Precision, simulate};
use host_tests::accuracy::{Case, paper_cases, random_cases};

fn err(c: &Case, p: Precision, cfg: TwinConfig) -> f64 {
    match simulate(&c.raw, p, cfg, &c.profile, c.ticks) {
        Ok(r) => c.error_pct(&r.state.iter().map(|s| s.x).collect::<Vec<_>>()),
        Err(_) => f64::INFINITY,
    }
}
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let scheme = Scheme::from_name(&a[1]).unwrap();
    let substeps: u8 = a[2].parse().unwrap();
    let n: usize = a.get(3).map(|s| s.parse().unwrap()).unwrap_or(50);
    let cfg = TwinConfig {
        scheme,
        substeps,
        ..TwinConfig::SHIPPED
    };
    let raw = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).unwrap();
    let mut worst = [0.0f64; 3];
    let mut ok = [0usize; 3];
    let goals = [0.1, 0.5, 1.0];
    let ps = [Precision::F64, Precision::F32, Precision::Fixed];
    let mut all = paper_cases(&raw);
    let np = all.len();
    all.extend(random_cases(n));
    for (i, c) in all.iter().enumerate() {
        let e: Vec<f64> = ps.iter().map(|p| err(c, *p, cfg)).collect();
        for k in 0..3 {
            worst[k] = worst[k].max(e[k]);
            ok[k] += (e[k] <= goals[k]) as usize;
        }
        if e.iter().zip(goals).any(|(e, g)| *e > g) || i < np {
            println!("{i} {:?} f64 {:.4} f32 {:.4} fx {:.4}", c.profile, e[0], e[1], e[2]);
        }
    }
    println!(
        "worst f64 {:.4} f32 {:.4} fx {:.4}; ok {:?} of {}",
        worst[0],
        worst[1],
        worst[2],
        ok,
        all.len()
    );
}
