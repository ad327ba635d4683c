//! The soak's seeded temperature walk, its injected sensor faults and the
//! checks run on every tick (`docs/soak.md`), shared by the QEMU image
//! (`src/bin/soak.rs`) and the host soak (`host-tests/src/soak.rs`): a
//! seed gives the same walk and the same faults on both, tick for tick.
//!
//! No `std`, no allocation: the generator uses only integer arithmetic and
//! `f32` `+ - * /`, exact on every IEEE target.
//!
//! The walk is a chain of segments: holds (entered by an abrupt step, small
//! or beyond the spike threshold), ramps (0.2-2 C/s) and cold excursions
//! (a step down to the bottom of the oil range, held). A segment may carry
//! one fault, placed after the recovery room of the step that began it and
//! ending at least that room before the segment ends, so that no two
//! events overlap. The sensor is the device file's, simulated at register
//! level behind its real driver ([`SimulatedSource`]: the MAX31865 with its
//! diagnosis cycle, or the NTC on the STM32F4's ADC), read every
//! `sensor_every` ticks; the estimator ticks every tick. The walk and the
//! fault kinds are the sensor's neither: each kind is an [`Injection`]
//! (or a missing read), which the source maps onto its chip.

use compensator::Params;
use compensator::equilibrium::equilibrium;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, ObserverDesign, StateEstimate};
use compensator::params::RawEstimator;
use compensator::sensor::simulated::{Injection, SimulatedSource};
use compensator::uncertainty::UncertaintyTable;
use core::borrow::Borrow;

/// Agreement required of a settled hold's estimate with the closed form:
/// displacement as a fraction of the stroke, pressures of `dp` (the
/// twin's accuracy goal at steady state).
pub const HOLD_TOLERANCE: f64 = 1e-3;

/// Steady time before a hold's end is compared with the closed form [s],
/// on top of ten of the twin's slowest time constants: the filter's
/// approach to a small step (10 time constants of 0.2 s) and the twin's
/// slewed oil (at most ~0.6 s for a step to the coldest oil).
pub const SETTLE: f32 = 2.0;

/// The simulated element's fault band \[C\]: wide, as the QEMU twin's, so
/// that the estimator's oil range is what rejects samples.
pub const SENSOR_BAND: (f32, f32) = (-60.0, 250.0);

fn abs32(x: f32) -> f32 {
    if x < 0.0 { -x } else { x }
}

fn abs64(x: f64) -> f64 {
    if x < 0.0 { -x } else { x }
}

/// Marsaglia's xorshift64: deterministic, no dependency, the same sequence
/// on the host and the Cortex-M4F.
#[derive(Clone, Copy, Debug)]
pub struct XorShift64(u64);

impl XorShift64 {
    /// A generator from `seed` (any value; zero is mapped away).
    pub fn new(seed: u64) -> Self {
        let s = seed ^ 0x9E37_79B9_7F4A_7C15;
        XorShift64(if s == 0 { 1 } else { s })
    }

    /// Next 64 bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }

    /// Uniform in [0, 1), 24 bits.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in 0..n (0 for n = 0).
    pub fn below(&mut self, n: u32) -> u32 {
        (((self.next_u64() >> 32) * u64::from(n)) >> 32) as u32
    }

    /// `true` with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
}

