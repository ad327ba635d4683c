//! Error of the f64 twin against the reference for growing substep counts,
//! on the random sets where 2 substeps miss 0.1 %.
use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::Precision;
use compensator_reference::dynamics::Profile;
use host_tests::accuracy::{Case, random_step, settle_time};
use host_tests::random::{Rng, physical_params};

fn main() {
    let mut rng = Rng::new(0x5EED);
    for i in 0..50 {
        let raw = physical_params(&mut rng);
        let Some((from, to)) = random_step(&raw, &mut rng) else {
            continue;
        };
        if ![0, 11, 15, 16, 18, 19, 46, 48].contains(&i) {
            continue;
        }
        let p = compensator::Params::<f64>::new(&raw).unwrap();
        let wn = (raw.core.spring_rate / raw.core.mass).sqrt();
        let lam = compensator::dynamics::linear::linearise(&p, to).unwrap();
        let c = Case::new(&raw, Profile::Step { from, to }, settle_time(&raw, to));
        let errs: Vec<String> = [1u8, 2, 4, 8, 16, 32]
            .iter()
            .map(|&n| {
                format!(
                    "{:.4}",
                    c.error_pct(&c.twin(
                        Precision::F64,
                        TwinConfig {
                            scheme: Scheme::Ros3,
                            tick: 1e-3,
                            substeps: n
                        }
                    ))
                )
            })
            .collect();
        println!(
            "set {i:2}: sqrt(c/m) {wn:7.0} dominant {:8.1}{:+8.1}i zeta_p {:.3}: {}",
            lam.dominant.re,
            lam.dominant.im,
            lam.plunger_damping_ratio,
            errs.join(" ")
        );
    }
}
