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

#[cfg(test)]
mod tests {
    use super::*;

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
