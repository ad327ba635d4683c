//! A faulted history of one seeded device, as the condition monitor's
//! fault-injection campaign receives it (`host_tests::campaign`,
//! `docs/monitoring.md`, "Fault-injection data").
//!
//!     cargo run --release -p host-tests --example campaign_data -- [design] [fault] [sensor] [hours] [every_s]
//!
//! * `design`: `paper` (the paper preset) or a seed (a random design whose
//!   plunger travels over its range, `host_tests::campaign::design`); the
//!   same seed draws the as-built device, the history, the sensors'
//!   offsets and noises. Default 1.
//! * `fault`: `name:severity` (`capillary:0.8`, `orifice-worn:1.2`,
//!   `orifice-clogged:0.8`, `spring:0.9`, `preload:0.8`, `sticking:0.05`,
//!   `sensor-offset:0.005`) or `none`. Default `capillary:0.8`. Its onset:
//!   ten minutes after the warm-up reaches the working temperature (or
//!   half-way through a shorter run).
//! * `sensor`: `p_a`, `p_b`, `dp_ab` or `x`. Default `x`.
//! * `hours`: the history's length (24: the day a false-alarm count runs
//!   through). Default 2.
//! * `every_s`: one printed row every so many seconds (and the rows around
//!   the onset). Default 300.
//!
//! Each row: the time, the oil's true temperature, the probe's last
//! reading, the estimator's oil temperature, the true value of the
//! sensor's quantity, the reading, the residual against the estimator's
//! twin of the nominal design (what a monitor would test), and whether the
//! fault is present. At the end, the residual's statistics before and
//! after the onset.

use clap::Parser;
use host_tests::campaign::{Fault, Injection, Quantity, Scenario, design, onset_after_warm_up};
use std::time::Instant;

/// A faulted history of one seeded device, as the condition monitor's
/// fault-injection campaign receives it.
#[derive(Parser)]
struct Args {
    /// `paper` (the paper preset) or the seed of a random design, its
    /// as-built device, history and sensor.
    #[arg(value_name = "design", default_value = "1", value_parser = parse_design)]
    design: Design,
    /// `name:severity` (capillary, orifice-worn, orifice-clogged, spring,
    /// preload, sticking, sensor-offset) or `none`.
    #[arg(value_name = "fault", default_value = "capillary:0.8", value_parser = Fault::parse)]
    fault: Fault,
    /// The second sensor's quantity.
    #[arg(value_name = "sensor", default_value = "x", value_parser = sensor_parser())]
    sensor: Quantity,
    /// The history's length [hours].
    #[arg(value_name = "hours", default_value_t = 2.0)]
    hours: f64,
    /// One printed row every so many seconds [s] (and the rows around the
    /// onset).
    #[arg(value_name = "every_s", default_value_t = 300.0)]
    every_s: f64,
}

/// The paper preset, or a random design by its seed.
#[derive(Clone, Copy)]
enum Design {
    Paper,
    Seed(u64),
}

fn parse_design(s: &str) -> Result<Design, String> {
    if s == "paper" {
        return Ok(Design::Paper);
    }
    s.parse()
        .map(Design::Seed)
        .map_err(|_| format!("`{s}`: a design is `paper` or a seed"))
}

