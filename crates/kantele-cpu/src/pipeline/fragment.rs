//! The per-pixel path: for each tile, its triangles in submission order — tile depth bound,
//! coverage as 8 × 8 block masks, then eight pixels of a row at a time (barycentrics, depth, the
//! early depth test, perspective-correct varyings, the fragment program, blending and the depth
//! write) in one routine written over [`Lanes`] and compiled once per instruction set.
//!
//! The routine performs the same `f32` operations in the same order on every lane and for every
//! instruction set (no fused multiply-add), so the scalar build — the readable reference — and
//! the SIMD builds give the same picture bit for bit.

use super::budget::{FrameBudget, TRIANGLES_PER_CHECK};
use super::call::DrawCall;
use super::geometry::GeometryOutput;
use super::sanitize::zero_nan_channels;
use super::shader::{
    constant_varyings, vertex_varyings, FragmentLanes, Interpolation, LaneProgram, LaneProgramJob,
    Shader,
};
use super::shading_isas::dispatch_shading;
use crate::raster::bin::{TileBins, TriangleRef};
use crate::raster::samples::SampleCoverage;
use crate::raster::{rasterize_blocks, BlockCoverage, Strategy};
use crate::rop::{BlendMode, BlockRows, DeferredClear, DepthFunc, Framebuffer, TileBuffer};
use kantele_lanes::{prefetch, F32x8, I32x8, Isa, LaneKernel, Lanes, Mask8, MaskOf};
use kantele_rules::fixed::pixel_center;
use kantele_rules::setup::TriangleSetup;
use kantele_rules::state::RenderState;

use super::packed_rows::{packing_saves_a_row, PackedRows};

/// The raster's work for one draw, with the draw's shader type erased
/// ([`DrawJob`](super::draw::DrawJob) for the whole draw).
pub(super) trait RasterJob: Sync {
    /// Whether a triangle of this draw wholly behind a tile's depth bound can be skipped there:
    /// the test is LESS or LEQUAL (its fragments would all fail, and shaders have no side
    /// effects to miss).
    fn rejects_by_depth_bound(&self) -> bool;
    /// Shades the triangle's pixels in `coverage` into one tile (`packed`: the tile's storage
    /// for packed rows).
    fn raster(
        &self,
        tri: &TriangleSetup,
        attrs: &[f32],
        coverage: &BlockCoverage,
        packed: &mut PackedRows,
        tile: &mut TileBuffer,
        isa: Isa,
    ) -> RasterCounters;
    /// Shades the triangle's covered samples in `coverage` into one multisampled tile.
    fn raster_multisampled(
        &self,
        tri: &TriangleSetup,
        attrs: &[f32],
        coverage: &SampleCoverage,
        tile: &mut TileBuffer,
        isa: Isa,
    ) -> RasterCounters;
}

/// Fragment counters of one tile.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RasterCounters {
    pub(super) tile_rejected: u64,
    pub(super) blocks_rejected: u64,
    pub(super) covered: u64,
    pub(super) shaded: u64,
    pub(super) discarded: u64,
    /// Colour channels that were NaN and written as 0 (robust branch).
    pub(super) nan_channels: u64,
}

impl RasterCounters {
    pub(super) fn sum(a: Self, b: Self) -> Self {
        Self {
            tile_rejected: a.tile_rejected + b.tile_rejected,
            blocks_rejected: a.blocks_rejected + b.blocks_rejected,
            covered: a.covered + b.covered,
            shaded: a.shaded + b.shaded,
            discarded: a.discarded + b.discarded,
            nan_channels: a.nan_channels + b.nan_channels,
        }
    }
}

/// Tiles in one piece of the raster's parallel work, at most: every piece is one another thread
/// can take. Left to its own splitting, rayon gave each of two threads a run of tiles it could
/// not give away, and a picture whose costly tiles lay in one half waited for one thread;
/// single tiles balanced as well and cost more on full-screen fill.
pub(super) const TILES_PER_PIECE: usize = 4;

