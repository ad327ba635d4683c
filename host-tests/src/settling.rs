//! The settling study's designs and steps (`examples/settling.rs`) and
//! its estimator run, shared with the tests that pin its findings.

use crate::random::{Rng, physical_params};
use compensator::Params;
use compensator::dynamics::linear::linearise;
use compensator::estimator::{Estimator, EstimatorConfig};
use compensator::params::RawParams;

/// The abrupt steps [C] (from, to) applied to every design: cold steps
/// onto the closed stop, hot ones onto the open stop, and back.
pub const STEPS: [(f64, f64); 7] = [
    (40.0, 0.0),
    (60.0, -20.0),
    (40.0, -40.0),
    (40.0, 150.0),
    (26.0, 110.0),
    (26.0, 78.0),
    (78.0, 26.0),
];

/// The paper preset with every core field scaled by 4^u, u uniform in
/// [-1, 1].
pub fn perturbed_paper(rng: &mut Rng, paper: &RawParams) -> RawParams {
    let mut raw = *paper;
    raw.core = raw.core.map(|n| n.value * 4f64.powf(rng.uniform(-1.0, 1.0)));
    raw
}

/// The study's designs for `seed`, numbered from 1 as the study prints
/// them: random physical designs and perturbed paper presets alternately,
/// those the validation refuses skipped.
pub fn designs(seed: u64, paper: RawParams) -> impl Iterator<Item = (usize, RawParams)> {
    let mut rng = Rng::new(seed);
    let mut used = 0;
    std::iter::from_fn(move || {
        loop {
            let raw = if used % 2 == 0 {
                physical_params(&mut rng)
            } else {
                perturbed_paper(&mut rng, &paper)
            };
            if raw.validate().is_ok() {
                used += 1;
                return Some((used, raw));
            }
        }
    })
}

/// Re-seats of the estimator's twin over one step (`None`: out of reach).
pub fn estimator_reseats(raw: &RawParams, from: f64, to: f64) -> Option<u32> {
    let mut raw = *raw;
    raw.estimator.oil_min = -45.0;
    raw.estimator.oil_max = 160.0;
    let p32 = Params::<f32>::new(&raw).ok()?;
    let p64 = Params::<f64>::new(&raw).ok()?;
    let lin = linearise(&p64, to).ok()?;
    let rate = lin.eigenvalues.iter().map(|l| -l.re).fold(f64::INFINITY, f64::min);
    if !(rate > 2.0) {
        return None;
    }
    let cfg = EstimatorConfig::new(&raw).ok()?;
    let mut est = Estimator::new(&p32, cfg, from as f32).ok()?;
    let hold = (400.0 / rate).max(3.0);
    let tick = f64::from(cfg.tick());
    let mut last = 0;
    for (t, seconds) in [(from, 2.0), (to, hold)] {
        for k in 0..(seconds / tick) as usize {
            let sample = if k % 20 == 0 { Ok(Some(t as f32)) } else { Ok(None) };
            last = est.tick(sample).reseats;
        }
    }
    Some(last)
}
