//! Binning: sorting set-up triangles into the screen tiles they touch, in submission order.
//!
//! Takes the frame's triangles (in draw order) and produces one list of triangle indices per
//! tile. Each tile is later rasterized by one thread, in its list's order, which is why the
//! result does not depend on the number of threads.

use kantele_rules::fixed::{TILE_LOG2, TILE_SIZE};
use kantele_rules::setup::{PixelRect, TriangleSetup};
use kantele_rules::state::MAX_FRAME_BATCHES;

/// The tiles of a target: `tiles_x × tiles_y` tiles of `TILE_SIZE²` pixels, row-major. A grid
/// may hold only a band of the target's tile rows (`first_row..first_row + tiles_y`, see
/// [`TileGrid::band`]); tile indices then count from the band's first tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileGrid {
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
    /// Tiles per row.
    pub tiles_x: u32,
    /// Tile rows held.
    pub tiles_y: u32,
    /// The target's first tile row held (0 for a whole target).
    pub first_row: u32,
}

impl TileGrid {
    /// The grid covering a `width × height` target.
    pub fn new(width: u32, height: u32) -> Self {
        Self::band(width, height, 0..height.div_ceil(TILE_SIZE))
    }

    /// The tile rows `tile_rows` (clamped to the target) of a `width × height` target: the
    /// viewport stays the whole target's, only these tiles are stored, binned and drawn.
    pub fn band(width: u32, height: u32, tile_rows: std::ops::Range<u32>) -> Self {
        let all = height.div_ceil(TILE_SIZE);
        let first_row = tile_rows.start.min(all);
        Self {
            width,
            height,
            tiles_x: width.div_ceil(TILE_SIZE),
            tiles_y: tile_rows.end.min(all).saturating_sub(first_row),
            first_row,
        }
    }

    /// Number of tiles.
    pub fn tile_count(&self) -> usize {
        self.tiles_x as usize * self.tiles_y as usize
    }

    /// The pixels of tile `index`, clipped to the target.
    pub fn tile_rect(&self, index: usize) -> PixelRect {
        let tx = (index % self.tiles_x as usize) as i32;
        let ty = (index / self.tiles_x as usize) as i32 + self.first_row as i32;
        let size = TILE_SIZE as i32;
        PixelRect {
            x0: tx * size,
            y0: ty * size,
            x1: ((tx + 1) * size).min(self.width as i32),
            y1: ((ty + 1) * size).min(self.height as i32),
        }
    }
}

/// A set-up triangle's place in the frame: the primitive-stage batch it is in and its index
/// there, packed in 32 bits (bins hold millions of them). For triangles given as one slice
/// ([`TileBins::bin_triangles`]) the reference is simply the triangle's index in the slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TriangleRef(u32);

// The frame's batch limit is what the bits above a batch's index leave.
const _: () = assert!(MAX_FRAME_BATCHES == 1 << (32 - TriangleRef::INDEX_BITS));

impl TriangleRef {
    /// Bits of the index within a batch.
    const INDEX_BITS: u32 = 13;
    /// Most triangles a batch may hold (8192).
    pub const MAX_BATCH_TRIANGLES: usize = 1 << Self::INDEX_BITS;
    /// Most batches a frame may hold ([`MAX_FRAME_BATCHES`], 2^19: what the bits above
    /// the index leave).
    pub const MAX_BATCHES: usize = MAX_FRAME_BATCHES;

    /// The reference to triangle `index` of batch `batch` (`index <
    /// MAX_BATCH_TRIANGLES`, `batch < MAX_BATCHES`).
    #[inline]
    pub fn new(batch: usize, index: usize) -> Self {
        debug_assert!(index < Self::MAX_BATCH_TRIANGLES && batch < Self::MAX_BATCHES);
        Self(((batch as u32) << Self::INDEX_BITS) | index as u32)
    }

    /// The batch.
    #[inline]
    pub fn batch(self) -> usize {
        (self.0 >> Self::INDEX_BITS) as usize
    }

    /// The index within the batch.
    #[inline]
    pub fn index(self) -> usize {
        (self.0 & ((1 << Self::INDEX_BITS) - 1)) as usize
    }

