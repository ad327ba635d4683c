//! Every CLI command that reads a parameter file (`compensator --help`:
//! all but `completions` and `man`) refuses every bad input
//! by name: exit status 2, nothing on standard output, one line on
//! standard error (at most 240 bytes) naming the field, the same message
//! the library gives (`host_tests::matrix`, docs/parameters.md).
//!
//! The library's matrix runs every field against every bad case; here
//! each command gets a third of the fields (every field goes through five
//! commands), the case rotating with the field and the command, so that
//! every command sees at least six kinds of bad value (about 200 runs of the debug
//! binary, a few seconds on an idle machine).
//! Then the inputs that are not files (`/dev/zero`, a FIFO without a
//! writer, a directory) through every command, a closed pipe on every
//! command's output, and compact numbers in every table.

use host_tests::matrix::{Case, Outcome, base_text, edited, fields, run};
use host_tests::{cli_binary, repo_root, run_cli};
use std::time::{Duration, Instant};

/// Every command that reads a parameter file: its arguments before the
/// file, and the flag that names it.
const COMMANDS: [(&[&str], &str); 15] = [
    (&["equilibrium"], "--params"),
    (&["asymptotic", "--order", "1", "--reading", "temperature"], "--params"),
    (&["sensitivity"], "--params"),
    (&["step", "--from", "30", "--to", "40", "--t-end", "0.05"], "--params"),
    (&["twin-config"], "--params"),
    (&["eigen"], "--params"),
    (&["indicators", "--steps", "30:40"], "--params"),
    (&["compensation"], "--params"),
    (&["size", "--for", "machine"], "--params"),
    (&["size", "--for", "slot"], "--params"),
    (&["calibrate"], "--params"),
    (&["identify", "--data", "data/fmu/oil-temperature.csv"], "--params"),
    (&["paper"], "--params"),
    (&["report", "--dir", "target/cli-bad-input-report"], "--params"),
    (&["sweep", "--vary", "plunger.mass=10%", "--samples", "3"], "--params"),
];