/// The second sensor's quantities, by name (`p_a`, `p_b`, `dp_ab`, `x`).
fn sensor_parser() -> impl clap::builder::TypedValueParser<Value = Quantity> {
    use clap::builder::{PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(Quantity::ALL.map(Quantity::name))
        .try_map(|name| Quantity::parse(&name).ok_or("unknown sensor"))
}

fn main() -> Result<(), String> {
    let args = Args::parse();
    let (raw, seed, name) = match args.design {
        Design::Paper => {
            let raw = compensator_cli::load(&host_tests::repo_root().join("presets/paper.toml"))
                .map_err(|e| e.to_string())?;
            (raw, 1, "the paper preset".to_string())
        }
        Design::Seed(seed) => (design(seed), seed, format!("random design {seed}")),
    };
    let (fault, quantity, hours, every) = (args.fault, args.sensor, args.hours, args.every_s);
    let duration = hours * 3600.0;

    // The history first, for the onset after its warm-up.
    let mut s = Scenario::ordinary(&raw, quantity, Injection::HEALTHY, duration, seed);
    let warm = s.profile.warmed_up();
    let onset = onset_after_warm_up(&s.profile, duration);
    s.injection = Injection { fault, onset };

    let (lo, hi) = s.profile.extent();
    let c = &s.nominal.core;
    let d = &s.device;
    println!(
        "{name}: validated {}-{} C; as built: capillary bore {:+.2} %, orifice bore {:+.2} %, spring rate {:+.2} %, preload {:+.2} %",
        raw.estimator.valid_min,
        raw.estimator.valid_max,
        100.0 * (d.laminar_diameter / c.laminar_diameter - 1.0),
        100.0 * (d.turbulent_diameter / c.turbulent_diameter - 1.0),
        100.0 * (d.spring_rate / c.spring_rate - 1.0),
        100.0 * (d.preload / c.preload - 1.0),
    );
    println!(
        "history: {:.1} h, {:.1}..{:.1} C, {} knots, warm-up done at {:.0} s, fastest {:.2} C/s; probe {:+.2} of its tolerance",
        hours,
        lo,
        hi,
        s.profile.knots().len(),
        warm,
        s.profile.max_rate(),
        s.probe_class
    );
    let unit = quantity.unit();
    println!(
        "sensor {} over {:.4e}..{:.4e} {unit}, noise {:.3e} {unit}, offset {:+.3e} {unit}, {} Hz; fault {fault} from {onset:.0} s\n",
        quantity.name(),
        s.sensor.span.0,
        s.sensor.span.1,
        s.sensor.noise_sd,
        s.sensor_offset,
        s.sensor.rate_hz
    );
    println!(
        "{:>9} {:>8} {:>8} {:>8} {:>13} {:>13} {:>11} {:>6}",
        "t_s", "t_oil", "probe", "t_est", "truth", "reading", "residual", "fault"
    );

    let twin = |e: &compensator::estimator::StateEstimate| -> f64 {
        f64::from(match quantity {
            Quantity::PA => e.p_a,
            Quantity::PB => e.p_b,
            Quantity::DPAB => e.p_b - e.p_a,
            Quantity::X => e.x,
        })
    };
    // Residual sums before and after the onset: count, sum, sum of squares, max |r|.
    let mut stats = [(0u64, 0.0f64, 0.0f64, 0.0f64); 2];
    let started = Instant::now();
    let mut next_row = 0.0;
    for o in s.estimated()? {
        let r = o.second - twin(&o.estimate);
        let near_onset = fault != Fault::None && (o.t - onset).abs() <= 2.0 && (o.t * 2.0).fract() == 0.0;
        if o.t >= next_row || near_onset {
            println!(
                "{:>9.2} {:>8.3} {:>8.3} {:>8.3} {:>13.6e} {:>13.6e} {:>+11.3e} {:>6}",
                o.t,
                o.t_true,
                o.estimate.t_probe,
                o.t_estimated,
                o.truth.value(quantity),
                o.second,
                r,
                if o.fault_active { "yes" } else { "no" }
            );
            if o.t >= next_row {
                next_row += every;
            }
        }
        // Residuals once the estimator has started (a minute).
        if o.t >= 60.0 {
            let st = &mut stats[usize::from(o.fault_active)];
            *st = (st.0 + 1, st.1 + r, st.2 + r * r, st.3.max(r.abs()));
        }
    }
    println!("\n{:.1} s of wall time", started.elapsed().as_secs_f64());
    for (i, what) in ["healthy", "faulty"].iter().enumerate() {
        let (n, sum, sq, max) = stats[i];
        if n == 0 {
            continue;
        }
        let mean = sum / n as f64;
        let sd = (sq / n as f64 - mean * mean).max(0.0).sqrt();
        println!(
            "residual {what}: {n} readings, mean {mean:+.3e} {unit}, sd {sd:.3e} {unit}, max |r| {max:.3e} {unit} ({:.1} sensor noise sd)",
            max / s.sensor.noise_sd
        );
    }
    Ok(())
}
