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

use std::time::Instant;

use glam::Vec4;
use rayon::prelude::*;

use crate::error::RenderError;
use crate::fixed::TILE_SIZE;
use crate::geometry::clip::{classify, ClipPolygon, ClipTest, ClipVertex, GuardBand};
use crate::raster::bin::TileBins;
use crate::raster::{rasterize, Strategy};
use crate::rop::{BlendMode, DepthFunc, Framebuffer, TileBuffer};
use crate::setup::{
    setup_triangle, CullMode, FrontFace, PixelRect, SetupReject, TriangleSetup, Viewport,
};
use crate::stats::FrameStats;
use crate::{MAX_TARGET_SIZE, MAX_VARYINGS};

/// A vertex and a fragment program with their uniforms (the shader's own fields).
///
/// The vertex stage turns a user-defined vertex into a clip-space position and writes
/// `varying_count()` floats of varyings; the fragment stage receives them interpolated
/// perspective-correctly and returns a colour, or `None` to discard the fragment.
pub trait Shader: Send + Sync {
    /// The vertex type this shader reads.
    type Vertex: Sync;

    /// Number of `f32` varyings written by [`Shader::vertex`] (at most [`MAX_VARYINGS`]).
    fn varying_count(&self) -> usize;

    /// Transforms one vertex: returns its clip-space position and fills `varyings`
    /// (`varying_count()` long).
    fn vertex(&self, vertex: &Self::Vertex, varyings: &mut [f32]) -> Vec4;

    /// Shades one fragment: its colour, or `None` to discard it.
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4>;
}

/// A [`Shader`] made of two closures, for quick programs:
/// `FnShader::new(n, |v, out| …, |frag| …)`.
pub struct FnShader<V, VS, FS> {
    varying_count: usize,
    vertex: VS,
    fragment: FS,
    _vertex: std::marker::PhantomData<fn(&V)>,
}

impl<V, VS, FS> FnShader<V, VS, FS>
where
    VS: Fn(&V, &mut [f32]) -> Vec4 + Send + Sync,
    FS: Fn(&Fragment<'_>) -> Option<Vec4> + Send + Sync,
{
    /// A shader writing `varying_count` varyings with the given stages.
    pub fn new(varying_count: usize, vertex: VS, fragment: FS) -> Self {
        Self {
            varying_count,
            vertex,
            fragment,
            _vertex: std::marker::PhantomData,
        }
    }
}

impl<V: Sync, VS, FS> Shader for FnShader<V, VS, FS>
where
    VS: Fn(&V, &mut [f32]) -> Vec4 + Send + Sync,
    FS: Fn(&Fragment<'_>) -> Option<Vec4> + Send + Sync,
{
    type Vertex = V;
    fn varying_count(&self) -> usize {
        self.varying_count
    }
    fn vertex(&self, vertex: &V, varyings: &mut [f32]) -> Vec4 {
        (self.vertex)(vertex, varyings)
    }
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        (self.fragment)(fragment)
    }
}

/// What the fragment stage sees of one pixel.
pub struct Fragment<'a> {
    /// Pixel column (0 = left).
    pub x: u32,
    /// Pixel row (0 = top).
    pub y: u32,
    /// Window depth in [0, 1].
    pub depth: f32,
    /// Index of the triangle within its draw (before clipping and sorting).
    pub primitive_id: u32,
    /// Whether the triangle faces the viewer.
    pub front_facing: bool,
    varyings: &'a [f32],
    interpolation: &'a Interpolation<'a>,
    /// Perspective weights of the three vertices at this pixel (sum to 1).
    weights: [f32; 3],
    /// `1 / Σ(λ_i / w_i)`: the pixel's clip w.
    w: f32,
}

