//! One tile's storage: colour and depth planes laid out for lanes, the per-tile and per-block
//! depth bounds (the depth hierarchy), and the deferred clear.

use glam::Vec4;

use super::depth_planes;
use kantele_rules::error::RenderError;
use kantele_rules::fixed::{BLOCK_LOG2, BLOCK_SIZE, TILE_LOG2, TILE_PIXELS, TILE_SIZE};
use kantele_rules::multisample::SampleCount;
use kantele_rules::setup::PixelRect;

/// 8 × 8 blocks in a tile (64).
const BLOCKS_PER_TILE: usize = ((TILE_SIZE >> BLOCK_LOG2) * (TILE_SIZE >> BLOCK_LOG2)) as usize;

/// One tile's colour and depth, `TILE_SIZE × TILE_SIZE`, row-major within the tile. Colour is
/// stored as four planes (red, green, blue, alpha; structure of arrays) so that eight adjacent
/// pixels of a row are one lane load per channel.
///
/// A multisampled tile (N samples) holds N planes per channel (channel `c`, sample `s` at plane
/// `c·N + s`) and N + 1 depth planes: plane 0 is the depth at the pixel centre (the per-pixel
/// depth read back, see [`kantele_rules::multisample`]), plane `1 + s` that of sample `s`. At 1× the
/// single colour plane per channel and depth plane 0 are the only ones, as before.
#[derive(Clone, Debug)]
pub struct TileBuffer {
    /// Linear colour planes: red at `0..TILE_PIXELS·N`, then green, blue and alpha.
    pub(super) color: Vec<f32>,
    /// Window depth planes: the pixel centre's, then each sample's (multisampled only).
    pub(super) depth: Vec<f32>,
    /// Samples per pixel (1, 4 or 8).
    pub(super) samples: usize,
    /// The depth hierarchy and the deferred clear: what an 8-bit target's tile keeps beside
    /// its storage ([`super::srgb8`]).
    pub(super) state: TileState,
}

/// A tile's bookkeeping beside its colour and depth storage: the depth hierarchy's bounds and
/// the deferred clear.
#[derive(Clone, Copy, Debug)]
pub(super) struct TileState {
    /// An upper bound of every value in `depth` (kept by every depth write).
    pub(super) depth_bound: f32,
    /// Whether `depth_bound` is the exact maximum (false after writes until recomputed).
    pub(super) depth_bound_exact: bool,
    /// The largest depth of each 8 × 8 block (row-major blocks of the tile), kept exact by the
    /// per-pixel path after every block it writes: the second level of the depth hierarchy.
    pub(super) block_depth_max: [f32; BLOCKS_PER_TILE],
    /// A clear not yet written to (some blocks of) the storage: while set, every pixel and
    /// sample of a block in its `pending` set holds this colour and depth, whatever `color` and
    /// `depth` contain. Clearing a frame only records it. At 1× the per-pixel path writes a
    /// pending block's clear together with the first triangle that reaches the block
    /// ([`TileBuffer::take_pending_block`]: every pixel of the block is stored once, the
    /// triangle's where it wrote, the clear elsewhere); other paths write all pending blocks
    /// first ([`TileBuffer::materialize`]). A block that no triangle reaches is never written.
    pub(super) deferred_clear: Option<DeferredClear>,
}

/// The values of a clear that some blocks of a tile have not written to the storage yet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeferredClear {
    /// Linear colour of every sample.
    pub color: Vec4,
    /// Window depth of every depth plane.
    pub depth: f32,
    /// The blocks (bit `b` for block `b`, row-major blocks of the tile) whose storage does not
    /// hold their values yet; never 0 while the clear is recorded.
    pending: u64,
}

const _: () = assert!(
    BLOCKS_PER_TILE == 64,
    "one bit of DeferredClear::pending per block"
);

/// Every block of a tile pending.
pub(super) const ALL_BLOCKS: u64 = u64::MAX;

/// Pixels from the first of an 8 × 8 block to its last, in a tile's row-major order: seven
/// tile rows and one block row.
pub const BLOCK_SPAN: usize = (BLOCK_SIZE as usize - 1) * TILE_SIZE as usize + BLOCK_SIZE as usize;

/// The depth and colour (red, green, blue, alpha planes) of one 8 × 8 block of a single-sample
/// tile, each from the block's first pixel on: block row `r` starts at `r · TILE_SIZE`.
pub struct BlockRows<'a> {
    /// Window depths.
    pub depth: &'a mut [f32; BLOCK_SPAN],
    /// Linear colour planes.
    pub color: [&'a mut [f32; BLOCK_SPAN]; 4],
}

