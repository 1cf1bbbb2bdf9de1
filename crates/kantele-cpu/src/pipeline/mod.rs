//! The programmable pipeline: shaders, render state, and the frame that runs the stages.
//!
//! ```text
//! Frame::draw (queue, in order)
//!   └─ end():
//!      1. vertex stage      Shader::vertex on every vertex            (parallel over chunks)
//!      2. primitive stage   assemble, reject, clip, cull, set up      (parallel over chunks,
//!                           → TriangleSetup + varyings                  results kept in order)
//!      3. binning           triangles → per-tile lists, in order      (serial, cheap)
//!      4. raster            per tile: traverse, depth, Shader::fragment, blend
//!                                                                      (parallel over tiles)
//! ```
//! Each tile is owned by one thread and processes its triangles in submission order, so the
//! picture is identical for every thread count and traversal strategy.

mod budget;
mod call;
mod draw;
mod fragment;
mod geometry;
mod multisample;
mod packed_rows;
mod points_lines;
mod sanitize;
mod shader;
mod shading_isas;
mod warm;
mod workers;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::Vec4;

pub use self::call::Indices;
pub use self::shader::{
    FnShader, Fragment, FragmentLanes, LaneProgram, LaneProgramJob, ShadedLanes, Shader,
    ShaderLanes,
};
pub use self::workers::PIN_ENV;
pub use kantele_rules::state::{RenderState, Topology};

use self::budget::FrameBudget;
use self::call::DrawCall;
use self::draw::DrawJob;
use self::geometry::{run_geometry, GeometryScratch};
use self::shading_isas::compiled_level;
#[cfg(test)]
pub(crate) use self::shading_isas::compiled_supported;
use self::warm::{WarmWorkers, WARM_AFTER_FRAME, WARM_WHILE_QUEUING};
use crate::raster::bin::TileBins;
use crate::raster::Strategy;
use crate::rop::{Framebuffer, TargetFormat};
use kantele_lanes::Isa;
use kantele_rules::error::RenderError;
use kantele_rules::multisample::SampleCount;
use kantele_rules::setup::{PixelRect, Viewport};
use kantele_rules::stats::{FrameStats, FrameStop};
use kantele_rules::{MAX_TARGET_SIZE, MAX_VARYINGS};

/// Options of a [`Renderer`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RendererOptions {
    /// Worker threads; `None` uses every core.
    pub threads: Option<usize>,
    /// Triangle traversal strategy.
    pub strategy: Strategy,
    /// Instruction set of the per-pixel path; `None` uses [`Isa::selected`] (the best the CPU
    /// has, or `KANTELE_ISA`). Every choice gives the same picture, bit for bit.
    pub isa: Option<Isa>,
    /// Wall-clock budget of one frame; `None` (the default) is unlimited. A frame that runs
    /// out stops between chunks of work, leaves the picture partly drawn and reports
    /// [`FrameStop::TimedOut`] ([`Frame::try_end`]: [`RenderError::TimedOut`]).
    pub timeout: Option<Duration>,
    /// Samples per pixel of the target (multisample antialiasing; see
    /// [`kantele_rules::multisample`]). The default, 1×, is the single-sample path.
    pub samples: SampleCount,
    /// How the target stores colour: linear `f32` (the default, exact) or 8-bit sRGB (a
    /// quarter of the colour memory; the same 8-bit picture for a frame that starts with a
    /// clear, see [`TargetFormat`]).
    pub target: TargetFormat,
    /// Whether each worker is pinned to its own CPU (one of those the creating thread may run
    /// on; a pool with more workers than such CPUs is not pinned): `None` (the default) reads
    /// [`PIN_ENV`] (`1` pins), `Some(false)` never pins. Pinning keeps workers apart where
    /// the system would put several on one CPU, and costs where other busy threads need the
    /// CPUs (a pinned worker cannot move away from them). It never changes the picture.
    pub pin_workers: Option<bool>,
}

/// The CPU renderer: owns the framebuffer and the worker threads.
pub struct Renderer {
    framebuffer: Framebuffer,
    pool: rayon::ThreadPool,
    strategy: Strategy,
    isa: Isa,
    bins: TileBins,
    scratch: GeometryScratch,
    timeout: Option<Duration>,
    cancel: Option<Arc<AtomicBool>>,
    /// Keeps the workers awake from a frame's start until shortly after its end.
    warm: Arc<WarmWorkers>,
}

