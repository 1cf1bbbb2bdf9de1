//! Fuzz target `clip`: see `kantele::fuzz_targets::clip`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele::fuzz_targets::clip(data));