/// What a fault does to the sensor path, whatever the sensor: each kind
/// is an [`Injection`] the source maps onto its chip ([`Kind::injection`]),
/// or a read left out (a dropout), or the oil's temperature moved (a
/// spike).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// 1..=`spike_limit` consecutive samples off by more than the spike
    /// threshold (inside the oil range): `SPIKE` on each.
    Spike,
    /// The bus fails ([`Injection::Bus`]: MAX31865, every SPI transaction;
    /// NTC, no conversion ends): `SENSOR_FAULT`.
    BusError,
    /// No read at all (the sample is not delivered): `DEGRADED` after
    /// `stale_after` ticks.
    Dropout,
    /// The converter keeps reporting the code of the fault's start
    /// (a frozen reading): indistinguishable from a constant temperature,
    /// so no flag is expected; the estimate follows the frozen value.
    StuckCode,
    /// The converter stuck ([`Injection::Stuck`]: MAX31865, MISO stuck
    /// high, every byte 0xFF; NTC, no conversion ends): `SENSOR_FAULT`.
    StuckConverter,
    /// The element open ([`Injection::Open`]: MAX31865, its RTD-high
    /// status; NTC, the input at `V_REF+`): `SENSOR_FAULT`.
    OpenElement,
    /// The element shorted ([`Injection::Short`]: MAX31865, RTD-low; NTC,
    /// the input at ground): `SENSOR_FAULT`.
    ShortedElement,
    /// Code 0: `SENSOR_FAULT` (MAX31865: the driver's implausible code;
    /// NTC: a shorted divider's code).
    ZeroCode,
    /// The full-scale code ([`Injection::Saturated`]: MAX31865 0x7FFF,
    /// NTC `2^bits - 1`): `SENSOR_FAULT`.
    FullScaleCode,
    /// The code of a temperature 1-20 C below the oil range: `SENSOR_FAULT`
    /// (the estimator's oil range).
    ColdCode,
    /// The code of a temperature 1-40 C above the oil range: `SENSOR_FAULT`.
    HotCode,
}

impl Kind {
    /// Every kind, in index order.
    pub const ALL: [Kind; 11] = [
        Kind::Spike,
        Kind::BusError,
        Kind::Dropout,
        Kind::StuckCode,
        Kind::StuckConverter,
        Kind::OpenElement,
        Kind::ShortedElement,
        Kind::ZeroCode,
        Kind::FullScaleCode,
        Kind::ColdCode,
        Kind::HotCode,
    ];

    /// Index into [`Kind::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Spike => "spike",
            Kind::BusError => "bus error",
            Kind::Dropout => "dropout",
            Kind::StuckCode => "stuck code",
            Kind::StuckConverter => "stuck converter",
            Kind::OpenElement => "open element",
            Kind::ShortedElement => "shorted element",
            Kind::ZeroCode => "code 0",
            Kind::FullScaleCode => "code full scale",
            Kind::ColdCode => "code below oil range",
            Kind::HotCode => "code above oil range",
        }
    }

    /// The flag an unusable sample of this fault raises on its tick
    /// (`None`: no sample of it is unusable, or it is not detectable).
    pub fn flag(self) -> Option<Flags> {
        match self {
            Kind::Spike => Some(Flags::SPIKE),
            Kind::Dropout | Kind::StuckCode => None,
            _ => Some(Flags::SENSOR_FAULT),
        }
    }

    /// What the fault injects into the simulated converter, `code` being
    /// the source's code of the fault's [`Fault::level`] (`None`: nothing,
    /// the healthy converter: a spike moves the temperature, a dropout
    /// leaves the read out).
    pub fn injection(self, code: u16) -> Option<Injection> {
        match self {
            Kind::Spike | Kind::Dropout => None,
            Kind::BusError => Some(Injection::Bus),
            Kind::StuckConverter => Some(Injection::Stuck),
            Kind::OpenElement => Some(Injection::Open),
            Kind::ShortedElement => Some(Injection::Short),
            Kind::ZeroCode => Some(Injection::Code(0)),
            Kind::FullScaleCode => Some(Injection::Saturated),
            Kind::StuckCode | Kind::ColdCode | Kind::HotCode => Some(Injection::Code(code)),
        }
    }
}

/// One injected fault: `kind` over ticks `start..end`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fault {
    /// What is injected.
    pub kind: Kind,
    /// First tick.
    pub start: u32,
    /// First tick after it.
    pub end: u32,
    /// What a spike adds to the temperature [C].
    pub delta: f32,
    /// The temperature whose code the converter is forced to (stuck and
    /// out-of-range codes) \[C\]: the source's [`SimulatedSource::code_of`]
    /// turns it into the chip's code when the fault starts.
    pub level: f32,
}

/// One piece of the walk, ticks `start..end`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// First tick.
    pub start: u32,
    /// First tick after it.
    pub end: u32,
    /// Temperature at `start` [C].
    pub from: f32,
    /// Temperature at `end` [C] (a hold: `from`).
    pub to: f32,
    /// A hold (the end is checked against the closed form when settled).
    pub hold: bool,
    /// Entered by an abrupt change from the previous segment's end.
    pub step: bool,
    /// A cold excursion (a hold at the oil range's bottom).
    pub cold: bool,
    /// The fault it carries.
    pub fault: Option<Fault>,
}

