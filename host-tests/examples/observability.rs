//! Which device faults a second sensor can see at steady state, and which
//! it cannot tell apart: the observability analysis behind condition
//! monitoring (`docs/monitoring.md`).
//!
//!     cargo run --release -p host-tests --example observability -- [designs] [seed]
//!
//! Each fault is a change of the device file's fields (a capillary
//! restriction: conductance x 0.8, the bore by its fourth root; an orifice
//! worn to 1.2 times its area; an oil 1.25 times thicker at 40 C with the
//! same Walther slope; the spring rate x 0.9; the preload x 0.8; the
//! window's discharge coefficient x 1.1). Its *signature* on a sensor is
//! the change of the steady reading at 9 temperatures over the validated
//! range, from the independent reference equilibrium
//! (`compensator_reference::statics`). Per sensor (the chamber pressures
//! `p_a`, `p_b`, their difference, the displacement `x`), each fault's:
//!
//! * `snr`: the largest change over the range in standard deviations of
//!   one reading (0.1 % of the supply pressure for a pressure transducer,
//!   0.1 % of the stroke for a displacement sensor);
//! * `twin` and `|cos|`: the fault whose signature is most nearly parallel
//!   (1: the two look alike at every temperature, and no test on steady
//!   readings can tell them apart; at one temperature every pair is
//!   parallel, one reading being one number);
//! * `snr_perp`: what is left of the signature once the twin's best fit
//!   is taken out, in reading standard deviations: what an isolation test
//!   has to work with.
//!
//! Defaults: the paper preset, the model example and 20 random designs
//! (`host_tests::random::physical_params`) whose plunger travels over the
//! range, seed 1.

use compensator::params::RawCore;
use host_tests::random::{Rng, physical_params};
use host_tests::reference::{Point, equilibrium};

/// Temperatures per signature.
const TEMPS: usize = 9;

/// A fault: its name and the change of the device.
type Fault = (&'static str, fn(&mut RawCore));

/// What [`analyse`] finds of one fault on one sensor: `snr`, the index
/// of its twin, `|cos|`, `snr_perp`.
type Finding = (f64, usize, f64, f64);

/// The faults.
const FAULTS: [Fault; 6] = [
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

/// The sensors: name, reading, one reading's standard deviation.
type Sensor = (&'static str, fn(&Point) -> f64, fn(&RawCore) -> f64);
const SENSORS: [Sensor; 4] = [
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
fn analyse(core: &RawCore, lo: f64, hi: f64, sensor: &Sensor) -> Vec<Finding> {
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

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: u64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let (count, seed) = (arg(0, 20) as usize, arg(1, 1));
    let root = host_tests::repo_root();
    let paper = compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset");
    let example = compensator_cli::load(&root.join("presets/model-example.toml")).expect("model example");
    let mut designs = vec![("paper preset", paper), ("model example", example)];
    let mut rng = Rng::new(seed ^ 0x0B5E);
    while designs.len() < count + 2 {
        let raw = physical_params(&mut rng);
        let x = |t: f64| equilibrium(&raw.core, t).x;
        if (x(raw.estimator.valid_max - 2.0) - x(raw.estimator.valid_min + 2.0)).abs() < 0.1 * raw.core.stroke {
            continue;
        }
        designs.push(("random", raw));
    }

    for (name, raw) in designs.iter().take(2) {
        let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
        println!("\n{name}, {lo}-{hi} C: snr | twin | |cos| | snr_perp\n");
        print!("| fault |");
        for s in &SENSORS {
            print!(" {} |", s.0);
        }
        println!("\n|---|{}", "---|".repeat(SENSORS.len()));
        let per_sensor: Vec<_> = SENSORS.iter().map(|s| analyse(&raw.core, lo, hi, s)).collect();
        for (i, (fault, _)) in FAULTS.iter().enumerate() {
            print!("| {fault} |");
            for a in &per_sensor {
                let (snr, twin, cos, perp) = a[i];
                let twin = FAULTS.get(twin).map_or("-", |f| f.0.split(' ').next().unwrap_or("-"));
                print!(" {snr:.0} \\| {twin} \\| {cos:.4} \\| {perp:.1} |");
            }
            println!();
        }
    }

    // Over all designs: the median snr, and the share of designs where the
    // fault is seen (snr >= 5) and separable from every other fault
    // (snr_perp >= 5 against its nearest twin).
    println!(
        "\n{} designs (the two presets and {count} random, seed {seed}): median snr; seen (snr >= 5); separable (also snr_perp >= 5 against its twin)\n",
        designs.len()
    );
    print!("| fault |");
    for s in &SENSORS {
        print!(" {} |", s.0);
    }
    println!("\n|---|{}", "---|".repeat(SENSORS.len()));
    let all: Vec<Vec<Vec<Finding>>> = designs
        .iter()
        .map(|(_, raw)| {
            SENSORS
                .iter()
                .map(|s| analyse(&raw.core, raw.estimator.valid_min, raw.estimator.valid_max, s))
                .collect()
        })
        .collect();
    let n = designs.len() as f64;
    for (i, (fault, _)) in FAULTS.iter().enumerate() {
        print!("| {fault} |");
        for s in 0..SENSORS.len() {
            let mut snr: Vec<f64> = all.iter().map(|d| d[s][i].0).collect();
            snr.sort_by(f64::total_cmp);
            let seen = all.iter().filter(|d| d[s][i].0 >= 5.0).count() as f64;
            let sep = all.iter().filter(|d| d[s][i].0 >= 5.0 && d[s][i].3 >= 5.0).count() as f64;
            print!(
                " {:.0} \\| {:.0} % \\| {:.0} % |",
                snr[snr.len() / 2],
                100.0 * seen / n,
                100.0 * sep / n
            );
        }
        println!();
    }
}
