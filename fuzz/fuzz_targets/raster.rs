//! Fuzz target `raster`: see `kantele::fuzz_targets::raster`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| kantele::fuzz_targets::raster(data));
