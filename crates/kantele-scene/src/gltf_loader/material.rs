//! Materials, their textures and samplers, the images behind them, and the texture coordinates
//! each material reads.

use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3, Vec4};
use kantele_rules::scene::{AlphaMode, Material, TextureBinding};
use kantele_rules::shade::texture::{Filter, MinFilter, Sampler, Texture, Wrap};

use super::spec_gloss::SPEC_GLOSS;
use super::{capped_name, named, Loader};
use crate::accessor::BufferData;
use crate::texture_util::{decode_within, image_size, placeholder, ImageError};
use crate::uri::read_uri;
use crate::LoadError;
use kantele_rules::shade::texture::ColorSpace;

/// Which texture coordinates a texture reads: a `TEXCOORD_n` set and a
/// `KHR_texture_transform`. The loader applies it to the coordinates of the meshes that use
/// the material, which carry up to [`MESH_UV_MAPS`] such maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct UvMap {
    /// The `TEXCOORD_n` set.
    pub(super) set: u32,
    /// The `KHR_texture_transform` (identity without one).
    pub(super) transform: Mat3,
}

/// How many different [`UvMap`]s a material's textures may read: the sets of texture
/// coordinates a mesh carries ([`kantele_rules::scene::Mesh::texcoords`] and `texcoords1`).
pub(super) const MESH_UV_MAPS: usize = 2;

/// The maps of a material's textures, in the mesh's order: the first texture's first (the
/// base colour's when it has one), then the next different one.
pub(super) type MaterialUvMaps = [Option<UvMap>; MESH_UV_MAPS];

/// A texture reference read from extension JSON (`{"index", "texCoord", "extensions":
/// {"KHR_texture_transform"}}`): the file's texture and the coordinates it reads; `None` when
/// `index` names no texture of `document`.
pub(super) fn json_texture_reference<'a>(
    document: &'a gltf::Document,
    info: &serde_json::Value,
) -> Option<(gltf::texture::Texture<'a>, UvMap)> {
    let texture = info
        .get("index")
        .and_then(serde_json::Value::as_u64)
        .and_then(|i| document.textures().nth(usize::try_from(i).ok()?))?;
    let tex_coord = info
        .get("texCoord")
        .and_then(serde_json::Value::as_u64)
        .and_then(|t| u32::try_from(t).ok())
        .unwrap_or(0);
    let transform = info
        .get("extensions")
        .and_then(|e| e.get("KHR_texture_transform"));
    Some((texture, UvMap::of(tex_coord, transform)))
}

impl UvMap {
    /// `TEXCOORD_0` as it is.
    pub(super) const PLAIN: UvMap = UvMap {
        set: 0,
        transform: Mat3::IDENTITY,
    };

    /// The map of a texture reference: its `texCoord` and its `KHR_texture_transform`
    /// extension value, if any.
    pub(super) fn of(tex_coord: u32, texture_transform: Option<&serde_json::Value>) -> Self {
        let mut set = tex_coord;
        let mut transform = Mat3::IDENTITY;
        if let Some(t) = texture_transform {
            let pair = |key: &str, default: Vec2| {
                t.get(key)
                    .and_then(|v| v.as_array())
                    .and_then(|a| {
                        Some(Vec2::new(
                            a.first()?.as_f64()? as f32,
                            a.get(1)?.as_f64()? as f32,
                        ))
                    })
                    .unwrap_or(default)
            };
            let offset = pair("offset", Vec2::ZERO);
            let scale = pair("scale", Vec2::ONE);
            let rotation = t.get("rotation").and_then(|v| v.as_f64()).unwrap_or(0.0) as f32;
            // uv' = T × R × S × uv. R's columns are (cos, −sin) and (sin, cos): the direction
            // in which the sample models (TextureTransformTest, TextureTransformMultiTest) and
            // the common viewers rotate; checked by the corpus test.
            let (sin, cos) = rotation.sin_cos();
            let translation = Mat3::from_cols(Vec3::X, Vec3::Y, offset.extend(1.0));
            let rotation =
                Mat3::from_cols(Vec3::new(cos, -sin, 0.0), Vec3::new(sin, cos, 0.0), Vec3::Z);
            let scale = Mat3::from_diagonal(scale.extend(1.0));
            transform = translation * rotation * scale;
            if let Some(s) = t.get("texCoord").and_then(|v| v.as_u64()) {
                set = s as u32;
            }
            if !transform.is_finite() {
                transform = Mat3::IDENTITY;
            }
        }
        Self { set, transform }
    }
}

