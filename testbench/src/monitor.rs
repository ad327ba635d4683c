//! The condition monitor's second sensor in the QEMU twin's replay (a
//! device file that names one): what the true device reads at the oil's
//! temperature, healthy and, from an onset on, with its capillary
//! restricted, tabulated by the build from the independent reference
//! (`compensator_codegen::replay::MonitorTrack`), and the transducer's
//! open loop. The twin image and the host-side replica drive the
//! simulated transducer with [`Track::drive`], so that both read the same
//! codes.

use compensator::sensor::ntc::RegisterAdc;
use compensator::sensor::transducer::{SimulatedMonitor, SimulatedTransducer, TransducerFault};

/// The seed of the simulated transducer's noise in the replay.
pub const SEED: u64 = 0x5EC0_2D5E_2502;

/// Time over which the restriction grows, linearly, from its onset \[s\]:
/// a capillary silts up over time, and a step of the pressure within one
/// of the transducer's noise windows would read as a noisy sensor.
pub const ONSET: f32 = 10.0;

/// The replay's second-sensor track.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Track<'a> {
    /// The true reading \[Pa or m\]: (oil C, healthy, restricted), evenly
    /// spaced, ascending.
    pub truth: &'a [(f32, f32, f32)],
    /// From this time on \[s\] the capillary is restricted (fully after
    /// [`ONSET`]).
    pub restricted_from: f32,
    /// The transducer's loop is open over (from s, to s).
    pub open_loop: (f32, f32),
}

/// The healthy and the restricted reading at `t` \[C\], interpolated
/// linearly in `truth` (held at its ends; `(NaN, NaN)` for an empty one).
pub fn truth_at(truth: &[(f32, f32, f32)], t: f32) -> (f32, f32) {
    let n = truth.len();
    let (Some(first), Some(last)) = (truth.first(), truth.last()) else {
        return (f32::NAN, f32::NAN);
    };
    if n == 1 || !(t > first.0) {
        return (first.1, first.2);
    }
    if t >= last.0 {
        return (last.1, last.2);
    }
    // The row below `t`: from the even spacing, then corrected (the rows'
    // temperatures are rounded to f32).
    let step = (last.0 - first.0) / (n - 1) as f32;
    let mut i = (((t - first.0) / step) as usize).min(n - 2);
    while i > 0 && truth.get(i).is_some_and(|r| r.0 > t) {
        i -= 1;
    }
    while i + 2 < n && truth.get(i + 1).is_some_and(|r| r.0 <= t) {
        i += 1;
    }
    match (truth.get(i), truth.get(i + 1)) {
        (Some(a), Some(b)) => {
            let w = (t - a.0) / (b.0 - a.0);
            (a.1 + w * (b.1 - a.1), a.2 + w * (b.2 - a.2))
        }
        _ => (last.1, last.2),
    }
}

impl Track<'_> {
    /// Whether the capillary is restricted at `time` \[s\].
    pub fn restricted(&self, time: f32) -> bool {
        time >= self.restricted_from
    }

    /// Whether the transducer's loop is open at `time` \[s\].
    pub fn open(&self, time: f32) -> bool {
        time >= self.open_loop.0 && time < self.open_loop.1
    }

    /// The true device's reading at `time` \[s\] with the oil at `oil` \[C\]:
    /// the healthy device's, moving to the restricted one's over [`ONSET`]
    /// from the restriction's onset.
    pub fn reading(&self, time: f32, oil: f32) -> f32 {
        let (healthy, restricted) = truth_at(self.truth, oil);
        let w = (time - self.restricted_from) / ONSET;
        if !(w > 0.0) {
            healthy
        } else if w >= 1.0 {
            restricted
        } else {
            healthy + w * (restricted - healthy)
        }
    }

    /// Sets the simulated transducer to what it reads at `time` with the
    /// oil at `oil`: the true reading, and the open loop while it lasts.
    pub fn drive(&self, transducer: &mut SimulatedMonitor, time: f32, oil: f32) {
        let sim: &mut SimulatedTransducer = RegisterAdc::registers_mut(transducer.device_mut());
        sim.reading = self.reading(time, oil);
        sim.fault = self.open(time).then_some(TransducerFault::OpenLoop);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_truth_interpolates_between_its_rows_and_holds_its_ends() {
        let truth = [(10.0, 100.0, 200.0), (10.5, 110.0, 230.0), (11.0, 130.0, 250.0)];
        assert_eq!(truth_at(&truth, 10.25), (105.0, 215.0));
        assert_eq!(truth_at(&truth, 10.75), (120.0, 240.0));
        assert_eq!(truth_at(&truth, 10.5), (110.0, 230.0));
        assert_eq!(truth_at(&truth, 9.0), (100.0, 200.0));
        assert_eq!(truth_at(&truth, 12.0), (130.0, 250.0));
        assert!(truth_at(&[], 1.0).0.is_nan());
        let track = Track {
            truth: &truth,
            restricted_from: 5.0,
            open_loop: (1.0, 2.0),
        };
        assert_eq!(track.reading(4.9, 10.25), 105.0);
        assert_eq!(track.reading(5.0, 10.25), 105.0);
        assert_eq!(track.reading(5.0 + 0.5 * ONSET, 10.25), 160.0);
        assert_eq!(track.reading(5.0 + ONSET, 10.25), 215.0);
        assert!(track.open(1.0) && !track.open(2.0) && !track.open(0.99));
    }
}
