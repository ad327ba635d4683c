//! `cargo fuzz run twin`: see `compensator_fuzz::twin` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| compensator_fuzz::twin::run(data));