impl BlockRows<'_> {
    /// Offset of block row `row` (0..8) from the block's first pixel.
    #[inline(always)]
    pub fn row_offset(row: usize) -> usize {
        row * TILE_SIZE as usize
    }
}

/// The [`BLOCK_SPAN`] values of `plane` from the block's first pixel `first` on.
#[inline(always)]
fn block_span(plane: &mut [f32], first: usize) -> &mut [f32; BLOCK_SPAN] {
    plane[first..]
        .first_chunk_mut::<BLOCK_SPAN>()
        .expect("an 8 x 8 block lies inside its tile")
}

/// Margin below a triangle's smallest vertex depth. Interpolated depth is clamped to the
/// vertex range (`TriangleSetup::depth_at`), so none is needed; this is belt and braces.
const DEPTH_BOUND_SLACK: f32 = 1e-6;

/// Least triangle ∩ tile area (pixels) for which a stale depth bound is recomputed: scanning
/// 4096 depths pays off only when the triangle could cover many pixels.
const DEPTH_BOUND_REFRESH_AREA: i32 = 1024;

impl TileBuffer {
    pub(super) fn new(samples: SampleCount) -> Result<Self, RenderError> {
        let n = samples.count();
        Ok(Self {
            color: filled_vec(4 * n * TILE_PIXELS, 0.0)?,
            depth: filled_vec(depth_planes(samples) * TILE_PIXELS, 1.0)?,
            samples: n,
            state: TileState::new(),
        })
    }

    /// Depths of the row starting at tile index `index` (to the end of the tile).
    #[inline(always)]
    pub fn depth_row(&self, index: usize) -> &[f32] {
        self.debug_assert_materialized();
        &self.depth[index..]
    }

    /// Mutable depths of the row starting at tile index `index`; call
    /// [`TileBuffer::note_depth_written`] after writing.
    #[inline(always)]
    pub fn depth_row_mut(&mut self, index: usize) -> &mut [f32] {
        self.debug_assert_materialized();
        &mut self.depth[index..]
    }

