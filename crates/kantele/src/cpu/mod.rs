//! The CPU backend: the software pipeline behind the [`Backend`] interface.

use std::sync::Arc;

use crate::backend::{Backend, FrameImage, FrameView};
use crate::error::RenderError;
use crate::raster::Strategy;
use crate::scene::Scene;
use crate::stats::FrameStats;

/// Options of the CPU backend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CpuOptions {
    /// Worker threads; `None` uses every core.
    pub threads: Option<usize>,
    /// Triangle traversal strategy.
    pub strategy: Strategy,
}

/// Renders scenes with Kantele's CPU pipeline.
pub struct CpuBackend {
    options: CpuOptions,
    scene: Option<Arc<Scene>>,
}

impl CpuBackend {
    /// A backend with the given options.
    pub fn new(options: CpuOptions) -> Result<Self, RenderError> {
        Ok(Self {
            options,
            scene: None,
        })
    }
}

impl Backend for CpuBackend {
    fn name(&self) -> &str {
        "cpu"
    }
    fn renderer(&self) -> String {
        format!("kantele cpu ({})", self.options.strategy.name())
    }
    fn threads(&self) -> usize {
        self.options.threads.unwrap_or(1)
    }
    fn load(&mut self, scene: Arc<Scene>) -> Result<(), RenderError> {
        self.scene = Some(scene);
        Ok(())
    }
    fn render(&mut self, _view: &FrameView) -> Result<FrameStats, RenderError> {
        Err(RenderError::Unsupported {
            backend: "cpu".into(),
            message: "not yet".into(),
        })
    }
    fn read_frame(&mut self) -> Result<FrameImage, RenderError> {
        Err(RenderError::Unsupported {
            backend: "cpu".into(),
            message: "not yet".into(),
        })
    }
}
