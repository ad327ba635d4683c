//! The mistakes a new user makes, each a case: misspelt commands, flags,
//! values and keys, data in the wrong unit, temperatures outside the
//! envelope, unknown formats, missing files. Each exits with status 2,
//! prints nothing on standard output, and says on one or two lines of
//! standard error what is wrong and, where there is one, the fix or the
//! nearest valid name. The expected message is a snapshot (snapbox:
//! `[..]` stands for the rest of a line), so a message that loses its
//! useful part fails; `SNAPSHOTS=overwrite` does not apply (they are
//! written here, in the table).

mod common;
use common::{root, run_in};
use std::path::PathBuf;

const PAPER: &str = include_str!("../../presets/paper.toml");

/// The files the cases use, in a scratch folder.
fn files() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-mistakes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::os::unix::fs::symlink(root().join("presets"), dir.join("presets")).unwrap();
    std::os::unix::fs::symlink(root().join("data"), dir.join("data")).unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    // The [plunger] key only (the file's [tolerances] and [[correlation]] name it too).
    write("sping.toml", &PAPER.replacen("spring_rate =", "sping_rate =", 1));
    write("plungr.toml", &PAPER.replace("[plunger]", "[plungr]"));
    write(
        "wrong-section.toml",
        &PAPER
            .replace("bulk_modulus", "# moved")
            .replace("[plunger]", "[plunger]\nbulk_modulus = 1.5e9"),
    );
    write("mm.toml", &PAPER.replace("stroke = 0.0015", "stroke = 1.5"));
    write("text.toml", &PAPER.replacen("\nmass = ", "\nmass = \"1\" # ", 1));
    write(
        "oil.toml",
        &PAPER
            .replace("[estimator]", "[estimator]\noil_mx = 100")
            .replace("[fluid]", "[estimator]\noil_mx = 100\n\n[fluid]"),
    );
    // The paper's Table 1 in bar instead of Pa.
    let pressure = std::fs::read_to_string(root().join("data/calibration/paper-pressure.csv")).unwrap();
    let mut bar = String::new();
    for line in pressure.lines() {
        let cells: Vec<&str> = line.split(',').collect();
        match (cells.first(), cells.get(1).and_then(|c| c.parse::<f64>().ok())) {
            (Some(t), Some(dp)) if !t.starts_with('#') => {
                let dp_ab: f64 = cells[2].parse().unwrap();
                bar.push_str(&format!("{t},{},{}\n", dp / 1e5, dp_ab / 1e5));
            }
            _ => {
                bar.push_str(line);
                bar.push('\n');
            }
        }
    }
    write("pressure-bar.csv", &bar);
    write(
        "pressure-kelvin.csv",
        "t_c,dp_pa,dp_ab_pa\n303.15,400000,-80000\n313.15,400000,60000\n",
    );
    write("displacement-mm.csv", "t_c,x_m\n30,0\n40,0.18\n50,0.49\n60,0.69\n");
    write(
        "step-ms.csv",
        "time_s,t_c,x_m\n0,40,0.00018\n1,50,0.0002\n2,50,0.00025\n",
    );
    write(
        "step-hot.csv",
        "time_s,t_c,x_m\n0,40,0.00018\n0.001,300000,0.0002\n0.002,50,0.00025\n",
    );
    write(
        "step-2m.csv",
        "time_s,t_c,x_m\n0,40,0.00018\n0.001,50,2\n0.002,50,0.00025\n",
    );
    // Probe logs for `estimate`.
    write("log-back.csv", "time_s,t_c\n0,40\n0.02,40\n0.01,40\n");
    write("log-tick.csv", "time_s,t_c\n0,40\n0.0004,40\n");
    write("log-gap.csv", "time_s,t_c\n0,40\n0.02,40\n0.04,40\n1.2,40\n");
    write("log-hot.csv", "time_s,t_c\n0,40\n0.02,300000\n");
    write("log-kelvin.csv", "time_s,t_c\n0,313.15\n0.02,313.15\n");
    write("log-empty.csv", "");
    write("log-header.csv", "time_s,t_c\n");
    write("log-one.csv", "time_s,t_c\n0,40\n");
    write("log-none.csv", "time_s,x_m\n0,0.0002\n0.02,0.0002\n");
    write("log-two.csv", "time_s,t_c,code\n0,40,9000\n0.02,40,9000\n");
    write("log-notime.csv", "t_s,t_c\n0,40\n0.02,40\n");
    write("log-kohm.csv", "time_s,rtd_ohm\n0,0.1155\n0.02,0.1155\n");
    write("log-pt1000.csv", "time_s,rtd_ohm\n0,1155\n0.02,1155\n");
    write("log-word.csv", "time_s,code\n0,17800\n0.02,35600\n");
    write("log-halfcode.csv", "time_s,code\n0,8900.5\n0.02,8900\n");
    write("log-cold.csv", "time_s,t_c\n0,-40\n0.02,20\n");
    write("log-short.csv", "time_s,t_c\n0,40\n0.02,40\n0.04,40\n");
    write("log-epoch.csv", "time_s,t_c\n1764640000,40\n1764640000.02,40\n");
    write("log-long.csv", "time_s,t_c\n0,40\n200000,40\n");
    let rows = compensator_cli::estimate::MAX_ROWS + 1;
    write("log-rows.csv", &format!("time_s,t_c\n{}", "1,40\n".repeat(rows)));
    let huge = std::fs::File::create(dir.join("log-huge.csv")).unwrap();
    huge.set_len(compensator_cli::input::MAX_LOG_BYTES + 1).unwrap();
    dir
}

