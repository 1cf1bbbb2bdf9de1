//! The material extensions read from a material's JSON: `KHR_materials_ior`,
//! `KHR_materials_specular`, `KHR_materials_clearcoat`, `KHR_materials_transmission`,
//! `KHR_materials_volume` and `KHR_materials_sheen` — their factors, and their textures with
//! the colour space and texture coordinates each reads.

use glam::Vec3;
use kantele_rules::shade::texture::ColorSpace;
use serde_json::Value;

use super::material::{json_texture_reference, TextureSlot, UvMap};
use super::Loader;

/// What the extensions give a material (the glTF defaults where it has none).
pub(super) struct MaterialExtensions<'a> {
    /// `((ior − 1) / (ior + 1))² × specularColorFactor`.
    pub(super) dielectric_f0: Vec3,
    /// `specularFactor`.
    pub(super) specular_weight: f32,
    /// `clearcoatFactor`.
    pub(super) clearcoat: f32,
    /// `clearcoatRoughnessFactor`.
    pub(super) clearcoat_roughness: f32,
    /// `clearcoatNormalTexture.scale`.
    pub(super) clearcoat_normal_scale: f32,
    /// `ior` (1.5 without the extension).
    pub(super) ior: f32,
    /// `transmissionFactor`.
    pub(super) transmission: f32,
    /// `thicknessFactor` (0 without `KHR_materials_volume`).
    pub(super) thickness: f32,
    /// `attenuationColor`.
    pub(super) attenuation_color: Vec3,
    /// `attenuationDistance` (infinite without it).
    pub(super) attenuation_distance: f32,
    /// `sheenColorFactor` (black without `KHR_materials_sheen`).
    pub(super) sheen_color: Vec3,
    /// `sheenRoughnessFactor`.
    pub(super) sheen_roughness: f32,
    /// The extensions' textures.
    pub(super) textures: Vec<(TextureSlot, gltf::texture::Texture<'a>, ColorSpace, UvMap)>,
}

/// `((ior − 1) / (ior + 1))²`, computed in `f64` so that IOR 1.5 gives 0.04 as `f32` exactly
/// (the reflectance of the core model).
fn f0_of_ior(ior: f64) -> f32 {
    (((ior - 1.0) / (ior + 1.0)).powi(2)) as f32
}

/// `value[key]` as an RGB colour of finite numbers, else `default`.
fn color_of(value: Option<&Value>, key: &str, default: Vec3) -> Vec3 {
    value
        .and_then(|v| v.get(key))
        .and_then(Value::as_array)
        .and_then(|a| {
            let c = |i: usize| a.get(i)?.as_f64().filter(|v| v.is_finite());
            Some(Vec3::new(c(0)? as f32, c(1)? as f32, c(2)? as f32))
        })
        .unwrap_or(default)
}

/// `value[key]` as a finite number, else `default`.
fn number(value: Option<&Value>, key: &str, default: f64) -> f64 {
    value
        .and_then(|v| v.get(key))
        .and_then(Value::as_f64)
        .filter(|v| v.is_finite())
        .unwrap_or(default)
}

