//! Fuzz target `draco`: see `kantele_testkit::fuzz_targets::draco`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_testkit::fuzz_targets::draco(data));
