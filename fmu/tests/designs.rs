//! The FMU against `compensator step --precision f32` on random plausible
//! designs (the survey's: +-0.3 decade around both presets): heating over
//! the validated range, cooling to the bottom of the oil range, and a
//! ramp; each through the FMI 3.0 interface, one tick per step with the
//! tick's midpoint temperature, compared with the CLI's output row by row.

mod common;

use common::Inst;
use compensator_fmu::variables::{VR_FIRST_OUTPUT, VR_T_OIL};
use std::path::{Path, PathBuf};

const DESIGNS: usize = 16;

/// The FMU at rest at `from`, then `n` ticks with `temperature(k)` [C].
fn fmu_run(dir: &Path, from: f64, n: usize, tick: f64, temperature: impl Fn(usize) -> f64) -> Vec<[f64; 4]> {
    let i = Inst::new(dir);
    i.set(VR_T_OIL, from);
    i.initialise();
    (0..n)
        .map(|k| {
            i.set(VR_T_OIL, temperature(k));
            i.step(k as f64 * tick, tick);
            [0, 1, 2, 3].map(|o| i.get(VR_FIRST_OUTPUT + o))
        })
        .collect()
}

/// `compensator step` with these arguments: the rows after t = 0.
fn cli_run(path: &Path, from: f64, to: f64, ramp: Option<f64>, tick: f64, n: usize) -> Vec<[f64; 4]> {
    let out = compensator_cli::dynamics::step(
        path,
        from,
        to,
        ramp,
        tick,
        Some(n as f64 * tick),
        compensator_cli::dynamics::Precision::F32,
        None,
        None,
    )
    .expect("compensator step runs");
    out.csv
        .lines()
        .skip(2)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().expect("a number")).collect();
            [v[1], v[2], v[3], v[4]]
        })
        .collect()
}

#[test]
fn random_designs_agree_with_compensator_step_exactly() {
    let base = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fmu-designs");
    let mut compared = 0;
    for (d, raw) in host_tests::survey::designs(DESIGNS, 0x464d55).into_iter().enumerate() {
        let dir = base.join(format!("{d}/resources"));
        std::fs::create_dir_all(&dir).expect("folder");
        let text = compensator_params::file::to_toml(&raw);
        assert_eq!(compensator_params::file::parse(&text).expect("reads back"), raw);
        let path = dir.join("params.toml");
        std::fs::write(&path, text).expect("written");
        let e = raw.estimator;
        let tick = 1.0 / e.tick_hz;
        let n = 200;
        let rate = (e.valid_max - e.valid_min) / (0.5 * n as f64 * tick);
        let ramp = |k: usize| {
            // The reference's `Profile::Ramp::temperature` at the midpoint.
            let span = (e.valid_max - e.valid_min).abs() / rate;
            let t = (k as f64 + 0.5) * tick;
            if t >= span {
                e.valid_max
            } else {
                e.valid_min + (e.valid_max - e.valid_min) * (t / span)
            }
        };
        let cases: [(f64, f64, Option<f64>); 3] = [
            (e.valid_min, e.valid_max, None),
            (e.valid_max, e.oil_min, None),
            (e.valid_min, e.valid_max, Some(rate)),
        ];
        for (from, to, r) in cases {
            let want = cli_run(&path, from, to, r, tick, n);
            let got = match r {
                None => fmu_run(&dir, from, n, tick, |_| to),
                Some(_) => fmu_run(&dir, from, n, tick, ramp),
            };
            assert_eq!(got.len(), want.len());
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                assert_eq!(g, w, "design {d}, {from} -> {to} C (ramp {r:?}), tick {k}");
            }
            compared += 1;
        }
    }
    assert_eq!(compared, 3 * DESIGNS);
}
