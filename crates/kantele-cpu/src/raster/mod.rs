//! Rasterization: finding the pixels a set-up triangle covers inside one tile.
//!
//! Takes a [`TriangleSetup`] and the rectangle of the tile it is drawn into, and calls a visitor
//! for each covered pixel. Five traversal strategies from the half-space paper are provided;
//! they differ only in how many edge-function evaluations they spend, never in the result:
//! every one visits exactly the pixels `p` of the rectangle with `E_i(p) + bias_i ≥ 0` for all
//! three edges, each once.

pub mod bin;
mod block_lanes;
mod blocks;
pub mod samples;

use std::str::FromStr;

use blocks::{Scan, ScanKernel};
use kantele_lanes::{dispatch, Isa};
use kantele_rules::fixed::{BLOCK_LOG2, BLOCK_SIZE, TILE_LOG2, TILE_SIZE};
use kantele_rules::setup::{PixelRect, TriangleSetup};

/// How a triangle's pixels are found. Every strategy produces identical coverage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// Every pixel of the bounding box, edge functions evaluated from scratch.
    BoundingBox,
    /// Bounding box scan with edge functions stepped incrementally.
    Incremental,
    /// 8 × 8 blocks classified empty / partial / full by their corners.
    Block,
    /// Blocks when the bounding box's aspect ratio is within 0.4–1.6 and it spans at least
    /// [`ADAPTIVE_MIN_SIDE`] pixels, incremental otherwise (the paper's adaptive model).
    Adaptive,
    /// Adaptive, with block rows traversed outwards from a start block halfway between the
    /// previous row's bounds (the paper's bisector traversal).
    #[default]
    Bisector,
}

impl Strategy {
    /// Every strategy.
    pub const ALL: [Strategy; 5] = [
        Strategy::BoundingBox,
        Strategy::Incremental,
        Strategy::Block,
        Strategy::Adaptive,
        Strategy::Bisector,
    ];

    /// The name used on command lines.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::BoundingBox => "bbox",
            Strategy::Incremental => "incremental",
            Strategy::Block => "block",
            Strategy::Adaptive => "adaptive",
            Strategy::Bisector => "bisector",
        }
    }
}

impl std::fmt::Display for Strategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Strategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Strategy::ALL
            .into_iter()
            .find(|st| st.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown strategy '{s}' (expected one of: bbox, incremental, block, adaptive, bisector)"
                )
            })
    }
}

/// The pixels a triangle covers in one 8 × 8 block: bit `8·r + c` is pixel `(x + c, y + r)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoveredBlock {
    /// Column of the block's first pixel (a multiple of 8).
    pub x: i32,
    /// Row of the block's first pixel (a multiple of 8).
    pub y: i32,
    /// Coverage bits, row-major: bit `8·r + c` is pixel `(x + c, y + r)`.
    pub mask: u64,
}

/// A triangle's coverage in one tile, as the blocks with at least one covered pixel. Reused
/// from triangle to triangle (no allocation once grown to the 64 blocks of a tile).
#[derive(Clone, Debug, Default)]
pub struct BlockCoverage {
    blocks: Vec<CoveredBlock>,
}

impl BlockCoverage {
    /// The covered blocks, in traversal order (each block once).
    #[inline]
    pub fn blocks(&self) -> &[CoveredBlock] {
        &self.blocks
    }

    /// Whether no pixel is covered.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Number of covered pixels.
    pub fn pixel_count(&self) -> u64 {
        self.blocks.iter().map(|b| b.mask.count_ones() as u64).sum()
    }

    #[inline]
    fn push(&mut self, x: i32, y: i32, mask: u64) {
        if mask != 0 {
            self.blocks.push(CoveredBlock {
                x: x & !(BLOCK_SIZE as i32 - 1),
                y: y & !(BLOCK_SIZE as i32 - 1),
                mask,
            });
        }
    }
}

