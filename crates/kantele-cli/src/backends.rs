//! Creating backends by name.

use anyhow::{anyhow, Result};
use kantele::backend::Backend;
use kantele::cpu::{CpuBackend, CpuOptions};

use crate::cli::{BackendKind, CpuArgs};

/// Creates a backend. `fast` asks the GL backend for its RGBA8 target (fair timing) instead of
/// the float target (pictures). Errors name the backend.
pub fn make_backend(kind: BackendKind, cpu: &CpuArgs, fast: bool) -> Result<Box<dyn Backend>> {
    match kind {
        BackendKind::Cpu => {
            let options = CpuOptions {
                threads: cpu.threads,
                strategy: cpu.strategy.unwrap_or_default(),
                ..CpuOptions::default()
            };
            let backend = CpuBackend::new(options).map_err(|e| anyhow!("cpu backend: {e}"))?;
            Ok(Box::new(backend))
        }
        #[cfg(feature = "gl")]
        BackendKind::Gl => {
            let mut backend = kantele_gl::GlBackend::new().map_err(|e| anyhow!("{e}"))?;
            backend.set_fast_target(fast);
            Ok(Box::new(backend))
        }
        #[cfg(not(feature = "gl"))]
        BackendKind::Gl => {
            let _ = fast;
            Err(anyhow!(
                "gl backend: this kantele was built without it (cargo install --locked --path crates/kantele-cli --features gl)"
            ))
        }
    }
}
