//! The C interfaces as an importer calls them: two instances in one
//! process, parameters set and refused, steps, outputs against the twin
//! driven directly (as `compensator step --precision f32` drives it),
//! reset, state get/set and serialisation round trips.

mod common;

use compensator::dynamics::{Twin, TwinConfig};
use compensator::{Params, RawParams};
use compensator_fmu::description::token;
use compensator_fmu::variables::{VR_FIRST_FIELD, VR_FIRST_OUTPUT, VR_T_OIL, VR_TIME, fields};
use compensator_fmu::{chosen_config, fmi2, fmi3};
use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

const OK: c_int = 0;
const DISCARD: c_int = 2;
const ERROR: c_int = 3;

fn paper() -> RawParams {
    compensator_params::file::load(&preset()).expect("the paper preset loads")
}

fn preset() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../presets/paper.toml")
}

/// A resources folder holding `text` as its params.toml.
fn resources(name: &str, text: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("fmu-{name}/resources"));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    std::fs::write(dir.join("params.toml"), text).expect("params.toml written");
    dir
}

fn paper_resources(name: &str) -> PathBuf {
    resources(name, &std::fs::read_to_string(preset()).expect("preset"))
}

fn vr_of(path: &str) -> u32 {
    VR_FIRST_FIELD + fields().position(|f| f.path == path).expect("a field") as u32
}

/// Messages each FMI 3.0 instance logged (keyed by its environment).
struct Log(Mutex<Vec<String>>);

unsafe extern "C" fn log3(env: *mut c_void, _status: c_int, _category: *const c_char, message: *const c_char) {
    // SAFETY: the environment is the `Log` the test passed; the message a C
    // string.
    unsafe {
        let log = &*(env as *const Log);
        log.0
            .lock()
            .expect("log")
            .push(CStr::from_ptr(message).to_string_lossy().into_owned());
    }
}

struct Fmu3 {
    inst: *mut c_void,
    log: Box<Log>,
}

impl Fmu3 {
    fn try_new(dir: &Path, token: &str) -> (Option<Fmu3>, Vec<String>) {
        let log = Box::new(Log(Mutex::new(Vec::new())));
        // The log outlives the instance.
        let inst = common::instantiate(dir, token, &*log as *const Log as *mut c_void, Some(log3));
        let messages = log.0.lock().expect("log").clone();
        if inst.is_null() {
            (None, messages)
        } else {
            (Some(Fmu3 { inst, log }), messages)
        }
    }

    fn new(dir: &Path) -> Fmu3 {
        Fmu3::try_new(dir, &token()).0.expect("instantiates")
    }

    fn messages(&self) -> Vec<String> {
        self.log.0.lock().expect("log").clone()
    }

    fn set(&self, vr: u32, v: f64) -> c_int {
        // SAFETY: one value reference, one value.
        unsafe { fmi3::fmi3SetFloat64(self.inst, &vr, 1, &v, 1) }
    }

    fn get(&self, vr: u32) -> f64 {
        let mut v = f64::NAN;
        // SAFETY: as `set`.
        assert_eq!(
            unsafe { fmi3::fmi3GetFloat64(self.inst, &vr, 1, &mut v, 1) },
            OK,
            "{:?}",
            self.messages()
        );
        v
    }

    fn flags(&self) -> i32 {
        let vr = VR_FIRST_OUTPUT + 9;
        let mut v = -1;
        // SAFETY: as `set`.
        assert_eq!(unsafe { fmi3::fmi3GetInt32(self.inst, &vr, 1, &mut v, 1) }, OK);
        v
    }

    fn init(&self, start: f64) -> c_int {
        // SAFETY: a live instance.
        unsafe {
            assert_eq!(
                fmi3::fmi3EnterInitializationMode(self.inst, false, 0.0, start, false, 0.0),
                OK
            );
            fmi3::fmi3ExitInitializationMode(self.inst)
        }
    }

    fn step(&self, t: f64, h: f64) -> c_int {
        let (mut a, mut b, mut c, mut last) = (true, true, true, f64::NAN);
        // SAFETY: a live instance, valid out-pointers.
        let s = unsafe { fmi3::fmi3DoStep(self.inst, t, h, false, &mut a, &mut b, &mut c, &mut last) };
        assert!(!a && !b && !c);
        assert_eq!(last, self.get(VR_TIME));
        s
    }

