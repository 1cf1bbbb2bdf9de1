//! Textures and samplers: texel storage with a mip chain, wrap modes, nearest / bilinear /
//! trilinear filtering and the level-of-detail rule of OpenGL.
//!
//! Texels are stored as linear `f32` RGBA. sRGB-encoded images are decoded when the texture is
//! created (as a GPU's sRGB formats decode before filtering), and mip levels are built by averaging
//! 2 × 2 texels in linear space.

use glam::{Vec2, Vec4};

use crate::color::srgb_to_linear;
use crate::error::RenderError;

/// Largest texture side accepted (texels).
pub const MAX_TEXTURE_SIZE: u32 = 16384;

/// How the 8-bit channels of an image are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    /// Values are linear intensities.
    Linear,
    /// RGB channels are sRGB-encoded (alpha is always linear).
    Srgb,
}

/// One level of a mip chain.
#[derive(Clone, Debug)]
pub struct MipLevel {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, row 0 first (the top row of the source image), linear RGBA.
    pub texels: Vec<Vec4>,
}

impl MipLevel {
    #[inline]
    fn fetch(&self, x: u32, y: u32) -> Vec4 {
        self.texels[(y * self.width + x) as usize]
    }
}

/// A 2D texture with its complete mip chain, in linear `f32` RGBA.
#[derive(Clone, Debug)]
pub struct Texture {
    levels: Vec<MipLevel>,
    source_color_space: ColorSpace,
}

impl Texture {
    /// Creates a texture from 8-bit RGBA texels (row 0 = top row), decoding sRGB if asked,
    /// and builds the full mip chain.
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
        let texels = rgba
            .chunks_exact(4)
            .map(|p| {
                let a = p[3] as f32 / 255.0;
                match color_space {
                    ColorSpace::Srgb => Vec4::new(
                        srgb_to_linear(p[0] as f32 / 255.0),
                        srgb_to_linear(p[1] as f32 / 255.0),
                        srgb_to_linear(p[2] as f32 / 255.0),
                        a,
                    ),
                    ColorSpace::Linear => Vec4::new(
                        p[0] as f32 / 255.0,
                        p[1] as f32 / 255.0,
                        p[2] as f32 / 255.0,
                        a,
                    ),
                }
            })
            .collect();
        Ok(Self::from_level0(
            MipLevel {
                width,
                height,
                texels,
            },
            color_space,
        ))
    }

    /// Creates a texture from linear float RGBA texels (row 0 = top row) and builds the mip chain.
    pub fn from_rgba_f32(width: u32, height: u32, texels: Vec<Vec4>) -> Result<Self, RenderError> {
        check_texture_size(width, height)?;
        let expected = width as usize * height as usize;
        if texels.len() != expected {
            return Err(RenderError::InvalidTextureData {
                expected,
                actual: texels.len(),
            });
        }
        Ok(Self::from_level0(
            MipLevel {
                width,
                height,
                texels,
            },
            ColorSpace::Linear,
        ))
    }

    fn from_level0(level0: MipLevel, source_color_space: ColorSpace) -> Self {
        let mut levels = vec![level0];
        while let Some(next) = downsample(levels.last().expect("level 0 exists")) {
            levels.push(next);
        }
        Self {
            levels,
            source_color_space,
        }
    }

    /// Width of level 0 in texels.
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    /// Height of level 0 in texels.
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// The mip chain, level 0 first, down to 1 × 1.
    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }

    /// The encoding of the 8-bit data the texture was made from.
    pub fn source_color_space(&self) -> ColorSpace {
        self.source_color_space
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
            (self.levels.len() - 1) as f32
        }
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
        if lod <= 0.0 || lod.is_nan() {
            return sample_level(&self.levels[0], sampler, sampler.mag_filter, uv);
        }
        let max_level = (self.levels.len() - 1) as f32;
        match sampler.min_filter {
            MinFilter::Nearest => sample_level(&self.levels[0], sampler, Filter::Nearest, uv),
            MinFilter::Linear => sample_level(&self.levels[0], sampler, Filter::Linear, uv),
            MinFilter::NearestMipmapNearest | MinFilter::LinearMipmapNearest => {
                let filter = sampler.min_filter.texel_filter();
                // d = ceil(λ + 1/2) − 1, clamped to the chain.
                let level = if lod <= 0.5 {
                    0.0
                } else {
                    (-floor(-(lod + 0.5)) - 1.0).min(max_level)
                };
                sample_level(&self.levels[level as usize], sampler, filter, uv)
            }
            MinFilter::NearestMipmapLinear | MinFilter::LinearMipmapLinear => {
                let filter = sampler.min_filter.texel_filter();
                if lod >= max_level {
                    return sample_level(&self.levels[max_level as usize], sampler, filter, uv);
                }
                let lower = floor(lod);
                let frac = lod - lower;
                let a = sample_level(&self.levels[lower as usize], sampler, filter, uv);
                let b = sample_level(&self.levels[lower as usize + 1], sampler, filter, uv);
                a * (1.0 - frac) + b * frac
            }
        }
    }
}

fn check_texture_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
        return Err(RenderError::InvalidTextureSize { width, height });
    }
    Ok(())
}

