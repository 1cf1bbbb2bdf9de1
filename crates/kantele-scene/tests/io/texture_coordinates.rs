//! Texture coordinate sets and tangents as the glTF loader gives them: each texture's own
//! `texCoord` and transform (two different ones per material, a third left out with a
//! warning), the file's `TANGENT`, and MikkTSpace tangents where a normal-mapped primitive has
//! none.

use crate::common::*;
use glam::{Vec2, Vec4};
use kantele::scene::Shading;
use kantele_scene::{load_scene, load_scene_with, LoadOptions, LoadedScene};
use serde_json::{json, Value};

/// The common textured quad with `material` on its primitive and `extra` attributes.
fn quad_with(material: Value, extra: &[(&str, usize)], g: &mut Gltf) {
    g.json["materials"][0] = material;
    for (name, accessor) in extra {
        g.json["meshes"][0]["primitives"][0]["attributes"][*name] = json!(accessor);
    }
}

fn load(g: &Gltf, name: &str) -> LoadedScene {
    let dir = temp_dir("texture-coordinates");
    let path = dir.join(format!("{name}.glb"));
    g.write_glb(&path);
    load_scene(&path).unwrap_or_else(|e| panic!("{name} should load: {e}"))
}

/// A normal texture without the file's tangents: MikkTSpace gives the quad (u along +x, v along
/// −y) the tangent +x with w = +1, so the bitangent n × t = +y points up the image. Only PBR
/// shading reads tangents: the quad drawn as a (Lambert) reference scene gets none.
#[test]
fn a_normal_texture_without_tangents_gets_mikktspace_tangents() {
    let mut g = textured_quad();
    quad_with(
        json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 0}}),
        &[],
        &mut g,
    );
    let path = temp_dir("texture-coordinates").join("generated.glb");
    g.write_glb(&path);
    let lambert = load_scene(&path).expect("loads");
    assert!(lambert.scene.meshes[0].tangents.is_none());
    let pbr = LoadOptions {
        shading: Some(Shading::Pbr),
        ..LoadOptions::default()
    };
    let loaded = load_scene_with(&path, &pbr).expect("loads");
    let mesh = &loaded.scene.meshes[0];
    let tangents = mesh.tangents.as_ref().expect("tangents");
    assert_eq!(tangents.len(), mesh.positions.len());
    for t in tangents {
        assert!(t.abs_diff_eq(Vec4::new(1.0, 0.0, 0.0, 1.0), 1e-6), "{t}");
    }
    assert!(
        loaded.info.warnings.is_empty(),
        "{:?}",
        loaded.info.warnings
    );
    // Without a normal texture, no tangents.
    let plain = load(&textured_quad(), "plain");
    assert!(plain.scene.meshes[0].tangents.is_none());
}

/// The file's tangents are used as they are.
#[test]
fn the_files_tangents_are_kept() {
    let mut g = textured_quad();
    let bytes: Vec<u8> = [0.0f32, 1.0, 0.0, -1.0]
        .repeat(4)
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let tangents = g.accessor(&bytes, FLOAT, "VEC4", 4, false);
    quad_with(
        json!({"normalTexture": {"index": 0}}),
        &[("TANGENT", tangents)],
        &mut g,
    );
    let loaded = load(&g, "file-tangents");
    let mesh = &loaded.scene.meshes[0];
    assert_eq!(
        mesh.tangents.as_deref(),
        Some(&[Vec4::new(0.0, 1.0, 0.0, -1.0); 4][..])
    );
}

/// An emissive texture on `TEXCOORD_1` reads the mesh's second set; the base colour keeps the
/// first; an occlusion texture reading `TEXCOORD_0` through a transform, a third mapping, is
/// left out with a warning.
#[test]
fn textures_on_another_set_read_the_second_set() {
    let mut g = textured_quad();
    let second = g.vec2(&[[0.5, 0.5], [0.75, 0.5], [0.75, 0.25], [0.5, 0.25]]);
    quad_with(
        json!({
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
            "emissiveTexture": {"index": 0, "texCoord": 1},
            "emissiveFactor": [1.0, 1.0, 1.0],
            "occlusionTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.0]}}},
        }),
        &[("TEXCOORD_1", second)],
        &mut g,
    );
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_texture_transform"]);
    let loaded = load(&g, "second-set");
    let mesh = &loaded.scene.meshes[0];
    let material = &loaded.scene.materials[mesh.material];
    let emissive = material.emissive_texture.expect("emissive");
    assert_eq!(emissive.texcoord, 1);
    assert_eq!(material.base_color_texture.expect("base").texcoord, 0);
    assert_eq!(
        mesh.texcoords1.as_deref(),
        Some(
            &[
                Vec2::new(0.5, 0.5),
                Vec2::new(0.75, 0.5),
                Vec2::new(0.75, 0.25),
                Vec2::new(0.5, 0.25)
            ][..]
        )
    );
    assert_eq!(
        mesh.texcoords.as_ref().expect("texcoords")[0],
        Vec2::new(0.0, 1.0)
    );
    // The occlusion texture's transform is a third mapping: left out, and said.
    assert!(material.occlusion_texture.is_none());
    assert!(
        loaded
            .info
            .warnings
            .iter()
            .any(|w| w.contains("occlusion") && w.contains("third")),
        "{:?}",
        loaded.info.warnings
    );
}

/// A second set the primitive lacks leaves the mesh without it (the texture reads (0, 0)),
/// as a missing first set always has.
#[test]
fn a_missing_second_set_is_absent() {
    let mut g = textured_quad();
    quad_with(
        json!({
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
            "occlusionTexture": {"index": 0, "texCoord": 1},
        }),
        &[],
        &mut g,
    );
    let loaded = load(&g, "missing-second-set");
    let mesh = &loaded.scene.meshes[0];
    assert!(mesh.texcoords1.is_none());
    assert!(mesh.texcoords.is_some());
}
