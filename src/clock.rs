//! Real time from a tick counter: what the board's defmt timestamps and
//! telemetry times use, so that they read in seconds whatever the
//! estimator's `tick_hz` (SysTick's reload is rounded to whole core
//! cycles; the time follows the reload actually programmed, not the
//! nominal rate).

/// A tick counter's clock: core cycles per tick and per microsecond.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TickClock {
    /// Core cycles per tick (SysTick reload + 1).
    pub cycles_per_tick: u32,
    /// Core cycles per microsecond (the core clock in MHz).
    pub cycles_per_us: u32,
}

impl TickClock {
    /// The clock of a SysTick reloading every `cycles_per_tick` cycles of a
    /// core running at `core_hz` [Hz]; `None` unless the core clock is a
    /// whole, non-zero number of MHz and the tick at least one cycle.
    pub const fn new(cycles_per_tick: u32, core_hz: u32) -> Option<TickClock> {
        if core_hz == 0 || !core_hz.is_multiple_of(1_000_000) || cycles_per_tick == 0 {
            return None;
        }
        Some(TickClock {
            cycles_per_tick,
            cycles_per_us: core_hz / 1_000_000,
        })
    }

    /// Time at tick `ticks` [us] (exact to the microsecond below; no
    /// overflow: at most 2^32 ticks of 2^24 cycles).
    pub const fn micros(&self, ticks: u32) -> u64 {
        ticks as u64 * self.cycles_per_tick as u64 / self.cycles_per_us as u64
    }

    /// Time at tick `ticks` [ms], saturating at `u32::MAX` (49.7 days).
    pub const fn millis(&self, ticks: u32) -> u32 {
        let ms = self.micros(ticks) / 1000;
        if ms > u32::MAX as u64 { u32::MAX } else { ms as u32 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_is_real_whatever_the_tick_rate() {
        // 168 MHz core: 1 kHz reloads every 168,000 cycles; 250 Hz every
        // 672,000; 3 kHz every 56,000 (333.33 us).
        let k1 = TickClock::new(168_000, 168_000_000).unwrap();
        assert_eq!((k1.micros(1), k1.millis(60_000)), (1_000, 60_000));
        let k250 = TickClock::new(672_000, 168_000_000).unwrap();
        assert_eq!((k250.micros(250), k250.millis(250)), (1_000_000, 1_000));
        let k3 = TickClock::new(56_000, 168_000_000).unwrap();
        assert_eq!((k3.micros(3), k3.micros(3_000)), (1_000, 1_000_000));
        // A reload rounded to whole cycles: 7 kHz asks for 24,000 cycles
        // exactly; 6 kHz for 28,000; 9 kHz for 18,666.67, programmed as
        // 18,666 (111.107 us): 9,000 ticks are 999,964 us, not a second.
        let k9 = TickClock::new(18_666, 168_000_000).unwrap();
        assert_eq!(k9.micros(9_000), 999_964);
        // 2^32 ticks of the longest SysTick period (2^24 cycles) fit.
        let slow = TickClock::new(1 << 24, 168_000_000).unwrap();
        assert_eq!(slow.micros(u32::MAX), (u32::MAX as u64) * (1 << 24) / 168);
        assert_eq!(slow.millis(u32::MAX), u32::MAX);
        assert_eq!(TickClock::new(1000, 167_500_000), None);
        assert_eq!(TickClock::new(0, 168_000_000), None);
    }
}
