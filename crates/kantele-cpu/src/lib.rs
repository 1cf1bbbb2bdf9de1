//! Kantele's CPU backend: the whole pipeline on a pool of worker threads.
//!
//! User shaders ([`pipeline::Shader`]) transform vertices and shade fragments; between them
//! the fixed stages run here, by the rules of `kantele-rules`: the frame and its workers
//! ([`pipeline`]), the vertex and primitive stages (clipping and setup from the rules),
//! binning into 64 × 64 tiles and the traversal strategies ([`raster`]), the fragment kernels
//! over lanes (`kantele-lanes`), and the output merger — depth test, blending and the tiled
//! framebuffer ([`rop`]). [`cpu::CpuBackend`] draws scenes behind the
//! [`Backend`](kantele_rules::backend::Backend) interface with the built-in materials
//! ([`material`]).
//!
//! Pictures are deterministic: the same for every thread count, every traversal strategy and
//! every instruction set.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod band;
pub mod cpu;
/// Bodies of the fuzz targets in `fuzz/`, callable from stable tests (not a public API).
#[doc(hidden)]
pub mod fuzz_targets;
pub mod material;
pub mod pbr_material;
pub mod pipeline;
pub mod raster;
pub mod rop;
