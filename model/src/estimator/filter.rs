//! The temperature filter: a spike filter in front of a first-order
//! low-pass.
//!
//! A sample further than `threshold` from the filtered value is a spike and
//! rejected, unless it is the `limit + 1`-th consecutive out-of-band sample
//! agreeing (within the threshold) with the one before: then it is a real
//! step and the filter jumps to it. The low-pass follows the last accepted
//! sample with the gain `1 - exp(-tick / tau)` per tick, whether a sample
//! came or not.
//!
//! The low-pass is a compensated (Kahan) sum in `f32`. A plain
//! `filtered += gain * (held - filtered)` stops moving once the increment
//! is below half an ulp of the temperature, `ulp(T) / (2 gain)` short of
//! its input for good (0.38 C at 100 kHz and tau = 1 s, 3.8 C at tau =
//! 10 s; with `gain` below `ulp(T) / |step|` it never moves at all). The
//! compensated sum keeps the rounding error of every increment and adds it
//! back to the next one, so the increments that are individually lost
//! still add up: the filtered value follows the exponential within a few
//! ulp of the temperature at every allowed tick rate and time constant,
//! and ends on its input within one ulp (`tests::
//! the_low_pass_reaches_its_input_over_the_allowed_settings`). Cost: three
//! `f32` additions and one word of state per tick.

use crate::scalar::Real;

/// What the filter made of a sample ([`TemperatureFilter::offer`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Within the threshold of the filtered value: the low-pass's new input.
    Accepted,
    /// The `limit + 1`-th consecutive out-of-band sample agreeing with the
    /// one before: a real step. The filtered value jumped to it.
    Step,
    /// Out of band: rejected; the low-pass keeps its input.
    Spike,
}

/// The filter's settings (the estimator's come from its
/// [`EstimatorConfig`](super::EstimatorConfig), which holds them anyway:
/// the filter keeps only its state).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSettings {
    /// Low-pass gain per tick, `1 - exp(-tick / tau)`
    /// ([`FilterSettings::gain`]).
    pub gain: f32,
    /// Spike threshold [C].
    pub threshold: f32,
    /// Consecutive agreeing out-of-band samples rejected before a step is
    /// taken as real.
    pub limit: u32,
}

impl FilterSettings {
    /// The low-pass gain per tick for a time constant `tau`:
    /// `1 - exp(-tick / tau)` (computed in `f64`).
    pub fn gain(tick: f64, tau: f64) -> f32 {
        (1.0 - libm::exp(-tick / tau)) as f32
    }
}

/// The spike filter and first-order low-pass (temperatures [C]): its
/// state; the settings come with each call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemperatureFilter {
    /// Filtered value [C].
    filtered: f32,
    /// The low-pass's rounding error carried to the next tick [C]: what
    /// the last additions to `filtered` lost (Kahan's compensation,
    /// [`Real::mul_add_compensated`]; the filtered value is `filtered +
    /// carry` to within rounding).
    carry: f32,
    /// Last accepted sample [C] (the low-pass's input).
    held: f32,
    /// Consecutive out-of-band samples agreeing with each other.
    spikes: u32,
    /// The last out-of-band sample [C].
    candidate: f32,
}

impl TemperatureFilter {
    /// A filter at rest at `initial` [C].
    pub const fn new(initial: f32) -> Self {
        TemperatureFilter {
            filtered: initial,
            carry: 0.0,
            held: initial,
            spikes: 0,
            candidate: initial,
        }
    }

    /// The filtered value [C].
    pub fn value(&self) -> f32 {
        self.filtered
    }

    /// Takes a sample `t` [C] (finite: the caller rejects the rest) to the
    /// spike filter; the low-pass moves at the next [`Self::advance`].
    #[inline]
    pub fn offer(&mut self, settings: &FilterSettings, t: f32) -> Verdict {
        let threshold = settings.threshold;
        if libm::fabsf(t - self.filtered) <= threshold {
            self.hold(t);
            return Verdict::Accepted;
        }
        // Out of band: a spike, unless it is the (limit + 1)-th consecutive
        // sample agreeing with the previous out-of-band one: then a real
        // step.
        let agrees = self.spikes > 0 && libm::fabsf(t - self.candidate) <= threshold;
        self.spikes = if agrees { self.spikes.saturating_add(1) } else { 1 };
        self.candidate = t;
        if self.spikes > settings.limit {
            self.filtered = t;
            self.carry = 0.0;
            self.hold(t);
            Verdict::Step
        } else {
            Verdict::Spike
        }
    }

