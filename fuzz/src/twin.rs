//! Target `twin`: the dynamic twin driven by arbitrary temperature
//! sequences, in `f32`, `f64` and Q12.20 fixed point.
//!
//! Input ([`arbitrary::Unstructured`], in this order):
//!
//! * a byte: the scalar, `% 3` (0: `Twin<f32, f32>`, 1: `Twin<f64, f64>`,
//!   2: `Twin<f32, Fixed>`, the firmware's three);
//! * a design ([`input::design`]: the presets, or the paper preset with
//!   every core field scaled);
//! * a byte: the configuration: below `0xC0` the shipped one
//!   (`TwinConfig::SHIPPED`: SDIRK3, one step per 1 ms tick); else scheme
//!   `Scheme::ALL[b % 7]` with `1 + (b >> 3) % 4` substeps;
//! * a 16-bit code: the start temperature ([`input::temperature`]);
//! * then segments, up to 64, while bytes remain: a temperature code and
//!   a tick count byte (0-255); the twin is given the temperature
//!   (`set_temperature`, which may refuse it and keep the previous one),
//!   then ticks that many times (2,048 ticks at most in all).
//!
//! Checks, after every tick, whether it succeeded or failed
//! ([`check::twin_state`]): the state finite, `0 <= x <= stroke`, the
//! pressures within `PRESSURE_MARGIN` (4) `dp` of `[p_c, p_p]` in model
//! units and in SI. A failed tick is allowed where the twin may diverge
//! (a perturbed design, a scheme other than SDIRK), never on a preset with
//! an SDIRK scheme.
//!
//! Then the last temperature the twin took is held. With an SDIRK scheme
//! (L-stable, stops as events: its state at rest is the closed form's)
//! and a stable linearisation there, the twin must come to rest on the
//! closed-form equilibrium (in the twin's parameter type) within
//! [`check::AT_REST`] (1e-3) of the stroke and of `dp`: the hold lasts
//! until the state has stayed within a tenth of that for three of the
//! slowest time constants (`linearise`: `1 / min(-Re lambda)`), and at
//! most [`SETTLE_TIME_CONSTANTS`] of them plus 50 ms, or [`MIN_HOLD`] if
//! longer, when it must be within the tolerance (on the closed stop
//! [`MAX_STOP_HOLD`], the travel onto it being no linear decay). Designs
//! slower than [`MAX_HOLD`] (on the closed stop, whose
//! [`STOP_SETTLE_TIME_CONSTANTS`] slowest time constants exceed
//! [`MAX_STOP_HOLD`]) are not held.

use crate::check;
use crate::input::{Design, byte, design, temperature, word};
use arbitrary::Unstructured;
use compensator::dynamics::linear::linearise;
use compensator::dynamics::{Scheme, Twin, TwinConfig};
use compensator::equilibrium::{Stop, equilibrium};
use compensator::estimator::STOP_SETTLE_TIME_CONSTANTS;
use compensator::scalar::Fixed;
use compensator::{Float, Params, RawParams, Real};

/// Most segments of an input.
pub const SEGMENTS: usize = 64;
/// Most ticks of the segments of an input.
pub const SEGMENT_TICKS: u32 = 2048;
/// Longest hold at the end [s]: slower designs are not held.
pub const MAX_HOLD: f64 = 10.0;
/// The hold's cap, in slowest time constants (plus 50 ms).
pub const SETTLE_TIME_CONSTANTS: f64 = 20.0;
/// Longest hold [s] when the closed form is on the closed stop, whose cap
/// is the estimator's [`STOP_SETTLE_TIME_CONSTANTS`] slowest time
/// constants (plus 50 ms): slower designs are not held.
pub const MAX_STOP_HOLD: f64 = 60.0;
/// Shortest cap of the hold [s] (the travel onto a stop in cold oil).
pub const MIN_HOLD: f64 = 5.0;
/// The early end of the hold: within `AT_REST / 10` for this many slowest
/// time constants.
pub const RESTING_TIME_CONSTANTS: f64 = 3.0;

/// An input, decoded.
pub struct Input {
    /// 0: `f32`, 1: `f64`, 2: fixed point.
    pub scalar: u8,
    /// Where the parameters come from.
    pub design: Design,
    /// The parameters.
    pub raw: RawParams,
    /// The twin's configuration.
    pub config: TwinConfig,
    /// The start temperature [C].
    pub start: f64,
    /// `(temperature [C], ticks)`.
    pub segments: Vec<(f64, u8)>,
}

/// Decodes an input (the module docs have the format).
pub fn decode(data: &[u8]) -> Input {
    let mut u = Unstructured::new(data);
    let scalar = byte(&mut u) % 3;
    let (design, raw) = design(&mut u);
    let c = byte(&mut u);
    let config = if c < 0xC0 {
        TwinConfig::SHIPPED
    } else {
        TwinConfig {
            scheme: Scheme::ALL[usize::from(c % 7)],
            substeps: 1 + (c >> 3) % 4,
            ..TwinConfig::SHIPPED
        }
    };
    let start = temperature(word(&mut u));
    let mut segments = Vec::with_capacity(SEGMENTS);
    while !u.is_empty() && segments.len() < SEGMENTS {
        segments.push((temperature(word(&mut u)), byte(&mut u)));
    }
    Input {
        scalar,
        design,
        raw,
        config,
        start,
        segments,
    }
}

