//! Kantele (work in progress).
#![warn(missing_docs)]
pub mod backend;
pub mod camera;
pub mod color;
pub mod error;
pub mod scene;
pub mod shade;
pub mod stats;
pub use error::RenderError;
/// Largest render target side in pixels.
pub const MAX_TARGET_SIZE: u32 = 16384;
/// Most `f32` varyings a vertex can carry to the fragment stage.
pub const MAX_VARYINGS: usize = 16;
pub mod cpu;
pub mod raster;
