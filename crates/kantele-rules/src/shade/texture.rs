//! Textures and samplers: 8-bit texel storage with a mip chain, wrap modes, nearest / bilinear /
//! trilinear filtering and the level-of-detail rule of OpenGL.
//!
//! Texels are stored as packed RGBA8 ([`texel`](super::texel)), every level of the mip chain in
//! one `Vec<u32>` with a per-level table (offset, width, height): a 4096 × 4096 texture with its
//! chain takes 89.5 MB. sRGB textures keep their sRGB-encoded bytes, as OpenGL's
//! `GL_SRGB8_ALPHA8`, and are decoded to linear through a 256-entry table *before* filtering.
//! Mip levels are built by averaging 2 × 2 texels in linear space, then re-encoded (sRGB or
//! linear) to 8 bits with round-to-nearest, unless the image brings its own complete chain
//! ([`Texture::from_rgba8_levels`], for files that store their levels). Float images ([`Texture::from_rgba_f32`]) are
//! quantised to linear 8 bits.
//!
//! Two samplers read that storage: the scalar [`Texture::sample_grad`] / [`Texture::sample_lod`]
//! (for user shaders, one pixel at a time) and the lane-wide [`Texture::sample_grad_lanes`]
//! (eight pixels at a time, used by the built-in materials). They apply the same rules; their
//! results may differ by about 1e-4 (the lane sampler computes `log2` with a polynomial and
//! filters in fixed point, channels in units of 1/32640 and weights in units of 1/32768, and
//! scales to [0, 1] after filtering). The lane sampler keeps a small sRGB texture's texels
//! decoded to those units (8 bytes a texel, built once: [`Texture::prepare_lane_sampling`]), so it
//! reads them without a table lookup per channel; larger ones (level 0 over 2048 × 2048) keep to
//! 4 bytes a texel and the table.

use std::sync::OnceLock;

use glam::{Vec2, Vec4};

use super::levels::{lane_table, LaneTable, LevelTable};
pub use super::texel::ColorSpace;
use super::texel::{
    decode_table, decode_texel, encode_texel, pack_rgba8, srgb_texel_to_linear15, unpack_rgba8,
};
use crate::error::RenderError;
pub use crate::state::MAX_TEXTURE_SIZE;

/// Largest level 0 (texels) of an sRGB texture whose texels the lane-wide sampler keeps decoded
/// to 15-bit linear units ([`Texture::prepare_lane_sampling`]): 2048 × 2048, a copy of at most
/// 45 MB.
const LINEAR15_MAX_TEXELS: usize = 2048 * 2048;

/// One level of a mip chain: a view into the texture's storage.
#[derive(Clone, Copy, Debug)]
pub struct MipLevel<'a> {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major packed RGBA8 texels ([`pack_rgba8`]), row 0 first (the top row of the source
    /// image), encoded in the texture's [`ColorSpace`].
    pub texels: &'a [u32],
    /// The encoding of the red, green and blue bytes.
    pub color_space: ColorSpace,
}

impl MipLevel<'_> {
    /// The texel at column `x`, row `y`, decoded to linear RGBA. Panics outside the level.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec4 {
        decode_texel(self.packed(x, y), self.color_space)
    }

    /// The packed texel at column `x`, row `y`. Panics outside the level.
    #[inline]
    pub fn packed(&self, x: u32, y: u32) -> u32 {
        self.texels[y as usize * self.width as usize + x as usize]
    }
}

/// A 2D texture with its complete mip chain, stored as packed RGBA8.
#[derive(Clone)]
pub struct Texture {
    /// Every level's texels, level 0 first, each row-major.
    pub(super) texels: Vec<u32>,
    pub(super) levels: LevelTable,
    pub(super) color_space: ColorSpace,
    /// An sRGB texture's texels decoded to 15-bit linear units ([`Linear15Copy`]): built on first
    /// use by the lane-wide sampler, for textures up to [`LINEAR15_MAX_TEXELS`] (see
    /// [`Texture::linear15`]).
    linear15: OnceLock<Linear15Copy>,
}

/// An sRGB texture's texels decoded for the lane-wide sampler: 16 bits per channel, two words
/// per texel (`[r | g << 16, b | a << 16]`, [`srgb_texel_to_linear15`]), level by level and row
/// by row as in the texel storage, but every row one texel longer: its last texel repeats the
/// row's first. A bilinear footprint whose right column wraps around to column 0 (REPEAT) then
/// still finds its row's two texels side by side in memory, one read per lane like every other
/// footprint. Row `y` of level `l` starts at texel `offsets[l] + y · (width_l + 1)`.
#[derive(Clone, Debug)]
pub(super) struct Linear15Copy {
    /// The decoded texels, two words each.
    pub(super) words: Vec<u32>,
    /// Index (in texels, half the word index) of each level's first texel, level 0 first.
    pub(super) offsets: Vec<u32>,
    /// The offsets as a [`LaneTable`].
    pub(super) lane_offsets: LaneTable,
}