/// Finds the covered pixels of `rect` as 8 × 8 block masks, replacing what `out` held. `rect`
/// must lie within one 64 × 64 tile (tile-aligned), as the pipeline's tiles do. `isa` is the
/// instruction set of the lane-wide block masks (every level gives the same bits).
#[inline(never)]
pub fn rasterize_blocks(
    tri: &TriangleSetup,
    rect: PixelRect,
    strategy: Strategy,
    isa: Isa,
    out: &mut BlockCoverage,
) {
    out.blocks.clear();
    let rect = rect.intersect(&tri.bbox);
    if rect.is_empty() {
        return;
    }
    debug_assert!(
        rect.x0 >> TILE_LOG2 == (rect.x1 - 1) >> TILE_LOG2
            && rect.y0 >> TILE_LOG2 == (rect.y1 - 1) >> TILE_LOG2,
        "rectangle spans more than one tile"
    );
    let uses_blocks = match strategy {
        Strategy::BoundingBox | Strategy::Incremental => false,
        Strategy::Block => true,
        Strategy::Adaptive | Strategy::Bisector => prefers_blocks(tri),
    };
    // The block strategies first try the whole rectangle: when it lies inside the triangle
    // (a full-screen quad in most of its tiles), every pixel is covered and no block is
    // classified or scanned.
    if uses_blocks && rect_inside(tri, &rect) {
        push_rect(rect, out);
        return;
    }
    let scan = match strategy {
        Strategy::BoundingBox => return scan_bounding_box(tri, rect, out),
        Strategy::Bisector if uses_blocks => Scan::Bisector,
        Strategy::Block | Strategy::Adaptive if uses_blocks => Scan::Blocks,
        _ => return scan_incremental(tri, rect, out),
    };
    dispatch(
        isa,
        ScanKernel {
            tri,
            rect,
            scan,
            out,
        },
    );
}

/// Whether the centre of every pixel of `rect` (non-empty) is covered: edge functions are
/// linear, so a rectangle whose four corner pixels are inside an edge is wholly inside it.
#[inline]
fn rect_inside(tri: &TriangleSetup, rect: &PixelRect) -> bool {
    let (x1, y1) = (rect.x1 - 1, rect.y1 - 1);
    tri.edges.iter().all(|e| {
        e.biased_at_pixel(rect.x0, rect.y0) >= 0
            && e.biased_at_pixel(x1, rect.y0) >= 0
            && e.biased_at_pixel(rect.x0, y1) >= 0
            && e.biased_at_pixel(x1, y1) >= 0
    })
}

/// Appends every pixel of `rect` (non-empty, within one tile) as covered, block by block in
/// row-major order.
fn push_rect(rect: PixelRect, out: &mut BlockCoverage) {
    let block = BLOCK_SIZE as i32;
    let mut y0 = rect.y0;
    while y0 < rect.y1 {
        let y1 = ((y0 & !(block - 1)) + block).min(rect.y1);
        let mut x0 = rect.x0;
        while x0 < rect.x1 {
            let x1 = ((x0 & !(block - 1)) + block).min(rect.x1);
            out.push(x0, y0, rect_mask(&PixelRect { x0, y0, x1, y1 }));
            x0 = x1;
        }
        y0 = y1;
    }
}

/// The bits of `part` (non-empty, within one 8-aligned block) in that block's mask.
#[inline(always)]
fn rect_mask(part: &PixelRect) -> u64 {
    let columns = (0xffu64 >> (BLOCK_SIZE as i32 - part.width())) << (part.x0 & 7);
    let rows = (u64::MAX >> (64 - 8 * part.height())) << ((part.y0 & 7) << 3);
    (columns * 0x0101_0101_0101_0101) & rows
}

/// Calls `visit(x, y)` once for every pixel of `rect` whose centre `tri` covers (any rectangle;
/// it is walked tile by tile through [`rasterize_blocks`], with the instruction set `isa`).
pub fn rasterize(
    tri: &TriangleSetup,
    rect: PixelRect,
    strategy: Strategy,
    isa: Isa,
    mut visit: impl FnMut(i32, i32),
) {
    let rect = rect.intersect(&tri.bbox);
    if rect.is_empty() {
        return;
    }
    let mut coverage = BlockCoverage::default();
    let tile = TILE_SIZE as i32;
    let mut ty = rect.y0 & !(tile - 1);
    while ty < rect.y1 {
        let mut tx = rect.x0 & !(tile - 1);
        while tx < rect.x1 {
            let part = rect.intersect(&PixelRect {
                x0: tx,
                y0: ty,
                x1: tx + tile,
                y1: ty + tile,
            });
            rasterize_blocks(tri, part, strategy, isa, &mut coverage);
            for block in coverage.blocks() {
                let mut bits = block.mask;
                while bits != 0 {
                    let bit = bits.trailing_zeros() as i32;
                    visit(block.x + (bit & 7), block.y + (bit >> 3));
                    bits &= bits - 1;
                }
            }
            tx += tile;
        }
        ty += tile;
    }
}

