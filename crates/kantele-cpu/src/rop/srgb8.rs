//! The 8-bit sRGB target's tile storage ([`super::TargetFormat::Srgb8`]).
//!
//! A tile of an 8-bit target keeps one packed RGBA8 value per sample and pixel (red, green and
//! blue sRGB-encoded, alpha linear, as OpenGL's `GL_SRGB8_ALPHA8`) and `f32` depth: 8 bytes a
//! pixel at 1× instead of the `f32` target's 20. Rasterization does not work on it directly.
//! Each worker thread owns one `f32` tile ([`TileBuffer`]); a tile with work in a frame is
//! decoded into it (`load`), drawn there by the same per-pixel paths as an `f32` target's, and
//! encoded back (`store`) when its bin is done. So within a frame blending happens in linear
//! `f32`, and the 8-bit values are those the `f32` target would read back: encoding is exact
//! ([`kantele_rules::color::srgb8_encode_table`]), and a frame that starts from a clear gives the same
//! bytes as the `f32` target's 8-bit readback. Between frames the target holds 8-bit values, as
//! OpenGL's sRGB framebuffers do (a frame drawn without a colour clear starts from them).
//!
//! The bookkeeping beside the storage (`TileState`: depth bounds, deferred clear) moves with
//! the tile, so a clear is recorded without touching the storage, and blocks that no triangle
//! reached are neither decoded nor encoded.

use glam::Vec4;

use super::tile::{block_first_pixel, filled_vec, resolve, TileBuffer, TileState, ALL_BLOCKS};
use kantele_lanes::{dispatch, F32x8, I32x8, Isa, LaneKernel, Lanes, Mask8};
use kantele_rules::color::{encode_rgba8, srgb8_encode_table, srgb8_table};
use kantele_rules::error::RenderError;
use kantele_rules::fixed::{BLOCK_SIZE, TILE_PIXELS, TILE_SIZE};
use kantele_rules::multisample::SampleCount;
use kantele_rules::shade::texel::{decode_texel, pack_rgba8};
use kantele_rules::shade::texture::ColorSpace;

/// One tile of an 8-bit sRGB target: packed colour, `f32` depth and the tile's bookkeeping.
#[derive(Clone, Debug)]
pub struct Srgb8Tile {
    /// Packed RGBA8 (bytes r, g, b, a in memory order, as [`pack_rgba8`]; kept as `i32` bits
    /// for lane stores): sample `s` of the pixel at tile index `i` at `s · TILE_PIXELS + i`.
    color: Vec<i32>,
    /// Window depth planes, as [`TileBuffer`]'s.
    depth: Vec<f32>,
    /// Samples per pixel (1, 4 or 8).
    samples: usize,
    /// Depth bounds and the deferred clear, as [`TileBuffer`]'s.
    state: TileState,
    /// The deferred clear's colour and its packed 8-bit value (encoded once, not per pixel read
    /// back).
    clear_texel: (Vec4, u32),
}

impl Srgb8Tile {
    /// A tile with `samples` samples per pixel, cleared to transparent black and depth 1.
    pub(super) fn new(samples: SampleCount) -> Result<Self, RenderError> {
        Ok(Self {
            color: filled_vec(samples.count() * TILE_PIXELS, 0)?,
            depth: filled_vec(super::depth_planes(samples) * TILE_PIXELS, 1.0)?,
            samples: samples.count(),
            state: TileState::new(),
            clear_texel: (Vec4::ZERO, 0),
        })
    }

    /// Bytes of storage of a tile with `samples` samples per pixel: 4 per sample of colour,
    /// 4 per depth plane.
    pub(super) fn bytes(samples: SampleCount) -> usize {
        (samples.count() + super::depth_planes(samples)) * TILE_PIXELS * 4
    }

    /// Records a clear of colour and depth (nothing is written).
    pub(super) fn clear(&mut self, color: Vec4, depth: f32) {
        self.state.clear(color, depth);
        self.note_clear_color();
    }

    /// Keeps `clear_texel` the packed value of the deferred clear's colour.
    fn note_clear_color(&mut self) {
        if let Some(clear) = self.state.deferred_clear {
            if clear.color.to_array().map(f32::to_bits)
                != self.clear_texel.0.to_array().map(f32::to_bits)
            {
                self.clear_texel = (
                    clear.color,
                    pack_rgba8(encode_rgba8(clear.color.to_array(), true)),
                );
            }
        }
    }