impl Fragment<'_> {
    /// The interpolated varyings.
    #[inline]
    pub fn varyings(&self) -> &[f32] {
        self.varyings
    }

    /// One interpolated varying.
    #[inline]
    pub fn varying(&self, index: usize) -> f32 {
        self.varyings[index]
    }

    /// Perspective-correct barycentric weights of the triangle's vertices at this pixel.
    pub fn weights(&self) -> [f32; 3] {
        self.weights
    }

    /// Screen-space derivatives `(∂v/∂x, ∂v/∂y)` of varying `index`, per pixel, computed
    /// analytically from the triangle's plane equations (thesis §2.3.3).
    pub fn derivatives(&self, index: usize) -> (f32, f32) {
        let ip = self.interpolation;
        let n = ip.varying_count;
        let a = [
            ip.attrs[index],
            ip.attrs[n + index],
            ip.attrs[2 * n + index],
        ];
        let value = self.varyings[index];
        // v = N / S with S = Σ λ_i / w_i and N = Σ λ_i a_i / w_i; dv = (dN − v dS) / S = (dN − v dS)·w.
        let d = |dl: &[f32; 3]| {
            let dq = [
                dl[0] * ip.inv_w[0],
                dl[1] * ip.inv_w[1],
                dl[2] * ip.inv_w[2],
            ];
            let ds = dq[0] + dq[1] + dq[2];
            let dn = dq[0] * a[0] + dq[1] * a[1] + dq[2] * a[2];
            (dn - value * ds) * self.w
        };
        (d(&ip.dl_dx), d(&ip.dl_dy))
    }
}

/// Per-triangle data for interpolation and derivatives.
struct Interpolation<'a> {
    /// Varyings of the three (oriented) vertices, vertex-major.
    attrs: &'a [f32],
    varying_count: usize,
    inv_w: [f32; 3],
    dl_dx: [f32; 3],
    dl_dy: [f32; 3],
}

/// Fixed-function state of a draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderState {
    /// Which faces are removed.
    pub cull: CullMode,
    /// Which winding is front.
    pub front_face: FrontFace,
    /// Whether fragments are tested against the depth buffer.
    pub depth_test: bool,
    /// The depth comparison when testing.
    pub depth_func: DepthFunc,
    /// Whether passing fragments write their depth.
    pub depth_write: bool,
    /// How colours are combined.
    pub blend: BlendMode,
    /// Sort the draw's triangles back to front by the clip-space w of their centroid (the eye
    /// distance for perspective projections) before rasterizing; the user's buffers stay as
    /// they are. For transparency (the lecture exercise's step e).
    pub sort_back_to_front: bool,
}

impl Default for RenderState {
    fn default() -> Self {
        Self {
            cull: CullMode::Back,
            front_face: FrontFace::Ccw,
            depth_test: true,
            depth_func: DepthFunc::Less,
            depth_write: true,
            blend: BlendMode::Replace,
            sort_back_to_front: false,
        }
    }
}

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
    fn get(&self, i: usize) -> usize {
        match self {
            Indices::None => i,
            Indices::U16(ix) => ix[i] as usize,
            Indices::U32(ix) => ix[i] as usize,
        }
    }

    fn len(&self, vertex_count: usize) -> usize {
        match self {
            Indices::None => vertex_count,
            Indices::U16(ix) => ix.len(),
            Indices::U32(ix) => ix.len(),
        }
    }
}

/// Options of a [`Renderer`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RendererOptions {
    /// Worker threads; `None` uses every core.
    pub threads: Option<usize>,
    /// Triangle traversal strategy.
    pub strategy: Strategy,
}

/// The CPU renderer: owns the framebuffer and the worker threads.
pub struct Renderer {
    framebuffer: Framebuffer,
    pool: rayon::ThreadPool,
    strategy: Strategy,
    bins: TileBins,
    scratch: GeometryScratch,
}

impl Renderer {
    /// A renderer with a `width × height` target (each side 1..=[`MAX_TARGET_SIZE`]).
    pub fn new(width: u32, height: u32, options: RendererOptions) -> Result<Self, RenderError> {
        check_target_size(width, height)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(options.threads.unwrap_or(0))
            .thread_name(|i| format!("kantele-worker-{i}"))
            .build()
            .map_err(|e| RenderError::Backend {
                backend: "cpu".into(),
                message: format!("cannot start worker threads: {e}"),
            })?;
        Ok(Self {
            framebuffer: Framebuffer::new(width, height)?,
            pool,
            strategy: options.strategy,
            bins: TileBins::default(),
            scratch: GeometryScratch::default(),
        })
    }