/// Smallest bounding-box side (pixels, in x or y) for which the adaptive rule uses blocks. The
/// paper says one block; measured here (`benches/traversal.rs`, BENCHMARKS.md) triangles of
/// about one block straddle up to four blocks and scan twice as slowly as incrementally, so
/// blocks start at two.
pub const ADAPTIVE_MIN_SIDE: i32 = 2 * BLOCK_SIZE as i32;

/// The adaptive rule: blocks for boxes with the paper's aspect 0.4–1.6 that are large enough
/// ([`ADAPTIVE_MIN_SIDE`]), and for every box whose shorter side reaches that size too. The
/// paper scans thin boxes incrementally whatever their size; here coverage leaves traversal as
/// block masks, and a full block costs no edge test at all, so a 1300 × 700 box (the thesis'
/// full-screen quads) is far cheaper in blocks (perf: 47% of the frame in the incremental scan).
#[inline]
pub fn prefers_blocks(tri: &TriangleSetup) -> bool {
    let w = tri.bbox.width();
    let h = tri.bbox.height();
    if w < ADAPTIVE_MIN_SIDE && h < ADAPTIVE_MIN_SIDE {
        return false;
    }
    if w.min(h) >= ADAPTIVE_MIN_SIDE {
        return true;
    }
    // 0.4 ≤ w / h ≤ 1.6, in integers: 2h ≤ 5w and 5w ≤ 8h.
    2 * h <= 5 * w && 5 * w <= 8 * h
}

// A row of a tile is one `u64` of coverage bits.
const _: () = assert!(TILE_SIZE <= 64);

/// Appends the coverage of `rect` (which lies in one tile) given row by row: `row_bits(y)` is
/// row `y`'s bits (bit `k` = pixel `rect.x0 + k`), asked for in order from `rect.y0`. Works one
/// block row (8 pixel rows) at a time: a row's bits go into that block row's masks a byte per
/// block, and its non-empty blocks are appended (row-major) before the next block row, so a
/// small triangle clears and visits only the one or two blocks it touches.
#[inline]
fn scan_rows(rect: PixelRect, out: &mut BlockCoverage, mut row_bits: impl FnMut(i32) -> u64) {
    let block = BLOCK_SIZE as i32;
    if rect.x1 - (rect.x0 & !(block - 1)) <= 2 * block {
        return scan_rows_narrow(rect, out, row_bits);
    }
    let tile_x = rect.x0 & !(TILE_SIZE as i32 - 1);
    // The rectangle's block columns, counted from the tile's left edge.
    let (bx0, bx1) = (
        ((rect.x0 - tile_x) >> BLOCK_LOG2) as usize,
        (((rect.x1 - 1 - tile_x) >> BLOCK_LOG2) + 1) as usize,
    );
    // Bit `c` of a row's bits shifted by this = tile column `c` (the rectangle lies in the
    // tile, so nothing is shifted out).
    let column_shift = (rect.x0 - tile_x) as u32;
    let mut y = rect.y0;
    while y < rect.y1 {
        let block_y = y & !(block - 1);
        let band_end = (block_y + block).min(rect.y1);
        let mut masks = [0u64; (TILE_SIZE / BLOCK_SIZE) as usize];
        for y in y..band_end {
            let mut bits = row_bits(y) << column_shift;
            let shift = ((y & (block - 1)) << BLOCK_LOG2) as u32;
            while bits != 0 {
                let bx = (bits.trailing_zeros() >> BLOCK_LOG2) as usize;
                let first = (bx as u32) << BLOCK_LOG2;
                masks[bx] |= ((bits >> first) & 0xff) << shift;
                bits &= !(0xffu64 << first);
            }
        }
        for (bx, &mask) in masks.iter().enumerate().take(bx1).skip(bx0) {
            out.push(tile_x + ((bx as i32) << BLOCK_LOG2), block_y, mask);
        }
        y = band_end;
    }
}

