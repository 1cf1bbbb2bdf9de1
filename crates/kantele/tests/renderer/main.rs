//! Integration tests of the `kantele` library: coverage, stages, multisampling, points and lines,
//! bands, robustness and the reference images.
//!
//! One test binary with a module per subject: a binary per file would compile the shared
//! generic code and link every dependency into each (in a clean build, 31 test binaries took a
//! quarter of CI's compile time).

#[path = "../common/mod.rs"]
mod common;

mod bands;
mod coverage;
mod isa_scenes;
mod multisample;
mod pipeline;
mod points_lines;
mod reference;
mod robustness;
mod target_format;
