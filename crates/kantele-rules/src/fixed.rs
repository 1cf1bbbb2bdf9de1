//! The fixed-point rules every backend shares: sub-pixel precision, tile and block sizes, and
//! the guard band that keeps integer edge functions from overflowing.
//!
//! Window coordinates are snapped to `1 / SUBPIXEL_ONE` of a pixel with round-half-to-even (as
//! `lrintf` in Mesa's llvmpipe). After guard-band clipping every snapped coordinate lies in
//! `[-GUARD_BAND_PIXELS, MAX_TARGET_SIZE + GUARD_BAND_PIXELS]` pixels, i.e. within ±2^15 pixels
//! = ±2^23 sub-pixel units. An edge function `a·x + b·y + c` then has |a|, |b| < 2^24 and
//! |x|, |y| < 2^23, so each product is below 2^47 and the sum below 2^49: `i64` never overflows.

/// Bits of sub-pixel precision.
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in sub-pixel units (256).
pub const SUBPIXEL_ONE: i64 = 1 << SUBPIXEL_BITS;
/// Half a pixel in sub-pixel units: pixel centres lie at `x·256 + 128`.
pub const SUBPIXEL_HALF: i64 = SUBPIXEL_ONE / 2;

/// log2 of the tile side: the frame is split into 64 × 64-pixel tiles, each rasterized by one
/// thread from its own bin of triangles.
pub const TILE_LOG2: u32 = 6;
/// Tile side in pixels (64).
pub const TILE_SIZE: u32 = 1 << TILE_LOG2;
/// Pixels in one tile (4096).
pub const TILE_PIXELS: usize = (TILE_SIZE * TILE_SIZE) as usize;

/// log2 of the block side used by the block and bisector traversals (8 × 8 pixels, as in the
/// paper); a tile is 8 × 8 blocks.
pub const BLOCK_LOG2: u32 = 3;
/// Block side in pixels (8).
pub const BLOCK_SIZE: u32 = 1 << BLOCK_LOG2;

/// How far (in pixels) outside the target a vertex may lie before the triangle is clipped
/// against the guard band.
pub const GUARD_BAND_PIXELS: f32 = 16384.0;

/// Largest magnitude of a snapped coordinate (sub-pixel units, = 65536 pixels, twice the
/// guard band's reach): a final clamp that keeps the overflow bound (now |a|, |b| < 2^25,
/// products < 2^50) even for clip intersections rounded a little past the guard band.
pub const SUBPIXEL_LIMIT: i64 = 1 << 24;

/// Snaps a window coordinate in pixels to sub-pixel units (round half to even). NaN maps to 0
/// and values beyond the guard band are clamped; callers reject those triangles earlier.
#[inline]
pub fn snap(window: f32) -> i64 {
    let scaled = round_ties_even(window * SUBPIXEL_ONE as f32);
    (scaled as i64).clamp(-SUBPIXEL_LIMIT, SUBPIXEL_LIMIT)
}

/// `x` rounded to the nearest integer, ties to even, as an integral `f32` (the value of
/// [`f32::round_ties_even`]; the sign of a zero may differ). Plain IEEE arithmetic: below 2^23
/// in magnitude, adding and subtracting 2^23 (with `x`'s sign) rounds the fraction away in the
/// default round-to-nearest-even mode; from 2^23 on every `f32` is an integer already. No
/// library call and no per-call instruction-set check, so it inlines into triangle setup.
#[inline(always)]
fn round_ties_even(x: f32) -> f32 {
    const TWO_POW_23: f32 = 8_388_608.0;
    if x.abs() < TWO_POW_23 {
        let shift = TWO_POW_23.copysign(x);
        (x + shift) - shift
    } else {
        x
    }
}

/// The sub-pixel coordinate of the centre of pixel `p`.
#[inline]
pub fn pixel_center(p: i64) -> i64 {
    p * SUBPIXEL_ONE + SUBPIXEL_HALF
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snapping_rounds_half_to_even_and_clamps() {
        assert_eq!(snap(1.0), 256);
        assert_eq!(snap(0.5 / 256.0), 0);
        assert_eq!(snap(1.5 / 256.0), 2);
        assert_eq!(snap(-3.25), -832);
        assert_eq!(snap(f32::NAN), 0);
        assert_eq!(snap(1e30), SUBPIXEL_LIMIT);
        assert_eq!(snap(-1e30), -SUBPIXEL_LIMIT);
    }

    #[test]
    fn rounding_matches_the_standard_library() {
        // Ties, near-ties and values around every power of two up to beyond 2^23, both signs.
        let mut values = vec![0.0f32, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::MAX];
        for e in -4..26 {
            let p = 2f32.powi(e);
            for x in [p, p + 0.5, p - 0.5, p + 1.5, p * 1.25, p * 1.75] {
                for v in [x, x.next_up(), x.next_down()] {
                    values.extend([v, -v]);
                }
            }
        }
        // A dense sweep of sub-pixel-scaled window coordinates.
        values.extend((-70_000..70_000).map(|i| i as f32 * 0.37));
        for x in values {
            let expected = x.round_ties_even();
            let got = round_ties_even(x);
            assert!(got == expected, "{x}: {got} vs {expected}");
            assert_eq!(snap(x / 256.0), snap_reference(x / 256.0), "{x}");
        }
        assert!(round_ties_even(f32::NAN).is_nan());
    }

    fn snap_reference(window: f32) -> i64 {
        ((window * SUBPIXEL_ONE as f32).round_ties_even() as i64)
            .clamp(-SUBPIXEL_LIMIT, SUBPIXEL_LIMIT)
    }
}
