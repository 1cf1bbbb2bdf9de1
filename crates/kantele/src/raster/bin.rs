//! Binning: sorting set-up triangles into the screen tiles they touch, in submission order.
//!
//! Takes the frame's triangles (in draw order) and produces one list of triangle indices per
//! tile. Each tile is later rasterized by one thread, in its list's order, which is why the
//! result does not depend on the number of threads.

use crate::fixed::{TILE_LOG2, TILE_SIZE};
use crate::setup::{PixelRect, TriangleSetup};

/// The tiles of a target: `tiles_x × tiles_y` tiles of `TILE_SIZE²` pixels, row-major.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileGrid {
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
    /// Tiles per row.
    pub tiles_x: u32,
    /// Tile rows.
    pub tiles_y: u32,
}

impl TileGrid {
    /// The grid covering a `width × height` target.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            tiles_x: width.div_ceil(TILE_SIZE),
            tiles_y: height.div_ceil(TILE_SIZE),
        }
    }

    /// Number of tiles.
    pub fn tile_count(&self) -> usize {
        self.tiles_x as usize * self.tiles_y as usize
    }

    /// The pixels of tile `index`, clipped to the target.
    pub fn tile_rect(&self, index: usize) -> PixelRect {
        let tx = (index % self.tiles_x as usize) as i32;
        let ty = (index / self.tiles_x as usize) as i32;
        let size = TILE_SIZE as i32;
        PixelRect {
            x0: tx * size,
            y0: ty * size,
            x1: ((tx + 1) * size).min(self.width as i32),
            y1: ((ty + 1) * size).min(self.height as i32),
        }
    }
}

/// Per-tile lists of triangle indices.
#[derive(Clone, Debug, Default)]
pub struct TileBins {
    /// `bins[tile]` lists indices into the frame's triangles, in submission order.
    pub bins: Vec<Vec<u32>>,
}

impl TileBins {
    /// Empties every bin, keeping allocations, and sizes the list for `grid`.
    pub fn reset(&mut self, grid: &TileGrid) {
        self.bins.resize_with(grid.tile_count(), Vec::new);
        self.bins.truncate(grid.tile_count());
        for bin in &mut self.bins {
            bin.clear();
        }
    }

    /// Appends every triangle to the bins its bounding box touches; returns the number of bin
    /// entries written. A triangle whose box touches a tile but covers none of its pixels is
    /// still binned there; traversal finds no pixel.
    pub fn bin_triangles(&mut self, grid: &TileGrid, triangles: &[TriangleSetup]) -> u64 {
        self.reset(grid);
        let mut entries = 0u64;
        for (index, tri) in triangles.iter().enumerate() {
            let b = tri.bbox;
            let tx0 = (b.x0 >> TILE_LOG2) as usize;
            let tx1 = ((b.x1 - 1) >> TILE_LOG2) as usize;
            let ty0 = (b.y0 >> TILE_LOG2) as usize;
            let ty1 = ((b.y1 - 1) >> TILE_LOG2) as usize;
            for ty in ty0..=ty1 {
                let row = ty * grid.tiles_x as usize;
                for tx in tx0..=tx1 {
                    self.bins[row + tx].push(index as u32);
                }
            }
            entries += ((tx1 - tx0 + 1) * (ty1 - ty0 + 1)) as u64;
        }
        entries
    }
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
        assert_eq!(bins.bins[0], vec![0, 1]);
        assert_eq!(bins.bins[1], vec![0, 1]);
        assert_eq!(bins.bins[2], vec![1]);
    }
}