/// Rasterizes every tile's bin of a single-sampled frame, tiles in parallel, each tile's
/// triangles in order (a multisampled frame: `multisample::raster_tiles_multisampled`).
pub(super) fn raster_tiles<J: RasterJob + ?Sized>(
    framebuffer: &mut Framebuffer,
    bins: &TileBins,
    geometry: &GeometryOutput<'_>,
    draws: &[Box<J>],
    strategy: Strategy,
    isa: Isa,
    budget: &FrameBudget<'_>,
) -> RasterCounters {
    let grid = *framebuffer.grid();
    framebuffer.par_tiles(
        TILES_PER_PIECE,
        isa,
        |tile_index| !bins.tile_is_empty(tile_index),
        // The storage for packed rows is made once per piece of work (2 KB on the stack).
        PackedRows::new,
        |packed, tile_index, tile| {
            let rect = grid.tile_rect(tile_index);
            let mut counters = RasterCounters::default();
            let mut coverage = BlockCoverage::default();
            for (k, t) in binned_triangles(bins, geometry, tile_index) {
                // Budget: every few triangles (robust branch).
                if k % TRIANGLES_PER_CHECK == 0 && budget.exhausted() {
                    break;
                }
                let tri = geometry.triangle(t);
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
                rasterize_blocks(tri, rect, strategy, isa, &mut coverage);
                if coverage.is_empty() {
                    continue;
                }
                let attrs = geometry.attrs(t);
                // No `materialize`: the per-pixel path writes each block's pending clear
                // together with the first triangle that reaches the block.
                let c = draw.raster(tri, attrs, &coverage, packed, tile, isa);
                counters = RasterCounters::sum(counters, c);
            }
            counters
        },
        RasterCounters::sum,
    )
}

/// The triangles of tile `tile_index`'s bin in submission order, numbered from 0. When one is
/// handed out, the next one's setup record and varyings are prefetched: they are scattered over
/// what the geometry stage wrote, and would miss the cache when the next triangle is reached.
pub(super) fn binned_triangles<'a>(
    bins: &'a TileBins,
    geometry: &'a GeometryOutput<'_>,
    tile_index: usize,
) -> impl Iterator<Item = (usize, TriangleRef)> + 'a {
    let mut refs = bins.tile(tile_index).peekable();
    std::iter::from_fn(move || {
        let current = refs.next()?;
        if let Some(&next) = refs.peek() {
            prefetch(geometry.triangle(next));
            prefetch(geometry.attrs(next));
        }
        Some(current)
    })
    .enumerate()
}

/// Shades one triangle's covered pixels in one tile with the instruction set `isa`.
pub(super) fn shade_triangle<S: Shader>(
    draw: &DrawCall<'_, S>,
    tri: &TriangleSetup,
    attrs: &[f32],
    coverage: &BlockCoverage,
    packed: &mut PackedRows,
    tile: &mut TileBuffer,
    isa: Isa,
) -> RasterCounters {
    draw.shader.with_lane_program(ShadeTriangleJob {
        draw,
        tri,
        attrs,
        coverage,
        packed,
        tile,
        isa,
    })
}

/// [`shade_triangle`] waiting for the draw's lane program (see [`Shader::with_lane_program`]).
struct ShadeTriangleJob<'k, 'a, S: Shader> {
    draw: &'k DrawCall<'a, S>,
    tri: &'k TriangleSetup,
    attrs: &'k [f32],
    coverage: &'k BlockCoverage,
    packed: &'k mut PackedRows,
    tile: &'k mut TileBuffer,
    isa: Isa,
}

impl<S: Shader> LaneProgramJob for ShadeTriangleJob<'_, '_, S> {
    type Output = RasterCounters;

