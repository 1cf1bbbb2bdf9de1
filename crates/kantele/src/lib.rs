//! Kantele: the whole graphics pipeline in software.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod backend;
pub mod camera;
pub mod color;
pub mod compare;
pub mod cpu;
pub mod demo;
pub mod error;
#[cfg(feature = "fault-injection")]
pub mod fault;
pub mod fixed;
pub mod geometry;
pub mod material;
pub mod pipeline;
pub mod raster;
pub mod rop;
pub mod scene;
pub mod setup;
pub mod shade;
pub mod stats;

pub use error::RenderError;

/// Largest render target side in pixels.
pub const MAX_TARGET_SIZE: u32 = 16384;
/// Most `f32` varyings a vertex can carry to the fragment stage.
pub const MAX_VARYINGS: usize = 16;
