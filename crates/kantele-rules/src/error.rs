//! The library's error type: every failure a caller cannot rule out up front.

use thiserror::Error;

/// An error from building render resources or submitting work.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RenderError {
    /// The render target is empty or larger than [`crate::MAX_TARGET_SIZE`] on a side.
    #[error("invalid render target size {width}x{height} (each side must be 1..={max})", max = crate::MAX_TARGET_SIZE)]
    InvalidSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
    },
    /// A render region (band of rows) that is empty or reaches past the target.
    #[error("invalid render region: rows {}..{} of a target {height} rows high", rows.0, rows.1)]
    InvalidRegion {
        /// The requested rows, `start..end`.
        rows: (u32, u32),
        /// The target's height.
        height: u32,
    },
    /// Memory for a render target or texture could not be reserved.
    #[error("out of memory: cannot reserve {bytes} bytes for {what}")]
    OutOfMemory {
        /// What was being allocated.
        what: &'static str,
        /// How much was asked for.
        bytes: usize,
    },
    /// A texture is empty or larger than [`crate::shade::texture::MAX_TEXTURE_SIZE`].
    #[error("invalid texture size {width}x{height}")]
    InvalidTextureSize {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
    },
    /// Texture data does not match its declared size.
    #[error("texture data has {actual} elements, expected {expected}")]
    InvalidTextureData {
        /// Elements expected from the size.
        expected: usize,
        /// Elements given.
        actual: usize,
    },
    /// A mip chain given level by level ([`crate::shade::texture::Texture::from_rgba8_levels`])
    /// lacks levels, has too many, or has a level of the wrong size.
    #[error("invalid mip chain: {0}")]
    InvalidMipChain(String),
    /// An index refers past the end of the vertex buffer.
    #[error("index {index} at position {position} is out of range for {vertex_count} vertices")]
    IndexOutOfRange {
        /// The offending index value.
        index: u32,
        /// Its position in the index buffer.
        position: usize,
        /// Number of vertices in the buffer.
        vertex_count: usize,
    },
    /// The index buffer does not hold whole triangles.
    #[error("index count {0} is not a multiple of 3")]
    IncompleteTriangle(usize),
    /// The index buffer of a line draw does not hold whole segments (an odd count).
    #[error("index count {0} of a line draw is not a multiple of 2")]
    IncompleteLine(usize),
    /// A vertex shader declared more varyings than the pipeline carries.
    #[error("shader declares {0} varyings, at most {max} are supported", max = crate::MAX_VARYINGS)]
    TooManyVaryings(usize),
    /// The draws of one frame would make more primitive-stage batches than a triangle
    /// reference can address (about 2^29 triangles; fewer with many small draws).
    #[error("a frame holds at most {max} triangles in {batches} batches; this draw would exceed it", max = crate::state::MAX_FRAME_BATCHES * 1024, batches = crate::state::MAX_FRAME_BATCHES)]
    FrameTooLarge,
    /// A scene refers to a mesh, material or texture that does not exist.
    #[error("scene is inconsistent: {0}")]
    InvalidScene(String),
    /// The backend cannot do what was asked.
    #[error("{backend} backend: {message}")]
    Unsupported {
        /// Backend name.
        backend: String,
        /// What is not supported.
        message: String,
    },
    /// A backend failed (driver error, lost context, ...).
    #[error("{backend} backend failed: {message}")]
    Backend {
        /// Backend name.
        backend: String,
        /// What went wrong.
        message: String,
    },
    /// The frame was cancelled by the caller's flag before it finished (the picture is partly
    /// drawn).
    #[error("frame cancelled")]
    Cancelled,
    /// The frame ran out of its time budget before it finished (the picture is partly drawn).
    #[error("frame stopped after its time budget of {} ms", budget.as_millis())]
    TimedOut {
        /// The budget it had.
        budget: std::time::Duration,
    },
}