    /// The depth and colour rows of the 8 × 8 block whose first pixel has tile index `first`
    /// (single-sample tiles): fixed-size views, so the per-pixel loop indexes its rows without
    /// bounds checks.
    #[inline(always)]
    pub fn block_rows_mut(&mut self, first: usize) -> BlockRows<'_> {
        self.debug_assert_block_written(first);
        debug_assert_eq!(self.samples, 1);
        let (r, rest) = self.color.split_at_mut(TILE_PIXELS);
        let (g, rest) = rest.split_at_mut(TILE_PIXELS);
        let (b, a) = rest.split_at_mut(TILE_PIXELS);
        BlockRows {
            depth: block_span(&mut self.depth, first),
            color: [
                block_span(r, first),
                block_span(g, first),
                block_span(b, first),
                block_span(a, first),
            ],
        }
    }

    /// Samples per pixel of this tile.
    #[inline(always)]
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Depths of sample `sample` from tile index `index` on (multisampled tiles only).
    #[inline(always)]
    pub fn sample_depth_row(&self, sample: usize, index: usize) -> &[f32] {
        self.debug_assert_materialized();
        debug_assert!(self.samples > 1 && sample < self.samples);
        &self.depth[(1 + sample) * TILE_PIXELS + index..]
    }

    /// Mutable depths of sample `sample` from tile index `index` on (multisampled tiles only).
    #[inline(always)]
    pub fn sample_depth_row_mut(&mut self, sample: usize, index: usize) -> &mut [f32] {
        self.debug_assert_materialized();
        debug_assert!(self.samples > 1 && sample < self.samples);
        &mut self.depth[(1 + sample) * TILE_PIXELS + index..]
    }

    /// Depths of depth plane `plane` (0: pixel centres, `1 + s`: sample `s`) from tile index
    /// `index` on.
    #[inline(always)]
    pub fn depth_plane_row(&self, plane: usize, index: usize) -> &[f32] {
        self.debug_assert_materialized();
        &self.depth[plane * TILE_PIXELS + index..]
    }

    /// Number of depth planes (1 at 1×, samples + 1 when multisampled).
    #[inline(always)]
    pub fn depth_plane_count(&self) -> usize {
        self.depth.len() / TILE_PIXELS
    }

    /// The four colour planes of sample `sample` from tile index `index` on.
    #[inline(always)]
    pub fn sample_color_row(&self, sample: usize, index: usize) -> [&[f32]; 4] {
        self.debug_assert_materialized();
        let plane = self.samples * TILE_PIXELS;
        let at = sample * TILE_PIXELS + index;
        [
            &self.color[at..],
            &self.color[plane + at..],
            &self.color[2 * plane + at..],
            &self.color[3 * plane + at..],
        ]
    }

    /// The four colour planes of sample `sample` from tile index `index` on, mutable.
    #[inline(always)]
    pub fn sample_color_row_mut(&mut self, sample: usize, index: usize) -> [&mut [f32]; 4] {
        self.debug_assert_materialized();
        let plane = self.samples * TILE_PIXELS;
        let at = sample * TILE_PIXELS + index;
        let (r, rest) = self.color.split_at_mut(plane);
        let (g, rest) = rest.split_at_mut(plane);
        let (b, a) = rest.split_at_mut(plane);
        [&mut r[at..], &mut g[at..], &mut b[at..], &mut a[at..]]
    }

    /// The four colour planes from tile index `index` on (single-sample tiles).
    #[inline(always)]
    pub fn color_row(&self, index: usize) -> [&[f32]; 4] {
        self.debug_assert_materialized();
        debug_assert_eq!(self.samples, 1);
        let (r, rest) = self.color.split_at(TILE_PIXELS);
        let (g, rest) = rest.split_at(TILE_PIXELS);
        let (b, a) = rest.split_at(TILE_PIXELS);
        [&r[index..], &g[index..], &b[index..], &a[index..]]
    }

    /// The four colour planes from tile index `index` on, mutable (single-sample tiles).
    #[inline(always)]
    pub fn color_row_mut(&mut self, index: usize) -> [&mut [f32]; 4] {
        self.debug_assert_materialized();
        debug_assert_eq!(self.samples, 1);
        let (r, rest) = self.color.split_at_mut(TILE_PIXELS);
        let (g, rest) = rest.split_at_mut(TILE_PIXELS);
        let (b, a) = rest.split_at_mut(TILE_PIXELS);
        [
            &mut r[index..],
            &mut g[index..],
            &mut b[index..],
            &mut a[index..],
        ]
    }

    /// The colour of the pixel at tile index `index`; on a multisampled tile the resolved
    /// colour: the mean of its samples in linear space (summed in sample order).
    #[inline]
    pub fn color_at(&self, index: usize) -> Vec4 {
        // A deferred clear resolves through the same sum and division as stored samples, so it
        // reads back bit for bit as a written one.
        match self.state.deferred_clear {
            Some(clear) if clear.holds(index) => resolve(self.samples, |c, _| clear.color[c]),
            _ => {
                let plane = self.samples * TILE_PIXELS;
                resolve(self.samples, |c, s| {
                    self.color[c * plane + s * TILE_PIXELS + index]
                })
            }
        }
    }

    /// The depth of the pixel at tile index `index`.
    #[inline]
    pub fn depth_at(&self, index: usize) -> f32 {
        match self.state.deferred_clear {
            Some(clear) if clear.holds(index) => clear.depth,
            _ => self.depth[index],
        }
    }

    /// Writes a deferred clear to the storage of every block still pending (nothing when none
    /// is). Paths that touch the tile's storage other than block by block
    /// ([`TileBuffer::take_pending_block`]) call it first.
    #[inline]
    pub(crate) fn materialize(&mut self) {
        let Some(clear) = self.state.deferred_clear.take() else {
            return;
        };
        if clear.pending == ALL_BLOCKS {
            self.write_color(clear.color);
            self.depth.fill(clear.depth);
            return;
        }
        let mut pending = clear.pending;
        while pending != 0 {
            let first = block_first_pixel(pending.trailing_zeros() as usize);
            pending &= pending - 1;
            // Colour plane `c·N + s` holds channel `c` of sample `s`.
            for (k, plane) in self.color.chunks_exact_mut(TILE_PIXELS).enumerate() {
                fill_block(plane, first, clear.color[k / self.samples]);
            }
            for plane in self.depth.chunks_exact_mut(TILE_PIXELS) {
                fill_block(plane, first, clear.depth);
            }
        }
    }

    /// The recorded clear when block `block` (1× tiles) does not hold it in the storage yet; the
    /// block then counts as written, and the caller must store every pixel of the block's
    /// colour and depth (the clear's values where it draws nothing). `None` when the storage
    /// holds the block's values.
    #[inline(always)]
    pub fn take_pending_block(&mut self, block: usize) -> Option<DeferredClear> {
        debug_assert_eq!(self.samples, 1);
        let clear = self.state.deferred_clear.as_mut()?;
        if !clear.pending_block(block) {
            return None;
        }
        let taken = *clear;
        clear.pending &= !(1u64 << block);
        if clear.pending == 0 {
            self.state.deferred_clear = None;
        }
        Some(taken)
    }

    /// Sets every sample's colour in the storage.
    fn write_color(&mut self, color: Vec4) {
        let plane = self.samples * TILE_PIXELS;
        for (planes, value) in self.color.chunks_exact_mut(plane).zip(color.to_array()) {
            planes.fill(value);
        }
    }

    /// Panics (debug builds) if the storage is read or written while a clear is deferred.
    #[inline(always)]
    fn debug_assert_materialized(&self) {
        debug_assert!(
            self.state.deferred_clear.is_none(),
            "tile storage used before materialize"
        );
    }

    /// Panics (debug builds) if the block holding tile index `first` still has a pending clear.
    #[inline(always)]
    fn debug_assert_block_written(&self, first: usize) {
        debug_assert!(
            self.state
                .deferred_clear
                .is_none_or(|clear| !clear.holds(first)),
            "block storage used before its pending clear was taken"
        );
    }

    /// Index of the 8 × 8 block holding absolute pixel `(x, y)` within its tile.
    #[inline(always)]
    pub fn block_index(x: i32, y: i32) -> usize {
        let mask = (TILE_SIZE >> BLOCK_LOG2) as i32 - 1;
        ((((y >> BLOCK_LOG2) & mask) << (TILE_LOG2 - BLOCK_LOG2)) | ((x >> BLOCK_LOG2) & mask))
            as usize
    }

    /// Whether a triangle whose vertex depths are at least `min_depth` fails a LESS or LEQUAL
    /// test on every pixel of block `block` (so the block can be skipped).
    #[inline(always)]
    pub fn block_occludes(&self, block: usize, min_depth: f32) -> bool {
        min_depth - DEPTH_BOUND_SLACK > self.state.block_depth_max[block]
    }

    /// Records the exact largest depth of block `block` after the per-pixel path wrote it, and
    /// keeps the tile's bound valid.
    #[inline(always)]
    pub fn set_block_depth_max(&mut self, block: usize, max_depth: f32) {
        self.state.block_depth_max[block] = max_depth;
        self.note_depth_written(max_depth);
    }

    /// Records that depths up to `max_depth` were written, keeping the tile's bound valid.
    #[inline]
    pub fn note_depth_written(&mut self, max_depth: f32) {
        self.state.depth_bound = self.state.depth_bound.max(max_depth);
        self.state.depth_bound_exact = false;
    }

    /// Fills colour and/or depth. Clearing both is deferred ([`TileBuffer::materialize`]);
    /// clearing one of them writes a pending clear first, then that one.
    pub(super) fn fill(&mut self, color: Option<Vec4>, depth: Option<f32>) {
        if let (Some(color), Some(depth)) = (color, depth) {
            self.state.clear(color, depth);
            return;
        }
        self.materialize();
        if let Some(c) = color {
            self.write_color(c);
        }
        if let Some(d) = depth {
            self.depth.fill(d);
            self.state.reset_depth(d);
        }
    }

    /// Whether every fragment of a triangle whose vertex depths are at least `min_depth` would
    /// fail a LESS or LEQUAL test in this tile (so the triangle can be skipped here without
    /// changing the picture). `tile` is the tile's rectangle on the target and `area` the area
    /// of the triangle's box within it, used to decide whether a stale bound is worth
    /// recomputing.
    #[inline]
    pub fn occludes(&mut self, min_depth: f32, area: i32, tile: &PixelRect) -> bool {
        let min_depth = min_depth - DEPTH_BOUND_SLACK;
        if min_depth > self.state.depth_bound {
            return true;
        }
        let tile_area = tile.width() * tile.height();
        if self.state.depth_bound_exact || area < DEPTH_BOUND_REFRESH_AREA.min(tile_area / 4) {
            return false;
        }
        self.state.depth_bound = self.exact_depth_bound(tile);
        self.state.depth_bound_exact = true;
        min_depth > self.state.depth_bound
    }

    /// The largest depth of the tile's pixels on the target (`tile` is the tile's rectangle on
    /// it; pixels past its edge keep the clear value forever), over every depth plane (the
    /// pixel centres' and, when multisampled, each sample's). A block wholly on the target
    /// gives its exact maximum, kept by the per-pixel paths, so only blocks cut by the
    /// target's edge are read pixel by pixel: 64 values instead of 4096 for an inner tile.
    fn exact_depth_bound(&self, tile: &PixelRect) -> f32 {
        let pending = match self.state.deferred_clear {
            Some(clear) if clear.pending == ALL_BLOCKS => return clear.depth,
            Some(clear) => Some(clear),
            None => None,
        };
        let side = TILE_SIZE as i32;
        if tile.width() == side && tile.height() == side {
            // A tile wholly on the target (most of them): every block is whole, so the bound is
            // the largest of the 64 kept block maxima (a pending block's is its clear depth),
            // taken eight at a time so that the compiler keeps it in vector registers.
            let mut lanes = [f32::NEG_INFINITY; 8];
            for eight in self.state.block_depth_max.chunks_exact(8) {
                for (lane, &value) in lanes.iter_mut().zip(eight) {
                    *lane = lane.max(value);
                }
            }
            return lanes.into_iter().fold(f32::NEG_INFINITY, f32::max);
        }
        let block = BLOCK_SIZE as i32;
        let mut bound = f32::NEG_INFINITY;
        for by in 0..(TILE_SIZE as i32 / block) {
            let y0 = tile.y0 + by * block;
            let y1 = (y0 + block).min(tile.y1);
            if y0 >= y1 {
                break;
            }
            for bx in 0..(TILE_SIZE as i32 / block) {
                let x0 = tile.x0 + bx * block;
                let x1 = (x0 + block).min(tile.x1);
                if x0 >= x1 {
                    break;
                }
                let block_index = Self::block_index(x0, y0);
                if y1 - y0 == block && x1 - x0 == block {
                    bound = bound.max(self.state.block_depth_max[block_index]);
                    continue;
                }
                if let Some(clear) = pending.filter(|c| c.pending_block(block_index)) {
                    bound = bound.max(clear.depth);
                    continue;
                }
                for plane in self.depth.chunks_exact(TILE_PIXELS) {
                    for y in y0..y1 {
                        let row = Self::index(x0, y);
                        bound = plane[row..row + (x1 - x0) as usize]
                            .iter()
                            .copied()
                            .fold(bound, f32::max);
                    }
                }
            }
        }
        bound
    }

    /// Index of absolute pixel `(x, y)` within the tile (the tile's origin is a multiple of
    /// `TILE_SIZE`).
    #[inline]
    pub fn index(x: i32, y: i32) -> usize {
        let mask = TILE_SIZE as i32 - 1;
        (((y & mask) << TILE_LOG2) | (x & mask)) as usize
    }
}

