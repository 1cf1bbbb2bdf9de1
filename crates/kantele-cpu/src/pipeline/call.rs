//! A recorded draw: its shader, vertices, index buffer, topology and state, as the stages read
//! them.

use super::shader::Shader;
use kantele_rules::state::{RenderState, Topology};

/// An index buffer.
#[derive(Clone, Copy, Debug)]
pub enum Indices<'a> {
    /// Vertices taken in order, three per triangle.
    None,
    /// 16-bit indices.
    U16(&'a [u16]),
    /// 32-bit indices.
    U32(&'a [u32]),
}

impl Indices<'_> {
    #[inline]
    pub(super) fn get(&self, i: usize) -> usize {
        match self {
            Indices::None => i,
            Indices::U16(ix) => ix[i] as usize,
            Indices::U32(ix) => ix[i] as usize,
        }
    }

    pub(super) fn len(&self, vertex_count: usize) -> usize {
        match self {
            Indices::None => vertex_count,
            Indices::U16(ix) => ix.len(),
            Indices::U32(ix) => ix.len(),
        }
    }
}

/// One queued draw, with its concrete shader (the stages' jobs are implemented on it in
/// `draw.rs`).
pub(super) struct DrawCall<'a, S: Shader> {
    pub(super) shader: &'a S,
    pub(super) vertices: &'a [S::Vertex],
    pub(super) indices: Indices<'a>,
    pub(super) topology: Topology,
    pub(super) state: RenderState,
}
