//! The condition monitor against the fault-injection data
//! ([`crate::campaign`]): each scenario's records run through the
//! firmware's `f32` estimator with its monitor (`compensator::monitor`),
//! the probe's readings on their ticks and the second sensor's offered as
//! they come, and what the monitor's flags said and when.

use crate::campaign::{Fault, MOVE, Quantity, Records, Sample, Scenario, SecondSensor};
use compensator::Params;
use compensator::estimator::{Estimator, EstimatorConfig, Flags, StateEstimate};
use compensator::monitor::{self, MonitorSettings};

/// The monitor's flags that name or announce a device change (not the
/// per-reading ones).
pub const ALARMS: Flags = Flags(
    Flags::DEVICE_CHANGED.0
        | Flags::CAPILLARY_RESTRICTED.0
        | Flags::ORIFICE_CLOGGED.0
        | Flags::SPRING_RELAXED.0
        | Flags::PRELOAD_LOST.0
        | Flags::PLUNGER_STICKING.0
        | Flags::SENSOR_OFFSET.0,
);

/// The monitor's settings for the campaign's sensor: its noise with the
/// ADC's quantisation (`lsb^2 / 12`), its class as a uniform limit (GUM
/// 4.3.7), its period; the probe of the `nominal` design file.
pub fn settings(sensor: &SecondSensor, nominal: &compensator::params::RawParams) -> MonitorSettings {
    let quantity = match sensor.quantity {
        Quantity::PA => monitor::Quantity::ChamberA,
        Quantity::PB => monitor::Quantity::ChamberB,
        Quantity::DPAB => monitor::Quantity::Difference,
        Quantity::X => monitor::Quantity::Displacement,
    };
    let lsb = sensor.lsb();
    MonitorSettings {
        quantity,
        sd_noise: (sensor.noise_sd * sensor.noise_sd + lsb * lsb / 12.0).sqrt() as f32,
        sd_accuracy: (sensor.accuracy * sensor.width() / 3f64.sqrt()) as f32,
        sample_period: (1.0 / sensor.rate_hz) as f32,
        probe: monitor::ProbeModel::new(nominal),
    }
}

/// The flags that name `fault` correctly on `quantity`'s sensor, or `None`
/// where the sensor cannot see it at all (a pressure sensor and the
/// spring, the preload or friction: `docs/monitoring.md`).
pub fn expected(fault: Fault, quantity: Quantity) -> Option<Flags> {
    let pressure = quantity != Quantity::X;
    match fault {
        Fault::None => None,
        Fault::CapillaryRestricted(_) | Fault::OrificeWorn(_) => Some(Flags::CAPILLARY_RESTRICTED),
        Fault::OrificeClogged(_) => Some(Flags::ORIFICE_CLOGGED),
        Fault::SpringRelaxed(_) if !pressure => Some(Flags::SPRING_RELAXED),
        Fault::PreloadLost(_) if !pressure => Some(Flags::PRELOAD_LOST),
        Fault::Sticking(_) if !pressure => Some(Flags::PLUNGER_STICKING),
        // A displacement sensor's zero moved up reads as a lost preload.
        Fault::SensorOffset(_) if !pressure => Some(Flags(Flags::SENSOR_OFFSET.0 | Flags::PRELOAD_LOST.0)),
        Fault::SensorOffset(_) => Some(Flags::SENSOR_OFFSET),
        _ => None,
    }
}

/// A scenario's records through the firmware's `f32` estimator of its
/// nominal design with the monitor of its second sensor, as the firmware
/// runs them: a tick per estimator period, the probe's readings on theirs,
/// each second-sensor reading offered before its record's tick.
pub struct Replay {
    /// The estimator.
    pub estimator: Estimator,
    /// The scenario's records not yet fed.
    pub records: core::iter::Peekable<Records>,
    tick: u64,
}

impl Replay {
    /// The estimator started on `scenario`'s first probe reading.
    ///
    /// # Errors
    ///
    /// A scenario the records or the estimator refuse, or whose first
    /// record has no probe reading.
    pub fn new(scenario: &Scenario) -> Result<Replay, String> {
        let nominal = &scenario.nominal;
        let p32 = Params::<f32>::new(nominal).map_err(|e| e.to_string())?;
        let config = EstimatorConfig::new(nominal).map_err(|e| e.to_string())?;
        let mut records = scenario.records()?.peekable();
        let first = records
            .peek()
            .and_then(|s| s.probe)
            .ok_or("the first record has no probe reading")?;
        let estimator = Estimator::new(&p32, config, first as f32)
            .map_err(|e| e.to_string())?
            .with_monitor(settings(&scenario.sensor, nominal))
            .map_err(|e| e.to_string())?;
        Ok(Replay {
            estimator,
            records,
            tick: 0,
        })
    }

