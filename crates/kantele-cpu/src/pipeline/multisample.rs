//! The per-pixel path of a multisampled target: per-sample coverage, depth test, depth write
//! and blending, with the fragment program run once per pixel at the pixel centre (OpenGL's
//! multisampling without `centroid` or sample shading). See [`kantele_rules::multisample`].
//!
//! Like the single-sample path in `fragment.rs` (which a 1× target keeps using, unchanged), the
//! routine is written once over [`Lanes`] and performs the same `f32` operations in the same
//! order on every lane and instruction set, so the picture is identical bit for bit for every
//! instruction set, strategy and thread count.
//!
//! Besides its samples, each pixel has a hidden *centre* plane (coverage plane 0, depth plane
//! 0): covered, depth-tested and depth-written exactly as the single sample of a 1× frame, and
//! never part of the colour. It keeps the read-back depth equal to a 1× render's.
//!
//! The depth hierarchy stays exact: a block's bound is the largest depth over every plane of
//! the block (centre and samples), and the tile's bound is refreshed over every plane, so a
//! block or tile is skipped only when every sample in it would fail.

use super::budget::{FrameBudget, TRIANGLES_PER_CHECK};
use super::call::DrawCall;
use super::fragment::{
    binned_triangles, RasterCounters, RasterJob, TriangleLanes, TILES_PER_PIECE,
};
use super::geometry::GeometryOutput;
use super::sanitize::zero_nan_channels;
use super::shader::{
    constant_varyings, vertex_varyings, FragmentLanes, Interpolation, LaneProgram, LaneProgramJob,
    Shader,
};
use super::shading_isas::dispatch_shading;
use crate::raster::bin::TileBins;
use crate::raster::samples::{rasterize_samples, SampleCoverage, MAX_COVERAGE_PLANES};
use crate::raster::Strategy;
use crate::rop::{BlendMode, DepthFunc, Framebuffer, TileBuffer};
use kantele_lanes::{F32x8, Isa, LaneKernel, Lanes, Mask8};
use kantele_rules::fixed::{pixel_center, BLOCK_SIZE, TILE_SIZE};
use kantele_rules::setup::TriangleSetup;

/// Rasterizes every tile's bin into a multisampled framebuffer, tiles in parallel, each tile's
/// triangles in order.
pub(super) fn raster_tiles_multisampled<J: RasterJob + ?Sized>(
    framebuffer: &mut Framebuffer,
    bins: &TileBins,
    geometry: &GeometryOutput<'_>,
    draws: &[Box<J>],
    strategy: Strategy,
    isa: Isa,
    budget: &FrameBudget<'_>,
) -> RasterCounters {
    let grid = *framebuffer.grid();
    let samples = framebuffer.samples();
    framebuffer.par_tiles(
        TILES_PER_PIECE,
        isa,
        |tile_index| !bins.tile_is_empty(tile_index),
        || (),
        |(), tile_index, tile| {
            let rect = grid.tile_rect(tile_index);
            let mut counters = RasterCounters::default();
            let mut coverage = SampleCoverage::default();
            for (k, t) in binned_triangles(bins, geometry, tile_index) {
                if k % TRIANGLES_PER_CHECK == 0 && budget.exhausted() {
                    break;
                }
                let tri = geometry.triangle(t);
                let draw = &draws[tri.draw as usize];
                // The tile's bound covers every depth plane (centre and samples).
                if draw.rejects_by_depth_bound() {
                    let r = rect.intersect(&tri.bbox);
                    let area = r.width() * r.height();
                    if tile.occludes(tri.depth_range[0], area, &rect) {
                        counters.tile_rejected += 1;
                        continue;
                    }
                }
                rasterize_samples(tri, rect, strategy, samples, isa, &mut coverage);
                if coverage.is_empty() {
                    continue;
                }
                let attrs = geometry.attrs(t);
                tile.materialize();
                let c = draw.raster_multisampled(tri, attrs, &coverage, tile, isa);
                counters = RasterCounters::sum(counters, c);
            }
            counters
        },
        RasterCounters::sum,
    )
}

/// Shades one triangle's covered samples in one multisampled tile with the instruction set
/// `isa`, running the draw's lane program ([`Shader::with_lane_program`], as the 1× path does).
pub(super) fn shade_triangle_multisampled<S: Shader>(
    draw: &DrawCall<'_, S>,
    tri: &TriangleSetup,
    attrs: &[f32],
    coverage: &SampleCoverage,
    tile: &mut TileBuffer,
    isa: Isa,
) -> RasterCounters {
    draw.shader.with_lane_program(ShadeSamplesJob {
        draw,
        tri,
        attrs,
        coverage,
        tile,
        isa,
    })
}

