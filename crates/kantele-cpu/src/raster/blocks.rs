//! The block traversals (the `block`, `adaptive` and `bisector` strategies): 8 × 8 blocks
//! aligned to multiples of 8 pixels, each classified empty, full or partial, the partial ones'
//! masks computed a row of eight pixels at a time ([`super::block_lanes`]). Compiled per
//! instruction set through [`ScanKernel`].

use super::block_lanes::EdgeLanes;
use super::{rect_mask, BlockCoverage, EdgeStepper};
use kantele_lanes::{LaneKernel, Lanes};
use kantele_rules::fixed::{BLOCK_LOG2, BLOCK_SIZE};
use kantele_rules::setup::{PixelRect, TriangleSetup};

/// The scans of 8 × 8 blocks, whose partial blocks' masks are lane-wide.
#[derive(Clone, Copy)]
pub(super) enum Scan {
    Blocks,
    Bisector,
}

/// One scan of one triangle in one tile, compiled per instruction set.
pub(super) struct ScanKernel<'a> {
    pub(super) tri: &'a TriangleSetup,
    pub(super) rect: PixelRect,
    pub(super) scan: Scan,
    pub(super) out: &'a mut BlockCoverage,
}

impl LaneKernel for ScanKernel<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) {
        match self.scan {
            Scan::Blocks => scan_blocks(lanes, self.tri, self.rect, self.out),
            Scan::Bisector => scan_bisector(lanes, self.tri, self.rect, self.out),
        }
    }
}

/// How an 8 × 8 block relates to the triangle, judged by the edge values at its corner pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BlockClass {
    /// Every corner is outside one edge: no pixel is covered.
    Empty,
    /// Every corner is inside every edge: every pixel is covered (edges are linear).
    Full,
    /// Anything else: test pixel by pixel.
    Partial,
}

/// The block grid of the strategies that use 8 × 8 blocks: blocks are aligned to multiples of
/// 8 pixels, classified whole, and their coverage clipped to the rectangle being drawn.
///
/// Classifying the whole aligned block rather than its part inside the rectangle costs one
/// pair of additions per edge (the extreme corners' offsets are the same for every block) and
/// changes no bit: a whole block that is empty or full is so inside the rectangle too, and a
/// partial one is tested pixel by pixel. At the rectangle's border a block empty inside it may
/// be called partial, which only lets the bisector's walk go one block further (the blocks not
/// rejected by an edge still form one run per row).
struct BlockGrid {
    rect: PixelRect,
    stepper: EdgeStepper,
    /// Per edge, the offsets from a block's first pixel to its smallest and largest value
    /// (a linear function's extremes over a rectangle lie at the corners its steps' signs
    /// pick).
    lowest: [i64; 3],
    highest: [i64; 3],
    /// First and one-past-last block column / row (in block units).
    bx0: i32,
    bx1: i32,
    by0: i32,
    by1: i32,
}

impl BlockGrid {
    fn new(tri: &TriangleSetup, rect: PixelRect) -> Self {
        let stepper = EdgeStepper::at(tri, rect.x0, rect.y0);
        let last = (BLOCK_SIZE - 1) as i64;
        let (mut lowest, mut highest) = ([0; 3], [0; 3]);
        for e in 0..3 {
            let (sx, sy) = (stepper.step_x[e], stepper.step_y[e]);
            lowest[e] = (sx.min(0) + sy.min(0)) * last;
            highest[e] = (sx.max(0) + sy.max(0)) * last;
        }
        Self {
            rect,
            stepper,
            lowest,
            highest,
            bx0: rect.x0 >> BLOCK_LOG2,
            bx1: ((rect.x1 - 1) >> BLOCK_LOG2) + 1,
            by0: rect.y0 >> BLOCK_LOG2,
            by1: ((rect.y1 - 1) >> BLOCK_LOG2) + 1,
        }
    }

    /// The pixels of block `(bx, by)` inside the rectangle.
    #[inline]
    fn block_rect(&self, bx: i32, by: i32) -> PixelRect {
        PixelRect {
            x0: bx << BLOCK_LOG2,
            y0: by << BLOCK_LOG2,
            x1: (bx + 1) << BLOCK_LOG2,
            y1: (by + 1) << BLOCK_LOG2,
        }
        .intersect(&self.rect)
    }

    /// Biased edge values at pixel `(x, y)`, stepped from the rectangle's corner.
    #[inline]
    fn values_at(&self, x: i32, y: i32) -> [i64; 3] {
        self.stepper.offset(
            self.stepper.value,
            (x - self.rect.x0) as i64,
            (y - self.rect.y0) as i64,
        )
    }

    /// Classifies the whole block whose first pixel has the edge values `origin`, and returns,
    /// with the class, the edge that rejected an empty block (for the bisector's search
    /// direction) and which edges cross a partial one.
    #[inline(always)]
    fn classify(&self, origin: [i64; 3]) -> (BlockClass, Option<usize>, [bool; 3]) {
        let mut crossing = [false; 3];
        for (edge, crosses) in crossing.iter_mut().enumerate() {
            if origin[edge] + self.highest[edge] < 0 {
                return (BlockClass::Empty, Some(edge), crossing);
            }
            *crosses = origin[edge] + self.lowest[edge] < 0;
        }
        let class = if crossing.contains(&true) {
            BlockClass::Partial
        } else {
            BlockClass::Full
        };
        (class, None, crossing)
    }

