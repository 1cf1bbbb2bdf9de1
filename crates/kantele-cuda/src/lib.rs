//! The CUDA backend of Kantele: the whole pipeline — vertex transform, clipping, culling,
//! fixed-point setup, binning, fine rasterization, materials and blending — on an NVIDIA GPU,
//! by the CPU backend's rules, so that coverage and depth are bit-identical to
//! the CPU backend (`kantele::cpu::CpuBackend`).
//!
//! The entry point is [`CudaBackend`], a [`kantele_rules::backend::Backend`]. The CUDA driver
//! (`libcuda`) and NVRTC (`libnvrtc`) are opened at run time, so this crate builds, and
//! programs using it run, on machines without CUDA: [`CudaBackend::new`] then returns a
//! one-line error.
//!
//! - `kernels/*.cu`: one file per stage (vertex, primitive, binning, raster, resolve) plus the
//!   thesis' two schemes (`baselines.cu`), sharing `common.cuh`. They are embedded in the
//!   binary, compiled with NVRTC at start-up with the rules as `-D` defines ([`defines`]) and
//!   `--fmad=false`, and the PTX is cached on disk by source hash ([`kernels`]).
//! - [`records`]: the `#[repr(C)]` records the kernels read, built from a scene at `load`.
//! - [`plan`]: buffer sizes, growth after an overflow, and the frame's launch sequence.
//! - [`nvrtc`]: the run-time compiler binding.
//!
//! Read `ARCHITECTURE.md` (section "CUDA backend") for how a frame runs on the GPU.

#![warn(missing_docs)]
#![warn(unsafe_op_in_unsafe_fn)]

mod backend;
pub mod defines;
pub mod kernels;
pub mod layout;
pub mod nvrtc;
pub mod plan;
pub mod records;

pub use backend::{driver_present, CudaBackend};
pub use plan::CudaStrategy;
