//! The probe's response, applied to what the second sensor says of the
//! oil: the probe (a first-order lag `tau_p`, optionally behind a second,
//! the thermowell's `tau_w`) read from the device file's `[probe]`, stepped
//! at the second sensor's readings.
//!
//! Each step of `h` seconds treats a stage's input as linear between its
//! values at the step's ends and takes it at the midpoint, `x <- m + (x -
//! m) e^(-h / tau)`: second order in `h / tau` (at 100 readings a second
//! and `tau` = 8 s, a ramp's lag is reproduced to 1e-6 of its rate times
//! `tau`), one multiply-add per stage and signal, the exponential computed
//! once per step length. Every signal of a [`Lag`] goes through the same
//! chain: the lag is linear, so the lag of a derivative is the derivative
//! of the lag (the filter's Jacobian), and of a sum the sum (a hypothesis'
//! signature).

use crate::estimator::{observer_settings, reading_period};
use crate::mathf::exp2;
use crate::params::RawParams;

/// The oil-temperature probe as the monitor models it (the device file's
/// `[probe]`, the converter's resolution).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeModel {
    /// The probe's first-order time constant `tau_p` \[s\] (`probe.time_constant`).
    pub time_constant: f32,
    /// The well's time constant `tau_w` in series \[s\]; 0: none
    /// (`probe.well_time_constant`).
    pub well_time_constant: f32,
    /// Standard deviation of one reading \[K\]: the probe's noise and the
    /// converter's quantization (`noise^2 + code^2 / 12`, GUM 4.3.7).
    pub reading_sd: f32,
    /// The constant part `a` of the probe's tolerance `+-(a + b |t|)` \[K\]
    /// (IEC 60751: class B 0.3, class A 0.15).
    pub tolerance_a: f32,
    /// The part `b` proportional to `|t|` \[1/K\] (class B 0.005, class A 0.002).
    pub tolerance_b: f32,
}

impl ProbeModel {
    /// The probe of the device file `raw` (its `[probe]`, read through its
    /// sensor at the file's reading period, the converter's resolution at
    /// the middle of the validated range).
    pub fn new(raw: &RawParams) -> ProbeModel {
        let s = observer_settings(raw, reading_period(&raw.estimator));
        ProbeModel {
            time_constant: s.time_constant as f32,
            well_time_constant: s.well_time_constant as f32,
            reading_sd: libm::sqrt(s.noise * s.noise + s.resolution * s.resolution / 12.0) as f32,
            tolerance_a: raw.probe.tolerance_a as f32,
            tolerance_b: raw.probe.tolerance_b as f32,
        }
    }

    /// Half-width of the tolerance at `t` \[C\]: `a + b |t|` \[K\].
    #[inline]
    pub fn tolerance_at(&self, t: f32) -> f32 {
        self.tolerance_a + self.tolerance_b * libm::fabsf(t)
    }

    /// Whether a well lags in front of the probe.
    #[inline]
    pub fn has_well(&self) -> bool {
        self.well_time_constant > 0.0
    }
}

/// `e^(-h / tau)` for each stage at a step of `h` seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decay {
    /// The step \[s\] the factors are for.
    pub h: f32,
    /// The well's factor (1 without a well: it passes its input).
    pub well: f32,
    /// The probe's factor.
    pub probe: f32,
}

impl Decay {
    /// The factors of `probe` for a step of `h` seconds.
    pub fn new(probe: &ProbeModel, h: f32) -> Decay {
        let factor = |tau: f32| {
            if tau > 0.0 {
                exp2(-h / tau * core::f32::consts::LOG2_E)
            } else {
                0.0
            }
        };
        Decay {
            h,
            well: if probe.has_well() {
                factor(probe.well_time_constant)
            } else {
                0.0
            },
            probe: factor(probe.time_constant),
        }
    }
}

/// `N` signals through the probe's chain: per signal the last input, the
/// well's and the probe's temperature (the well's is the input without a
/// well).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lag<const N: usize> {
    input: [f32; N],
    well: [f32; N],
    probe: [f32; N],
}

impl<const N: usize> Lag<N> {
    /// At rest at `values` (every stage equal to its input).
    pub fn at_rest(values: [f32; N]) -> Self {
        Lag {
            input: values,
            well: values,
            probe: values,
        }
    }

    /// One step of `decay.h` to the new inputs `u` (see the module docs).
    pub fn step(&mut self, u: &[f32; N], decay: &Decay) {
        self.step_signals(u, decay, 0..N);
    }

    /// [`Lag::step`] of the signals `signals` alone (the others keep
    /// their stages): a step may be taken in parts, each signal once.
    pub fn step_signals(&mut self, u: &[f32; N], decay: &Decay, signals: core::ops::Range<usize>) {
        let stages = u
            .iter()
            .zip(self.input.iter_mut())
            .zip(self.well.iter_mut())
            .zip(self.probe.iter_mut());
        for (((&u, input), well), probe) in stages.take(signals.end).skip(signals.start) {
            let w0 = *well;
            let w1 = if decay.well > 0.0 {
                let m = 0.5 * (*input + u);
                m + (w0 - m) * decay.well
            } else {
                u
            };
            let m = 0.5 * (w0 + w1);
            *probe = m + (*probe - m) * decay.probe;
            *well = w1;
            *input = u;
        }
    }