impl Segment {
    /// The oil temperature at tick `k` of the segment [C].
    pub fn temperature(&self, k: u32) -> f32 {
        if self.hold || self.end <= self.start {
            self.to
        } else {
            self.from + (self.to - self.from) * ((k - self.start) as f32 / (self.end - self.start) as f32)
        }
    }
}

/// The sensor's and the estimator's timing, the walk's ranges, and the
/// bounds of the checks, from the device's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Tick [s].
    pub tick: f32,
    /// Ticks between two reads of the converter (the source's sample
    /// period).
    pub sensor_every: u32,
    /// Reads after a diagnosis cycle that return no sample (the source's
    /// [`SimulatedSource::restart_readings`]: 0 for the NTC).
    pub restart: u32,
    /// `EstimatorConfig::spike_limit`.
    pub spike_limit: u32,
    /// `EstimatorConfig::spike_threshold` [C].
    pub spike_threshold: f32,
    /// `EstimatorConfig::stale_after` [ticks].
    pub stale_after: u32,
    /// The estimator's oil range [C].
    pub oil: (f32, f32),
    /// Levels of a cold excursion [C]: the oil range's bottom (half a
    /// degree inside, clear of the sensor's quantization) to 2.5 C above.
    pub cold: (f32, f32),
    /// Levels of the ordinary walk [C]: from 6 C below the validated range
    /// to 12 C above it, inside the range the oil model accepts.
    pub range: (f32, f32),
}

impl Limits {
    /// From the estimator's configuration and what the simulated `source`
    /// says of itself (its sample period, its reads without a sample after
    /// a diagnosis cycle); the model `params` bounds the walk to
    /// temperatures it accepts.
    ///
    /// # Errors
    ///
    /// The oil model leaves no room for a walk (less than 10 C accepted
    /// above the cold levels).
    pub fn new<S: SimulatedSource, U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy>(
        params: &Params<f32>,
        config: &EstimatorConfig<U, O>,
        source: &S,
    ) -> Result<Limits, &'static str> {
        let accepts = |t: f32| params.oil.state(t).is_ok() && equilibrium(params, t).is_ok();
        let (oil_lo, oil_hi) = (config.oil.min, config.oil.max);
        // The coldest oil the model accepts, in whole degrees from the
        // range's bottom.
        let mut cold_lo = oil_lo + 0.5;
        while !accepts(cold_lo) && cold_lo < config.valid.min {
            cold_lo += 1.0;
        }
        let cold = (cold_lo, cold_lo + 2.5);
        let lo = (config.valid.min - 6.0).max(cold.1 + 1.0);
        let mut hi = (config.valid.max + 12.0).min(oil_hi - 1.0);
        while !(accepts(hi) && accepts(hi + 1.0)) && hi > lo {
            hi -= 1.0;
        }
        if !(hi >= lo + 10.0) || !accepts(cold.0) {
            return Err("the oil model accepts too narrow a range for the walk");
        }
        Ok(Limits {
            tick: config.tick(),
            sensor_every: config.ticks_per(source.sample_period()),
            restart: source.restart_readings(),
            spike_limit: config.spikes.limit,
            spike_threshold: config.spikes.threshold,
            stale_after: config.stale_after,
            oil: (config.oil.min, config.oil.max),
            cold,
            range: (lo, hi),
        })
    }

    /// Ticks in `seconds`.
    pub fn ticks(&self, seconds: f32) -> u32 {
        (seconds / self.tick) as u32
    }

    /// Bound on the ticks from a fault's start to the flag of its first
    /// unusable sample (`SENSOR_FAULT`, or `SPIKE`): the driver reads every
    /// `sensor_every` ticks, and a diagnosis cycle started by the read just
    /// before the fault hides it for one read (the cycle's result) and
    /// `restart - 1` more (the converter's stale registers), so the fault
    /// shows at the `restart + 1`-th read after its start at the latest.
    pub fn detection_bound(&self) -> u32 {
        (self.restart + 1) * self.sensor_every
    }

    /// Bound on the ticks from a fault's start to `DEGRADED` when no usable
    /// sample comes: the estimator raises it `stale_after + 1` ticks after
    /// the last usable sample, which came before the fault.
    pub fn degraded_bound(&self) -> u32 {
        self.stale_after
    }

    /// Bound on the ticks from the end of a fault (or from a step) to the
    /// next accepted sample, which clears every sensor flag: the first read
    /// (at most `sensor_every - 1` ticks on), then at most one diagnosis
    /// cycle (the cycle resets the driver's countdown to the next one),
    /// after a reconfiguration when MISO was stuck high (a configuration,
    /// the cycle's result, `restart - 1` stale reads), `spike_limit`
    /// samples rejected when the oil moved beyond the spike threshold
    /// meanwhile, and the one accepted: `restart + spike_limit + 2` reads,
    /// the last `restart + spike_limit + 1` reads after the first; one read
    /// of margin on top.
    pub fn recovery_bound(&self) -> u32 {
        (self.restart + self.spike_limit + 4) * self.sensor_every
    }
}

