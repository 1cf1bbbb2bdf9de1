//! MTL materials onto glTF's metallic-roughness model, as the table *OBJ and MTL materials* in
//! `docs/rendering-rules.md` says: colours and factors, the textures they name (decoded by
//! `obj_textures`, combined by `mtl_texels` where glTF wants two images in one texture), which
//! texture options apply, and the texture-coordinate scale and offset (`-s`, `-o`) that the
//! loader applies to the meshes of the material.
//!
//! OBJ states no winding, so every OBJ material is double-sided.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};
use kantele_rules::scene::{AlphaMode, Material, Scene, TextureBinding};
use kantele_rules::shade::texture::{ColorSpace, Sampler, Texture, Wrap};

use crate::budget::Budget;
use crate::mtl::MtlMaterial;
use crate::mtl_texels::{
    has_translucent_texels, made_size, metallic_roughness, with_alpha, Scalar,
};
use crate::mtl_texture::{Channel, TextureOptions, TextureRef};
use crate::obj_textures::{Image, Made, ObjTextures};
use crate::spec_gloss_texels::Source;
use crate::texture_util::{placeholder, trilinear_repeat, ImageError};
use crate::SceneInfo;

/// The material of OBJ faces without one: white, dielectric, fully rough, double-sided.
pub(crate) fn default_material() -> Material {
    Material {
        double_sided: true,
        metallic: 0.0,
        ..Material::default()
    }
}

/// The roughness of a specular exponent `Ns`: `1 − √(Ns / 1000)`, the inverse of Blender's
/// OBJ exporter (`Ns = 1000 (1 − roughness)²`), clamped to [0, 1].
pub(crate) fn roughness_from_shininess(ns: f32) -> f32 {
    (1.0 - (ns.max(0.0) / 1000.0).sqrt()).clamp(0.0, 1.0)
}

/// A converted material and the texture-coordinate scale and offset of its textures.
#[derive(Debug)]
pub(crate) struct ObjMaterial {
    /// The material.
    pub material: Material,
    /// `(scale, offset)` from `-s` / `-o`, applied to OBJ texture coordinates as
    /// `uv × scale + offset` (before `v` is flipped); `None` when they do not move them.
    pub uv: Option<(Vec2, Vec2)>,
}

/// Which texture statement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    Diffuse,
    Emissive,
    Normal,
    Roughness,
    Shininess,
    Metallic,
    Alpha,
    Specular,
}

impl Slot {
    fn keyword(self) -> &'static str {
        match self {
            Slot::Diffuse => "map_Kd",
            Slot::Emissive => "map_Ke",
            Slot::Normal => "the normal map",
            Slot::Roughness => "map_Pr",
            Slot::Shininess => "map_Ns",
            Slot::Metallic => "map_Pm",
            Slot::Alpha => "map_d",
            Slot::Specular => "map_Ks",
        }
    }

    /// Read as one channel (`-imfchan` applies).
    fn scalar(self) -> bool {
        matches!(
            self,
            Slot::Roughness | Slot::Shininess | Slot::Metallic | Slot::Alpha
        )
    }

    /// How its texels are encoded unless `-colorspace` says otherwise.
    fn color_space(self) -> ColorSpace {
        match self {
            Slot::Diffuse | Slot::Emissive | Slot::Specular => ColorSpace::Srgb,
            _ => ColorSpace::Linear,
        }
    }

    /// Whether an option is applied to this statement.
    fn applies(self, option: &str) -> bool {
        match option {
            "-s" | "-o" | "-clamp" | "-colorspace" => true,
            "-bm" => self == Slot::Normal,
            "-imfchan" => self.scalar(),
            _ => false,
        }
    }
}

/// The sampler a statement's options ask for: repeating unless `-clamp on`.
fn sampler(options: &TextureOptions) -> Sampler {
    let mut sampler = trilinear_repeat();
    if options.clamp {
        sampler.wrap_s = Wrap::ClampToEdge;
        sampler.wrap_t = Wrap::ClampToEdge;
    }
    sampler
}

