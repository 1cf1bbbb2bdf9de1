//! Fuzz target `dds`: see `kantele_scene::fuzz_dds`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_scene::fuzz_dds(data));
