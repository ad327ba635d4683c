//! `compensator estimate` and `monitor` on second-sensor logs a field
//! logger writes and a new user hands them: a stuck transducer (the
//! firmware's driver flags it, so must the replay), a column with no
//! reading, a telemetry CSV given to `monitor`, the two sensors' readings
//! on rows of their own within one tick, a single reading of the second
//! sensor. Each either flagged as the firmware flags it or refused in one
//! line that names the column and says what to do. And a second sensor
//! that stopped reporting for a while, told with its column and rows,
//! beside one slower than the probe, whose empty cells are its rate.

use host_tests::run_cli;
use std::path::{Path, PathBuf};

const PARAMS: &str = "presets/paper-monitor.toml";

/// The first `rows` rows of the documented log (`docs/monitoring.md`):
/// the probe every 20 ms, the chamber (a) transducer every 10 ms.
fn documented(rows: usize) -> Vec<(String, String, String)> {
    let text = std::fs::read_to_string(host_tests::repo_root().join("data/logs/monitor-capillary.csv")).unwrap();
    text.lines()
        .skip(1)
        .take(rows)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[0].to_string(), c[1].to_string(), c[2].to_string())
        })
        .collect()
}

fn write(name: &str, header: &str, rows: &[(String, String, String)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-cli-monitor-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let mut text = format!("{header}\n");
    for (t, probe, second) in rows {
        text.push_str(&format!("{t},{probe},{second}\n"));
    }
    std::fs::write(&path, text).unwrap();
    path
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_stuck_transducer_is_flagged_as_the_firmware_s_driver_flags_it() {
    // 20 s at 60 C, the transducer stuck on one reading from the start:
    // the driver's check (37 equal codes for the preset's noise) flags it.
    let rows: Vec<_> = documented(2001)
        .into_iter()
        .map(|(t, probe, second)| {
            let stuck = if second.is_empty() {
                second
            } else {
                "84395.6".to_string()
            };
            (t, probe, stuck)
        })
        .collect();
    let log = write("stuck.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, out, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    let flags: Vec<&str> = out.lines().skip(1).map(|l| l.split(',').next().unwrap()).collect();
    assert_eq!(flags, ["SECOND_SENSOR_FAULT"], "{out}");
    // Raised on the 37th reading (row 37, 0.36 s), not before.
    let first: Vec<&str> = out.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(first[1], "37", "{out}");
    // The healthy readings of the same log raise nothing.
    let log = write("healthy.csv", "time_s,t_c,p_a_pa", &documented(2001));
    let (code, out, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 1, "{out}");
}

#[test]
fn monitor_refuses_a_column_without_a_reading() {
    let rows: Vec<_> = documented(2001)
        .into_iter()
        .filter(|r| !r.1.is_empty())
        .map(|(t, probe, _)| (t, probe, String::new()))
        .collect();
    let log = write("empty-column.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("column p_a_pa: no reading in any row"), "{err}");
    assert!(!err.contains("NaN"), "{err}");
}

#[test]
fn one_reading_of_the_second_sensor_takes_the_file_s_period() {
    // No interval to take the median of: the file's monitor.sample_hz
    // (100 Hz), not one tick.
    let rows: Vec<_> = documented(2001)
        .into_iter()
        .filter(|r| !r.1.is_empty())
        .enumerate()
        .map(|(i, (t, probe, second))| (t, probe, if i == 100 { second } else { String::new() }))
        .collect();
    let log = write("one-reading.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("1 readings of the second sensor (p_a_pa), one every 10 ms"),
        "{err}"
    );
}

#[test]
fn monitor_on_a_telemetry_csv_says_its_pressures_are_estimates() {
    // A telemetry CSV has a p_a_pa column: the estimator's estimate.
    let rows: Vec<_> = (0..20)
        .map(|i| {
            (
                format!("{}", f64::from(i) * 0.5 + 0.499),
                "60.5,60.5".to_string(),
                "84000".to_string(),
            )
        })
        .collect();
    let log = write("telemetry.csv", "time_s,t_probe_c,t_oil_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("telemetry CSV"), "{err}");
    assert!(!err.contains("no column p_a_pa"), "{err}");
}

#[test]
fn the_two_sensors_on_rows_of_their_own_within_a_tick_are_told_to_share_a_row() {
    // A logger writing each sensor's reading on its own row, 0.3 ms apart.
    let mut rows = Vec::new();
    for (t, probe, second) in documented(200) {
        if probe.is_empty() {
            rows.push((t, probe, second));
        } else {
            let later = format!("{:.4}", t.parse::<f64>().unwrap() + 3e-4);
            rows.push((t, probe, String::new()));
            rows.push((later, String::new(), second));
        }
    }
    let log = write("async.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("row 2 (line 3), column time_s"), "{err}");
    assert!(err.contains("merge rows 1 and 2"), "{err}");
}

#[test]
fn a_sensor_column_under_another_name_is_refused_naming_the_right_one() {
    // `p_a_bar` (or `P_A_PA`) was ignored as an unknown column: `estimate`
    // ran without the monitor, and with the probe's cells empty beside it
    // the error named an empty t_c cell.
    let rows = documented(400);
    for name in ["p_a_bar", "P_A_PA", "p_a"] {
        let log = write(&format!("{name}.csv"), &format!("time_s,t_c,{name}"), &rows);
        for command in ["estimate", "monitor"] {
            let (code, _, err) = run_cli(&[command, "--params", PARAMS, "--sensor-data", path(&log)]);
            assert_eq!(code, 2, "{command} {name}: {err}");
            assert!(
                err.contains(&format!("column {name}: ")) && err.contains("column p_a_pa"),
                "{command} {name}: {err}"
            );
        }
    }
    // A probe log beside the estimates' uncertainties is no sensor log.
    let probe: Vec<_> = rows
        .into_iter()
        .filter(|r| !r.1.is_empty())
        .map(|(t, probe, _)| (t, probe, "900".to_string()))
        .collect();
    // Nor is another quantity's column whose name starts as the sensor's.
    for name in ["p_a_sd_pa", "p_a_set_pa", "p_a_ref"] {
        let log = write(&format!("other-{name}.csv"), &format!("time_s,t_c,{name}"), &probe);
        let (code, _, err) = run_cli(&["estimate", "--params", PARAMS, "--sensor-data", path(&log)]);
        assert_eq!(code, 0, "{name}: {err}");
    }
}

/// An open loop for a tenth of a second in an otherwise healthy log (the
/// logger wrote what the ADC read, -25 kPa: below the 4-20 mA band): the
/// driver reports a level fault there, so the replay flags those readings
/// `SECOND_SENSOR_FAULT` and goes on, where it refused the whole log. The
/// rows of `estimate --every-sample` carry the flag, on the row after
/// each refused reading's tick, and the published rows (the telemetry's)
/// on the first after it.
#[test]
fn a_short_open_loop_is_flagged_not_refused() {
    let rows: Vec<_> = documented(2001)
        .into_iter()
        .enumerate()
        .map(|(i, (t, probe, second))| {
            let open = (1000..1010).contains(&i) && !second.is_empty();
            (t, probe, if open { "-25000".to_string() } else { second })
        })
        .collect();
    let log = write("open.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, out, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    let flags: Vec<Vec<&str>> = out.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(flags.len(), 1, "{out}");
    assert_eq!(flags[0][0], "SECOND_SENSOR_FAULT", "{out}");
    // The first refused reading is row 1000's, taken on the next job tick.
    assert!(["1000", "1001"].contains(&flags[0][1]), "{out}");
    for every in [true, false] {
        let mut args = vec!["estimate", "--params", PARAMS, "--sensor-data", path(&log)];
        if every {
            args.push("--every-sample");
        }
        let (code, out, err) = run_cli(&args);
        assert_eq!(code, 0, "{err}");
        let header: Vec<&str> = out.lines().next().unwrap().split(',').collect();
        let (t, f) = (
            header.iter().position(|h| *h == "time_s").unwrap(),
            header.iter().position(|h| *h == "flags").unwrap(),
        );
        let flagged: Vec<f64> = out
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|c| c[f].contains("SECOND_SENSOR_FAULT"))
            .map(|c| c[t].parse().unwrap())
            .collect();
        if every {
            // The ten refused readings' rows (10.00-10.09 s) and the next.
            assert!(
                flagged.len() >= 10 && flagged.iter().all(|t| (10.0..10.2).contains(t)),
                "--every-sample rows flagged at {flagged:?}"
            );
        } else {
            // The first telemetry row after 10.0 s (2 Hz) and no other.
            assert!(
                flagged.len() == 1 && (10.0..10.6).contains(&flagged[0]),
                "telemetry rows flagged at {flagged:?}"
            );
        }
    }
    // Most of the column outside the band is no sensor's fault: refused.
    let rows: Vec<_> = documented(2001)
        .into_iter()
        .map(|(t, probe, second)| (t, probe, if second.is_empty() { second } else { "-25000".into() }))
        .collect();
    let log = write("dead.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("column p_a_pa") && err.contains("of the column's"),
        "{err}"
    );
}

/// The documented log's first 20 s with the second sensor's reading kept
/// on every `every`-th row only (`every` 1: all of them, every 10 ms; 4:
/// every 40 ms, on every other probe row) and none from 10.00 s to 13.00
/// s when `silent`, the rows left with neither reading dropped (a row
/// holds at least one).
fn second_every(every: usize, silent: bool) -> Vec<(String, String, String)> {
    documented(2001)
        .into_iter()
        .enumerate()
        .map(|(i, (t, probe, second))| {
            let quiet = silent && (1000..1300).contains(&i);
            let kept = i % every == 0 && !quiet;
            (t, probe, if kept { second } else { String::new() })
        })
        .filter(|r| !r.1.is_empty() || !r.2.is_empty())
        .collect()
}

/// The first and last row (0-based) from `from` to `to` \[s\].
fn rows_within(rows: &[(String, String, String)], from: f64, to: f64) -> (usize, usize) {
    let t = |r: &(String, String, String)| r.0.parse::<f64>().unwrap();
    let first = rows.iter().position(|r| t(r) >= from - 1e-9).unwrap();
    let last = rows.iter().rposition(|r| t(r) <= to + 1e-9).unwrap();
    (first, last)
}

/// A chamber transducer that stopped reporting for 3 s in the middle of
/// the log (its column empty from 10.00 s to 12.99 s while the probe's
/// goes on) passed without a word: both commands now say how many
/// readings are missing and name the column and the stretch's rows.
#[test]
fn a_second_sensor_that_stopped_reporting_is_named_with_its_rows() {
    let rows = second_every(1, true);
    // Readings were due every 10 ms from 10.00 s to 12.99 s.
    let (first, last) = rows_within(&rows, 10.0, 12.99);
    // The probe's rows go on every 20 ms in the stretch: 150 of them.
    assert_eq!(last - first + 1, 150);
    let log = write("silent.csv", "time_s,t_c,p_a_pa", &rows);
    let stretch = format!(
        "column p_a_pa: no reading from row {} (line {}) to row {} (line {}): 3.01 s between the readings either \
         side, where the second sensor reads one every 10 ms; 300 readings missing",
        first + 1,
        first + 2,
        last + 1,
        last + 2
    );
    for command in ["monitor", "estimate"] {
        let (code, _, err) = run_cli(&[command, "--params", PARAMS, "--sensor-data", path(&log)]);
        assert_eq!(code, 0, "{command}: {err}");
        assert!(
            err.contains(
                "1701 readings of the second sensor (p_a_pa), one every 10 ms (the monitor's period), 300 missing"
            ),
            "{command}: {err}"
        );
        assert!(err.contains(&format!("{command}: {stretch}")), "{command}: {err}");
    }
    // Two stretches: the longer is named, both are counted. The readings
    // of 18.00 s and 18.01 s dropped, the latter's row with them (it has
    // no probe reading).
    let mut two = rows.clone();
    let (j, _) = rows_within(&two, 18.0, 18.0);
    assert!(!two[j].1.is_empty() && two[j + 1].1.is_empty(), "{:?}", &two[j..j + 2]);
    two[j].2 = String::new();
    two.remove(j + 1);
    let log = write("silent-twice.csv", "time_s,t_c,p_a_pa", &two);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(&stretch) && err.contains("(the longest of 2 stretches, 302 readings missing over the log)"),
        "{err}"
    );
}

/// A second sensor slower than the probe (a reading every 40 ms, on every
/// other probe row) leaves cells empty at its own rate: none of them is
/// missing. Stopped for 3 s, it misses the readings due at that rate.
#[test]
fn a_slower_second_sensor_s_empty_cells_are_not_missing_readings() {
    let rows = second_every(4, false);
    let log = write("slow.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("501 readings of the second sensor (p_a_pa), one every 40 ms (the monitor's period)"),
        "{err}"
    );
    assert!(!err.contains("missing") && !err.contains("no reading from"), "{err}");
    let rows = second_every(4, true);
    // Readings were due every 40 ms from 10.00 s to 12.96 s; the empty
    // cells at 9.98 s and 12.98 s are the sensor's own rate.
    let (first, last) = rows_within(&rows, 10.0, 12.96);
    let log = write("slow-silent.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    // 9.96 s to 13.00 s: the 75 readings due every 40 ms, not the
    // stretch's 151 empty cells.
    assert!(
        err.contains(&format!(
            "monitor: column p_a_pa: no reading from row {} (line {}) to row {} (line {}): 3.04 s between the \
             readings either side, where the second sensor reads one every 40 ms; 75 readings missing",
            first + 1,
            first + 2,
            last + 1,
            last + 2
        )) && err.contains("one every 40 ms (the monitor's period), 75 missing"),
        "{err}"
    );
}

/// The documented log's first 20 s with each of the transducer's readings
/// on a row of its own, stamped up to 3 ms early or late (a logger that
/// timestamps as it gets round to it: under half the sensor's 10 ms
/// period), none from 10.00 s to 12.99 s when `silent`.
fn second_jittered(silent: bool) -> Vec<(String, String, String)> {
    const JITTER_MS: [i64; 10] = [0, 0, -3, 3, 0, 0, 3, -3, 0, 0];
    let mut rows: Vec<(i64, String, String)> = Vec::new();
    for (i, (t, probe, second)) in documented(2001).into_iter().enumerate() {
        let ms = (t.parse::<f64>().unwrap() * 1000.0).round() as i64;
        if !probe.is_empty() {
            rows.push((ms, probe, String::new()));
        }
        if second.is_empty() || (silent && (1000..1300).contains(&i)) {
            continue;
        }
        let at = ms + JITTER_MS[i % 10];
        match rows.iter_mut().find(|r| r.0 == at) {
            Some(r) => r.2 = second,
            None => rows.push((at, String::new(), second)),
        }
    }
    rows.sort_by_key(|r| r.0);
    rows.into_iter()
        .map(|(ms, probe, second)| (format!("{:.3}", ms as f64 / 1000.0), probe, second))
        .collect()
}

/// A transducer whose readings are all there but stamped a few ms off its
/// 10 ms slots was said to miss dozens: a reading 3 ms early then one 3
/// ms late are 16 ms apart, past 1.5 periods, though neither is missing
/// (the next interval is that much shorter). The count now places the
/// slots either side of a long interval by the readings around them.
#[test]
fn a_second_sensor_s_jittered_timestamps_are_no_missing_readings() {
    let log = write("jittered.csv", "time_s,t_c,p_a_pa", &second_jittered(false));
    for command in ["monitor", "estimate"] {
        let (code, _, err) = run_cli(&[command, "--params", PARAMS, "--sensor-data", path(&log)]);
        assert_eq!(code, 0, "{command}: {err}");
        assert!(
            err.contains("2001 readings of the second sensor (p_a_pa), one every 10 ms (the monitor's period)"),
            "{command}: {err}"
        );
        assert!(
            !err.contains("missing") && !err.contains("no reading"),
            "{command}: {err}"
        );
    }
    // Silent for 3 s as well: the 300 readings due then, one stretch.
    let log = write("jittered-silent.csv", "time_s,t_c,p_a_pa", &second_jittered(true));
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "1701 readings of the second sensor (p_a_pa), one every 10 ms (the monitor's period), 300 missing"
        ) && err.contains("; 300 readings missing, the monitor ran without them\n"),
        "{err}"
    );
}

/// The documented log's first three probe rows at 0, 20 and 100 ms (the
/// interval 20 ms, then 80 ms), the transducer read on each.
fn three_readings() -> Vec<(String, String, String)> {
    let rows = documented(2001);
    [0usize, 2, 10].iter().map(|&i| rows[i].clone()).collect()
}

/// Three readings have two intervals, and the "median" of two was the
/// longer: a probe read at 0, 20 and 100 ms was taken as one every 80 ms,
/// and the transducer's period (the monitor's) as 80 ms where the file
/// says 10 ms. The probe's interval is now the shorter of the two middle
/// ones (a reading missing only lengthens one); a second sensor with
/// fewer than 8 intervals measures no period: the monitor takes the
/// device file's, and says so.
#[test]
fn a_handful_of_readings_measure_no_period() {
    let log = write("three.csv", "time_s,t_c,p_a_pa", &three_readings());
    for command in ["monitor", "estimate"] {
        let mut args = vec![command, "--params", PARAMS, "--sensor-data", path(&log)];
        if command == "estimate" {
            args.push("--every-sample");
        }
        let (code, _, err) = run_cli(&args);
        assert_eq!(code, 0, "{command}: {err}");
        assert!(
            err.contains(&format!(
                "{command}: 3 readings (t_c) over 0.1 s, one every 20 ms (the median interval"
            )),
            "{command}: {err}"
        );
        assert!(
            err.contains(
                "3 readings of the second sensor (p_a_pa), one every 10 ms (the monitor's period, the device file's: \
                 too few readings to measure one)"
            ),
            "{command}: {err}"
        );
        assert!(
            err.contains(&format!(
                "{command}: column p_a_pa: 3 readings, 2 intervals, 20 ms to 80 ms: fewer than the 8 intervals the \
                 second sensor's period is measured from; the monitor's period is the device file's, 10 ms \
                 (monitor.sample_hz = 100 Hz), and no reading is counted missing"
            )),
            "{command}: {err}"
        );
    }
    // Nine readings, eight intervals, one every 40 ms: measured.
    let rows: Vec<_> = second_every(4, false).into_iter().take(17).collect();
    assert_eq!(rows.iter().filter(|r| !r.2.is_empty()).count(), 9);
    let log = write("nine.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("9 readings of the second sensor (p_a_pa), one every 40 ms (the monitor's period)\n"),
        "{err}"
    );
}

/// The documented log's first 20 s with the transducer read every 100 ms
/// up to 10.00 s and every 1 s from there (`slow_first`: every 1 s up to
/// 10.00 s, every 100 ms from there), without its reading of 15.00 s when
/// `dropped`; the rows left with neither reading dropped.
fn second_rate_change(slow_first: bool, dropped: bool) -> Vec<(String, String, String)> {
    documented(2001)
        .into_iter()
        .enumerate()
        .map(|(i, (t, probe, second))| {
            let every = if (i < 1000) != slow_first { 10 } else { 100 };
            let kept = i % every == 0 && !(dropped && i == 1500);
            (t, probe, if kept { second } else { String::new() })
        })
        .filter(|r| !r.1.is_empty() || !r.2.is_empty())
        .collect()
}

/// A transducer read at 10 Hz for 10 s, then at 1 Hz (or the reverse),
/// had one median interval for the log, 100 ms, and each of its 1 s
/// intervals counted as nine readings missing: 90 over 10 stretches,
/// where none was. The change of rate is now found (a local median of
/// the intervals around each that lasts 8 or more), told with its row,
/// and each stretch's missing readings are counted at its own interval.
#[test]
fn a_second_sensor_that_changed_its_rate_misses_no_reading() {
    let rows = second_rate_change(false, false);
    assert_eq!(rows.iter().filter(|r| !r.2.is_empty()).count(), 111);
    let (at, _) = rows_within(&rows, 10.0, 10.0);
    let (last, _) = rows_within(&rows, 20.0, 20.0);
    assert_eq!((at, last), (500, 1000));
    let log = write("rate-change.csv", "time_s,t_c,p_a_pa", &rows);
    for command in ["monitor", "estimate"] {
        let (code, _, err) = run_cli(&[command, "--params", PARAMS, "--sensor-data", path(&log)]);
        assert_eq!(code, 0, "{command}: {err}");
        // No count of missing readings after the change, nor a stretch
        // without one.
        let next = if command == "monitor" { "\n" } else { "; " };
        assert!(
            err.contains(&format!(
                "111 readings of the second sensor (p_a_pa), one every 100 ms (the monitor's period), 1 change of \
                 rate{next}"
            )),
            "{command}: {err}"
        );
        assert!(!err.contains("no reading"), "{command}: {err}");
        assert!(
            err.contains(&format!(
                "{command}: column p_a_pa: the second sensor's interval changed from 100 ms to 1 s at row 501 (line \
                 502, 10 s): one reading every 1 s from there to row 1001 (line 1002, 20 s), 10 intervals; a change \
                 of its rate, not readings missing"
            )),
            "{command}: {err}"
        );
        assert!(
            err.contains(&format!(
                "{command}: column p_a_pa: the monitor's period is 100 ms, the interval of its stretch with the most \
                 readings (100 intervals of the column's 110, row 1 (line 2, 0 s) to row 501 (line 502, 10 s))"
            )),
            "{command}: {err}"
        );
    }
    // The reverse: 1 s, then 100 ms.
    let log = write(
        "rate-change-reverse.csv",
        "time_s,t_c,p_a_pa",
        &second_rate_change(true, false),
    );
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "111 readings of the second sensor (p_a_pa), one every 100 ms (the monitor's period), 1 change of rate\n"
        ) && err.contains(
            "monitor: column p_a_pa: the second sensor's interval changed from 1 s to 100 ms at row 501 (line 502, 10 \
             s): one reading every 100 ms from there to row 1001 (line 1002, 20 s), 100 intervals"
        ) && err.contains("the monitor's period is 100 ms, the interval of its stretch with the most readings (100 intervals of the column's 110, row 501 (line 502, 10 s) to row 1001 (line 1002, 20 s))"),
        "{err}"
    );
    // The slower stretch's reading of 15.00 s dropped: 1 missing at its
    // 1 s, due on the rows more than 0.5 s from 14 s and 16 s.
    let rows = second_rate_change(false, true);
    let (first, last) = rows_within(&rows, 14.52, 15.48);
    assert_eq!((first, last), (726, 774));
    let log = write("rate-change-dropped.csv", "time_s,t_c,p_a_pa", &rows);
    let (code, _, err) = run_cli(&["monitor", "--params", PARAMS, "--sensor-data", path(&log)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "110 readings of the second sensor (p_a_pa), one every 100 ms (the monitor's period), 1 change of rate, 1 \
             missing"
        ) && err.contains(
            "monitor: column p_a_pa: no reading from row 727 (line 728) to row 775 (line 776): 2 s between the \
             readings either side, where the second sensor reads one every 1 s; 1 reading missing, the monitor ran \
             without them\n"
        ) && err.contains("one reading every 1 s from there to row 1001 (line 1002, 20 s), 9 intervals"),
        "{err}"
    );
}
