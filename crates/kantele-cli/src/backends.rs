//! Creating backends by name.

use anyhow::{anyhow, Result};
use kantele::backend::Backend;
use kantele::cpu::{CpuBackend, CpuOptions};

use crate::cli::{BackendKind, CpuArgs};

/// Creates a backend with `--msaa`'s samples per pixel. `fast` asks the GL backend for its
/// RGBA8 target (fair timing) instead of the float target (pictures). Errors name the backend.
pub fn make_backend(kind: BackendKind, cpu: &CpuArgs, fast: bool) -> Result<Box<dyn Backend>> {
    let mut backend = make_plain_backend(kind, cpu, fast)?;
    backend
        .set_samples(cpu.samples())
        .map_err(|e| anyhow!("--msaa {}: {e}", cpu.samples()))?;
    Ok(backend)
}

/// Creates a backend at 1×.
fn make_plain_backend(kind: BackendKind, cpu: &CpuArgs, fast: bool) -> Result<Box<dyn Backend>> {
    match kind {
        BackendKind::Cpu => {
            let options = CpuOptions {
                threads: cpu.threads,
                strategy: cpu.strategy.unwrap_or_default(),
                timeout: cpu.timeout,
                target: cpu.target,
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
        BackendKind::Cuda | BackendKind::CudaOcot | BackendKind::CudaOcmt => {
            cuda_backend(kind, fast)
        }
    }
}

/// The CUDA backend with the scheme `kind` names; `fast` also resolves each frame to 8-bit
/// sRGB on the device (the counterpart of the GL backend's RGBA8 target).
#[cfg(feature = "cuda")]
fn cuda_backend(kind: BackendKind, fast: bool) -> Result<Box<dyn Backend>> {
    use kantele_cuda::{CudaBackend, CudaStrategy};
    let mut backend = CudaBackend::new().map_err(|e| anyhow!("{e}"))?;
    backend.set_strategy(match kind {
        BackendKind::CudaOcot => CudaStrategy::Ocot,
        BackendKind::CudaOcmt => CudaStrategy::Ocmt,
        _ => CudaStrategy::Tiled,
    });
    backend.set_resolve_rgba8(fast);
    Ok(Box::new(backend))
}

/// Without the `cuda` feature there is no CUDA backend: one clear line.
#[cfg(not(feature = "cuda"))]
fn cuda_backend(kind: BackendKind, _fast: bool) -> Result<Box<dyn Backend>> {
    anyhow::bail!(
        "{} backend: this kantele was built without CUDA support (cargo build --features cuda)",
        kind.name()
    )
}