    #[inline(always)]
    fn run<P: LaneProgram>(self, program: &P) -> RasterCounters {
        let opaque_less = is_opaque_less(&self.draw.state);
        macro_rules! shade {
            ($opaque_less:literal, $constant:literal) => {
                dispatch_shading(
                    self.isa,
                    ShadeTriangle::<S, P, $opaque_less, $constant> {
                        draw: self.draw,
                        program,
                        tri: self.tri,
                        attrs: self.attrs,
                        coverage: self.coverage,
                        packed: self.packed,
                        tile: self.tile,
                    },
                )
            };
        }
        // `P::CONSTANT_KERNELS` is known when the kernel is compiled: a program that opts out
        // has no constant kernels compiled at all.
        if !P::CONSTANT_KERNELS {
            return if opaque_less {
                shade!(true, false)
            } else {
                shade!(false, false)
            };
        }
        match (opaque_less, constant_varyings(self.attrs)) {
            (true, false) => shade!(true, false),
            (true, true) => shade!(true, true),
            (false, false) => shade!(false, false),
            (false, true) => shade!(false, true),
        }
    }
}

/// Whether `state` is the common opaque state that the 1× kernels are compiled once more for:
/// depth test LESS with depth writes, no blending.
fn is_opaque_less(state: &RenderState) -> bool {
    state.depth_test
        && state.depth_func == DepthFunc::Less
        && state.depth_write
        && state.blend == BlendMode::Replace
}

/// A triangle's per-pixel constants splatted across the lanes, and the steps every lane kernel
/// (1× and multisampled) takes per row in the same order, so all give the same bits.
pub(super) struct TriangleLanes<L: Lanes> {
    /// `TriangleSetup::bary_gradient` of λ1 and λ2.
    g1: [L::F32; 2],
    g2: [L::F32; 2],
    /// Window depth and `1/w` per vertex, and the depth range.
    z: [L::F32; 3],
    z_range: [L::F32; 2],
    inv_w: [L::F32; 3],
    /// `1/w` per vertex over the largest of the three ([`relative_inv_w`]).
    inv_w_relative: [L::F32; 3],
    /// Sub-pixel offsets of the eight lanes' centres from lane 0's.
    lane_offset: L::I32,
    /// 0 and 1 in every lane.
    pub(super) zero: L::F32,
    pub(super) one: L::F32,
}

impl<L: Lanes> TriangleLanes<L> {
    #[inline(always)]
    pub(super) fn new(lanes: L, tri: &TriangleSetup) -> Self {
        let g = tri.bary_gradient;
        Self {
            g1: [lanes.splat_f32(g[0][0]), lanes.splat_f32(g[0][1])],
            g2: [lanes.splat_f32(g[1][0]), lanes.splat_f32(g[1][1])],
            z: [
                lanes.splat_f32(tri.depth[0]),
                lanes.splat_f32(tri.depth[1]),
                lanes.splat_f32(tri.depth[2]),
            ],
            z_range: [
                lanes.splat_f32(tri.depth_range[0]),
                lanes.splat_f32(tri.depth_range[1]),
            ],
            inv_w: [
                lanes.splat_f32(tri.inv_w[0]),
                lanes.splat_f32(tri.inv_w[1]),
                lanes.splat_f32(tri.inv_w[2]),
            ],
            inv_w_relative: {
                let r = relative_inv_w(tri.inv_w);
                [
                    lanes.splat_f32(r[0]),
                    lanes.splat_f32(r[1]),
                    lanes.splat_f32(r[2]),
                ]
            },
            lane_offset: lanes
                .lane_index()
                .shl::<{ kantele_rules::fixed::SUBPIXEL_BITS as i32 }>(),
            zero: lanes.splat_f32(0.0),
            one: lanes.splat_f32(1.0),
        }
    }

    /// Barycentrics `[λ0, λ1, λ2]` of the eight lanes whose first lies `(dx, dy)` sub-pixel
    /// units from vertex 0 (`TriangleSetup::barycentrics`): the offsets are exact integers
    /// (|d| < 2^31), converted to f32 with round-to-nearest-even.
    #[inline(always)]
    pub(super) fn barycentrics(&self, lanes: L, dx: i64, dy: i64) -> [L::F32; 3] {
        let columns = self.column_terms(lanes, dx);
        self.barycentrics_in_row(lanes, &columns, dy)
    }