    /// Signal `i` at the probe.
    #[inline]
    pub fn probe(&self, i: usize) -> f32 {
        self.probe[i]
    }

    /// Signal `i`'s last input.
    #[inline]
    pub fn input(&self, i: usize) -> f32 {
        self.input[i]
    }

    /// The rate of signal `i` at the probe, `(T_in - T_probe) / tau_p`
    /// \[per s\], `T_in` the well's (or the input's).
    #[inline]
    pub fn probe_rate(&self, i: usize, probe: &ProbeModel) -> f32 {
        (self.well[i] - self.probe[i]) / probe.time_constant
    }

    /// Signal `i` alone, its input and stages.
    pub fn signal(&self, i: usize) -> Lag<1> {
        Lag {
            input: [self.input[i]],
            well: [self.well[i]],
            probe: [self.probe[i]],
        }
    }

    /// Signal `i` back to zero, input and stages.
    pub fn clear(&mut self, i: usize) {
        self.input[i] = 0.0;
        self.well[i] = 0.0;
        self.probe[i] = 0.0;
    }

    /// Adds `by` times signal `j` to signal `i`, stages and input: the lag
    /// of the sum is the sum of the lags.
    pub fn add_scaled(&mut self, i: usize, j: usize, by: f32) {
        if !by.is_finite() {
            return;
        }
        self.input[i] += by * self.input[j];
        self.well[i] += by * self.well[j];
        self.probe[i] += by * self.probe[j];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn probe(tau: f32, well: f32) -> ProbeModel {
        ProbeModel {
            time_constant: tau,
            well_time_constant: well,
            reading_sd: 0.01,
            tolerance_a: 0.3,
            tolerance_b: 0.005,
        }
    }

    /// A ramp through one lag ends `rate tau` behind it with the transient
    /// `rate tau e^(-t / tau)` (the closed form), and a step through two
    /// lags in series rises as `1 - (tau_p e^(-t/tau_p) - tau_w
    /// e^(-t/tau_w)) / (tau_p - tau_w)`.
    #[test]
    fn the_chain_is_the_closed_form() {
        let p = probe(8.0, 0.0);
        let h = 0.01;
        let d = Decay::new(&p, h);
        let mut lag = Lag::at_rest([20.0f32]);
        for k in 1..=3000 {
            let t = k as f32 * h;
            lag.step(&[20.0 + 0.5 * t], &d);
            let exact = 20.0 + 0.5 * t - 0.5 * 8.0 * (1.0 - (-t / 8.0).exp());
            assert!((lag.probe(0) - exact).abs() < 2e-4, "{t}: {} {exact}", lag.probe(0));
        }
        let p = probe(6.0, 20.0);
        let d = Decay::new(&p, h);
        let mut lag = Lag::at_rest([0.0f32]);
        for k in 1..=6000 {
            let t = k as f32 * h;
            lag.step(&[1.0], &d);
            let exact = 1.0 - (6.0 * (-t / 6.0).exp() - 20.0 * (-t / 20.0).exp()) / (6.0 - 20.0);
            // The first step's input jumps, which the midpoint rule halves.
            assert!((lag.probe(0) - exact).abs() < 1e-3, "{t}: {} {exact}", lag.probe(0));
        }
    }

    #[test]
    fn sums_and_clears_are_linear() {
        let p = probe(4.0, 10.0);
        let d = Decay::new(&p, 0.02);
        let mut lag = Lag::at_rest([1.0f32, 2.0, 0.0]);
        for k in 0..500 {
            let u = k as f32 * 0.01;
            lag.step(&[u, u * u, u + 2.0 * u * u], &d);
        }
        let mut sum = lag;
        sum.clear(0);
        sum.add_scaled(0, 0, 5.0);
        assert_eq!(sum.probe(0), 0.0);
        sum.add_scaled(0, 1, 2.0);
        let want = lag.probe(1) * 2.0;
        assert!((sum.probe(0) - want).abs() < 1e-6);
        // Signal 2 (u + 2 u^2 from rest at 0) is signal 0 (from 1) plus
        // twice signal 1 (from 2), less their rests' lag.
        let lin = lag.probe(0) + 2.0 * lag.probe(1);
        let rest = Lag::at_rest([5.0f32]);
        let mut r = rest;
        for _ in 0..500 {
            r.step(&[0.0], &d);
        }
        assert!((lag.probe(2) - (lin - r.probe(0))).abs() < 1e-4);
        assert!(p.tolerance_at(-50.0) == 0.3 + 0.25);
    }
}
