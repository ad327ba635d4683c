//! The condition monitor in the FMU (FMI 3.0 interface): the second
//! sensor's reading as the input `second_reading`, the health estimate
//! and the monitor's flags as outputs.
//!
//! The reference is the core's monitor run here on what the FMU's docs
//! say it sees: each step's reading at the step's start, against the twin
//! as the previous step left it (the FMU's outputs `x`, `p_a`, `p_b`) and
//! the oil at the step's `T_oil`, known exactly. The readings are the
//! reference crate's equilibrium (`compensator_reference::statics`, no
//! code shared with the core) of a device whose capillary is restricted to
//! 0.8 of its conductance from 20 s on, during a cooling: the FMU's health
//! outputs equal the reference's at every step, and settle on the
//! restriction (`A` x 1.25).

mod common;

use common::Inst;
use compensator::Params;
use compensator::estimator::health::HEALTH_FIELDS;
use compensator::estimator::{Flags, NO_LAG};
use compensator::monitor::{Monitor, MonitorSettings, PlantView, ProbeModel, ProbeSample};
use compensator_fmu::fmi3;
use compensator_fmu::variables::{
    FIRST_HEALTH_OUTPUT, FLAGS_OUTPUT, VR_FIRST_OUTPUT, VR_SECOND_READING, VR_T_OIL, outputs,
};
use compensator_reference::statics::equilibrium;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A resources folder holding the preset `name`, one per run.
fn resources(name: &str) -> PathBuf {
    static RUN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = RUN.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("fmu-monitor/{n}/resources"));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    std::fs::copy(root().join("presets").join(name), dir.join("params.toml")).expect("params.toml");
    dir
}

fn int32(i: &Inst, vr: u32) -> i32 {
    let mut v = 0;
    // SAFETY: a live instance, one value.
    assert_eq!(unsafe { fmi3::fmi3GetInt32(i.0, &vr, 1, &mut v, 1) }, 0);
    v
}

/// `fmi3SetFloat64`'s status for one value.
fn set_status(i: &Inst, vr: u32, v: f64) -> i32 {
    // SAFETY: a live instance, one value.
    unsafe { fmi3::fmi3SetFloat64(i.0, &vr, 1, &v, 1) }
}

const VR_X: u32 = VR_FIRST_OUTPUT;
const VR_P_A: u32 = VR_FIRST_OUTPUT + 2;
const VR_P_B: u32 = VR_FIRST_OUTPUT + 3;