    /// The x terms `g1.x · dx` and `g2.x · dx` of [`TriangleLanes::barycentrics`] for the eight
    /// lanes whose first lies `dx` sub-pixel units right of vertex 0: the same for every row of
    /// a block, so computed once per block.
    #[inline(always)]
    pub(super) fn column_terms(&self, lanes: L, dx: i64) -> [L::F32; 2] {
        let dx = (lanes.splat_i32(dx as i32) + self.lane_offset).to_f32();
        [self.g1[0] * dx, self.g2[0] * dx]
    }

    /// [`TriangleLanes::barycentrics`] of a row `dy` sub-pixel units below vertex 0, from the
    /// row's [`TriangleLanes::column_terms`] (the same operations in the same order).
    #[inline(always)]
    pub(super) fn barycentrics_in_row(
        &self,
        lanes: L,
        [x1, x2]: &[L::F32; 2],
        dy: i64,
    ) -> [L::F32; 3] {
        let dy = lanes.splat_f32(dy as f32);
        let l1 = *x1 + self.g1[1] * dy;
        let l2 = *x2 + self.g2[1] * dy;
        [self.one - l1 - l2, l1, l2]
    }

    /// Affine depth, clamped to the vertex range (`TriangleSetup::depth_at`).
    #[inline(always)]
    pub(super) fn depth(&self, [l0, l1, l2]: [L::F32; 3]) -> L::F32 {
        (l0 * self.z[0] + l1 * self.z[1] + l2 * self.z[2])
            .max(self.z_range[0])
            .min(self.z_range[1])
    }

    /// What the fragment program sees of the lanes `active` of `tri` with barycentrics `bary`
    /// and depths `depth`, lane 0 at pixel `[x, y]`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn fragments<'i>(
        &self,
        tri: &TriangleSetup,
        interpolation: &'i Interpolation<'i>,
        active: MaskOf<L>,
        depth: L::F32,
        bary: [L::F32; 3],
        [x, y]: [i32; 2],
    ) -> FragmentLanes<'i, L> {
        let (weights, w) = self.perspective_weights(bary);
        FragmentLanes {
            direction_weights: self.direction_weights(bary),
            lanes: self.zero.lanes(),
            x: x as u32,
            y: y as u32,
            active,
            depth,
            primitive_id: tri.primitive_id,
            front_facing: tri.front_facing(),
            weights,
            w,
            interpolation,
        }
    }

    /// Weights proportional to the perspective-correct ones, without their division
    /// ([`FragmentLanes::varying_direction`]): `λ_i · r_i` with `r` from [`relative_inv_w`].
    #[inline(always)]
    pub(super) fn direction_weights(&self, [l0, l1, l2]: [L::F32; 3]) -> [L::F32; 3] {
        let r = self.inv_w_relative;
        [l0 * r[0], l1 * r[1], l2 * r[2]]
    }

    /// Perspective-correct weights and `w` from screen-space barycentrics.
    #[inline(always)]
    pub(super) fn perspective_weights(&self, [l0, l1, l2]: [L::F32; 3]) -> ([L::F32; 3], L::F32) {
        let q = [l0 * self.inv_w[0], l1 * self.inv_w[1], l2 * self.inv_w[2]];
        let w = self.one / (q[0] + q[1] + q[2]);
        ([q[0] * w, q[1] * w, q[2] * w], w)
    }
}

