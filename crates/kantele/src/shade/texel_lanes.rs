//! Reading texels into lanes for the lane-wide sampler ([`super::sample_lanes`]): where a
//! texture's texels are read ([`TexelSource`]), one texel or a row's two neighbouring texels per
//! lane gathered, and unpacked to one lane value per channel ([`Channels`]), in the units the
//! sampler filters in: raw bytes for linear textures, 16-bit linear units for sRGB ones.

use crate::simd::{F32x8, I32x8, Lanes, TexelGather};

/// One lane value per texel channel, in the units of its [`TexelSource`] ([`TexelSource::unit`]).
pub(super) type Channels<L> = [<L as Lanes>::F32; 4];

/// Where the sampler reads a texture's texels, and how it unpacks them to [`Channels`].
#[derive(Clone, Copy)]
pub(super) enum TexelSource<'t> {
    /// A linear texture's packed bytes, every channel as its raw byte value (0–255).
    LinearBytes(&'t [u32]),
    /// An sRGB texture's packed bytes: red, green and blue decoded through the table of 16-bit
    /// linear values ([`linear16_table`](super::texel::linear16_table)), alpha as `a · 257`.
    SrgbBytes(&'t [u32], &'t [u32; 256]),
    /// An sRGB texture's decoded copy: two words per texel, `[r | g << 16, b | a << 16]`, the same
    /// values as `SrgbBytes` gives.
    Linear16(&'t [u32]),
}

impl TexelSource<'_> {
    /// The value of one unit of [`Channels`]: 1/255 for bytes, 1/65535 for 16-bit linear units.
    pub(super) fn unit(self) -> f32 {
        match self {
            TexelSource::LinearBytes(_) => 1.0 / 255.0,
            TexelSource::SrgbBytes(..) | TexelSource::Linear16(_) => 1.0 / 65535.0,
        }
    }

    /// Gathers the texels at `index` and unpacks them.
    #[inline(always)]
    pub(super) fn fetch<L: Lanes>(self, index: L::I32) -> Channels<L> {
        match self {
            TexelSource::LinearBytes(texels) | TexelSource::SrgbBytes(texels, _) => {
                self.unpack_bytes::<L>(index.gather_u32(texels))
            }
            TexelSource::Linear16(words) => {
                let (rg, ba) = (index + index).gather_u32_pair(words);
                unpack_words::<L>(rg, ba)
            }
        }
    }

    /// The texels at `index` and `index + 1` (one 8-byte read per lane and texel of bytes, one
    /// 16-byte read per lane of a decoded copy), unpacked. `index + 1` must lie in the
    /// texture's storage for live lanes.
    #[inline(always)]
    pub(super) fn fetch_pair<L: Lanes>(self, index: L::I32) -> (Channels<L>, Channels<L>) {
        match self {
            TexelSource::LinearBytes(texels) | TexelSource::SrgbBytes(texels, _) => {
                let (first, second) = index.gather_u32_pair(texels);
                (
                    self.unpack_bytes::<L>(first),
                    self.unpack_bytes::<L>(second),
                )
            }
            TexelSource::Linear16(words) => {
                let [rg0, ba0, rg1, ba1] = (index + index).gather_u32_quad(words);
                (unpack_words::<L>(rg0, ba0), unpack_words::<L>(rg1, ba1))
            }
        }
    }

    /// Unpacks packed texels of bytes: red, green and blue through the table of an sRGB texture
    /// with alpha as `a · 257`, or every channel as its raw byte value (0–255) in a linear one.
    #[inline(always)]
    fn unpack_bytes<L: Lanes>(self, texel: L::I32) -> Channels<L> {
        let lanes = texel.lanes();
        let a = texel.shr_logical::<24>().to_f32();
        match self {
            TexelSource::SrgbBytes(_, table) => {
                let [r, g, b] = texel.lookup_rgb(table);
                [
                    L::F32::from_bits(r),
                    L::F32::from_bits(g),
                    L::F32::from_bits(b),
                    a * lanes.splat_f32(257.0),
                ]
            }
            TexelSource::LinearBytes(_) | TexelSource::Linear16(_) => {
                let byte = lanes.splat_i32(0xff);
                [
                    (texel & byte).to_f32(),
                    (texel.shr_logical::<8>() & byte).to_f32(),
                    (texel.shr_logical::<16>() & byte).to_f32(),
                    a,
                ]
            }
        }
    }
}

/// Unpacks decoded texels, the words `rg = r | g << 16` and `ba = b | a << 16`, to 16-bit units.
#[inline(always)]
fn unpack_words<L: Lanes>(rg: L::I32, ba: L::I32) -> Channels<L> {
    let low = rg.lanes().splat_i32(0xffff);
    [
        (rg & low).to_f32(),
        rg.shr_logical::<16>().to_f32(),
        (ba & low).to_f32(),
        ba.shr_logical::<16>().to_f32(),
    ]
}
