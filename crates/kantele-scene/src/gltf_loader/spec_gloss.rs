//! `KHR_materials_pbrSpecularGlossiness`: a material's specular-glossiness values, read from the
//! extension's JSON, converted to the metallic-roughness values Kantele shades.
//!
//! Factors alone convert to factors. With a diffuse or specular-glossiness texture, a new base
//! colour texture and metallic-roughness texture are made texel by texel
//! ([`crate::spec_gloss_texels`]), the material's factors become 1 (the diffuse factor's alpha
//! stays the base colour factor's alpha), and the new textures read the sources' texture
//! coordinates. The diffuse texture's colour and the specular-glossiness texture's specular
//! colour are sRGB-encoded, their alpha (opacity, glossiness) linear.

use glam::{Vec3, Vec4};
use kantele_rules::scene::TextureBinding;
use kantele_rules::shade::spec_gloss::{to_metallic_roughness, SpecularGlossiness};
use kantele_rules::shade::texture::{ColorSpace, Sampler};
use serde_json::Value;

use super::material::{json_texture_reference, sampler_of, SourceImage, UvMap};
use super::Loader;
use crate::spec_gloss_texels::{convert_textures, converted_size, Source, SpecGlossFactors};
use crate::texture_util::{placeholder, ImageError};
use crate::LoadError;

/// The extension's name.
pub(super) const SPEC_GLOSS: &str = "KHR_materials_pbrSpecularGlossiness";

/// What a specular-glossiness material becomes.
#[derive(Clone, Copy, Debug)]
pub(super) struct SpecGlossMaterial {
    /// Linear base colour factor (alpha: the diffuse factor's).
    pub(super) base_color_factor: Vec4,
    /// Metallic factor.
    pub(super) metallic: f32,
    /// Roughness factor.
    pub(super) roughness: f32,
    /// The converted textures (`None` when either could not be made) and the texture
    /// coordinates both read.
    pub(super) textures: Option<ConvertedTextures>,
}

/// The converted textures of a material.
#[derive(Clone, Copy, Debug)]
pub(super) struct ConvertedTextures {
    /// sRGB base colour, read through the diffuse texture's sampler.
    pub(super) base_color: TextureBinding,
    /// Linear metallic-roughness, read through the specular-glossiness texture's sampler.
    pub(super) metallic_roughness: TextureBinding,
    /// The texture coordinates both read.
    pub(super) uv: UvMap,
}

/// The converted textures of one conversion: the glTF textures it read (`None`: absent) and
/// the bits of its factors. Equal keys give the same textures.
pub(super) type ConversionKey = (Option<usize>, Option<usize>, [u32; 8]);

/// A texture that the extension refers to.
struct TextureRef<'a> {
    texture: gltf::texture::Texture<'a>,
    uv: UvMap,
}

impl<'a> Loader<'a> {
    /// Converts the `KHR_materials_pbrSpecularGlossiness` value `extension` of material `name`.
    /// What cannot be used (malformed values, missing textures, textures reading different
    /// texture coordinates) gives a warning and the rest is converted.
    pub(super) fn spec_gloss(
        &mut self,
        name: &str,
        extension: &Value,
    ) -> Result<SpecGlossMaterial, LoadError> {
        let factors = self.spec_gloss_factors(name, extension);
        let mut diffuse = self.spec_gloss_texture(name, extension, "diffuseTexture");
        let mut specular_glossiness =
            self.spec_gloss_texture(name, extension, "specularGlossinessTexture");
        if let (Some(d), Some(s)) = (&diffuse, &specular_glossiness) {
            if d.uv != s.uv {
                self.info.warn(format!(
                    "material '{name}': {SPEC_GLOSS}: the diffuse and specular-glossiness textures read different texture coordinates; converted from the factors alone"
                ));
                diffuse = None;
                specular_glossiness = None;
            }
        }
        let from_factors = {
            let converted = to_metallic_roughness(SpecularGlossiness {
                diffuse: factors.diffuse.truncate(),
                specular: factors.specular,
                glossiness: factors.glossiness,
            });
            SpecGlossMaterial {
                base_color_factor: converted.base_color.extend(factors.diffuse.w),
                metallic: converted.metallic,
                roughness: converted.roughness,
                textures: None,
            }
        };
        let Some(uv) = diffuse
            .as_ref()
            .or(specular_glossiness.as_ref())
            .map(|t| t.uv)
        else {
            return Ok(from_factors);
        };
        let samplers = (
            diffuse.as_ref().map(|t| sampler_of(&t.texture)),
            specular_glossiness.as_ref().map(|t| sampler_of(&t.texture)),
        );
        let mut bits = [0; 8];
        for (bit, value) in bits.iter_mut().zip(
            factors
                .diffuse
                .to_array()
                .into_iter()
                .chain(factors.specular.to_array())
                .chain([factors.glossiness]),
        ) {
            *bit = value.to_bits();
        }
        let key = (
            diffuse.as_ref().map(|t| t.texture.index()),
            specular_glossiness.as_ref().map(|t| t.texture.index()),
            bits,
        );
        let made = match self.spec_gloss_textures.get(&key) {
            Some(&made) => made,
            None => {
                let made = self.convert_spec_gloss_textures(
                    factors,
                    diffuse.as_ref().map(|t| &t.texture),
                    specular_glossiness.as_ref().map(|t| &t.texture),
                    samplers,
                )?;
                self.spec_gloss_textures.insert(key, made);
                made
            }
        };
        let Some((base_color, metallic_roughness)) = made else {
            return Ok(from_factors);
        };
        let sampler = |own: Option<Sampler>, other: Option<Sampler>| {
            own.or(other)
                .unwrap_or_else(crate::texture_util::trilinear_repeat)
        };
        Ok(SpecGlossMaterial {
            base_color_factor: Vec4::new(1.0, 1.0, 1.0, factors.diffuse.w),
            metallic: 1.0,
            roughness: 1.0,
            textures: Some(ConvertedTextures {
                base_color: TextureBinding {
                    texture: base_color,
                    sampler: sampler(samplers.0, samplers.1),
                    texcoord: 0,
                },
                metallic_roughness: TextureBinding {
                    texture: metallic_roughness,
                    sampler: sampler(samplers.1, samplers.0),
                    texcoord: 0,
                },
                uv,
            }),
        })
    }

