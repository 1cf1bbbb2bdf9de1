//! The geometry stages: the vertex stage (the shader's vertex program on every vertex) and the
//! primitive stage (assembly, trivial reject, clipping, culling and triangle setup), both parallel
//! over chunks. The primitive stage's batches are handed on as they are, in submission order:
//! binning and raster address a triangle by its batch and its place in it ([`TriangleRef`]), so
//! no stage copies the frame's set-up triangles into one array.

use glam::Vec4;
use rayon::prelude::*;

use super::budget::FrameBudget;
use kantele_rules::geometry::clip::{ClipCode, GuardBand};
use kantele_rules::setup::{PixelRect, TriangleSetup, Viewport, WindowVertex};
use kantele_rules::stats::FrameStats;

/// The geometry stage's work for one draw, with the draw's shader type erased
/// ([`DrawJob`](super::draw::DrawJob) for the whole draw).
pub(super) trait GeometryJob: Sync {
    fn vertex_count(&self) -> usize;
    fn varying_count(&self) -> usize;
    /// Triangles, lines or points, by the draw's topology.
    fn primitive_count(&self) -> usize;
    fn shade_vertices(&self, first: usize, pos: &mut [Vec4], varyings: &mut [f32]);
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
}

/// Triangle counters of the primitive stage.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PrimitiveCounters {
    pub(super) triangles_in: u64,
    pub(super) invalid: u64,
    pub(super) rejected: u64,
    pub(super) clipped: u64,
    pub(super) culled: u64,
    pub(super) degenerate: u64,
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

/// The frame's set-up triangles and their varyings, as the primitive stage left them: batches in
/// submission order, each from one draw.
pub(super) struct GeometryOutput<'g> {
    batches: &'g [PrimitiveBatch],
}

impl<'g> GeometryOutput<'g> {
    /// The batches' triangles' pixel boxes, in submission order (what binning reads).
    pub(super) fn bbox_batches(&self) -> impl Iterator<Item = &'g [PixelRect]> + 'g {
        self.batches.iter().map(|b| b.bboxes.as_slice())
    }

    /// The triangle `r` refers to.
    #[inline]
    pub(super) fn triangle(&self, r: TriangleRef) -> &'g TriangleSetup {
        &self.batches[r.batch()].triangles[r.index()]
    }

    /// The varyings of the three (oriented) vertices of triangle `r`, vertex-major.
    #[inline]
    pub(super) fn attrs(&self, r: TriangleRef) -> &'g [f32] {
        let batch = &self.batches[r.batch()];
        let n3 = 3 * batch.varying_count;
        let start = r.index() * n3;
        &batch.attrs[start..start + n3]
    }
}

pub(super) use crate::raster::bin::TriangleRef;

/// Triangles per unit of parallel work in the primitive stage.
pub(super) const PRIMITIVE_CHUNK: usize = 1024;

// Clipping turns a triangle into at most `MAX_CLIPPED_VERTICES − 2` triangles: a batch must fit
// the index part of a `TriangleRef`.
const _: () = assert!(
    PRIMITIVE_CHUNK * (kantele_rules::geometry::clip::MAX_CLIPPED_VERTICES - 2)
        <= TriangleRef::MAX_BATCH_TRIANGLES
);
/// Vertices per unit of parallel work in the vertex stage. Small enough that a mesh of a few
/// thousand vertices is split evenly between threads: the 3644-vertex teapot in 2048-vertex
/// chunks gave two threads 2048 and 1596 vertices, and the geometry stages of `paper-c2` took
/// 175–181 µs on two threads instead of 98–106 µs with 512-vertex chunks; meshes of 100 000
/// vertices and more, already in many chunks, did not change.
const VERTEX_CHUNK: usize = 512;

/// One vertex-stage chunk's outputs besides the varyings: positions, window vertices, clip codes.
type VertexOutputs<'o> = (&'o mut [Vec4], &'o mut [WindowVertex], &'o mut [ClipCode]);

/// Output of the vertex stage for one draw.
#[derive(Default)]
pub(super) struct ShadedVertices {
    pub(super) pos_clip: Vec<Vec4>,
    /// Each vertex in window space ([`Viewport::window_vertex`]), computed once per vertex for
    /// the triangles that need no clipping (meaningless for vertices outside the guard band,
    /// which such triangles do not have).
    pub(super) window: Vec<WindowVertex>,
    /// Each vertex's [`ClipCode`] (finite, outcode, inside the guard band).
    pub(super) clip_codes: Vec<ClipCode>,
    pub(super) varyings: Vec<f32>,
}

/// The part of a draw the primitive stage produces for a range of its triangles.
#[derive(Default)]
pub(super) struct PrimitiveBatch {
    triangles: Vec<TriangleSetup>,
    /// Each triangle's `bbox` again, packed: binning reads only these, four to a cache line
    /// instead of one 232-byte record each (on two cores, the records were mostly written by
    /// the other core, and binning read at half speed).
    bboxes: Vec<PixelRect>,
    pub(super) attrs: Vec<f32>,
    /// Varyings per vertex of the batch's draw.
    pub(super) varying_count: usize,
    pub(super) counters: PrimitiveCounters,
}

impl PrimitiveBatch {
    pub(super) fn clear(&mut self, varying_count: usize) {
        self.triangles.clear();
        self.bboxes.clear();
        self.attrs.clear();
        self.varying_count = varying_count;
        self.counters = PrimitiveCounters::default();
    }

    /// Appends a set-up triangle (its varyings go to `attrs` separately).
    pub(super) fn push(&mut self, triangle: TriangleSetup) {
        self.bboxes.push(triangle.bbox);
        self.triangles.push(triangle);
    }
}

