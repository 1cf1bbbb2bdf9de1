//! Fuzz target `stl`: see `kantele_testkit::fuzz_targets::stl`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_testkit::fuzz_targets::stl(data));