    /// `[x, v, p_a, p_b]`.
    fn state(&self) -> [f64; 4] {
        [0, 1, 2, 3].map(|i| self.get(VR_FIRST_OUTPUT + i))
    }
}

impl Drop for Fmu3 {
    fn drop(&mut self) {
        // SAFETY: freed once.
        unsafe { fmi3::fmi3FreeInstance(self.inst) }
    }
}

/// The twin driven as `compensator step --precision f32` drives it: at
/// rest at `from`, each tick's temperature set before the tick; the states
/// after each tick.
fn direct(raw: &RawParams, from: f32, temps: &[f32]) -> Vec<[f64; 4]> {
    let p = Params::<f32>::new(raw).expect("valid");
    let mut twin = Twin::<f32, f32>::new(&p, chosen_config(raw).expect("chosen"), from).expect("twin");
    temps
        .iter()
        .map(|&t| {
            twin.set_temperature(t).expect("temperature");
            twin.tick().expect("tick");
            let s = twin.state();
            [s.x as f64, s.v as f64, s.p_a as f64, s.p_b as f64]
        })
        .collect()
}

#[test]
fn a_step_and_a_ramp_follow_the_twin_exactly_in_two_instances() {
    let dir = paper_resources("two");
    let raw = paper();
    let tick = 1.0 / raw.estimator.tick_hz;
    let (a, b) = (Fmu3::new(&dir), Fmu3::new(&dir));
    assert_eq!(a.set(VR_T_OIL, 40.0), OK);
    assert_eq!(b.set(VR_T_OIL, 70.0), OK);
    assert_eq!(a.init(0.0), OK, "{:?}", a.messages());
    assert_eq!(b.init(0.0), OK);
    // a: a step 40 -> 60 C; b: a ramp 70 -> 30 C at 100 C/s, each tick's
    // temperature its midpoint's; interleaved, one tick per step.
    let n = 300;
    let step_temps = vec![60.0f32; n];
    let ramp = |k: usize| (70.0 - 100.0 * (k as f64 + 0.5) * tick).max(30.0);
    let ramp_temps: Vec<f32> = (0..n).map(|k| ramp(k) as f32).collect();
    let (want_a, want_b) = (direct(&raw, 40.0, &step_temps), direct(&raw, 70.0, &ramp_temps));
    for k in 0..n {
        let t = k as f64 * tick;
        assert_eq!(a.set(VR_T_OIL, 60.0), OK);
        assert_eq!(b.set(VR_T_OIL, ramp(k)), OK);
        assert_eq!(a.step(t, tick), OK);
        assert_eq!(b.step(t, tick), OK);
        assert_eq!(a.state(), want_a[k], "step, tick {k}");
        assert_eq!(b.state(), want_b[k], "ramp, tick {k}");
    }
    // The two really moved, apart: the step opens, the ramp closes.
    assert!(a.state()[0] > 0.0 && (a.state()[0] - b.state()[0]).abs() > 1e-5);
    assert!((a.get(VR_TIME) - n as f64 * tick).abs() < 1e-12);
    // Flows add up; the paper preset is monotonic, stable, in range.
    let q: Vec<f64> = (4..8).map(|i| a.get(VR_FIRST_OUTPUT + i)).collect();
    assert!((q[0] + q[1] + q[2] - q[3]).abs() <= 1e-6 * q[3].abs(), "{q:?}");
    assert_eq!(a.flags() & !1, 0);
}

#[test]
fn several_ticks_per_step_equal_one_tick_per_step() {
    let dir = paper_resources("multi");
    let raw = paper();
    let tick = 1.0 / raw.estimator.tick_hz;
    let (a, b) = (Fmu3::new(&dir), Fmu3::new(&dir));
    for f in [&a, &b] {
        f.set(VR_T_OIL, 35.0);
        assert_eq!(f.init(2.0), OK);
        f.set(VR_T_OIL, 75.0);
    }
    for k in 0..50 {
        assert_eq!(a.step(2.0 + k as f64 * 10.0 * tick, 10.0 * tick), OK);
    }
    for k in 0..500 {
        assert_eq!(b.step(2.0 + k as f64 * tick, tick), OK);
    }
    assert_eq!(a.state(), b.state());
    assert!((a.get(VR_TIME) - 2.5).abs() < 1e-9);
}

