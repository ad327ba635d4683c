//! The twin's errors against the reference, per precision, on the paper
//! cases and the 50 random cases of the accuracy goals (what
//! `docs/dynamics.md` reports): `cargo run --release -p host-tests --example accuracy_survey`.
use compensator::dynamics::TwinConfig;
use compensator_cli::dynamics::Precision;
use host_tests::accuracy::{paper_cases, random_cases};

fn main() {
    let raw = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml")).unwrap();
    let cfg = TwinConfig::SHIPPED;
    let precisions = [
        Precision::F64,
        Precision::F32,
        Precision::Fixed,
        Precision::FixedQ16,
        Precision::FixedQ24,
    ];
    println!("case,step_stroke,dominant_re,f64,f32,q12.20,q16.16,q8.24");
    let report = |name: String, c: &host_tests::accuracy::Case| {
        let p = compensator::Params::<f64>::new(&c.raw).unwrap();
        let lam = compensator::dynamics::linear::linearise(&p, c.profile.end())
            .unwrap()
            .dominant;
        let e: Vec<String> = precisions
            .iter()
            .map(|p| format!("{:.4}", c.error_pct(&c.twin(*p, cfg))))
            .collect();
        println!(
            "{name},{:.3},{:.1}{:+.1}i,{}",
            c.step / c.raw.core.stroke,
            lam.re,
            lam.im,
            e.join(",")
        );
    };
    for c in paper_cases(&raw) {
        report(format!("paper {:?}", c.profile).replace(',', ";"), &c);
    }
    for (i, c) in random_cases(50).iter().enumerate() {
        report(format!("random {i} {:?}", c.profile).replace(',', ";"), c);
    }
}