/// A triangle's `1/w` per vertex divided by the largest of the three (each in `(0, 1]`, the
/// largest exactly 1). Screen-space barycentrics times these are proportional to the
/// perspective-correct weights (the factor is the smallest vertex `w` over the pixel's `w`), at
/// most 1 and summing to at least the ratio of the smallest to the largest vertex `w`, so that
/// a direction interpolated with them ([`FragmentLanes::varying_direction`]) neither overflows
/// nor underflows where the perspective-correct one would not. Non-finite where `1/w` is (not
/// for a triangle that passed clipping); the shader's normalisation then gives zero.
pub(crate) fn relative_inv_w(inv_w: [f32; 3]) -> [f32; 3] {
    let scale = 1.0 / inv_w[0].max(inv_w[1]).max(inv_w[2]);
    [inv_w[0] * scale, inv_w[1] * scale, inv_w[2] * scale]
}

/// A tile's deferred clear ([`DeferredClear`]) splatted across the lanes.
struct ClearLanes<L: Lanes> {
    color: [L::F32; 4],
    depth: L::F32,
}

impl<L: Lanes> ClearLanes<L> {
    /// `clear` across the lanes (`None` stays `None`; no closure: see [`kantele_lanes`]).
    #[inline(always)]
    fn splat(lanes: L, clear: Option<DeferredClear>) -> Option<Self> {
        let clear = clear?;
        Some(Self {
            color: [
                lanes.splat_f32(clear.color.x),
                lanes.splat_f32(clear.color.y),
                lanes.splat_f32(clear.color.z),
                lanes.splat_f32(clear.color.w),
            ],
            depth: lanes.splat_f32(clear.depth),
        })
    }
}

/// One triangle in one tile, as a kernel compiled per instruction set and lane program, and
/// once more for the state of most draws (`OPAQUE_LESS`: depth test LESS with depth writes, no
/// blending), whose per-row tests of that state are then decided at compile time. `CONSTANT`
/// triangles (every varying the same at the three vertices: [`Interpolation::constant`]) have
/// kernels of their own, unless the program opts out ([`LaneProgram::CONSTANT_KERNELS`]),
/// which read each varying as that value: a program that reads only
/// varyings then computes no perspective weights (no division per row), and the other kernels
/// test nothing for it per row.
struct ShadeTriangle<
    'k,
    'a,
    S: Shader,
    P: LaneProgram,
    const OPAQUE_LESS: bool,
    const CONSTANT: bool,
> {
    draw: &'k DrawCall<'a, S>,
    program: &'k P,
    tri: &'k TriangleSetup,
    attrs: &'k [f32],
    coverage: &'k BlockCoverage,
    packed: &'k mut PackedRows,
    tile: &'k mut TileBuffer,
}

