//! NaN colours made defined: a NaN colour channel is written as 0 (and counted), lane-wide,
//! with the same operations on every instruction set.

use kantele_lanes::{F32x8, Lanes, Mask8};

/// Replaces NaN channels of the lanes in `keep` by 0; returns the colour and how many channels
/// (over the lanes in `keep`) were NaN. Lanes outside `keep` are left as they are.
#[inline(always)]
pub(super) fn zero_nan_channels<L: Lanes>(
    lanes: L,
    color: [L::F32; 4],
    keep: L::Mask,
) -> ([L::F32; 4], u64) {
    // The common case first: no NaN in a kept lane leaves the colour as it is (the selects
    // below would change nothing). A NaN channel makes the sum of the four NaN, so a sum that
    // is not NaN proves there is none, at three adds, one compare and one mask test; a NaN sum
    // without a NaN channel (∞ − ∞) only takes the exact path below.
    let sum = (color[0] + color[1]) + (color[2] + color[3]);
    if sum.simd_ne(sum).and(keep).none() {
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

#[cfg(test)]
mod tests {
    use super::*;
    use kantele_lanes::{dispatch, Isa, LaneKernel};

    struct Sanitize {
        color: [[f32; 8]; 4],
        keep: u8,
    }

    impl LaneKernel for Sanitize {
        type Output = ([[u32; 8]; 4], u64);
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Self::Output {
            let color = [
                lanes.f32_from_array(self.color[0]),
                lanes.f32_from_array(self.color[1]),
                lanes.f32_from_array(self.color[2]),
                lanes.f32_from_array(self.color[3]),
            ];
            let (out, count) = zero_nan_channels(lanes, color, lanes.mask_from_bits(self.keep));
            let bits = |c: [f32; 8]| c.map(f32::to_bits);
            (
                [
                    bits(out[0].to_array()),
                    bits(out[1].to_array()),
                    bits(out[2].to_array()),
                    bits(out[3].to_array()),
                ],
                count,
            )
        }
    }

    /// Every kept NaN channel becomes 0 and is counted, whatever else the lane holds (infinities
    /// of both signs, whose sum is NaN without a NaN channel, included); nothing else changes.
    #[test]
    fn kept_nan_channels_become_zero_and_are_counted() {
        let values = [
            0.0,
            1.0,
            -2.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            1e38,
        ];
        let mut state = 0x2545_f491u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        };
        for _ in 0..2000 {
            let color: [[f32; 8]; 4] = std::array::from_fn(|_| {
                std::array::from_fn(|_| values[next() as usize % values.len()])
            });
            let keep = next() as u8;
            let mut expected = color.map(|c| c.map(f32::to_bits));
            let mut count = 0;
            for (channel, out) in color.iter().zip(expected.iter_mut()) {
                for k in 0..8 {
                    if keep & (1 << k) != 0 && channel[k].is_nan() {
                        out[k] = 0.0f32.to_bits();
                        count += 1;
                    }
                }
            }
            for isa in Isa::supported() {
                let got = dispatch(isa, Sanitize { color, keep });
                assert_eq!(got, (expected, count), "{isa}, keep {keep:#010b}");
            }
        }
    }
}
