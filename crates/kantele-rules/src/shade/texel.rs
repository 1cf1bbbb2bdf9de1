//! Packed 8-bit texels: the RGBA8 layout, the 256-entry tables that decode a stored byte to a
//! linear value, and the rounding that encodes a linear value back to 8 bits.
//!
//! A texel is one `u32` holding the bytes `[r, g, b, a]` in memory order (red in the low byte,
//! `u32::from_le_bytes`). In an sRGB texture the red, green and blue bytes are sRGB-encoded and
//! alpha is linear, as in OpenGL's `GL_SRGB8_ALPHA8`; in a linear texture all four are linear,
//! as in `GL_RGBA8`. Texels are decoded to linear *before* filtering, as a GPU's sRGB formats do.

use std::sync::OnceLock;

use glam::Vec4;

use crate::color::{encode_rgba8, srgb_to_linear};

/// How the 8-bit channels of an image are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ColorSpace {
    /// Values are linear intensities.
    Linear,
    /// RGB channels are sRGB-encoded (alpha is always linear).
    Srgb,
}

/// Packs four bytes `[r, g, b, a]` into one texel (red in the low byte).
#[inline]
pub fn pack_rgba8(rgba: [u8; 4]) -> u32 {
    u32::from_le_bytes(rgba)
}

/// The bytes `[r, g, b, a]` of a texel.
#[inline]
pub fn unpack_rgba8(texel: u32) -> [u8; 4] {
    texel.to_le_bytes()
}

/// Decodes a texel to linear RGBA: red, green and blue through [`decode_table`], alpha as
/// `a / 255`.
#[inline]
pub fn decode_texel(texel: u32, color_space: ColorSpace) -> Vec4 {
    let table = decode_table(color_space);
    let [r, g, b, a] = unpack_rgba8(texel);
    let channel = |byte: u8| f32::from_bits(table[byte as usize]);
    Vec4::new(channel(r), channel(g), channel(b), a as f32 / 255.0)
}

/// Encodes linear RGBA to a texel with round-to-nearest, clamping to [0, 1] (NaN gives 0):
/// red, green and blue sRGB-encoded in an sRGB texture, alpha always linear.
#[inline]
pub fn encode_texel(linear: Vec4, color_space: ColorSpace) -> u32 {
    pack_rgba8(encode_rgba8(
        linear.to_array(),
        color_space == ColorSpace::Srgb,
    ))
}

/// The linear value of each byte of a red, green or blue channel, as `f32` bit patterns (so the
/// lane-wide sampler can gather from it): `srgb_to_linear(k / 255)` for sRGB, `k / 255` for
/// linear. Built once per process.
pub fn decode_table(color_space: ColorSpace) -> &'static [u32; 256] {
    static SRGB: OnceLock<[u32; 256]> = OnceLock::new();
    static LINEAR: OnceLock<[u32; 256]> = OnceLock::new();
    match color_space {
        ColorSpace::Srgb => {
            SRGB.get_or_init(|| std::array::from_fn(|k| srgb_to_linear(k as f32 / 255.0).to_bits()))
        }
        ColorSpace::Linear => {
            LINEAR.get_or_init(|| std::array::from_fn(|k| unorm_to_f32(k as u8).to_bits()))
        }
    }
}

/// The fixed-point unit the lane-wide sampler filters in: a channel value `v` stands for
/// `v / LINEAR15_SCALE`. `255 · 128`, so a linear byte `k` is exactly `k · 128` units; below
/// 2^15, so two values and a 15-bit weight fit the 16-bit multiplies of the SIMD filter.
pub const LINEAR15_SCALE: u32 = 255 * 128;

/// The linear value of an sRGB byte in units of 1/[`LINEAR15_SCALE`],
/// `round(srgb_to_linear(k / 255) · 32640)`: what the lane-wide sampler filters for the red,
/// green and blue channels of sRGB textures (as integers, scaled to [0, 1] once after
/// filtering). Every byte survives the round trip through it back to 8-bit sRGB.
#[inline]
pub fn srgb_to_linear15(k: u8) -> u16 {
    (srgb_to_linear(k as f32 / 255.0) * LINEAR15_SCALE as f32).round() as u16
}

