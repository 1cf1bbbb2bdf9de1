//! The specular-glossiness material model (glTF's `KHR_materials_pbrSpecularGlossiness`)
//! converted to the metallic-roughness model that Kantele shades, one material point at a time.
//!
//! The conversion is the one the Khronos Group published with the extension:
//! `ConvertToMetallicRoughness` in the glTF repository's
//! `extensions/2.0/Archived/KHR_materials_pbrSpecularGlossiness/examples/convert-between-workflows/js/three.pbrUtilities.js`
//! (the same file for Babylon.js, `convert-between-workflows-bjs/js/babylon.pbrUtilities.js`,
//! and Babylon.js's glTF exporter use the same formula). With `F0 = 0.04` the reflectance of
//! dielectrics ([`DIELECTRIC_F0`]), `brightness(c) = √(0.299 r² + 0.587 g² + 0.114 b²)` and
//! `s = 1 − max(specular.r, specular.g, specular.b)`:
//!
//! - `roughness = 1 − glossiness`.
//! - `metallic = 0` when `brightness(specular) < F0`; otherwise the root in [0, 1] of
//!   `F0 m² + (brightness(diffuse) × s / (1 − F0) + brightness(specular) − 2 F0) m +
//!   (F0 − brightness(specular)) = 0`, clamped to [0, 1]. It is the metallic at which a grey
//!   metallic-roughness material with that base colour would have had this diffuse and specular
//!   brightness (the inverse of `specular = F0 + (base − F0) m`,
//!   `diffuse = base (1 − F0)(1 − m) / (1 − max(specular))`).
//! - `base = lerp(diffuse × s / (1 − F0) / max(1 − m, ε), (specular − F0 (1 − m)) / max(m, ε), m²)`
//!   with `ε = 10⁻⁶`, clamped to [0, 1] per channel: the base colour that the diffuse colour
//!   implies for a dielectric, blended towards the one that the specular colour implies for a
//!   metal as the material becomes metallic.
//!
//! The conversion is exact for grey materials that came from the metallic-roughness model and an
//! approximation for coloured ones (metallic is solved from brightness, not per channel). Alpha
//! (the diffuse colour's) carries over unchanged and is not an input here.

use glam::Vec3;

use super::pbr::DIELECTRIC_F0;

/// Guards the two divisions of the base colour blend, as the published conversion does.
const EPSILON: f32 = 1e-6;

/// One point of a specular-glossiness material, every value linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularGlossiness {
    /// Diffuse colour (`diffuseFactor` × the decoded `diffuseTexture`), RGB.
    pub diffuse: Vec3,
    /// Specular colour (`specularFactor` × the decoded RGB of `specularGlossinessTexture`).
    pub specular: Vec3,
    /// Glossiness (`glossinessFactor` × the alpha of `specularGlossinessTexture`).
    pub glossiness: f32,
}

/// One point of a metallic-roughness material, every value linear and in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetallicRoughness {
    /// Base colour, RGB.
    pub base_color: Vec3,
    /// Metallic.
    pub metallic: f32,
    /// Perceptual roughness.
    pub roughness: f32,
}

/// Converts a specular-glossiness point to metallic-roughness by the formula of the module
/// documentation (the Khronos sample conversion). Inputs are first clamped to [0, 1] (NaN
/// becomes 0), so the result is always finite and in [0, 1].
pub fn to_metallic_roughness(point: SpecularGlossiness) -> MetallicRoughness {
    let unit = |c: f32| if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    let diffuse = point.diffuse.to_array().map(unit);
    let specular = point.specular.to_array().map(unit);
    let (diffuse, specular) = (Vec3::from(diffuse), Vec3::from(specular));
    let glossiness = unit(point.glossiness);

    let one_minus_specular_strength = 1.0 - specular.max_element();
    let metallic = solve_metallic(
        perceived_brightness(diffuse),
        perceived_brightness(specular),
        one_minus_specular_strength,
    );
    let from_diffuse = diffuse
        * (one_minus_specular_strength / (1.0 - DIELECTRIC_F0) / (1.0 - metallic).max(EPSILON));
    let from_specular =
        (specular - Vec3::splat(DIELECTRIC_F0 * (1.0 - metallic))) / metallic.max(EPSILON);
    // lerp(a, b, t) written as a (1 − t) + b t: exact at t = 0 and t = 1, where the unused
    // colour may be around 1 / ε.
    let t = metallic * metallic;
    let base = from_diffuse * (1.0 - t) + from_specular * t;
    MetallicRoughness {
        base_color: base.clamp(Vec3::ZERO, Vec3::ONE),
        metallic,
        roughness: 1.0 - glossiness,
    }
}

/// `√(0.299 r² + 0.587 g² + 0.114 b²)`: the brightness the conversion compares.
fn perceived_brightness(c: Vec3) -> f32 {
    (0.299 * c.x * c.x + 0.587 * c.y * c.y + 0.114 * c.z * c.z).sqrt()
}

/// The metallic whose metallic-roughness material has these diffuse and specular brightnesses:
/// the larger root of the quadratic of the module documentation, clamped to [0, 1]; 0 below the
/// dielectric reflectance.
fn solve_metallic(diffuse: f32, specular: f32, one_minus_specular_strength: f32) -> f32 {
    if specular < DIELECTRIC_F0 {
        return 0.0;
    }
    let a = DIELECTRIC_F0;
    let b = diffuse * one_minus_specular_strength / (1.0 - DIELECTRIC_F0) + specular
        - 2.0 * DIELECTRIC_F0;
    let c = DIELECTRIC_F0 - specular;
    let discriminant = (b * b - 4.0 * a * c).max(0.0);
    ((-b + discriminant.sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
}

#[cfg(test)]
#[path = "spec_gloss_tests.rs"]
mod tests;