    /// Changes the target size (contents become undefined: clear before drawing).
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        check_target_size(width, height)?;
        if (width, height) != (self.framebuffer.width(), self.framebuffer.height()) {
            self.framebuffer = Framebuffer::new(width, height)?;
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

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// The colour and depth target.
    pub fn framebuffer(&self) -> &Framebuffer {
        &self.framebuffer
    }

    /// Starts a frame: optionally clears colour and depth, then collects draws until
    /// [`Frame::end`].
    pub fn begin_frame<'a>(
        &mut self,
        clear_color: Option<Vec4>,
        clear_depth: Option<f32>,
    ) -> Frame<'_, 'a> {
        Frame {
            renderer: self,
            clear_color,
            clear_depth,
            draws: Vec::new(),
        }
    }
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
}

impl<'a> Frame<'_, 'a> {
    /// Queues a draw of `indices` (or of the vertices in order) from `vertices` with `shader`
    /// and `state`. Checks the buffers now; nothing is drawn until [`Frame::end`].
    pub fn draw<S: Shader>(
        &mut self,
        shader: &'a S,
        vertices: &'a [S::Vertex],
        indices: Indices<'a>,
        state: RenderState,
    ) -> Result<(), RenderError> {
        let n = shader.varying_count();
        if n > MAX_VARYINGS {
            return Err(RenderError::TooManyVaryings(n));
        }
        let count = indices.len(vertices.len());
        if count % 3 != 0 {
            return Err(RenderError::IncompleteTriangle(count));
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
        self.draws.push(Box::new(DrawCall {
            shader,
            vertices,
            indices,
            state,
        }));
        Ok(())
    }

    /// Runs every queued draw and returns what each stage did.
    pub fn end(self) -> FrameStats {
        let Frame {
            renderer,
            clear_color,
            clear_depth,
            draws,
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
            bins,
            scratch,
        } = renderer;
        let strategy = *strategy;
        pool.install(|| {
            framebuffer.clear(clear_color, clear_depth);
            let viewport = Viewport::new(framebuffer.width(), framebuffer.height());
            let geometry_start = Instant::now();
            run_geometry(&draws, &viewport, &mut stats, scratch);
            let geometry = &scratch.output;
            stats.geometry_time = geometry_start.elapsed();

            let binning_start = Instant::now();
            let grid = *framebuffer.grid();
            stats.bin_entries = bins.bin_triangles(&grid, &geometry.triangles);
            stats.triangles_binned = geometry.triangles.len() as u64;
            stats.binning_time = binning_start.elapsed();

            let raster_start = Instant::now();
            let counters = framebuffer
                .tiles_mut()
                .par_iter_mut()
                .zip(bins.bins.par_iter())
                .enumerate()
                .map(|(tile_index, (tile, bin))| {
                    let rect = grid.tile_rect(tile_index);
                    let mut counters = RasterCounters::default();
                    for &t in bin {
                        let tri = &geometry.triangles[t as usize];
                        let draw = &draws[tri.draw as usize];
                        // Early rejection: behind everything already in this tile.
                        if draw.rejects_by_depth_bound() {
                            let r = rect.intersect(&tri.bbox);
                            let area = r.width() * r.height();
                            if tile.occludes(tri.depth_range[0], area, &rect) {
                                counters.tile_rejected += 1;
                                continue;
                            }
                        }
                        let attrs = geometry.attrs_of(t as usize, &draws);
                        draw.raster(tri, attrs, tile, rect, strategy, &mut counters);
                    }
                    counters
                })
                .reduce(RasterCounters::default, RasterCounters::sum);
            stats.fragments_covered = counters.covered;
            stats.tiles_depth_rejected = counters.tile_rejected;
            stats.fragments_shaded = counters.shaded;
            stats.fragments_discarded = counters.discarded;
            stats.raster_time = raster_start.elapsed();
        });
        stats.total_time = start.elapsed();
        stats
    }
}

/// Fragment counters of one tile.
#[derive(Clone, Copy, Debug, Default)]
struct RasterCounters {
    tile_rejected: u64,
    covered: u64,
    shaded: u64,
    discarded: u64,
}