/// [`scan_rows`] for a rectangle within two block columns (most small triangles): a row's bits
/// go to the two columns' masks by two shifts, with no loop over the row's blocks; the same
/// blocks, appended in the same order.
#[inline]
fn scan_rows_narrow(
    rect: PixelRect,
    out: &mut BlockCoverage,
    mut row_bits: impl FnMut(i32) -> u64,
) {
    let block = BLOCK_SIZE as i32;
    // The first block column's left edge; bit `c` of a row's bits shifted by `offset` is column
    // `c` from that edge (at most 16 bits: the rectangle ends within the second column).
    let x_first = rect.x0 & !(block - 1);
    let offset = (rect.x0 - x_first) as u32;
    let two_columns = rect.x1 - x_first > block;
    let mut y = rect.y0;
    while y < rect.y1 {
        let block_y = y & !(block - 1);
        let band_end = (block_y + block).min(rect.y1);
        let (mut left, mut right) = (0u64, 0u64);
        for y in y..band_end {
            let bits = row_bits(y) << offset;
            let shift = ((y & (block - 1)) << BLOCK_LOG2) as u32;
            left |= (bits & 0xff) << shift;
            right |= ((bits >> 8) & 0xff) << shift;
        }
        out.push(x_first, block_y, left);
        if two_columns {
            out.push(x_first + block, block_y, right);
        }
        y = band_end;
    }
}

/// The simplest scan: every pixel of the box, every edge evaluated from scratch.
fn scan_bounding_box(tri: &TriangleSetup, rect: PixelRect, out: &mut BlockCoverage) {
    scan_rows(rect, out, |y| {
        (rect.x0..rect.x1)
            .enumerate()
            .filter(|&(_, x)| tri.covers(x, y))
            .fold(0u64, |bits, (k, _)| bits | 1 << k)
    });
}

/// Biased edge values at the centre of pixel `(x, y)` and their per-pixel steps.
#[derive(Clone, Copy)]
struct EdgeStepper {
    value: [i64; 3],
    step_x: [i64; 3],
    step_y: [i64; 3],
}

impl EdgeStepper {
    #[inline]
    fn at(tri: &TriangleSetup, x: i32, y: i32) -> Self {
        let e = &tri.edges;
        Self {
            value: [
                e[0].biased_at_pixel(x, y),
                e[1].biased_at_pixel(x, y),
                e[2].biased_at_pixel(x, y),
            ],
            step_x: [e[0].step_x(), e[1].step_x(), e[2].step_x()],
            step_y: [e[0].step_y(), e[1].step_y(), e[2].step_y()],
        }
    }

    /// Coverage bits of row pixels `x0..x1` (bit `k` = pixel `x0 + k`, at most 64), starting
    /// from the values at `(x0, y)` in `row`.
    ///
    /// An edge value is linear along the row, so an edge whose first and last values are both
    /// inside holds every pixel and one whose both are outside holds none; an edge that crosses
    /// the row holds a prefix or a suffix of it, found by an exact integer division (the same
    /// pixels as testing each one's value, so the same bits).
    #[inline]
    fn row_bits(&self, row: [i64; 3], x0: i32, x1: i32) -> u64 {
        let n = x1 - x0;
        if n <= 0 {
            return 0;
        }
        let mut bits = u64::MAX >> (64 - n);
        for (first, step) in row.into_iter().zip(self.step_x) {
            let last = first + step * (n - 1) as i64;
            match (first >= 0, last >= 0) {
                (true, true) => {}
                (false, false) => return 0,
                // The edge crosses the row (so `step` is not 0): its inside pixels are a suffix
                // of the row where it grows and a prefix where it falls, bounded by one exact
                // integer division instead of a test per pixel.
                _ if step > 0 => {
                    // first < 0 ≤ last: inside from k0 = ⌈−first / step⌉ (1 ≤ k0 ≤ n − 1) on.
                    let k0 = (step - 1 - first) / step;
                    bits &= !((1u64 << k0) - 1);
                }
                _ => {
                    // first ≥ 0 > last: inside up to k1 = ⌊first / −step⌋ (0 ≤ k1 ≤ n − 2).
                    let k1 = first / -step;
                    bits &= (2u64 << k1) - 1;
                }
            }
        }
        bits
    }

