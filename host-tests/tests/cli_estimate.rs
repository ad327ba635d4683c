//! `compensator estimate` against independent references: a board's
//! telemetry CSV (what `cargo xtask flash --csv` writes) replayed through
//! its `t_probe_c` column gives back the firmware's estimates; a steady
//! log's estimate is the reference crate's equilibrium (`reference/`,
//! bisection on each chamber's flow balance, no code shared with the core)
//! within the estimate's own band; the documented probe log is what the
//! simulated board writes.

use compensator_reference::statics::equilibrium;
use host_tests::board::{self, ROUND_TRIP, WARM_UP, WARM_UP_LOG};
use host_tests::{repo_root, run_cli};

const P: &str = "presets/paper.toml";

fn paper() -> compensator::params::RawParams {
    compensator_cli::load(&repo_root().join(P)).unwrap()
}

/// A CSV's rows as maps from the header's names to numbers (`flags` kept
/// as text in its own vector).
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn parse(text: &str) -> Table {
        let mut lines = text.lines().filter(|l| !l.is_empty() && !l.starts_with('#'));
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines.map(|l| l.split(',').map(String::from).collect()).collect();
        Table { header, rows }
    }

    fn index(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}: {:?}", self.header))
    }

    fn column(&self, name: &str) -> Vec<f64> {
        let i = self.index(name);
        self.rows.iter().map(|r| r[i].parse().unwrap()).collect()
    }

    fn text(&self, name: &str) -> Vec<String> {
        let i = self.index(name);
        self.rows.iter().map(|r| r[i].clone()).collect()
    }
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-cli-estimate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn the_documented_probe_log_is_what_the_simulated_board_writes() {
    let written = board::warm_up_log(&paper()).unwrap();
    let committed = std::fs::read_to_string(repo_root().join(WARM_UP_LOG)).unwrap();
    assert!(
        written == committed,
        "{WARM_UP_LOG} is stale: cargo run -p host-tests --example probe_log"
    );
}

