//! Kantele's rendering rules: what a picture is, written once, for every backend.
//!
//! This crate holds the rules that decide a picture and the data every backend draws, and no
//! stage of any pipeline: the CPU backend (`kantele-cpu`), the OpenGL yardstick (`kantele-gl`)
//! and the CUDA backend (`kantele-cuda`) all stand on it. Lane code (the per-pixel forms of
//! the depth, blend and sampling rules) is written over [`kantele_lanes::Lanes`], so one
//! definition serves every instruction set, with the scalar build as its reference.
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
//! - **Winding**: counter-clockwise in NDC is front by default ([`setup::FrontFace::Ccw`]);
//!   back faces are culled by default ([`setup::CullMode::Back`]).
//! - **Fill rule**: top-left, as in Direct3D and OpenGL implementations — a pixel centre
//!   exactly on an edge belongs to the triangle only if the edge is a top or left edge, so
//!   triangles sharing an edge cover each of its pixels exactly once.
//! - **Colour** is linear `f32` RGBA throughout; blending happens in linear space, and sRGB
//!   encoding happens only on read-back ([`color`]). Textures decode sRGB when created
//!   ([`shade::texture`]).
//! - **Texture coordinates**: `(0, 0)` is the top-left of the image (glTF's convention).
//!
//! # Modules
//!
//! - [`fixed`] — sub-pixel bits, tile and block sizes, guard band, overflow bounds.
//! - [`geometry`] — trivial reject and clipping in homogeneous clip space, the segment and
//!   lane-wide forms.
//! - [`setup`] — viewport transform, snapping, culling, integer edge functions with the fill
//!   rule as a bias ([`TriangleSetup`](setup::TriangleSetup), `#[repr(C)]`).
//! - [`state`] — render state, depth and blend rules (scalar and lanes), limits, the id
//!   encoding.
//! - [`multisample`] — sample counts and standard sample positions.
//! - [`shade`] — textures, samplers, mip chains, level of detail, the lane sampler.
//! - [`color`] — the sRGB transfer curves and 8-bit quantisation.
//! - [`camera`] — view and projection matrices (OpenGL conventions).
//! - [`scene`] and [`vertex`] — plain scene data and the vertex layout every backend draws.
//! - [`backend`] — the [`Backend`](backend::Backend) interface, frames and passes.
//! - [`stats`] — per-stage counters and timings of a frame; [`error`] — [`RenderError`].
//! - `fault` — planted bugs for testing the test tools (only with the `fault-injection`
//!   feature, switched on by `KANTELE_FAULT`).
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod backend;
pub mod camera;
pub mod color;
pub mod error;
#[cfg(feature = "fault-injection")]
pub mod fault;
pub mod fixed;
pub mod geometry;
pub mod multisample;
/// The exact coverage reference of the tests and the `raster` fuzz target (not a public API).
#[doc(hidden)]
pub mod reference;
pub mod scene;
pub mod setup;
pub mod shade;
pub mod state;
pub mod stats;
pub mod vertex;

pub use error::RenderError;

pub use state::{MAX_TARGET_SIZE, MAX_VARYINGS};