    /// Values moved by `dx` pixels in x and `dy` in y.
    #[inline]
    fn offset(&self, base: [i64; 3], dx: i64, dy: i64) -> [i64; 3] {
        [
            base[0] + self.step_x[0] * dx + self.step_y[0] * dy,
            base[1] + self.step_x[1] * dx + self.step_y[1] * dy,
            base[2] + self.step_x[2] * dx + self.step_y[2] * dy,
        ]
    }
}

/// Bounding-box scan with incremental edge functions: each row's values stepped by one add per
/// edge from the row above ([`EdgeStepper::row_bits`] within the row). (Lane-wide block masks
/// were measured here too: for the few rows of a small triangle their set-up costs more than
/// the rows, 0–4% more instructions on the mesh scenes.)
fn scan_incremental(tri: &TriangleSetup, rect: PixelRect, out: &mut BlockCoverage) {
    let stepper = EdgeStepper::at(tri, rect.x0, rect.y0);
    let mut row = stepper.value;
    scan_rows(rect, out, |_| {
        let bits = stepper.row_bits(row, rect.x0, rect.x1);
        row[0] += stepper.step_y[0];
        row[1] += stepper.step_y[1];
        row[2] += stepper.step_y[2];
        bits
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;
    use kantele_rules::setup::{setup_triangle, CullMode, FrontFace, Viewport};

    fn coverage(
        tri: &TriangleSetup,
        rect: PixelRect,
        strategy: Strategy,
        isa: Isa,
    ) -> Vec<(i32, i32)> {
        let mut out = Vec::new();
        rasterize(tri, rect, strategy, isa, |x, y| out.push((x, y)));
        out.sort_unstable();
        out
    }

    /// `row_bits` (a division per crossing edge) against testing every pixel's stepped value,
    /// over rows of every length, crossings at every position and steps of both signs,
    /// including values and steps near the fixed-point bound.
    #[test]
    fn row_bits_match_per_pixel_tests() {
        let per_pixel = |row: [i64; 3], step_x: [i64; 3], n: i32| {
            let mut bits = 0u64;
            for k in 0..n as i64 {
                if (0..3).all(|e| row[e] + step_x[e] * k >= 0) {
                    bits |= 1 << k;
                }
            }
            bits
        };
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..60_000 {
            let n = 1 + (next() % 64) as i32;
            // Small steps cross within the row; large ones (up to 2^40) test the division at
            // the scale of big triangles' edge values. One case in 16 has an edge parallel to
            // the rows; one in three crosses exactly at a pixel centre (value 0 there).
            let scale = if case % 2 == 0 { 1 << 10 } else { 1i64 << 40 };
            let step_x: [i64; 3] = std::array::from_fn(|e| match (case % 16, e) {
                (5, 1) => 0,
                _ => (next() as i64) % scale,
            });
            let exact = case % 3 == 0;
            let row: [i64; 3] = std::array::from_fn(|e| {
                let crossing = (next() % (n as u64 + 2)) as i64 - 1;
                let offset = if exact {
                    0
                } else {
                    (next() as i64) % (step_x[e].abs() + 1)
                };
                match step_x[e] {
                    0 => (next() as i64) % 3 - 1,
                    s => -s * crossing + offset,
                }
            });
            let stepper = EdgeStepper {
                value: row,
                step_x,
                step_y: [0; 3],
            };
            assert_eq!(
                stepper.row_bits(row, 0, n),
                per_pixel(row, step_x, n),
                "row {row:?}, steps {step_x:?}, {n} pixels"
            );
        }
    }

    /// Every strategy at every supported instruction-set level finds the pixels of the
    /// bounding-box scan (each pixel tested from scratch), for triangles within the target and,
    /// one in four, reaching far into the guard band (edge values beyond 32 bits within a
    /// block, where the lane-wide masks give way to the 64-bit rows).
    #[test]
    fn all_strategies_agree_on_many_triangles() {
        let vp = Viewport::new(200, 150);
        let mut seed = 12345u64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 10_000) as f32 / 10_000.0 * 2.6 - 1.3
        };
        let isas: Vec<Isa> = Isa::supported().collect();
        let mut checked = 0;
        for case in 0..400 {
            // NDC ±1.3, or ±130 (about ±13 000 pixels) for one vertex in four triangles.
            let far = if case % 4 == 3 { 100.0 } else { 1.0 };
            let p = [
                Vec4::new(rand() * far, rand() * far, 0.0, 1.0),
                Vec4::new(rand(), rand(), 0.0, 1.0),
                Vec4::new(rand(), rand(), 0.0, 1.0),
            ];
            let Ok(tri) = setup_triangle(&vp, p, CullMode::None, FrontFace::Ccw) else {
                continue;
            };
            // Tiles of 64 pixels, as the pipeline uses them.
            for ty in 0..3 {
                for tx in 0..4 {
                    let rect = PixelRect {
                        x0: tx * 64,
                        y0: ty * 64,
                        x1: (tx * 64 + 64).min(200),
                        y1: (ty * 64 + 64).min(150),
                    };
                    let reference = coverage(&tri, rect, Strategy::BoundingBox, Isa::Scalar);
                    for s in Strategy::ALL {
                        for &isa in &isas {
                            assert_eq!(
                                coverage(&tri, rect, s, isa),
                                reference,
                                "{s} at {isa} differs"
                            );
                        }
                    }
                }
            }
            checked += 1;
        }
        assert!(checked > 300);
    }

    #[test]
    fn wholly_covered_tiles_give_every_pixel_once() {
        // A triangle far larger than the 150 × 100 target: every tile (whole or cut by the
        // target's edge, at any alignment of the rectangle) is inside it.
        let vp = Viewport::new(150, 100);
        let tri = setup_triangle(
            &vp,
            [
                Vec4::new(-3.0, -3.0, 0.0, 1.0),
                Vec4::new(5.0, -3.0, 0.0, 1.0),
                Vec4::new(-3.0, 5.0, 0.0, 1.0),
            ],
            CullMode::None,
            FrontFace::Ccw,
        )
        .expect("valid");
        for rect in [
            PixelRect {
                x0: 0,
                y0: 0,
                x1: 64,
                y1: 64,
            },
            PixelRect {
                x0: 128,
                y0: 64,
                x1: 150,
                y1: 100,
            },
            PixelRect {
                x0: 67,
                y0: 3,
                x1: 125,
                y1: 61,
            },
        ] {
            let expected: Vec<(i32, i32)> = (rect.x0..rect.x1)
                .flat_map(|x| (rect.y0..rect.y1).map(move |y| (x, y)))
                .collect();
            for s in Strategy::ALL {
                for isa in Isa::supported() {
                    assert_eq!(
                        coverage(&tri, rect, s, isa),
                        expected,
                        "{s} {isa} on {rect:?}"
                    );
                }
            }
            let mut blocks = BlockCoverage::default();
            rasterize_blocks(&tri, rect, Strategy::Bisector, Isa::best(), &mut blocks);
            assert_eq!(blocks.pixel_count(), expected.len() as u64);
        }
    }

    #[test]
    fn adaptive_rule_uses_blocks_for_large_or_square_boxes() {
        let vp = Viewport::new(100, 100);
        let make = |w: f32, h: f32| {
            setup_triangle(
                &vp,
                [
                    Vec4::new(-1.0, 1.0 - h, 0.0, 1.0),
                    Vec4::new(-1.0 + w, 1.0, 0.0, 1.0),
                    Vec4::new(-1.0, 1.0, 0.0, 1.0),
                ],
                CullMode::None,
                FrontFace::Ccw,
            )
            .expect("valid")
        };
        assert!(prefers_blocks(&make(1.0, 1.0)));
        // 50 × 10 px: thin and short, incremental.
        assert!(!prefers_blocks(&make(1.0, 0.2)));
        assert!(!prefers_blocks(&make(0.1, 0.1)));
        // 100 × 40 px: outside the paper's aspect range, but both sides span two blocks.
        assert!(prefers_blocks(&make(2.0, 0.8)));
    }
}
