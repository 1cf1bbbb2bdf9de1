//! Output merger: depth test, blending, and the tiled framebuffer they write to.
//!
//! The default target ([`TargetFormat::LinearF32`]) keeps colour as linear `f32` RGBA (so
//! blending happens in linear space and nothing is lost before the final encode); it is
//! converted to 8-bit — sRGB-encoded or not — when read back. The 8-bit target
//! ([`TargetFormat::Srgb8`], [`srgb8`]) stores 8-bit sRGB between frames and draws each tile
//! in a worker's `f32` tile. Storage is tile-major: each 64 × 64 tile owns its colour and
//! depth, so tiles can be rasterized in parallel without sharing memory.

use std::sync::Mutex;

use glam::Vec4;
use rayon::prelude::*;

pub use kantele_rules::state::{BlendMode, DepthFunc};

pub mod srgb8;
mod tile;

pub use srgb8::Srgb8Tile;
pub use tile::{BlockRows, DeferredClear, TileBuffer, BLOCK_SPAN};

use kantele_lanes::Isa;

/// How a target stores colour between frames.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TargetFormat {
    /// Linear `f32` RGBA, 16 bytes a sample: exact; encoded to 8-bit only when read back.
    #[default]
    LinearF32,
    /// 8-bit RGBA, red, green and blue sRGB-encoded, 4 bytes a sample (OpenGL's
    /// `GL_SRGB8_ALPHA8` with `GL_FRAMEBUFFER_SRGB`). Within a frame each tile is drawn and
    /// blended in linear `f32`, then encoded exactly, so a frame that starts with a clear reads
    /// back as the same 8-bit picture as [`TargetFormat::LinearF32`] (see [`srgb8`]).
    Srgb8,
}

impl TargetFormat {
    /// Every format.
    pub const ALL: [TargetFormat; 2] = [TargetFormat::LinearF32, TargetFormat::Srgb8];

    /// The name `kantele --target` and `bench` use: `f32` or `srgb8`.
    pub fn name(self) -> &'static str {
        match self {
            TargetFormat::LinearF32 => "f32",
            TargetFormat::Srgb8 => "srgb8",
        }
    }
}

impl std::fmt::Display for TargetFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for TargetFormat {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        TargetFormat::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| format!("unknown target format '{s}' (expected f32 or srgb8)"))
    }
}

use crate::raster::bin::TileGrid;
use kantele_rules::error::RenderError;
use kantele_rules::fixed::{TILE_LOG2, TILE_PIXELS, TILE_SIZE};
use kantele_rules::multisample::{SampleCount, MAX_MULTISAMPLE_TARGET_BYTES};

/// Bytes the tiles of a `width × height` `f32` target take: 16 bytes of linear RGBA and 4 of
/// depth per pixel, for every pixel of the whole 64 × 64 tiles covering it (saturating).
pub fn framebuffer_bytes(width: u32, height: u32) -> usize {
    multisample_framebuffer_bytes(width, height, SampleCount::X1)
}