/// The seeded walk.
#[derive(Clone, Copy, Debug)]
pub struct Walk {
    rng: XorShift64,
    limits: Limits,
    segment: Segment,
    /// Segments begun so far.
    pub segments: u32,
}

impl Walk {
    /// The walk of `seed`: it starts with a hold at a random level.
    pub fn new(limits: Limits, seed: u64) -> Walk {
        let mut rng = XorShift64::new(seed);
        let level = rng.uniform(limits.range.0, limits.range.1);
        let segment = Segment {
            start: 0,
            end: limits.ticks(2.0),
            from: level,
            to: level,
            hold: true,
            step: false,
            cold: false,
            fault: None,
        };
        Walk {
            rng,
            limits,
            segment,
            segments: 1,
        }
    }

    /// The segment in force at tick `k` (call with `k` = 0, 1, 2, ...).
    pub fn at(&mut self, k: u32) -> &Segment {
        while k >= self.segment.end {
            self.segment = self.next_segment();
            self.segments += 1;
        }
        &self.segment
    }

    fn next_segment(&mut self) -> Segment {
        let lim = self.limits;
        let rng = &mut self.rng;
        let start = self.segment.end;
        let level = self.segment.to;
        let (lo, hi) = lim.range;
        let room = lim.recovery_bound();
        let u = rng.unit();
        let mut seg = Segment {
            start,
            end: start,
            from: level,
            to: level,
            hold: true,
            step: true,
            cold: false,
            fault: None,
        };
        if u < 0.1 && level > lim.cold.1 + lim.spike_threshold {
            // A cold excursion: a real step down to the oil's coldest.
            seg.to = rng.uniform(lim.cold.0, lim.cold.1);
            seg.cold = true;
        } else if u < 0.4 {
            // A ramp of 0.2-2 C/s, 2-15 C away (out of the cold: anywhere).
            let to = if level < lo {
                rng.uniform(lo, hi)
            } else {
                let d = rng.uniform(2.0, 15.0);
                if rng.chance(0.5) { level + d } else { level - d }
            };
            seg.to = to.max(lo).min(hi);
            seg.hold = false;
            seg.step = false;
            let rate = rng.uniform(0.2, 2.0);
            let secs = abs32(seg.to - level) / rate;
            seg.end = start + lim.ticks(secs).max(1);
        } else if rng.chance(0.4) {
            // A small step, through the filter.
            let d = rng.uniform(0.3, lim.spike_threshold - 1.0);
            let to = if rng.chance(0.5) { level + d } else { level - d };
            seg.to = to.max(lim.cold.0).min(hi);
        } else {
            // A step anywhere: often beyond the spike threshold.
            seg.to = rng.uniform(lo, hi);
        }
        seg.from = if seg.hold { seg.to } else { level };
        // The fault: after the step's recovery room, ending the same room
        // before the segment does.
        let mut fault = None;
        if rng.chance(0.8) {
            let kind = Kind::ALL[rng.below(Kind::ALL.len() as u32) as usize];
            let every = lim.sensor_every;
            let long = lim.stale_after + lim.detection_bound() + rng.below(lim.ticks(2.0));
            let reads = |rng: &mut XorShift64, n: u32| (1 + rng.below(n)) * every;
            let length = match kind {
                Kind::Spike => reads(rng, lim.spike_limit),
                Kind::Dropout => long,
                Kind::StuckCode => lim.ticks(rng.uniform(0.5, 5.0)),
                _ if rng.chance(0.5) => reads(rng, 10),
                _ => long,
            };
            let earliest = start + room + rng.below(4 * every);
            let begin = if seg.hold {
                Some(earliest)
            } else if earliest + length + room <= seg.end {
                Some(earliest + rng.below(seg.end - room - length - earliest + 1))
            } else {
                None
            };
            if let Some(mut begin) = begin {
                if kind == Kind::Spike {
                    // Aligned on reads: exactly `length / every` of them.
                    begin = begin.div_ceil(every) * every;
                }
                let at = seg.temperature(begin);
                let magnitude = rng.uniform(lim.spike_threshold + 2.0, 4.0 * lim.spike_threshold);
                let delta = if at + magnitude <= lim.oil.1 - 1.0 {
                    magnitude
                } else {
                    -magnitude
                };
                let level = match kind {
                    Kind::ColdCode => lim.oil.0 - rng.uniform(1.0, 20.0),
                    Kind::HotCode => lim.oil.1 + rng.uniform(1.0, 40.0),
                    _ => at,
                };
                let end = if kind == Kind::Spike {
                    begin + length - every + 1
                } else {
                    begin + length
                };
                fault = Some(Fault {
                    kind,
                    start: begin,
                    end,
                    delta,
                    level,
                });
            }
        }
        seg.fault = fault;
        if seg.hold {
            // The steady tail the closed form is checked after.
            let tail = lim.ticks(rng.uniform(0.5, 5.0));
            let busy = fault.map_or(start + room, |f| f.end + room);
            seg.end = busy + tail;
        }
        seg
    }
}