/// The round trip: a board (the firmware's driver and `f32` estimator at
/// 1 kHz, readings every 20 ms through the lagging, noisy probe of the
/// paper preset) over 320 s of holds, ramps and a 10 C step; its telemetry
/// (2 Hz) as the CSV `cargo xtask flash --csv` decodes it to; that CSV
/// replayed by `compensator estimate --every-sample`, whose observer then
/// reads the telemetry's `t_probe_c` (the last accepted reading) every
/// 0.5 s, 25 times fewer readings than the firmware's. Stated tolerance:
/// every row's oil temperature and plunger displacement within the two
/// estimates' combined 95 % band (`1.96 sqrt(sd_fw^2 + sd_replay^2)`),
/// but in the second after the step (faster than any oil moves: the
/// replay's first reading after it comes up to 0.5 s after the
/// firmware's); and once the probe has settled in a hold (its last 30 s,
/// five probe time constants) within 0.1 C (five times the probe's noise,
/// 0.02 C) and 0.5 % of the stroke of the firmware's; no fault flag.
#[test]
fn a_boards_telemetry_csv_replays_to_the_firmwares_estimates() {
    let raw = paper();
    let run = board::run(&raw, &ROUND_TRIP, false, 7).unwrap();
    let csv = board::telemetry_csv(&run.telemetry);
    let path = temp("round-trip.csv");
    std::fs::write(&path, &csv).unwrap();
    let (code, out, err) = run_cli(&[
        "estimate",
        "--params",
        P,
        "--sensor-data",
        path.to_str().unwrap(),
        "--every-sample",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("(t_probe_c)") && err.contains("one every 500 ms"), "{err}");
    let (fw, replay) = (Table::parse(&csv), Table::parse(&out));
    assert_eq!(replay.rows.len(), fw.rows.len());
    assert!(fw.rows.len() >= 600, "{} telemetry rows", fw.rows.len());
    let (t_fw, t_re) = (fw.column("time_s"), replay.column("time_s"));
    for (a, b) in t_fw.iter().zip(&t_re) {
        assert!((a - b).abs() < 1e-9, "time {b} against {a}");
    }
    assert_eq!(fw.column("t_probe_c"), replay.column("t_probe_c"));
    // The profile's steps (a piece that starts where the last did not end).
    let steps: Vec<f64> = ROUND_TRIP
        .windows(2)
        .filter(|w| w[0].3 != w[1].2)
        .map(|w| w[1].0)
        .collect();
    assert_eq!(steps, [160.0]);
    let after_step = |t: f64| steps.iter().any(|&s| t >= s && t < s + 1.0);
    let settled = |t: f64| {
        ROUND_TRIP
            .iter()
            .any(|&(_, t1, from, to)| from == to && t >= t1 - 30.0 && t < t1)
    };
    let mut summary = Vec::new();
    for (value, sd, hold_tol) in [
        ("t_oil_c", "t_oil_sd_c", 0.1),
        ("x_m", "x_sd_m", 0.005 * raw.core.stroke),
    ] {
        let (a, sa, b, sb) = (fw.column(value), fw.column(sd), replay.column(value), replay.column(sd));
        let (mut worst_band, mut worst_settled) = (0.0f64, 0.0f64);
        for i in 0..a.len() {
            let (t, d) = (t_fw[i], (a[i] - b[i]).abs());
            let band = 1.96 * sa[i].hypot(sb[i]);
            if !after_step(t) {
                assert!(
                    d <= band,
                    "t = {t} s, {value}: replay {} against the firmware's {} (band {band})",
                    b[i],
                    a[i]
                );
                worst_band = worst_band.max(d / band);
            }
            if settled(t) {
                assert!(
                    d <= hold_tol,
                    "t = {t} s (settled), {value}: replay {} against the firmware's {}",
                    b[i],
                    a[i]
                );
                worst_settled = worst_settled.max(d);
            }
        }
        summary.push(format!(
            "{value}: worst {:.2} of the band, settled within {worst_settled:.3e}",
            worst_band
        ));
    }
    for flags in replay.text("flags") {
        assert!(
            !flags.contains("SENSOR_FAULT") && !flags.contains("DEGRADED") && !flags.contains("SPIKE"),
            "{flags}"
        );
    }
    println!("round trip of {} telemetry rows: {}", fw.rows.len(), summary.join("; "));
    let _ = std::fs::remove_file(&path);
}

/// The documented log ends with a minute's hold of the oil at 60 C (ten
/// probe time constants): its last estimate is the oil's temperature and
/// the reference crate's equilibrium there, each within its reported 95 %
/// band (1.96 sd), the model's quantities within a tenth of their sd.
#[test]
fn a_steady_log_estimates_the_reference_equilibrium_within_its_band() {
    let raw = paper();
    let (code, out, err) = run_cli(&["estimate", "--params", P, "--sensor-data", WARM_UP_LOG]);
    assert_eq!(code, 0, "{err}");
    let table = Table::parse(&out);
    let last = table.rows.len() - 1;
    let get = |name: &str| table.column(name)[last];
    let oil = WARM_UP.last().unwrap().3;
    assert!(get("time_s") > 119.0, "{}", get("time_s"));
    let t = get("t_oil_c");
    assert!((t - oil).abs() <= 1.96 * get("t_oil_sd_c"), "t_oil {t} against {oil}");
    let reference = equilibrium(&raw.core, oil);
    for (name, sd, expected) in [
        ("x_m", "x_sd_m", reference.x),
        ("p_a_pa", "p_a_sd_pa", reference.p_a),
        ("p_b_pa", "p_b_sd_pa", reference.p_b),
        ("q_total_m3s", "q_total_sd_m3s", reference.q_total),
    ] {
        let (v, s) = (get(name), get(sd));
        println!(
            "{name}: {v} against the reference's {expected}: {:.2} sd",
            (v - expected) / s
        );
        assert!(s > 0.0 && s < 0.2 * expected.abs(), "{name}: sd {s} against {expected}");
        assert!(
            (v - expected).abs() <= 1.96 * s,
            "{name}: {v} against the reference's {expected} (sd {s})"
        );
        // Closer still: the settled estimate's error is its oil
        // temperature's (a few mC here), not the model's.
        assert!(
            (v - expected).abs() <= 0.1 * s,
            "{name}: {v} against the reference's {expected} (sd {s})"
        );
    }
    assert_eq!(table.text("flags")[last], "", "{}", table.rows[last].join(","));
}
