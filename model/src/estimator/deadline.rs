//! Ticks that start late: a controller still busy when the next tick was
//! due has missed that tick's deadline. The firmware's tick loop measures
//! the tick periods elapsed since the last tick it ran and hands them to
//! [`Estimator::tick_after`]; the estimator counts the missed deadlines,
//! flags the estimate, and catches up in simulated time: the twin, the
//! oil-temperature observer's prediction and the tick counter advance by
//! the elapsed ticks, not silently by one.

#[cfg(doc)]
use super::Flags;
use super::{Estimator, ObserverDesign};
use crate::scalar::Real;
use crate::sensor::SensorFault;
use crate::uncertainty::UncertaintyTable;
use core::borrow::Borrow;

/// Most ticks a late tick adds to catch up (each one twin tick and one
/// observer prediction, no job): the cost of a late tick is bounded by
/// this many twin ticks more. A controller whose twin tick alone is shorter than the
/// tick period keeps up with real time this way (each late tick takes the
/// ticks it missed, and the lateness settles at a few ticks); beyond the
/// bound the rest of the elapsed ticks is lost to the twin, counted
/// ([`Estimator::lost_ticks`]) and flagged like any miss.
pub const MAX_CATCH_UP: u32 = 8;

impl<T: Real, U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy> Estimator<T, U, O> {
    /// One tick that starts `elapsed` tick periods after the previous one
    /// (`1`: on time; `0` is taken as `1`). A later tick missed `elapsed -
    /// 1` deadlines: they are counted
    /// ([`StateEstimate::deadline_misses`](super::StateEstimate::deadline_misses),
    /// in telemetry), the estimate is flagged [`Flags::DEADLINE_MISSED`],
    /// and before the tick the twin and the observer's prediction advance
    /// through the missed ticks (at most [`MAX_CATCH_UP`]; the twin's coefficients
    /// are those of the last Fluid job, the jobs wait), so that the twin's
    /// simulated time is the real time. Then the tick runs as
    /// [`Estimator::tick`] with `sample`.
    pub fn tick_after(&mut self, sample: Result<Option<f32>, SensorFault>, elapsed: u32) -> super::StateEstimate {
        let missed = elapsed.saturating_sub(1);
        if missed > 0 {
            self.deadline_misses = self.deadline_misses.saturating_add(missed);
            self.late = true;
            let caught = missed.min(MAX_CATCH_UP);
            self.lost_ticks = self.lost_ticks.saturating_add(missed - caught);
            for _ in 0..caught {
                self.plant.coast();
                self.observer.predict(self.config.observer_design());
            }
            // The tick counter (telemetry's cadence, staleness) follows real
            // time; a record due inside the gap goes out with this tick.
            let (before, after) = (self.tick, self.tick.wrapping_add(missed));
            let every = self.config.telemetry_every;
            if every > 0 && after / every != before / every {
                self.telemetry_pending = true;
            }
            self.tick = after;
            self.since_sample = self.since_sample.saturating_add(missed);
        }
        self.tick(sample)
    }

    /// Tick deadlines missed since start (saturating).
    pub fn deadline_misses(&self) -> u32 {
        self.deadline_misses
    }

    /// Ticks of real time the twin did not advance through since start
    /// (late ticks beyond [`MAX_CATCH_UP`] each; saturating): zero when
    /// the twin's simulated time is the real time.
    pub fn lost_ticks(&self) -> u32 {
        self.lost_ticks
    }
}
