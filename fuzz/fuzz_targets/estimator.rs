//! `cargo fuzz run estimator`: see `compensator_fuzz::estimator` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| compensator_fuzz::estimator::run(data));
