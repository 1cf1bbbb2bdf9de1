//! Fuzz target `gltf`: see `kantele_scene::fuzz_targets::gltf`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele_scene::fuzz_targets::gltf(data));
