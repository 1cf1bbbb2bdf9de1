//! Colour encoding: the exact sRGB transfer curves and 8-bit quantisation.

/// Decodes one sRGB-encoded channel in [0, 1] to linear (IEC 61966-2-1).
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Encodes one linear channel to sRGB (IEC 61966-2-1); input is clamped to [0, 1].
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Quantises a channel in [0, 1] to 8 bits with round-to-nearest (NaN becomes 0).
#[inline]
pub fn unorm8(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    (c * 255.0 + 0.5) as u8
}

/// Converts linear RGBA to 8-bit, encoding RGB as sRGB when `srgb` is set (alpha stays linear).
#[inline]
pub fn encode_rgba8(c: [f32; 4], srgb: bool) -> [u8; 4] {
    if srgb {
        [
            unorm8(linear_to_srgb(c[0])),
            unorm8(linear_to_srgb(c[1])),
            unorm8(linear_to_srgb(c[2])),
            unorm8(c[3]),
        ]
    } else {
        [unorm8(c[0]), unorm8(c[1]), unorm8(c[2]), unorm8(c[3])]
    }
}

/// The table behind an exact 8-bit sRGB encode without `powf`: [`srgb8_encode_table`].
///
/// A linear value `c` in `[2^-13, 1]` falls in bucket `(c.to_bits() >> 16) − FIRST` — its
/// exponent and the top 7 bits of its mantissa. Each bucket spans less than one step of the
/// 8-bit sRGB curve (checked when the table is built), so within it the encoded value is the
/// bucket's first value or one more. An entry is `base << 17 | step_at`: `base` is the encoded
/// value at the bucket's start, `step_at` the low 16 bits of the first value that encodes to
/// `base + 1` (`0x10000` when none does). So
/// `encode(c) = base + (c.to_bits() & 0xFFFF >= step_at)`, bit for bit
/// `unorm8(linear_to_srgb(c))`. Values below the first bucket (zero, negatives) index below
/// 0 and those above 1 past the end: clamped to the first entry (0, no step) and the last
/// (255, no step). NaN must be tested first (it encodes to 0).
pub mod srgb8_table {
    /// The bucket of `2^-13` (exponent 114), below the first step of the curve at
    /// `0.5 / 255 / 12.92 ≈ 2^-12.7`.
    pub const FIRST: i32 = 114 << 7;
    /// Buckets up to and including that of 1.0 (exponent 127).
    pub const LEN: usize = ((127 << 7) - FIRST + 1) as usize;
    /// Bits of an entry below `base`.
    pub const BASE_SHIFT: u32 = 17;
    /// `step_at` of a bucket without a step.
    pub const NO_STEP: u32 = 0x1_0000;
}

/// The table of the exact 8-bit sRGB encode ([`srgb8_table`]), built once per process from
/// [`linear_to_srgb`] and [`unorm8`] by a binary search in each bucket.
pub fn srgb8_encode_table() -> &'static [u32] {
    static TABLE: std::sync::OnceLock<Vec<u32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let encode = |bits: u32| unorm8(linear_to_srgb(f32::from_bits(bits)));
        (0..srgb8_table::LEN as u32)
            .map(|k| {
                let start = (srgb8_table::FIRST as u32 + k) << 16;
                let base = encode(start);
                let last = encode(start | 0xFFFF);
                let step_at = if last == base {
                    srgb8_table::NO_STEP
                } else {
                    assert_eq!(last, base + 1, "an sRGB bucket spans one step at most");
                    // The first low half in 1..=0xFFFF that encodes above `base`.
                    let (mut below, mut above) = (0u32, 0xFFFFu32);
                    while above - below > 1 {
                        let mid = (below + above) / 2;
                        if encode(start | mid) > base {
                            above = mid;
                        } else {
                            below = mid;
                        }
                    }
                    above
                };
                (base as u32) << srgb8_table::BASE_SHIFT | step_at
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scalar form of the 8-bit target's lane-wide encode: [`unorm8`]`(`[`linear_to_srgb`]`(c))`
    /// through [`srgb8_encode_table`].
    fn encode_srgb8_by_table(c: f32) -> u8 {
        if c.is_nan() {
            return 0;
        }
        let bits = c.to_bits() as i32;
        let table = srgb8_encode_table();
        let index = ((bits >> 16) - srgb8_table::FIRST).clamp(0, table.len() as i32 - 1);
        let entry = table[index as usize];
        let step = (bits as u32 & 0xFFFF) >= (entry & 0x1_FFFF);
        ((entry >> srgb8_table::BASE_SHIFT) + step as u32) as u8
    }

    /// The table encode equals the `powf` one on every bucket edge, one float either side of
    /// every step, special values and a sweep over every 61st float of `[0, 2]`.
    #[test]
    fn srgb8_table_encode_is_exact() {
        let exact = |c: f32| unorm8(linear_to_srgb(c));
        let check = |c: f32| {
            assert_eq!(
                encode_srgb8_by_table(c),
                exact(c),
                "{c:e} ({:#x})",
                c.to_bits()
            )
        };
        for special in [
            0.0,
            -0.0,
            -1.0,
            1.0,
            1.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::MIN_POSITIVE,
            1e-30,
        ] {
            check(special);
        }
        let table = srgb8_encode_table();
        for (k, entry) in table.iter().enumerate() {
            let start = (srgb8_table::FIRST as u32 + k as u32) << 16;
            for bits in [start, start | 0xFFFF, start.wrapping_sub(1)] {
                check(f32::from_bits(bits));
            }
            let step_at = entry & 0x1_FFFF;
            if step_at != srgb8_table::NO_STEP {
                check(f32::from_bits(start | step_at));
                check(f32::from_bits(start | (step_at - 1)));
            }
        }
        let base = |entry: u32| entry >> srgb8_table::BASE_SHIFT;
        assert_eq!((base(table[0]), base(table[table.len() - 1])), (0, 255));
        for bits in (0..0x4000_0000u32).step_by(61 * 64) {
            check(f32::from_bits(bits));
        }
    }

    #[test]
    fn srgb_round_trips_every_8_bit_value() {
        for v in 0..=255u8 {
            let linear = srgb_to_linear(v as f32 / 255.0);
            assert_eq!(unorm8(linear_to_srgb(linear)), v);
        }
    }

    #[test]
    fn srgb_known_values() {
        assert_eq!(unorm8(linear_to_srgb(0.5)), 188);
        assert_eq!(unorm8(linear_to_srgb(0.0)), 0);
        assert_eq!(unorm8(linear_to_srgb(1.0)), 255);
        assert_eq!(unorm8(linear_to_srgb(f32::NAN)), 0);
    }
}
