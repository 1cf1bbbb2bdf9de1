//! Kantele set against OpenGL (Mesa's llvmpipe through EGL): agreement on every scene,
//! multisampling, near-plane precision, points and lines, loader features; PBR shading against
//! the rules evaluated directly; transmission against the rules fed with its backdrop.
//!
//! One test binary with a module per subject: a binary per file would compile the shared
//! generic code and link every dependency into each (in a clean build, 31 test binaries took a
//! quarter of CI's compile time).

#[path = "../common/mod.rs"]
mod common;

mod agreement;
mod loader_features;
mod multisample;
mod near_plane;
mod pbr;
mod points_lines;
mod render;
mod transmission;
