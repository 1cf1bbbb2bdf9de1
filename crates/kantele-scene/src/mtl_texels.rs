//! Textures that an MTL material needs made from two images, texel by texel: a base colour
//! texture whose alpha comes from `map_d`, and a metallic-roughness texture from `map_Pr` (or
//! `map_Ns`) and `map_Pm`, which glTF's model wants in one texture (roughness green, metallic
//! blue).
//!
//! As for the specular-glossiness conversion (`spec_gloss_texels`, whose reader this uses), a
//! made texture has along each axis the larger of its sources' sizes, and a smaller source is
//! resampled at level 0 through its own sampler. A scalar source is read in the channel that
//! `-imfchan` names.

use glam::Vec4;
use kantele_rules::color::encode_rgba8;
use kantele_rules::shade::texture::{ColorSpace, Texture};

use crate::budget::{vec_with_capacity, Budget};
use crate::mtl_texture::Channel;
use crate::spec_gloss_texels::{converted_size, Reader, Source};
use crate::texture_util::{ImageError, TEXTURE_BYTES_PER_TEXEL};

/// A source read as a scalar: one channel of its linear texels.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scalar<'a> {
    /// The image and its sampler.
    pub(crate) source: Source<'a>,
    /// The channel read.
    pub(crate) channel: Channel,
}

/// The value of `channel` in a linear texel.
pub(crate) fn channel_value(texel: Vec4, channel: Channel) -> f32 {
    match channel {
        Channel::Red => texel.x,
        Channel::Green => texel.y,
        Channel::Blue => texel.z,
        Channel::Alpha => texel.w,
        Channel::Luminance => 0.2126 * texel.x + 0.7152 * texel.y + 0.0722 * texel.z,
    }
}

/// Whether any texel of the texture's first level is not opaque.
pub(crate) fn has_translucent_texels(texture: &Texture) -> bool {
    texture.level(0).is_some_and(|level| {
        (0..texture.height()).any(|y| (0..texture.width()).any(|x| level.texel(x, y).w < 1.0))
    })
}

/// The size of a texture made from sources of these sizes.
pub(crate) fn made_size(a: Option<(u32, u32)>, b: Option<(u32, u32)>) -> Option<(u32, u32)> {
    converted_size(a, b)
}

/// Charges a made texture of `width` × `height` (with its mip chain and its 8-bit level 0)
/// and makes it from `texel`, which gives the RGBA of each texel (linear), encoded in
/// `color_space`.
fn make(
    width: u32,
    height: u32,
    color_space: ColorSpace,
    what: &str,
    budget: &mut Budget,
    texel: impl Fn(u32, u32) -> [f32; 4],
) -> Result<Texture, ImageError> {
    let texels = width as u64 * height as u64;
    budget
        .charge(
            texels,
            TEXTURE_BYTES_PER_TEXEL + 4,
            &format!("{what} ({width}x{height})"),
        )
        .map_err(ImageError::Budget)?;
    let mut rgba =
        vec_with_capacity::<u8>(texels as usize * 4, what).map_err(ImageError::Budget)?;
    for y in 0..height {
        for x in 0..width {
            rgba.extend_from_slice(&encode_rgba8(texel(x, y), color_space == ColorSpace::Srgb));
        }
    }
    Texture::from_rgba8(width, height, &rgba, color_space)
        .map_err(|e| ImageError::Decode(e.to_string()))
}

fn size(source: Source<'_>) -> (u32, u32) {
    (source.texture.width(), source.texture.height())
}

/// An sRGB base colour texture: the colour of `color` (white without it) and the alpha of
/// `alpha`.
pub(crate) fn with_alpha(
    color: Option<Source<'_>>,
    alpha: Scalar<'_>,
    budget: &mut Budget,
) -> Result<Texture, ImageError> {
    let (width, height) =
        made_size(color.map(size), Some(size(alpha.source))).unwrap_or_else(|| size(alpha.source));
    let read_color = Reader::new(color, width, height);
    let read_alpha = Reader::new(Some(alpha.source), width, height);
    make(
        width,
        height,
        ColorSpace::Srgb,
        "a base colour texture with the alpha of map_d",
        budget,
        |x, y| {
            let c = read_color.texel(x, y);
            let a = channel_value(read_alpha.texel(x, y), alpha.channel);
            [c.x, c.y, c.z, a]
        },
    )
}