impl TileState {
    /// The state of a new tile: depth 1 everywhere, nothing deferred.
    pub(super) fn new() -> Self {
        Self {
            depth_bound: 1.0,
            depth_bound_exact: true,
            block_depth_max: [1.0; BLOCKS_PER_TILE],
            deferred_clear: None,
        }
    }

    /// Records a clear of colour and depth for every block, deferred.
    pub(super) fn clear(&mut self, color: Vec4, depth: f32) {
        self.deferred_clear = Some(DeferredClear {
            color,
            depth,
            pending: ALL_BLOCKS,
        });
        self.reset_depth(depth);
    }

    /// The depth bounds after every depth was set to `depth`.
    fn reset_depth(&mut self, depth: f32) {
        self.depth_bound = depth;
        self.depth_bound_exact = true;
        self.block_depth_max = [depth; BLOCKS_PER_TILE];
    }

    /// The blocks whose storage does not hold their values yet (bit `b` for block `b`; 0
    /// when nothing is deferred).
    pub(super) fn pending_blocks(&self) -> u64 {
        self.deferred_clear.map_or(0, |clear| clear.pending)
    }
}

impl DeferredClear {
    /// Whether block `block` is pending.
    #[inline(always)]
    pub(super) fn pending_block(&self, block: usize) -> bool {
        self.pending & (1u64 << block) != 0
    }