/// The checks, by index into [`Stats::violations`].
pub const CHECKS: [&str; 10] = [
    "an estimate not finite",
    "the twin re-seated (TWIN_RESEATED or reseats > 0)",
    "SENSOR_FAULT not exactly on the unusable samples",
    "DEGRADED not exactly after stale_after ticks without an accepted sample",
    "a spiked sample without SPIKE",
    "a fault's flag late or missing",
    "recovery late (no accepted sample within the bound after a fault or a step)",
    "a sensor flag while the sensor is healthy",
    "a settled hold's estimate off the closed form",
    "a model error building the check (closed form refused)",
];

const NAN: usize = 0;
const RESEAT: usize = 1;
const SENSOR_FLAG: usize = 2;
const DEGRADED_FLAG: usize = 3;
const SPIKE_MISSED: usize = 4;
const DETECTION: usize = 5;
const RECOVERY: usize = 6;
const QUIET: usize = 7;
const HOLD: usize = 8;
const MODEL: usize = 9;

/// What the soak counted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Ticks run.
    pub ticks: u32,
    /// Segments of the walk begun.
    pub segments: u32,
    /// Abrupt steps (segments entered by one).
    pub steps: u32,
    /// Cold excursions.
    pub cold_excursions: u32,
    /// Coldest and hottest oil of the walk [C].
    pub span: (f32, f32),
    /// Samples the driver returned (a temperature or a fault).
    pub samples: u32,
    /// Of them, unusable.
    pub unusable: u32,
    /// Samples rejected as spikes (injected spikes and real steps).
    pub spikes: u32,
    /// Faults injected, per [`Kind`].
    pub injected: [u32; 11],
    /// Faults whose window held no read that returned a sample (all hidden
    /// by a diagnosis cycle), per kind: nothing to flag.
    pub unread: [u32; 11],
    /// Worst ticks from a fault's start to its flag ([`Kind::flag`]).
    pub detection: [u32; 11],
    /// Worst ticks from a fault's start to `DEGRADED` (faults longer than
    /// `stale_after` plus the detection bound, and dropouts).
    pub degraded: [u32; 11],
    /// Long faults (and dropouts) that had to raise `DEGRADED`, per kind.
    pub long: [u32; 11],
    /// Worst ticks from a fault's end to the next accepted sample.
    pub recovery: [u32; 11],
    /// Worst ticks from a step to the next accepted sample.
    pub step_recovery: u32,
    /// Holds compared with the closed form at their end.
    pub holds_checked: u32,
    /// Holds too short after their last disturbance to be compared.
    pub holds_skipped: u32,
    /// Worst settled hold: displacement off the closed form [strokes].
    pub hold_x: f64,
    /// Worst settled hold: pressures off the closed form [dp].
    pub hold_p: f64,
    /// The estimator's re-seats at the end.
    pub reseats: u32,
    /// Violations per check ([`CHECKS`]).
    pub violations: [u32; 10],
    /// The first tick of each check's first violation (`u32::MAX`: none).
    pub first_violation: [u32; 10],
}

