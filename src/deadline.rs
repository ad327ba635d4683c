//! The tick loop's deadline: how many tick periods elapsed since the last
//! tick ran, from a counter of periods (the SysTick interrupt's). One is
//! on time; more is a tick that starts after the next one was due, which
//! [`compensator::estimator::Estimator::tick_after`] counts, flags and
//! catches up.

/// The periods elapsed between the ticks the loop runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TickPace {
    /// The period counter at the last tick run.
    last: u32,
}

impl TickPace {
    /// A pace starting at the counter's `now`.
    pub const fn new(now: u32) -> Self {
        TickPace { last: now }
    }

    /// Whether a tick is due at the counter's `now` (a period elapsed since
    /// the last tick run).
    pub fn due(&self, now: u32) -> bool {
        now != self.last
    }

    /// Takes the tick due at `now`: the periods elapsed since the last one
    /// (1 on time; the counter may wrap).
    pub fn take(&mut self, now: u32) -> u32 {
        let elapsed = now.wrapping_sub(self.last);
        self.last = now;
        elapsed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periods_elapsed_across_the_counter_wrap() {
        let mut p = TickPace::new(u32::MAX - 1);
        assert!(!p.due(u32::MAX - 1));
        assert_eq!(p.take(u32::MAX), 1);
        assert_eq!(p.take(2), 3);
        assert!(p.due(3) && !p.due(2));
    }
}