impl Linear15Copy {
    /// The copy of `texture`'s mip chain.
    fn new(texture: &Texture) -> Self {
        let padded: usize = (texture.levels())
            .map(|l| (l.width as usize + 1) * l.height as usize)
            .sum();
        let mut words = Vec::with_capacity(2 * padded);
        let mut offsets = Vec::with_capacity(texture.level_count());
        for level in texture.levels() {
            // At most (16384 + 1) · 16384 · 4/3 texels: fits u32 (and i32, for the lane table).
            offsets.push((words.len() / 2) as u32);
            for row in level.texels.chunks_exact(level.width as usize) {
                for &texel in row.iter().chain(&row[..1]) {
                    words.extend(srgb_texel_to_linear15(texel));
                }
            }
        }
        debug_assert_eq!(words.len(), 2 * padded);
        let lane_offsets = lane_table(&offsets);
        Self {
            words,
            offsets,
            lane_offsets,
        }
    }
}

impl std::fmt::Debug for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Texture")
            .field("width", &self.width())
            .field("height", &self.height())
            .field("levels", &self.level_count())
            .field("color_space", &self.color_space)
            .finish_non_exhaustive()
    }
}

impl Texture {
    /// Creates a texture from 8-bit RGBA texels (row 0 = top row) encoded in `color_space`, kept
    /// as they are, and builds the full mip chain.
    pub fn from_rgba8(
        width: u32,
        height: u32,
        rgba: &[u8],
        color_space: ColorSpace,
    ) -> Result<Self, RenderError> {
        check_texture_size(width, height)?;
        let expected = width as usize * height as usize * 4;
        if rgba.len() != expected {
            return Err(RenderError::InvalidTextureData {
                expected,
                actual: rgba.len(),
            });
        }
        let level0 = rgba
            .chunks_exact(4)
            .map(|p| pack_rgba8([p[0], p[1], p[2], p[3]]))
            .collect();
        Ok(Self::from_level0(width, height, level0, color_space))
    }

    /// Creates a linear texture from float RGBA texels (row 0 = top row) and builds the mip chain.
    ///
    /// The texels are **quantised** to linear 8 bits per channel (clamped to [0, 1], rounded to
    /// the nearest of `k / 255`, NaN becomes 0), as an upload to `GL_RGBA8` would.
    pub fn from_rgba_f32(width: u32, height: u32, texels: Vec<Vec4>) -> Result<Self, RenderError> {
        check_texture_size(width, height)?;
        let expected = width as usize * height as usize;
        if texels.len() != expected {
            return Err(RenderError::InvalidTextureData {
                expected,
                actual: texels.len(),
            });
        }
        let level0 = texels
            .iter()
            .map(|&t| encode_texel(t, ColorSpace::Linear))
            .collect();
        Ok(Self::from_level0(width, height, level0, ColorSpace::Linear))
    }

    /// Creates a texture from its complete mip chain of 8-bit RGBA levels (each row-major, row 0
    /// = top row), encoded in `color_space` and kept as they are: for images whose file holds
    /// its own smaller levels (KTX2, DDS), where [`Texture::from_rgba8`] would build them from
    /// level 0 instead.
    ///
    /// `levels[0]` is `width` × `height` texels and level `i` is `max(1, width >> i)` ×
    /// `max(1, height >> i)`, down to 1 × 1: the chain [`Texture::levels`] gives, one level per
    /// entry, 4 bytes per texel. A level size outside `1..=MAX_TEXTURE_SIZE`, a chain with
    /// another number of levels or a level with another byte length is an error
    /// ([`RenderError::InvalidTextureSize`], [`RenderError::InvalidMipChain`]), and no texture
    /// is made.
    pub fn from_rgba8_levels(
        width: u32,
        height: u32,
        levels: &[&[u8]],
        color_space: ColorSpace,
    ) -> Result<Self, RenderError> {
        check_texture_size(width, height)?;
        let sizes = chain_sizes(width, height);
        if levels.len() != sizes.len() {
            return Err(RenderError::InvalidMipChain(format!(
                "a {width}x{height} texture has {} levels, {} given",
                sizes.len(),
                levels.len()
            )));
        }
        for (index, (level, &(w, h))) in levels.iter().zip(&sizes).enumerate() {
            let expected = w as usize * h as usize * 4;
            if level.len() != expected {
                return Err(RenderError::InvalidMipChain(format!(
                    "level {index} ({w}x{h}) holds {} bytes, expected {expected}",
                    level.len()
                )));
            }
        }
        let total: usize = sizes.iter().map(|&(w, h)| w as usize * h as usize).sum();
        let mut texels = Vec::with_capacity(total);
        for level in levels {
            texels.extend(
                level
                    .chunks_exact(4)
                    .map(|p| pack_rgba8([p[0], p[1], p[2], p[3]])),
            );
        }
        debug_assert_eq!(texels.len(), total);
        Ok(Self {
            texels,
            levels: LevelTable::new(&sizes),
            color_space,
            linear15: OnceLock::new(),
        })
    }

