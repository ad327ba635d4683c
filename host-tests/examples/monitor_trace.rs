//! One campaign run's monitor, traced: per second-sensor reading (thinned to
//! one row every `every` seconds, and every reading within 5 s of an alarm)
//! the true and the estimated oil temperature, the reading, the monitor's
//! prediction, its standardised innovation, CUSUM, health parameters and
//! flags.
//!
//!     cargo run --release -p host-tests --example monitor_trace -- [design] [seed] [hours] [sensor] [fault] [every]
//!
//! `TRACE_FROM` and `TRACE_TO` (seconds) print only that window, every
//! reading in it with `every` 0; the trace ends 5 s after the first alarm
//! (with `TRACE_RESET=1` the monitor is reset after each alarm, as in the
//! campaign's healthy runs, and the trace goes on, a `#` line per alarm;
//! with `TRACE_ALL=1` it goes on without a reset). `TRACE_GAINS=1` adds
//! the isolation's gains per hypothesis (`Monitor::isolation`: capillary,
//! clogged, spring, offset up, offset down, sticking), its margin and span.
//! `design` 0 is the paper preset (the campaign's onset, `monitor_campaign`'s), `n` the seeded `host_tests::campaign::design(seed * 1000 + n - 1)`.
use host_tests::campaign::{Fault, Injection, Quantity, Scenario, catalogue_before_move, design};
use host_tests::monitor_campaign::{ALARMS, Replay};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let d: u64 = args.first().and_then(|a| a.parse().ok()).unwrap_or(0);
    let seed: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1);
    let hours: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1.5);
    let q = args.get(3).and_then(|s| Quantity::parse(s)).unwrap_or(Quantity::PA);
    let fault = args.get(4).map_or(Ok(Fault::None), |s| Fault::parse(s)).expect("fault");
    let every: f64 = args.get(5).and_then(|a| a.parse().ok()).unwrap_or(10.0);
    let root = host_tests::repo_root();
    let nominal = if d == 0 {
        compensator_cli::load(&root.join("presets/paper.toml")).expect("paper preset")
    } else {
        design(seed.wrapping_mul(1000) + d - 1)
    };
    let lead = ((seed * 7 + d) % 21) as f64;
    let base = &catalogue_before_move(&nominal, q, hours * 3600.0, seed + d, lead)[0];
    let mut s = Scenario {
        injection: Injection {
            fault,
            onset: base.injection.onset,
        },
        ..base.clone()
    };
    if std::env::var("NO_CLASS").is_ok() {
        s.probe_class = 0.0;
    }
    if std::env::var("NO_OFFSET").is_ok() {
        s.sensor_offset = 0.0;
    }
    if std::env::var("NO_SPREAD").is_ok() {
        s.device = s.nominal.core;
    }
    println!(
        "probe class {:.3}, sensor offset {:.4e}, onset {:.0} s",
        s.probe_class, s.sensor_offset, s.injection.onset
    );
    let mut replay = Replay::new(&s).unwrap();
    // `TRACE_FROM` / `TRACE_TO` [s]: print only that window (every reading
    // in it with `every` 0).
    let from: f64 = std::env::var("TRACE_FROM")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    let to: f64 = std::env::var("TRACE_TO")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::INFINITY);
    let mut last_row = -1e9;
    let mut last_alarm = -1e9;
    let mut first_alarm = f64::INFINITY;
    // `TRACE_RESET=1`: reset the monitor after each alarm and go on, as the
    // campaign's healthy runs do, printing a `#` line per alarm.
    let keep_on = std::env::var("TRACE_RESET").is_ok_and(|v| v == "1");
    // `TRACE_ALL=1`: go on past the first alarm without a reset, to `TRACE_TO`.
    let all = std::env::var("TRACE_ALL").is_ok_and(|v| v == "1");
    // `TRACE_GAINS=1`: each row also gives the isolation's gains (in
    // `Hypothesis::ALL`'s order), its margin and the run's span [K].
    let gains = std::env::var("TRACE_GAINS").is_ok_and(|v| v == "1");
    println!("t T_true T_est dT T_s y pred truth twin z cusum divider sd_div bias offset flags");
    while let Some((r, e)) = replay.next_fed() {
        let est = &mut replay.estimator;
        if r.second.is_none() {
            continue;
        }
        let h = est.health();
        let alarm = e.flags.0 & ALARMS.0 != 0;
        if alarm {
            last_alarm = r.t;
            first_alarm = first_alarm.min(r.t);
        }
        if r.t > to {
            break;
        }
        if r.t >= from && (r.t - last_row >= every || (!all && r.t - last_alarm < 5.0)) {
            last_row = r.t;
            println!(
                "{:.2} {:.3} {:.3} {:.3} {:.3} {:.6e} {:.6e} {:.6e} {:.4e} {:.2} {:.2} {:.4} {:.4} {:.4} {:.3e} {:08x}",
                r.t,
                r.t_true,
                e.temperature,
                f64::from(e.temperature) - r.t_true,
                h.oil,
                r.second.unwrap(),
                h.predicted,
                r.truth.value(q),
                e.x,
                h.innovation,
                h.cusum,
                h.divider,
                h.sd_divider,
                h.probe_bias,
                h.offset,
                e.flags.0
            );
            if let (true, Some(m)) = (gains, est.monitor()) {
                let iso = m.isolation();
                println!(
                    "  gains {:?} margin {:.1} span {:.2}",
                    iso.gain.map(|g| (g * 10.0).round() / 10.0),
                    iso.margin,
                    iso.span
                );
            }
        }
        if alarm && keep_on {
            println!(
                "# alarm at {:.2} s, oil {:.3} C, flags {:08x}, offset {:.3e}, divider {:.4}",
                r.t, r.t_true, e.flags.0, h.offset, h.divider
            );
            est.reset_monitor();
        } else if alarm && !all && r.t - first_alarm > 4.9 {
            break;
        }
    }
}
