//! The binary's output contract: help, built-in data, output formats and
//! files, parameters from standard input, a closed pipe, and parameter
//! files that are not regular files.

use std::io::Read;
use std::process::{Command, Stdio};

mod common;
use common::{cli, root, run, run_in};

const COMMANDS: [&str; 18] = [
    "equilibrium",
    "asymptotic",
    "sensitivity",
    "step",
    "twin-config",
    "eigen",
    "indicators",
    "compensation",
    "size",
    "calibrate",
    "identify",
    "estimate",
    "monitor",
    "paper",
    "report",
    "sweep",
    "completions",
    "man",
];

#[test]
fn every_option_is_described_and_long_help_has_columns_and_an_example() {
    for command in COMMANDS {
        let (code, out, err) = run(&[command, "--help"]);
        assert_eq!(code, 0, "{command}: {err}");
        assert!(out.contains("Example:\n  compensator "), "{command}: {out}");
        assert!(out.contains("Output:"), "{command}: {out}");
        // Every option line is followed by a description line.
        let lines: Vec<&str> = out.lines().take_while(|l| !l.starts_with("Output:")).collect();
        for (i, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            if t.starts_with("--") || (t.starts_with('-') && t.chars().nth(1).is_some_and(char::is_alphabetic)) {
                let next = lines.get(i + 1).map_or("", |l| l.trim());
                assert!(!next.is_empty(), "{command}: option without a description: {line}");
            }
        }
    }
    let (_, out, _) = run(&["step", "--help"]);
    for column in ["time_s [s]", "x_m [m]", "v_m_s [m/s]", "p_a_pa [Pa]"] {
        assert!(out.contains(column), "{out}");
    }
}

#[test]
fn calibrate_and_paper_work_from_any_directory() {
    let dir = std::env::temp_dir();
    let (code, out, err) = run_in(&dir, &["paper"], b"");
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("## Table 1"), "{out}");
    let (code_root, out_root, _) = run(&["paper", "--params", "presets/paper.toml", "--data", "data/paper"]);
    assert_eq!(code_root, 0);
    assert_eq!(out, out_root, "the built-in copies are the repository's");
    let (code, out, err) = run_in(&dir, &["calibrate"], b"");
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("plunger.spring_rate"), "{out}");
    let (_, out_root, _) = run(&[
        "calibrate",
        "--base",
        "presets/model-example.toml",
        "--pressure-data",
        "data/calibration/paper-pressure.csv",
        "--displacement-data",
        "data/calibration/paper-displacement.csv",
    ]);
    assert_eq!(out, out_root);
    // The overrides still apply.
    let (code, _, err) = run_in(&dir, &["paper", "--data", "/nonexistent"], b"");
    assert_eq!(code, 2);
    assert!(err.contains("/nonexistent"), "{err}");
}