/// One input.
pub fn run(data: &[u8]) {
    let input = decode(data);
    let raw = input.raw;
    let Ok(p64) = Params::<f64>::new(&raw) else {
        return;
    };
    let case = Case {
        raw: &raw,
        design: input.design,
        config: input.config,
        start: input.start,
        segments: &input.segments,
        p64: &p64,
    };
    match input.scalar {
        0 => {
            if let Ok(p) = Params::<f32>::new(&raw) {
                drive::<f32, f32>(&case, &p);
            }
        }
        1 => drive::<f64, f64>(&case, &p64),
        _ => {
            if let Ok(p) = Params::<f32>::new(&raw) {
                drive::<f32, Fixed>(&case, &p);
            }
        }
    }
}

/// What a run is given.
pub struct Case<'a> {
    /// The parameter set.
    pub raw: &'a RawParams,
    /// Where it comes from.
    pub design: Design,
    /// The twin's configuration.
    pub config: TwinConfig,
    /// The start temperature [C].
    pub start: f64,
    /// `(temperature [C], ticks)`.
    pub segments: &'a [(f64, u8)],
    /// The parameters in `f64` (the linearisation).
    pub p64: &'a Params<f64>,
}

/// Runs one case on `Twin<F, T>`; panics on a broken promise.
pub fn drive<F: Float, T: Real>(case: &Case, p: &Params<F>) {
    let Ok(mut twin) = Twin::<F, T>::new(p, case.config, F::from_f64(case.start)) else {
        return;
    };
    let sdirk = matches!(case.config.scheme, Scheme::Sdirk2 | Scheme::Sdirk3);
    let must_not_fail = sdirk && matches!(case.design, Design::Preset(_));
    let name = || format!("Twin<{}, {}> {:?} {:?}", F::NAME, T::NAME, case.config, case.raw);
    let mut held = F::from_f64(case.start);
    check::twin_state(&twin, p, &|| format!("{} at start {} C", name(), case.start));
    let mut ticks = 0u32;
    for (i, &(t, n)) in case.segments.iter().enumerate() {
        let t = F::from_f64(t);
        if twin.set_temperature(t).is_ok() {
            held = t;
        }
        for k in 0..n {
            if ticks >= SEGMENT_TICKS {
                break;
            }
            ticks += 1;
            let result = twin.tick();
            let what = || format!("{}: segment {i} ({t:?} C), tick {k}: {result:?}", name());
            check::twin_state(&twin, p, &what);
            if result.is_err() {
                assert!(!must_not_fail, "{}: the tick failed", what());
                return;
            }
        }
    }
    if !sdirk {
        return;
    }
    hold(case, p, &mut twin, held, must_not_fail, &name);
}

/// Holds `t` until the twin rests (see the module docs).
fn hold<F: Float, T: Real>(
    case: &Case,
    p: &Params<F>,
    twin: &mut Twin<F, T>,
    t: F,
    must_not_fail: bool,
    name: &dyn Fn() -> String,
) {
    let Ok(eq) = equilibrium(p, t) else {
        return;
    };
    let Ok(lin) = linearise(case.p64, t.to_f64()) else {
        return;
    };
    if !lin.stable {
        return;
    }
    let slowest = lin.eigenvalues.iter().map(|l| -l.re).fold(f64::INFINITY, f64::min);
    let tau = 1.0 / slowest;
    // The travel onto the closed stop is no linear decay: through cold oil
    // the plunger crosses its stroke at the speed the capillary's flow
    // allows (a whole stroke in ~12 s at -79 C on a random design whose
    // slowest time constant is 0.19 s), in up to ~110 of those time
    // constants on 1,000 seeded designs (docs/fuzzing.md, O2 and F6).
    let closed = matches!(eq.stop, Stop::Closed);
    let (constants, longest) = if closed {
        (f64::from(STOP_SETTLE_TIME_CONSTANTS), MAX_STOP_HOLD)
    } else {
        (SETTLE_TIME_CONSTANTS, MAX_HOLD)
    };
    let cap = constants * tau + 0.05;
    if !(cap <= longest) {
        return;
    }
    // Nor do those time constants bound it: the travel's speed is the
    // chambers' flows', a whole stroke at -0.55 mm/s taking 7.9 s at
    // -80 C on a design whose 150 time constants are 7.8 s (docs/fuzzing.md,
    // F7). On the closed stop the hold lasts up to `MAX_STOP_HOLD`, ending
    // early once at rest.
    let cap = if closed { longest } else { cap };
    // The linearisation at a stop is the free motion there: a plunger
    // driven a whole stroke onto the closed stop through cold oil arrives
    // in up to ~110 of those time constants (docs/fuzzing.md, O2;
    // `cargo run --release -p host-tests --example settling`): hence the
    // floor of MIN_HOLD.
    let cap = cap.max(MIN_HOLD);
    let tick = case.config.tick;
    let max_ticks = (cap / tick).ceil() as u32;
    let resting = ((RESTING_TIME_CONSTANTS * tau / tick).ceil() as u32).max(20);
    let mut within = 0u32;
    for k in 0..max_ticks {
        let result = twin.tick();
        let what = || format!("{}: held at {t:?} C, tick {k}: {result:?}", name());
        check::twin_state(twin, p, &what);
        if result.is_err() {
            assert!(!must_not_fail, "{}: the tick failed", what());
            return;
        }
        if check::off_rest(&twin.state(), &eq, p) <= 0.1 * check::AT_REST {
            within += 1;
            if within >= resting {
                return;
            }
        } else {
            within = 0;
        }
    }
    let off = check::off_rest(&twin.state(), &eq, p);
    assert!(
        off <= check::AT_REST,
        "{}: held at {t:?} C for {max_ticks} ticks ({SETTLE_TIME_CONSTANTS} x {tau:.3e} s + 50 ms), \
         the state {:?} is {off:.3e} from the closed form {eq:?}",
        name(),
        twin.state()
    );
}