/// Next mip level: each texel is the mean of the (up to) 2 × 2 texels it covers.
fn downsample(level: &MipLevel) -> Option<MipLevel> {
    if level.width == 1 && level.height == 1 {
        return None;
    }
    let width = (level.width / 2).max(1);
    let height = (level.height / 2).max(1);
    let mut texels = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        let y0 = (2 * y).min(level.height - 1);
        let y1 = (2 * y + 1).min(level.height - 1);
        for x in 0..width {
            let x0 = (2 * x).min(level.width - 1);
            let x1 = (2 * x + 1).min(level.width - 1);
            let sum = level.fetch(x0, y0)
                + level.fetch(x1, y0)
                + level.fetch(x0, y1)
                + level.fetch(x1, y1);
            texels.push(sum * 0.25);
        }
    }
    Some(MipLevel {
        width,
        height,
        texels,
    })
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
    fn texel_filter(self) -> Filter {
        match self {
            MinFilter::Nearest
            | MinFilter::NearestMipmapNearest
            | MinFilter::NearestMipmapLinear => Filter::Nearest,
            _ => Filter::Linear,
        }
    }

    /// Whether this filter reads levels other than level 0.
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
    /// Moves a coordinate into the first period of a repeating mode ([0, 1) for REPEAT,
    /// [0, 2) for MIRRORED_REPEAT) so texel indices stay small and mostly inside the texture;
    /// CLAMP_TO_EDGE is left alone.
    #[inline]
    fn reduce(self, t: f32) -> f32 {
        match self {
            Wrap::Repeat => t - floor(t),
            Wrap::MirroredRepeat => t - 2.0 * floor(t * 0.5),
            Wrap::ClampToEdge => t,
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
fn sample_level(level: &MipLevel, sampler: &Sampler, filter: Filter, uv: Vec2) -> Vec4 {
    let w = level.width as i32;
    let h = level.height as i32;
    let u = sampler.wrap_s.reduce(uv.x) * w as f32;
    let v = sampler.wrap_t.reduce(uv.y) * h as f32;
    match filter {
        Filter::Nearest => {
            let i = sampler.wrap_s.apply(floor_to_i32(u), w);
            let j = sampler.wrap_t.apply(floor_to_i32(v), h);
            level.fetch(i as u32, j as u32)
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
            let top = level.fetch(x0, y0) * (1.0 - alpha) + level.fetch(x1, y0) * alpha;
            let bottom = level.fetch(x0, y1) * (1.0 - alpha) + level.fetch(x1, y1) * alpha;
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

    /// A 4 × 1 texture with texel values 0, 1, 2, 3 in red.
    fn ramp() -> Texture {
        let texels = (0..4).map(|i| Vec4::new(i as f32, 0.0, 0.0, 1.0)).collect();
        Texture::from_rgba_f32(4, 1, texels).expect("texture")
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
            t.sample_lod(&sampler(wrap, Filter::Nearest), Vec2::new(u, 0.5), 0.0)
                .x
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
            t.sample_lod(&sampler(wrap, Filter::Linear), Vec2::new(u, 0.5), 0.0)
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
        // sRGB 188 ≈ linear 0.5; a 2 × 2 of black and sRGB-white averages to linear 0.5.
        let rgba = [
            0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255, 255, 0, 0, 0, 255,
        ];
        let t = Texture::from_rgba8(2, 2, &rgba, ColorSpace::Srgb).expect("texture");
        assert_eq!(t.levels().len(), 2);
        let top = t.levels()[1].texels[0];
        assert!((top.x - 0.5).abs() < 1e-6, "{top:?}");
        // Non-square and odd sizes go down to 1 × 1.
        let odd = Texture::from_rgba_f32(5, 3, vec![Vec4::ONE; 15]).expect("texture");
        let sizes: Vec<(u32, u32)> = odd.levels().iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, vec![(5, 3), (2, 1), (1, 1)]);
        assert_eq!(odd.levels()[2].texels[0], Vec4::ONE);
    }

    #[test]
    fn level_selection_follows_opengl() {
        // Level i has red = i (set the levels by hand to see which is read).
        let mut t = Texture::from_rgba_f32(8, 8, vec![Vec4::ZERO; 64]).expect("texture");
        for (i, level) in t.levels.iter_mut().enumerate() {
            level.texels.fill(Vec4::new(i as f32, 0.0, 0.0, 1.0));
        }
        let with = |min_filter| Sampler {
            min_filter,
            ..Sampler::default()
        };
        let uv = Vec2::splat(0.3);
        let red = |min, lod: f32| t.sample_lod(&with(min), uv, lod).x;
        assert_eq!(red(MinFilter::LinearMipmapNearest, 0.4), 0.0);
        assert_eq!(red(MinFilter::LinearMipmapNearest, 0.6), 1.0);
        assert_eq!(red(MinFilter::NearestMipmapNearest, 1.49), 1.0);
        assert_eq!(red(MinFilter::NearestMipmapNearest, 1.51), 2.0);
        assert!((red(MinFilter::LinearMipmapLinear, 1.25) - 1.25).abs() < 1e-6);
        assert_eq!(red(MinFilter::LinearMipmapLinear, 10.0), 3.0);
        assert_eq!(red(MinFilter::Linear, 2.0), 0.0, "no mipmaps: level 0");
        assert_eq!(
            red(MinFilter::LinearMipmapLinear, -1.0),
            0.0,
            "magnified: level 0"
        );
        // λ = log2 of the larger footprint in texels.
        assert!((t.lod(Vec2::new(0.5, 0.0), Vec2::new(0.0, 0.125)) - 2.0).abs() < 1e-6);
    }
}