impl<S: Shader, P: LaneProgram, const OPAQUE_LESS: bool, const CONSTANT: bool> LaneKernel
    for ShadeTriangle<'_, '_, S, P, OPAQUE_LESS, CONSTANT>
{
    type Output = RasterCounters;

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> RasterCounters {
        let ShadeTriangle {
            draw,
            program,
            tri,
            attrs,
            coverage,
            packed,
            tile,
        } = self;
        let state = &draw.state;
        let shader = draw.shader;
        let (dl_dx, dl_dy) = tri.barycentric_gradients();
        let vertex_attrs = vertex_varyings(attrs);
        let interpolation = Interpolation {
            attrs: &vertex_attrs,
            varying_count: shader.varying_count(),
            inv_w: tri.inv_w,
            dl_dx,
            dl_dy,
            constant: CONSTANT,
        };
        let triangle = TriangleLanes::new(lanes, tri);
        let (zero, one) = (triangle.zero, triangle.one);
        let [v0x, v0y] = tri.pos_subpixel[0];
        let mut counters = RasterCounters::default();
        let blocks_can_reject = draw.rejects_by_depth_bound();
        let rules = RowRules {
            state,
            // Interpolated depth is clamped to the vertex range, so when that range lies in
            // [0, 1] no lane can fall outside it and the per-row range test is skipped (a NaN
            // bound fails the comparison and keeps the test).
            depth_needs_range_test: !(tri.depth_range[0] >= 0.0 && tri.depth_range[1] <= 1.0),
            // Replace ignores the stored colour and passes the sanitised source through:
            // nothing to load, and nothing new to sanitise after blending.
            blend_reads_target: !OPAQUE_LESS && state.blend != BlendMode::Replace,
            depth_test: OPAQUE_LESS || state.depth_test,
            depth_write: OPAQUE_LESS || state.depth_write,
            // LESS, every built-in material's test, is compared directly: the general function
            // is a jump table in the row loop.
            depth_less: OPAQUE_LESS || state.depth_func == DepthFunc::Less,
        };

        for block in coverage.blocks() {
            // Depth hierarchy, second level: a block whose every stored depth is in front of the
            // triangle's nearest vertex is skipped (LESS / LEQUAL only; shaders are pure).
            let block_index = TileBuffer::block_index(block.x, block.y);
            if blocks_can_reject && tile.block_occludes(block_index, tri.depth_range[0]) {
                counters.blocks_rejected += 1;
                continue;
            }
            counters.covered += block.mask.count_ones() as u64;
            // The tile's clear, when this block's storage does not hold it yet: every row of the
            // block is then stored whole, the clear where this triangle writes nothing, so the
            // clear is written once, together with the triangle, and never read back.
            let pending = ClearLanes::splat(lanes, tile.take_pending_block(block_index));
            // Lanes shaded and lanes kept, row by row (bit `8·row + lane`): counted once per
            // block, not per row.
            let mut shaded_bits = 0u64;
            let mut kept_bits = 0u64;
            let columns = triangle.column_terms(lanes, pixel_center(block.x as i64) - v0x);
            let mut rows = tile.block_rows_mut(TileBuffer::index(block.x, block.y));
            // Packed (see `packed_rows`): the rows' tests first, their fragments packed one
            // after another, then the program eight packed fragments at a time, then each
            // row's results back in its lanes. Otherwise the program runs row by row. The
            // program has one call site for both, so it is compiled once per kernel.
            let pack = P::PACKED_ROWS && !CONSTANT && packing_saves_a_row(block.mask);
            let mut row_active = [0u8; 8];
            let mut row_depth = [zero; 8];
            let mut count = 0;
            if pack {
                for row in 0..8 {
                    let row_bits = (block.mask >> (8 * row)) as u8;
                    if row_bits == 0 {
                        continue;
                    }
                    let dy = pixel_center((block.y + row as i32) as i64) - v0y;
                    let bary = triangle.barycentrics_in_row(lanes, &columns, dy);
                    let depth = triangle.depth(bary);
                    let at = BlockRows::row_offset(row);
                    let active = rules.active(lanes, row_bits, depth, &rows, at, &pending);
                    let bits = active.bits();
                    if bits == 0 {
                        continue;
                    }
                    (row_active[row], row_depth[row]) = (bits, depth);
                    packed.pack(lanes, count, bits, bary, depth);
                    count += bits.count_ones() as usize;
                }
            }
            let calls = if pack { count.div_ceil(8) } else { 8 };
            for call in 0..calls {
                // The fragments of this call: a packed group, or the row at `at`.
                let at = BlockRows::row_offset(call);
                let (active, depth, bary, y) = if pack {
                    let group = 8 * call;
                    let active =
                        lanes.mask_from_bits((0xffu16 >> (8 - (count - group).min(8))) as u8);
                    let (bary, depth) = packed.group(lanes, group, one);
                    (active, depth, bary, block.y)
                } else {
                    let row_bits = (block.mask >> (8 * call)) as u8;
                    let y = block.y + call as i32;
                    // No closure around lane code here: LLVM may compile its body out of line,
                    // without the kernel's instruction set.
                    let mut active = lanes.mask_all(false);
                    let (mut depth, mut bary) = (zero, [zero; 3]);
                    if row_bits != 0 {
                        let dy = pixel_center(y as i64) - v0y;
                        bary = triangle.barycentrics_in_row(lanes, &columns, dy);
                        depth = triangle.depth(bary);
                        active = rules.active(lanes, row_bits, depth, &rows, at, &pending);
                    }
                    if active.none() {
                        rules.store(lanes, None, &mut rows, at, &pending);
                        continue;
                    }
                    (active, depth, bary, y)
                };
                let shaded = program.fragment_lanes(&triangle.fragments(
                    tri,
                    &interpolation,
                    active,
                    depth,
                    bary,
                    [block.x, y],
                ));
                let keep = active.and(shaded.keep);
                if pack {
                    packed.store_shaded::<L>(8 * call, shaded.color, keep, [zero, one]);
                    continue;
                }
                shaded_bits |= (active.bits() as u64) << (8 * call);
                kept_bits |= (keep.bits() as u64) << (8 * call);
                let written = rules
                    .finish(
                        lanes,
                        shaded.color,
                        keep,
                        &rows,
                        at,
                        &pending,
                        &mut counters,
                    )
                    .map(|color| (color, depth, keep));
                rules.store(lanes, written, &mut rows, at, &pending);
            }
            if pack {
                // Each row's results back in its lanes, blended and stored.
                let mut group_at = 0;
                for row in 0..8 {
                    let at = BlockRows::row_offset(row);
                    let bits = row_active[row];
                    let written = if bits == 0 {
                        None
                    } else {
                        shaded_bits |= (bits as u64) << (8 * row);
                        let (color, keep) = packed.unpack(lanes, group_at, bits, zero);
                        group_at += bits.count_ones() as usize;
                        kept_bits |= (keep.bits() as u64) << (8 * row);
                        rules
                            .finish(lanes, color, keep, &rows, at, &pending, &mut counters)
                            .map(|color| (color, row_depth[row], keep))
                    };
                    rules.store(lanes, written, &mut rows, at, &pending);
                }
            }
            let shaded_count = shaded_bits.count_ones() as u64;
            counters.shaded += shaded_count;
            counters.discarded += shaded_count - kept_bits.count_ones() as u64;
            if rules.depth_write && kept_bits != 0 {
                // Keep the block's bound exact: the largest of its 64 depths.
                let mut largest = lanes.load_f32(&rows.depth[..8]);
                for row in 1..8 {
                    let at = BlockRows::row_offset(row);
                    largest = largest.max(lanes.load_f32(&rows.depth[at..at + 8]));
                }
                tile.set_block_depth_max(block_index, largest.reduce_max());
            }
        }
        counters
    }
}