    /// Whether the pixel at tile index `index` lies in a pending block.
    #[inline(always)]
    pub(super) fn holds(&self, index: usize) -> bool {
        let (x, y) = (index % TILE_SIZE as usize, index / TILE_SIZE as usize);
        self.pending_block(TileBuffer::block_index(x as i32, y as i32))
    }
}

/// A pixel's colour from `sample(channel, sample)` of its `samples` samples: the value itself
/// at 1×, the mean of the samples (summed in sample order) when multisampled.
#[inline]
pub(super) fn resolve(samples: usize, sample: impl Fn(usize, usize) -> f32) -> Vec4 {
    if samples == 1 {
        return Vec4::from_array(std::array::from_fn(|c| sample(c, 0)));
    }
    let mut sum = [0.0f32; 4];
    for (c, total) in sum.iter_mut().enumerate() {
        for s in 0..samples {
            *total += sample(c, s);
        }
    }
    Vec4::from_array(sum) / samples as f32
}

/// Sets the 8 × 8 block of `plane` (one tile plane) whose first pixel is `first` to `value`.
fn fill_block(plane: &mut [f32], first: usize, value: f32) {
    for row in 0..BLOCK_SIZE as usize {
        let at = first + row * TILE_SIZE as usize;
        plane[at..at + BLOCK_SIZE as usize].fill(value);
    }
}

