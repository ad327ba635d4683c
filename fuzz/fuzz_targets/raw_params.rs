//! `cargo fuzz run raw_params`: see `compensator_fuzz::raw_params` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| compensator_fuzz::raw_params::run(data));