/// Which of a material's textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TextureSlot {
    BaseColor,
    Emissive,
    MetallicRoughness,
    Normal,
    Occlusion,
    Specular,
    SpecularColor,
    Clearcoat,
    ClearcoatRoughness,
    ClearcoatNormal,
    Transmission,
    Thickness,
    SheenColor,
    SheenRoughness,
}

impl TextureSlot {
    pub(super) fn name(self) -> &'static str {
        match self {
            TextureSlot::BaseColor => "base colour",
            TextureSlot::Emissive => "emissive",
            TextureSlot::MetallicRoughness => "metallic-roughness",
            TextureSlot::Normal => "normal",
            TextureSlot::Occlusion => "occlusion",
            TextureSlot::Specular => "specular",
            TextureSlot::SpecularColor => "specular colour",
            TextureSlot::Clearcoat => "clear coat",
            TextureSlot::ClearcoatRoughness => "clear-coat roughness",
            TextureSlot::ClearcoatNormal => "clear-coat normal",
            TextureSlot::Transmission => "transmission",
            TextureSlot::Thickness => "thickness",
            TextureSlot::SheenColor => "sheen colour",
            TextureSlot::SheenRoughness => "sheen roughness",
        }
    }
}

/// A glTF image read by [`Loader::read_image`].
enum ReadImage {
    /// Identical encoded bytes were loaded before, as this scene texture.
    Loaded(usize),
    /// Newly decoded (a placeholder when textures are not decoded), with its encoded bytes
    /// (the key of `encoded_images`) and its size.
    Decoded {
        texture: Box<Texture>,
        encoded: Vec<u8>,
        size: (u32, u32),
    },
}

/// A decoded image to read texels from ([`Loader::source_image`]).
pub(super) struct SourceImage {
    /// The texture (shared with the scene when the scene has it).
    pub(super) texture: Arc<Texture>,
    /// Its size (that of the image when textures are not decoded).
    pub(super) size: (u32, u32),
}

/// Where a material's texture comes from.
enum TextureSource<'a> {
    /// A texture of the file, decoded in a colour space.
    File(gltf::texture::Texture<'a>, ColorSpace),
    /// A texture the loader made (`KHR_materials_pbrSpecularGlossiness`).
    Made(TextureBinding),
}