/// Tile index of the first pixel of block `block` (the inverse of [`TileBuffer::block_index`]).
#[inline(always)]
pub(super) fn block_first_pixel(block: usize) -> usize {
    let blocks_per_row = (TILE_SIZE / BLOCK_SIZE) as usize;
    let (bx, by) = (block % blocks_per_row, block / blocks_per_row);
    TileBuffer::index(
        (bx * BLOCK_SIZE as usize) as i32,
        (by * BLOCK_SIZE as usize) as i32,
    )
}

/// A vector of `n` copies of `value`, or an error instead of an abort when memory runs out.
pub(super) fn filled_vec<T: Clone>(n: usize, value: T) -> Result<Vec<T>, RenderError> {
    let mut v = reserved_vec(n)?;
    v.resize(n, value);
    Ok(v)
}

/// An empty vector with room for exactly `n` values, or an error instead of an abort when
/// memory runs out.
pub(super) fn reserved_vec<T>(n: usize) -> Result<Vec<T>, RenderError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| RenderError::OutOfMemory {
            what: "render target",
            bytes: n.saturating_mul(std::mem::size_of::<T>()),
        })?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bound of a tile wholly on the target (the 64 kept block maxima) and of a tile cut by
    /// the target's edge (blocks read pixel by pixel there) both follow the depths written.
    #[test]
    fn exact_depth_bound_follows_block_maxima_and_pixels() {
        let full = PixelRect {
            x0: 0,
            y0: 0,
            x1: TILE_SIZE as i32,
            y1: TILE_SIZE as i32,
        };
        let cut = PixelRect { y1: 60, ..full };
        let mut tile = TileBuffer::new(SampleCount::X1).expect("tile");
        tile.fill(Some(Vec4::ZERO), Some(0.5));
        assert_eq!(tile.exact_depth_bound(&full), 0.5);
        // Block 9 written with depths up to 0.75; the rest still pending at 0.5.
        let _ = tile.take_pending_block(9);
        let first = block_first_pixel(9);
        fill_block(&mut tile.depth, first, 0.25);
        tile.depth[first + 3] = 0.75;
        tile.set_block_depth_max(9, 0.75);
        assert_eq!(tile.exact_depth_bound(&full), 0.75);
        assert_eq!(tile.exact_depth_bound(&cut), 0.75);
        // The last block row lies partly past the target's edge (rows 56–59 of 64): there only
        // the pixels on the target count, whatever the block's kept maximum says.
        let last = BLOCKS_PER_TILE - 1;
        let _ = tile.take_pending_block(last);
        let first = block_first_pixel(last);
        fill_block(&mut tile.depth, first, 0.125);
        tile.depth[first + 6 * TILE_SIZE as usize] = 0.875;
        tile.set_block_depth_max(last, 0.875);
        assert_eq!(tile.exact_depth_bound(&full), 0.875);
        assert_eq!(tile.exact_depth_bound(&cut), 0.75);
        tile.set_block_depth_max(17, 0.9375);
        assert_eq!(tile.exact_depth_bound(&full), 0.9375);
    }
}