impl Drop for Renderer {
    fn drop(&mut self) {
        self.warm.release();
    }
}

impl Renderer {
    /// A renderer with a `width × height` target (each side 1..=[`MAX_TARGET_SIZE`]).
    pub fn new(width: u32, height: u32, options: RendererOptions) -> Result<Self, RenderError> {
        check_target_size(width, height)?;
        let pool = workers::worker_pool(options.threads, options.pin_workers).map_err(|e| {
            RenderError::Backend {
                backend: "cpu".into(),
                message: format!("cannot start worker threads: {e}"),
            }
        })?;
        let framebuffer = Framebuffer::band(
            width,
            height,
            0..height,
            options.samples,
            options.target,
            pool.current_num_threads(),
        )?;
        Ok(Self {
            framebuffer,
            pool,
            strategy: options.strategy,
            isa: resolve_isa(options.isa),
            bins: TileBins::default(),
            scratch: GeometryScratch::default(),
            timeout: options.timeout,
            cancel: None,
            warm: WarmWorkers::new(),
        })
    }

    /// Changes the target size (contents become undefined: clear before drawing).
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        self.resize_band(width, height, 0..height)
    }

    /// Makes the target rows `rows` of a `width × height` picture (a render region): the
    /// viewport, snapping and coverage stay those of the whole picture, so the band is
    /// bit-identical to the same rows of an unbanded frame, but only the 64-row tile rows
    /// holding `rows` are allocated, binned and drawn, and readback returns `rows` only.
    /// `rows` must be a non-empty range within `0..height`. Contents become undefined: clear
    /// before drawing.
    pub fn resize_band(
        &mut self,
        width: u32,
        height: u32,
        rows: std::ops::Range<u32>,
    ) -> Result<(), RenderError> {
        check_target_size(width, height)?;
        if rows.is_empty() || rows.end > height {
            return Err(RenderError::InvalidRegion {
                rows: (rows.start, rows.end),
                height,
            });
        }
        let fb = &self.framebuffer;
        if (width, height, rows.clone()) != (fb.width(), fb.height(), fb.rows()) {
            self.rebuild_target(width, height, rows, fb.samples(), fb.format())?;
        }
        Ok(())
    }

    /// Replaces the target with a new one (contents undefined).
    fn rebuild_target(
        &mut self,
        width: u32,
        height: u32,
        rows: std::ops::Range<u32>,
        samples: SampleCount,
        format: TargetFormat,
    ) -> Result<(), RenderError> {
        // Free the old target first: two big targets need not fit at once.
        self.framebuffer = Framebuffer::new(1, 1, SampleCount::X1)?;
        let workers = self.pool.current_num_threads();
        self.framebuffer = Framebuffer::band(width, height, rows, samples, format, workers)?;
        Ok(())
    }

    /// How the target stores colour.
    pub fn target_format(&self) -> TargetFormat {
        self.framebuffer.format()
    }

    /// Changes how the target stores colour (contents become undefined: clear before drawing).
    pub fn set_target_format(&mut self, format: TargetFormat) -> Result<(), RenderError> {
        let fb = &self.framebuffer;
        if format != fb.format() {
            self.rebuild_target(fb.width(), fb.height(), fb.rows(), fb.samples(), format)?;
        }
        Ok(())
    }

    /// Samples per pixel of the target.
    pub fn samples(&self) -> SampleCount {
        self.framebuffer.samples()
    }

    /// Changes the samples per pixel (contents become undefined: clear before drawing); an
    /// error when the multisampled target would be too large (see
    /// [`kantele_rules::multisample::MAX_MULTISAMPLE_TARGET_BYTES`]).
    pub fn set_samples(&mut self, samples: SampleCount) -> Result<(), RenderError> {
        let fb = &self.framebuffer;
        if samples != fb.samples() {
            self.rebuild_target(fb.width(), fb.height(), fb.rows(), samples, fb.format())?;
        }
        Ok(())
    }

    /// The traversal strategy in use.
    pub fn strategy(&self) -> Strategy {
        self.strategy
    }

    /// Changes the traversal strategy (pictures stay identical).
    pub fn set_strategy(&mut self, strategy: Strategy) {
        self.strategy = strategy;
    }

    /// The instruction set of the per-pixel path.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Changes the instruction set of the per-pixel path (pictures stay identical); an
    /// instruction set this CPU lacks falls back to scalar.
    pub fn set_isa(&mut self, isa: Isa) {
        self.isa = resolve_isa(Some(isa));
    }

    /// The time budget of a frame (`None`: unlimited).
    pub fn timeout(&self) -> Option<Duration> {
        self.timeout
    }

    /// Changes the time budget of a frame (`None`: unlimited).
    pub fn set_timeout(&mut self, timeout: Option<Duration>) {
        self.timeout = timeout;
    }

    /// A flag that cancels the frame in flight (and every later one) while it is `true`: set it
    /// from another thread or a signal handler; the frame stops between chunks of work and
    /// reports [`FrameStop::Cancelled`]. Clear it again before the next frame. `None` removes
    /// the flag.
    pub fn set_cancel_flag(&mut self, flag: Option<Arc<AtomicBool>>) {
        self.cancel = flag;
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// The colour and depth target.
    pub fn framebuffer(&self) -> &Framebuffer {
        &self.framebuffer
    }

    /// Exchanges the colour and depth target with `other`: a second target kept between
    /// frames (the CPU backend's backdrop of transmissive frames) is drawn into without
    /// rebuilding either.
    pub(crate) fn swap_target(&mut self, other: &mut Framebuffer) {
        std::mem::swap(&mut self.framebuffer, other);
    }

    /// Starts a frame: optionally clears colour and depth, then collects draws until
    /// [`Frame::end`].
    pub fn begin_frame<'a>(
        &mut self,
        clear_color: Option<Vec4>,
        clear_depth: Option<f32>,
    ) -> Frame<'_, 'a> {
        // The workers wake while the draws are queued, not in the frame's first stage.
        self.warm.keep_awake(&self.pool, WARM_WHILE_QUEUING);
        Frame {
            renderer: self,
            clear_color,
            clear_depth,
            draws: Vec::new(),
            batches: 0,
        }
    }
}

