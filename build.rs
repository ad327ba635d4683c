//! Build script of the firmware package.
//!
//! 1. Puts the memory layout on the linker's search path as `memory.x`:
//!    `link/memory-qemu.x` (STM32F405: 1 MiB flash, 128 KiB RAM) for the
//!    QEMU images (the Cortex-M3 benchmark runs on QEMU's `netduino2`, an
//!    STM32F205 with the same map), `link/memory-board.x` for the board
//!    image (feature `board`: the stack alone in the core-coupled RAM, so
//!    that an overflow faults instead of corrupting `.bss`). No `memory.x`
//!    may sit in the workspace root: the linker runs there and would find
//!    it before the search path.
//! 2. For the firmware images (features `qemu`, `board`; host builds
//!    include no parameter file), turns the parameter file into constants
//!    (`$OUT_DIR/params.rs`): the file named by `COMPENSATOR_PARAMS`
//!    (default `presets/paper.toml`; a relative path is taken from the
//!    directory the command was run in, `$PWD`, as the CLI takes
//!    `--params`), read and validated by the same
//!    reader as the host tools, so that a device is only ever flashed with
//!    a valid parameter set. A refused file fails the build with one line
//!    naming the field (`cargo::error`, no backtrace).
//!    It also chooses the twin's configuration for the file (SDIRK3 and the
//!    substeps per tick that follow its dynamics to 0.1 % of a step:
//!    `compensator::dynamics::config::choose`, run here on the host), so
//!    that the cost per tick is decided before anything is flashed.
//! 3. For the QEMU images only (feature `qemu`): the QEMU twin's replay
//!    schedule, adapted to the device's validated and oil ranges, and the
//!    bounds it checks itself against (`$OUT_DIR/replay.rs`, and the same
//!    schedule as text in `$OUT_DIR/replay.txt` for the host-side replica
//!    of `cargo xtask test`), and the expectations of the on-target tests
//!    (`$OUT_DIR/expectations.rs`). Both are computed here, on the host, in
//!    `f64` by the independent reference (`compensator-reference`:
//!    bisection on each chamber's flow balance, Walther and density written
//!    from `docs/model.md`), never by the core. The board image needs none of it,
//!    and does not build the reference.

// The replay's template is only used for the QEMU images (feature `qemu`).
#![cfg_attr(not(feature = "qemu"), allow(dead_code))]