    fn from_level0(width: u32, height: u32, level0: Vec<u32>, color_space: ColorSpace) -> Self {
        let sizes = chain_sizes(width, height);
        let total: usize = sizes.iter().map(|&(w, h)| w as usize * h as usize).sum();
        let levels = LevelTable::new(&sizes);
        let mut texels = level0;
        texels.reserve_exact(total - texels.len());
        // Each level from the one before it, the last one excepted.
        for (&previous, &size) in levels.offsets.iter().zip(&sizes).take(sizes.len() - 1) {
            downsample(&mut texels, previous as usize, size, color_space);
        }
        debug_assert_eq!(texels.len(), total);
        Self {
            texels,
            levels,
            color_space,
            linear15: OnceLock::new(),
        }
    }

    /// Decodes an sRGB texture's texels for the lane-wide sampler now rather than on its first
    /// use ([`Texture::sample_grad_lanes`] reads them, when the texture is small enough, instead
    /// of decoding each texel through a table; the results are the same). Backends that sample
    /// lane-wide call it when a scene is loaded, so that no frame pays for it.
    pub fn prepare_lane_sampling(&self) {
        let _ = self.linear15();
    }

    /// The texels decoded to 15-bit linear units (two words per texel, [`srgb_texel_to_linear15`]) for an
    /// sRGB texture whose level 0 holds at most [`LINEAR15_MAX_TEXELS`] texels, built on first
    /// use; `None` for linear and larger textures.
    pub(super) fn linear15(&self) -> Option<&Linear15Copy> {
        let small = self.width() as usize * self.height() as usize <= LINEAR15_MAX_TEXELS;
        if self.color_space != ColorSpace::Srgb || !small {
            return None;
        }
        Some(self.linear15.get_or_init(|| Linear15Copy::new(self)))
    }

    /// Width of level 0 in texels.
    #[inline]
    pub fn width(&self) -> u32 {
        self.levels.widths[0]
    }

    /// Height of level 0 in texels.
    #[inline]
    pub fn height(&self) -> u32 {
        self.levels.heights[0]
    }

    /// How many levels the mip chain has (level 0 down to 1 × 1).
    #[inline]
    pub fn level_count(&self) -> usize {
        self.levels.offsets.len()
    }