/// [`shade_triangle_multisampled`] waiting for the draw's lane program.
struct ShadeSamplesJob<'k, 'a, S: Shader> {
    draw: &'k DrawCall<'a, S>,
    tri: &'k TriangleSetup,
    attrs: &'k [f32],
    coverage: &'k SampleCoverage,
    tile: &'k mut TileBuffer,
    isa: Isa,
}

impl<S: Shader> LaneProgramJob for ShadeSamplesJob<'_, '_, S> {
    type Output = RasterCounters;

    #[inline(always)]
    fn run<P: LaneProgram>(self, program: &P) -> RasterCounters {
        dispatch_shading(
            self.isa,
            ShadeSamples::<S, P> {
                draw: self.draw,
                program,
                tri: self.tri,
                attrs: self.attrs,
                coverage: self.coverage,
                tile: self.tile,
            },
        )
    }
}

/// One triangle in one multisampled tile, as a kernel compiled per instruction set and lane
/// program. A LESS depth test is compared directly, and Replace writes the shaded colour
/// without reading the samples' colours (what blending with Replace would give, bit for bit):
/// branches on the draw's state, not kernels of their own. A kernel per state class cost build
/// time and memory (the largest part of the renderer's compile) and gave no measurable speed,
/// the shading program dominating a multisampled row.
struct ShadeSamples<'k, 'a, S: Shader, P: LaneProgram> {
    draw: &'k DrawCall<'a, S>,
    program: &'k P,
    tri: &'k TriangleSetup,
    attrs: &'k [f32],
    coverage: &'k SampleCoverage,
    tile: &'k mut TileBuffer,
}