/// The injected faults, shared with the twin image and xtask's replica.
#[cfg(feature = "qemu")]
#[allow(dead_code)]
#[path = "src/replay_faults.rs"]
mod replay_faults;
use compensator_params::{Field, Named, RawCore, RawEstimator, RawMachine};
use std::path::PathBuf;
use std::{env, fs};

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    let target = env::var("TARGET").unwrap_or_default();
    let board = env::var_os("CARGO_FEATURE_BOARD").is_some();
    let firmware = board || env::var_os("CARGO_FEATURE_QEMU").is_some();

    if target.starts_with("thumb") {
        let layout = if board {
            "link/memory-board.x"
        } else {
            "link/memory-qemu.x"
        };
        fs::copy(manifest.join(layout), out.join("memory.x")).expect("copy the memory layout");
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rerun-if-changed={layout}");
    }

    if !firmware {
        // Host builds (CLI, host tests, xtask) include no parameter file:
        // COMPENSATOR_PARAMS neither rebuilds nor breaks them.
        println!("cargo:rerun-if-changed=build.rs");
        return;
    }
    println!("cargo:rerun-if-env-changed=COMPENSATOR_PARAMS");
    let params = match env::var_os("COMPENSATOR_PARAMS") {
        Some(p) => {
            let p = PathBuf::from(p);
            if p.is_absolute() {
                p
            } else {
                // Where the user ran cargo (cargo itself runs this script in
                // the package's directory).
                println!("cargo:rerun-if-env-changed=PWD");
                match env::var_os("PWD").map(PathBuf::from) {
                    Some(cwd) if cwd.is_absolute() => cwd.join(p),
                    _ => manifest.join(p),
                }
            }
        }
        None => manifest.join("presets/paper.toml"),
    };
    // `dir/../file` as `file`, in messages and for cargo (a missing file is
    // reported by the reader below).
    let params = fs::canonicalize(&params).unwrap_or(params);
    println!("cargo:rerun-if-changed={}", params.display());
    println!("cargo:rerun-if-changed=src/replay_faults.rs");
    let raw = match compensator_params::file::load(&params) {
        Ok(raw) => raw,
        Err(e) => {
            // One line naming the field; cargo fails the build after it.
            println!("cargo::error=parameter file {}: {e}", params.display());
            return;
        }
    };
    // The twin's configuration for this design, from its own dynamics.
    let choice = match twin_configuration(&raw) {
        Ok(c) => c,
        Err(e) => {
            println!(
                "cargo::error=parameter file {}: no twin configuration: {e}",
                params.display()
            );
            return;
        }
    };
    if !choice.goal_met {
        println!(
            "cargo::warning=parameter file {}: the twin's {} substeps per tick are estimated {:.3} % of a step off (target {} %)",
            params.display(),
            choice.config.substeps,
            choice.estimated_error_pct,
            compensator::dynamics::config::TARGET_PCT
        );
    }
    // Struct literals by field name (`spring_rate: 25684.5`): the constants
    // do not depend on the order of the fields.
    fn literal(ty: &str, fields: &[(Field, Named)]) -> String {
        let body = fields
            .iter()
            .map(|(f, n)| format!("{}: {:?}", f.name, n.value))
            .collect::<Vec<_>>()
            .join(", ");
        format!("::compensator::params::{ty} {{ {body} }}")
    }
    let core = literal("RawCore", &RawCore::FIELD.zip(raw.core.named()).into_array());
    let machine = match &raw.machine {
        Some(m) => format!(
            "Some({})",
            literal("RawMachine", &RawMachine::FIELD.zip(m.named()).into_array())
        ),
        None => "None".to_string(),
    };
    let estimator = literal(
        "RawEstimator",
        &RawEstimator::FIELD.zip(raw.estimator.named()).into_array(),
    );
    let code = format!(
        "// Generated by build.rs from {}\n\
         /// The parameter set the firmware was built with (validated at build time).\n\
         pub const RAW_PARAMS: ::compensator::params::RawParams = ::compensator::params::RawParams {{\n    \
         core: {core},\n    \
         machine: {machine},\n    \
         estimator: {estimator},\n}};\n\
         /// Where the parameters came from.\n\
         pub const PARAMS_SOURCE: &str = {:?};\n\
         /// The twin's scheme, by name (`compensator::dynamics::Scheme::from_name`),\n\
         /// chosen at build time for this parameter file.\n\
         pub const TWIN_SCHEME: &str = {:?};\n\
         /// The twin's steps per tick, chosen at build time for this parameter\n\
         /// file from its own dynamics (`compensator::dynamics::config::choose`).\n\
         pub const TWIN_SUBSTEPS: u8 = {};\n\
         /// The chooser's estimate of the twin's error [% of a step].\n\
         pub const TWIN_ESTIMATED_ERROR_PCT: f32 = {:?};\n",
        params.display(),
        params
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default(),
        choice.config.scheme.name(),
        choice.config.substeps,
        choice.estimated_error_pct as f32,
    );
    fs::write(out.join("params.rs"), code).expect("write params.rs");
    #[cfg(feature = "qemu")]
    {
        let replay = adapt(&raw.estimator);
        for note in &replay.notes {
            println!("cargo::warning={note}");
        }
        fs::write(out.join("replay.rs"), replay_rs(&raw.core, &raw.estimator, &replay)).expect("write replay.rs");
        fs::write(out.join("replay.txt"), replay.schedule()).expect("write replay.txt");
        fs::write(out.join("expectations.rs"), expectations(&raw.core)).expect("write expectations.rs");
    }
}

/// The twin's configuration for `raw` at its tick over its validated range
/// and down to its coldest oil (`compensator::dynamics::config::choose`).
fn twin_configuration(raw: &compensator_params::RawParams) -> Result<compensator::dynamics::config::Choice, String> {
    let p = compensator::Params::<f64>::new(raw).map_err(|e| e.to_string())?;
    let e = &raw.estimator;
    compensator::dynamics::config::choose(&p, 1.0 / e.tick_hz, (e.valid_min, e.valid_max)).map_err(|e| e.to_string())
}

