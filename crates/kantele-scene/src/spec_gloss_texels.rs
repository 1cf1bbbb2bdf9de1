//! Specular-glossiness textures converted texel by texel into a base colour texture and a
//! metallic-roughness texture (`KHR_materials_pbrSpecularGlossiness`, converted at load by
//! [`to_metallic_roughness`]).
//!
//! The converted textures have, along each axis, the larger of the two sources' sizes. A source
//! of that size is read texel by texel; a smaller one is resampled: read at the centre of each
//! converted texel through its own sampler's wrap modes and magnification filter at level 0,
//! as a renderer reading it at that resolution would (bilinear unless the file asks for
//! nearest). Colours are converted in linear space and re-encoded to 8 bits.

use glam::{Vec2, Vec3, Vec4};
use kantele_rules::color::encode_rgba8;
use kantele_rules::shade::spec_gloss::{to_metallic_roughness, SpecularGlossiness};
use kantele_rules::shade::texture::{ColorSpace, MinFilter, Sampler, Texture};

use crate::budget::{vec_with_capacity, Budget};
use crate::texture_util::{ImageError, TEXTURE_BYTES_PER_TEXEL};

/// The factors of a specular-glossiness material, linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SpecGlossFactors {
    /// `diffuseFactor` (RGBA).
    pub(crate) diffuse: Vec4,
    /// `specularFactor`.
    pub(crate) specular: Vec3,
    /// `glossinessFactor`.
    pub(crate) glossiness: f32,
}

impl Default for SpecGlossFactors {
    /// The extension's defaults.
    fn default() -> Self {
        Self {
            diffuse: Vec4::ONE,
            specular: Vec3::ONE,
            glossiness: 1.0,
        }
    }
}

/// A source texture and the sampler the material reads it through. Both sources are stored as
/// sRGB textures: their red, green and blue are sRGB-encoded, their alpha linear.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Source<'a> {
    /// The decoded image.
    pub(crate) texture: &'a Texture,
    /// Its sampler (wrap modes and magnification filter are used to resample it).
    pub(crate) sampler: Sampler,
}

/// The two converted textures, of the same size.
#[derive(Debug)]
pub(crate) struct Converted {
    /// sRGB base colour; alpha is the diffuse texture's alpha (the factor's alpha is not
    /// multiplied in: it stays the material's).
    pub(crate) base_color: Texture,
    /// Linear: green = roughness, blue = metallic, red and alpha 1.
    pub(crate) metallic_roughness: Texture,
}

/// The size of the converted textures: along each axis the larger of the sources' sizes;
/// `None` without a source.
pub(crate) fn converted_size(a: Option<(u32, u32)>, b: Option<(u32, u32)>) -> Option<(u32, u32)> {
    match (a, b) {
        (Some(a), Some(b)) => Some((a.0.max(b.0), a.1.max(b.1))),
        (a, b) => a.or(b),
    }
}

/// Converts a specular-glossiness material with at least one texture: every texel of the
/// result is [`to_metallic_roughness`] of `factors` × the sources' texels (a missing source
/// reads as white). The memory of both textures is charged to `budget` before anything is
/// allocated.
pub(crate) fn convert_textures(
    factors: SpecGlossFactors,
    diffuse: Option<Source<'_>>,
    specular_glossiness: Option<Source<'_>>,
    budget: &mut Budget,
) -> Result<Converted, ImageError> {
    let size = |s: Option<Source<'_>>| s.map(|s| (s.texture.width(), s.texture.height()));
    let Some((width, height)) = converted_size(size(diffuse), size(specular_glossiness)) else {
        return Err(ImageError::Decode(
            "a specular-glossiness conversion needs a texture".to_string(),
        ));
    };
    let texels = width as u64 * height as u64;
    // Two textures with their mip chains, and their level 0 as bytes before they are built.
    budget
        .charge(
            texels,
            2 * TEXTURE_BYTES_PER_TEXEL + 8,
            &format!("converting specular-glossiness textures to a {width}x{height} base colour and metallic-roughness texture"),
        )
        .map_err(ImageError::Budget)?;
    let bytes = texels as usize * 4;
    let mut base = vec_with_capacity::<u8>(bytes, "a converted base colour texture")
        .map_err(ImageError::Budget)?;
    let mut metallic_roughness =
        vec_with_capacity::<u8>(bytes, "a converted metallic-roughness texture")
            .map_err(ImageError::Budget)?;
    let read_diffuse = Reader::new(diffuse, width, height);
    let read_specular_glossiness = Reader::new(specular_glossiness, width, height);
    for y in 0..height {
        for x in 0..width {
            let d = read_diffuse.texel(x, y);
            let sg = read_specular_glossiness.texel(x, y);
            let converted = to_metallic_roughness(SpecularGlossiness {
                diffuse: factors.diffuse.truncate() * d.truncate(),
                specular: factors.specular * sg.truncate(),
                glossiness: factors.glossiness * sg.w,
            });
            let c = converted.base_color;
            base.extend_from_slice(&encode_rgba8([c.x, c.y, c.z, d.w], true));
            metallic_roughness.extend_from_slice(&encode_rgba8(
                [1.0, converted.roughness, converted.metallic, 1.0],
                false,
            ));
        }
    }
    let built = |rgba: &[u8], color_space| {
        Texture::from_rgba8(width, height, rgba, color_space)
            .map_err(|e| ImageError::Decode(e.to_string()))
    };
    Ok(Converted {
        base_color: built(&base, ColorSpace::Srgb)?,
        metallic_roughness: built(&metallic_roughness, ColorSpace::Linear)?,
    })
}

/// Reads one source at the converted textures' texels (see the module documentation); the
/// OBJ loader's combined textures (`mtl_texels`) read their sources the same way.
pub(crate) struct Reader<'a> {
    source: Option<Source<'a>>,
    /// The source has the converted size: read its texels directly.
    same_size: bool,
    /// The converted size, as `f32`.
    size: Vec2,
}

impl<'a> Reader<'a> {
    /// A reader of `source` for converted textures of `width` × `height` texels.
    pub(crate) fn new(source: Option<Source<'a>>, width: u32, height: u32) -> Self {
        let same_size =
            source.is_some_and(|s| (s.texture.width(), s.texture.height()) == (width, height));
        Self {
            source: source.map(|s| Source {
                // Level 0 with the file's magnification filter.
                sampler: Sampler {
                    min_filter: MinFilter::Linear,
                    ..s.sampler
                },
                ..s
            }),
            same_size,
            size: Vec2::new(width as f32, height as f32),
        }
    }

    /// The linear RGBA of converted texel (`x`, `y`); white without a source.
    pub(crate) fn texel(&self, x: u32, y: u32) -> Vec4 {
        let Some(source) = self.source else {
            return Vec4::ONE;
        };
        if self.same_size {
            if let Some(level) = source.texture.level(0) {
                return level.texel(x, y);
            }
        }
        let uv = (Vec2::new(x as f32, y as f32) + 0.5) / self.size;
        source.texture.sample_lod(&source.sampler, uv, 0.0)
    }
}

#[cfg(test)]
#[path = "spec_gloss_texels_tests.rs"]
mod tests;
