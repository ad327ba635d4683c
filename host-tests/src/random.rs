//! Deterministic pseudo-random physical parameter sets.
//!
//! SplitMix64 (public domain, Vigna): no dependency, same sequence on every
//! machine, so a failing set can be reproduced from its index.

use compensator::params::{RawCore, RawEstimator, RawParams};

/// SplitMix64 generator.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Log-uniform in [lo, hi).
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
}

/// Walther constants through two viscosities [cSt] at 40 and 100 C.
pub fn walther_through(nu40: f64, nu100: f64) -> (f64, f64) {
    let w = |nu: f64| (nu + 0.7).log10().log10();
    let (l40, l100) = ((40.0f64 + 273.15).log10(), (100.0f64 + 273.15).log10());
    let b = (w(nu40) - w(nu100)) / (l100 - l40);
    (w(nu40) + b * l40, b)
}

/// A random but physical compensator: mineral oils from ISO VG 10 to 100,
/// throttles and plungers of hydraulic-valve size, drops of 1 to 20 bar.
/// Every set is valid, and the oil stays within Walther's range (above
/// 2 cSt) up to 100 C.
///
/// The spring is sized as a designer would: between 30 and 80 C the free
/// displacement changes by 0.3 to 2.5 strokes, and the window starts to
/// open somewhere between 20 and 60 C (the preload). A spring picked
/// independently of the hydraulics would make a switch that jumps from
/// stop to stop within a fraction of a degree, not a compensator.
pub fn physical_params(rng: &mut Rng) -> RawParams {
    let mut core = unsized_params(rng);
    let area = std::f64::consts::FRAC_PI_4 * core.plunger_diameter * core.plunger_diameter;
    let hydraulics = core;
    let dp_ab = |t: f64| {
        let r = compensator_reference::statics::equilibrium(&hydraulics, t);
        r.p_b - r.p_a
    };
    let travel = rng.uniform(0.3, 2.5) * core.stroke;
    let compliance = travel / (dp_ab(80.0) - dp_ab(30.0));
    let opening = rng.uniform(20.0, 60.0);
    core.spring_rate = area / compliance;
    core.preload = (dp_ab(opening) * compliance).clamp(0.0, core.stroke);
    let raw = RawParams {
        core,
        machine: None,
        estimator: RawEstimator::DEFAULT,
        probe: compensator::params::RawProbe::DEFAULT,
        monitor: compensator::params::RawMonitor::NONE,
        tolerances: compensator::params::RawTolerances::NONE,
    };
    raw.validate().expect("the generator makes valid sets");
    raw
}

/// As [`physical_params`] but with the spring rate and preload drawn
/// independently of the hydraulics (log-uniform 5e3..1e5 N/m, preload up
/// to half the stroke): mostly switch-like devices, for robustness tests.
pub fn unsized_params(rng: &mut Rng) -> RawCore {
    let nu40 = rng.log_uniform(10.0, 100.0);
    // Viscosity index roughly 90-150: nu100 / nu40 between these bounds.
    let nu100 = (nu40 * rng.uniform(0.14, 0.22)).max(2.6);
    let (walther_a, walther_b) = walther_through(nu40, nu100);
    let plunger_diameter = rng.uniform(5e-3, 25e-3);
    let stroke = rng.uniform(0.5e-3, 5e-3);
    let area = std::f64::consts::FRAC_PI_4 * plunger_diameter * plunger_diameter;
    let swept = area * stroke;
    let laminar_diameter = rng.uniform(0.4e-3, 1.5e-3);
    let core = RawCore {
        walther_a,
        walther_b,
        density_15: rng.uniform(820.0, 900.0),
        expansion: rng.uniform(5e-4, 9e-4),
        bulk_modulus: rng.uniform(0.8e9, 1.8e9),
        laminar_diameter,
        laminar_length: laminar_diameter * rng.uniform(15.0, 60.0),
        turbulent_diameter: rng.uniform(0.3e-3, 1.5e-3),
        turbulent_discharge: rng.uniform(0.55, 0.75),
        plunger_diameter,
        mass: rng.uniform(0.005, 0.1),
        damping: rng.uniform(0.0, 20.0),
        spring_rate: rng.log_uniform(5e3, 1e5),
        preload: stroke * rng.uniform(0.0, 0.5),
        stroke,
        slot_diameter: rng.uniform(1e-3, 5e-3),
        slot_discharge: rng.uniform(0.55, 0.75),
        volume_a: swept * rng.log_uniform(1.5, 50.0),
        volume_b: swept * rng.log_uniform(1.5, 50.0),
        pressure_drop: rng.log_uniform(1e5, 2e6),
        // The schema takes 0 or 1 Pa and more: a draw below 1 Pa (one in
        // 5e5) is an open outlet (the same draws as before otherwise).
        outlet_pressure: match rng.uniform(0.0, 5e5) {
            p if p < 1.0 => 0.0,
            p => p,
        },
    };
    core.validate().expect("the generator makes valid sets");
    core
}