/// Bytes the tiles of a `width × height` target in `format` with `samples` samples per pixel
/// take (saturating): [`multisample_framebuffer_bytes`] for `f32`; for 8-bit sRGB 4 bytes of
/// colour per sample and 4 of depth per depth plane, plus one `f32` tile per worker thread
/// (`workers`).
pub fn target_bytes(
    width: u32,
    height: u32,
    samples: SampleCount,
    format: TargetFormat,
    workers: usize,
) -> usize {
    match format {
        TargetFormat::LinearF32 => multisample_framebuffer_bytes(width, height, samples),
        TargetFormat::Srgb8 => TileGrid::new(width, height)
            .tile_count()
            .saturating_mul(Srgb8Tile::bytes(samples))
            .saturating_add(
                workers
                    .saturating_mul(multisample_framebuffer_bytes(TILE_SIZE, TILE_SIZE, samples)),
            ),
    }
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
#[derive(Debug)]
pub struct Framebuffer {
    grid: TileGrid,
    storage: Storage,
    /// The pixel rows held and read back (`0..height` for a whole target).
    rows: std::ops::Range<u32>,
    samples: SampleCount,
}

/// The tiles of a target, by [`TargetFormat`].
#[derive(Debug)]
enum Storage {
    LinearF32(Vec<TileBuffer>),
    Srgb8 {
        tiles: Vec<Srgb8Tile>,
        /// One `f32` tile per worker thread (rayon's thread index, modulo their number), where
        /// the tiles with work are drawn ([`srgb8`]).
        workers: Vec<Mutex<TileBuffer>>,
    },
}

/// A tile of either format, for readback.
#[derive(Clone, Copy)]
enum TileRef<'a> {
    LinearF32(&'a TileBuffer),
    Srgb8(&'a Srgb8Tile),
}

impl TileRef<'_> {
    #[inline]
    fn color_at(self, index: usize) -> Vec4 {
        match self {
            TileRef::LinearF32(t) => t.color_at(index),
            TileRef::Srgb8(t) => t.color_at(index),
        }
    }

    #[inline]
    fn depth_at(self, index: usize) -> f32 {
        match self {
            TileRef::LinearF32(t) => t.depth_at(index),
            TileRef::Srgb8(t) => t.depth_at(index),
        }
    }
}

/// `n` values made by `make`, or an error instead of an abort when memory runs out.
fn try_vec<T>(
    n: usize,
    mut make: impl FnMut() -> Result<T, RenderError>,
) -> Result<Vec<T>, RenderError> {
    let mut v = tile::reserved_vec(n)?;
    for _ in 0..n {
        v.push(make()?);
    }
    Ok(v)
}

impl Framebuffer {
    /// An `f32` target of `width × height` with `samples` samples per pixel (sides checked by
    /// the caller), cleared to transparent black and depth 1.
    pub(crate) fn new(width: u32, height: u32, samples: SampleCount) -> Result<Self, RenderError> {
        Self::band(
            width,
            height,
            0..height,
            samples,
            TargetFormat::LinearF32,
            1,
        )
    }

    /// Rows `rows` (non-empty, within `0..height`, checked by the caller) of a `width × height`
    /// target in `format` with `samples` samples per pixel: only the tiles holding them are
    /// allocated (and, for 8-bit sRGB, one `f32` tile for each of `workers` threads). A
    /// multisampled band larger than [`MAX_MULTISAMPLE_TARGET_BYTES`] is refused before
    /// anything is allocated.
    pub(crate) fn band(
        width: u32,
        height: u32,
        rows: std::ops::Range<u32>,
        samples: SampleCount,
        format: TargetFormat,
        workers: usize,
    ) -> Result<Self, RenderError> {
        let workers = workers.max(1);
        let bytes = target_bytes(width, rows.end - rows.start, samples, format, workers);
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
        let storage = match format {
            TargetFormat::LinearF32 => {
                Storage::LinearF32(try_vec(grid.tile_count(), || TileBuffer::new(samples))?)
            }
            TargetFormat::Srgb8 => Storage::Srgb8 {
                tiles: try_vec(grid.tile_count(), || Srgb8Tile::new(samples))?,
                workers: try_vec(workers, || TileBuffer::new(samples).map(Mutex::new))?,
            },
        };
        Ok(Self {
            grid,
            storage,
            rows,
            samples,
        })
    }

    /// How the target stores colour.
    pub fn format(&self) -> TargetFormat {
        match self.storage {
            Storage::LinearF32(_) => TargetFormat::LinearF32,
            Storage::Srgb8 { .. } => TargetFormat::Srgb8,
        }
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

    /// The `f32` tiles of an `f32` target (`None` for other formats).
    #[cfg(test)]
    pub(crate) fn f32_tiles_mut(&mut self) -> Option<&mut [TileBuffer]> {
        match &mut self.storage {
            Storage::LinearF32(tiles) => Some(tiles),
            Storage::Srgb8 { .. } => None,
        }
    }

    /// Runs `work(state, tile_index, tile)` on every tile for which `busy(tile_index)` holds,
    /// tiles in parallel in pieces of at most `piece` tiles (`init` makes one `state` per
    /// piece), and sums the results with `sum` (tiles not visited give `R::default()`). The
    /// tile is an `f32` one whatever the format: an 8-bit target's tile is decoded into the
    /// worker's `f32` tile, worked on there and encoded back with the lanes of `isa`
    /// ([`srgb8`]).
    pub(crate) fn par_tiles<S, R: Default + Send>(
        &mut self,
        piece: usize,
        isa: Isa,
        busy: impl Fn(usize) -> bool + Sync + Send,
        init: impl Fn() -> S + Sync + Send,
        work: impl Fn(&mut S, usize, &mut TileBuffer) -> R + Sync + Send,
        sum: impl Fn(R, R) -> R + Sync + Send,
    ) -> R {
        match &mut self.storage {
            Storage::LinearF32(tiles) => tiles
                .par_iter_mut()
                .enumerate()
                .with_max_len(piece)
                .map_init(init, |state, (i, tile)| match busy(i) {
                    true => work(state, i, tile),
                    false => R::default(),
                })
                .reduce(R::default, sum),
            Storage::Srgb8 { tiles, workers } => {
                let workers = &*workers;
                tiles
                    .par_iter_mut()
                    .enumerate()
                    .with_max_len(piece)
                    .map_init(init, |state, (i, tile)| {
                        if !busy(i) {
                            return R::default();
                        }
                        let worker = rayon::current_thread_index().unwrap_or(0) % workers.len();
                        // Each worker thread locks its own tile; the work does not fork, so a
                        // thread never waits on itself. A poisoned lock (a panic while drawing)
                        // is taken over: `load` replaces everything the tile holds.
                        let mut scratch = workers[worker]
                            .lock()
                            .unwrap_or_else(|poisoned| poisoned.into_inner());
                        srgb8::load(&mut scratch, tile);
                        let result = work(state, i, &mut scratch);
                        srgb8::store(tile, &scratch, isa);
                        result
                    })
                    .reduce(R::default, sum)
            }
        }
    }

    /// Sets every pixel's colour and/or depth. Clearing both only records the clear; clearing
    /// one of them writes it (on an 8-bit target through the workers' `f32` tiles).
    pub fn clear(&mut self, color: Option<Vec4>, depth: Option<f32>) {
        match &mut self.storage {
            Storage::LinearF32(tiles) => {
                tiles.par_iter_mut().for_each(|t| t.fill(color, depth));
                return;
            }
            Storage::Srgb8 { tiles, .. } => {
                if let (Some(color), Some(depth)) = (color, depth) {
                    tiles.par_iter_mut().for_each(|t| t.clear(color, depth));
                    return;
                }
            }
        }
        self.par_tiles(
            1,
            Isa::selected(),
            |_| true,
            || (),
            |_, _, tile| tile.fill(color, depth),
            |(), ()| (),
        )
    }

    /// The tile at `index`.
    #[inline]
    fn tile(&self, index: usize) -> TileRef<'_> {
        match &self.storage {
            Storage::LinearF32(tiles) => TileRef::LinearF32(&tiles[index]),
            Storage::Srgb8 { tiles, .. } => TileRef::Srgb8(&tiles[index]),
        }
    }

    // Readback (robust branch). Everything goes through `read_rows`, which holds one row of
    // output at a time: the streaming readers add one row to the framebuffer's memory, the
    // whole-frame readers exactly their result (reserved fallibly in the `try_` forms).

    /// Calls `emit(y, row)` for every row held, top to bottom, with `row` holding `per_pixel`
    /// values per pixel made by `get(tile, index, out)`; one row buffer is reused.
    fn read_rows<T: Copy + Default>(
        &self,
        per_pixel: usize,
        get: impl Fn(TileRef<'_>, usize, &mut [T]),
        mut emit: impl FnMut(u32, &[T]),
    ) {
        let w = self.grid.width as usize;
        let mut row = vec![T::default(); w * per_pixel];
        for y in self.rows.clone() {
            let band_row = (y >> TILE_LOG2) - self.grid.first_row;
            let tile_row = band_row as usize * self.grid.tiles_x as usize;
            for (x, out) in row.chunks_exact_mut(per_pixel).enumerate() {
                let tile = self.tile(tile_row + (x >> TILE_LOG2));
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
                out.copy_from_slice(&kantele_rules::color::encode_rgba8(
                    t.color_at(i).to_array(),
                    srgb,
                ))
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
    fn locate(&self, x: u32, y: u32) -> Option<(TileRef<'_>, usize)> {
        if x >= self.grid.width || !self.rows.contains(&y) {
            return None;
        }
        let band_row = (y >> TILE_LOG2) - self.grid.first_row;
        let tile = band_row as usize * self.grid.tiles_x as usize + (x >> TILE_LOG2) as usize;
        Some((self.tile(tile), TileBuffer::index(x as i32, y as i32)))
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
            for tile in fb.f32_tiles_mut().expect("f32 target") {
                tile.materialize();
            }
            let written = (fb.read_color(), fb.read_depth());
            assert_eq!(deferred, written, "{samples}");
            assert!(written.1.iter().all(|&d| d == 0.375));
            assert_eq!(fb.depth_at(69, 2), Some(0.375));
        }
    }

    /// A block taken from a deferred clear reads back what was written into it, every other
    /// pixel the clear, before and after the rest of the clear is written out; a block is
    /// handed out once.
    #[test]
    fn blocks_taken_from_a_deferred_clear_read_back_their_own_values() {
        let mut fb = Framebuffer::new(130, 70, SampleCount::X1).expect("small target");
        let color = Vec4::new(0.1, 0.7, 1.0 / 3.0, 0.9);
        fb.clear(Some(color), Some(0.375));
        // Tile 0's block 9 (pixels x 8..16, y 8..16) and tile 1's block 0 (x 64..72, y 0..8).
        let taken = [(0, 9, 8, 8), (1, 0, 64, 0)];
        for (tile, block, x, y) in taken {
            let tile = &mut fb.f32_tiles_mut().expect("f32 target")[tile];
            let clear = tile
                .take_pending_block(block)
                .expect("pending after a clear");
            assert_eq!((clear.color, clear.depth), (color, 0.375));
            assert!(tile.take_pending_block(block).is_none(), "handed out twice");
            let mut rows = tile.block_rows_mut(TileBuffer::index(x, y));
            for row in 0..8 {
                let at = BlockRows::row_offset(row);
                rows.depth[at..at + 8].fill(0.25);
                for plane in rows.color.iter_mut() {
                    plane[at..at + 8].fill(0.5);
                }
            }
        }
        let in_taken = |x: u32, y: u32| {
            taken.iter().any(|&(_, _, bx, by)| {
                (bx as u32..bx as u32 + 8).contains(&x) && (by as u32..by as u32 + 8).contains(&y)
            })
        };
        let expected: Vec<(Vec4, f32)> = (0..70u32)
            .flat_map(|y| (0..130u32).map(move |x| (x, y)))
            .map(|(x, y)| match in_taken(x, y) {
                true => (Vec4::splat(0.5), 0.25),
                false => (color, 0.375),
            })
            .collect();
        let read = |fb: &Framebuffer| -> Vec<(Vec4, f32)> {
            let colors = fb.read_color();
            let depths = fb.read_depth();
            colors
                .into_iter()
                .zip(depths)
                .map(|(c, d)| (Vec4::from_array(c), d))
                .collect()
        };
        assert_eq!(read(&fb), expected, "deferred");
        for tile in fb.f32_tiles_mut().expect("f32 target") {
            tile.materialize();
            assert!(tile.take_pending_block(3).is_none());
        }
        assert_eq!(read(&fb), expected, "written out");
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