/// A linear metallic-roughness texture: green from `roughness`, blue from `metallic` (1 for a
/// missing one), red and alpha 1. `None` without a source.
pub(crate) fn metallic_roughness(
    roughness: Option<Scalar<'_>>,
    metallic: Option<Scalar<'_>>,
    budget: &mut Budget,
) -> Result<Option<Texture>, ImageError> {
    let source_size = |s: Option<Scalar<'_>>| s.map(|s| size(s.source));
    let Some((width, height)) = made_size(source_size(roughness), source_size(metallic)) else {
        return Ok(None);
    };
    let read_roughness = Reader::new(roughness.map(|s| s.source), width, height);
    let read_metallic = Reader::new(metallic.map(|s| s.source), width, height);
    let value = |reader: &Reader<'_>, scalar: Option<Scalar<'_>>, x, y| {
        scalar.map_or(1.0, |s| channel_value(reader.texel(x, y), s.channel))
    };
    make(
        width,
        height,
        ColorSpace::Linear,
        "a metallic-roughness texture from map_Pr and map_Pm",
        budget,
        |x, y| {
            [
                1.0,
                value(&read_roughness, roughness, x, y),
                value(&read_metallic, metallic, x, y),
                1.0,
            ]
        },
    )
    .map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture_util::trilinear_repeat;

    fn texture(width: u32, height: u32, rgba: &[u8], color_space: ColorSpace) -> Texture {
        Texture::from_rgba8(width, height, rgba, color_space).expect("a valid texture")
    }

    fn source(texture: &Texture) -> Source<'_> {
        Source {
            texture,
            sampler: trilinear_repeat(),
        }
    }

    #[test]
    fn metallic_roughness_takes_the_named_channels() {
        let rough = texture(
            2,
            1,
            &[10, 200, 0, 255, 20, 100, 0, 255],
            ColorSpace::Linear,
        );
        let metal = texture(2, 1, &[0, 0, 0, 51, 0, 0, 0, 255], ColorSpace::Linear);
        let mut budget = Budget::new(1 << 20);
        let scalar = |texture, channel| Scalar {
            source: source(texture),
            channel,
        };
        let made = metallic_roughness(
            Some(scalar(&rough, Channel::Green)),
            Some(scalar(&metal, Channel::Alpha)),
            &mut budget,
        )
        .unwrap()
        .expect("a texture");
        assert_eq!(made.source_color_space(), ColorSpace::Linear);
        let level = made.level(0).unwrap();
        let close = |a: Vec4, b: Vec4| (a - b).abs().max_element() < 1e-6;
        assert!(close(
            level.texel(0, 0),
            Vec4::new(1.0, 200.0 / 255.0, 0.2, 1.0)
        ));
        assert!(close(
            level.texel(1, 0),
            Vec4::new(1.0, 100.0 / 255.0, 1.0, 1.0)
        ));
        // Only a metallic map: roughness reads 1.
        let made = metallic_roughness(None, Some(scalar(&metal, Channel::Red)), &mut budget)
            .unwrap()
            .unwrap();
        assert_eq!(
            made.level(0).unwrap().texel(0, 0),
            Vec4::new(1.0, 1.0, 0.0, 1.0)
        );
        assert!(metallic_roughness(None, None, &mut budget)
            .unwrap()
            .is_none());
        let e = metallic_roughness(
            Some(scalar(&rough, Channel::Red)),
            None,
            &mut Budget::new(10),
        )
        .unwrap_err();
        assert!(matches!(e, ImageError::Budget(_)));
    }

    #[test]
    fn base_colour_gains_an_alpha_at_the_larger_size() {
        let colour = texture(1, 1, &[255, 0, 0, 255], ColorSpace::Srgb);
        let alpha = texture(
            2,
            2,
            &[0, 0, 0, 255, 255, 255, 255, 255].repeat(2),
            ColorSpace::Linear,
        );
        let made = with_alpha(
            Some(source(&colour)),
            Scalar {
                source: source(&alpha),
                channel: Channel::Luminance,
            },
            &mut Budget::new(1 << 20),
        )
        .unwrap();
        assert_eq!((made.width(), made.height()), (2, 2));
        let level = made.level(0).unwrap();
        assert_eq!(level.texel(0, 0), Vec4::new(1.0, 0.0, 0.0, 0.0));
        assert_eq!(level.texel(1, 1), Vec4::new(1.0, 0.0, 0.0, 1.0));
        assert!(!has_translucent_texels(&colour));
        assert!(has_translucent_texels(&made));
    }

    #[test]
    fn channels() {
        let t = Vec4::new(1.0, 0.5, 0.25, 0.125);
        assert_eq!(channel_value(t, Channel::Red), 1.0);
        assert_eq!(channel_value(t, Channel::Green), 0.5);
        assert_eq!(channel_value(t, Channel::Blue), 0.25);
        assert_eq!(channel_value(t, Channel::Alpha), 0.125);
        assert!((channel_value(Vec4::ONE, Channel::Luminance) - 1.0).abs() < 1e-6);
    }
}