/// [`srgb_to_linear15`] of every byte, for the lane-wide sampler's gathers. Built once per
/// process.
pub fn linear15_table() -> &'static [u32; 256] {
    static TABLE: OnceLock<[u32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|k| srgb_to_linear15(k as u8) as u32))
}

/// An sRGB texel decoded to units of 1/[`LINEAR15_SCALE`], as two words
/// `[r | g << 16, b | a << 16]`: red, green and blue by [`srgb_to_linear15`], alpha (linear) as
/// `a · 128` (`a / 255` exactly).
#[inline]
pub fn srgb_texel_to_linear15(texel: u32) -> [u32; 2] {
    let table = linear15_table();
    let [r, g, b, a] = unpack_rgba8(texel);
    // The table holds `srgb_to_linear15` of every byte: read it rather than evaluate `powf` per
    // channel of every texel (a 2048² texture has 5.6 M).
    let linear = |byte: u8| table[byte as usize];
    [
        linear(r) | linear(g) << 16,
        linear(b) | (a as u32 * 128) << 16,
    ]
}

/// `k / 255`, the linear value of an 8-bit unsigned normalised byte.
#[inline]
fn unorm_to_f32(k: u8) -> f32 {
    k as f32 / 255.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::{linear_to_srgb, unorm8};

    #[test]
    fn packing_puts_red_in_the_low_byte() {
        assert_eq!(pack_rgba8([1, 2, 3, 4]), 0x0403_0201);
        assert_eq!(unpack_rgba8(0x0403_0201), [1, 2, 3, 4]);
    }

    #[test]
    fn decode_tables_are_exact() {
        let srgb = decode_table(ColorSpace::Srgb);
        let linear = decode_table(ColorSpace::Linear);
        assert_eq!(f32::from_bits(srgb[0]), 0.0);
        assert_eq!(f32::from_bits(srgb[255]), 1.0);
        assert_eq!(f32::from_bits(linear[255]), 1.0);
        for k in 0..=255u8 {
            assert_eq!(f32::from_bits(linear[k as usize]), k as f32 / 255.0);
            // Every byte survives decode then encode.
            let decoded = f32::from_bits(srgb[k as usize]);
            assert_eq!(unorm8(linear_to_srgb(decoded)), k);
        }
    }

    #[test]
    fn fifteen_bit_decoding_keeps_every_byte() {
        let table = linear15_table();
        let scale = LINEAR15_SCALE as f32;
        let mut previous = -1i64;
        for k in 0..=255u8 {
            let value = table[k as usize];
            assert_eq!(value, srgb_to_linear15(k) as u32);
            assert!(value as i64 > previous, "increasing at {k}");
            previous = value as i64;
            // Within half a unit of the exact decode, and back to the same byte.
            let exact = srgb_to_linear(k as f32 / 255.0) * scale;
            assert!(
                (value as f32 - exact).abs() <= 0.5,
                "{k}: {value} vs {exact}"
            );
            assert_eq!(unorm8(linear_to_srgb(value as f32 / scale)), k);
        }
        assert_eq!(srgb_to_linear15(255) as u32, LINEAR15_SCALE);
        let [rg, ba] = srgb_texel_to_linear15(pack_rgba8([255, 0, 188, 128]));
        assert_eq!(rg, LINEAR15_SCALE);
        assert_eq!(ba, srgb_to_linear15(188) as u32 | (128 * 128) << 16);
    }

    #[test]
    fn texels_round_trip_through_linear() {
        for texel in [0u32, 0xffff_ffff, 0x80bc_4020, 0x0102_fe7f] {
            for cs in [ColorSpace::Srgb, ColorSpace::Linear] {
                assert_eq!(
                    encode_texel(decode_texel(texel, cs), cs),
                    texel,
                    "{texel:x}"
                );
            }
        }
        // Out of range and NaN clamp.
        let t = encode_texel(Vec4::new(-1.0, 2.0, f32::NAN, 0.5), ColorSpace::Linear);
        assert_eq!(unpack_rgba8(t), [0, 255, 0, 128]);
    }
}
