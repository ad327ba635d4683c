//! Helpers shared by the binary tests: the repository root, the binary,
//! and running it with arguments and standard input.
#![allow(dead_code, reason = "each test file uses a different subset")]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The `compensator` binary, run in the repository root.
pub fn cli() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_compensator"));
    c.current_dir(root());
    c
}

/// Runs the binary in `dir` with `stdin`: (code, stdout, stderr).
pub fn run_in(dir: &Path, args: &[&str], stdin: &[u8]) -> (i32, String, String) {
    let mut child = cli()
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    let _ = input.write_all(stdin);
    drop(input);
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// Runs the binary in the repository root: (code, stdout, stderr).
pub fn run(args: &[&str]) -> (i32, String, String) {
    run_in(&root(), args, b"")
}

/// Runs the binary in the repository root with extra environment
/// variables: (code, stdout, stderr).
pub fn run_env(args: &[&str], env: &[(&str, &str)]) -> (i32, String, String) {
    let out = cli()
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// A fresh, empty folder for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("compensator-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// CSV text as (header, rows of cells); `#` lines are comments.
pub fn csv(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines().filter(|l| !l.is_empty() && !l.starts_with('#'));
    let header = lines.next().unwrap_or("").split(',').map(String::from).collect();
    (
        header,
        lines.map(|l| l.split(',').map(String::from).collect()).collect(),
    )
}

/// Column `name` of CSV text as numbers (NaN for an empty cell).
pub fn column(text: &str, name: &str) -> Vec<f64> {
    let (header, rows) = csv(text);
    let i = header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    rows.iter()
        .map(|r| {
            if r[i].is_empty() {
                f64::NAN
            } else {
                r[i].parse().unwrap()
            }
        })
        .collect()
}

/// The paper preset's text.
pub fn paper_preset() -> String {
    std::fs::read_to_string(root().join("presets/paper.toml")).unwrap()
}