/// A texture statement whose image was read.
struct Loaded<'m> {
    file: PathBuf,
    color_space: ColorSpace,
    image: Image,
    options: &'m TextureOptions,
}

impl Loaded<'_> {
    fn key(&self) -> (PathBuf, ColorSpace) {
        (self.file.clone(), self.color_space)
    }

    fn source(&self) -> Source<'_> {
        Source {
            texture: &self.image.texture,
            sampler: sampler(self.options),
        }
    }

    /// The channel a scalar statement reads: `-imfchan`, else luminance.
    fn channel(&self) -> Channel {
        self.options.channel.unwrap_or(Channel::Luminance)
    }

    /// The image read as a scalar in [`Loaded::channel`].
    fn scalar(&self) -> Scalar<'_> {
        Scalar {
            source: self.source(),
            channel: self.channel(),
        }
    }
}

/// What converting a material uses of the load.
pub(crate) struct Converter<'l, 't> {
    /// The textures.
    pub textures: &'l mut ObjTextures<'t>,
    /// The scene the textures go into.
    pub scene: &'l mut Scene,
    /// Warnings and ignored features.
    pub info: &'l mut SceneInfo,
    /// The load's budget.
    pub budget: &'l mut Budget,
}

impl Converter<'_, '_> {
    /// Converts a material of the library in `folder` (its texture names are relative to it).
    pub(crate) fn convert(
        &mut self,
        m: &MtlMaterial,
        folder: &Path,
    ) -> Result<ObjMaterial, String> {
        let label = format!("material '{}'", m.name);
        let maps = &m.maps;
        if maps.roughness.is_some() && maps.shininess.is_some() {
            self.info.ignore("MTL map_Ns (map_Pr is used)");
        }
        let roughness_map = match (&maps.roughness, &maps.shininess) {
            (Some(t), _) => Some((Slot::Roughness, t)),
            (None, Some(t)) => Some((Slot::Shininess, t)),
            (None, None) => None,
        };
        let used: Vec<(Slot, &TextureRef)> = [
            maps.diffuse.as_ref().map(|t| (Slot::Diffuse, t)),
            maps.emissive.as_ref().map(|t| (Slot::Emissive, t)),
            maps.normal.as_ref().map(|t| (Slot::Normal, t)),
            roughness_map,
            maps.metallic.as_ref().map(|t| (Slot::Metallic, t)),
            maps.alpha.as_ref().map(|t| (Slot::Alpha, t)),
            maps.specular.as_ref().map(|t| (Slot::Specular, t)),
        ]
        .into_iter()
        .flatten()
        .collect();
        for (slot, t) in &used {
            for option in &t.options.given {
                if !slot.applies(option) {
                    self.info.ignore(format!("MTL texture option {option}"));
                }
            }
        }
        let uv = self.uv_transform(&label, &used);
        let mut loaded: Vec<(Slot, Loaded<'_>)> = Vec::new();
        for (slot, t) in used {
            let file = folder.join(t.file.replace('\\', "/"));
            let color_space = t.options.color_space.unwrap_or(slot.color_space());
            let what = format!("{label}: texture {}", file.display());
            let image = self
                .textures
                .image(&file, color_space, &what, self.budget, self.info)?;
            if let Some(image) = image {
                loaded.push((
                    slot,
                    Loaded {
                        file,
                        color_space,
                        image,
                        options: &t.options,
                    },
                ));
            }
        }
        let take = |slot: Slot| loaded.iter().find(|(s, _)| *s == slot).map(|(_, l)| l);
        let roughness = take(Slot::Roughness).or(take(Slot::Shininess));

        let finite = |v: f32| v.is_finite().then_some(v);
        let alpha = m
            .dissolve
            .or(m.transparency.map(|t| 1.0 - t))
            .and_then(finite)
            .unwrap_or(1.0)
            .clamp(0.0, 1.0);
        let diffuse = m.diffuse.unwrap_or(Vec3::ONE);
        let emissive_map = take(Slot::Emissive);
        let emissive = match (m.emissive, emissive_map) {
            (Some(ke), Some(_)) if ke != Vec3::ZERO => ke,
            (_, Some(_)) => Vec3::ONE,
            (Some(ke), None) => ke,
            (None, None) => Vec3::ZERO,
        };
        let mut out = Material {
            name: m.name.clone(),
            base_color_factor: diffuse.extend(alpha),
            double_sided: true,
            alpha_mode: if alpha < 1.0 || take(Slot::Alpha).is_some() {
                AlphaMode::Blend
            } else {
                AlphaMode::Opaque
            },
            emissive: emissive.max(Vec3::ZERO),
            // A texture gives the value itself (its factor is 1).
            roughness: if roughness.is_some() {
                1.0
            } else {
                m.roughness
                    .or(m.shininess.map(roughness_from_shininess))
                    .unwrap_or(1.0)
                    .clamp(0.0, 1.0)
            },
            metallic: if take(Slot::Metallic).is_some() {
                1.0
            } else {
                m.metallic.unwrap_or(0.0).clamp(0.0, 1.0)
            },
            normal_scale: take(Slot::Normal)
                .and_then(|l| l.options.bump_multiplier)
                .unwrap_or(1.0),
            clearcoat: m.clearcoat.unwrap_or(0.0).clamp(0.0, 1.0),
            ..Material::default()
        };
        if let Some(pcr) = m.clearcoat_roughness {
            out.clearcoat_roughness = pcr.clamp(0.0, 1.0);
        }
        if let Some(ks) = m.specular {
            // Blender's convention: Ks 0.5 is the usual dielectric (F0 = 0.04).
            out.dielectric_f0 = (ks * 0.08).clamp(Vec3::ZERO, Vec3::ONE);
        }
        out.base_color_texture = self.base_color(take(Slot::Diffuse), take(Slot::Alpha))?;
        out.emissive_texture = emissive_map.map(|l| self.file(l)).transpose()?;
        out.normal_texture = take(Slot::Normal).map(|l| self.file(l)).transpose()?;
        out.specular_color_texture = take(Slot::Specular).map(|l| self.file(l)).transpose()?;
        out.metallic_roughness_texture =
            self.metallic_roughness(roughness, take(Slot::Metallic))?;
        Ok(ObjMaterial { material: out, uv })
    }

    /// The texture-coordinate transform of the material's textures: that of its first
    /// texture statement; a warning when the others differ.
    fn uv_transform(&mut self, label: &str, used: &[(Slot, &TextureRef)]) -> Option<(Vec2, Vec2)> {
        let (slot, first) = used.first()?;
        let moves = |o: &TextureOptions| (o.scale, o.offset);
        if used
            .iter()
            .any(|(_, t)| moves(&t.options) != moves(&first.options))
        {
            self.info.warn(format!(
                "{label}: its textures have different -s / -o options; those of {} apply to all",
                slot.keyword()
            ));
        }
        first
            .options
            .moves_coordinates()
            .then_some(moves(&first.options))
    }

    /// A texture of the scene for an image file as it is.
    fn file(&mut self, l: &Loaded<'_>) -> Result<TextureBinding, String> {
        let image = l.image.clone();
        let texture =
            self.textures
                .scene_texture(Made::File(l.key()), self.scene, self.info, || Ok(image))?;
        Ok(TextureBinding {
            texture,
            sampler: sampler(l.options),
            texcoord: 0,
        })
    }

    /// A texture made from images (a placeholder of the made size when textures are not
    /// decoded).
    fn made(
        &mut self,
        made: Made,
        sizes: [Option<(u32, u32)>; 2],
        sampler: Sampler,
        make: impl FnOnce(&mut Budget) -> Result<Option<Texture>, ImageError>,
    ) -> Result<TextureBinding, String> {
        let decoded = self.textures.decoded();
        let budget = &mut *self.budget;
        let texture = self
            .textures
            .scene_texture(made, self.scene, self.info, || {
                let size = made_size(sizes[0], sizes[1]).unwrap_or((1, 1));
                if !decoded {
                    return Ok(Image {
                        texture: Arc::new(placeholder()),
                        size,
                    });
                }
                match make(budget) {
                    Ok(Some(texture)) => Ok(Image {
                        size: (texture.width(), texture.height()),
                        texture: Arc::new(texture),
                    }),
                    Ok(None) => Err("a made texture needs an image".to_string()),
                    Err(ImageError::Budget(e) | ImageError::Decode(e)) => Err(e),
                }
            })?;
        Ok(TextureBinding {
            texture,
            sampler,
            texcoord: 0,
        })
    }

    /// The base colour texture: `map_Kd`, with the alpha of `map_d` when there is one (the
    /// `map_Kd` image itself when `map_d` names the same file and reads its alpha).
    fn base_color(
        &mut self,
        diffuse: Option<&Loaded<'_>>,
        alpha: Option<&Loaded<'_>>,
    ) -> Result<Option<TextureBinding>, String> {
        let Some(alpha) = alpha else {
            return diffuse.map(|d| self.file(d)).transpose();
        };
        // Images with an alpha channel give their alpha, others their luminance.
        let channel = alpha.options.channel.unwrap_or_else(|| {
            if has_translucent_texels(&alpha.image.texture) {
                Channel::Alpha
            } else {
                Channel::Luminance
            }
        });
        if let Some(d) = diffuse {
            if d.file == alpha.file && channel == Channel::Alpha {
                return self.file(d).map(Some);
            }
        }
        let made = Made::BaseWithAlpha {
            color: diffuse.map(Loaded::key),
            alpha: (alpha.key(), channel),
        };
        let sizes = [diffuse.map(|d| d.image.size), Some(alpha.image.size)];
        let sampler = sampler(diffuse.unwrap_or(alpha).options);
        let scalar = Scalar {
            source: alpha.source(),
            channel,
        };
        let color = diffuse.map(Loaded::source);
        self.made(made, sizes, sampler, |budget| {
            with_alpha(color, scalar, budget).map(Some)
        })
        .map(Some)
    }

    /// The metallic-roughness texture, from a roughness and a metallic image.
    fn metallic_roughness(
        &mut self,
        roughness: Option<&Loaded<'_>>,
        metallic: Option<&Loaded<'_>>,
    ) -> Result<Option<TextureBinding>, String> {
        let Some(first) = roughness.or(metallic) else {
            return Ok(None);
        };
        let keyed = |l: &Loaded<'_>| (l.key(), l.channel());
        let made = Made::MetallicRoughness {
            roughness: roughness.map(keyed),
            metallic: metallic.map(keyed),
        };
        let sizes = [
            roughness.map(|l| l.image.size),
            metallic.map(|l| l.image.size),
        ];
        let (r, m) = (roughness.map(Loaded::scalar), metallic.map(Loaded::scalar));
        self.made(made, sizes, sampler(first.options), |budget| {
            metallic_roughness(r, m, budget)
        })
        .map(Some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_follows_blender() {
        assert_eq!(roughness_from_shininess(0.0), 1.0);
        assert_eq!(roughness_from_shininess(250.0), 0.5);
        assert_eq!(roughness_from_shininess(1000.0), 0.0);
        assert_eq!(roughness_from_shininess(5000.0), 0.0);
        assert_eq!(roughness_from_shininess(-3.0), 1.0);
    }

    #[test]
    fn options_that_apply() {
        assert!(Slot::Normal.applies("-bm") && !Slot::Diffuse.applies("-bm"));
        assert!(Slot::Alpha.applies("-imfchan") && !Slot::Diffuse.applies("-imfchan"));
        assert!(Slot::Diffuse.applies("-clamp") && !Slot::Diffuse.applies("-blendu"));
        assert_eq!(Slot::Normal.color_space(), ColorSpace::Linear);
        assert_eq!(Slot::Emissive.color_space(), ColorSpace::Srgb);
    }
}