impl RasterCounters {
    fn sum(a: Self, b: Self) -> Self {
        Self {
            tile_rejected: a.tile_rejected + b.tile_rejected,
            covered: a.covered + b.covered,
            shaded: a.shaded + b.shaded,
            discarded: a.discarded + b.discarded,
        }
    }
}

/// Triangle counters of the primitive stage.
#[derive(Clone, Copy, Debug, Default)]
struct PrimitiveCounters {
    triangles_in: u64,
    invalid: u64,
    rejected: u64,
    clipped: u64,
    culled: u64,
    degenerate: u64,
}

impl PrimitiveCounters {
    fn sum(a: Self, b: Self) -> Self {
        Self {
            triangles_in: a.triangles_in + b.triangles_in,
            invalid: a.invalid + b.invalid,
            rejected: a.rejected + b.rejected,
            clipped: a.clipped + b.clipped,
            culled: a.culled + b.culled,
            degenerate: a.degenerate + b.degenerate,
        }
    }
}

/// The frame's set-up triangles (in draw order) and their varyings.
#[derive(Default)]
struct GeometryOutput {
    triangles: Vec<TriangleSetup>,
    /// Varyings of every triangle's three vertices, concatenated in triangle order.
    attrs: Vec<f32>,
    /// Per draw: index of its first triangle and of its first varying in `attrs`.
    draw_first: Vec<(usize, usize)>,
}