impl Stats {
    fn new() -> Stats {
        Stats {
            ticks: 0,
            segments: 0,
            steps: 0,
            cold_excursions: 0,
            span: (f32::INFINITY, f32::NEG_INFINITY),
            samples: 0,
            unusable: 0,
            spikes: 0,
            injected: [0; 11],
            unread: [0; 11],
            detection: [0; 11],
            degraded: [0; 11],
            long: [0; 11],
            recovery: [0; 11],
            step_recovery: 0,
            holds_checked: 0,
            holds_skipped: 0,
            hold_x: 0.0,
            hold_p: 0.0,
            reseats: 0,
            violations: [0; 10],
            first_violation: [u32::MAX; 10],
        }
    }

    fn violate(&mut self, check: usize, k: u32) {
        self.violations[check] = self.violations[check].saturating_add(1);
        if self.first_violation[check] == u32::MAX {
            self.first_violation[check] = k;
        }
    }

    /// Violations of every check.
    pub fn total_violations(&self) -> u32 {
        self.violations.iter().fold(0u32, |a, &v| a.saturating_add(v))
    }

    /// Faults injected in all.
    pub fn total_injected(&self) -> u32 {
        self.injected.iter().sum()
    }
}

/// A fault being watched.
#[derive(Clone, Copy, Debug)]
struct Watch {
    fault: Fault,
    /// What the converter is given meanwhile.
    injection: Option<Injection>,
    /// Reads in its window that returned a sample or a fault.
    reads: u32,
    flagged: Option<u32>,
    degraded: Option<u32>,
}

/// An event (a fault's end, a step) waiting for the next accepted sample.
#[derive(Clone, Copy, Debug)]
struct Pending {
    since: u32,
    kind: Option<Kind>,
}

/// A settled hold's end, for further checks by the caller (the host soak
/// compares it with the independent reference; the QEMU image has none).
#[derive(Clone, Copy, Debug)]
pub struct HoldEnd {
    /// The tick.
    pub tick: u32,
    /// The estimate.
    pub estimate: StateEstimate,
}

/// The soak: walk, the simulated sensor `S` behind its real driver
/// ([`SimulatedSource`]: the device file's), estimator (its uncertainty
/// table held as `U`: by value on the host, a reference to flash in the
/// QEMU image), checks.
pub struct Soak<S, U = UncertaintyTable, O = ObserverDesign> {
    /// Timing, ranges, bounds.
    pub limits: Limits,
    walk: Walk,
    sensor: S,
    estimator: Estimator<f32, U, O>,
    params64: Params<f64>,
    machine: bool,
    k: u32,
    /// Tick number (1-based, as the estimator counts) of the last accepted
    /// sample; 0: the start.
    last_accept: u32,
    watch: Option<Watch>,
    pending: Option<Pending>,
    /// The tick after which the oil and the sensor were last left alone.
    disturbed: u32,
    /// Ticks a hold must have been left alone to be compared (besides the
    /// twin's ten slowest time constants).
    settle: u32,
    /// What was counted.
    pub stats: Stats,
}