impl<'a> Loader<'a> {
    /// Converts a material; also records which texture coordinates its textures read
    /// (`self.material_uv`), which the loader bakes into the meshes that use it, and whether
    /// it bends normals (`self.material_normal_map`: which of those maps orients the tangents).
    pub(super) fn material(
        &mut self,
        material: &gltf::Material<'a>,
    ) -> Result<Material, LoadError> {
        let name = named(material.name(), "material", material.index().unwrap_or(0));
        let pbr = material.pbr_metallic_roughness();
        // KHR_materials_pbrSpecularGlossiness replaces pbrMetallicRoughness (then a fallback
        // for viewers without the extension), as in the viewers that support it.
        let spec_gloss = match material.extension_value(SPEC_GLOSS) {
            Some(extension) if extension.is_object() => Some(self.spec_gloss(&name, extension)?),
            Some(_) => {
                self.info.warn(format!(
                    "material '{name}': {SPEC_GLOSS} is not an object; its metallic-roughness values are used"
                ));
                None
            }
            None => None,
        };
        let transform = "KHR_texture_transform";
        // Every texture of the material, with where it comes from and the coordinates it reads.
        let mut refs: Vec<(TextureSlot, TextureSource, UvMap)> = Vec::new();
        let file = TextureSource::File;
        match &spec_gloss {
            Some(converted) => {
                if let Some(t) = converted.textures {
                    let made = TextureSource::Made(t.base_color);
                    refs.push((TextureSlot::BaseColor, made, t.uv));
                }
            }
            None => {
                if let Some(info) = pbr.base_color_texture() {
                    let uv = UvMap::of(info.tex_coord(), info.extension_value(transform));
                    let source = file(info.texture(), ColorSpace::Srgb);
                    refs.push((TextureSlot::BaseColor, source, uv));
                }
            }
        }
        if let Some(info) = material.emissive_texture() {
            let uv = UvMap::of(info.tex_coord(), info.extension_value(transform));
            let source = file(info.texture(), ColorSpace::Srgb);
            refs.push((TextureSlot::Emissive, source, uv));
        }
        match &spec_gloss {
            Some(converted) => {
                if let Some(t) = converted.textures {
                    let made = TextureSource::Made(t.metallic_roughness);
                    refs.push((TextureSlot::MetallicRoughness, made, t.uv));
                }
            }
            None => {
                if let Some(info) = pbr.metallic_roughness_texture() {
                    let uv = UvMap::of(info.tex_coord(), info.extension_value(transform));
                    let source = file(info.texture(), ColorSpace::Linear);
                    refs.push((TextureSlot::MetallicRoughness, source, uv));
                }
            }
        }
        if let Some(t) = material.normal_texture() {
            let uv = UvMap::of(t.tex_coord(), t.extension_value(transform));
            refs.push((
                TextureSlot::Normal,
                file(t.texture(), ColorSpace::Linear),
                uv,
            ));
        }
        if let Some(t) = material.occlusion_texture() {
            let uv = UvMap::of(t.tex_coord(), t.extension_value(transform));
            let source = file(t.texture(), ColorSpace::Linear);
            refs.push((TextureSlot::Occlusion, source, uv));
        }
        let extensions = self.material_extensions(material, &name);
        for (slot, texture, color_space, uv) in &extensions.textures {
            refs.push((*slot, file(texture.clone(), *color_space), *uv));
        }
        let strength = material
            .extension_value("KHR_materials_emissive_strength")
            .and_then(|v| v.get("emissiveStrength"))
            .and_then(serde_json::Value::as_f64)
            .filter(|s| s.is_finite() && *s >= 0.0)
            .unwrap_or(1.0) as f32;
        let mut emissive = Vec3::from(material.emissive_factor()) * strength;
        if !emissive.is_finite() {
            emissive = Vec3::ZERO;
        }
        let finite_or = |v: f32, default: f32| if v.is_finite() { v } else { default };
        let mut out = Material {
            name: capped_name(material.name().unwrap_or_default()),
            base_color_factor: Vec4::from(pbr.base_color_factor()),
            double_sided: material.double_sided(),
            unlit: material.unlit(),
            emissive,
            metallic: finite_or(pbr.metallic_factor(), 1.0).clamp(0.0, 1.0),
            roughness: finite_or(pbr.roughness_factor(), 1.0).clamp(0.0, 1.0),
            normal_scale: material
                .normal_texture()
                .map_or(1.0, |t| finite_or(t.scale(), 1.0)),
            occlusion_strength: material
                .occlusion_texture()
                .map_or(1.0, |t| finite_or(t.strength(), 1.0).clamp(0.0, 1.0)),
            dielectric_f0: extensions.dielectric_f0,
            specular_weight: extensions.specular_weight,
            clearcoat: extensions.clearcoat,
            clearcoat_roughness: extensions.clearcoat_roughness,
            clearcoat_normal_scale: extensions.clearcoat_normal_scale,
            ior: extensions.ior,
            transmission: extensions.transmission,
            thickness: extensions.thickness,
            attenuation_color: extensions.attenuation_color,
            attenuation_distance: extensions.attenuation_distance,
            sheen_color: extensions.sheen_color,
            sheen_roughness: extensions.sheen_roughness,
            ..Material::default()
        };
        if let Some(converted) = spec_gloss {
            out.base_color_factor = converted.base_color_factor;
            out.metallic = converted.metallic;
            out.roughness = converted.roughness;
        }
        // The meshes carry up to MESH_UV_MAPS sets of texture coordinates per material: the
        // first texture's (the base colour's when it has one), then the next different map's.
        // A texture reading yet another map is left out.
        let mut maps: MaterialUvMaps = [None; MESH_UV_MAPS];
        let mut normal_map = None;
        for (slot, source, map) in refs {
            if material.unlit() && slot != TextureSlot::BaseColor {
                // KHR_materials_unlit: every property but the base colour is a fallback for
                // viewers without the extension.
                continue;
            }
            let Some(set) = maps.iter().position(|m| m.is_none_or(|m| m == map)) else {
                self.info.warn(format!(
                    "material '{name}': the {} texture reads a third mapping of texture coordinates (set or transform); it is left out",
                    slot.name(),
                ));
                if slot == TextureSlot::Emissive {
                    out.emissive = Vec3::ZERO;
                }
                continue;
            };
            maps[set] = Some(map);
            let binding = match source {
                TextureSource::File(texture, color_space) => {
                    self.texture_binding(&texture, color_space)?
                }
                TextureSource::Made(binding) => Some(binding),
            };
            let binding = binding.map(|b| TextureBinding {
                texcoord: set as u32,
                ..b
            });
            if binding.is_some()
                && (slot == TextureSlot::Normal
                    || (slot == TextureSlot::ClearcoatNormal && normal_map.is_none()))
            {
                normal_map = Some(set);
            }
            match slot {
                TextureSlot::BaseColor => out.base_color_texture = binding,
                TextureSlot::Emissive => out.emissive_texture = binding,
                TextureSlot::MetallicRoughness => out.metallic_roughness_texture = binding,
                TextureSlot::Normal => out.normal_texture = binding,
                TextureSlot::Occlusion => out.occlusion_texture = binding,
                TextureSlot::Specular => out.specular_texture = binding,
                TextureSlot::SpecularColor => out.specular_color_texture = binding,
                TextureSlot::Clearcoat => out.clearcoat_texture = binding,
                TextureSlot::ClearcoatRoughness => out.clearcoat_roughness_texture = binding,
                TextureSlot::ClearcoatNormal => out.clearcoat_normal_texture = binding,
                TextureSlot::Transmission => out.transmission_texture = binding,
                TextureSlot::Thickness => out.thickness_texture = binding,
                TextureSlot::SheenColor => out.sheen_color_texture = binding,
                TextureSlot::SheenRoughness => out.sheen_roughness_texture = binding,
            }
        }
        self.material_uv.push(maps);
        self.material_normal_map.push(normal_map);
        out.alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                cutoff: material.alpha_cutoff().unwrap_or(0.5),
            },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        if material.unlit() {
            // The unlit shading adds emission: drop the fallback's.
            out.emissive = Vec3::ZERO;
        }
        Ok(out)
    }

    /// The glTF image `texture` shows (as patching the JSON found it), if any.
    fn texture_image(&self, texture: &gltf::texture::Texture) -> Option<usize> {
        self.patched
            .texture_images
            .get(texture.index())
            .copied()
            .flatten()
    }

    fn texture_binding(
        &mut self,
        texture: &gltf::texture::Texture,
        color_space: ColorSpace,
    ) -> Result<Option<TextureBinding>, LoadError> {
        let Some(image_index) = self.texture_image(texture) else {
            return Ok(None);
        };
        let texture_index = match self.image_textures.get(&(image_index, color_space)) {
            Some(&t) => t,
            None => {
                let t = self.image(image_index, color_space)?;
                self.image_textures.insert((image_index, color_space), t);
                t
            }
        };
        let Some(texture_index) = texture_index else {
            return Ok(None);
        };
        Ok(Some(TextureBinding {
            texture: texture_index,
            sampler: sampler_of(texture),
            texcoord: 0,
        }))
    }

    /// The decoded image of `texture` in `color_space`, with its size, for reading texels: the
    /// scene's texture when the image is loaded in that colour space, otherwise decoded here
    /// (charged to the budget) without adding it to the scene. `None` when the texture has no
    /// image or it cannot be loaded and the load is not strict (a warning says so).
    pub(super) fn source_image(
        &mut self,
        texture: &gltf::texture::Texture,
        color_space: ColorSpace,
    ) -> Result<Option<SourceImage>, LoadError> {
        let Some(image_index) = self.texture_image(texture) else {
            return Ok(None);
        };
        let loaded = match self.image_textures.get(&(image_index, color_space)) {
            Some(&loaded) => loaded,
            None => match self.read_image(image_index, color_space)? {
                None => None,
                Some(ReadImage::Loaded(t)) => Some(t),
                Some(ReadImage::Decoded { texture, size, .. }) => {
                    return Ok(Some(SourceImage {
                        texture: Arc::from(texture),
                        size,
                    }))
                }
            },
        };
        Ok(loaded.and_then(|t| {
            Some(SourceImage {
                texture: self.scene.textures.get(t)?.clone(),
                size: *self.info.texture_sizes.get(t)?,
            })
        }))
    }

    /// Loads one glTF image as a texture of `color_space` into the scene (once per distinct
    /// encoded image and colour space); `None` when it is missing or cannot be decoded and the
    /// load is not strict (a warning says so). Budget overruns are always errors.
    fn image(&mut self, index: usize, color_space: ColorSpace) -> Result<Option<usize>, LoadError> {
        Ok(match self.read_image(index, color_space)? {
            None => None,
            Some(ReadImage::Loaded(t)) => Some(t),
            Some(ReadImage::Decoded {
                texture,
                encoded,
                size,
            }) => {
                let t = self.push_texture(*texture, size);
                self.encoded_images.insert((encoded, color_space), t);
                Some(t)
            }
        })
    }

    /// Reads and decodes one glTF image as a texture of `color_space`, or finds it among the
    /// scene's textures when identical encoded bytes were loaded before; `None` when it is
    /// missing or cannot be decoded and the load is not strict (a warning says so). Budget
    /// overruns are always errors.
    fn read_image(
        &mut self,
        index: usize,
        color_space: ColorSpace,
    ) -> Result<Option<ReadImage>, LoadError> {
        let Some(image) = self.document.images().nth(index) else {
            return Ok(None);
        };
        let mut what = format!("image {index}");
        if let Some(name) = image.name() {
            what = format!("{what} ('{name}')");
        }
        let loaded = match image.source() {
            gltf::image::Source::View { view, mime_type } => {
                let data = BufferData {
                    buffers: self.buffers,
                    decoded_views: self.decoded_views,
                };
                data.view(&view)
                    .map(|b| (b.to_vec(), Some(mime_type.to_string())))
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                if !uri.starts_with("data:") {
                    what = format!("{what} from '{uri}'");
                }
                read_uri(self.path, uri, self.policy, &mut self.budget)
                    .map(|b| (b, mime_type.map(str::to_string)))
            }
        };
        let (bytes, mime_type) = match loaded {
            Ok(loaded) => loaded,
            Err(e) if e.contains("memory budget") => {
                return Err(self.invalid(format!("{what}: {e}")))
            }
            Err(e) => return self.texture_problem(format!("{what}: {e}")),
        };
        let key = (bytes, color_space);
        if let Some(&t) = self.encoded_images.get(&key) {
            return Ok(Some(ReadImage::Loaded(t)));
        }
        let bytes = key.0;
        let size = match image_size(&bytes, mime_type.as_deref()) {
            Ok(size) => size,
            Err(ImageError::Budget(e) | ImageError::Decode(e)) => {
                return self.texture_problem(format!("{what}: {e}"))
            }
        };
        if !self.options.decode_textures {
            // Describing the scene: the header's size is reported, nothing is decoded.
            return Ok(Some(ReadImage::Decoded {
                texture: Box::new(placeholder()),
                encoded: bytes,
                size,
            }));
        }
        let note = crate::ktx2_image::color_space_note(&bytes, color_space)
            .or_else(|| crate::dds_image::color_space_note(&bytes, color_space));
        if let Some(note) = note {
            self.info.warn(format!("{what}: {note}"));
        }
        match decode_within(&bytes, mime_type.as_deref(), color_space, &mut self.budget) {
            Ok(texture) => Ok(Some(ReadImage::Decoded {
                texture: Box::new(texture),
                encoded: bytes,
                size,
            })),
            Err(ImageError::Budget(e)) => Err(self.invalid(format!("{what}: {e}"))),
            Err(ImageError::Decode(e)) => self.texture_problem(format!("{what}: {e}")),
        }
    }

    /// Adds a texture to the scene, with the size `kantele info` reports; its index.
    pub(super) fn push_texture(&mut self, texture: Texture, size: (u32, u32)) -> usize {
        self.scene.textures.push(Arc::new(texture));
        self.info.texture_sizes.push(size);
        self.scene.textures.len() - 1
    }

    /// A texture that cannot be loaded: an error when strict, otherwise a warning and no
    /// texture.
    pub(super) fn texture_problem<T>(&mut self, message: String) -> Result<Option<T>, LoadError> {
        if self.options.strict {
            return Err(self.invalid(message));
        }
        self.info.warn(format!(
            "{message}; drawn untextured (--strict makes this an error)"
        ));
        Ok(None)
    }

    pub(super) fn default_material(&mut self) -> usize {
        *self.default_material.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            self.scene.materials.len() - 1
        })
    }
}

/// The sampler of a glTF texture (glTF's defaults where the file gives none: REPEAT, bilinear
/// magnification, trilinear minification).
pub(super) fn sampler_of(texture: &gltf::texture::Texture) -> Sampler {
    let s = texture.sampler();
    let wrap = |mode| match mode {
        gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
    };
    Sampler {
        wrap_s: wrap(s.wrap_s()),
        wrap_t: wrap(s.wrap_t()),
        mag_filter: match s.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
            Some(gltf::texture::MagFilter::Linear) | None => Filter::Linear,
        },
        min_filter: match s.min_filter() {
            Some(gltf::texture::MinFilter::Nearest) => MinFilter::Nearest,
            Some(gltf::texture::MinFilter::Linear) => MinFilter::Linear,
            Some(gltf::texture::MinFilter::NearestMipmapNearest) => MinFilter::NearestMipmapNearest,
            Some(gltf::texture::MinFilter::LinearMipmapNearest) => MinFilter::LinearMipmapNearest,
            Some(gltf::texture::MinFilter::NearestMipmapLinear) => MinFilter::NearestMipmapLinear,
            Some(gltf::texture::MinFilter::LinearMipmapLinear) | None => {
                MinFilter::LinearMipmapLinear
            }
        },
    }
}
