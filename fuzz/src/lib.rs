//! The fuzz targets' bodies (`fuzz_targets/*.rs` call `run` of the module
//! of the same name) and the invariants they check. docs/fuzzing.md has
//! the input formats, the checks and the figures of the long run.
//!
//! Every target decodes its bytes with [`arbitrary::Unstructured`] read
//! in a fixed order (integers little-endian, `f64` from its bits; missing
//! bytes read as zero), so that a seed is written by hand ([`seeds`]) and
//! a crash input reads back as the values it stands for. `cargo fuzz run
//! TARGET FILE` replays one input; the panic message says which check
//! failed and with what values.
//!
//! A check that fails panics: libFuzzer records the input as a crash.

pub mod check;
pub mod estimator;
pub mod input;
pub mod params_file;
pub mod raw_params;
pub mod seeds;
pub mod twin;
