//! `cargo fuzz run params_file`: see `compensator_fuzz::params_file` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| compensator_fuzz::params_file::run(data));