impl<'a> Loader<'a> {
    /// The extensions of `material` (named `name` in warnings). Out-of-range values become
    /// the nearest valid ones (an IOR below 1 the default 1.5, with a warning); a texture
    /// reference to no texture is left out with a warning.
    pub(super) fn material_extensions(
        &mut self,
        material: &gltf::Material<'a>,
        name: &str,
    ) -> MaterialExtensions<'a> {
        let ior_extension = material.extension_value("KHR_materials_ior");
        let mut ior = number(ior_extension, "ior", 1.5);
        if ior < 1.0 {
            self.info.warn(format!(
                "material '{name}': KHR_materials_ior's ior {ior} is below 1; 1.5 is used"
            ));
            ior = 1.5;
        }
        let specular = material.extension_value("KHR_materials_specular");
        let color = specular
            .and_then(|s| s.get("specularColorFactor"))
            .and_then(Value::as_array)
            .and_then(|a| {
                let c = |i: usize| a.get(i)?.as_f64().filter(|v| v.is_finite() && *v >= 0.0);
                Some(Vec3::new(c(0)? as f32, c(1)? as f32, c(2)? as f32))
            })
            .unwrap_or(Vec3::ONE);
        let clearcoat = material.extension_value("KHR_materials_clearcoat");
        let transmission = material.extension_value("KHR_materials_transmission");
        // KHR_materials_volume only applies under transmission (or diffuse transmission).
        let volume = material
            .extension_value("KHR_materials_volume")
            .filter(|_| transmission.is_some());
        let attenuation_color =
            color_of(volume, "attenuationColor", Vec3::ONE).clamp(Vec3::ZERO, Vec3::ONE);
        let sheen = material.extension_value("KHR_materials_sheen");
        let attenuation_distance = number(volume, "attenuationDistance", f64::INFINITY);
        let mut out = MaterialExtensions {
            dielectric_f0: Vec3::splat(f0_of_ior(ior)) * color,
            specular_weight: number(specular, "specularFactor", 1.0).clamp(0.0, 1.0) as f32,
            clearcoat: number(clearcoat, "clearcoatFactor", 0.0).clamp(0.0, 1.0) as f32,
            clearcoat_roughness: number(clearcoat, "clearcoatRoughnessFactor", 0.0).clamp(0.0, 1.0)
                as f32,
            clearcoat_normal_scale: number(
                clearcoat.and_then(|c| c.get("clearcoatNormalTexture")),
                "scale",
                1.0,
            ) as f32,
            ior: ior as f32,
            transmission: number(transmission, "transmissionFactor", 0.0).clamp(0.0, 1.0) as f32,
            thickness: number(volume, "thicknessFactor", 0.0).max(0.0) as f32,
            attenuation_color,
            attenuation_distance: if attenuation_distance > 0.0 {
                attenuation_distance as f32
            } else {
                f32::INFINITY
            },
            sheen_color: color_of(sheen, "sheenColorFactor", Vec3::ZERO)
                .clamp(Vec3::ZERO, Vec3::ONE),
            sheen_roughness: number(sheen, "sheenRoughnessFactor", 0.0).clamp(0.0, 1.0) as f32,
            textures: Vec::new(),
        };
        let references = [
            (
                specular,
                "specularTexture",
                TextureSlot::Specular,
                ColorSpace::Linear,
            ),
            (
                specular,
                "specularColorTexture",
                TextureSlot::SpecularColor,
                ColorSpace::Srgb,
            ),
            (
                clearcoat,
                "clearcoatTexture",
                TextureSlot::Clearcoat,
                ColorSpace::Linear,
            ),
            (
                clearcoat,
                "clearcoatRoughnessTexture",
                TextureSlot::ClearcoatRoughness,
                ColorSpace::Linear,
            ),
            (
                clearcoat,
                "clearcoatNormalTexture",
                TextureSlot::ClearcoatNormal,
                ColorSpace::Linear,
            ),
            (
                transmission,
                "transmissionTexture",
                TextureSlot::Transmission,
                ColorSpace::Linear,
            ),
            (
                volume,
                "thicknessTexture",
                TextureSlot::Thickness,
                ColorSpace::Linear,
            ),
            (
                sheen,
                "sheenColorTexture",
                TextureSlot::SheenColor,
                ColorSpace::Srgb,
            ),
            (
                sheen,
                "sheenRoughnessTexture",
                TextureSlot::SheenRoughness,
                ColorSpace::Linear,
            ),
        ];
        for (extension, key, slot, color_space) in references {
            let Some(info) = extension.and_then(|e| e.get(key)) else {
                continue;
            };
            let Some((texture, uv)) = json_texture_reference(self.document, info) else {
                self.info.warn(format!(
                    "material '{name}': the {} texture refers to no texture; it is left out",
                    slot.name()
                ));
                continue;
            };
            out.textures.push((slot, texture, color_space, uv));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// IOR 1.5 is the core model's 0.04 to the bit; IOR 1 reflects nothing.
    #[test]
    fn ior_gives_the_core_reflectance() {
        assert_eq!(f0_of_ior(1.5), kantele_rules::shade::pbr::DIELECTRIC_F0);
        assert_eq!(f0_of_ior(1.0), 0.0);
        assert!((f0_of_ior(1.33) - 0.020_059).abs() < 1e-6);
    }
}
