//! `KHR_materials_pbrSpecularGlossiness`: factors and textures converted to metallic-roughness
//! at load (written files), the fallbacks, and the Khronos sample that shows one bottle in both
//! models (`$KANTELE_SHARED/realworld`).

use std::path::Path;

use crate::common::*;
use glam::{Vec3, Vec4};
use kantele::scene::{Material, Scene};
use kantele::shade::spec_gloss::{to_metallic_roughness, SpecularGlossiness};
use kantele::shade::texture::{ColorSpace, Texture};
use kantele_scene::{load_scene, LoadedScene};
use serde_json::{json, Value};

const EXTENSION: &str = "KHR_materials_pbrSpecularGlossiness";

fn load(path: &Path) -> LoadedScene {
    load_scene(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

/// The textured quad with `material` as its only material, using the extension.
fn quad_with(material: Value, dir_name: &str) -> LoadedScene {
    let mut g = textured_quad();
    g.json["materials"] = json!([material]);
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", EXTENSION]);
    let path = temp_dir(dir_name).join("quad.glb");
    g.write_glb(&path);
    let loaded = load(&path);
    assert!(
        !loaded.info.ignored.iter().any(|i| i == EXTENSION),
        "{EXTENSION} reported as ignored: {:?}",
        loaded.info.ignored
    );
    loaded
}

fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
    scene
        .materials
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("material {name}"))
}

fn texture(scene: &Scene, index: Option<usize>) -> &Texture {
    let index = index.expect("a texture");
    &scene.textures[index]
}

fn mean(texture: &Texture) -> Vec4 {
    let level = texture.level(0).expect("level 0");
    let mut sum = Vec4::ZERO;
    for y in 0..level.height {
        for x in 0..level.width {
            sum += level.texel(x, y);
        }
    }
    sum / (level.width * level.height) as f32
}

#[test]
fn factors_convert_to_factors_and_win_over_metallic_roughness() {
    let gold = [1.0, 0.766, 0.336];
    let loaded = quad_with(
        json!({
            "name": "gold",
            "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
            "extensions": {EXTENSION: {
                "diffuseFactor": [0.0, 0.0, 0.0, 0.5],
                "specularFactor": gold,
                "glossinessFactor": 0.75,
            }},
        }),
        "specgloss-factors",
    );
    let m = material(&loaded.scene, "gold");
    assert!((m.metallic - 1.0).abs() < 1e-3, "metallic {}", m.metallic);
    assert!(
        (m.roughness - 0.25).abs() < 1e-6,
        "roughness {}",
        m.roughness
    );
    let base = m.base_color_factor;
    assert!(
        (base.truncate() - Vec3::from(gold)).abs().max_element() < 2e-3,
        "base {base}"
    );
    assert_eq!(base.w, 0.5, "the diffuse alpha");
    assert!(m.base_color_texture.is_none() && m.metallic_roughness_texture.is_none());
}

#[test]
fn textures_convert_texel_by_texel_to_the_larger_size() {
    let mut g = textured_quad();
    // The quad's 2 × 2 image is the diffuse texture (texture 0); a 1 × 1 specular-glossiness
    // texture: specular sRGB 200, glossiness 0.6.
    let sg_image = g.image(png(1, 1, &[200, 200, 200, 153]));
    let sg_texture = g.texture(json!({"source": sg_image}));
    let transform = json!({"KHR_texture_transform": {"offset": [0.5, 0.0]}});
    g.json["materials"] = json!([{
        "name": "textured",
        "extensions": {EXTENSION: {
            "diffuseFactor": [1.0, 1.0, 1.0, 0.5],
            "diffuseTexture": {"index": 0, "extensions": transform},
            "specularFactor": [0.5, 0.5, 0.5],
            "specularGlossinessTexture": {"index": sg_texture, "extensions": transform},
        }},
    }]);
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", EXTENSION, "KHR_texture_transform"]);
    let path = temp_dir("specgloss-textures").join("quad.glb");
    g.write_glb(&path);
    let loaded = load(&path);
    let scene = &loaded.scene;
    let m = material(scene, "textured");
    assert_eq!(m.base_color_factor, Vec4::new(1.0, 1.0, 1.0, 0.5));
    assert_eq!((m.metallic, m.roughness), (1.0, 1.0));
    let base = texture(scene, m.base_color_texture.map(|b| b.texture));
    let mr = texture(scene, m.metallic_roughness_texture.map(|b| b.texture));
    assert_eq!(base.source_color_space(), ColorSpace::Srgb);
    assert_eq!(mr.source_color_space(), ColorSpace::Linear);
    assert_eq!((base.width(), base.height()), (2, 2));
    assert_eq!((mr.width(), mr.height()), (2, 2));
    // Texel by texel, the rules' conversion of the decoded sources (the red texel at the
    // top-left, the white one at the bottom-right).
    let specular = Vec3::splat(0.5 * kantele::color::srgb_to_linear(200.0 / 255.0));
    for (x, y, diffuse) in [(0, 0, Vec3::X), (1, 1, Vec3::ONE)] {
        let expected = to_metallic_roughness(SpecularGlossiness {
            diffuse,
            specular,
            glossiness: 0.6,
        });
        let b = base.level(0).expect("level 0").texel(x, y);
        let r = mr.level(0).expect("level 0").texel(x, y);
        assert!(
            (b.truncate() - expected.base_color).abs().max_element() < 0.01,
            "texel ({x}, {y}): base {b}, expected {}",
            expected.base_color
        );
        assert!(
            (r.y - expected.roughness).abs() < 0.003,
            "roughness {}",
            r.y
        );
        assert!((r.z - expected.metallic).abs() < 0.003, "metallic {}", r.z);
    }
    // The texture transform is applied to the mesh's coordinates, as for any texture.
    let uv = scene.meshes[0].texcoords.as_ref().expect("texcoords");
    assert_eq!(uv[0].x, 0.5);
}