/// The render state's per-row decisions of one kernel call, made before its first row.
struct RowRules<'s> {
    state: &'s RenderState,
    /// The triangle's depth range is not within [0, 1] (or is NaN): each row tests its depths.
    depth_needs_range_test: bool,
    /// Blending reads the stored colour (not Replace).
    blend_reads_target: bool,
    depth_test: bool,
    depth_write: bool,
    /// The depth test is LESS.
    depth_less: bool,
}

impl RowRules<'_> {
    /// The lanes of the row at `at` in `rows` that hold a fragment: covered (`row_bits`),
    /// inside [0, 1] in depth where that needs a test, and passing the depth test against the
    /// stored depth (the pending clear's where there is one).
    #[inline(always)]
    fn active<L: Lanes>(
        &self,
        lanes: L,
        row_bits: u8,
        depth: L::F32,
        rows: &BlockRows<'_>,
        at: usize,
        pending: &Option<ClearLanes<L>>,
    ) -> MaskOf<L> {
        let mut active = lanes.mask_from_bits(row_bits);
        if self.depth_needs_range_test {
            // Outside [0, 1] (or NaN): beyond the near or far plane.
            active = active
                .and(depth.simd_ge(lanes.splat_f32(0.0)))
                .and(depth.simd_le(lanes.splat_f32(1.0)));
        }
        if self.depth_test {
            let stored = match pending {
                Some(clear) => clear.depth,
                None => lanes.load_f32(&rows.depth[at..at + 8]),
            };
            let passes = if self.depth_less {
                depth.simd_lt(stored)
            } else {
                self.state.depth_func.passes_lanes(lanes, depth, stored)
            };
            active = active.and(passes);
        }
        active
    }

    /// The colour a row writes where `keep` is set, from the program's `src`: NaN channels
    /// written as 0 and counted, before and after blending with the stored colour (blending
    /// infinities can make NaN) (robust branch). `None` when no lane is kept.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn finish<L: Lanes>(
        &self,
        lanes: L,
        src: [L::F32; 4],
        keep: MaskOf<L>,
        rows: &BlockRows<'_>,
        at: usize,
        pending: &Option<ClearLanes<L>>,
        counters: &mut RasterCounters,
    ) -> Option<[L::F32; 4]> {
        if keep.none() {
            return None;
        }
        let (src, nan_src) = zero_nan_channels(lanes, src, keep);
        counters.nan_channels += nan_src;
        if !self.blend_reads_target {
            return Some(src);
        }
        let dst = match pending {
            Some(clear) => clear.color,
            None => [
                lanes.load_f32(&rows.color[0][at..at + 8]),
                lanes.load_f32(&rows.color[1][at..at + 8]),
                lanes.load_f32(&rows.color[2][at..at + 8]),
                lanes.load_f32(&rows.color[3][at..at + 8]),
            ],
        };
        let blended = self.state.blend.blend_lanes(lanes, src, dst);
        let (blended, nan_blended) = zero_nan_channels(lanes, blended, keep);
        counters.nan_channels += nan_blended;
        Some(blended)
    }

    /// Stores the row at `at`: `written` (colour, depth and the kept lanes) where kept; with a
    /// pending clear, the whole row, the clear elsewhere (a row the triangle did not write
    /// keeps no lane).
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn store<L: Lanes>(
        &self,
        lanes: L,
        written: Option<([L::F32; 4], L::F32, MaskOf<L>)>,
        rows: &mut BlockRows<'_>,
        at: usize,
        pending: &Option<ClearLanes<L>>,
    ) {
        let [r, g, b, a] = &mut rows.color;
        match pending {
            None => {
                if let Some((color, depth, keep)) = written {
                    color[0].store_masked(keep, &mut r[at..at + 8]);
                    color[1].store_masked(keep, &mut g[at..at + 8]);
                    color[2].store_masked(keep, &mut b[at..at + 8]);
                    color[3].store_masked(keep, &mut a[at..at + 8]);
                    if self.depth_write {
                        depth.store_masked(keep, &mut rows.depth[at..at + 8]);
                    }
                }
            }
            Some(clear) => {
                let (color, depth, keep) =
                    written.unwrap_or((clear.color, clear.depth, lanes.mask_all(false)));
                let depth = if self.depth_write { depth } else { clear.depth };
                keep.select_f32(color[0], clear.color[0])
                    .store(&mut r[at..at + 8]);
                keep.select_f32(color[1], clear.color[1])
                    .store(&mut g[at..at + 8]);
                keep.select_f32(color[2], clear.color[2])
                    .store(&mut b[at..at + 8]);
                keep.select_f32(color[3], clear.color[3])
                    .store(&mut a[at..at + 8]);
                keep.select_f32(depth, clear.depth)
                    .store(&mut rows.depth[at..at + 8]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::relative_inv_w;

    /// The largest `1/w` becomes 1 exactly, the others keep their ratios to it, and far-apart
    /// values neither overflow nor vanish.
    #[test]
    fn relative_inv_w_scales_the_largest_to_one() {
        assert_eq!(relative_inv_w([0.5, 2.0, 1.0]), [0.25, 1.0, 0.5]);
        assert_eq!(relative_inv_w([4.0, 4.0, 4.0]), [1.0, 1.0, 1.0]);
        let r = relative_inv_w([1e-20, 1.0, 1e20]);
        assert_eq!(r[2], 1.0);
        assert!(
            r[0] > 0.0 && r[1] > 0.0 && r.iter().all(|v| v.is_finite()),
            "{r:?}"
        );
    }
}
