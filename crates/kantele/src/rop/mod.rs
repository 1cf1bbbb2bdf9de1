//! Output merger: depth test, blending, and the tiled framebuffer they write to.
//!
//! Colour is kept as linear `f32` RGBA (so blending happens in linear space and nothing is lost
//! before the final encode); it is converted to 8-bit — sRGB-encoded or not — when read back.
//! Storage is tile-major: each 64 × 64 tile owns its colour and depth, so tiles can be
//! rasterized in parallel without sharing memory.

use glam::Vec4;

pub use crate::state::{BlendMode, DepthFunc};

use crate::error::RenderError;
use crate::fixed::{BLOCK_LOG2, BLOCK_SIZE, TILE_LOG2, TILE_PIXELS, TILE_SIZE};
use crate::multisample::{SampleCount, MAX_MULTISAMPLE_TARGET_BYTES};

/// 8 × 8 blocks in a tile (64).
const BLOCKS_PER_TILE: usize = ((TILE_SIZE >> BLOCK_LOG2) * (TILE_SIZE >> BLOCK_LOG2)) as usize;
use crate::raster::bin::TileGrid;
use crate::setup::PixelRect;

/// One tile's colour and depth, `TILE_SIZE × TILE_SIZE`, row-major within the tile. Colour is
/// stored as four planes (red, green, blue, alpha; structure of arrays) so that eight adjacent
/// pixels of a row are one lane load per channel.
///
/// A multisampled tile (N samples) holds N planes per channel (channel `c`, sample `s` at plane
/// `c·N + s`) and N + 1 depth planes: plane 0 is the depth at the pixel centre (the per-pixel
/// depth read back, see [`crate::multisample`]), plane `1 + s` that of sample `s`. At 1× the
/// single colour plane per channel and depth plane 0 are the only ones, as before.
#[derive(Clone, Debug)]
pub struct TileBuffer {
    /// Linear colour planes: red at `0..TILE_PIXELS·N`, then green, blue and alpha.
    color: Vec<f32>,
    /// Window depth planes: the pixel centre's, then each sample's (multisampled only).
    depth: Vec<f32>,
    /// Samples per pixel (1, 4 or 8).
    samples: usize,
    /// An upper bound of every value in `depth` (kept by every depth write).
    depth_bound: f32,
    /// Whether `depth_bound` is the exact maximum (false after writes until recomputed).
    depth_bound_exact: bool,
    /// The largest depth of each 8 × 8 block (row-major blocks of the tile), kept exact by the
    /// per-pixel path after every block it writes: the second level of the depth hierarchy.
    block_depth_max: [f32; BLOCKS_PER_TILE],
    /// A clear not yet written to the storage: while set, every pixel and sample of the tile
    /// holds this colour and depth, whatever `color` and `depth` contain. Clearing a frame only
    /// sets it; the first triangle that reaches the tile writes it out
    /// ([`TileBuffer::materialize`]), in the thread that rasterizes the tile, so the tile is
    /// in cache for its triangles, and a tile that no triangle reaches is never written.
    deferred_clear: Option<DeferredClear>,
}

