//! Reading texels into lanes for the lane-wide sampler ([`super::sample_lanes`]): where a
//! texture's texels are read ([`TexelSource`]), one texel or a row's two neighbouring texels per
//! lane gathered, and unpacked to one lane value per channel ([`Channels`]) in the fixed-point
//! units the sampler filters in, 1/[`LINEAR15_SCALE`](super::texel::LINEAR15_SCALE) (a linear byte `k` is `k · 128`).

use super::texture::Linear15Copy;
use kantele_lanes::{gather_texel_pair15, unpack_words15, I32x8, Lanes, TexelGather};

/// One lane value per texel channel, in units of 1/[`LINEAR15_SCALE`](super::texel::LINEAR15_SCALE) (0 to 32640).
pub(super) type Channels<L> = [<L as Lanes>::I32; 4];

/// Where the sampler reads a texture's texels, and how it unpacks them to [`Channels`].
#[derive(Clone, Copy)]
pub(super) enum TexelSource<'t> {
    /// A linear texture's packed bytes, every channel as `byte · 128`.
    LinearBytes(&'t [u32]),
    /// An sRGB texture's packed bytes: red, green and blue decoded through the table of
    /// fixed-point linear values ([`linear15_table`](super::texel::linear15_table)), alpha as
    /// `a · 128`.
    SrgbBytes(&'t [u32], &'t [u32; 256]),
    /// An sRGB texture's decoded copy ([`Linear15Copy`]): two words per texel,
    /// `[r | g << 16, b | a << 16]`, the same values as `SrgbBytes` gives, in rows one texel
    /// longer than the level's.
    Linear15(&'t Linear15Copy),
}

impl TexelSource<'_> {
    /// Gathers the texels at `index` and unpacks them.
    #[inline(always)]
    pub(super) fn fetch<L: Lanes>(self, index: L::I32) -> Channels<L> {
        match self {
            TexelSource::LinearBytes(texels) | TexelSource::SrgbBytes(texels, _) => {
                self.unpack_bytes::<L>(index.gather_u32(texels))
            }
            TexelSource::Linear15(copy) => {
                let (rg, ba) = (index + index).gather_u32_pair(&copy.words);
                unpack_words15::<L>(rg, ba)
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
            TexelSource::Linear15(copy) => gather_texel_pair15::<L>(&copy.words, index),
        }
    }

    /// Unpacks packed texels of bytes: red, green and blue through the table of an sRGB texture,
    /// or as `byte · 128` in a linear one; alpha as `a · 128`.
    #[inline(always)]
    fn unpack_bytes<L: Lanes>(self, texel: L::I32) -> Channels<L> {
        let lanes = texel.lanes();
        let a = texel.shr_logical::<24>().shl::<7>();
        match self {
            TexelSource::SrgbBytes(_, table) => {
                let [r, g, b] = texel.lookup_rgb(table);
                [r, g, b, a]
            }
            TexelSource::LinearBytes(_) | TexelSource::Linear15(_) => {
                let byte = lanes.splat_i32(0xff);
                [
                    (texel & byte).shl::<7>(),
                    (texel.shr_logical::<8>() & byte).shl::<7>(),
                    (texel.shr_logical::<16>() & byte).shl::<7>(),
                    a,
                ]
            }
        }
    }
}
