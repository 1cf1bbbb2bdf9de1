//! Horizontal bands: how a picture too big for a memory budget is split into render regions
//! ([`kantele_rules::backend::Backend::set_render_region`], [`crate::pipeline::Renderer::resize_band`]).
//!
//! Bands are whole 64-row tile rows (the last one ends at the picture's bottom), so no tile is
//! drawn twice, and every band is bit-identical to the same rows of the unbanded picture: the
//! viewport, snapping and coverage are always those of the whole picture.

use std::ops::Range;

use kantele_rules::fixed::{TILE_PIXELS, TILE_SIZE};
use kantele_rules::multisample::SampleCount;

/// Bytes the CPU backend's tiles take per pixel: linear RGBA and depth, `f32` each.
pub const TARGET_BYTES_PER_PIXEL: usize = target_bytes_per_pixel(SampleCount::X1);

/// Bytes the CPU backend's `f32` tiles take per pixel at `samples` samples per pixel: linear
/// RGBA and depth, `f32` each, per sample, and a centre depth when multisampled (what
/// [`crate::rop::multisample_framebuffer_bytes`] counts for each pixel).
pub const fn target_bytes_per_pixel(samples: SampleCount) -> usize {
    let n = samples.count();
    let centre = if samples.is_multisampled() { 1 } else { 0 };
    (5 * n + centre) * std::mem::size_of::<f32>()
}

/// Bytes of one tile row (64 pixel rows) of a `width`-pixel picture when every pixel costs
/// `bytes_per_pixel` (saturating). Tiles are whole, so the width is rounded up to 64.
pub fn tile_row_bytes(width: u32, bytes_per_pixel: usize) -> usize {
    (width.div_ceil(TILE_SIZE) as usize)
        .saturating_mul(TILE_PIXELS)
        .saturating_mul(bytes_per_pixel)
}

/// Splits the rows of a `width × height` picture into bands of whole tile rows, each needing
/// at most `budget` bytes at `bytes_per_pixel`, top to bottom. A band is never less than one
/// tile row, so a budget below [`tile_row_bytes`] still gives bands of 64 rows. One band
/// (`0..height`) when the whole picture fits; none for an empty picture.
pub fn plan_bands(
    width: u32,
    height: u32,
    bytes_per_pixel: usize,
    budget: usize,
) -> Vec<Range<u32>> {
    if width == 0 || height == 0 {
        return Vec::new();
    }
    let per_tile_row = tile_row_bytes(width, bytes_per_pixel).max(1);
    let tile_rows = (budget / per_tile_row).clamp(1, u32::MAX as usize / TILE_SIZE as usize);
    let rows = tile_rows as u32 * TILE_SIZE;
    (0..height)
        .step_by(rows as usize)
        .map(|y0| y0..y0.saturating_add(rows).min(height))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_picture_within_budget_is_one_band() {
        assert_eq!(plan_bands(100, 70, 20, usize::MAX), vec![0..70]);
        assert_eq!(plan_bands(0, 70, 20, 1), Vec::<Range<u32>>::new());
    }

    #[test]
    fn bands_are_whole_tile_rows_within_budget() {
        // 130 px wide = 3 tiles; one tile row = 3 × 4096 × 20 bytes.
        let row = tile_row_bytes(130, 20);
        assert_eq!(row, 3 * 4096 * 20);
        let bands = plan_bands(130, 300, 20, 2 * row + 1);
        assert_eq!(bands, vec![0..128, 128..256, 256..300]);
        // Below one tile row: bands of one tile row.
        assert_eq!(plan_bands(130, 100, 20, 1), vec![0..64, 64..100]);
        // Every row once, in order.
        let bands = plan_bands(16384, 16384, 56, 1 << 30);
        assert_eq!(bands.first().map(|b| b.start), Some(0));
        assert_eq!(bands.last().map(|b| b.end), Some(16384));
        assert!(bands.windows(2).all(|w| w[0].end == w[1].start));
        assert!(bands.iter().all(|b| b.len() * 16384 * 56 <= 1 << 30));
    }

    /// Bands planned at a sample count's bytes per pixel keep that count's tiles within the
    /// budget (but for the one-tile-row minimum).
    #[test]
    fn multisampled_bands_keep_their_tiles_within_budget() {
        use crate::rop::multisample_framebuffer_bytes;
        for samples in [SampleCount::X1, SampleCount::X4, SampleCount::X8] {
            let per_pixel = target_bytes_per_pixel(samples);
            assert_eq!(
                per_pixel * TILE_PIXELS,
                multisample_framebuffer_bytes(TILE_SIZE, TILE_SIZE, samples)
            );
            for (width, height) in [(100, 700), (4096, 4096), (16384, 300)] {
                for budget in [1 << 20, 64 << 20, 1 << 30] {
                    for band in plan_bands(width, height, per_pixel, budget) {
                        let bytes =
                            multisample_framebuffer_bytes(width, band.len() as u32, samples);
                        assert!(
                            bytes <= budget || band.len() <= TILE_SIZE as usize,
                            "{samples}: {width}x{height} band {band:?} takes {bytes} bytes of {budget}"
                        );
                    }
                }
            }
        }
    }
}