/// The instruction set to use: the requested one when the CPU has it, else the selected one
/// (as [`shading_isas::compiled_level`] compiles it).
fn resolve_isa(requested: Option<Isa>) -> Isa {
    compiled_level(match requested {
        Some(isa) if isa.is_supported() => isa,
        Some(_) => Isa::Scalar,
        None => Isa::selected(),
    })
}

fn check_target_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width > MAX_TARGET_SIZE || height > MAX_TARGET_SIZE {
        return Err(RenderError::InvalidSize { width, height });
    }
    Ok(())
}

/// A frame being recorded: draws are queued in order and run by [`Frame::end`]. `'r` is the
/// borrow of the renderer, `'a` that of the draws' shaders and buffers.
pub struct Frame<'r, 'a> {
    renderer: &'r mut Renderer,
    clear_color: Option<Vec4>,
    clear_depth: Option<f32>,
    draws: Vec<Box<dyn DrawJob + 'a>>,
    /// Primitive-stage batches the queued draws will make (bounded by `TriangleRef`).
    batches: usize,
}

impl<'a> Frame<'_, 'a> {
    /// Queues a draw of the triangles `indices` (or the vertices in order) describe, from
    /// `vertices` with `shader` and `state`. Checks the buffers now; nothing is drawn until
    /// [`Frame::end`].
    pub fn draw<S: Shader>(
        &mut self,
        shader: &'a S,
        vertices: &'a [S::Vertex],
        indices: Indices<'a>,
        state: RenderState,
    ) -> Result<(), RenderError> {
        self.draw_primitives(shader, vertices, indices, Topology::Triangles, state)
    }

    /// [`Frame::draw`] for any [`Topology`]: lines are drawn 1 pixel wide and points as one
    /// pixel, by OpenGL's rules (never culled, always front-facing; see
    /// [`kantele_rules::geometry::wide`]).
    pub fn draw_primitives<S: Shader>(
        &mut self,
        shader: &'a S,
        vertices: &'a [S::Vertex],
        indices: Indices<'a>,
        topology: Topology,
        state: RenderState,
    ) -> Result<(), RenderError> {
        let n = shader.varying_count();
        if n > MAX_VARYINGS {
            return Err(RenderError::TooManyVaryings(n));
        }
        let count = indices.len(vertices.len());
        match topology {
            Topology::Triangles if !count.is_multiple_of(3) => {
                return Err(RenderError::IncompleteTriangle(count))
            }
            Topology::Lines if !count.is_multiple_of(2) => {
                return Err(RenderError::IncompleteLine(count))
            }
            _ => {}
        }
        let out_of_range = |ix: usize| ix >= vertices.len();
        let bad = match indices {
            Indices::None => None,
            Indices::U16(ix) => ix.iter().position(|&i| out_of_range(i as usize)),
            Indices::U32(ix) => ix.iter().position(|&i| out_of_range(i as usize)),
        };
        if let Some(position) = bad {
            return Err(RenderError::IndexOutOfRange {
                index: indices.get(position) as u32,
                position,
                vertex_count: vertices.len(),
            });
        }
        let primitives = count / topology.vertices_per_primitive();
        let batches = self.batches + primitives.div_ceil(geometry::PRIMITIVE_CHUNK);
        if batches > crate::raster::bin::TriangleRef::MAX_BATCHES {
            return Err(RenderError::FrameTooLarge);
        }
        self.batches = batches;
        self.draws.push(Box::new(DrawCall {
            shader,
            vertices,
            indices,
            topology,
            state,
        }));
        Ok(())
    }

    /// Runs every queued draw and returns what each stage did. A frame cut short by its time
    /// budget or the cancellation flag returns early, with [`FrameStats::stopped`] set and the
    /// picture partly drawn; [`Frame::try_end`] turns that into an error.
    pub fn end(self) -> FrameStats {
        let Frame {
            renderer,
            clear_color,
            clear_depth,
            draws,
            batches: _,
        } = self;
        let start = Instant::now();
        let mut stats = FrameStats {
            draws: draws.len() as u64,
            ..FrameStats::default()
        };
        let Renderer {
            framebuffer,
            pool,
            strategy,
            isa,
            bins,
            scratch,
            timeout,
            cancel,
            warm,
        } = renderer;
        let (strategy, isa) = (*strategy, *isa);
        let budget = FrameBudget::new(start, *timeout, cancel.as_deref());
        pool.install(|| {
            // A frame cancelled before it began (a big target takes a while to allocate)
            // skips even the clear.
            if budget.exhausted() {
                return;
            }
            framebuffer.clear(clear_color, clear_depth);
            let viewport = Viewport::new(framebuffer.width(), framebuffer.height())
                .with_samples(framebuffer.samples());
            let geometry_start = Instant::now();
            run_geometry(&draws, &viewport, &mut stats, scratch, &budget);
            let geometry = scratch.output();
            stats.geometry_time = geometry_start.elapsed();
            if budget.exhausted() {
                return;
            }

            let binning_start = Instant::now();
            let grid = *framebuffer.grid();
            let batches: Vec<&[PixelRect]> = geometry.bbox_batches().collect();
            stats.bin_entries = bins.bin_batches(&grid, &batches);
            stats.triangles_binned = batches.iter().map(|b| b.len() as u64).sum();
            stats.binning_time = binning_start.elapsed();
            if budget.exhausted() {
                return;
            }

            let raster_start = Instant::now();
            let counters = if framebuffer.samples().is_multisampled() {
                multisample::raster_tiles_multisampled(
                    framebuffer,
                    bins,
                    &geometry,
                    &draws,
                    strategy,
                    isa,
                    &budget,
                )
            } else {
                fragment::raster_tiles(framebuffer, bins, &geometry, &draws, strategy, isa, &budget)
            };
            stats.fragments_covered = counters.covered;
            stats.tiles_depth_rejected = counters.tile_rejected;
            stats.blocks_depth_rejected = counters.blocks_rejected;
            stats.fragments_shaded = counters.shaded;
            stats.fragments_discarded = counters.discarded;
            stats.nan_color_channels = counters.nan_channels;
            stats.raster_time = raster_start.elapsed();
        });
        // Awake a little longer, for the next frame of a loop.
        warm.keep_awake(pool, WARM_AFTER_FRAME);
        stats.stopped = budget.stop();
        stats.empty_picture = stats.is_unexpectedly_empty();
        stats.total_time = start.elapsed();
        stats
    }

    /// [`Frame::end`], with a frame cut short by its budget or the cancellation flag reported
    /// as [`RenderError::TimedOut`] or [`RenderError::Cancelled`].
    pub fn try_end(self) -> Result<FrameStats, RenderError> {
        let stats = self.end();
        match stats.stopped {
            None => Ok(stats),
            Some(FrameStop::Cancelled) => Err(RenderError::Cancelled),
            Some(FrameStop::TimedOut { budget }) => Err(RenderError::TimedOut { budget }),
        }
    }
}
