//! The spike gate in front of the oil-temperature observer.
//!
//! A reading further than `threshold` from the last accepted reading is a
//! spike and rejected, unless it is the
//! `limit + 1`-th consecutive out-of-band reading agreeing (within the
//! threshold) with the one before: then it is a real step (a probe
//! replaced, a reading that jumped and stays), and the observer restarts
//! at it. A genuine change of the oil reaches the reading through the
//! probe's lag, a few hundredths of a degree per reading, and is followed
//! by the observer, never gated. Cost: one comparison per reading, two on
//! an out-of-band one.

/// What the gate made of a reading ([`SpikeGate::offer`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Within the threshold of the expected reading: the observer's update.
    Accepted,
    /// The `limit + 1`-th consecutive out-of-band reading agreeing with the
    /// one before: a real step. The observer restarts at it.
    Step,
    /// Out of band: rejected.
    Spike,
}

/// The gate's settings (from the `[estimator]` section's `spike_threshold`
/// and `spike_limit`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpikeSettings {
    /// Spike threshold \[C\].
    pub threshold: f32,
    /// Consecutive agreeing out-of-band readings rejected before a step is
    /// taken as real.
    pub limit: u32,
}

/// The gate's state: the run of agreeing out-of-band readings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpikeGate {
    /// Consecutive out-of-band readings agreeing with each other.
    spikes: u32,
    /// The last out-of-band reading [C].
    candidate: f32,
}

impl SpikeGate {
    /// No out-of-band reading yet; `initial` \[C\] is the first candidate.
    pub const fn new(initial: f32) -> Self {
        SpikeGate {
            spikes: 0,
            candidate: initial,
        }
    }

    /// Judges the reading `y` \[C\] against the expected reading `expected`
    /// \[C\] (both finite: the caller rejects the rest).
    #[inline]
    pub fn offer(&mut self, settings: &SpikeSettings, expected: f32, y: f32) -> Verdict {
        let threshold = settings.threshold;
        if libm::fabsf(y - expected) <= threshold {
            self.spikes = 0;
            return Verdict::Accepted;
        }
        let agrees = self.spikes > 0 && libm::fabsf(y - self.candidate) <= threshold;
        self.spikes = if agrees { self.spikes.saturating_add(1) } else { 1 };
        self.candidate = y;
        if self.spikes > settings.limit {
            self.spikes = 0;
            Verdict::Step
        } else {
            Verdict::Spike
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(limit: u32) -> SpikeSettings {
        SpikeSettings { threshold: 5.0, limit }
    }

    #[test]
    fn spikes_are_rejected() {
        let s = settings(5);
        let mut g = SpikeGate::new(50.0);
        for spike in [90.0, 10.0, 55.5, 44.0, 1e6] {
            assert_eq!(g.offer(&s, 50.0, spike), Verdict::Spike, "{spike}");
            // Alternating spikes never agree with each other.
            assert_eq!(g.offer(&s, 50.0, 50.0 - (spike - 50.0)), Verdict::Spike, "{spike}");
        }
        // In band: accepted, and the count of agreeing spikes starts over.
        assert_eq!(g.offer(&s, 50.0, 70.0), Verdict::Spike);
        assert_eq!(g.offer(&s, 50.0, 70.0), Verdict::Spike);
        assert_eq!(g.offer(&s, 50.0, 54.0), Verdict::Accepted);
        for _ in 0..5 {
            assert_eq!(g.offer(&s, 50.0, 70.0), Verdict::Spike);
        }
    }

    #[test]
    fn a_real_step_is_taken_after_limit_agreeing_readings() {
        for limit in [0, 1, 5, 20] {
            let s = settings(limit);
            let mut g = SpikeGate::new(50.0);
            assert_eq!(
                g.offer(&s, 50.0, 90.0),
                if limit == 0 { Verdict::Step } else { Verdict::Spike }
            );
            let mut g = SpikeGate::new(50.0);
            for k in 0..limit {
                // Agreeing within the threshold, not equal.
                let t = 70.0 + (k % 3) as f32;
                assert_eq!(g.offer(&s, 50.0, t), Verdict::Spike, "limit {limit}, reading {k}");
            }
            assert_eq!(g.offer(&s, 50.0, 71.0), Verdict::Step, "limit {limit}");
            // After the step the expectation is the step's: in band.
            assert_eq!(g.offer(&s, 71.0, 73.0), Verdict::Accepted);
        }
        // A run broken by a disagreeing reading starts over.
        let s = settings(2);
        let mut g = SpikeGate::new(50.0);
        assert_eq!(g.offer(&s, 50.0, 70.0), Verdict::Spike);
        assert_eq!(g.offer(&s, 50.0, 70.0), Verdict::Spike);
        assert_eq!(g.offer(&s, 50.0, 90.0), Verdict::Spike);
        assert_eq!(g.offer(&s, 50.0, 90.0), Verdict::Spike);
        assert_eq!(g.offer(&s, 50.0, 90.0), Verdict::Step);
    }
}