    /// Coverage bits of a partial block whose first pixel has the edge values `origin`, within
    /// `part` (its pixels inside the rectangle), the edges other than `crossing` holding the
    /// whole block: the lane-wide rows of [`EdgeLanes`] when the block's values fit in 32 bits,
    /// else [`BlockGrid::rows_mask`].
    #[inline(always)]
    fn partial_mask<L: Lanes>(
        &self,
        lanes: L,
        origin: [i64; 3],
        crossing: [bool; 3],
        part: &PixelRect,
    ) -> u64 {
        // An edge that holds the whole block is left out: its values may be large, and it
        // changes no bit.
        let keep =
            |values: [i64; 3]| std::array::from_fn(|e| if crossing[e] { values[e] } else { 0 });
        match EdgeLanes::new(
            lanes,
            keep(origin),
            keep(self.stepper.step_x),
            keep(self.stepper.step_y),
        ) {
            Some(edges) => {
                let rows = (part.y0 & 7)..((part.y1 - 1) & 7) + 1;
                edges.mask(lanes, rows) & rect_mask(part)
            }
            None => self.rows_mask(part),
        }
    }

    /// The coverage bits of `part` (the pixels of one block) by 64-bit values, a row at a
    /// time ([`EdgeStepper::row_bits`]).
    #[inline(never)]
    fn rows_mask(&self, part: &PixelRect) -> u64 {
        let mut row = self.values_at(part.x0, part.y0);
        let mut mask = 0;
        for y in part.y0..part.y1 {
            let shift = ((y & 7) << 3) | (part.x0 & 7);
            mask |= self.stepper.row_bits(row, part.x0, part.x1) << shift;
            row[0] += self.stepper.step_y[0];
            row[1] += self.stepper.step_y[1];
            row[2] += self.stepper.step_y[2];
        }
        mask
    }

    /// Classifies one block and appends its coverage; returns its class and rejecting edge.
    #[inline(always)]
    fn process<L: Lanes>(
        &self,
        lanes: L,
        bx: i32,
        by: i32,
        out: &mut BlockCoverage,
    ) -> (BlockClass, Option<usize>) {
        let origin = self.values_at(bx << BLOCK_LOG2, by << BLOCK_LOG2);
        let (class, edge, crossing) = self.classify(origin);
        let part = self.block_rect(bx, by);
        let mask = match class {
            BlockClass::Empty => 0,
            BlockClass::Full => rect_mask(&part),
            BlockClass::Partial => self.partial_mask(lanes, origin, crossing, &part),
        };
        out.push(part.x0, part.y0, mask);
        (class, edge)
    }
}

/// Row-by-row block traversal of the whole box (the paper's block-based model).
#[inline(always)]
fn scan_blocks<L: Lanes>(lanes: L, tri: &TriangleSetup, rect: PixelRect, out: &mut BlockCoverage) {
    let grid = BlockGrid::new(tri, rect);
    for by in grid.by0..grid.by1 {
        for bx in grid.bx0..grid.bx1 {
            grid.process(lanes, bx, by, out);
        }
    }
}

/// The bisector traversal: in each block row, start from a block inside the triangle and walk
/// outwards left and right until an empty block. The blocks not rejected by an edge form one
/// contiguous run per row (each edge keeps a prefix or a suffix of the row, and the triangle is
/// their intersection), so stopping at the first empty block on each side misses nothing. The
/// start is halfway between the previous row's bounds (the topmost vertex's block on the first
/// row); when the start itself is empty, the edge that rejected it says on which side the run
/// lies.
#[inline(always)]
fn scan_bisector<L: Lanes>(
    lanes: L,
    tri: &TriangleSetup,
    rect: PixelRect,
    out: &mut BlockCoverage,
) {
    let grid = BlockGrid::new(tri, rect);
    let top = tri
        .pos_subpixel
        .iter()
        .min_by_key(|p| p[1])
        .map_or(0, |p| (p[0] >> kantele_rules::fixed::SUBPIXEL_BITS) as i32);
    let mut start = (top >> BLOCK_LOG2).clamp(grid.bx0, grid.bx1 - 1);
    for by in grid.by0..grid.by1 {
        // Find a non-empty block of this row, starting from `start`.
        let mut bx = start;
        let mut found = None;
        let mut direction = 0i32;
        while (grid.bx0..grid.bx1).contains(&bx) {
            let (class, edge) = grid.process(lanes, bx, by, out);
            if class != BlockClass::Empty {
                found = Some(bx);
                break;
            }
            // The run lies where the rejecting edge grows; a horizontal rejecting edge, or a
            // direction that reverses, means the row is empty.
            let a = edge.map_or(0, |e| tri.edges[e].a);
            let wanted = a.signum() as i32;
            if wanted == 0 || (direction != 0 && wanted != direction) {
                break;
            }
            direction = wanted;
            bx += direction;
        }
        let Some(seed) = found else { continue };
        let mut right = seed + 1;
        while right < grid.bx1 && grid.process(lanes, right, by, out).0 != BlockClass::Empty {
            right += 1;
        }
        let mut left = seed - 1;
        while left >= grid.bx0 && grid.process(lanes, left, by, out).0 != BlockClass::Empty {
            left -= 1;
        }
        // Next row starts halfway between this row's bounds.
        start = (left + 1 + (right - 1 - (left + 1)) / 2).clamp(grid.bx0, grid.bx1 - 1);
    }
}