    /// Level `index` of the mip chain, `None` past the last.
    #[inline]
    pub fn level(&self, index: usize) -> Option<MipLevel<'_>> {
        let offset = *self.levels.offsets.get(index)? as usize;
        let (width, height) = (self.levels.widths[index], self.levels.heights[index]);
        Some(MipLevel {
            width,
            height,
            texels: &self.texels[offset..offset + width as usize * height as usize],
            color_space: self.color_space,
        })
    }

    /// The mip chain, level 0 first, down to 1 × 1.
    pub fn levels(&self) -> impl ExactSizeIterator<Item = MipLevel<'_>> + '_ {
        (0..self.level_count()).map(|i| self.level(i).expect("index below level_count"))
    }

    /// The encoding of the stored red, green and blue bytes (the 8-bit data the texture was made
    /// from; [`ColorSpace::Linear`] for float images).
    #[inline]
    pub fn source_color_space(&self) -> ColorSpace {
        self.color_space
    }

    /// Bytes of memory the texture holds: the texels of every level, the level table and, once
    /// built, the lane-wide sampler's decoded copy ([`Texture::prepare_lane_sampling`]).
    pub fn memory_bytes(&self) -> usize {
        let decoded = self
            .linear15
            .get()
            .map_or(0, |copy| copy.words.capacity() + copy.offsets.capacity());
        std::mem::size_of::<Self>()
            + (self.texels.capacity() + decoded) * std::mem::size_of::<u32>()
            + 3 * self.levels.offsets.capacity() * std::mem::size_of::<u32>()
    }

    /// Samples at `uv` with the level of detail computed from the screen-space derivatives of
    /// `uv` (per pixel, in texture-coordinate units), as OpenGL does.
    pub fn sample_grad(&self, sampler: &Sampler, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec4 {
        let lod = self.lod(duv_dx, duv_dy);
        self.sample_lod(sampler, uv, lod)
    }

    /// Level of detail λ = log2 ρ, with ρ the larger screen-space footprint of one pixel in
    /// level-0 texels (OpenGL 4.6 §8.14, equation 8.6 without the optional approximations).
    pub fn lod(&self, duv_dx: Vec2, duv_dy: Vec2) -> f32 {
        let size = Vec2::new(self.width() as f32, self.height() as f32);
        // log2 ρ = ½ log2 ρ²: one logarithm, no square roots.
        let rho2 = (duv_dx * size)
            .length_squared()
            .max((duv_dy * size).length_squared());
        if rho2.is_finite() && rho2 > 0.0 {
            0.5 * rho2.log2()
        } else if rho2 == 0.0 {
            f32::NEG_INFINITY
        } else {
            // Non-finite derivatives (degenerate mapping): use the smallest level.
            self.max_level() as f32
        }
    }

    /// Index of the last (1 × 1) level.
    #[inline]
    pub(super) fn max_level(&self) -> usize {
        self.level_count() - 1
    }

    #[inline]
    fn level_unchecked(&self, index: usize) -> MipLevel<'_> {
        self.level(index.min(self.max_level()))
            .expect("index clamped to the chain")
    }

    /// Samples at `uv` with an explicit level of detail (OpenGL 4.6 §8.14–8.15).
    pub fn sample_lod(&self, sampler: &Sampler, uv: Vec2, lod: f32) -> Vec4 {
        #[cfg(feature = "fault-injection")]
        let uv = if crate::fault::active(crate::fault::Fault::FlipV) {
            Vec2::new(uv.x, 1.0 - uv.y)
        } else {
            uv
        };
        if !(uv.x.is_finite() && uv.y.is_finite()) {
            return Vec4::ZERO;
        }
        // The magnification / minification switch point c is 0 (mag filter LINEAR or min filter
        // not NEAREST_MIPMAP_LINEAR / LINEAR_MIPMAP_NEAREST gives c = 0 in the spec).
        let level = |i: usize| self.level_unchecked(i);
        if lod <= 0.0 || lod.is_nan() {
            return sample_level(&level(0), sampler, sampler.mag_filter, uv);
        }
        let max_level = self.max_level() as f32;
        match sampler.min_filter {
            MinFilter::Nearest => sample_level(&level(0), sampler, Filter::Nearest, uv),
            MinFilter::Linear => sample_level(&level(0), sampler, Filter::Linear, uv),
            MinFilter::NearestMipmapNearest | MinFilter::LinearMipmapNearest => {
                let filter = sampler.min_filter.texel_filter();
                // d = ceil(λ + 1/2) − 1, clamped to the chain.
                let d = if lod <= 0.5 {
                    0.0
                } else {
                    (-floor(-(lod + 0.5)) - 1.0).min(max_level)
                };
                sample_level(&level(d as usize), sampler, filter, uv)
            }
            MinFilter::NearestMipmapLinear | MinFilter::LinearMipmapLinear => {
                let filter = sampler.min_filter.texel_filter();
                if lod >= max_level {
                    return sample_level(&level(max_level as usize), sampler, filter, uv);
                }
                let lower = floor(lod);
                let frac = lod - lower;
                let a = sample_level(&level(lower as usize), sampler, filter, uv);
                let b = sample_level(&level(lower as usize + 1), sampler, filter, uv);
                a * (1.0 - frac) + b * frac
            }
        }
    }
}

/// The sizes of a complete mip chain whose level 0 is `width` × `height`: each level half the
/// one before (rounded down, at least 1), down to 1 × 1.
fn chain_sizes(width: u32, height: u32) -> Vec<(u32, u32)> {
    let mut sizes = vec![(width, height)];
    while let Some(&(w, h)) = sizes.last().filter(|&&(w, h)| w > 1 || h > 1) {
        sizes.push(((w / 2).max(1), (h / 2).max(1)));
    }
    sizes
}

fn check_texture_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
        return Err(RenderError::InvalidTextureSize { width, height });
    }
    Ok(())
}

/// Appends the level below the one at `texels[previous..]` of size `(width, height)`: each
/// texel is the mean of the (up to) 2 × 2 texels it covers, averaged in linear space (clamping at
/// odd edges) and re-encoded to 8 bits with round-to-nearest.
fn downsample(
    texels: &mut Vec<u32>,
    previous: usize,
    (width, height): (u32, u32),
    color_space: ColorSpace,
) {
    let (w, h) = ((width / 2).max(1), (height / 2).max(1));
    let table = decode_table(color_space);
    let decode = |texel: u32| {
        let [r, g, b, a] = unpack_rgba8(texel);
        let channel = |byte: u8| f32::from_bits(table[byte as usize]);
        Vec4::new(channel(r), channel(g), channel(b), a as f32 / 255.0)
    };
    let mut row = Vec::with_capacity(w as usize);
    for y in 0..h {
        let y0 = (2 * y).min(height - 1) as usize;
        let y1 = (2 * y + 1).min(height - 1) as usize;
        let above = &texels[previous + y0 * width as usize..][..width as usize];
        let below = &texels[previous + y1 * width as usize..][..width as usize];
        row.clear();
        for x in 0..w {
            let x0 = (2 * x).min(width - 1) as usize;
            let x1 = (2 * x + 1).min(width - 1) as usize;
            let sum = decode(above[x0]) + decode(above[x1]) + decode(below[x0]) + decode(below[x1]);
            row.push(encode_texel(sum * 0.25, color_space));
        }
        texels.extend_from_slice(&row);
    }
}