/// (arguments, the expected standard error).
const CASES: &[(&str, &str)] = &[
    // Commands and flags.
    (
        "equilibrum --params presets/paper.toml",
        "error: unrecognized subcommand 'equilibrum'\n  tip: a similar subcommand exists: 'equilibrium'\n",
    ),
    (
        "eigne --params presets/paper.toml",
        "error: unrecognized subcommand 'eigne'\n  tip: a similar subcommand exists: 'eigen'\n",
    ),
    (
        "twinconfig --params presets/paper.toml",
        "error: unrecognized subcommand 'twinconfig'\n  tip: a similar subcommand exists: 'twin-config'\n",
    ),
    (
        "equilibrium",
        "error: the following required arguments were not provided: --params <FILE>\n  usage: compensator equilibrium --params <FILE>\n",
    ),
    (
        "step --params presets/paper.toml --from 40",
        "error: the following required arguments were not provided: --to <TO>\n  usage: [..]\n",
    ),
    (
        "report -o DIR",
        "error: the following required arguments were not provided: --dir <DIR>\n  usage: [..]\n",
    ),
    (
        "identify --params presets/paper.toml",
        "error: the following required arguments were not provided: --data <STEP.csv>\n  usage: [..]\n",
    ),
    (
        "equilibrium --param presets/paper.toml",
        "error: unexpected argument '--param' found\n  tip: a similar argument exists: '--params'\n",
    ),
    (
        "eigen --params presets/paper.toml --temp 30",
        "error: unexpected argument '--temp' found\n  tip: a similar argument exists: '--temps'\n",
    ),
    (
        "step --params presets/paper.toml --from 40 --too 50",
        "error: unexpected argument '--too' found\n  tip: a similar argument exists: '--to'\n",
    ),
    (
        "sweep --params presets/paper.toml --varry plunger.mass=1%",
        "error: unexpected argument '--varry' found\n  tip: a similar argument exists: '--vary'\n",
    ),
    (
        "calibrate --presure-data data/calibration/paper-pressure.csv",
        "error: unexpected argument '--presure-data' found\n  tip: a similar argument exists: '--pressure-data'\n",
    ),
    // Values.
    (
        "equilibrium --params presets/paper.toml --format xlsx",
        "error: invalid value 'xlsx' for '--format <FORMAT>' [possible values: csv, json, table]\n",
    ),
    (
        "equilibrium --params presets/paper.toml --units imperial",
        "error: invalid value 'imperial' for '--units <UNITS>' [possible values: si, eng]\n",
    ),
    (
        "equilibrium --params presets/paper.toml --precision f16",
        "error: invalid value 'f16' for '--precision <PRECISION>' [possible values: f64, f32]\n",
    ),
    (
        "size --params presets/paper.toml --for machin",
        "error: invalid value 'machin' for '--for <WHAT>' [possible values: machine, slot]\n  tip: a similar value exists: 'machine'\n",
    ),
    (
        "step --params presets/paper.toml --from 40 --to 50 --scheme sdirk4",
        "error: invalid value 'sdirk4' for '--scheme <SCHEME>' [possible values: [..]]\n  tip: a similar value exists: 'sdirk[..]'\n",
    ),
    (
        "equilibrium --params presets/paper.toml --plot fig.pdf",
        "error: invalid value 'fig.pdf' for '--plot <FILE.svg|FILE.png>': the figure file must end in .svg or .png\n",
    ),
    (
        "asymptotic --params presets/paper.toml --order 3 --reading property",
        "error: invalid value '3' for '--order <ORDER>': 3 is not in 0..=2\n",
    ),
    (
        "completions tcsh",
        "error: invalid value 'tcsh' for '<SHELL>' [possible values: bash, elvish, fish, powershell, zsh]\n  tip: a similar value exists: 'zsh'\n",
    ),
    // Options a command does not take.
    (
        "paper --format json",
        "error: unexpected argument '--format' found\n  tip: --format is taken by equilibrium, [..]\n",
    ),
    (
        "calibrate --units eng",
        "error: unexpected argument '--units' found\n  tip: --units is taken by equilibrium, [..]\n",
    ),
    (
        "size --params presets/paper.toml --for machine --plot size.svg",
        "error: unexpected argument '--plot' found\n  tip: --plot is taken by equilibrium, [..]\n",
    ),
    // Lists.
    (
        "equilibrium --params presets/paper.toml --temps 30-80",
        "error: --temps: '30-80' is not a number\n",
    ),
    (
        "equilibrium --params presets/paper.toml --temps 80:30:10",
        "error: --temps: end 30 is below start 80\n",
    ),
    (
        "indicators --params presets/paper.toml --steps 30-40",
        "error: --steps: '30-40' is not of the form from:to\n",
    ),
    // Temperatures outside the envelope.
    (
        "equilibrium --params presets/paper.toml --temps 105,106,110",
        "error: --temps: 106 C is above the oil model's range -20 to 105.9 C (105.9 C: viscosity below 2 cSt; estimator.oil_max = 150 C); validated 26 to 78 C\n",
    ),
    (
        "equilibrium --params presets/paper.toml --temps=-30",
        "error: --temps: -30 C is below the oil model's range -20 to 105.9 C (-20 C: estimator.oil_min); validated 26 to 78 C\n",
    ),
    (
        "step --params presets/paper.toml --from 40 --to 120",
        "error: --to: 120 C is above the oil model's range -20 to 105.9 C [..]\n",
    ),
    (
        "indicators --params presets/paper.toml --steps 40:200",
        "error: --steps: 200 C is above the oil model's range [..]\n",
    ),
    (
        "sweep --params presets/paper.toml --temps 30,150",
        "error: --temps: 150 C is above the oil model's range [..]\n",
    ),
    (
        "asymptotic --params presets/paper.toml --order 1 --reading property --t0 130",
        "error: --t0: 130 C is above the oil model's range [..]\n",
    ),
    // Parameter files.
    (
        "equilibrium --params nosuch.toml",
        "error: --params: nosuch.toml: No such file or directory (os error 2)\n",
    ),
    (
        "equilibrium --params sping.toml",
        "error: plunger.sping_rate: unknown key; did you mean plunger.spring_rate?\n",
    ),
    (
        "equilibrium --params plungr.toml",
        "error: plungr.[..]: unknown key; did you mean [plunger]?\n",
    ),
    (
        "equilibrium --params wrong-section.toml",
        "error: plunger.bulk_modulus: unknown key; did you mean fluid.bulk_modulus?\n",
    ),
    (
        "equilibrium --params oil.toml",
        "error: estimator.oil_mx: unknown key; did you mean estimator.oil_max?\n",
    ),
    ("equilibrium --params mm.toml", "error: plunger.stroke = 1.5: [..]\n"),
    (
        "equilibrium --params text.toml",
        "error: plunger.mass: expected a number, found a TOML string\n",
    ),
    (
        "equilibrium --params presets",
        "error: --params: presets: not a regular file\n",
    ),
    // Names of parameters on the command line.
    (
        "sweep --params presets/paper.toml --set plunger.sping_rate=1:2:2",
        "error: --set: unknown parameter 'plunger.sping_rate' (a section.key of docs/parameters.md); did you mean plunger.spring_rate?\n",
    ),
    (
        "sweep --params presets/paper.toml --vary mass=1%",
        "error: --vary: unknown parameter 'mass' [..]\n",
    ),
    (
        "identify --params presets/paper.toml --data data/fmu/oil-temperature.csv --fit mas",
        "error: --fit: 'mas' is not one of plunger.mass, [..]\n",
    ),
    // Measured data in the wrong unit.
    (
        "calibrate --pressure-data pressure-bar.csv",
        "error: --pressure-data: pressure-bar.csv: row 1 (line [..]), column dp_pa: 4 Pa is not a plausible inlet-outlet pressure drop p_p - p_c [1000, 1e8] Pa; written in another unit? (4 bar = 400000 Pa)\n",
    ),
    (
        "calibrate --pressure-data pressure-kelvin.csv",
        "error: --pressure-data: pressure-kelvin.csv: row 1 (line 2), column t_c: 303.15 C is not a plausible oil temperature [-60, 300] C; written in another unit? (303.15 K = 30 C)\n",
    ),
    (
        "calibrate --pressure-data data/calibration/paper-pressure.csv --displacement-data displacement-mm.csv",
        "error: --displacement-data: data row 2, column x_m: 0.18 m is outside the plunger's travel [-0.00015, 0.00165] m (0 to plunger.stroke = 0.0015 m, with 10 % slack); written in another unit? (0.18 mm = 0.00018 m)\n",
    ),
    (
        "identify --params presets/paper.toml --data step-hot.csv",
        "error: --data: step-hot.csv: row 2 (line 3), column t_c: 300000 C is not a plausible oil temperature [-60, 300] C\n",
    ),
    (
        "identify --params presets/paper.toml --data step-2m.csv",
        "error: --data: step-2m.csv: row 2 (line 3), column x_m: 2 m is not a plausible plunger displacement [-1, 1] m; written in another unit? (2 mm = 0.002 m)\n",
    ),
    (
        "calibrate --pressure-data nosuch.csv",
        "error: --pressure-data: nosuch.csv: No such file or directory (os error 2)\n",
    ),
    (
        "identify --params presets/paper.toml --data nosuch.csv",
        "error: --data: nosuch.csv: No such file or directory (os error 2)\n",
    ),
    // Probe logs: times, gaps, units, columns, sizes.
    (
        "estimate --params presets/paper.toml --sensor-data log-back.csv",
        "error: --sensor-data: log-back.csv: row 3 (line 4), column time_s: 0.01 s is not after the row before (0.02 s): the sample times must increase\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-tick.csv",
        "error: --sensor-data: log-tick.csv: row 2 (line 3), column time_s: 0.4 ms after the row before, within one tick of the estimator (1 ms at estimator.tick_hz = 1000 Hz): it takes one reading a tick\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-gap.csv",
        "error: --sensor-data: log-gap.csv: row 4 (line 5), column time_s: 1.16 s after the row before, longer than the estimator's fault timeout: it flags the estimate DEGRADED after 500 ms without a reading (500 ticks at estimator.tick_hz = 1000 Hz); split the log at this row and replay each part on its own\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-hot.csv",
        "error: --sensor-data: log-hot.csv: row 2 (line 3), column t_c: 300000 C is not a plausible oil temperature [-60, 300] C\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-kelvin.csv",
        "error: --sensor-data: log-kelvin.csv: row 1 (line 2), column t_c: 313.15 C is not a plausible oil temperature [-60, 300] C; written in another unit? (313.15 K = 40 C)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-empty.csv",
        "error: --sensor-data: log-empty.csv: empty file: no header row\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-header.csv",
        "error: --sensor-data: log-header.csv: no readings: the file has a header and no rows\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-one.csv",
        "error: --sensor-data: log-one.csv: one reading: the estimator needs at least two to know the log's reading interval\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-none.csv",
        "error: --sensor-data: log-none.csv: no reading column (columns: time_s,x_m; expected time_s and one of t_c, t_probe_c, rtd_ohm, code)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-two.csv",
        "error: --sensor-data: log-two.csv: two reading columns, t_c and code: which one the probe read is unknown; keep one\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-notime.csv",
        "error: --sensor-data: log-notime.csv: no column time_s (columns: t_s,t_c; expected time_s and one of t_c, t_probe_c, rtd_ohm, code)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-kohm.csv",
        "error: --sensor-data: log-kohm.csv: row 1 (line 2), column rtd_ohm: 0.1155 ohm is not a plausible RTD resistance [1, 100000] ohm; written in another unit? (0.1155 kohm = 115.5 ohm)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-pt1000.csv",
        "error: --sensor-data: log-pt1000.csv: row 1 (line 2), column rtd_ohm: 1155 ohm is no temperature: the file's RTD, estimator.rtd_r0 = 100 ohm, reads 18.52 to 390.5 ohm over IEC 60751's -200 to 850 C; the estimator starts at the first reading: begin the log at a valid one\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-word.csv",
        "error: --sensor-data: log-word.csv: row 2 (line 3), column code: 35600 LSB is not a plausible MAX31865 15-bit RTD code [0, 32767] LSB; written in another unit? (35600 register word (code x 2 + fault bit) = 17800 LSB)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-halfcode.csv",
        "error: --sensor-data: log-halfcode.csv: row 1 (line 2), column code: 8900.5 is not a whole number (the MAX31865's RTD code is an integer 0 to 32767)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-cold.csv",
        "error: --sensor-data: log-cold.csv: row 1 (line 2), column t_c (the estimator starts at the first reading): -40 C is below the oil model's range -20 to 105.9 C (-20 C: estimator.oil_min); validated 26 to 78 C\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-epoch.csv",
        "error: --sensor-data: log-epoch.csv: row 1 (line 2), column time_s: 1.76464e9 s is not a plausible sample time [0, 1e7] s; written in another unit? (1.76464e9 ms = 1765000 s); or a Unix time (s since 1970)? time_s counts from the log's start: subtract the first row's time\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-short.csv",
        "error: --sensor-data: log-short.csv: no telemetry tick in the log's 0.04 s (the firmware publishes one every 500 ms): no row to print; give --every-sample for one row per reading\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-long.csv",
        "error: --sensor-data: log-long.csv: row 2 (line 3), column time_s: the log spans 200000 s, more than the limit of 1e8 ticks (100000 s at estimator.tick_hz = 1000 Hz): split the log (each part replays from its first reading)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-rows.csv",
        "error: --sensor-data: log-rows.csv: 1000001 rows, more than the limit of 1000000 readings: split the log (each part replays from its first reading)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data log-huge.csv",
        "error: --sensor-data: log-huge.csv: 67108865 bytes, larger than the limit of 64 MiB: split the log (each part replays from its first reading)\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data nosuch.csv",
        "error: --sensor-data: nosuch.csv: No such file or directory (os error 2)\n",
    ),
    (
        "estimate --params - --sensor-data -",
        "error: --sensor-data: standard input is --params' already; give one of them as a file\n",
    ),
    (
        "estimate --params presets/paper.toml --sensor-data data/logs/probe-warm-up.csv --every-samples",
        "error: unexpected argument '--every-samples' found\n  tip: a similar argument exists: '--every-sample'\n",
    ),
];

#[test]
fn every_mistake_exits_2_with_one_or_two_lines_naming_it_and_the_fix() {
    let dir = files();
    let mut failures = Vec::new();
    for (args, expected) in CASES {
        let argv: Vec<&str> = args.split_whitespace().collect();
        let (code, out, err) = run_in(&dir, &argv, b"");
        let mut problems = Vec::new();
        if code != 2 {
            problems.push(format!("exit {code}"));
        }
        if !out.is_empty() {
            problems.push(format!("stdout: {out}"));
        }
        if !(1..=2).contains(&err.lines().count()) {
            problems.push(format!("{} lines", err.lines().count()));
        }
        let assert = snapbox::Assert::new();
        if let Err(diff) = assert.try_eq(Some(args), err.clone().into(), expected.to_string().into()) {
            problems.push(format!("{diff}"));
        }
        if !problems.is_empty() {
            failures.push(format!("compensator {args}\n{err}{}", problems.join("\n")));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(CASES.len() >= 40, "{} cases", CASES.len());
    println!("{} mistakes, each exit 2 with its message", CASES.len());
    assert!(
        failures.is_empty(),
        "{} of {}:\n\n{}",
        failures.len(),
        CASES.len(),
        failures.join("\n\n")
    );
}