impl<S: SimulatedSource, U: Borrow<UncertaintyTable> + Copy, O: Borrow<ObserverDesign> + Copy> Soak<S, U, O> {
    /// A soak of `seed` for the device of `params` (`params64`: the same
    /// parameters in `f64`, for the closed form the holds are checked
    /// against), the estimator `config` and the sensor `S` built from the
    /// file's `[estimator]` section `sensor` (its fault band widened to
    /// [`SENSOR_BAND`]).
    ///
    /// # Errors
    ///
    /// No room for the walk ([`Limits::new`]), the converter's
    /// configuration failed, or the estimator refused the start.
    pub fn new(
        params: &Params<f32>,
        params64: &Params<f64>,
        config: EstimatorConfig<U, O>,
        sensor: &RawEstimator,
        seed: u64,
    ) -> Result<Soak<S, U, O>, &'static str> {
        let mut sensor = S::simulated(sensor, SENSOR_BAND, config.oil.min);
        let limits = Limits::new(params, &config, &sensor)?;
        let walk = Walk::new(limits, seed);
        let start = walk.segment.to;
        sensor.set_temperature(start);
        sensor.start().map_err(|_| "the converter's configuration failed")?;
        let estimator = Estimator::new(params, config, start).map_err(|_| "the estimator refused the start")?;
        let mut stats = Stats::new();
        stats.segments = 1;
        Ok(Soak {
            limits,
            walk,
            sensor,
            estimator,
            params64: *params64,
            machine: params.machine.is_some(),
            k: 0,
            last_accept: 0,
            watch: None,
            // The converter's start-up diagnosis: no sample for a while.
            pending: Some(Pending { since: 0, kind: None }),
            disturbed: 0,
            settle: limits.ticks(SETTLE),
            stats,
        })
    }

    /// Runs one tick; returns the estimate at a settled hold's end.
    pub fn step(&mut self) -> Option<HoldEnd> {
        let k = self.k;
        self.k += 1;
        let lim = self.limits;
        let seg = *self.walk.at(k);
        let st = &mut self.stats;
        st.ticks = self.k;
        if seg.start == k && k > 0 {
            st.segments = self.walk.segments;
            self.disturbed = k;
            if seg.step {
                st.steps += 1;
                st.cold_excursions += u32::from(seg.cold);
                if self.pending.take().is_some() {
                    // The previous event has not recovered in its room.
                    st.violate(RECOVERY, k);
                }
                self.pending = Some(Pending { since: k, kind: None });
            }
        }
        // The fault's window.
        if let Some(w) = self.watch
            && k == w.fault.end
        {
            self.watch = None;
            Self::close(st, &lim, &w, k);
            self.pending = Some(Pending {
                since: k,
                kind: Some(w.fault.kind),
            });
        }
        if let Some(f) = seg.fault
            && k == f.start
        {
            st.injected[f.kind.index()] += 1;
            if self.pending.take().is_some() {
                // The previous event has not recovered in its room.
                st.violate(RECOVERY, k);
            }
            self.watch = Some(Watch {
                fault: f,
                injection: f.kind.injection(self.sensor.code_of(f.level)),
                reads: 0,
                flagged: None,
                degraded: None,
            });
        }
        let active = self.watch.map(|w| (w.fault, w.injection));
        // Drive the converter.
        let t = seg.temperature(k);
        st.span = (st.span.0.min(t), st.span.1.max(t));
        let mut read = k.is_multiple_of(lim.sensor_every);
        let mut at = t;
        let mut injection = None;
        if let Some((f, i)) = active {
            match f.kind {
                Kind::Spike => at = t + f.delta,
                Kind::Dropout => read = false,
                _ => injection = i,
            }
        }
        self.sensor.set_temperature(at);
        self.sensor.inject(injection);
        let sample = if read { self.sensor.read() } else { Ok(None) };
        let e = self.estimator.tick(sample);
        let n = k + 1;
        // What the sample was.
        let (oil_lo, oil_hi) = lim.oil;
        let unusable = match sample {
            Err(_) => true,
            Ok(Some(v)) => !(v.is_finite() && v >= oil_lo && v <= oil_hi),
            Ok(None) => false,
        };
        let returned = !matches!(sample, Ok(None));
        let spiked = e.flags.contains(Flags::SPIKE);
        let accepted = returned && !unusable && !spiked;
        st.samples += u32::from(returned);
        st.unusable += u32::from(unusable);
        st.spikes += u32::from(spiked);
        if accepted {
            self.last_accept = n;
        }
        // The invariants.
        if !e.is_finite() || (self.machine && !e.compensation_error.is_finite()) {
            st.violate(NAN, k);
        }
        st.reseats = e.reseats;
        if e.reseats != 0 || e.flags.contains(Flags::TWIN_RESEATED) {
            st.violate(RESEAT, k);
        }
        if e.flags.contains(Flags::SENSOR_FAULT) != unusable {
            st.violate(SENSOR_FLAG, k);
        }
        let stale = n - self.last_accept > lim.stale_after;
        if e.flags.contains(Flags::DEGRADED) != stale {
            st.violate(DEGRADED_FLAG, k);
        }
        if let Some(w) = self.watch.as_mut() {
            w.reads += u32::from(returned);
            if w.fault.kind == Kind::Spike && returned && !unusable && !spiked {
                st.violate(SPIKE_MISSED, k);
            }
            if let Some(flag) = w.fault.kind.flag()
                && w.flagged.is_none()
                && e.flags.contains(flag)
            {
                w.flagged = Some(k - w.fault.start);
            }
            if w.degraded.is_none() && e.flags.contains(Flags::DEGRADED) {
                w.degraded = Some(k - w.fault.start);
            }
        }
        if accepted && let Some(p) = self.pending.take() {
            let took = k - p.since;
            match p.kind {
                Some(kind) => st.recovery[kind.index()] = st.recovery[kind.index()].max(took),
                None => st.step_recovery = st.step_recovery.max(took),
            }
            if took > lim.recovery_bound() {
                st.violate(RECOVERY, k);
            }
            self.disturbed = self.disturbed.max(k);
        }
        let sensor_flags = Flags(Flags::SENSOR_FAULT.0 | Flags::SPIKE.0 | Flags::DEGRADED.0);
        if self.watch.is_none() && self.pending.is_none() && e.flags.0 & sensor_flags.0 != 0 {
            st.violate(QUIET, k);
        }
        // The end of a hold: the closed form, once settled.
        if seg.hold && k + 1 == seg.end {
            let tau = self.estimator.slowest_time_constant();
            let settled = self.watch.is_none()
                && self.pending.is_none()
                && tau.is_finite()
                && k - self.disturbed >= self.settle + lim.ticks(10.0 * tau);
            if settled {
                st.holds_checked += 1;
                let p = &self.params64;
                match equilibrium(p, f64::from(e.temperature)) {
                    Ok(eq) => {
                        let dx = abs64(f64::from(e.x) - eq.x) / p.plunger.stroke;
                        let dx_eq = abs64(f64::from(e.x_equilibrium) - eq.x) / p.plunger.stroke;
                        let dp =
                            abs64(f64::from(e.p_a) - eq.p_a).max(abs64(f64::from(e.p_b) - eq.p_b)) / p.pressure_drop;
                        let dx = dx.max(dx_eq);
                        st.hold_x = st.hold_x.max(dx);
                        st.hold_p = st.hold_p.max(dp);
                        if !(dx <= HOLD_TOLERANCE && dp <= HOLD_TOLERANCE) {
                            st.violate(HOLD, k);
                        }
                    }
                    Err(_) => st.violate(MODEL, k),
                }
                return Some(HoldEnd { tick: k, estimate: e });
            }
            st.holds_skipped += 1;
        }
        None
    }

    /// The end of a fault's window: was it flagged in time?
    fn close(st: &mut Stats, lim: &Limits, w: &Watch, k: u32) {
        let i = w.fault.kind.index();
        let length = w.fault.end - w.fault.start;
        let long = w.fault.kind == Kind::Dropout
            || (w.fault.kind != Kind::StuckCode && length >= lim.stale_after + lim.detection_bound());
        if long {
            st.long[i] += 1;
            match w.degraded {
                Some(d) if d <= lim.degraded_bound() => st.degraded[i] = st.degraded[i].max(d),
                Some(d) => {
                    st.degraded[i] = st.degraded[i].max(d);
                    st.violate(DETECTION, k);
                }
                None => st.violate(DETECTION, k),
            }
        }
        if w.fault.kind.flag().is_some() {
            if w.reads == 0 {
                st.unread[i] += 1;
            } else {
                match w.flagged {
                    Some(d) if d <= lim.detection_bound() => st.detection[i] = st.detection[i].max(d),
                    Some(d) => {
                        st.detection[i] = st.detection[i].max(d);
                        st.violate(DETECTION, k);
                    }
                    None => st.violate(DETECTION, k),
                }
            }
        }
    }
}