/// Temperature pieces of the replay: (start [s], end [s], from [C], to [C]).
/// A piece with `from == to` is a hold, checked at its end against the
/// reference; one that starts more than `spike_threshold` away from the
/// level before it is a real step the spike filter must accept.
const PIECES: [(f64, f64, f64, f64); 10] = [
    (0.0, 3.0, 26.0, 26.0),   // cold start: window closed
    (3.0, 55.0, 26.0, 78.0),  // warm-up ramp, 1 C/s
    (55.0, 58.0, 78.0, 78.0), // hot hold
    (58.0, 62.0, 40.0, 40.0), // step down (a spike first, then a real step)
    (62.0, 66.0, 60.0, 60.0), // step up
    (66.0, 68.0, 90.0, 90.0), // outside the validated range
    (68.0, 74.0, 50.0, 50.0), // back, through a sensor outage
    // The cold excursion: hot oil, then cold (outside the validated range,
    // window closed), then warming back onto the closed stop.
    (74.0, 76.0, 80.0, 80.0),
    (76.0, 79.0, 10.0, 10.0),
    (79.0, 82.0, 30.0, 30.0),
];

/// Time the filter needs to leave the validated range after a step out of
/// it [s] (a few of its 0.2 s time constants would do; half a second is
/// ample for the 60 -> 90 C step).
const OUT_OF_RANGE_DELAY: f64 = 0.5;

/// Margin kept inside the oil range by the replay's temperatures [C]: a
/// sample outside `estimator.oil_min..oil_max` is a sensor fault, not a
/// temperature.
const OIL_MARGIN: f64 = 1.0;

/// Room the out-of-range hold needs beyond the validated range [C].
const OUT_OF_RANGE_ROOM: f64 = 2.0;

/// How far the template's out-of-range hold lies beyond the validated
/// range (90 C against 78 C) [C].
const OUT_OF_RANGE_DEPTH: f64 = 12.0;

/// The replay as run for this device.
#[cfg(feature = "qemu")]
struct Replay {
    /// (start s, end s, from C, to C).
    pieces: Vec<(f64, f64, f64, f64)>,
    /// When OUT_OF_RANGE must be raised (from s, to s); `None` when the
    /// oil range leaves no room outside the validated one.
    out_of_range: Option<(f64, f64)>,
    /// What the injected spike adds to the temperature [C].
    spike: f64,
    /// What could not be adapted (shown as build warnings).
    notes: Vec<String>,
}

#[cfg(feature = "qemu")]
impl Replay {
    /// Temperature of the replay at `t` [s].
    fn temperature_at(&self, t: f64) -> f64 {
        for &(t0, t1, a, b) in &self.pieces {
            if t >= t0 && t < t1 {
                return a + (b - a) * (t - t0) / (t1 - t0);
            }
        }
        self.pieces.last().map_or(0.0, |p| p.3)
    }

    /// The schedule as text, one item a line (read by `cargo xtask`).
    fn schedule(&self) -> String {
        let mut s =
            String::from("# The QEMU twin's replay, generated by build.rs (read by cargo xtask's host-side replica)\n");
        for (a, b, c, d) in &self.pieces {
            s += &format!("piece {a:?} {b:?} {c:?} {d:?}\n");
        }
        s += &format!("spike_delta {:?}\n", self.spike);
        s
    }
}

