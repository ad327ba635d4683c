//! Target `params_file`: arbitrary bytes as a parameter file.
//!
//! Input: the bytes of a file. Bytes that are not UTF-8 are no parameter
//! file (`file::load` refuses them when reading); the rest goes through
//! `compensator_params::file::parse` (TOML, known keys, numbers, defaults,
//! validation). Checks:
//!
//! * an error's `Display` is one line (what the CLI and the firmware's
//!   build script print), and a refused value names a known field;
//! * an accepted file validates (`RawParams::validate`), converts to
//!   `Params<f64>` (or is refused as not representable, never otherwise),
//!   and `file::to_toml` writes it back as text that parses to the same
//!   parameter set;
//! * the closed-form equilibrium at the validated range's ends and middle,
//!   in `f64` and `f32`, keeps its promises ([`crate::check::equilibrium`]).

use crate::check;
use compensator::equilibrium::equilibrium;
use compensator::params::{CORE_FIELDS, ESTIMATOR_FIELDS, MACHINE_FIELDS, Problem};
use compensator::{Float, Params, RawParams};
use compensator_params::file::{LoadError, parse, to_toml};

/// One input.
pub fn run(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match parse(text) {
        Ok(raw) => accepted(&raw, text),
        Err(e) => refused(&e, text),
    }
}

fn refused(e: &LoadError, text: &str) {
    let shown = e.to_string();
    assert!(
        !shown.contains('\n') && !shown.is_empty(),
        "the error for {text:?} is not one line: {shown:?}"
    );
    if let LoadError::Param(p) = e {
        let known = CORE_FIELDS
            .iter()
            .chain(MACHINE_FIELDS.iter())
            .chain(ESTIMATOR_FIELDS.iter())
            .any(|f| f.path == p.field);
        assert!(known, "{text:?}: error names no field of the format: {p:?}");
    }
}

fn accepted(raw: &RawParams, text: &str) {
    if let Err(e) = raw.validate() {
        panic!("{text:?} was accepted, yet does not validate: {e}");
    }
    match Params::<f64>::new(raw) {
        Ok(p) => statics(&p, raw, text),
        Err(e) => assert!(
            matches!(e.problem, Problem::NotRepresentable(_)),
            "{text:?} was accepted, yet Params<f64> refuses it: {e}"
        ),
    }
    if let Ok(p) = Params::<f32>::new(raw) {
        statics(&p, raw, text);
    }
    let written = to_toml(raw);
    match parse(&written) {
        Ok(back) => assert!(
            back == *raw,
            "{text:?} reads as {raw:?}; written back as {written:?} it reads as {back:?}"
        ),
        Err(e) => panic!("{text:?} was accepted; written back as {written:?} it is refused: {e}"),
    }
}

/// The closed form at the validated range's ends and middle.
fn statics<F: Float>(p: &Params<F>, raw: &RawParams, text: &str) {
    let (lo, hi) = (raw.estimator.valid_min, raw.estimator.valid_max);
    for t in [lo, 0.5 * (lo + hi), hi] {
        if let Ok(e) = equilibrium(p, F::from_f64(t)) {
            check::equilibrium(p, &e, &|| format!("{} at {t} C, file {text:?}", F::NAME));
        }
    }
}
