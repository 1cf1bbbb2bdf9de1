//! Fuzz target `obj`: see `kantele_testkit::fuzz_targets::obj`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_testkit::fuzz_targets::obj(data));
