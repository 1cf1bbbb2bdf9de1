//! Fuzz target `ktx2`: see `kantele_scene::fuzz_ktx2`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_scene::fuzz_ktx2(data));
