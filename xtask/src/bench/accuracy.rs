//! The host half of the bench (`host` feature): each configuration the
//! firmware measured, simulated on the host against the Radau5 reference
//! over the paper preset's cases (`host_tests::accuracy`).

use super::measure::Config;
use compensator::dynamics::{Scheme, TwinConfig};
use compensator_cli::dynamics::{Precision, simulate};

/// Worst error (% of the step) over the paper cases of one configuration;
/// infinite where the scheme is unstable at that step.
pub struct Accuracy {
    pub config: Config,
    pub f64: f64,
    pub f32: f64,
    /// In the shipped fixed-point format (Q12.20).
    pub fixed: f64,
}

/// The accuracy of each configuration, in the order given.
pub fn points(configs: &[Config]) -> Result<Vec<Accuracy>, String> {
    let root = crate::root();
    let raw = compensator_cli::load(&root.join("presets/paper.toml")).map_err(|e| e.to_string())?;
    let cases = host_tests::accuracy::paper_cases(&raw);
    let mut out = Vec::new();
    for config in configs {
        let scheme = Scheme::from_name(&config.scheme).ok_or_else(|| format!("unknown scheme {}", config.scheme))?;
        let twin = TwinConfig {
            scheme,
            tick: host_tests::accuracy::TICK,
            substeps: config.substeps as u8,
        };
        let worst = |p: Precision| {
            cases
                .iter()
                .map(|c| match simulate(&c.raw, p, twin, &c.profile, c.ticks) {
                    Ok(r) => {
                        let x: Vec<f64> = r.state.iter().map(|s| s.x).collect();
                        let e = c.error_pct(&x);
                        if e.is_finite() { e } else { f64::INFINITY }
                    }
                    Err(_) => f64::INFINITY,
                })
                .fold(0.0, f64::max)
        };
        out.push(Accuracy {
            config: config.clone(),
            f64: worst(Precision::F64),
            f32: worst(Precision::F32),
            fixed: worst(Precision::Fixed),
        });
    }
    Ok(out)
}