/// The template replay (`PIECES`, and the faults of `src/replay_faults.rs`, written for the paper's 26-78 C
/// and -20..150 C) adapted to a device's ranges, so that any parameter file
/// the CLI accepts builds the QEMU twin: every temperature inside the oil
/// range; an out-of-range hold outside the validated range (the template's
/// if it is, else the hottest hold moved above it, or the coldest below,
/// where the oil range leaves room); a spike larger than the spike
/// threshold that stays inside the oil range.
#[cfg(feature = "qemu")]
fn adapt(est: &compensator_params::RawEstimator) -> Replay {
    let (oil_lo, oil_hi) = (est.oil_min + OIL_MARGIN, est.oil_max - OIL_MARGIN);
    let (valid_lo, valid_hi) = (est.valid_min, est.valid_max);
    let clamp = |t: f64| {
        if oil_lo < oil_hi {
            t.clamp(oil_lo, oil_hi)
        } else {
            (est.oil_min + est.oil_max) / 2.0
        }
    };
    let mut notes = Vec::new();
    let mut pieces: Vec<(f64, f64, f64, f64)> = PIECES.iter().map(|&(a, b, c, d)| (a, b, clamp(c), clamp(d))).collect();
    let outside = |t: f64| !(valid_lo..=valid_hi).contains(&t);
    let is_hold = |p: &(f64, f64, f64, f64)| p.2 == p.3;
    if !pieces.iter().any(|p| is_hold(p) && outside(p.3)) {
        let above = oil_hi - valid_hi;
        let below = valid_lo - oil_lo;
        let hottest = (0..pieces.len())
            .filter(|&i| is_hold(&pieces[i]))
            .max_by(|&i, &j| pieces[i].3.total_cmp(&pieces[j].3));
        let coldest = (0..pieces.len())
            .filter(|&i| is_hold(&pieces[i]))
            .min_by(|&i, &j| pieces[i].3.total_cmp(&pieces[j].3));
        if let (Some(i), true) = (hottest, above >= OUT_OF_RANGE_ROOM) {
            let t = valid_hi + OUT_OF_RANGE_DEPTH.min(above);
            pieces[i].2 = t;
            pieces[i].3 = t;
        } else if let (Some(i), true) = (coldest, below >= OUT_OF_RANGE_ROOM) {
            let t = valid_lo - OUT_OF_RANGE_DEPTH.min(below);
            pieces[i].2 = t;
            pieces[i].3 = t;
        } else {
            notes.push(format!(
                "the validated range {valid_lo}..{valid_hi} C leaves no room inside the oil range {}..{} C: the QEMU twin does not check OUT_OF_RANGE",
                est.oil_min, est.oil_max
            ));
        }
    }
    let out_of_range = pieces
        .iter()
        .find(|p| is_hold(p) && outside(p.3))
        .map(|p| (p.0 + OUT_OF_RANGE_DELAY, p.1));
    let mut replay = Replay {
        pieces,
        out_of_range,
        spike: 0.0,
        notes,
    };
    // The spike: out of the filter's band (more than spike_threshold away),
    // inside the oil range (else it is a sensor fault, not a spike).
    let at = replay_faults::FAULTS
        .iter()
        .find(|f| f.injected == replay_faults::Injected::Spike)
        .map_or(0.0, |f| f64::from(f.start));
    let t = replay.temperature_at(at);
    let want = (2.0 * est.spike_threshold).max(40.0);
    let (up, down) = (oil_hi - t, t - oil_lo);
    replay.spike = if up >= want {
        want
    } else if down >= want {
        -want
    } else if up >= down {
        up
    } else {
        -down
    };
    if replay.spike.abs() <= est.spike_threshold {
        replay.notes.push(format!(
            "the oil range leaves no room for a spike beyond estimator.spike_threshold = {}: the QEMU twin's spike check will fail",
            est.spike_threshold
        ));
    }
    replay
}