    /// The packed value (for one-slice binning: the triangle's index).
    #[inline]
    pub fn packed(self) -> u32 {
        self.0
    }
}

/// Per-tile lists of triangle references, built in parallel: the frame's batches are split into
/// consecutive chunks, each chunk is binned by one thread into lists of its own, and a tile's
/// triangles are its lists read chunk after chunk — submission order, whatever the thread count,
/// with no merge copy. Lists keep their allocations from frame to frame.
#[derive(Clone, Debug, Default)]
pub struct TileBins {
    /// `chunks[c][tile]`: chunk `c`'s triangles touching `tile`, in order (only the first
    /// `chunk_count` chunks are current).
    chunks: Vec<Vec<Vec<TriangleRef>>>,
    chunk_count: usize,
    tile_count: usize,
    /// The first batch of each chunk, then the end (kept to avoid an allocation per frame).
    bounds: Vec<usize>,
}

/// Fewest triangles per binning chunk: below this, one thread bins them all.
const MIN_TRIANGLES_PER_CHUNK: usize = 4096;

impl TileBins {
    /// Bins one slice of triangles (references are their indices in the slice); returns the
    /// number of bin entries written. See [`TileBins::bin_batches`].
    pub fn bin_triangles(&mut self, grid: &TileGrid, triangles: &[TriangleSetup]) -> u64 {
        let boxes: Vec<PixelRect> = triangles.iter().map(|t| t.bbox).collect();
        let batches: Vec<&[PixelRect]> = boxes.chunks(TriangleRef::MAX_BATCH_TRIANGLES).collect();
        self.bin_batches(grid, &batches)
    }

    /// Appends every triangle of `batches` (in order; each given by its pixel box,
    /// [`TriangleSetup::bbox`]) to the bins its box touches; returns the number of bin entries
    /// written. A triangle whose box touches a tile but covers none of its pixels is still
    /// binned there; traversal finds no pixel. Each batch holds at most
    /// [`TriangleRef::MAX_BATCH_TRIANGLES`] triangles, and there are at most
    /// [`TriangleRef::MAX_BATCHES`] batches.
    pub fn bin_batches(&mut self, grid: &TileGrid, batches: &[&[PixelRect]]) -> u64 {
        use rayon::prelude::*;
        let tile_count = grid.tile_count();
        let total: usize = batches.iter().map(|b| b.len()).sum();
        let wanted = (2 * rayon::current_num_threads()).max(1);
        let chunk_count = total
            .div_ceil(MIN_TRIANGLES_PER_CHUNK)
            .clamp(1, wanted)
            .min(batches.len().max(1));
        // Consecutive runs of batches with about `total / chunk_count` triangles each.
        let bounds = &mut self.bounds;
        bounds.clear();
        bounds.push(0);
        let mut seen = 0;
        for (i, b) in batches.iter().enumerate() {
            seen += b.len();
            if bounds.len() < chunk_count && seen * chunk_count >= bounds.len() * total {
                bounds.push(i + 1);
            }
        }
        while bounds.len() <= chunk_count {
            bounds.push(batches.len());
        }
        if self.chunks.len() < chunk_count {
            self.chunks.resize_with(chunk_count, Vec::new);
        }
        self.chunk_count = chunk_count;
        self.tile_count = tile_count;
        let bounds = &self.bounds;
        self.chunks[..chunk_count]
            .par_iter_mut()
            .enumerate()
            .map(|(c, bins)| {
                bins.resize_with(tile_count, Vec::new);
                bins.truncate(tile_count);
                for bin in bins.iter_mut() {
                    bin.clear();
                }
                (bounds[c]..bounds[c + 1])
                    .map(|b| bin_batch(grid, b, batches[b], bins))
                    .sum::<u64>()
            })
            .sum()
    }

