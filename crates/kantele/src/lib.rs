//! Kantele: the whole graphics pipeline in software.
//!
//! A programmable rasterizer on the CPU: user shaders ([`pipeline::Shader`]) transform vertices
//! and shade fragments, and the fixed stages between them — clipping, triangle setup in fixed
//! point, binning into 64 × 64 tiles, traversal, depth test and blending — run on a pool of
//! worker threads. Pictures are deterministic: the same for every thread count and every
//! traversal strategy. The same pipeline also draws loaded scenes behind the [`backend::Backend`]
//! interface ([`cpu::CpuBackend`]), which the OpenGL reference backend (`kantele-gl`) implements
//! too, so the two can be compared picture for picture.
//!
//! # Example
//!
//! One red triangle, counter-clockwise in NDC and therefore front-facing, plus its clockwise
//! mirror image, which the default [`RenderState`](pipeline::RenderState) culls:
//!
//! ```
//! use glam::{Vec2, Vec4};
//! use kantele::pipeline::{FnShader, Indices, RenderState, Renderer, RendererOptions};
//!
//! // Positions are already in NDC (x right, y up); no varyings.
//! let red = FnShader::new(
//!     0,
//!     |p: &Vec2, _varyings: &mut [f32]| Vec4::new(p.x, p.y, 0.0, 1.0),
//!     |_fragment| Some(Vec4::new(1.0, 0.0, 0.0, 1.0)),
//! );
//! let green = FnShader::new(
//!     0,
//!     |p: &Vec2, _varyings: &mut [f32]| Vec4::new(p.x, p.y, 0.0, 1.0),
//!     |_fragment| Some(Vec4::new(0.0, 1.0, 0.0, 1.0)),
//! );
//! let ccw = [Vec2::new(-0.5, -0.5), Vec2::new(0.5, -0.5), Vec2::new(0.0, 0.5)];
//! let cw = [ccw[0], ccw[2], ccw[1]];
//!
//! let mut renderer = Renderer::new(64, 64, RendererOptions::default())?;
//! let mut frame = renderer.begin_frame(Some(Vec4::new(0.0, 0.0, 0.0, 1.0)), Some(1.0));
//! frame.draw(&red, &ccw, Indices::None, RenderState::default())?;
//! frame.draw(&green, &cw, Indices::None, RenderState::default())?; // back face: culled
//! let stats = frame.end();
//! assert_eq!((stats.triangles_in, stats.triangles_culled), (2, 1));
//!
//! // 8-bit RGBA, sRGB-encoded, row 0 at the top.
//! let rgba = renderer.framebuffer().read_rgba8(true);
//! let pixel = |x: usize, y: usize| &rgba[(y * 64 + x) * 4..][..4];
//! assert_eq!(pixel(32, 32), [255, 0, 0, 255]); // the centre is inside the triangle
//! assert_eq!(pixel(0, 0), [0, 0, 0, 255]); // a corner keeps the clear colour
//! # Ok::<(), kantele::RenderError>(())
//! ```
//!
//! `kantele_testkit::demo` draws two complete scenes (a textured cube, a lit and blended scene)
//! the same way.
//!
//! # Layers
//!
//! This crate is the library's one front door: it re-exports, under the paths used
//! everywhere, three crates that each hold one layer.
//!
//! - **Lanes** (`kantele-lanes`, here [`simd`]): 8-lane types per instruction set, chosen
//!   once at run time, identical bits on every one. All of the CPU path's `unsafe` lives there.
//! - **Rules** (`kantele-rules`): what a picture is — [`fixed`] point, [`geometry`] clipping,
//!   triangle [`setup`], render [`state`] (depth, blend, limits, ids), [`multisample`]
//!   positions, texture sampling ([`shade`]), [`color`], [`camera`], the [`scene`] data and
//!   its [`vertex`] layout, the [`backend`] interface, [`stats`] and [`error`]. Every backend
//!   (CPU, OpenGL, CUDA) stands on it. Its crate docs state the conventions (clip space,
//!   pixels, winding, fill rule, colour, texture coordinates).
//! - **CPU** (`kantele-cpu`): the programmable [`pipeline`] (shaders, renderer, frame,
//!   workers), binning and traversal ([`raster`]), the output merger and framebuffer
//!   ([`rop`]), the built-in [`material`] shaders, the [`cpu`] backend and [`band`]ed
//!   rendering of big pictures.
//!
//! `ARCHITECTURE.md` at the repository root draws the layers and the data flow of a frame.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub use kantele_lanes as simd;

pub use kantele_rules::{
    backend, camera, color, error, fixed, geometry, multisample, scene, setup, shade, state, stats,
    vertex,
};
pub use kantele_rules::{RenderError, MAX_TARGET_SIZE, MAX_VARYINGS};

#[cfg(feature = "fault-injection")]
pub use kantele_rules::fault;
/// The exact coverage reference of the tests and the `raster` fuzz target (not a public API).
#[doc(hidden)]
pub use kantele_rules::reference;

/// Bodies of the fuzz targets in `fuzz/`, callable from stable tests (not a public API).
#[doc(hidden)]
pub use kantele_cpu::fuzz_targets;
pub use kantele_cpu::{band, cpu, material, pbr_material, pipeline, raster, rop};

/// The README's Rust example, compiled and run as a doctest (`cargo test --doc -p kantele`):
/// the README's other code blocks run in `python/tests/test_readme.py`.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