    /// Feeds record `r` (the ticks without a reading before it, its second
    /// sensor's reading, its own tick) and returns its tick's estimate.
    pub fn feed(&mut self, r: &Sample) -> StateEstimate {
        while self.tick < r.tick {
            self.estimator.tick(Ok(None));
            self.tick += 1;
        }
        if let Some(y) = r.second {
            self.estimator.offer_second(Ok(y as f32));
        }
        self.tick += 1;
        self.estimator.tick(Ok(r.probe.map(|v| v as f32)))
    }

    /// The next record, fed, with its estimate.
    pub fn next_fed(&mut self) -> Option<(Sample, StateEstimate)> {
        let r = self.records.next()?;
        let e = self.feed(&r);
        Some((r, e))
    }
}

/// What one scenario's run found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// The fault's onset \[s\] (infinite for a healthy run).
    pub onset: f64,
    /// First alarm before the onset \[s\] (a false alarm), if any.
    pub false_alarm: Option<f64>,
    /// Alarms before the onset: a healthy run's monitor is reset after each
    /// (as after an inspection that found the device healthy) and watches
    /// on; a faulty run ends at its first.
    pub false_alarms: u32,
    /// Delay from the onset to the first alarm \[s\].
    pub detected: Option<f64>,
    /// Delay from the onset to the first named fault \[s\], and the flag.
    pub named: Option<(f64, Flags)>,
    /// Delay from the onset until the oil's temperature since the onset
    /// spans [`MOVE`]'s span \[s\] (the operation a divider's fault is to be
    /// named within).
    pub spanned: Option<f64>,
    /// Delay from the onset until the true plunger lags its frictionless
    /// position (clamped to the stops) by half its play band \[s\]: the
    /// first temperature change that should have moved a plunger the
    /// friction holds (sticking faults only).
    pub held: Option<f64>,
    /// Simulated healthy time \[s\] (before the onset).
    pub healthy_time: f64,
    /// Readings the monitor rejected (gate, non-finite).
    pub rejected: u32,
}

/// How long the records are followed after a fault is named, to find when
/// the operation spanned [`MOVE`] and when the plunger was held \[s\].
const FOLLOW: f64 = 900.0;

/// Runs `scenario` through the estimator of its nominal design with the
/// monitor of its sensor: a healthy scenario through its whole duration,
/// a faulty one until its fault is named and [`FOLLOW`] after it.
///
/// # Errors
///
/// A scenario the records or the estimator refuse.
pub fn run(scenario: &Scenario) -> Result<Outcome, String> {
    let mut replay = Replay::new(scenario)?;
    let fault = scenario.injection.fault;
    let onset = if fault == Fault::None {
        f64::INFINITY
    } else {
        scenario.injection.onset
    };
    let mut out = Outcome {
        onset,
        false_alarm: None,
        false_alarms: 0,
        detected: None,
        named: None,
        spanned: None,
        held: None,
        healthy_time: scenario.duration.min(onset),
        rejected: 0,
    };
    let band = match fault {
        Fault::Sticking(_) => {
            let device = fault.degrade(&scenario.device);
            fault.friction(&scenario.device) / device.spring_rate
        }
        _ => f64::NAN,
    };
    let stroke = scenario.device.stroke;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let names = Flags(ALARMS.0 & !Flags::DEVICE_CHANGED.0);
    while let Some(s) = replay.records.next() {
        if s.t >= onset {
            lo = lo.min(s.t_true);
            hi = hi.max(s.t_true);
            if out.spanned.is_none() && hi - lo >= MOVE.0 {
                out.spanned = Some(s.t - onset);
            }
            if out.held.is_none() && (s.truth.x - s.truth.x_free.clamp(0.0, stroke)).abs() >= 0.5 * band {
                out.held = Some(s.t - onset);
            }
        }
        if let Some((t, _)) = out.named {
            let held_known = out.held.is_some() || band.is_nan();
            if (out.spanned.is_some() && held_known) || s.t > onset + t + FOLLOW {
                break;
            }
            continue;
        }
        let e = replay.feed(&s);
        let alarm = Flags(e.flags.0 & ALARMS.0);
        if alarm.is_empty() {
            continue;
        }
        if s.t < onset {
            out.false_alarm.get_or_insert(s.t);
            out.false_alarms += 1;
            if fault != Fault::None {
                // A false alarm ends a faulty run's use: the monitor latched it.
                break;
            }
            replay.estimator.reset_monitor();
            continue;
        }
        out.detected.get_or_insert(s.t - onset);
        let named = Flags(alarm.0 & names.0);
        if !named.is_empty() {
            out.named = Some((s.t - onset, named));
        }
    }
    out.rejected = replay.estimator.health().rejected;
    Ok(out)
}
