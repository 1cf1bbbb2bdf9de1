//! Fuzz target `ply`: see `kantele_testkit::fuzz_targets::ply`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_testkit::fuzz_targets::ply(data));