/// Where triangles are set up: the viewport and its guard band.
pub(super) struct TargetSpace {
    pub(super) viewport: Viewport,
    pub(super) guard: GuardBand,
}

/// Buffers of the geometry stages, kept by the renderer between frames so that a frame reuses
/// the previous one's allocations instead of paging fresh memory in and out.
#[derive(Default)]
pub(super) struct GeometryScratch {
    /// Vertex-stage output per draw (only the first `draws.len()` are current).
    pub(super) shaded: Vec<ShadedVertices>,
    /// Primitive-stage output per chunk (only the first `current_batches` are current).
    pub(super) batches: Vec<PrimitiveBatch>,
    pub(super) current_batches: usize,
    /// The primitive stage's units of work, `(draw, first triangle, end)`, one per batch.
    primitive_jobs: Vec<(usize, usize, usize)>,
    /// Each draw's back-to-front triangle order, where its state asks for one.
    orders: Vec<Option<Vec<u32>>>,
}

impl GeometryScratch {
    /// The current frame's set-up triangles.
    pub(super) fn output(&self) -> GeometryOutput<'_> {
        GeometryOutput {
            batches: &self.batches[..self.current_batches],
        }
    }
}

pub(super) fn run_geometry<J: GeometryJob + ?Sized>(
    draws: &[Box<J>],
    viewport: &Viewport,
    stats: &mut FrameStats,
    scratch: &mut GeometryScratch,
    budget: &FrameBudget<'_>,
) {
    let GeometryScratch {
        shaded,
        batches,
        current_batches,
        primitive_jobs,
        orders,
    } = scratch;
    // 1. Vertex stage over all draws, in chunks.
    if shaded.len() < draws.len() {
        shaded.resize_with(draws.len(), ShadedVertices::default);
    }
    let shaded = &mut shaded[..draws.len()];
    // Every element is overwritten below: resizing without clearing keeps last frame's values
    // in place of a fill with zeros (a frame stopped by its budget draws nothing from them).
    for (d, out) in draws.iter().zip(shaded.iter_mut()) {
        out.pos_clip.resize(d.vertex_count(), Vec4::ZERO);
        out.window.resize(d.vertex_count(), WindowVertex::default());
        out.clip_codes.resize(d.vertex_count(), ClipCode::default());
        out.varyings
            .resize(d.vertex_count() * d.varying_count(), 0.0);
    }
    let guard = GuardBand::new(viewport.width, viewport.height);
    // Draws in parallel, and each draw's vertices in chunks (no job list to allocate).
    shaded.par_iter_mut().enumerate().for_each(|(draw, out)| {
        let job = &draws[draw];
        let n = job.varying_count();
        let run = |chunk: usize, (pos, window, codes): VertexOutputs<'_>, vary: &mut [f32]| {
            // Budget: a chunk at a time (robust branch).
            if budget.exhausted() {
                return;
            }
            job.shade_vertices(chunk * VERTEX_CHUNK, pos, vary);
            for ((w, c), p) in window.iter_mut().zip(codes.iter_mut()).zip(pos.iter()) {
                *w = viewport.window_vertex(*p);
                *c = ClipCode::of(*p, &guard);
            }
        };
        let ShadedVertices {
            pos_clip,
            window,
            clip_codes,
            varyings,
        } = out;
        if pos_clip.len() <= VERTEX_CHUNK {
            // One chunk (a small draw, e.g. one of 2500 cubes): no nested parallel iterator.
            run(0, (pos_clip, window, clip_codes), varyings);
            return;
        }
        let chunks = pos_clip
            .par_chunks_mut(VERTEX_CHUNK)
            .zip(window.par_chunks_mut(VERTEX_CHUNK))
            .zip(clip_codes.par_chunks_mut(VERTEX_CHUNK))
            .map(|((pos, window), codes)| (pos, window, codes));
        if n == 0 {
            chunks
                .enumerate()
                .for_each(|(chunk, outputs)| run(chunk, outputs, &mut []));
        } else {
            chunks
                .zip(varyings.par_chunks_mut(VERTEX_CHUNK * n))
                .enumerate()
                .for_each(|(chunk, (outputs, vary))| run(chunk, outputs, vary));
        }
    });
    let shaded = &*shaded;
    if budget.exhausted() {
        *current_batches = 0;
        return;
    }

    // 2. Primitive stage over all draws, in chunks; results concatenated in order.
    primitive_jobs.clear();
    draws
        .par_iter()
        .zip(shaded.par_iter())
        .map(|(d, s)| d.sort_order(s))
        .collect_into_vec(orders);
    for (draw, d) in draws.iter().enumerate() {
        let count = d.primitive_count();
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
            batch.clear(draws[draw].varying_count());
            // Budget: a chunk at a time (robust branch).
            if budget.exhausted() {
                return;
            }
            draws[draw].assemble(
                draw as u32,
                first..last,
                orders[draw].as_deref(),
                &shaded[draw],
                &target,
                batch,
            );
        });

    *current_batches = batches.len();
    let mut counters = PrimitiveCounters::default();
    for batch in batches.iter() {
        counters = PrimitiveCounters::sum(counters, batch.counters);
    }
    stats.triangles_in = counters.triangles_in;
    stats.triangles_invalid = counters.invalid;
    stats.triangles_rejected = counters.rejected;
    stats.triangles_clipped = counters.clipped;
    stats.triangles_culled = counters.culled;
    stats.triangles_degenerate = counters.degenerate;
}
