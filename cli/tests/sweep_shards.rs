//! `sweep --shard K/N`, the streamed output and the Slurm recipe
//! (`cli/scale-out/slurm-sweep.sh`): shards concatenated in order are the
//! single run byte for byte, for any shard count and thread count; the
//! Slurm array script's shard arithmetic (run here with the variables
//! Slurm would set); a streamed file appears only once complete; `--units
//! eng` converts the streamed rows as the other tables; a reader that
//! closes the pipe ends the run quietly.

mod common;
use common::{root, run, run_env};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

/// A grid of 3 spring rates with 11 draws each: 33 variants, some of them
/// failing (the window's discharge coefficient drawn across its range's
/// upper edge, 1.0) so that error rows are sharded too.
const SWEEP: [&str; 15] = [
    "sweep",
    "--params",
    "presets/paper.toml",
    "--set",
    "plunger.spring_rate=20e3:30e3:3",
    "--vary",
    "plunger.diameter=2%",
    "--vary",
    "slot.discharge_coefficient=0.4",
    "--samples",
    "11",
    "--seed",
    "5",
    "--t-end",
    "0.1",
];

fn with(extra: &[&str]) -> Vec<String> {
    SWEEP.iter().chain(extra).map(|s| s.to_string()).collect()
}

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn shards_concatenated_are_the_single_run_byte_for_byte() {
    let (code, single, err) = run(&SWEEP);
    assert_eq!(code, 1, "some rows fail on purpose: {err}");
    assert_eq!(single.lines().count(), 1 + 33);
    assert!(single.lines().any(|l| !l.ends_with(',')), "an error row");
    for n in [1usize, 2, 3, 7, 33, 40] {
        for threads in ["1", "2"] {
            let mut joined = String::new();
            for k in 1..=n {
                let shard = format!("{k}/{n}");
                let a = with(&["--shard", &shard]);
                let (code, out, err) = run_env(&args(&a), &[("RAYON_NUM_THREADS", threads)]);
                assert!(code == 0 || code == 1, "{shard}: {err}");
                if k > 1 {
                    assert!(!out.starts_with("variant,"), "{shard}: only shard 1 writes the header");
                }
                joined.push_str(&out);
            }
            assert_eq!(joined, single, "{n} shards on {threads} threads");
        }
    }
}

#[test]
fn bad_shards_are_bad_input() {
    for bad in ["0/3", "4/3", "1/0", "x/3", "2"] {
        let a = with(&["--shard", bad]);
        let (code, out, err) = run(&args(&a));
        assert_eq!(code, 2, "{bad}: {err}");
        assert!(out.is_empty());
        assert!(err.contains("--shard") && err.contains(bad), "{err}");
    }
    let a = with(&["--shard", "1/2", "--format", "json"]);
    let (code, _, err) = run(&args(&a));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--shard"), "{err}");
}

/// Runs `cli/scale-out/slurm-sweep.sh` as array task `id` of `min..=max`.
fn slurm_task(dir: &std::path::Path, id: i64, min: i64, max: i64, count: i64) -> (i32, String) {
    let out = Command::new("bash")
        .arg(root().join("cli/scale-out/slurm-sweep.sh"))
        .arg(dir)
        .args(SWEEP)
        .current_dir(root())
        .env("COMPENSATOR", env!("CARGO_BIN_EXE_compensator"))
        .env("SLURM_ARRAY_TASK_ID", id.to_string())
        .env("SLURM_ARRAY_TASK_MIN", min.to_string())
        .env("SLURM_ARRAY_TASK_MAX", max.to_string())
        .env("SLURM_ARRAY_TASK_COUNT", count.to_string())
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn merge(dir: &std::path::Path) -> (i32, String, String) {
    let out = Command::new("bash")
        .arg(root().join("cli/scale-out/slurm-sweep.sh"))
        .arg("--merge")
        .arg(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_slurm_array_script_shards_and_merges_into_the_single_run() {
    let (_, single, _) = run(&SWEEP);
    let base = std::env::temp_dir().join(format!("compensator-slurm-{}", std::process::id()));
    // Arrays numbered from 0 and from 1, of 5 tasks (sbatch --array=0-4 and 1-5).
    for (min, max) in [(0i64, 4i64), (1, 5)] {
        let dir = base.join(format!("array-{min}"));
        for id in min..=max {
            let (code, err) = slurm_task(&dir, id, min, max, max - min + 1);
            assert!(code == 0 || code == 1, "task {id}: {err}");
        }
        let names: Vec<String> = (1..=5).map(|k| format!("shard-{k}-of-5.csv")).collect();
        for n in &names {
            assert!(dir.join(n).is_file(), "{n}");
            assert!(!dir.join(format!("{n}.partial")).exists());
        }
        let (code, merged, err) = merge(&dir);
        assert_eq!(code, 0, "{err}");
        assert_eq!(merged, single, "array {min}-{max}");
        // A task that has not finished: the merge refuses, naming it.
        std::fs::remove_file(dir.join(&names[2])).unwrap();
        let (code, _, err) = merge(&dir);
        assert_eq!(code, 2);
        assert!(err.contains("shard-3-of-5.csv"), "{err}");
    }
    // Not an array task, or an array with a step (0-8:2 has 5 tasks).
    let (code, err) = Command::new("bash")
        .arg(root().join("cli/scale-out/slurm-sweep.sh"))
        .arg(base.join("none"))
        .args(SWEEP)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .output()
        .map(|o| {
            (
                o.status.code().unwrap_or(-1),
                String::from_utf8_lossy(&o.stderr).into_owned(),
            )
        })
        .unwrap();
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("sbatch --array"), "{err}");
    let (code, err) = slurm_task(&base.join("step"), 2, 0, 8, 5);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("contiguous"), "{err}");
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn a_streamed_file_appears_complete_and_eng_units_convert_the_rows() {
    let (_, single, _) = run(&SWEEP);
    let dir = std::env::temp_dir().join(format!("compensator-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("out.csv");
    let a = with(&["-o", file.to_str().unwrap()]);
    let (code, out, _) = run(&args(&a));
    assert_eq!(code, 1);
    assert!(out.is_empty());
    assert_eq!(std::fs::read_to_string(&file).unwrap(), single);
    assert!(!dir.join("out.csv.partial").exists());
    let a = with(&["--units", "eng"]);
    let (_, eng, _) = run(&args(&a));
    assert_eq!(eng, compensator_cli::units::Units::Eng.convert_csv(&single));
    assert!(eng.lines().next().unwrap().contains("x_30c_mm"), "{eng}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_reader_that_closes_the_pipe_ends_the_sweep_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_compensator"))
        .args([
            "sweep",
            "--params",
            "presets/paper.toml",
            "--vary",
            "plunger.diameter=1%",
            "--samples",
            "1000000",
        ])
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    assert!(lines.next().unwrap().unwrap().starts_with("variant,"));
    assert!(lines.next().unwrap().unwrap().starts_with("0,"));
    drop(lines);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("error"), "{err}");
}