/// The twin as `compensator step --precision f32 --dt TICK --substeps N`
/// drives it (built with that tick from the start): at rest at `from`,
/// each tick's temperature set before the tick; the states after each tick.
fn direct_at(raw: &RawParams, tick: f64, from: f32, to: f32, n: usize) -> Vec<[f64; 4]> {
    let p = Params::<f32>::new(raw).expect("valid");
    let config = TwinConfig {
        tick,
        ..chosen_config(raw).expect("chosen")
    };
    let mut twin = Twin::<f32, f32>::new(&p, config, from).expect("twin");
    (0..n)
        .map(|_| {
            twin.set_temperature(to).expect("temperature");
            twin.tick().expect("tick");
            let s = twin.state();
            [s.x as f64, s.v as f64, s.p_a as f64, s.p_b as f64]
        })
        .collect()
}

#[test]
fn steps_of_any_length_end_exactly_and_equal_the_twin_at_that_tick() {
    // 0.1 ms (sub-tick), 2.5 ms (between 2 and 3 ticks: 3 ticks of 5/6 ms),
    // 1/3 ms: each the twin built with the tick h / ceil(h / tick), what
    // `compensator step --dt` runs, to the last bit.
    let raw = paper();
    let tick = 1.0 / raw.estimator.tick_hz;
    for (h, ticks_per_step) in [(1e-4, 1), (2.5e-3, 3), (1.0 / 3.0 * 1e-3, 1)] {
        let f = Fmu3::new(&paper_resources("any step"));
        f.set(VR_T_OIL, 40.0);
        assert_eq!(f.init(0.0), OK);
        f.set(VR_T_OIL, 60.0);
        let steps = (0.06 / h) as usize;
        let want = direct_at(&raw, h / ticks_per_step as f64, 40.0, 60.0, steps * ticks_per_step);
        let mut t = 0.0;
        for k in 0..steps {
            assert_eq!(f.step(t, h), OK, "{h} s, step {k}: {:?}", f.messages());
            t += h;
            assert_eq!(f.state(), want[(k + 1) * ticks_per_step - 1], "{h} s, step {k}");
            assert_eq!(f.get(VR_TIME), t);
        }
        assert!(f.state()[0] > 1e-4, "the plunger moved");
        assert_eq!(tick, 1e-3);
    }
}

#[test]
fn a_variable_step_sequence_matches_the_twin_step_by_step() {
    // Whole ticks, sub-ticks and steps between counts mixed: each step the
    // twin at that step's tick, carried over from the step before.
    let raw = paper();
    let p = Params::<f32>::new(&raw).expect("valid");
    let config = chosen_config(&raw).expect("chosen");
    let mut twin = Twin::<f32, f32>::new(&p, config, 35.0).expect("twin");
    let f = Fmu3::new(&paper_resources("variable"));
    f.set(VR_T_OIL, 35.0);
    assert_eq!(f.init(0.0), OK);
    let sequence = [
        1e-3,
        1e-4,
        2.5e-3,
        3e-3,
        1.0 / 3.0 * 1e-3,
        7e-4,
        1.7e-3,
        1e-3,
        5e-5,
        1e-2,
    ];
    let mut t = 0.0;
    for (k, h) in sequence.iter().cycle().take(200).enumerate() {
        let temp = 35.0 + 40.0 * ((k / 20) % 2) as f32;
        f.set(VR_T_OIL, temp as f64);
        assert_eq!(f.step(t, *h), OK);
        t += h;
        let n = (h / config.tick - 1e-6).ceil().max(1.0);
        twin.set_temperature(temp).expect("temperature");
        twin.set_tick(if n * config.tick == *h { config.tick } else { h / n })
            .expect("tick");
        for _ in 0..n as usize {
            twin.tick().expect("tick");
        }
        let s = twin.state();
        assert_eq!(
            f.state(),
            [s.x as f64, s.v as f64, s.p_a as f64, s.p_b as f64],
            "step {k} of {h} s"
        );
        assert_eq!(f.get(VR_TIME), t);
    }
}

