//! Fuzz target `gltf`: see `kantele_testkit::fuzz_targets::gltf`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_testkit::fuzz_targets::gltf(data));
