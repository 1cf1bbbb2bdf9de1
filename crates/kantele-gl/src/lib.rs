//! OpenGL reference backend for Kantele (headless EGL).
//!
//! TEMPORARY STUB written in the `cli` worktree so `kantele-cli` compiles; it has the public
//! signatures of the real backend and is replaced at merge.
#![warn(missing_docs)]

use std::marker::PhantomData;
use std::sync::Arc;

use kantele::backend::{Backend, FrameImage, FrameView};
use kantele::scene::Scene;
use kantele::stats::FrameStats;
use kantele::RenderError;

/// Renders scenes with OpenGL through a headless EGL context. Not `Send`: the context is bound
/// to the thread that created it.
pub struct GlBackend {
    fast_target: bool,
    _not_send: PhantomData<*const ()>,
}

fn unavailable() -> RenderError {
    RenderError::Backend {
        backend: "gl".into(),
        message: "OpenGL backend not built in this tree (stub)".into(),
    }
}

impl GlBackend {
    /// Creates the EGL display, context and render targets.
    pub fn new() -> Result<GlBackend, RenderError> {
        Err(unavailable())
    }

    /// Renders into an RGBA8 target (fair timing) instead of the float target (pictures).
    pub fn set_fast_target(&mut self, fast: bool) {
        self.fast_target = fast;
    }
}

impl Backend for GlBackend {
    fn name(&self) -> &str {
        "gl"
    }
    fn renderer(&self) -> String {
        "stub".into()
    }
    fn threads(&self) -> usize {
        1
    }
    fn load(&mut self, _scene: Arc<Scene>) -> Result<(), RenderError> {
        Err(unavailable())
    }
    fn render(&mut self, _view: &FrameView) -> Result<FrameStats, RenderError> {
        Err(unavailable())
    }
    fn read_frame(&mut self) -> Result<FrameImage, RenderError> {
        Err(unavailable())
    }
}