    /// One tick of the low-pass towards the last accepted sample; returns
    /// the filtered value [C].
    ///
    /// `filtered += gain * (held - filtered)` as a compensated sum (Kahan
    /// 1965): the part of the increment the addition rounds away is carried
    /// into the next tick's, so that increments below half an ulp of the
    /// temperature still add up (module docs).
    #[inline]
    pub fn advance(&mut self, settings: &FilterSettings) -> f32 {
        self.filtered = self
            .filtered
            .mul_add_compensated(settings.gain, self.held - self.filtered, &mut self.carry);
        self.filtered
    }

    /// Takes `t` [C] as the low-pass's input.
    fn hold(&mut self, t: f32) {
        self.spikes = 0;
        self.held = t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimator's defaults: 1 kHz, tau = 0.2 s, 5 C, five samples.
    const TICK: f64 = 1e-3;
    const TAU: f64 = 0.2;

    /// A filter at rest at `initial` with the defaults but `limit`,
    /// driven through its settings.
    struct Filter {
        settings: FilterSettings,
        state: TemperatureFilter,
    }

    impl Filter {
        fn offer(&mut self, t: f32) -> Verdict {
            self.state.offer(&self.settings, t)
        }
        fn advance(&mut self) -> f32 {
            self.state.advance(&self.settings)
        }
        fn value(&self) -> f32 {
            self.state.value()
        }
    }

    fn filter(limit: u32, initial: f32) -> Filter {
        Filter {
            settings: FilterSettings {
                gain: FilterSettings::gain(TICK, TAU),
                threshold: 5.0,
                limit,
            },
            state: TemperatureFilter::new(initial),
        }
    }

    #[test]
    fn spikes_are_rejected() {
        let mut f = filter(5, 50.0);
        for spike in [90.0, 10.0, 55.5, 44.0, 1e6] {
            assert_eq!(f.offer(spike), Verdict::Spike, "{spike}");
            // Alternating spikes never agree with each other.
            assert_eq!(f.offer(50.0 - (spike - 50.0)), Verdict::Spike, "{spike}");
            for _ in 0..100 {
                assert_eq!(f.advance(), 50.0);
            }
        }
        // In band: accepted, and the count of agreeing spikes starts over.
        assert_eq!(f.offer(70.0), Verdict::Spike);
        assert_eq!(f.offer(70.0), Verdict::Spike);
        assert_eq!(f.offer(54.0), Verdict::Accepted);
        for _ in 0..5 {
            assert_eq!(f.offer(70.0), Verdict::Spike);
        }
    }

    #[test]
    fn a_real_step_is_taken_after_limit_agreeing_samples() {
        for limit in [0, 1, 5, 20] {
            let mut f = filter(limit, 50.0);
            // A different out-of-band value first: not part of the run.
            assert_eq!(f.offer(90.0), if limit == 0 { Verdict::Step } else { Verdict::Spike });
            let mut f = filter(limit, 50.0);
            for k in 0..limit {
                // Agreeing within the threshold, not equal.
                let t = 70.0 + (k % 3) as f32;
                assert_eq!(f.offer(t), Verdict::Spike, "limit {limit}, sample {k}");
                assert_eq!(f.advance(), 50.0);
            }
            assert_eq!(f.offer(71.0), Verdict::Step, "limit {limit}");
            assert_eq!(f.value(), 71.0);
            // The step is the low-pass's input: it stays there.
            assert_eq!(f.advance(), 71.0);
            assert_eq!(f.offer(73.0), Verdict::Accepted);
        }
        // A run broken by a disagreeing sample starts over.
        let mut f = filter(2, 50.0);
        assert_eq!(f.offer(70.0), Verdict::Spike);
        assert_eq!(f.offer(70.0), Verdict::Spike);
        assert_eq!(f.offer(90.0), Verdict::Spike);
        assert_eq!(f.offer(90.0), Verdict::Spike);
        assert_eq!(f.offer(90.0), Verdict::Step);
    }

    /// One ulp of `x` in `f32` [C].
    fn ulp(x: f32) -> f32 {
        let a = libm::fabsf(x);
        f32::from_bits(a.to_bits() + 1) - a
    }

    /// The low-pass from `from` to `to` [C] at `tick_hz` and `tau`: the
    /// largest distance from the exact exponential (with the same `f32`
    /// gain) over at most `max_ticks` ticks, and where it ended.
    fn low_pass_run(tick_hz: f64, tau: f64, from: f32, to: f32, max_ticks: u64) -> (f64, f32, u64) {
        let settings = FilterSettings {
            gain: FilterSettings::gain(1.0 / tick_hz, tau),
            threshold: 1e3,
            limit: 5,
        };
        let mut f = TemperatureFilter::new(from);
        assert_eq!(f.offer(&settings, to), Verdict::Accepted);
        let g = settings.gain as f64;
        // Enough ticks to reach the input: 30 time constants and the last
        // ulp (1 / gain ticks), where that is affordable.
        let ticks = ((30.0 / g) as u64 + 10).min(max_ticks);
        let (mut left, mut worst) = ((from as f64) - (to as f64), 0.0f64);
        for _ in 0..ticks {
            let y = f.advance(&settings) as f64;
            left *= 1.0 - g;
            worst = worst.max((y - (to as f64 + left)).abs());
        }
        (worst, f.value(), ticks)
    }

    /// F2 (docs/fuzzing.md): the low-pass used to stall `ulp(T) / (2 gain)`
    /// short of a constant input (0.38 C at 100 kHz, tau = 1 s, holding
    /// 104 C after 100 C) and not to move at all where `gain |step|` was
    /// below half an ulp. Over the whole range the parameter schema allows
    /// (`estimator.tick_hz` 1 Hz-100 kHz, `estimator.filter_time_constant`
    /// 10 us-10^4 s) and cold and hot steps, small and large: the filtered
    /// value follows the exponential within 3 ulp of the larger
    /// temperature, and where 30 time constants fit in 400,000 ticks it
    /// ends within one ulp of its input (or e^-30 of the step, at 0 C).
    #[test]
    fn the_low_pass_reaches_its_input_over_the_allowed_settings() {
        let steps: [(f32, f32); 6] = [
            (100.0, 104.0),
            (104.0, 100.0),
            (-40.0, -39.5),
            (20.0, -40.0),
            (250.0, 249.99),
            (0.5, 0.0),
        ];
        let mut checked_end = 0;
        for tick_hz in [1.0, 10.0, 250.0, 1e3, 4e3, 2e4, 1e5] {
            for tau in [1e-5, 1e-3, 0.05, 0.2, 1.0, 10.0, 1e2, 1e4] {
                for (from, to) in steps {
                    let (worst, end, ticks) = low_pass_run(tick_hz, tau, from, to, 400_000);
                    let scale = libm::fmaxf(libm::fabsf(from), libm::fabsf(to));
                    assert!(
                        worst <= 3.0 * ulp(scale) as f64,
                        "{tick_hz} Hz, tau {tau} s, {from} -> {to} C: {worst} C off the exponential"
                    );
                    let g = FilterSettings::gain(1.0 / tick_hz, tau) as f64;
                    if ((30.0 / g) as u64 + 10) <= ticks {
                        checked_end += 1;
                        // One ulp, or e^-30 of the step where the input is 0.
                        assert!(
                            libm::fabsf(end - to) <= ulp(to) + 1e-12 * libm::fabsf(from - to),
                            "{tick_hz} Hz, tau {tau} s, {from} -> {to} C: ended at {end} C"
                        );
                    }
                }
            }
        }
        assert!(checked_end > 200, "{checked_end}");
    }

    #[test]
    fn the_low_pass_step_response_is_the_exponential() {
        // A unit step (inside the spike threshold) over ten time constants.
        // Each tick rounds the filtered value by at most half an ulp of 1
        // (3e-8), which decays with the filter: at most 3e-8 / gain = 6e-6
        // accumulated.
        let mut f = filter(5, 0.0);
        assert_eq!(f.offer(1.0), Verdict::Accepted);
        for k in 1..=2000u32 {
            let y = f.advance();
            let want = 1.0 - libm::exp(-(k as f64) * TICK / TAU);
            assert!(((y as f64) - want).abs() <= 1e-5, "tick {k}: {y} vs {want}");
        }
        // At an oil temperature: 63.2 % of a 4 C step after one time
        // constant, with no further sample (the low-pass keeps following
        // the last accepted one).
        let mut f = filter(5, 50.0);
        assert_eq!(f.offer(54.0), Verdict::Accepted);
        let ticks = (TAU / TICK).round() as usize;
        let y = (0..ticks).map(|_| f.advance()).last().unwrap();
        let frac = (y - 50.0) / 4.0;
        assert!((frac - 0.632_120_6).abs() < 1e-4, "{frac}");
    }
}