impl GeometryOutput {
    #[inline]
    fn attrs_of<'s>(&'s self, triangle: usize, draws: &[Box<dyn DrawJob + '_>]) -> &'s [f32] {
        let draw = self.triangles[triangle].draw as usize;
        let n3 = 3 * draws[draw].varying_count();
        let (first_tri, first_attr) = self.draw_first[draw];
        let start = first_attr + (triangle - first_tri) * n3;
        &self.attrs[start..start + n3]
    }
}

/// Triangles per unit of parallel work in the primitive stage.
const PRIMITIVE_CHUNK: usize = 1024;
/// Vertices per unit of parallel work in the vertex stage.
const VERTEX_CHUNK: usize = 2048;

/// Output of the vertex stage for one draw.
#[derive(Default)]
struct ShadedVertices {
    pos_clip: Vec<Vec4>,
    varyings: Vec<f32>,
}

/// The part of a draw the primitive stage produces for a range of its triangles.
#[derive(Default)]
struct PrimitiveBatch {
    triangles: Vec<TriangleSetup>,
    attrs: Vec<f32>,
    counters: PrimitiveCounters,
}

impl PrimitiveBatch {
    fn clear(&mut self) {
        self.triangles.clear();
        self.attrs.clear();
        self.counters = PrimitiveCounters::default();
    }
}

/// Where triangles are set up: the viewport and its guard band.
struct TargetSpace {
    viewport: Viewport,
    guard: GuardBand,
}

/// Buffers of the geometry stages, kept by the renderer between frames so that a frame reuses
/// the previous one's allocations instead of paging fresh memory in and out.
#[derive(Default)]
struct GeometryScratch {
    /// Vertex-stage output per draw (only the first `draws.len()` are current).
    shaded: Vec<ShadedVertices>,
    /// Primitive-stage output per chunk (only the first `jobs` are current).
    batches: Vec<PrimitiveBatch>,
    /// The frame's triangles and varyings.
    output: GeometryOutput,
}

fn run_geometry(
    draws: &[Box<dyn DrawJob + '_>],
    viewport: &Viewport,
    stats: &mut FrameStats,
    scratch: &mut GeometryScratch,
) {
    let GeometryScratch {
        shaded,
        batches,
        output,
    } = scratch;
    // 1. Vertex stage over all draws, in chunks.
    if shaded.len() < draws.len() {
        shaded.resize_with(draws.len(), ShadedVertices::default);
    }
    let shaded = &mut shaded[..draws.len()];
    for (d, out) in draws.iter().zip(shaded.iter_mut()) {
        out.pos_clip.clear();
        out.pos_clip.resize(d.vertex_count(), Vec4::ZERO);
        out.varyings.clear();
        out.varyings
            .resize(d.vertex_count() * d.varying_count(), 0.0);
    }
    let mut vertex_jobs = Vec::new();
    for (draw, out) in shaded.iter_mut().enumerate() {
        let n = draws[draw].varying_count();
        let vary_chunks: Box<dyn Iterator<Item = &mut [f32]>> = if n == 0 {
            Box::new(std::iter::repeat_with(|| &mut [][..]))
        } else {
            Box::new(out.varyings.chunks_mut(VERTEX_CHUNK * n))
        };
        for (chunk, (pos, vary)) in out
            .pos_clip
            .chunks_mut(VERTEX_CHUNK)
            .zip(vary_chunks)
            .enumerate()
        {
            vertex_jobs.push((draw, chunk * VERTEX_CHUNK, pos, vary));
        }
    }
    vertex_jobs
        .into_par_iter()
        .for_each(|(draw, first, pos, vary)| draws[draw].shade_vertices(first, pos, vary));
    let shaded = &*shaded;

    // 2. Primitive stage over all draws, in chunks; results concatenated in order.
    let mut primitive_jobs = Vec::new();
    let orders: Vec<Option<Vec<u32>>> = draws
        .par_iter()
        .zip(shaded.par_iter())
        .map(|(d, s)| d.sort_order(s))
        .collect();
    for (draw, d) in draws.iter().enumerate() {
        let count = d.triangle_count();
        let mut first = 0;
        while first < count {
            let last = (first + PRIMITIVE_CHUNK).min(count);
            primitive_jobs.push((draw, first, last));
            first = last;
        }
    }
    let target = TargetSpace {
        viewport: *viewport,
        guard: GuardBand::new(viewport.width, viewport.height),
    };
    if batches.len() < primitive_jobs.len() {
        batches.resize_with(primitive_jobs.len(), PrimitiveBatch::default);
    }
    let batches = &mut batches[..primitive_jobs.len()];
    batches
        .par_iter_mut()
        .zip(primitive_jobs.par_iter())
        .for_each(|(batch, &(draw, first, last))| {
            batch.clear();
            draws[draw].assemble(
                draw as u32,
                first..last,
                orders[draw].as_deref(),
                &shaded[draw],
                &target,
                batch,
            );
        });

    output.triangles.clear();
    output.attrs.clear();
    output.draw_first.clear();
    output.draw_first.resize(draws.len(), (0, 0));
    output
        .triangles
        .reserve(batches.iter().map(|b| b.triangles.len()).sum());
    output
        .attrs
        .reserve(batches.iter().map(|b| b.attrs.len()).sum());
    let mut counters = PrimitiveCounters::default();
    let mut next_draw = 0;
    for batch in batches.iter() {
        if let Some(first) = batch.triangles.first() {
            // Record where each draw begins (draws with no triangles keep a harmless value).
            while next_draw <= first.draw as usize {
                output.draw_first[next_draw] = (output.triangles.len(), output.attrs.len());
                next_draw += 1;
            }
        }
        output.triangles.extend_from_slice(&batch.triangles);
        output.attrs.extend_from_slice(&batch.attrs);
        counters = PrimitiveCounters::sum(counters, batch.counters);
    }
    stats.triangles_in = counters.triangles_in;
    stats.triangles_invalid = counters.invalid;
    stats.triangles_rejected = counters.rejected;
    stats.triangles_clipped = counters.clipped;
    stats.triangles_culled = counters.culled;
    stats.triangles_degenerate = counters.degenerate;
}

/// A queued draw with its shader type erased; the methods run the stages for it, so the hot
/// loops inside are compiled for the concrete shader.
trait DrawJob: Sync {
    fn vertex_count(&self) -> usize;
    fn varying_count(&self) -> usize;
    fn triangle_count(&self) -> usize;
    fn shade_vertices(&self, first: usize, pos: &mut [Vec4], varyings: &mut [f32]);
    /// Whether a triangle of this draw wholly behind a tile's depth bound can be skipped there:
    /// the test is LESS or LEQUAL (its fragments would all fail, and shaders have no side
    /// effects to miss).
    fn rejects_by_depth_bound(&self) -> bool;
    fn sort_order(&self, shaded: &ShadedVertices) -> Option<Vec<u32>>;
    fn assemble(
        &self,
        draw: u32,
        triangles: std::ops::Range<usize>,
        order: Option<&[u32]>,
        shaded: &ShadedVertices,
        target: &TargetSpace,
        out: &mut PrimitiveBatch,
    );
    fn raster(
        &self,
        tri: &TriangleSetup,
        attrs: &[f32],
        tile: &mut TileBuffer,
        rect: PixelRect,
        strategy: Strategy,
        counters: &mut RasterCounters,
    );
}

struct DrawCall<'a, S: Shader> {
    shader: &'a S,
    vertices: &'a [S::Vertex],
    indices: Indices<'a>,
    state: RenderState,
}

impl<S: Shader> DrawCall<'_, S> {
    #[inline]
    fn triangle_vertices(&self, t: usize) -> [usize; 3] {
        [
            self.indices.get(3 * t),
            self.indices.get(3 * t + 1),
            self.indices.get(3 * t + 2),
        ]
    }