    /// The packed value of sample `sample` of the pixel at tile index `index`.
    #[inline]
    fn texel(&self, sample: usize, index: usize) -> u32 {
        match self.state.deferred_clear {
            Some(clear) if clear.holds(index) => self.clear_texel.1,
            _ => self.color[sample * TILE_PIXELS + index] as u32,
        }
    }

    /// The linear colour of the pixel at tile index `index`, decoded from its 8-bit values (a
    /// pending clear reads back as the 8-bit value it would be stored as); multisampled, the
    /// mean of the decoded samples.
    #[inline]
    pub fn color_at(&self, index: usize) -> Vec4 {
        resolve(self.samples, |c, s| {
            decode_texel(self.texel(s, index), ColorSpace::Srgb)[c]
        })
    }

    /// The depth of the pixel at tile index `index`.
    #[inline]
    pub fn depth_at(&self, index: usize) -> f32 {
        match self.state.deferred_clear {
            Some(clear) if clear.holds(index) => clear.depth,
            _ => self.depth[index],
        }
    }
}

/// Makes `scratch` (a worker's `f32` tile with the same samples per pixel) hold `tile`: its
/// bookkeeping, and the decoded colour and the depth of every block not pending a clear.
pub(super) fn load(scratch: &mut TileBuffer, tile: &Srgb8Tile) {
    debug_assert_eq!(scratch.samples, tile.samples);
    scratch.state = tile.state;
    let pending = tile.state.pending_blocks();
    if pending == ALL_BLOCKS {
        return;
    }
    scratch.depth.copy_from_slice(&tile.depth);
    let plane = tile.samples * TILE_PIXELS;
    for_each_block_row(!pending, |at| {
        for s in 0..tile.samples {
            let at = s * TILE_PIXELS + at;
            for i in at..at + BLOCK_SIZE as usize {
                let linear = decode_texel(tile.color[i] as u32, ColorSpace::Srgb).to_array();
                for (c, value) in linear.into_iter().enumerate() {
                    scratch.color[c * plane + i] = value;
                }
            }
        }
    });
}

/// Stores `scratch` back into `tile`: its bookkeeping and depth, and its colour encoded with
/// the lanes of `isa`, for every block not pending a clear.
pub(super) fn store(tile: &mut Srgb8Tile, scratch: &TileBuffer, isa: Isa) {
    debug_assert_eq!(scratch.samples, tile.samples);
    tile.state = scratch.state;
    tile.note_clear_color();
    let pending = tile.state.pending_blocks();
    if pending == ALL_BLOCKS {
        return;
    }
    tile.depth.copy_from_slice(&scratch.depth);
    dispatch(
        isa,
        EncodeBlocks {
            color: &scratch.color,
            samples: tile.samples,
            out: &mut tile.color,
            blocks: !pending,
            table: srgb8_encode_table(),
        },
    );
}

/// Calls `row(at)` with the tile index of the first pixel of every row of every block in
/// `blocks` (bit `b` for block `b`).
#[inline(always)]
fn for_each_block_row(mut blocks: u64, mut row: impl FnMut(usize)) {
    while blocks != 0 {
        let first = block_first_pixel(blocks.trailing_zeros() as usize);
        blocks &= blocks - 1;
        for r in 0..BLOCK_SIZE as usize {
            row(first + r * TILE_SIZE as usize);
        }
    }
}

/// Encodes the `f32` colour planes of the blocks `blocks` into packed 8-bit sRGB, eight pixels
/// of a row at a time.
struct EncodeBlocks<'a> {
    /// The `f32` tile's colour planes (channel `c`, sample `s` at plane `c · samples + s`).
    color: &'a [f32],
    samples: usize,
    /// The packed values (sample `s` at plane `s`).
    out: &'a mut [i32],
    blocks: u64,
    table: &'static [u32],
}