/// Texel filter within one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    /// The texel containing the sample point.
    Nearest,
    /// Bilinear blend of the four nearest texel centres.
    #[default]
    Linear,
}

/// Minification filter, as glTF and OpenGL name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MinFilter {
    /// Nearest texel of level 0.
    Nearest,
    /// Bilinear in level 0.
    Linear,
    /// Nearest texel of the nearest level.
    NearestMipmapNearest,
    /// Bilinear in the nearest level.
    LinearMipmapNearest,
    /// Nearest texel in the two nearest levels, blended.
    NearestMipmapLinear,
    /// Bilinear in the two nearest levels, blended (trilinear).
    #[default]
    LinearMipmapLinear,
}

impl MinFilter {
    pub(super) fn texel_filter(self) -> Filter {
        match self {
            MinFilter::Nearest
            | MinFilter::NearestMipmapNearest
            | MinFilter::NearestMipmapLinear => Filter::Nearest,
            _ => Filter::Linear,
        }
    }

    /// Whether this filter reads levels other than level 0.
    #[inline]
    pub fn uses_mipmaps(self) -> bool {
        !matches!(self, MinFilter::Nearest | MinFilter::Linear)
    }
}

/// What happens to texture coordinates outside [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// The texture tiles.
    #[default]
    Repeat,
    /// Coordinates are clamped to the edge texels.
    ClampToEdge,
    /// The texture tiles, every other copy mirrored.
    MirroredRepeat,
}

impl Wrap {
    /// Maps an integer texel coordinate into `0..size` (OpenGL 4.6 §8.14.2, table 8.20).
    #[inline]
    fn apply(self, i: i32, size: i32) -> i32 {
        // Inside the texture every mode is the identity (the common case, no division).
        if (i as u32) < size as u32 {
            return i;
        }
        match self {
            Wrap::Repeat => i.rem_euclid(size),
            Wrap::ClampToEdge => i.clamp(0, size - 1),
            Wrap::MirroredRepeat => {
                let period = i.rem_euclid(2 * size);
                if period < size {
                    period
                } else {
                    2 * size - 1 - period
                }
            }
        }
    }
}

impl Wrap {
    /// The coordinate `t` in texels of a level `size` texels wide, moved into the first period
    /// of a repeating mode ([0, size] for REPEAT, [0, 2·size] for MIRRORED_REPEAT) so texel
    /// indices stay small and mostly inside the texture. CLAMP_TO_EDGE is limited to
    /// [−2, size + 2], which changes no texel or weight that is read and keeps huge coordinates
    /// finite.
    #[inline]
    fn to_texels(self, t: f32, size: f32) -> f32 {
        match self {
            Wrap::Repeat => (t - floor(t)) * size,
            Wrap::MirroredRepeat => (t - 2.0 * floor(t * 0.5)) * size,
            Wrap::ClampToEdge => (t * size).clamp(-2.0, size + 2.0),
        }
    }
}

/// How a texture is read: wrap modes and filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sampler {
    /// Wrap mode along u (s).
    pub wrap_s: Wrap,
    /// Wrap mode along v (t).
    pub wrap_t: Wrap,
    /// Filter when a texel covers more than a pixel.
    pub mag_filter: Filter,
    /// Filter when a pixel covers more than a texel.
    pub min_filter: MinFilter,
}

/// Samples one level with one filter. `uv` (0, 0) is the top-left corner of the image (the first
/// texel in memory), as in glTF.
fn sample_level(level: &MipLevel<'_>, sampler: &Sampler, filter: Filter, uv: Vec2) -> Vec4 {
    let w = level.width as i32;
    let h = level.height as i32;
    let u = sampler.wrap_s.to_texels(uv.x, w as f32);
    let v = sampler.wrap_t.to_texels(uv.y, h as f32);
    match filter {
        Filter::Nearest => {
            let i = sampler.wrap_s.apply(floor_to_i32(u), w);
            let j = sampler.wrap_t.apply(floor_to_i32(v), h);
            level.texel(i as u32, j as u32)
        }
        Filter::Linear => {
            let us = u - 0.5;
            let vs = v - 0.5;
            let i0f = floor(us);
            let j0f = floor(vs);
            // NaN or infinite coordinates (uv × size overflowing) make the fraction NaN: take
            // the first texel of the pair instead, as NEAREST does (robust branch).
            let alpha = defined_fraction(us - i0f);
            let beta = defined_fraction(vs - j0f);
            let i0 = floor_to_i32(i0f);
            let j0 = floor_to_i32(j0f);
            let x0 = sampler.wrap_s.apply(i0, w) as u32;
            let x1 = sampler.wrap_s.apply(i0.wrapping_add(1), w) as u32;
            let y0 = sampler.wrap_t.apply(j0, h) as u32;
            let y1 = sampler.wrap_t.apply(j0.wrapping_add(1), h) as u32;
            let top = level.texel(x0, y0) * (1.0 - alpha) + level.texel(x1, y0) * alpha;
            let bottom = level.texel(x0, y1) * (1.0 - alpha) + level.texel(x1, y1) * alpha;
            top * (1.0 - beta) + bottom * beta
        }
    }
}