    /// Sets up one (clipped or whole) triangle and appends it with its varyings.
    #[allow(clippy::too_many_arguments)] // the stage's inputs; bundling them would only rename them
    fn emit(
        &self,
        draw: u32,
        primitive_id: u32,
        pos: [Vec4; 3],
        varyings: [&[f32]; 3],
        viewport: &Viewport,
        out: &mut PrimitiveBatch,
    ) {
        match setup_triangle(viewport, pos, self.state.cull, self.state.front_face) {
            Ok(mut tri) => {
                tri.draw = draw;
                tri.primitive_id = primitive_id;
                let order = if tri.swapped { [0, 2, 1] } else { [0, 1, 2] };
                for v in order {
                    out.attrs.extend_from_slice(varyings[v]);
                }
                out.triangles.push(tri);
            }
            Err(SetupReject::Culled) => out.counters.culled += 1,
            Err(SetupReject::Degenerate) => out.counters.degenerate += 1,
        }
    }
}

impl<S: Shader> DrawJob for DrawCall<'_, S> {
    fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    fn varying_count(&self) -> usize {
        self.shader.varying_count()
    }

    fn triangle_count(&self) -> usize {
        self.indices.len(self.vertices.len()) / 3
    }

    fn shade_vertices(&self, first: usize, pos: &mut [Vec4], varyings: &mut [f32]) {
        let n = self.shader.varying_count();
        for (i, p) in pos.iter_mut().enumerate() {
            let out = &mut varyings[i * n..(i + 1) * n];
            *p = self.shader.vertex(&self.vertices[first + i], out);
        }
    }

    fn rejects_by_depth_bound(&self) -> bool {
        self.state.depth_test
            && matches!(
                self.state.depth_func,
                DepthFunc::Less | DepthFunc::LessEqual
            )
    }

    fn sort_order(&self, shaded: &ShadedVertices) -> Option<Vec<u32>> {
        if !self.state.sort_back_to_front {
            return None;
        }
        let key = |t: usize| {
            let [a, b, c] = self.triangle_vertices(t);
            let w = shaded.pos_clip[a].w + shaded.pos_clip[b].w + shaded.pos_clip[c].w;
            if w.is_nan() {
                f32::NEG_INFINITY
            } else {
                w
            }
        };
        let mut order: Vec<u32> = (0..self.triangle_count() as u32).collect();
        // Farthest first; a stable sort keeps submission order among equals.
        order.sort_by(|&a, &b| key(b as usize).total_cmp(&key(a as usize)));
        Some(order)
    }

    fn assemble(
        &self,
        draw: u32,
        triangles: std::ops::Range<usize>,
        order: Option<&[u32]>,
        shaded: &ShadedVertices,
        target: &TargetSpace,
        out: &mut PrimitiveBatch,
    ) {
        let TargetSpace { viewport, guard } = target;
        let n = self.shader.varying_count();
        for slot in triangles {
            out.counters.triangles_in += 1;
            let t = order.map_or(slot, |o| o[slot] as usize);
            let ix = self.triangle_vertices(t);
            let pos = ix.map(|i| shaded.pos_clip[i]);
            if !pos.iter().all(|p| p.is_finite()) {
                out.counters.invalid += 1;
                continue;
            }
            let vary = ix.map(|i| &shaded.varyings[i * n..(i + 1) * n]);
            match classify(pos, guard) {
                ClipTest::Reject => out.counters.rejected += 1,
                ClipTest::Accept => self.emit(draw, t as u32, pos, vary, viewport, out),
                ClipTest::Clip => {
                    out.counters.clipped += 1;
                    let vertex = |k: usize| {
                        let mut v = ClipVertex {
                            pos_clip: pos[k],
                            varyings: [0.0; MAX_VARYINGS],
                        };
                        v.varyings[..n].copy_from_slice(vary[k]);
                        v
                    };
                    let mut poly = ClipPolygon::triangle(vertex(0), vertex(1), vertex(2));
                    poly.clip(guard, n);
                    let verts = poly.vertices();
                    if verts.iter().any(|v| !v.pos_clip.is_finite()) {
                        out.counters.invalid += 1;
                        continue;
                    }
                    for k in 1..verts.len().saturating_sub(1) {
                        let (a, b, c) = (&verts[0], &verts[k], &verts[k + 1]);
                        self.emit(
                            draw,
                            t as u32,
                            [a.pos_clip, b.pos_clip, c.pos_clip],
                            [&a.varyings[..n], &b.varyings[..n], &c.varyings[..n]],
                            viewport,
                            out,
                        );
                    }
                }
            }
        }
    }

    fn raster(
        &self,
        tri: &TriangleSetup,
        attrs: &[f32],
        tile: &mut TileBuffer,
        rect: PixelRect,
        strategy: Strategy,
        counters: &mut RasterCounters,
    ) {
        let n = self.shader.varying_count();
        let state = &self.state;
        let (dl_dx, dl_dy) = tri.barycentric_gradients();
        let interpolation = Interpolation {
            attrs,
            varying_count: n,
            inv_w: tri.inv_w,
            dl_dx,
            dl_dy,
        };
        let (a0, rest) = attrs.split_at(n);
        let (a1, a2) = rest.split_at(n);
        debug_assert!(rect.width() <= TILE_SIZE as i32);
        // Counted locally and added once: the closure then keeps them in registers.
        let (mut covered, mut shaded, mut discarded) = (0u64, 0u64, 0u64);
        rasterize(tri, rect, strategy, |x, y| {
            covered += 1;
            let bary = tri.barycentrics(x, y);
            let depth = tri.depth_at(&bary);
            // Outside the [0, 1] depth range (or NaN): clipped by the near/far planes.
            if !(0.0..=1.0).contains(&depth) {
                return;
            }
            let index = TileBuffer::index(x, y);
            if state.depth_test && !state.depth_func.passes(depth, tile.depth[index]) {
                return;
            }
            let q = [
                bary[0] * tri.inv_w[0],
                bary[1] * tri.inv_w[1],
                bary[2] * tri.inv_w[2],
            ];
            let w = 1.0 / (q[0] + q[1] + q[2]);
            let weights = [q[0] * w, q[1] * w, q[2] * w];
            let mut varyings = [0.0f32; MAX_VARYINGS];
            for k in 0..n {
                varyings[k] = weights[0] * a0[k] + weights[1] * a1[k] + weights[2] * a2[k];
            }
            let fragment = Fragment {
                x: x as u32,
                y: y as u32,
                depth,
                primitive_id: tri.primitive_id,
                front_facing: tri.front_facing,
                varyings: &varyings[..n],
                interpolation: &interpolation,
                weights,
                w,
            };
            shaded += 1;
            match self.shader.fragment(&fragment) {
                None => discarded += 1,
                Some(color) => {
                    tile.color[index] = state.blend.blend(color, tile.color[index]);
                    if state.depth_write {
                        tile.write_depth(index, depth);
                    }
                }
            }
        });
        counters.covered += covered;
        counters.shaded += shaded;
        counters.discarded += discarded;
    }
}