impl LaneKernel for EncodeBlocks<'_> {
    type Output = ();

    // No closures in here or below: a closure is compiled outside the instruction set's entry
    // point, and its lane operations would become calls.
    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) {
        let EncodeBlocks {
            color,
            samples,
            out,
            mut blocks,
            table,
        } = self;
        let plane = samples * TILE_PIXELS;
        while blocks != 0 {
            let first = block_first_pixel(blocks.trailing_zeros() as usize);
            blocks &= blocks - 1;
            for r in 0..BLOCK_SIZE as usize {
                for s in 0..samples {
                    let at = s * TILE_PIXELS + first + r * TILE_SIZE as usize;
                    let rgba = [
                        lanes.load_f32(&color[at..]),
                        lanes.load_f32(&color[plane + at..]),
                        lanes.load_f32(&color[2 * plane + at..]),
                        lanes.load_f32(&color[3 * plane + at..]),
                    ];
                    encode_srgb8_lanes(lanes, rgba, table).store(&mut out[at..]);
                }
            }
        }
    }
}

/// One channel of eight pixels encoded to 8-bit sRGB through the table of [`srgb8_table`] (bit
/// for bit [`kantele_rules::color::unorm8`]`(`[`kantele_rules::color::linear_to_srgb`]`(c))`).
#[inline(always)]
fn encode_srgb8_channel<L: Lanes>(lanes: L, c: L::F32, table: &[u32]) -> L::I32 {
    let bits = c.to_bits();
    let index = bits.shr_arith::<16>() - lanes.splat_i32(srgb8_table::FIRST);
    let entry = index.gather_u32(table);
    let base = entry.shr_logical::<{ srgb8_table::BASE_SHIFT as i32 }>();
    let step_at = entry & lanes.splat_i32(0x1_FFFF);
    let low = bits & lanes.splat_i32(0xFFFF);
    let zero = lanes.splat_i32(0);
    let encoded = base + step_at.simd_gt(low).select_i32(zero, lanes.splat_i32(1));
    // NaN encodes to 0.
    c.simd_ne(c).select_i32(zero, encoded)
}

/// Eight pixels' linear RGBA packed as 8-bit sRGB (bit for bit
/// [`encode_rgba8`]`(…, true)` per pixel): red, green and blue through the table of
/// [`srgb8_table`], alpha rounded linearly.
#[inline(always)]
fn encode_srgb8_lanes<L: Lanes>(lanes: L, rgba: [L::F32; 4], table: &[u32]) -> L::I32 {
    let [r, g, b, a] = rgba;
    let zero = lanes.splat_f32(0.0);
    let alpha = a.simd_eq(a).select_f32(a, zero);
    let alpha = alpha.max(zero).min(lanes.splat_f32(1.0));
    let alpha = (alpha * lanes.splat_f32(255.0) + lanes.splat_f32(0.5)).to_i32_trunc();
    encode_srgb8_channel(lanes, r, table)
        | encode_srgb8_channel(lanes, g, table).shl::<8>()
        | encode_srgb8_channel(lanes, b, table).shl::<16>()
        | alpha.shl::<24>()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane encode gives [`encode_rgba8`]'s bytes on every instruction set, for values in
    /// and out of `[0, 1]`, NaN and infinities.
    #[test]
    fn lane_encode_matches_the_scalar_encode_on_every_isa() {
        struct Encode([[f32; 8]; 4]);
        impl LaneKernel for Encode {
            type Output = [i32; 8];
            #[inline(always)]
            fn run<L: Lanes>(self, lanes: L) -> [i32; 8] {
                let rgba = self.0.map(|c| lanes.f32_from_array(c));
                encode_srgb8_lanes(lanes, rgba, srgb8_encode_table()).to_array()
            }
        }
        let mut values = vec![
            0.0,
            -0.0,
            -0.5,
            1.0,
            1.0000001,
            2.0,
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e-30,
            0.003_130_8,
            0.5,
            0.999,
        ];
        let mut x = 0x1234_5678u32;
        while values.len() < 8 * 4 * 64 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            values.push(f32::from_bits(x % 0x3F90_0000));
        }
        for isa in Isa::supported() {
            for chunk in values.chunks_exact(32) {
                let rgba: [[f32; 8]; 4] =
                    std::array::from_fn(|c| std::array::from_fn(|k| chunk[c * 8 + k]));
                let got = dispatch(isa, Encode(rgba));
                for k in 0..8 {
                    let expected = encode_rgba8(std::array::from_fn(|c| rgba[c][k]), true);
                    assert_eq!(
                        (got[k] as u32).to_le_bytes(),
                        expected,
                        "{isa}: {:?}",
                        std::array::from_fn::<f32, 4, _>(|c| rgba[c][k])
                    );
                }
            }
        }
    }
}