impl<S: Shader, P: LaneProgram> LaneKernel for ShadeSamples<'_, '_, S, P> {
    type Output = RasterCounters;

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> RasterCounters {
        let ShadeSamples {
            draw,
            program,
            tri,
            attrs,
            coverage,
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
            constant: constant_varyings(attrs),
        };
        let triangle = TriangleLanes::new(lanes, tri);
        let (zero, one) = (triangle.zero, triangle.one);
        let [v0x, v0y] = tri.pos_subpixel[0];
        let planes = coverage.planes();
        let samples = planes - 1;
        let offsets = tile_sample_offsets(samples);
        let mut counters = RasterCounters::default();
        let blocks_can_reject = draw.rejects_by_depth_bound();
        let none = lanes.mask_all(false);
        // Depth at a covered sample is clamped to the vertex range (`TriangleLanes::depth`):
        // within [0, 1] when that range is, so the range test is needed only otherwise (a NaN
        // bound fails the comparison and keeps the test), as in the 1× path.
        let depth_needs_range_test = !(tri.depth_range[0] >= 0.0 && tri.depth_range[1] <= 1.0);
        let (depth_test, depth_write) = (state.depth_test, state.depth_write);
        let depth_less = state.depth_func == DepthFunc::Less;
        let replace = state.blend == BlendMode::Replace;

        for block in coverage.blocks() {
            if blocks_can_reject && tile.block_occludes(block.index, tri.depth_range[0]) {
                counters.blocks_rejected += 1;
                continue;
            }
            let mut wrote_depth = false;
            for row in 0..8 {
                let union_bits = (block.union >> (8 * row)) as u8;
                if union_bits == 0 {
                    continue;
                }
                counters.covered += union_bits.count_ones() as u64;
                let (x, y) = (block.x, block.y + row);
                let index = TileBuffer::index(x, y);
                let centre_dx = pixel_center(x as i64) - v0x;
                let centre_dy = pixel_center(y as i64) - v0y;
                // Per plane: which lanes pass, and their depth. Plane 0 (the pixel centre) is
                // computed exactly as the 1× path does; it also feeds the fragment program.
                let mut pass = [none; MAX_COVERAGE_PLANES];
                let mut depths = [zero; MAX_COVERAGE_PLANES];
                let mut centre = [zero; 3];
                let mut any = none;
                for plane in 0..planes {
                    let bits = (coverage.mask(plane, block.index) >> (8 * row)) as u8;
                    // An uncovered sample needs nothing; the centre's values feed shading.
                    if bits == 0 && plane != 0 {
                        continue;
                    }
                    let [ox, oy] = offsets[plane];
                    let bary = triangle.barycentrics(lanes, centre_dx + ox, centre_dy + oy);
                    let depth = triangle.depth(bary);
                    depths[plane] = depth;
                    if plane == 0 {
                        centre = bary;
                    }
                    if bits == 0 {
                        continue;
                    }
                    let mut active = lanes.mask_from_bits(bits);
                    if depth_needs_range_test {
                        active = active.and(depth.simd_ge(zero)).and(depth.simd_le(one));
                    }
                    if depth_test {
                        let stored = lanes.load_f32(tile.depth_plane_row(plane, index));
                        let passes = if depth_less {
                            depth.simd_lt(stored)
                        } else {
                            state.depth_func.passes_lanes(lanes, depth, stored)
                        };
                        active = active.and(passes);
                    }
                    pass[plane] = active;
                    any = any.or(active);
                }
                if any.none() {
                    continue;
                }
                // One shading per pixel, at the pixel centre (perspective-correct weights).
                let (weights, w) = triangle.perspective_weights(centre);
                let fragments = FragmentLanes {
                    lanes,
                    x: x as u32,
                    y: y as u32,
                    active: any,
                    depth: depths[0].max(zero).min(one),
                    primitive_id: tri.primitive_id,
                    front_facing: tri.front_facing(),
                    weights,
                    direction_weights: triangle.direction_weights(centre),
                    w,
                    interpolation: &interpolation,
                };
                let shaded = program.fragment_lanes(&fragments);
                let keep = any.and(shaded.keep);
                let active_count = any.count() as u64;
                let kept = keep.count() as u64;
                counters.shaded += active_count;
                counters.discarded += active_count - kept;
                if kept == 0 {
                    continue;
                }
                let (src, nan_src) = zero_nan_channels(lanes, shaded.color, keep);
                counters.nan_channels += nan_src;
                for sample in 0..samples {
                    let keep_sample = pass[1 + sample].and(shaded.keep);
                    if keep_sample.none() {
                        continue;
                    }
                    let blended = if replace {
                        // Replace: the sanitised source, as `blend_lanes` would return it.
                        src
                    } else {
                        let [r, g, b, a] = tile.sample_color_row(sample, index);
                        let dst = [
                            lanes.load_f32(r),
                            lanes.load_f32(g),
                            lanes.load_f32(b),
                            lanes.load_f32(a),
                        ];
                        let blended = state.blend.blend_lanes(lanes, src, dst);
                        let (blended, nan_blended) = zero_nan_channels(lanes, blended, keep_sample);
                        counters.nan_channels += nan_blended;
                        blended
                    };
                    let [r, g, b, a] = tile.sample_color_row_mut(sample, index);
                    blended[0].store_masked(keep_sample, r);
                    blended[1].store_masked(keep_sample, g);
                    blended[2].store_masked(keep_sample, b);
                    blended[3].store_masked(keep_sample, a);
                    if depth_write {
                        depths[1 + sample]
                            .store_masked(keep_sample, tile.sample_depth_row_mut(sample, index));
                        wrote_depth = true;
                    }
                }
                let keep_centre = pass[0].and(shaded.keep);
                if depth_write && keep_centre.any() {
                    depths[0].store_masked(keep_centre, tile.depth_row_mut(index));
                    wrote_depth = true;
                }
            }
            if wrote_depth {
                // Keep the block's bound exact: the largest depth over every plane.
                let first = TileBuffer::index(block.x, block.y);
                let row_stride = TILE_SIZE as usize;
                let mut largest = lanes.load_f32(tile.depth_plane_row(0, first));
                for plane in 0..planes {
                    for row in 0..BLOCK_SIZE as usize {
                        let values = tile.depth_plane_row(plane, first + row * row_stride);
                        largest = largest.max(lanes.load_f32(values));
                    }
                }
                tile.set_block_depth_max(block.index, largest.reduce_max());
            }
        }
        counters
    }
}

/// Offsets (sub-pixel units) of each coverage plane from the pixel centre: plane 0 is the
/// centre itself, plane `1 + s` sample `s` of a `samples`-sample target.
#[inline(always)]
fn tile_sample_offsets(samples: usize) -> [[i64; 2]; MAX_COVERAGE_PLANES] {
    let count = match samples {
        8 => kantele_rules::multisample::SampleCount::X8,
        4 => kantele_rules::multisample::SampleCount::X4,
        _ => kantele_rules::multisample::SampleCount::X1,
    };
    let mut out = [[0; 2]; MAX_COVERAGE_PLANES];
    out[1..].copy_from_slice(&count.offsets_subpixel());
    out
}