    /// Decodes the sources and makes the two converted textures, added to the scene; `None`
    /// when no source could be decoded (each failure gave its warning, or is an error when the
    /// load is strict). Budget overruns are errors.
    fn convert_spec_gloss_textures(
        &mut self,
        factors: SpecGlossFactors,
        diffuse: Option<&gltf::texture::Texture>,
        specular_glossiness: Option<&gltf::texture::Texture>,
        samplers: (Option<Sampler>, Option<Sampler>),
    ) -> Result<Option<(usize, usize)>, LoadError> {
        // Both sources hold sRGB colours and linear alpha: an sRGB texture decodes them so.
        let mut decoded = |texture: Option<&gltf::texture::Texture>| match texture {
            Some(t) => self.source_image(t, ColorSpace::Srgb),
            None => Ok(None),
        };
        let diffuse = decoded(diffuse)?;
        let specular_glossiness = decoded(specular_glossiness)?;
        let Some(size) = converted_size(
            diffuse.as_ref().map(|d| d.size),
            specular_glossiness.as_ref().map(|s| s.size),
        ) else {
            return Ok(None);
        };
        if !self.options.decode_textures {
            // Describing the scene: placeholders of the converted size.
            let base = self.push_texture(placeholder(), size);
            let metallic_roughness = self.push_texture(placeholder(), size);
            return Ok(Some((base, metallic_roughness)));
        }
        let converted = convert_textures(
            factors,
            source(&diffuse, samplers.0),
            source(&specular_glossiness, samplers.1),
            &mut self.budget,
        );
        match converted {
            Ok(c) => {
                let base = self.push_texture(c.base_color, size);
                let metallic_roughness = self.push_texture(c.metallic_roughness, size);
                Ok(Some((base, metallic_roughness)))
            }
            Err(ImageError::Budget(e)) => Err(self.invalid(e)),
            Err(ImageError::Decode(e)) => {
                self.texture_problem::<()>(format!("{SPEC_GLOSS} conversion: {e}"))?;
                Ok(None)
            }
        }
    }

    /// The extension's factors; a malformed one gives a warning and its default.
    fn spec_gloss_factors(&mut self, name: &str, extension: &Value) -> SpecGlossFactors {
        let defaults = SpecGlossFactors::default();
        let mut numbers = |key: &str, default: &[f32]| -> Vec<f32> {
            let Some(value) = extension.get(key) else {
                return default.to_vec();
            };
            let parsed: Option<Vec<f32>> = match value {
                Value::Array(items) if items.len() == default.len() => items
                    .iter()
                    .map(|v| v.as_f64().map(|f| f as f32).filter(|f| f.is_finite()))
                    .collect(),
                Value::Number(n) if default.len() == 1 => n
                    .as_f64()
                    .map(|f| vec![f as f32])
                    .filter(|f| f[0].is_finite()),
                _ => None,
            };
            parsed.unwrap_or_else(|| {
                self.info.warn(format!(
                    "material '{name}': {SPEC_GLOSS}: {key} is malformed; its default is used"
                ));
                default.to_vec()
            })
        };
        let diffuse = numbers("diffuseFactor", &defaults.diffuse.to_array());
        let specular = numbers("specularFactor", &defaults.specular.to_array());
        let glossiness = numbers("glossinessFactor", &[defaults.glossiness]);
        // Each has the length asked for; the range is the extension's [0, 1].
        let unit = |v: &[f32], i: usize| v.get(i).copied().unwrap_or(1.0).clamp(0.0, 1.0);
        SpecGlossFactors {
            diffuse: Vec4::new(
                unit(&diffuse, 0),
                unit(&diffuse, 1),
                unit(&diffuse, 2),
                unit(&diffuse, 3),
            ),
            specular: Vec3::new(unit(&specular, 0), unit(&specular, 1), unit(&specular, 2)),
            glossiness: unit(&glossiness, 0),
        }
    }

    /// The texture that the extension's `key` (`diffuseTexture`, `specularGlossinessTexture`)
    /// refers to, with its texture coordinates; `None` when absent, or (with a warning) when
    /// it names no texture of the file.
    fn spec_gloss_texture(
        &mut self,
        name: &str,
        extension: &Value,
        key: &str,
    ) -> Option<TextureRef<'a>> {
        let info = extension.get(key)?;
        let Some((texture, uv)) = json_texture_reference(self.document, info) else {
            self.info.warn(format!(
                "material '{name}': {SPEC_GLOSS}: {key} names no texture of the file; left out"
            ));
            return None;
        };
        Some(TextureRef { texture, uv })
    }
}

/// A decoded source with the sampler it is read through.
fn source(image: &Option<SourceImage>, sampler: Option<Sampler>) -> Option<Source<'_>> {
    Some(Source {
        texture: &image.as_ref()?.texture,
        sampler: sampler.unwrap_or_default(),
    })
}