#[test]
fn a_step_the_instance_cannot_take_is_discarded_and_logged() {
    let f = Fmu3::new(&paper_resources("refused step"));
    assert_eq!(f.init(0.0), OK);
    let before = f.state();
    for h in [0.0, -0.001, f64::NAN, f64::INFINITY, 1e5] {
        assert_eq!(f.step(0.0, h), DISCARD, "{h}");
    }
    assert!(
        f.messages().iter().any(|m| m.contains("must be positive and finite")),
        "{:?}",
        f.messages()
    );
    assert!(f.messages().iter().any(|m| m.contains("take shorter steps")));
    assert_eq!(f.get(VR_TIME), 0.0);
    assert_eq!(f.state(), before);
    assert_eq!(
        f.step(0.5, 0.001),
        DISCARD,
        "a communication point not the instance's time"
    );
    assert_eq!(f.step(1e-4, 0.001), DISCARD, "a skipped sub-tick step");
    // It goes on.
    assert_eq!(f.step(0.0, 0.002), OK);
}

#[test]
fn a_bad_parameter_is_refused_naming_the_field() {
    let dir = paper_resources("bad");
    let f = Fmu3::new(&dir);
    assert_eq!(f.set(vr_of("plunger.stroke"), -1.0), ERROR);
    assert!(
        f.messages().last().expect("logged").starts_with("plunger.stroke"),
        "{:?}",
        f.messages()
    );
    assert_eq!(f.set(vr_of("fluid.walther_a"), f64::NAN), ERROR);
    assert!(f.messages().last().expect("logged").starts_with("fluid.walther_a"));
    // Each in its range, together against a rule: refused when
    // initialisation ends, naming the field.
    let stroke = f.get(vr_of("plunger.stroke"));
    assert_eq!(f.set(vr_of("plunger.preload"), 2.0 * stroke), OK);
    assert_eq!(f.init(0.0), ERROR);
    assert!(
        f.messages().last().expect("logged").contains("plunger.preload"),
        "{:?}",
        f.messages()
    );
    // Parameters are fixed after initialisation.
    let g = Fmu3::new(&dir);
    assert_eq!(g.init(0.0), OK);
    assert_eq!(g.set(vr_of("plunger.mass"), 1e-3), ERROR);
    assert!(g.messages().last().expect("logged").contains("plunger.mass"));
}