#[test]
fn textures_reading_different_coordinates_fall_back_to_the_factors() {
    let loaded = quad_with(
        json!({
            "name": "split",
            "extensions": {EXTENSION: {
                "diffuseFactor": [0.5, 0.5, 0.5, 1.0],
                "diffuseTexture": {"index": 0},
                "specularFactor": [0.0, 0.0, 0.0],
                "specularGlossinessTexture": {"index": 0, "texCoord": 1},
            }},
        }),
        "specgloss-split",
    );
    let m = material(&loaded.scene, "split");
    assert!(m.base_color_texture.is_none() && m.metallic_roughness_texture.is_none());
    assert_eq!(m.metallic, 0.0);
    assert!((m.base_color_factor.x - 0.5 / 0.96).abs() < 1e-5);
    let warnings: Vec<_> = (loaded.info.warnings.iter())
        .filter(|w| w.contains(EXTENSION))
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("different texture coordinates"));
}

#[test]
fn a_missing_texture_and_malformed_factors_give_warnings() {
    let loaded = quad_with(
        json!({
            "name": "broken",
            "extensions": {EXTENSION: {
                "diffuseFactor": "red",
                "diffuseTexture": {"index": 99},
            }},
        }),
        "specgloss-broken",
    );
    let m = material(&loaded.scene, "broken");
    assert!(m.base_color_texture.is_none());
    // Defaults: white diffuse and white specular, a white metal.
    assert!((m.metallic - 1.0).abs() < 1e-4, "metallic {}", m.metallic);
    let warnings = loaded.info.warnings.join("\n");
    assert!(
        warnings.contains("diffuseFactor is malformed"),
        "{warnings}"
    );
    assert!(
        warnings.contains("diffuseTexture names no texture"),
        "{warnings}"
    );
}

#[test]
fn the_sample_bottle_converts_to_textures_like_its_metallic_roughness_twin() {
    let Some(dir) = kantele_testkit::shared_dir("realworld") else {
        return;
    };
    let path = dir.join("pbr/SpecGlossVsMetalRough/SpecGlossVsMetalRough.gltf");
    if !path.is_file() {
        kantele_testkit::skip("realworld", format!("{} is absent", path.display()));
        return;
    }
    let loaded = load(&path);
    assert!(!loaded.info.ignored.iter().any(|i| i == EXTENSION));
    let scene = &loaded.scene;
    let spec_gloss = material(scene, "BottleMat_SpecGloss");
    let metal_rough = material(scene, "BottleMat_MR");
    assert_eq!(spec_gloss.base_color_factor, Vec4::ONE);
    assert_eq!((spec_gloss.metallic, spec_gloss.roughness), (1.0, 1.0));
    let converted_base = texture(scene, spec_gloss.base_color_texture.map(|b| b.texture));
    let converted_mr = texture(
        scene,
        spec_gloss.metallic_roughness_texture.map(|b| b.texture),
    );
    let twin_base = texture(scene, metal_rough.base_color_texture.map(|b| b.texture));
    let twin_mr = texture(
        scene,
        metal_rough.metallic_roughness_texture.map(|b| b.texture),
    );
    assert_eq!(
        (converted_base.width(), converted_base.height()),
        (2048, 2048)
    );
    assert_eq!((converted_mr.width(), converted_mr.height()), (2048, 2048));
    // The two bottles were authored as one material: on average the converted textures come
    // close to the twin's.
    let (a, b) = (mean(converted_base), mean(twin_base));
    assert!(
        (a - b).truncate().abs().max_element() < 0.05,
        "mean base colour {a} against {b}"
    );
    let (a, b) = (mean(converted_mr), mean(twin_mr));
    assert!(
        (a.y - b.y).abs() < 0.05,
        "mean roughness {} against {}",
        a.y,
        b.y
    );
    assert!(
        (a.z - b.z).abs() < 0.1,
        "mean metallic {} against {}",
        a.z,
        b.z
    );
    // The label: no specular and no glossiness, a rough dielectric.
    let label = material(scene, "Label Material SpecGloss");
    let label_mr = texture(scene, label.metallic_roughness_texture.map(|b| b.texture));
    let m = mean(label_mr);
    assert!(
        m.z < 0.01 && m.y > 0.99,
        "label metallic {}, roughness {}",
        m.z,
        m.y
    );
}
