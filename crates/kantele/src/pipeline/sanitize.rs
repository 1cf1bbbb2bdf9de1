//! NaN colours made defined: a NaN colour channel is written as 0 (and counted), lane-wide,
//! with the same operations on every instruction set.

use crate::simd::{F32x8, Lanes, Mask8};

/// Replaces NaN channels of the lanes in `keep` by 0; returns the colour and how many channels
/// (over the lanes in `keep`) were NaN. Lanes outside `keep` are left as they are.
#[inline(always)]
pub(super) fn zero_nan_channels<L: Lanes>(
    lanes: L,
    color: [L::F32; 4],
    keep: L::Mask,
) -> ([L::F32; 4], u64) {
    // The common case first: no NaN in a kept lane leaves the colour as it is (the selects
    // below would change nothing), at one compare per channel and one mask test.
    let mut any_nan = lanes.mask_all(false);
    for channel in &color {
        let c = *channel;
        any_nan = any_nan.or(c.simd_ne(c));
    }
    if any_nan.and(keep).none() {
        return (color, 0);
    }
    let zero = lanes.splat_f32(0.0);
    let mut count = 0u64;
    let mut sanitized = color;
    // A plain loop, not `array::map`: a closure may be compiled out of line, without the
    // kernel's instruction set.
    for channel in &mut sanitized {
        let c = *channel;
        // `c != c` holds exactly on NaN lanes.
        let nan = c.simd_ne(c).and(keep);
        count += nan.count() as u64;
        *channel = nan.select_f32(zero, c);
    }
    (sanitized, count)
}