#[test]
fn the_health_outputs_are_the_core_monitors_on_the_same_readings() {
    let raw = compensator_params::file::load(&root().join("presets/paper-monitor.toml")).expect("preset");
    let p32 = Params::<f32>::new(&raw).expect("params");
    let settings = MonitorSettings::from_raw(&raw).expect("settings").expect("a sensor");
    // The FMU's oil temperature is its input, exact: a probe that neither
    // lags nor errs.
    let probe = ProbeModel {
        time_constant: NO_LAG as f32,
        well_time_constant: 0.0,
        tolerance_a: 0.0,
        tolerance_b: 0.0,
        ..settings.probe
    };
    let mut reference = Monitor::new(&p32, MonitorSettings { probe, ..settings }).expect("monitor");
    let mut last: Option<f64> = None;
    let mut restricted = raw.core;
    restricted.laminar_diameter *= 0.8f64.powf(0.25);
    let i = Inst::new(&resources("paper-monitor.toml"));
    let h = 0.01;
    let temp = |t: f64| if t < 20.0 { 60.0 } else { 60.0 - 0.1 * (t - 20.0) };
    i.set(VR_T_OIL, temp(0.0));
    i.initialise();
    // Before any reading the health estimate is undefined (NaN).
    assert!(i.get(VR_FIRST_OUTPUT + FIRST_HEALTH_OUTPUT as u32).is_nan());
    let mut named = None;
    let steps = 12_000;
    for k in 0..steps {
        let t = k as f64 * h;
        let core = if t < 20.0 { &raw.core } else { &restricted };
        // Every other step without a reading (NaN), as a 50 Hz sensor.
        let y = if k % 2 == 0 {
            equilibrium(core, temp(t)).p_a
        } else {
            f64::NAN
        };
        let view = PlantView {
            oil: p32.oil.point(temp(t) as f32).expect("oil"),
            x: i.get(VR_X) as f32,
            p_a: i.get(VR_P_A) as f32,
            p_b: i.get(VR_P_B) as f32,
            dt: last.map_or(0.0, |l| (t - l) as f32),
            probe: Some(ProbeSample {
                value: temp(t) as f32,
                age: 0.0,
            }),
        };
        let expected = if y.is_nan() {
            None
        } else {
            last = Some(t);
            Some(reference.update(&p32, &view, Ok::<f32, ()>(y as f32)))
        };
        i.set(VR_T_OIL, temp(t));
        i.set(VR_SECOND_READING, y);
        i.step(t, h);
        if let Some(e) = expected {
            for (j, f) in HEALTH_FIELDS.iter().enumerate() {
                let got = i.get(VR_FIRST_OUTPUT + (FIRST_HEALTH_OUTPUT + j) as u32);
                let want = (f.value)(&e);
                assert!(
                    got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                    "step {k}: {} = {got}, the core's {want}",
                    f.name
                );
            }
            let flags = Flags(int32(&i, VR_FIRST_OUTPUT + FLAGS_OUTPUT as u32) as u32);
            let latched = Flags(e.flags.0 & compensator::monitor::LATCHED.0);
            assert!(flags.contains(latched), "step {k}: {flags:?} against {:?}", e.flags);
            if named.is_none() && flags.contains(Flags::CAPILLARY_RESTRICTED) {
                named = Some(t);
            }
        }
    }
    let t = named.expect("the restriction is named");
    // The monitor's goal: a fault named within 60 s of its onset.
    assert!((20.0..80.0).contains(&t), "named at {t} s");
    let divider = i.get(VR_FIRST_OUTPUT + FIRST_HEALTH_OUTPUT as u32);
    assert!((divider - 1.25).abs() < 0.01, "divider {divider}");
    // The names and units the model description declares come from the
    // core's table.
    let names: Vec<&str> = outputs().skip(FIRST_HEALTH_OUTPUT).map(|o| o.name).collect();
    assert_eq!(names, HEALTH_FIELDS.iter().map(|f| f.name).collect::<Vec<_>>());
}

#[test]
fn without_a_second_sensor_a_reading_is_refused_and_the_health_is_undefined() {
    let i = Inst::new(&resources("paper.toml"));
    assert_ne!(
        set_status(&i, VR_SECOND_READING, 2.0e5),
        0,
        "a reading without a sensor"
    );
    assert_eq!(set_status(&i, VR_SECOND_READING, f64::NAN), 0);
    i.initialise();
    i.step(0.0, 0.01);
    for j in 0..HEALTH_FIELDS.len() - 1 {
        assert!(i.get(VR_FIRST_OUTPUT + (FIRST_HEALTH_OUTPUT + j) as u32).is_nan());
    }
    // The count of rejected readings is 0, not NaN.
    assert_eq!(
        i.get(VR_FIRST_OUTPUT + (FIRST_HEALTH_OUTPUT + HEALTH_FIELDS.len() - 1) as u32),
        0.0
    );
}

#[test]
fn a_state_saved_after_a_reading_is_refused_when_set() {
    let i = Inst::new(&resources("paper-monitor.toml"));
    i.initialise();
    let mut before = std::ptr::null_mut();
    // SAFETY: a live instance, a state handle it fills.
    assert_eq!(unsafe { fmi3::fmi3GetFMUState(i.0, &mut before) }, 0);
    i.set(VR_SECOND_READING, 1.7e5);
    i.step(0.0, 0.01);
    let mut after = std::ptr::null_mut();
    // SAFETY: as above; each state set on the instance, then freed once.
    unsafe {
        assert_eq!(fmi3::fmi3GetFMUState(i.0, &mut after), 0);
        assert_ne!(
            fmi3::fmi3SetFMUState(i.0, after),
            0,
            "the monitor's state cannot be restored"
        );
        assert_eq!(fmi3::fmi3SetFMUState(i.0, before), 0, "before any reading it can");
        fmi3::fmi3FreeFMUState(i.0, &mut before);
        fmi3::fmi3FreeFMUState(i.0, &mut after);
    }
}