    /// The triangles touching `tile`, in submission order.
    #[inline]
    pub fn tile(&self, tile: usize) -> impl Iterator<Item = TriangleRef> + '_ {
        self.chunks[..self.chunk_count]
            .iter()
            .flat_map(move |bins| bins[tile].iter().copied())
    }

    /// Whether no triangle touches `tile`.
    #[inline]
    pub fn tile_is_empty(&self, tile: usize) -> bool {
        self.chunks[..self.chunk_count]
            .iter()
            .all(|bins| bins[tile].is_empty())
    }

    /// Number of tiles binned for.
    pub fn tile_count(&self) -> usize {
        self.tile_count
    }
}

/// Bins the triangles of batch `batch` into `bins` (one list per tile).
fn bin_batch(
    grid: &TileGrid,
    batch: usize,
    boxes: &[PixelRect],
    bins: &mut [Vec<TriangleRef>],
) -> u64 {
    let mut entries = 0u64;
    for (index, &b) in boxes.iter().enumerate() {
        let tx0 = (b.x0 >> TILE_LOG2) as usize;
        let tx1 = ((b.x1 - 1) >> TILE_LOG2) as usize;
        // Only the grid's band of tile rows (all of them for a whole target).
        let (first, end) = (
            grid.first_row as usize,
            (grid.first_row + grid.tiles_y) as usize,
        );
        let ty0 = ((b.y0 >> TILE_LOG2) as usize).max(first);
        let ty1 = (((b.y1 - 1) >> TILE_LOG2) as usize).min(end.saturating_sub(1));
        if ty0 >= end || ty1 < ty0 {
            continue;
        }
        let r = TriangleRef::new(batch, index);
        for ty in ty0..=ty1 {
            let row = (ty - first) * grid.tiles_x as usize;
            for bin in &mut bins[row + tx0..=row + tx1] {
                bin.push(r);
            }
        }
        entries += ((tx1 - tx0 + 1) * (ty1 - ty0 + 1)) as u64;
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_covers_partial_tiles() {
        let grid = TileGrid::new(130, 64);
        assert_eq!((grid.tiles_x, grid.tiles_y), (3, 1));
        assert_eq!(
            grid.tile_rect(2),
            PixelRect {
                x0: 128,
                y0: 0,
                x1: 130,
                y1: 64
            }
        );
    }

    #[test]
    fn triangles_land_in_every_tile_of_their_box_in_order() {
        let grid = TileGrid::new(256, 256);
        let with_box = |x0, y0, x1, y1| TriangleSetup {
            bbox: PixelRect { x0, y0, x1, y1 },
            ..TriangleSetup::default()
        };
        let a = with_box(60, 0, 70, 10);
        let b = with_box(0, 0, 256, 256);
        let mut bins = TileBins::default();
        let entries = bins.bin_triangles(&grid, &[a, b]);
        assert_eq!(entries, 2 + 16);
        let tile = |t: usize| bins.tile(t).map(|r| r.packed()).collect::<Vec<_>>();
        assert_eq!(tile(0), vec![0, 1]);
        assert_eq!(tile(1), vec![0, 1]);
        assert_eq!(tile(2), vec![1]);
    }

    #[test]
    fn parallel_chunks_keep_submission_order() {
        let grid = TileGrid::new(256, 256);
        // Enough triangles for several chunks; every other one covers tile 0 only.
        let triangles: Vec<TriangleSetup> = (0..20_000)
            .map(|i| TriangleSetup {
                bbox: if i % 2 == 0 {
                    PixelRect {
                        x0: 0,
                        y0: 0,
                        x1: 8,
                        y1: 8,
                    }
                } else {
                    PixelRect {
                        x0: 100,
                        y0: 100,
                        x1: 200,
                        y1: 130,
                    }
                },
                ..TriangleSetup::default()
            })
            .collect();
        for threads in [1, 3, 8] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut bins = TileBins::default();
            pool.install(|| bins.bin_triangles(&grid, &triangles));
            let tile0: Vec<u32> = bins.tile(0).map(|r| r.packed()).collect();
            let expected: Vec<u32> = (0..20_000).step_by(2).collect();
            assert_eq!(tile0, expected, "{threads} threads");
            let tile5: Vec<u32> = bins.tile(5).map(|r| r.packed()).collect();
            assert_eq!(tile5, (1..20_000).step_by(2).collect::<Vec<u32>>());
        }
    }
}
