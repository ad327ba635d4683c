//! The temperature probe in front of the replay's oil, simulated: a
//! first-order lag (and optionally a second, the well, in series), each
//! exact for an input held over a tick, `y += (u - y) (1 - e^(-tick /
//! tau))`, and seeded noise on the reading. The QEMU twin and the host-side
//! replica of `cargo xtask test` run the same arithmetic on the same
//! numbers (`f32`, `libm`'s `expf` once at construction), tick for tick.

use crate::soak::XorShift64;

/// The seed of the QEMU replay's probe noise (the twin image and the host
/// replica draw the same noise).
pub const REPLAY_SEED: u64 = 16;

/// A probe (and its well) in front of an oil temperature.
#[derive(Clone, Copy, Debug)]
pub struct SimulatedProbe {
    /// The well's temperature [C] (the oil's without a well).
    well: f32,
    /// The probe's temperature [C].
    probe: f32,
    /// `1 - e^(-tick / tau_p)`.
    gain: f32,
    /// `1 - e^(-tick / tau_w)`, 1 without a well.
    well_gain: f32,
    /// Standard deviation of a reading's noise [C].
    noise: f32,
    rng: XorShift64,
}

impl SimulatedProbe {
    /// At rest at `initial` [C]: probe time constant `time_constant`, a well
    /// of `well_time_constant` (0: none) [s], ticked every `tick` [s], its
    /// readings with noise of standard deviation `noise` [C] from `seed`.
    pub fn new(initial: f32, time_constant: f32, well_time_constant: f32, noise: f32, tick: f32, seed: u64) -> Self {
        let gain = |tau: f32| if tau > 0.0 { -libm::expm1f(-tick / tau) } else { 1.0 };
        SimulatedProbe {
            well: initial,
            probe: initial,
            gain: gain(time_constant),
            well_gain: gain(well_time_constant),
            noise,
            rng: XorShift64::new(seed),
        }
    }

    /// The probe's temperature without noise [C].
    pub fn temperature(&self) -> f32 {
        self.probe
    }

    /// One tick with the oil at `oil` [C]; returns what the probe reads
    /// now: its temperature and a noise sample (the sum of twelve uniform
    /// deviates, less six: variance one, an Irwin-Hall approximation of the
    /// normal with `+-6` standard deviations at most).
    pub fn advance(&mut self, oil: f32) -> f32 {
        self.well += (oil - self.well) * self.well_gain;
        self.probe += (self.well - self.probe) * self.gain;
        let mut sum = -6.0f32;
        for _ in 0..12 {
            sum += self.rng.unit();
        }
        self.probe + self.noise * sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_is_followed_by_the_exponential_and_the_noise_has_its_spread() {
        let mut p = SimulatedProbe::new(20.0, 6.0, 0.0, 0.0, 1e-3, 1);
        for _ in 0..6000 {
            p.advance(40.0);
        }
        // One time constant: 63.2 % of the step.
        let frac = (p.temperature() - 20.0) / 20.0;
        assert!((frac - 0.632_12).abs() < 2e-4, "{frac}");
        let mut p = SimulatedProbe::new(50.0, 6.0, 0.0, 0.02, 1e-3, 7);
        let n = 20_000;
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let d = f64::from(p.advance(50.0) - 50.0);
            s += d;
            s2 += d * d;
        }
        let sd = (s2 / n as f64 - (s / n as f64).powi(2)).sqrt();
        assert!((sd - 0.02).abs() < 0.001, "{sd}");
        // A well in series: slower than the probe alone.
        let mut a = SimulatedProbe::new(20.0, 6.0, 0.0, 0.0, 1e-3, 1);
        let mut b = SimulatedProbe::new(20.0, 6.0, 12.0, 0.0, 1e-3, 1);
        for _ in 0..6000 {
            a.advance(40.0);
            b.advance(40.0);
        }
        assert!(b.temperature() < a.temperature() - 5.0);
    }
}