/// The values of a clear that a tile has not written to its storage yet.
#[derive(Clone, Copy, Debug)]
struct DeferredClear {
    color: Vec4,
    depth: f32,
}

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
    fn new(samples: SampleCount) -> Result<Self, RenderError> {
        let n = samples.count();
        Ok(Self {
            color: filled_vec(4 * n * TILE_PIXELS, 0.0)?,
            depth: filled_vec(depth_planes(samples) * TILE_PIXELS, 1.0)?,
            samples: n,
            depth_bound: 1.0,
            depth_bound_exact: true,
            block_depth_max: [1.0; BLOCKS_PER_TILE],
            deferred_clear: None,
        })
    }

    /// Depths of the row starting at tile index `index` (to the end of the tile).
    #[inline(always)]
    pub fn depth_row(&self, index: usize) -> &[f32] {
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
        &self.depth[index..]
    }

    /// Mutable depths of the row starting at tile index `index`; call
    /// [`TileBuffer::note_depth_written`] after writing.
    #[inline(always)]
    pub fn depth_row_mut(&mut self, index: usize) -> &mut [f32] {
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
        &mut self.depth[index..]
    }

    /// The depth and colour rows of the 8 × 8 block whose first pixel has tile index `first`
    /// (single-sample tiles): fixed-size views, so the per-pixel loop indexes its rows without
    /// bounds checks.
    #[inline(always)]
    pub fn block_rows_mut(&mut self, first: usize) -> BlockRows<'_> {
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
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
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
        debug_assert!(self.samples > 1 && sample < self.samples);
        &self.depth[(1 + sample) * TILE_PIXELS + index..]
    }

    /// Mutable depths of sample `sample` from tile index `index` on (multisampled tiles only).
    #[inline(always)]
    pub fn sample_depth_row_mut(&mut self, sample: usize, index: usize) -> &mut [f32] {
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
        debug_assert!(self.samples > 1 && sample < self.samples);
        &mut self.depth[(1 + sample) * TILE_PIXELS + index..]
    }

    /// Depths of depth plane `plane` (0: pixel centres, `1 + s`: sample `s`) from tile index
    /// `index` on.
    #[inline(always)]
    pub fn depth_plane_row(&self, plane: usize, index: usize) -> &[f32] {
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
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
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
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
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
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
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
        debug_assert_eq!(self.samples, 1);
        let (r, rest) = self.color.split_at(TILE_PIXELS);
        let (g, rest) = rest.split_at(TILE_PIXELS);
        let (b, a) = rest.split_at(TILE_PIXELS);
        [&r[index..], &g[index..], &b[index..], &a[index..]]
    }

    /// The four colour planes from tile index `index` on, mutable (single-sample tiles).
    #[inline(always)]
    pub fn color_row_mut(&mut self, index: usize) -> [&mut [f32]; 4] {
        debug_assert!(
            self.deferred_clear.is_none(),
            "tile storage read before materialize"
        );
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
        if let Some(clear) = self.deferred_clear {
            return self.resolved_clear_color(clear.color);
        }
        if self.samples > 1 {
            let plane = self.samples * TILE_PIXELS;
            let mut sum = [0.0f32; 4];
            for (c, total) in sum.iter_mut().enumerate() {
                for s in 0..self.samples {
                    *total += self.color[c * plane + s * TILE_PIXELS + index];
                }
            }
            return Vec4::from_array(sum) / self.samples as f32;
        }
        Vec4::new(
            self.color[index],
            self.color[TILE_PIXELS + index],
            self.color[2 * TILE_PIXELS + index],
            self.color[3 * TILE_PIXELS + index],
        )
    }

    /// The depth of the pixel at tile index `index`.
    #[inline]
    pub fn depth_at(&self, index: usize) -> f32 {
        match self.deferred_clear {
            Some(clear) => clear.depth,
            None => self.depth[index],
        }
    }

    /// What [`TileBuffer::color_at`] gives for a pixel whose every sample holds `color`: the
    /// same sum in sample order and the same division, so a deferred clear reads back bit for
    /// bit as a written one.
    fn resolved_clear_color(&self, color: Vec4) -> Vec4 {
        if self.samples == 1 {
            return color;
        }
        let mut sum = [0.0f32; 4];
        for (total, value) in sum.iter_mut().zip(color.to_array()) {
            for _ in 0..self.samples {
                *total += value;
            }
        }
        Vec4::from_array(sum) / self.samples as f32
    }

    /// Writes a deferred clear to the storage (nothing when none is pending). The per-pixel
    /// paths call it before they touch the tile's colour or depth.
    #[inline]
    pub(crate) fn materialize(&mut self) {
        if let Some(clear) = self.deferred_clear.take() {
            let plane = self.samples * TILE_PIXELS;
            for (planes, value) in self
                .color
                .chunks_exact_mut(plane)
                .zip(clear.color.to_array())
            {
                planes.fill(value);
            }
            self.depth.fill(clear.depth);
        }
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
        min_depth - DEPTH_BOUND_SLACK > self.block_depth_max[block]
    }

    /// Records the exact largest depth of block `block` after the per-pixel path wrote it, and
    /// keeps the tile's bound valid.
    #[inline(always)]
    pub fn set_block_depth_max(&mut self, block: usize, max_depth: f32) {
        self.block_depth_max[block] = max_depth;
        self.note_depth_written(max_depth);
    }

    /// Records that depths up to `max_depth` were written, keeping the tile's bound valid.
    #[inline]
    pub fn note_depth_written(&mut self, max_depth: f32) {
        self.depth_bound = self.depth_bound.max(max_depth);
        self.depth_bound_exact = false;
    }

    /// Fills colour and/or depth. Clearing both is deferred ([`TileBuffer::materialize`]);
    /// clearing one of them writes a pending clear first, then that one.
    fn fill(&mut self, color: Option<Vec4>, depth: Option<f32>) {
        if let (Some(color), Some(depth)) = (color, depth) {
            self.deferred_clear = Some(DeferredClear { color, depth });
            self.depth_bound = depth;
            self.depth_bound_exact = true;
            self.block_depth_max = [depth; BLOCKS_PER_TILE];
            return;
        }
        self.materialize();
        if let Some(c) = color {
            let plane = self.samples * TILE_PIXELS;
            for (planes, value) in self.color.chunks_exact_mut(plane).zip(c.to_array()) {
                planes.fill(value);
            }
        }
        if let Some(d) = depth {
            self.depth.fill(d);
            self.depth_bound = d;
            self.depth_bound_exact = true;
            self.block_depth_max = [d; BLOCKS_PER_TILE];
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
        if min_depth > self.depth_bound {
            return true;
        }
        let tile_area = tile.width() * tile.height();
        if self.depth_bound_exact || area < DEPTH_BOUND_REFRESH_AREA.min(tile_area / 4) {
            return false;
        }
        self.depth_bound = self.exact_depth_bound(tile);
        self.depth_bound_exact = true;
        min_depth > self.depth_bound
    }

    /// The largest depth of the tile's pixels on the target (`tile` is the tile's rectangle on
    /// it; pixels past its edge keep the clear value forever), over every depth plane (the
    /// pixel centres' and, when multisampled, each sample's). A block wholly on the target
    /// gives its exact maximum, kept by the per-pixel paths, so only blocks cut by the
    /// target's edge are read pixel by pixel: 64 values instead of 4096 for an inner tile.
    fn exact_depth_bound(&self, tile: &PixelRect) -> f32 {
        if let Some(clear) = self.deferred_clear {
            return clear.depth;
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
                if y1 - y0 == block && x1 - x0 == block {
                    bound = bound.max(self.block_depth_max[Self::block_index(x0, y0)]);
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

/// A vector of `n` copies of `value`, or an error instead of an abort when memory runs out.
fn filled_vec<T: Clone>(n: usize, value: T) -> Result<Vec<T>, RenderError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| RenderError::OutOfMemory {
            what: "render target",
            bytes: n.saturating_mul(std::mem::size_of::<T>()),
        })?;
    v.resize(n, value);
    Ok(v)
}

/// Bytes the tiles of a `width × height` target take: 16 bytes of linear RGBA and 4 of depth
/// per pixel, for every pixel of the whole 64 × 64 tiles covering it (saturating).
pub fn framebuffer_bytes(width: u32, height: u32) -> usize {
    multisample_framebuffer_bytes(width, height, SampleCount::X1)
}

/// Depth planes of a tile with `samples` samples per pixel.
fn depth_planes(samples: SampleCount) -> usize {
    if samples.is_multisampled() {
        samples.count() + 1
    } else {
        1
    }
}

/// Bytes the tiles of a `width × height` target with `samples` samples per pixel take: 16
/// bytes of linear RGBA and 4 of depth per sample, plus 4 of centre depth per pixel when
/// multisampled, for every pixel of the whole tiles covering it (saturating).
pub fn multisample_framebuffer_bytes(width: u32, height: u32, samples: SampleCount) -> usize {
    let grid = TileGrid::new(width, height);
    let floats = 4 * samples.count() + depth_planes(samples);
    grid.tile_count()
        .saturating_mul(TILE_PIXELS)
        .saturating_mul(floats * std::mem::size_of::<f32>())
}

/// Bytes a whole-frame readback of a `width × height` target takes at `bytes_per_pixel`
/// (saturating); the row-streaming readers need only `width × bytes_per_pixel`.
pub fn readback_bytes(width: u32, height: u32, bytes_per_pixel: usize) -> usize {
    (width as usize)
        .saturating_mul(height as usize)
        .saturating_mul(bytes_per_pixel)
}

/// A colour + depth target stored as tiles. It may hold only a band of the target's rows
/// ([`Framebuffer::rows`]): the viewport is the whole target's, readback returns the band.
#[derive(Clone, Debug)]
pub struct Framebuffer {
    grid: TileGrid,
    tiles: Vec<TileBuffer>,
    /// The pixel rows held and read back (`0..height` for a whole target).
    rows: std::ops::Range<u32>,
    samples: SampleCount,
}

impl Framebuffer {
    /// A target of `width × height` with `samples` samples per pixel (sides checked by the
    /// caller), cleared to transparent black and depth 1.
    pub(crate) fn new(width: u32, height: u32, samples: SampleCount) -> Result<Self, RenderError> {
        Self::band(width, height, 0..height, samples)
    }

    /// Rows `rows` (non-empty, within `0..height`, checked by the caller) of a `width × height`
    /// target with `samples` samples per pixel: only the tiles holding them are allocated. A
    /// multisampled band larger than [`MAX_MULTISAMPLE_TARGET_BYTES`] is refused before anything
    /// is allocated.
    pub(crate) fn band(
        width: u32,
        height: u32,
        rows: std::ops::Range<u32>,
        samples: SampleCount,
    ) -> Result<Self, RenderError> {
        let bytes = multisample_framebuffer_bytes(width, rows.end - rows.start, samples);
        if samples.is_multisampled() && bytes > MAX_MULTISAMPLE_TARGET_BYTES {
            return Err(RenderError::Unsupported {
                backend: "cpu".into(),
                message: format!(
                    "a {width}x{height} target at {samples} samples per pixel needs {} MiB of \
                     tile storage, more than the {} MiB limit of multisampled targets (use \
                     fewer samples or a smaller picture)",
                    bytes >> 20,
                    MAX_MULTISAMPLE_TARGET_BYTES >> 20
                ),
            });
        }
        let grid = TileGrid::band(
            width,
            height,
            rows.start >> TILE_LOG2..rows.end.div_ceil(TILE_SIZE),
        );
        let mut tiles = Vec::new();
        tiles
            .try_reserve_exact(grid.tile_count())
            .map_err(|_| RenderError::OutOfMemory {
                what: "render target",
                bytes: grid.tile_count() * std::mem::size_of::<TileBuffer>(),
            })?;
        for _ in 0..grid.tile_count() {
            tiles.push(TileBuffer::new(samples)?);
        }
        Ok(Self {
            grid,
            tiles,
            rows,
            samples,
        })
    }

    /// Samples per pixel.
    pub fn samples(&self) -> SampleCount {
        self.samples
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.grid.width
    }

    /// Height in pixels (of the whole target, also when only a band is held).
    pub fn height(&self) -> u32 {
        self.grid.height
    }

    /// The pixel rows held and read back: `0..height()` unless the target is a band.
    pub fn rows(&self) -> std::ops::Range<u32> {
        self.rows.clone()
    }

    /// The tile layout.
    pub fn grid(&self) -> &TileGrid {
        &self.grid
    }

    pub(crate) fn tiles_mut(&mut self) -> &mut [TileBuffer] {
        &mut self.tiles
    }

    /// Sets every pixel's colour and/or depth.
    pub fn clear(&mut self, color: Option<Vec4>, depth: Option<f32>) {
        use rayon::prelude::*;
        self.tiles
            .par_iter_mut()
            .for_each(|tile| tile.fill(color, depth));
    }

    // Readback (robust branch). Everything goes through `read_rows`, which holds one row of
    // output at a time: the streaming readers add one row to the framebuffer's memory, the
    // whole-frame readers exactly their result (reserved fallibly in the `try_` forms).

    /// Calls `emit(y, row)` for every row held, top to bottom, with `row` holding `per_pixel`
    /// values per pixel made by `get(tile, index, out)`; one row buffer is reused.
    fn read_rows<T: Copy + Default>(
        &self,
        per_pixel: usize,
        get: impl Fn(&TileBuffer, usize, &mut [T]),
        mut emit: impl FnMut(u32, &[T]),
    ) {
        let w = self.grid.width as usize;
        let mut row = vec![T::default(); w * per_pixel];
        for y in self.rows.clone() {
            let band_row = (y >> TILE_LOG2) - self.grid.first_row;
            let tile_row = band_row as usize * self.grid.tiles_x as usize;
            for (x, out) in row.chunks_exact_mut(per_pixel).enumerate() {
                let tile = &self.tiles[tile_row + (x >> TILE_LOG2)];
                get(tile, TileBuffer::index(x as i32, y as i32), out);
            }
            emit(y, &row);
        }
    }

    /// Streams linear RGBA a row at a time: `emit(y, row)` with `row` holding `width` pixels,
    /// row 0 = top. Needs one row of memory (16 bytes per pixel of width).
    pub fn read_color_rows(&self, mut emit: impl FnMut(u32, &[[f32; 4]])) {
        self.read_rows(
            1,
            |t, i, out| out[0] = t.color_at(i).to_array(),
            |y, row| emit(y, row),
        );
    }

    /// Streams 8-bit RGBA (RGB sRGB-encoded when `srgb` is set) a row at a time: `emit(y, row)`
    /// with `row` holding `4 × width` bytes, row 0 = top — what a PNG encoder consumes row by
    /// row. Needs one row of memory.
    pub fn read_rgba8_rows(&self, srgb: bool, emit: impl FnMut(u32, &[u8])) {
        self.read_rows(
            4,
            |t, i, out| {
                out.copy_from_slice(&crate::color::encode_rgba8(t.color_at(i).to_array(), srgb))
            },
            emit,
        );
    }

    /// Streams window depth a row at a time: `emit(y, row)` with `row` holding `width` values,
    /// row 0 = top (on a multisampled target the depth at the pixel centres, equal to a 1×
    /// render's). Needs one row of memory.
    pub fn read_depth_rows(&self, emit: impl FnMut(u32, &[f32])) {
        self.read_rows(1, |t, i, out| out[0] = t.depth_at(i), emit);
    }

    /// Bytes a whole-frame readback of `bytes_per_pixel` per pixel takes for this target.
    pub fn readback_bytes(&self, bytes_per_pixel: usize) -> usize {
        readback_bytes(self.grid.width, self.rows.len() as u32, bytes_per_pixel)
    }

    /// Collects rows into one vector of exactly `width × height × per_pixel` values, reserved
    /// fallibly.
    fn try_collect<T: Copy + Default>(
        &self,
        per_pixel: usize,
        what: &'static str,
        stream: impl FnOnce(&mut dyn FnMut(u32, &[T])),
    ) -> Result<Vec<T>, RenderError> {
        let len = self.grid.width as usize * self.rows.len() * per_pixel;
        let mut out = Vec::new();
        out.try_reserve_exact(len)
            .map_err(|_| RenderError::OutOfMemory {
                what,
                bytes: len.saturating_mul(std::mem::size_of::<T>()),
            })?;
        stream(&mut |_, row| out.extend_from_slice(row));
        Ok(out)
    }

    /// Linear RGBA, row-major, row 0 = top; an error instead of an abort when the memory for
    /// the result (16 bytes per pixel) cannot be reserved.
    pub fn try_read_color(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        self.try_collect(1, "colour readback", |emit| self.read_color_rows(emit))
    }

    /// 8-bit RGBA, row-major, row 0 = top; RGB sRGB-encoded when `srgb` is set; an error
    /// instead of an abort when the memory for the result (4 bytes per pixel) cannot be
    /// reserved.
    pub fn try_read_rgba8(&self, srgb: bool) -> Result<Vec<u8>, RenderError> {
        self.try_collect(4, "8-bit readback", |emit| self.read_rgba8_rows(srgb, emit))
    }

    /// Window depth, row-major, row 0 = top; an error instead of an abort when the memory for
    /// the result (4 bytes per pixel) cannot be reserved.
    pub fn try_read_depth(&self) -> Result<Vec<f32>, RenderError> {
        self.try_collect(1, "depth readback", |emit| self.read_depth_rows(emit))
    }

    /// Linear RGBA, row-major, row 0 = top (one allocation of exactly the result; see
    /// [`Framebuffer::try_read_color`] and [`Framebuffer::read_color_rows`]).
    pub fn read_color(&self) -> Vec<[f32; 4]> {
        self.try_read_color().unwrap_or_else(|e| panic!("{e}"))
    }

    /// 8-bit RGBA, row-major, row 0 = top; RGB sRGB-encoded when `srgb` is set (one allocation
    /// of exactly the result; see [`Framebuffer::try_read_rgba8`] and
    /// [`Framebuffer::read_rgba8_rows`]).
    pub fn read_rgba8(&self, srgb: bool) -> Vec<u8> {
        self.try_read_rgba8(srgb).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Window depth, row-major, row 0 = top (one allocation of exactly the result; see
    /// [`Framebuffer::try_read_depth`] and [`Framebuffer::read_depth_rows`]).
    pub fn read_depth(&self) -> Vec<f32> {
        self.try_read_depth().unwrap_or_else(|e| panic!("{e}"))
    }

    /// The tile and the index within it of pixel `(x, y)`, if it lies on the target.
    fn locate(&self, x: u32, y: u32) -> Option<(&TileBuffer, usize)> {
        if x >= self.grid.width || !self.rows.contains(&y) {
            return None;
        }
        let band_row = (y >> TILE_LOG2) - self.grid.first_row;
        let tile = band_row as usize * self.grid.tiles_x as usize + (x >> TILE_LOG2) as usize;
        Some((&self.tiles[tile], TileBuffer::index(x as i32, y as i32)))
    }

    /// Colour of one pixel (`None` outside the target).
    pub fn pixel(&self, x: u32, y: u32) -> Option<Vec4> {
        self.locate(x, y).map(|(tile, i)| tile.color_at(i))
    }

    /// Depth of one pixel (`None` outside the target).
    pub fn depth_at(&self, x: u32, y: u32) -> Option<f32> {
        self.locate(x, y).map(|(tile, i)| tile.depth_at(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_functions() {
        use DepthFunc::*;
        let cases = [
            (Never, [false, false, false]),
            (Less, [true, false, false]),
            (Equal, [false, true, false]),
            (LessEqual, [true, true, false]),
            (Greater, [false, false, true]),
            (NotEqual, [true, false, true]),
            (GreaterEqual, [false, true, true]),
            (Always, [true, true, true]),
        ];
        for (f, expected) in cases {
            assert_eq!(
                [f.passes(0.2, 0.5), f.passes(0.5, 0.5), f.passes(0.7, 0.5)],
                expected,
                "{f:?}"
            );
        }
    }

    #[test]
    fn blend_modes() {
        let dst = Vec4::new(0.0, 0.0, 1.0, 1.0);
        let red_half = Vec4::new(1.0, 0.0, 0.0, 0.5);
        assert_eq!(BlendMode::Replace.blend(red_half, dst), red_half);
        assert_eq!(
            BlendMode::Alpha.blend(red_half, dst),
            Vec4::new(0.5, 0.0, 0.5, 1.0)
        );
        let premultiplied = Vec4::new(0.5, 0.0, 0.0, 0.5);
        assert_eq!(
            BlendMode::PremultipliedOver.blend(premultiplied, dst),
            Vec4::new(0.5, 0.0, 0.5, 1.0)
        );
        assert_eq!(
            BlendMode::Additive.blend(red_half, dst),
            Vec4::new(1.0, 0.0, 1.0, 1.5)
        );
    }

    #[test]
    fn framebuffer_reads_back_row_major() {
        let mut fb = Framebuffer::new(70, 3, SampleCount::X1).expect("small target");
        fb.clear(Some(Vec4::ONE), Some(0.25));
        let c = fb.read_color();
        assert_eq!(c.len(), 210);
        assert!(c.iter().all(|p| *p == [1.0; 4]));
        assert_eq!(fb.read_depth()[209], 0.25);
        assert_eq!(fb.read_rgba8(true).len(), 840);
    }

    /// A cleared tile that no triangle reached reads back exactly as one whose clear was
    /// written out, at 1× and multisampled (the resolved mean of equal samples).
    #[test]
    fn deferred_clear_reads_back_as_a_written_one() {
        for samples in [SampleCount::X1, SampleCount::X4, SampleCount::X8] {
            let mut fb = Framebuffer::new(70, 3, samples).expect("small target");
            let color = Vec4::new(0.1, 0.7, 1.0 / 3.0, 0.9);
            fb.clear(Some(color), Some(0.375));
            let deferred = (fb.read_color(), fb.read_depth());
            for tile in fb.tiles_mut() {
                tile.materialize();
            }
            let written = (fb.read_color(), fb.read_depth());
            assert_eq!(deferred, written, "{samples}");
            assert!(written.1.iter().all(|&d| d == 0.375));
            assert_eq!(fb.depth_at(69, 2), Some(0.375));
        }
    }

    /// Clearing only colour or only depth keeps the other from the clear before it, deferred
    /// or not.
    #[test]
    fn partial_clear_after_a_deferred_one_keeps_the_other_values() {
        let mut fb = Framebuffer::new(70, 3, SampleCount::X1).expect("small target");
        fb.clear(Some(Vec4::ONE), Some(0.25));
        fb.clear(Some(Vec4::ZERO), None);
        assert!(fb.read_color().iter().all(|p| *p == [0.0; 4]));
        assert!(fb.read_depth().iter().all(|&d| d == 0.25));
        fb.clear(Some(Vec4::ONE), Some(0.5));
        fb.clear(None, Some(0.75));
        assert!(fb.read_color().iter().all(|p| *p == [1.0; 4]));
        assert!(fb.read_depth().iter().all(|&d| d == 0.75));
    }
}
