//! Shared pieces of the host tests: independent `f64` references, a
//! deterministic generator of physical parameter sets, tolerance helpers.
//!
//! Nothing here calls the core's closed forms: the references are written
//! from `docs/model.md` directly, so that an error in the core cannot hide in the
//! reference.

pub mod accuracy;
pub mod band;
pub mod bench;
pub mod board;
pub mod campaign;
pub mod coverage;
pub mod fixed_audit;
pub mod identify_study;
pub mod matrix;
pub mod monitor_campaign;
pub mod monitor_log;
pub mod observability;
pub mod probe;
pub mod random;
pub mod settling;
pub mod soak;
pub mod survey;
pub mod sweep_twin;
pub mod tracking;
pub use compensator_reference::statics as reference;

use std::path::PathBuf;

/// The repository root (where `Cargo.toml` of the workspace lives).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host-tests sits in the repo root")
        .to_path_buf()
}

/// numpy's `isclose`: `|actual - expected| <= atol + rtol |expected|`.
pub fn isclose(actual: f64, expected: f64, rtol: f64, atol: f64) -> bool {
    (actual - expected).abs() <= atol + rtol * expected.abs()
}

/// Asserts [`isclose`] element-wise with a message naming the quantity.
#[track_caller]
pub fn assert_allclose(what: &str, actual: &[f64], expected: &[f64], rtol: f64, atol: f64) {
    assert_eq!(actual.len(), expected.len(), "{what}: lengths differ");
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert!(
            isclose(*a, *e, rtol, atol),
            "{what}[{i}]: {a} vs {e} (diff {:.3e}, allowed {:.3e})",
            (a - e).abs(),
            atol + rtol * e.abs()
        );
    }
}

/// The `compensator` CLI binary, built once per test process (debug).
pub fn cli_binary() -> &'static PathBuf {
    static BIN: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BIN.get_or_init(|| {
        let root = repo_root();
        let status = std::process::Command::new(env!("CARGO"))
            .args(["build", "--quiet", "-p", "compensator-cli", "--bin", "compensator"])
            .current_dir(&root)
            .status()
            .expect("cargo runs");
        assert!(status.success(), "building the CLI failed");
        let target = std::env::var_os("CARGO_TARGET_DIR")
            .map(PathBuf::from)
            .unwrap_or(root.join("target"));
        target.join("debug").join("compensator")
    })
}

/// Runs the CLI in the repository root: (exit code, stdout, stderr).
pub fn run_cli(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(cli_binary())
        .args(args)
        .current_dir(repo_root())
        .output()
        .expect("the CLI runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).expect("utf-8"),
        String::from_utf8(out.stderr).expect("utf-8"),
    )
}