#[test]
fn an_invalid_packaged_file_or_token_fails_instantiation_cleanly() {
    let text: String = std::fs::read_to_string(preset())
        .expect("preset")
        .lines()
        .map(|l| {
            if l.starts_with("spring_rate") {
                "spring_rate = -5.0\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let dir = resources("invalid", &text);
    let (f, messages) = Fmu3::try_new(&dir, &token());
    assert!(f.is_none());
    assert!(
        messages.iter().any(|m| m.contains("plunger.spring_rate")),
        "{messages:?}"
    );
    let (f, messages) = Fmu3::try_new(&paper_resources("token"), "{not-the-token}");
    assert!(
        f.is_none() && messages[0].contains("instantiation token"),
        "{messages:?}"
    );
}

#[test]
fn a_changed_parameter_changes_the_twin() {
    let dir = paper_resources("changed");
    let (a, b) = (Fmu3::new(&dir), Fmu3::new(&dir));
    let k = b.get(vr_of("plunger.spring_rate"));
    assert_eq!(b.set(vr_of("plunger.spring_rate"), 1.5 * k), OK);
    assert_eq!(a.init(0.0), OK);
    assert_eq!(b.init(0.0), OK);
    let mut raw = paper();
    raw.core.spring_rate *= 1.5;
    let start = compensator_fmu::instance::t_oil_start(&raw) as f32;
    let eq = compensator::equilibrium::equilibrium(&Params::<f32>::new(&raw).expect("valid"), start).expect("eq");
    assert_eq!(b.get(VR_FIRST_OUTPUT) as f32, eq.x);
    assert!(a.get(VR_FIRST_OUTPUT) != b.get(VR_FIRST_OUTPUT));
}

#[test]
fn reset_returns_to_the_packaged_values() {
    let f = Fmu3::new(&paper_resources("reset"));
    f.set(VR_T_OIL, 30.0);
    assert_eq!(f.init(0.0), OK);
    let x0 = f.state();
    f.set(VR_T_OIL, 80.0);
    for k in 0..100 {
        f.step(k as f64 * 1e-3, 1e-3);
    }
    assert_ne!(f.state(), x0);
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi3::fmi3Reset(f.inst) }, OK);
    assert_eq!(f.get(vr_of("plunger.mass")), paper().core.mass);
    f.set(VR_T_OIL, 30.0);
    assert_eq!(f.init(0.0), OK);
    assert_eq!(f.state(), x0);
    assert_eq!(f.get(VR_TIME), 0.0);
}

#[test]
fn a_state_rolls_back_exactly_in_memory_and_serialised() {
    let dir = paper_resources("state");
    let f = Fmu3::new(&dir);
    f.set(VR_T_OIL, 30.0);
    assert_eq!(f.init(0.0), OK);
    f.set(VR_T_OIL, 80.0);
    for k in 0..20 {
        f.step(k as f64 * 1e-3, 1e-3);
    }
    let mut state = std::ptr::null_mut();
    // SAFETY: a live instance; the state is freed below.
    assert_eq!(unsafe { fmi3::fmi3GetFMUState(f.inst, &mut state) }, OK);
    let run = |f: &Fmu3| {
        (20..200)
            .map(|k| {
                f.set(VR_T_OIL, if k < 100 { 80.0 } else { 20.0 });
                assert_eq!(f.step(k as f64 * 1e-3, 1e-3), OK);
                (f.state(), f.flags())
            })
            .collect::<Vec<_>>()
    };
    let first = run(&f);
    // SAFETY: the state fmi3GetFMUState made.
    assert_eq!(unsafe { fmi3::fmi3SetFMUState(f.inst, state) }, OK);
    assert_eq!(f.get(VR_TIME), 0.02);
    assert_eq!(run(&f), first);
    // Serialised, into another instance.
    let mut size = 0;
    // SAFETY: as above, buffers of the size asked.
    let bytes = unsafe {
        assert_eq!(fmi3::fmi3SerializedFMUStateSize(f.inst, state, &mut size), OK);
        let mut bytes = vec![0u8; size];
        assert_eq!(fmi3::fmi3SerializeFMUState(f.inst, state, bytes.as_mut_ptr(), size), OK);
        assert_eq!(fmi3::fmi3FreeFMUState(f.inst, &mut state), OK);
        assert!(state.is_null());
        bytes
    };
    let g = Fmu3::new(&dir);
    let mut restored = std::ptr::null_mut();
    // SAFETY: as above.
    unsafe {
        assert_eq!(
            fmi3::fmi3DeserializeFMUState(g.inst, bytes.as_ptr(), size, &mut restored),
            OK
        );
        assert_eq!(fmi3::fmi3SetFMUState(g.inst, restored), OK);
        assert_eq!(fmi3::fmi3FreeFMUState(g.inst, &mut restored), OK);
    }
    assert_eq!(run(&g), first);
    // Bytes that are not a state are refused, and change nothing.
    let mut junk = std::ptr::null_mut();
    // SAFETY: as above.
    assert_eq!(
        unsafe { fmi3::fmi3DeserializeFMUState(g.inst, bytes.as_ptr(), size - 1, &mut junk) },
        ERROR
    );
    assert!(junk.is_null());
}

#[test]
fn an_unusable_temperature_is_flagged_not_used() {
    let f = Fmu3::new(&paper_resources("unusable"));
    assert_eq!(f.init(0.0), OK);
    let before = f.state();
    for (k, t) in [f64::NAN, 1e6, -300.0].into_iter().enumerate() {
        f.set(VR_T_OIL, t);
        assert_eq!(f.step(k as f64 * 1e-3, 1e-3), OK);
        assert_eq!(f.flags() & 16, 16, "SENSOR_FAULT at {t}");
        assert!(f.state().iter().all(|v| v.is_finite()));
    }
    // At rest at its last temperature, it stays there.
    assert!((f.state()[0] - before[0]).abs() <= 1e-9);
    f.set(VR_T_OIL, 95.0);
    assert_eq!(f.step(3e-3, 1e-3), OK);
    assert_eq!(f.flags() & (16 | 2), 2, "OUT_OF_RANGE above the validated range");
}

/// FMI 2.0: the same instance through the other interface.
struct Fmu2(*mut c_void);

impl Fmu2 {
    fn new(dir: &Path, guid: &str) -> Option<Fmu2> {
        let callbacks = fmi2::CallbackFunctions {
            logger: None,
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: std::ptr::null_mut(),
        };
        let name = CString::new("inst2").expect("name");
        let guid = CString::new(guid).expect("guid");
        let uri = CString::new(format!("file://{}", dir.display().to_string().replace(' ', "%20"))).expect("uri");
        // SAFETY: valid strings and callbacks (copied by the FMU).
        let c = unsafe { fmi2::fmi2Instantiate(name.as_ptr(), 1, guid.as_ptr(), uri.as_ptr(), &callbacks, 0, 0) };
        (!c.is_null()).then_some(Fmu2(c))
    }

    fn get(&self, vr: u32) -> f64 {
        let mut v = f64::NAN;
        // SAFETY: a live instance, one value.
        assert_eq!(unsafe { fmi2::fmi2GetReal(self.0, &vr, 1, &mut v) }, OK);
        v
    }

    fn set(&self, vr: u32, v: f64) -> c_int {
        // SAFETY: as `get`.
        unsafe { fmi2::fmi2SetReal(self.0, &vr, 1, &v) }
    }
}

impl Drop for Fmu2 {
    fn drop(&mut self) {
        // SAFETY: freed once.
        unsafe { fmi2::fmi2FreeInstance(self.0) }
    }
}

#[test]
fn fmi2_steps_refuses_and_rolls_back_as_fmi3() {
    let dir = paper_resources("fmi2 space");
    assert!(Fmu2::new(&dir, "{wrong}").is_none());
    let f = Fmu2::new(&dir, &token()).expect("instantiates");
    let g = Fmu3::new(&dir);
    assert_eq!(f.set(vr_of("plunger.stroke"), 0.0), ERROR);
    // SAFETY: a live instance throughout.
    unsafe {
        assert_eq!(fmi2::fmi2SetupExperiment(f.0, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2::fmi2EnterInitializationMode(f.0), OK);
        assert_eq!(fmi2::fmi2ExitInitializationMode(f.0), OK);
    }
    assert_eq!(g.init(0.0), OK);
    let mut state = std::ptr::null_mut();
    for k in 0..100 {
        let t = 40.0 + k as f64;
        f.set(VR_T_OIL, t);
        g.set(VR_T_OIL, t);
        // SAFETY: as above.
        assert_eq!(unsafe { fmi2::fmi2DoStep(f.0, k as f64 * 1e-3, 1e-3, 1) }, OK);
        g.step(k as f64 * 1e-3, 1e-3);
        assert_eq!([0, 1, 2, 3].map(|i| f.get(VR_FIRST_OUTPUT + i)), g.state());
        if k == 49 {
            // SAFETY: as above.
            assert_eq!(unsafe { fmi2::fmi2GetFMUstate(f.0, &mut state) }, OK);
        }
    }
    let end = f.get(VR_FIRST_OUTPUT);
    let mut flags = -1;
    let vr = VR_FIRST_OUTPUT + 9;
    // SAFETY: as above.
    unsafe {
        assert_eq!(fmi2::fmi2GetInteger(f.0, &vr, 1, &mut flags), OK);
        assert_eq!(flags, g.flags());
        assert_eq!(fmi2::fmi2DoStep(f.0, 0.1, -0.0005, 1), DISCARD);
        let mut last = f64::NAN;
        assert_eq!(fmi2::fmi2GetRealStatus(f.0, 2, &mut last), OK);
        assert!((last - 0.1).abs() < 1e-12);
        assert_eq!(fmi2::fmi2SetFMUstate(f.0, state), OK);
        assert_eq!(fmi2::fmi2FreeFMUstate(f.0, &mut state), OK);
    }
    for k in 50..100 {
        f.set(VR_T_OIL, 40.0 + k as f64);
        // SAFETY: as above.
        assert_eq!(unsafe { fmi2::fmi2DoStep(f.0, k as f64 * 1e-3, 1e-3, 1) }, OK);
    }
    assert_eq!(f.get(VR_FIRST_OUTPUT), end);
}