/// The replay's Rust constants and its checkpoints: at the end of each hold
/// inside the validated range the estimate must sit at the reference
/// equilibrium.
#[cfg(feature = "qemu")]
fn replay_rs(core: &compensator_params::RawCore, est: &compensator_params::RawEstimator, replay: &Replay) -> String {
    let mut s = String::from("// Generated by build.rs.\n");
    s += "/// Temperature pieces: (start s, end s, from C, to C).\n";
    s += &format!(
        "const REPLAY_PIECES: [(f32, f32, f32, f32); {}] = [\n",
        replay.pieces.len()
    );
    for (a, b, c, d) in &replay.pieces {
        s += &format!("    ({a:?}, {b:?}, {c:?}, {d:?}),\n");
    }
    s += "];\n";
    s += "/// What the injected spike adds to the temperature [C] (beyond the\n";
    s += "/// spike threshold, inside the oil range).\n";
    s += &format!("const SPIKE_DELTA: f32 = {:?};\n", replay.spike);
    let (from, to) = replay.out_of_range.unwrap_or((0.0, 0.0));
    s += "/// When the estimate must be flagged OUT_OF_RANGE: (from s, to s).\n";
    s += &format!("const OUT_OF_RANGE_HOLD: (f32, f32) = ({from:?}, {to:?});\n");
    s += "/// Whether the replay leaves the validated range at all (the oil\n";
    s += "/// range may leave no room beyond it).\n";
    s += &format!(
        "const OUT_OF_RANGE_REACHABLE: bool = {};\n",
        replay.out_of_range.is_some()
    );
    s += "/// Checkpoints from the f64 reference, over the sensor's quantization\n";
    s += "/// (half a code either side), at the end of every hold: (time s,\n";
    s += "/// temperature C, half code C, x min/max m, p_a min/max Pa, p_b min/max\n";
    s += "/// Pa, whether OUT_OF_RANGE is due: None when the quantization\n";
    s += "/// interval straddles a bound of the validated range).\n";
    let (valid_lo, valid_hi) = (est.valid_min, est.valid_max);
    let holds: Vec<(f64, f64)> = replay
        .pieces
        .iter()
        .filter(|p| p.2 == p.3)
        .map(|p| (p.1 - 0.001, p.3))
        .collect();
    s += &format!(
        "const CHECKPOINTS: [(f32, f32, f32, [f32; 6], Option<bool>); {}] = [\n",
        holds.len()
    );
    for (t, temp) in holds {
        let half = half_code(est, temp);
        let lo = compensator_reference::statics::equilibrium(core, temp - half);
        let hi = compensator_reference::statics::equilibrium(core, temp + half);
        // x and p_b rise with temperature, p_a falls.
        let bounds = [lo.x, hi.x, hi.p_a, lo.p_a, lo.p_b, hi.p_b].map(|v| v as f32);
        let outside = if temp + half < valid_lo || temp - half > valid_hi {
            Some(true)
        } else if temp - half >= valid_lo && temp + half <= valid_hi {
            Some(false)
        } else {
            None
        };
        s += &format!("    ({t:?}, {temp:?}, {:?}, {bounds:?}, {outside:?}),\n", half as f32);
    }
    s += "];\n";
    s += "/// Real steps (beyond the spike threshold from the level before):\n";
    s += "/// (start s, level C, half code C).\n";
    let steps: Vec<(f64, f64)> = replay
        .pieces
        .windows(2)
        .filter(|w| w[1].2 == w[1].3 && (w[1].2 - w[0].3).abs() > est.spike_threshold)
        .map(|w| (w[1].0, w[1].2))
        .collect();
    s += &format!("const REAL_STEPS: [(f32, f32, f32); {}] = [\n", steps.len());
    for (t, level) in steps {
        s += &format!("    ({t:?}, {level:?}, {:?}),\n", half_code(est, level) as f32);
    }
    s += "];\n";
    s
}

/// Half a MAX31865 code in degrees at `t` [C]: `(R_ref / 2^16) / (dR/dt)`,
/// with the device's Callendar-Van Dusen slope.
#[cfg(feature = "qemu")]
fn half_code(est: &compensator_params::RawEstimator, t: f64) -> f64 {
    (est.rtd_reference / 65536.0) / est.rtd_slope(t)
}

/// Host-computed values the core's `f32` results on the target are
/// checked against: (t C, nu m^2/s, rho kg/m^3, p_a Pa, p_b Pa, x m, Q0 m^3/s).
#[cfg(feature = "qemu")]
fn expectations(core: &compensator_params::RawCore) -> String {
    let mut s = String::from("// Generated by build.rs from the f64 reference.\n");
    let temps = [26.0, 30.0, 35.0, 40.0, 50.0, 60.0, 70.0, 78.0];
    s += &format!(
        "pub const EXPECTED: [(f32, f64, f64, f64, f64, f64, f64); {}] = [\n",
        temps.len()
    );
    for t in temps {
        let (nu, rho) = compensator_reference::statics::oil(core, t);
        let e = compensator_reference::statics::equilibrium(core, t);
        s += &format!(
            "    ({t:?}, {nu:?}, {rho:?}, {:?}, {:?}, {:?}, {:?}),\n",
            e.p_a, e.p_b, e.x, e.q_total
        );
    }
    s += "];\n";
    s
}
