//! Valid glTF that the `gltf` crate alone would reject, and KHR_mesh_quantization's attribute
//! types: each loads with the values the spec defines.

mod common;

use common::*;
use glam::{Vec2, Vec3, Vec4};
use kantele_io::load_scene;
use serde_json::json;

fn write(g: &Gltf, name: &str) -> std::path::PathBuf {
    let path = temp_dir(name).join(format!("{name}.glb"));
    g.write_glb(&path);
    path
}

#[test]
fn scene_without_nodes_is_empty() {
    let mut g = Gltf::new();
    g.json["scenes"] = json!([{"name": "empty"}]);
    let loaded = load_scene(&write(&g, "no-nodes")).expect("valid glTF");
    assert!(loaded.scene.draws.is_empty());
}

#[test]
fn accessor_without_buffer_view_is_zero_filled() {
    let mut g = Gltf::new();
    let p = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.json["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"componentType": 5126, "type": "VEC2", "count": 3}));
    let t = g.json["accessors"].as_array().unwrap().len() - 1;
    let mesh = g.mesh(
        "m",
        vec![json!({"attributes": {"POSITION": p, "TEXCOORD_0": t}})],
    );
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    let loaded = load_scene(&write(&g, "no-view")).expect("valid glTF");
    let mesh = &loaded.scene.meshes[0];
    assert!(mesh
        .texcoords
        .as_ref()
        .unwrap()
        .iter()
        .all(|t| *t == Vec2::ZERO));
}

#[test]
fn texture_without_source_and_ignored_animations() {
    let mut g = textured_quad();
    g.json["textures"][0] = json!({"sampler": 0});
    g.json["animations"] = json!([{
        "channels": [{"sampler": 0, "target": {"path": "pointer", "extensions": {"KHR_animation_pointer": {"pointer": "/x"}}}}],
        "samplers": [{"input": 0, "output": 0}]
    }]);
    let loaded = load_scene(&write(&g, "no-source")).expect("valid glTF");
    assert!(loaded.scene.materials[0].base_color_texture.is_none());
    let warnings = loaded.info.warnings.join("\n");
    assert!(warnings.contains("texture 0 has no image"), "{warnings}");
    assert!(warnings.contains("animations"), "{warnings}");
    // Every ignored feature is named in one line.
    assert_eq!(
        loaded
            .info
            .warnings
            .iter()
            .filter(|w| w.starts_with("ignored"))
            .count(),
        1,
        "{warnings}"
    );
}

#[test]
fn draco_is_refused_by_name_even_when_not_required() {
    let mut g = textured_quad();
    g.json["meshes"][0]["primitives"][0]["extensions"] =
        json!({"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}});
    let err = load_scene(&write(&g, "draco"))
        .expect_err("refused")
        .to_string();
    assert!(err.contains("KHR_draco_mesh_compression"), "{err}");
    assert_eq!(err.lines().count(), 1);
}

/// Little-endian bytes of i16 / u16 / i8 / u8 values.
fn bytes_i16(v: &[i16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
fn bytes_u16(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[test]
fn quantized_attributes_of_every_allowed_type() {
    let mut g = Gltf::new();
    g.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    g.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    // Positions: normalized shorts (padded to 4 components' alignment by a stride of 8).
    let mut pos = Vec::new();
    for p in [[32767i16, 0, 0], [0, 32767, 0], [-32768, -32767, 0]] {
        pos.extend(bytes_i16(&p));
        pos.extend([0, 0]);
    }
    let view = g.view(&pos);
    g.json["bufferViews"][view]["byteStride"] = json!(8);
    g.json["accessors"].as_array_mut().unwrap().push(json!({
        "bufferView": view, "componentType": 5122, "normalized": true, "type": "VEC3", "count": 3,
        "min": [-1, -1, 0], "max": [1, 1, 0]
    }));
    let positions = g.json["accessors"].as_array().unwrap().len() - 1;
    // Normals: normalized bytes, 4-byte stride.
    let normal_bytes: Vec<u8> = [[0i8, 0, 127, 0]; 3]
        .iter()
        .flatten()
        .map(|&b| b as u8)
        .collect();
    let nview = g.view(&normal_bytes);
    g.json["bufferViews"][nview]["byteStride"] = json!(4);
    g.json["accessors"].as_array_mut().unwrap().push(json!({
        "bufferView": nview, "componentType": 5120, "normalized": true, "type": "VEC3", "count": 3
    }));
    let normals = g.json["accessors"].as_array().unwrap().len() - 1;
    // Texcoords: unnormalized unsigned shorts (the values as they are).
    let texcoords = g.accessor(&bytes_u16(&[0, 0, 2, 0, 0, 3]), 5123, "VEC2", 3, false);
    // Colours: normalized unsigned bytes, RGBA.
    let colors = g.accessor(
        &[255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0],
        5121,
        "VEC4",
        3,
        true,
    );
    let mesh = g.mesh(
        "q",
        vec![json!({"attributes": {"POSITION": positions, "NORMAL": normals, "TEXCOORD_0": texcoords, "COLOR_0": colors}})],
    );
    // The dequantization transform lives on the node.
    let node = g.node(json!({"mesh": mesh, "scale": [2.0, 2.0, 2.0]}));
    g.root(node);
    let loaded = load_scene(&write(&g, "quantized")).expect("quantized file");
    let m = &loaded.scene.meshes[0];
    assert_eq!(
        m.positions,
        vec![Vec3::X, Vec3::Y, Vec3::new(-1.0, -1.0, 0.0)]
    );
    assert_eq!(m.normals.as_ref().unwrap(), &vec![Vec3::Z; 3]);
    assert_eq!(
        m.texcoords.as_ref().unwrap(),
        &vec![Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::new(0.0, 3.0)]
    );
    let c = m.colors.as_ref().unwrap();
    assert_eq!(c[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert!((c[1].w - 128.0 / 255.0).abs() < 1e-6);
    assert_eq!(loaded.scene.draws[0].model.x_axis.x, 2.0);
    assert!(
        !loaded
            .info
            .warnings
            .iter()
            .any(|w| w.contains("KHR_mesh_quantization")),
        "{:?}",
        loaded.info.warnings
    );
}