fn args<'a>(command: &'a [&'a str], flag: &'a str, file: &'a str) -> Vec<&'a str> {
    let mut v = command.to_vec();
    v.extend([flag, file]);
    v
}

#[test]
fn every_command_refuses_every_bad_field_by_its_name() {
    let base = base_text();
    let dir = std::env::temp_dir().join(format!("compensator-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Per field, the cases the library refuses naming that field.
    let refused: Vec<(&'static compensator::params::Field, Vec<(Case, String)>)> = fields()
        .map(|f| {
            let cases = Case::ALL
                .iter()
                .filter_map(|&case| match run(&base, f, case) {
                    Outcome::Refused(r) if r.field == Some(f.path) => Some((case, r.message)),
                    _ => None,
                })
                .collect();
            (f, cases)
        })
        .collect();
    let _ = cli_binary();
    let mut runs = 0;
    let mut cases_seen = std::collections::BTreeSet::new();
    for (c, (command, flag)) in COMMANDS.iter().enumerate() {
        for (i, (field, cases)) in refused.iter().enumerate() {
            // A third of the fields per command (every field through five
            // commands), to keep the test at a few hundred runs.
            if cases.is_empty() || i % 3 != c % 3 {
                continue;
            }
            let (case, message) = &cases[(i / 3 + c) % cases.len()];
            cases_seen.insert((c, case.header()));
            let file = dir.join(format!("c{c}-f{i}.toml"));
            std::fs::write(&file, edited(&base, field, case.value(field).as_deref())).unwrap();
            let file = file.to_string_lossy().into_owned();
            let argv = args(command, flag, &file);
            let (code, stdout, stderr) = run_cli(&argv);
            runs += 1;
            let what = format!("{argv:?} ({} {})", field.path, case.header());
            assert_eq!(code, 2, "{what}: {stderr}");
            assert!(stdout.is_empty(), "{what}: {stdout}");
            assert_eq!(stderr.lines().count(), 1, "{what}: {stderr}");
            assert!(stderr.len() <= 240, "{what}: {} bytes: {stderr}", stderr.len());
            assert!(
                stderr.contains(field.path) && stderr.contains(message.as_str()),
                "{what}: {stderr} (the library: {message})"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    // Every command saw most kinds of bad value.
    for (c, (command, _)) in COMMANDS.iter().enumerate() {
        let kinds = cases_seen.iter().filter(|(k, _)| *k == c).count();
        assert!(kinds >= 6, "{command:?}: {kinds} kinds of bad value");
    }
    assert!(runs >= 150, "{runs}");
}

#[test]
fn every_command_refuses_inputs_that_are_not_files_quickly() {
    let fifo = std::env::temp_dir().join(format!("compensator-cli-fifo-{}", std::process::id()));
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    assert!(made, "mkfifo");
    let fifo_path = fifo.to_string_lossy().into_owned();
    for (command, flag) in COMMANDS {
        for input in ["/dev/zero", fifo_path.as_str(), "presets", "/nonexistent/params.toml"] {
            let argv = args(command, flag, input);
            let start = Instant::now();
            let (code, stdout, stderr) = run_cli(&argv);
            assert!(
                start.elapsed() < Duration::from_secs(10),
                "{argv:?} took {:?}",
                start.elapsed()
            );
            assert_eq!(code, 2, "{argv:?}: {stderr}");
            assert!(stdout.is_empty(), "{argv:?}");
            assert_eq!(stderr.lines().count(), 1, "{argv:?}: {stderr}");
            // Named by its flag, or (a missing file) by its path.
            let named = stderr.contains(flag) || (input.starts_with("/nonexistent") && stderr.contains(input));
            assert!(named && stderr.len() <= 240, "{argv:?}: {stderr}");
        }
    }
    std::fs::remove_file(&fifo).unwrap();
}

/// Reading one byte and closing the pipe (`| head -c 1`): the command ends
/// with status 0 and says nothing of it (`step` still notes its twin's
/// configuration).
#[test]
fn every_command_ends_quietly_on_a_closed_pipe() {
    let bin = cli_binary().to_string_lossy().into_owned();
    for (command, flag) in COMMANDS {
        if matches!(command[0], "identify" | "report") {
            // No measured transient in data/ to fit; `report` writes files.
            continue;
        }
        let file = "presets/paper.toml";
        let mut argv = args(command, flag, file);
        if command[0] == "step" {
            // Long enough to fill the pipe: 5 s of 1 ms rows.
            argv = vec!["step", "--from", "30", "--to", "40", "--t-end", "5", flag, file];
        }
        let script = format!(
            "\"{bin}\" {} | head -c 1 >/dev/null; echo ${{PIPESTATUS[0]}}",
            argv.iter().map(|a| format!("'{a}'")).collect::<Vec<_>>().join(" ")
        );
        let out = std::process::Command::new("bash")
            .arg("-c")
            .arg(&script)
            .current_dir(repo_root())
            .output()
            .unwrap();
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        assert_eq!(stdout.trim(), "0", "{argv:?}: {stderr}");
        let lower = stderr.to_lowercase();
        assert!(
            !lower.contains("panick")
                && !lower.contains("broken pipe")
                && !lower.lines().any(|l| l.starts_with("error")),
            "{argv:?}: {stderr}"
        );
    }
}

/// Every number in every command's table is in its compact shortest form:
/// no cell over 24 characters, each a finite number or a word.
#[test]
fn every_table_prints_numbers_compactly() {
    for (command, flag) in COMMANDS {
        if matches!(command[0], "size" | "calibrate" | "paper" | "report" | "identify") {
            // TOML, text, files or a fit to data, not a table of the
            // parameter file (`size`'s numbers: params' `fmt_float`).
            continue;
        }
        let argv = args(command, flag, "presets/paper.toml");
        let (code, stdout, stderr) = run_cli(&argv);
        assert_eq!(code, 0, "{argv:?}: {stderr}");
        let mut lines = stdout.lines().filter(|l| !l.starts_with('#'));
        let header = lines.next().unwrap();
        assert!(
            header.split(',').all(|h| h.parse::<f64>().is_err()),
            "{argv:?}: {header}"
        );
        let error = header.split(',').position(|h| h == "error");
        for line in lines {
            for (i, cell) in line.split(',').enumerate() {
                if Some(i) == error {
                    assert!(cell.is_empty(), "{argv:?}: {line}");
                    continue;
                }
                assert!(cell.len() <= 24, "{argv:?}: {cell}");
                // Numbers read back; words (a scheme, a verdict) are words.
                let word = cell.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                    && cell.starts_with(|c: char| c.is_ascii_alphabetic())
                    && !matches!(cell, "inf" | "NaN");
                assert!(cell.parse::<f64>().is_ok() || word, "{argv:?}: {cell:?} in {line}");
            }
        }
    }
}
