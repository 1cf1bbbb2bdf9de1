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
//! # Conventions
//!
//! - **Clip space** is OpenGL's: `-w ≤ x, y, z ≤ w`; NDC x points right and y up. Window depth
//!   is `(z/w + 1) / 2` in `[0, 1]`, cleared to 1; fragments outside `[0, 1]` are discarded
//!   (there is no far-plane clipping). The near plane and the guard band are clipped
//!   ([`geometry::clip`]).
//! - **Pixels**: row 0 is the top row of the image; pixel `(x, y)` is sampled at its centre
//!   `(x + 0.5, y + 0.5)`. Vertices snap to 1/256 pixel ([`fixed::SUBPIXEL_BITS`] = 8, round
//!   half to even).
//! - **Winding**: counter-clockwise in NDC is front by default
//!   ([`setup::FrontFace::Ccw`]); back faces are culled by default ([`setup::CullMode::Back`]).
//! - **Fill rule**: top-left, as in Direct3D and OpenGL implementations — a pixel centre
//!   exactly on an edge belongs to the triangle only if the edge is a top or left edge, so
//!   triangles sharing an edge cover each of its pixels exactly once.
//! - **Colour** is linear `f32` RGBA throughout; blending happens in linear space, and sRGB
//!   encoding happens only on read-back ([`rop::Framebuffer::read_rgba8`]). Textures decode
//!   sRGB when created ([`shade::texture`]).
//! - **Texture coordinates**: `(0, 0)` is the top-left of the image (glTF's convention).
//!
//! # Modules
//!
//! In pipeline order:
//!
//! - [`pipeline`] — [`Shader`](pipeline::Shader), [`Renderer`](pipeline::Renderer),
//!   [`Frame`](pipeline::Frame): the programmable API and the frame that runs every stage.
//! - [`geometry`] — primitive stage: trivial reject and clipping in homogeneous clip space.
//! - [`fixed`] — the fixed-point rules: sub-pixel bits, tile and block sizes, guard band.
//! - [`setup`] — triangle setup: viewport transform, snapping, culling, integer edge
//!   functions with the fill rule as a bias ([`TriangleSetup`](setup::TriangleSetup)).
//! - [`raster`] — binning into tiles ([`raster::bin`]) and the five traversal strategies.
//! - [`shade`] — textures, samplers, mip chains and level of detail.
//! - [`rop`] — depth test, blending, and the tiled framebuffer.
//! - [`multisample`] — multisample antialiasing: sample counts, standard positions, limits.
//! - [`stats`] — per-stage counters and timings of a frame.
//!
//! Scenes and backends:
//!
//! - [`scene`] — plain scene data (meshes, materials, textures, draws, camera, light).
//! - [`material`] — the built-in material shader implementing the reference-scene rules.
//! - [`backend`] — the [`Backend`](backend::Backend) trait shared by CPU and OpenGL.
//! - [`cpu`] — the CPU backend: scenes through the pipeline with the built-in materials.
//! - [`camera`] — view and projection matrices (OpenGL conventions).
//! - [`color`] — the sRGB transfer curves and 8-bit quantisation.
//! - [`error`] — [`RenderError`].
//! - `fault` — planted bugs for testing the test tools (only with the `fault-injection`
//!   feature, switched on by `KANTELE_FAULT`).
//!
//! `ARCHITECTURE.md` at the repository root describes the data flow, the fixed-point and
//! interpolation rules, why pictures are deterministic, and how the crate is tested.
#![warn(missing_docs)]
#![deny(unsafe_code)]

pub mod backend;
pub mod band;
pub mod camera;
pub mod color;
pub mod cpu;
pub mod error;
#[cfg(feature = "fault-injection")]
pub mod fault;
pub mod fixed;
/// Bodies of the fuzz targets in `fuzz/`, callable from stable tests (not a public API).
#[doc(hidden)]
pub mod fuzz_targets;
pub mod geometry;
pub mod material;
pub mod multisample;
pub mod pipeline;
pub mod raster;
/// The exact coverage reference of the tests and the `raster` fuzz target (not a public API).
#[doc(hidden)]
pub mod reference;
pub mod rop;
pub mod scene;
pub mod setup;
pub mod shade;
#[allow(unsafe_code)]
pub mod simd;
pub mod state;
pub mod stats;

pub use error::RenderError;

pub use state::{MAX_TARGET_SIZE, MAX_VARYINGS};