#[test]
fn json_parses_and_has_the_columns_in_order() {
    let (code, out, err) = run(&[
        "equilibrium",
        "--params",
        "presets/paper.toml",
        "--temps",
        "30,40,50",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let rows = v.as_array().unwrap();
    assert_eq!(rows.len(), 3);
    let (_, csv, _) = run(&["equilibrium", "--params", "presets/paper.toml", "--temps", "30,40,50"]);
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let mut lines = csv.lines().skip(1);
    for row in rows {
        let obj = row.as_object().unwrap();
        assert_eq!(obj.len(), header.len());
        for (h, c) in header.iter().zip(lines.next().unwrap().split(',')) {
            match c.parse::<f64>() {
                Ok(x) => assert_eq!(obj[*h].as_f64().unwrap(), x, "{h}"),
                // Words stay strings; an empty cell (no error) is null.
                Err(_) if c.is_empty() => assert!(obj[*h].is_null(), "{h}"),
                Err(_) => assert_eq!(obj[*h].as_str(), Some(c), "{h}"),
            }
        }
    }
    // Columns in the header's order.
    let first = out.lines().nth(1).unwrap();
    let pos: Vec<usize> = header
        .iter()
        .map(|h| first.find(&format!("\"{h}\"")).unwrap())
        .collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "{first}");
    // Strings and booleans stay what they are.
    let (code, out, _) = run(&["twin-config", "--params", "presets/paper.toml", "--format", "json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v[0]["scheme"].is_string());
    assert!(v[0]["goal_met"].is_boolean());
    assert_eq!(v[0]["substeps"].as_u64(), Some(1));
}

#[test]
fn table_aligns_columns() {
    let (code, out, err) = run(&[
        "eigen",
        "--params",
        "presets/paper.toml",
        "--temps",
        "30,40",
        "--format",
        "table",
    ]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3);
    // Rows end where the header's last filled column ends (the empty
    // error cells are not padded).
    assert!(lines[1..].iter().all(|l| l.len() == lines[1].len()), "{out}");
    assert!(
        lines[0].find("envelope").map(|i| i + "envelope".len()) == Some(lines[1].len()),
        "{out}"
    );
    assert!(lines[0].trim_start().starts_with("t_c"));
    assert!(!out.contains(','));
}

#[test]
fn format_does_not_apply_to_toml_or_text() {
    let (code, out, err) = run(&[
        "size",
        "--params",
        "presets/paper.toml",
        "--for",
        "slot",
        "--format",
        "json",
    ]);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert!(err.contains("--format"), "{err}");
}

#[test]
fn output_file_holds_what_stdout_would() {
    let path = std::env::temp_dir().join(format!("compensator-out-{}.csv", std::process::id()));
    let file = path.to_str().unwrap();
    let args = ["eigen", "--params", "presets/paper.toml", "--temps", "40"];
    let (code, out, err) = run(&[&args[..], &["-o", file]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(out.is_empty());
    let (_, expected, _) = run(&args);
    assert_eq!(std::fs::read_to_string(&path).unwrap(), expected);
    std::fs::remove_file(&path).unwrap();
    let (code, _, err) = run(&[&args[..], &["-o", "/nonexistent/dir/x.csv"]].concat());
    assert_eq!(code, 2);
    assert!(err.contains("--output"), "{err}");
}

#[test]
fn params_from_stdin_equal_the_file() {
    let preset = std::fs::read(root().join("presets/paper.toml")).unwrap();
    for args in [
        &["equilibrium", "--temps", "30:80:10"][..],
        &["twin-config"][..],
        &["step", "--from", "40", "--to", "50", "--t-end", "0.05"][..],
    ] {
        let (code, from_stdin, err) = run_in(&root(), &[args, &["--params", "-"]].concat(), &preset);
        assert_eq!(code, 0, "{args:?}: {err}");
        let (_, from_file, _) = run(&[args, &["--params", "presets/paper.toml"]].concat());
        assert_eq!(from_stdin, from_file, "{args:?}");
    }
    // More than 1 MiB on standard input is refused.
    let mut big = preset.clone();
    big.extend(std::iter::repeat_n(b'#', 2 << 20));
    let (code, out, err) = run_in(&root(), &["equilibrium", "--params", "-"], &big);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert!(err.contains("--params"), "{err}");
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let mut child = cli()
        .args([
            "step",
            "--params",
            "presets/paper.toml",
            "--from",
            "40",
            "--to",
            "50",
            "--t-end",
            "5",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read two lines as `head -2` would, then close the pipe.
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 64];
    let _ = stdout.read(&mut first).unwrap();
    drop(stdout);
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn head_of_a_pipe_in_a_shell() {
    let out = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "{} step --params presets/paper.toml --from 40 --to 50 --t-end 5 | head -2 >/dev/null; echo ${{PIPESTATUS[0]}}",
            env!("CARGO_BIN_EXE_compensator")
        ))
        .current_dir(root())
        .output()
        .unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stdout.trim(), "0", "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn params_that_are_not_a_regular_file_are_refused() {
    let (code, out, err) = run(&["equilibrium", "--params", "/dev/zero"]);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert!(err.contains("--params"), "{err}");
    // A FIFO without a writer: refused, not waited on.
    let fifo = std::env::temp_dir().join(format!("compensator-fifo-{}", std::process::id()));
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if made {
        let start = std::time::Instant::now();
        let (code, _, err) = run(&["equilibrium", "--params", fifo.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("--params"), "{err}");
        assert!(start.elapsed().as_secs() < 30);
        std::fs::remove_file(&fifo).unwrap();
    }
    // A directory, and a file over 1 MiB.
    let (code, _, err) = run(&["equilibrium", "--params", "presets"]);
    assert_eq!(code, 2);
    assert!(err.contains("--params"), "{err}");
    let big = std::env::temp_dir().join(format!("compensator-big-{}.toml", std::process::id()));
    std::fs::write(&big, vec![b'#'; (1 << 20) + 1]).unwrap();
    let (code, _, err) = run(&["equilibrium", "--params", big.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("--params"), "{err}");
    std::fs::remove_file(&big).unwrap();
    // --base is checked the same way.
    let (code, _, err) = run(&["calibrate", "--base", "/dev/zero"]);
    assert_eq!(code, 2);
    assert!(err.contains("--params"), "{err}");
}

#[test]
fn size_never_prints_a_non_finite_result() {
    let text = std::fs::read_to_string(root().join("presets/paper.toml")).unwrap();
    let huge = text.replace("diameter = 0.002    # m", "diameter = 1e300    # m");
    assert_ne!(huge, text);
    let (code, out, err) = run_in(&root(), &["size", "--params", "-", "--for", "machine"], huge.as_bytes());
    assert_ne!(code, 0, "{out}");
    assert!(!out.contains("inf"), "{out}");
    assert!(err.contains("slot.diameter"), "{err}");
}

#[test]
fn step_sample_thins_the_output_not_the_tick() {
    let base = [
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "40",
        "--to",
        "50",
        "--t-end",
        "0.1",
    ];
    let (code, every_tick, err) = run(&base);
    assert_eq!(code, 0, "{err}");
    let (code, sampled, err) = run(&[&base[..], &["--sample", "0.01"]].concat());
    assert_eq!(code, 0, "{err}");
    let all: Vec<&str> = every_tick.lines().collect();
    let some: Vec<&str> = sampled.lines().collect();
    assert_eq!(some.len(), 1 + 11, "{sampled}");
    assert_eq!(some[0], all[0]);
    for (i, line) in some.iter().enumerate().skip(1) {
        assert_eq!(*line, all[1 + 10 * (i - 1)]);
    }
    for bad in ["0", "-1", "nan", "0.0001"] {
        let (code, out, err) = run(&[&base[..], &["--sample", bad]].concat());
        assert_eq!(code, 2, "{bad}");
        assert!(out.is_empty());
        assert!(err.contains("--sample"), "{bad}: {err}");
    }
}

/// A coarse tick is the twin's to take, not a panic: the core's chooser
/// once crossed a clamp's bounds beyond 25 ms (exit 101).
#[test]
fn a_coarse_tick_runs() {
    let (code, out, err) = run(&[
        "step",
        "--params",
        "presets/paper.toml",
        "--from",
        "20",
        "--to",
        "60",
        "--dt",
        "10",
        "--t-end",
        "100",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 1 + 11, "{out}");
    let last: Vec<f64> = out
        .lines()
        .last()
        .unwrap()
        .split(',')
        .filter_map(|c| c.parse().ok())
        .collect();
    // At rest at 60 C after 100 s: the closed form's displacement.
    let (_, eq, _) = run(&["equilibrium", "--params", "presets/paper.toml", "--temps", "60"]);
    let x_eq: f64 = eq.lines().nth(1).unwrap().split(',').nth(5).unwrap().parse().unwrap();
    // time_s, t_c, x_m, ...
    assert!((last[2] - x_eq).abs() <= 1e-6 * 1.5e-3, "{} vs {x_eq}", last[2]);
}