/// A bilinear weight in [0, 1], or 0 when it is not (NaN from NaN or infinite coordinates).
#[inline]
fn defined_fraction(f: f32) -> f32 {
    if (0.0..=1.0).contains(&f) {
        f
    } else {
        0.0
    }
}

/// `floor` to an integer, saturating far outside the `i32` range (coordinates that large wrap
/// meaninglessly anyway; this keeps them defined).
#[inline]
fn floor_to_i32(x: f32) -> i32 {
    // `as` truncates towards zero, saturates out of range and maps NaN to 0.
    let i = x as i32;
    if (i as f32) > x {
        i.saturating_sub(1)
    } else {
        i
    }
}

/// Exact `floor` without a libm call (the x86-64 baseline has no rounding instruction):
/// values of magnitude 2^23 or more are already integers.
#[inline]
fn floor(x: f32) -> f32 {
    if x.abs() < 8_388_608.0 {
        floor_to_i32(x) as f32
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_floor_is_exact() {
        for x in [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            2.999_999_8,
            -2.999_999_8,
            8_388_607.5,
            -8_388_607.5,
            1e10,
            -1e10,
            3e38,
        ] {
            assert_eq!(floor(x), x.floor(), "{x}");
        }
        assert_eq!(floor_to_i32(-0.25), -1);
        assert_eq!(floor_to_i32(f32::NAN), 0);
        assert_eq!(floor_to_i32(1e20), i32::MAX);
        assert_eq!(floor_to_i32(-1e20), i32::MIN);
    }

    /// A 4 × 1 linear texture with red 0, 1/3, 2/3, 1 (bytes 0, 85, 170, 255).
    fn ramp() -> Texture {
        let rgba = [0u8, 85, 170, 255].map(|r| [r, 0, 0, 255]).concat();
        Texture::from_rgba8(4, 1, &rgba, ColorSpace::Linear).expect("texture")
    }

    fn sampler(wrap: Wrap, filter: Filter) -> Sampler {
        Sampler {
            wrap_s: wrap,
            wrap_t: wrap,
            mag_filter: filter,
            min_filter: MinFilter::Nearest,
        }
    }

    #[test]
    fn nearest_with_each_wrap_mode() {
        let t = ramp();
        let red = |wrap, u: f32| {
            let r = t
                .sample_lod(&sampler(wrap, Filter::Nearest), Vec2::new(u, 0.5), 0.0)
                .x;
            (r * 3.0).round()
        };
        // Texel i covers u in [i/4, (i+1)/4).
        assert_eq!(red(Wrap::Repeat, 0.1), 0.0);
        assert_eq!(red(Wrap::Repeat, 0.9), 3.0);
        assert_eq!(red(Wrap::Repeat, 1.1), 0.0);
        assert_eq!(red(Wrap::Repeat, -0.1), 3.0);
        assert_eq!(red(Wrap::ClampToEdge, 1.7), 3.0);
        assert_eq!(red(Wrap::ClampToEdge, -5.0), 0.0);
        // Mirrored: [1, 2) runs backwards.
        assert_eq!(red(Wrap::MirroredRepeat, 1.1), 3.0);
        assert_eq!(red(Wrap::MirroredRepeat, 1.9), 0.0);
        assert_eq!(red(Wrap::MirroredRepeat, -0.1), 0.0);
        assert_eq!(red(Wrap::MirroredRepeat, 2.1), 0.0);
    }

    #[test]
    fn bilinear_blends_texel_centres() {
        let t = ramp();
        let red = |wrap, u: f32| {
            3.0 * t
                .sample_lod(&sampler(wrap, Filter::Linear), Vec2::new(u, 0.5), 0.0)
                .x
        };
        // Centres at u = (i + 0.5) / 4: exact values there, linear in between.
        assert!((red(Wrap::Repeat, 0.375) - 1.0).abs() < 1e-6);
        assert!((red(Wrap::Repeat, 0.5) - 1.5).abs() < 1e-6);
        // Beyond the last centre, REPEAT blends with texel 0, CLAMP holds texel 3.
        assert!((red(Wrap::Repeat, 1.0) - 1.5).abs() < 1e-6);
        assert!((red(Wrap::ClampToEdge, 1.0) - 3.0).abs() < 1e-6);
        assert!((red(Wrap::MirroredRepeat, 1.0) - 3.0).abs() < 1e-6);
    }

    #[test]
    fn mip_chain_averages_in_linear_space() {
        // sRGB 188 ≈ linear 0.5; a 2 × 2 of black and sRGB-white averages to linear 0.5, stored
        // as the sRGB byte 188.
        let rgba = [
            0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255, 255, 0, 0, 0, 255,
        ];
        let t = Texture::from_rgba8(2, 2, &rgba, ColorSpace::Srgb).expect("texture");
        assert_eq!(t.levels().len(), 2);
        let top = t.level(1).expect("level 1");
        assert_eq!(unpack_rgba8(top.texels[0]), [188, 188, 188, 255]);
        assert!(
            (top.texel(0, 0).x - 0.5).abs() < 4e-3,
            "{:?}",
            top.texel(0, 0)
        );
        // Linear textures average the values: (0 + 255 + 255 + 0) / 4 = 127.5 rounds to 128.
        let t = Texture::from_rgba8(2, 2, &rgba, ColorSpace::Linear).expect("texture");
        assert_eq!(
            unpack_rgba8(t.level(1).expect("level 1").texels[0]),
            [128, 128, 128, 255]
        );
        // Non-square and odd sizes go down to 1 × 1.
        let odd = Texture::from_rgba_f32(5, 3, vec![Vec4::ONE; 15]).expect("texture");
        let sizes: Vec<(u32, u32)> = odd.levels().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, vec![(5, 3), (2, 1), (1, 1)]);
        assert_eq!(odd.level(2).expect("level 2").texel(0, 0), Vec4::ONE);
        assert!(odd.level(3).is_none());
    }

    /// A `width` × `height` level of RGBA8 texels all `[value, 0, 0, 255]`.
    fn flat_level(width: u32, height: u32, value: u8) -> Vec<u8> {
        [value, 0, 0, 255].repeat(width as usize * height as usize)
    }

    #[test]
    fn a_given_mip_chain_is_kept_as_it_is() {
        // 4 × 2, 2 × 1, 1 × 1, each level a colour no average of the one above gives.
        let levels = [
            flat_level(4, 2, 10),
            flat_level(2, 1, 200),
            flat_level(1, 1, 77),
        ];
        let slices: Vec<&[u8]> = levels.iter().map(Vec::as_slice).collect();
        for color_space in [ColorSpace::Srgb, ColorSpace::Linear] {
            let t = Texture::from_rgba8_levels(4, 2, &slices, color_space).expect("texture");
            assert_eq!((t.width(), t.height(), t.level_count()), (4, 2, 3));
            assert_eq!(t.source_color_space(), color_space);
            let sizes: Vec<(u32, u32)> = t.levels().map(|l| (l.width, l.height)).collect();
            assert_eq!(sizes, vec![(4, 2), (2, 1), (1, 1)]);
            for (level, red) in t.levels().zip([10, 200, 77]) {
                assert!(level
                    .texels
                    .iter()
                    .all(|&p| unpack_rgba8(p) == [red, 0, 0, 255]));
            }
            // The lane-wide sampler's copy is built from the given levels as from built ones.
            t.prepare_lane_sampling();
            let nearest = Sampler {
                min_filter: MinFilter::NearestMipmapNearest,
                mag_filter: Filter::Nearest,
                ..Sampler::default()
            };
            let red = t.sample_lod(&nearest, Vec2::splat(0.5), 1.0).x;
            let expected = level_red(&t, 1);
            assert!((red - expected).abs() < 1e-6, "{red} vs {expected}");
        }
        // A single texel is a complete chain of one level.
        let one = Texture::from_rgba8_levels(1, 1, &[&[1, 2, 3, 4]], ColorSpace::Linear)
            .expect("texture");
        assert_eq!(one.level_count(), 1);
        assert_eq!(
            unpack_rgba8(one.level(0).expect("level 0").texels[0]),
            [1, 2, 3, 4]
        );
    }

    /// Red of level `index`'s first texel, decoded.
    fn level_red(t: &Texture, index: usize) -> f32 {
        t.level(index).expect("level").texel(0, 0).x
    }

    #[test]
    fn an_incomplete_or_wrongly_sized_chain_is_refused() {
        let (l0, l1, l2) = (
            flat_level(4, 2, 1),
            flat_level(2, 1, 2),
            flat_level(1, 1, 3),
        );
        let cases: [(&[&[u8]], &str); 5] = [
            (&[&l0, &l1], "has 3 levels, 2 given"),
            (&[&l0, &l1, &l2, &l2], "has 3 levels, 4 given"),
            (&[], "has 3 levels, 0 given"),
            (&[&l0, &l0, &l2], "level 1 (2x1) holds 32 bytes, expected 8"),
            (
                &[&l0, &l1, &l2[..3]],
                "level 2 (1x1) holds 3 bytes, expected 4",
            ),
        ];
        for (levels, message) in cases {
            match Texture::from_rgba8_levels(4, 2, levels, ColorSpace::Srgb) {
                Err(RenderError::InvalidMipChain(m)) => assert!(m.contains(message), "{m}"),
                other => panic!("{message}: {other:?}"),
            }
        }
        // Level 0 itself of the wrong length, and sizes outside the limit.
        match Texture::from_rgba8_levels(4, 1, &[&l0, &l1, &l2], ColorSpace::Srgb) {
            Err(RenderError::InvalidMipChain(m)) => {
                assert!(
                    m.contains("level 0 (4x1) holds 32 bytes, expected 16"),
                    "{m}"
                )
            }
            other => panic!("level 0 of the wrong length: {other:?}"),
        }
        assert!(matches!(
            Texture::from_rgba8_levels(0, 4, &[], ColorSpace::Srgb),
            Err(RenderError::InvalidTextureSize { .. })
        ));
        assert!(matches!(
            Texture::from_rgba8_levels(MAX_TEXTURE_SIZE + 1, 1, &[], ColorSpace::Srgb),
            Err(RenderError::InvalidTextureSize { .. })
        ));
    }

    #[test]
    fn float_images_are_quantised_to_8_bits() {
        let t = Texture::from_rgba_f32(
            2,
            1,
            vec![
                Vec4::new(0.5, -1.0, 2.0, f32::NAN),
                Vec4::new(0.2, 0.4, 0.6, 0.8),
            ],
        )
        .expect("texture");
        let level = t.level(0).expect("level 0");
        assert_eq!(unpack_rgba8(level.texels[0]), [128, 0, 255, 0]);
        assert_eq!(unpack_rgba8(level.texels[1]), [51, 102, 153, 204]);
        assert_eq!(level.texel(1, 0), Vec4::new(0.2, 0.4, 0.6, 0.8));
    }

    #[test]
    fn a_4096_texture_with_mips_fits_in_96_mb() {
        let size = 4096u32;
        let rgba = vec![200u8; (size * size * 4) as usize];
        // sRGB, prepared for the lane-wide sampler: too large for a decoded copy.
        let t = Texture::from_rgba8(size, size, &rgba, ColorSpace::Srgb).expect("texture");
        t.prepare_lane_sampling();
        assert_eq!(t.level_count(), 13);
        let texels: usize = t.levels().map(|l| l.texels.len()).sum();
        assert_eq!(texels, 22_369_621); // (4^13 − 1) / 3
        let bytes = t.memory_bytes();
        assert!(bytes >= texels * 4, "{bytes}");
        assert!(bytes <= 96_000_000, "{bytes} bytes");
    }

    #[test]
    fn level_selection_follows_opengl() {
        // Level i has red = i / 255 (set the levels by hand to see which is read).
        let mut t = Texture::from_rgba_f32(8, 8, vec![Vec4::ZERO; 64]).expect("texture");
        for i in 0..t.level_count() {
            let offset = t.levels.offsets[i] as usize;
            let len = (t.levels.widths[i] * t.levels.heights[i]) as usize;
            t.texels[offset..offset + len].fill(pack_rgba8([i as u8, 0, 0, 255]));
        }
        let with = |min_filter| Sampler {
            min_filter,
            ..Sampler::default()
        };
        let uv = Vec2::splat(0.3);
        let red = |min, lod: f32| t.sample_lod(&with(min), uv, lod).x * 255.0;
        let cases = [
            (MinFilter::LinearMipmapNearest, 0.4, 0.0),
            (MinFilter::LinearMipmapNearest, 0.6, 1.0),
            (MinFilter::NearestMipmapNearest, 1.49, 1.0),
            (MinFilter::NearestMipmapNearest, 1.51, 2.0),
            (MinFilter::LinearMipmapLinear, 1.25, 1.25),
            (MinFilter::LinearMipmapLinear, 10.0, 3.0),
            (MinFilter::Linear, 2.0, 0.0), // no mipmaps: level 0
            (MinFilter::LinearMipmapLinear, -1.0, 0.0), // magnified: level 0
        ];
        for (min, lod, expected) in cases {
            let got = red(min, lod);
            assert!((got - expected).abs() < 1e-4, "{min:?} at λ {lod}: {got}");
        }
        // λ = log2 of the larger footprint in texels.
        assert!((t.lod(Vec2::new(0.5, 0.0), Vec2::new(0.0, 0.125)) - 2.0).abs() < 1e-6);
    }
}
