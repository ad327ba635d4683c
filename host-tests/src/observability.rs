//! Steady signatures of device faults on a second sensor (the
//! observability analysis of `docs/monitoring.md`): each fault's change
//! of the steady reading over a temperature range, from the independent
//! reference equilibrium (`compensator_reference::statics`), and how
//! nearly parallel two faults' signatures are.

use crate::reference::{Point, equilibrium};
use compensator::params::RawCore;

/// Temperatures per signature.
pub const TEMPS: usize = 9;

/// A fault: its name and the change of the device.
pub type Fault = (&'static str, fn(&mut RawCore));

/// What [`analyse`] finds of one fault on one sensor: `snr`, the index
/// of its twin, `|cos|`, `snr_perp`.
pub type Finding = (f64, usize, f64, f64);

/// The faults.
pub const FAULTS: [Fault; 6] = [
    ("capillary restricted (conductance x 0.8)", |c| {
        c.laminar_diameter *= 0.8f64.powf(0.25)
    }),
    ("orifice worn (area x 1.2)", |c| c.turbulent_diameter *= 1.2f64.sqrt()),
    ("thicker oil (viscosity x 1.25 at 40 C)", |c| {
        // Walther: log10(log10(nu + 0.7)) = a - b log10(T); nu in cSt.
        let l40 = (40.0f64 + 273.15).log10();
        let nu = 10f64.powf(10f64.powf(c.walther_a - c.walther_b * l40)) - 0.7;
        c.walther_a = (1.25 * nu + 0.7).log10().log10() + c.walther_b * l40;
    }),
    ("spring relaxed (rate x 0.9)", |c| c.spring_rate *= 0.9),
    ("preload lost (x 0.8)", |c| c.preload *= 0.8),
    ("window eroded (discharge x 1.1)", |c| {
        c.slot_discharge = (c.slot_discharge * 1.1).min(1.0)
    }),
];

/// A sensor: name, reading, one reading's standard deviation.
pub type Sensor = (&'static str, fn(&Point) -> f64, fn(&RawCore) -> f64);
/// The sensors: the chamber pressures (0.1 % of the supply pressure), their
/// difference, the displacement (0.1 % of the stroke).
pub const SENSORS: [Sensor; 4] = [
    ("p_a", |p| p.p_a, |c| 1e-3 * (c.pressure_drop + c.outlet_pressure)),
    ("p_b", |p| p.p_b, |c| 1e-3 * (c.pressure_drop + c.outlet_pressure)),
    (
        "dp_ab",
        |p| p.p_b - p.p_a,
        |c| 1e-3 * (c.pressure_drop + c.outlet_pressure),
    ),
    ("x", |p| p.x, |c| 1e-3 * c.stroke),
];

/// Per fault: `(snr, twin, |cos|, snr_perp)` on `sensor` for `core` over
/// `lo..=hi` [C].
pub fn analyse(core: &RawCore, lo: f64, hi: f64, sensor: &Sensor) -> Vec<Finding> {
    let temps: Vec<f64> = (0..TEMPS)
        .map(|k| lo + (hi - lo) * k as f64 / (TEMPS - 1) as f64)
        .collect();
    let read = |c: &RawCore| -> Vec<f64> { temps.iter().map(|&t| (sensor.1)(&equilibrium(c, t))).collect() };
    let sigma = (sensor.2)(core);
    let healthy = read(core);
    let signatures: Vec<Vec<f64>> = FAULTS
        .iter()
        .map(|(_, change)| {
            let mut c = *core;
            change(&mut c);
            read(&c).iter().zip(&healthy).map(|(f, h)| (f - h) / sigma).collect()
        })
        .collect();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let norm = |a: &[f64]| dot(a, a).sqrt();
    (0..FAULTS.len())
        .map(|i| {
            let s = &signatures[i];
            let snr = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut best = (usize::MAX, 0.0f64, norm(s));
            for (j, o) in signatures.iter().enumerate() {
                if j == i || norm(o) == 0.0 || norm(s) == 0.0 {
                    continue;
                }
                let cos = (dot(s, o) / (norm(s) * norm(o))).abs();
                if cos > best.1 {
                    let k = dot(s, o) / dot(o, o);
                    let rest: Vec<f64> = s.iter().zip(o).map(|(a, b)| a - k * b).collect();
                    best = (j, cos, norm(&rest));
                }
            }
            (snr, best.0, best.1, best.2)
        })
        .collect()
}
