//! Valid glTF that the `gltf` crate alone would reject, and KHR_mesh_quantization's attribute
//! types: each loads with the values the spec defines.

use crate::common::*;
use glam::{Vec2, Vec3, Vec4};
use kantele_scene::load_scene;
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
    // The channel cannot be played (KHR_animation_pointer): named among the ignored features.
    assert!(
        warnings.contains("animation channels with path 'pointer'"),
        "{warnings}"
    );
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
fn draco_data_that_is_not_draco_is_refused_in_one_line() {
    let mut g = textured_quad();
    g.json["meshes"][0]["primitives"][0]["extensions"] =
        json!({"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}});
    let err = load_scene(&write(&g, "draco"))
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("KHR_draco_mesh_compression") && err.contains("not a Draco stream"),
        "{err}"
    );
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

#[test]
fn webp_textures_decode() {
    // A 2 × 2 lossless WebP (red, green / blue, white), shown through EXT_texture_webp with a
    // PNG fallback of another colour: the WebP must win.
    let rgba = [
        255u8, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255,
    ];
    let image = image::RgbaImage::from_raw(2, 2, rgba.to_vec()).unwrap();
    let mut webp = std::io::Cursor::new(Vec::new());
    image.write_to(&mut webp, image::ImageFormat::WebP).unwrap();
    let mut g = textured_quad();
    g.images[0] = png(1, 1, &[0, 0, 0, 255]);
    let webp_image = g.image(webp.into_inner());
    g.json["images"][webp_image]["mimeType"] = json!("image/webp");
    g.json["textures"][0]["extensions"] = json!({"EXT_texture_webp": {"source": webp_image}});
    g.json["extensionsUsed"] = json!(["EXT_texture_webp", "KHR_lights_punctual"]);
    let loaded = load_scene(&write(&g, "webp")).expect("webp texture");
    let texture = &loaded.scene.textures[0];
    assert_eq!((texture.width(), texture.height()), (2, 2));
    let level0 = texture.level(0).expect("level 0");
    assert_eq!(level0.texel(1, 0), Vec4::new(0.0, 1.0, 0.0, 1.0));
}

#[test]
fn meshopt_compressed_views_decode() {
    let positions: [[f32; 3]; 4] = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let indices: [u32; 6] = [0, 1, 2, 0, 2, 3];
    // Normals through the octahedral filter (8-bit), as gltfpack writes them.
    let normals: Vec<[i8; 4]> = meshopt::encode_filter_oct(&[[0.0, 0.0, 1.0, 0.0]; 4], 8);
    let encoded_positions = meshopt::encode_vertex_buffer(&positions).unwrap();
    let encoded_normals = meshopt::encode_vertex_buffer(&normals).unwrap();
    let encoded_indices = meshopt::encode_index_buffer(&indices, 4).unwrap();

    let mut g = Gltf::new();
    let compressed = |g: &mut Gltf,
                      bytes: &[u8],
                      stride: usize,
                      count: usize,
                      mode: &str,
                      filter: &str| {
        let source = g.view(bytes);
        let source_offset = g.json["bufferViews"][source]["byteOffset"].clone();
        // The view itself points into the (empty) fallback buffer 1.
        let mut view = json!({"buffer": 1, "byteOffset": 0, "byteLength": stride * count, "byteStride": stride,
            "extensions": {"EXT_meshopt_compression": {"buffer": 0, "byteOffset": source_offset,
                "byteLength": bytes.len(), "byteStride": stride, "count": count, "mode": mode, "filter": filter}}});
        if mode != "ATTRIBUTES" {
            view.as_object_mut().unwrap().remove("byteStride");
        }
        g.json["bufferViews"][source] = view;
        source
    };
    let pv = compressed(&mut g, &encoded_positions, 12, 4, "ATTRIBUTES", "NONE");
    let nv = compressed(&mut g, &encoded_normals, 4, 4, "ATTRIBUTES", "OCTAHEDRAL");
    let iv = compressed(&mut g, &encoded_indices, 4, 6, "TRIANGLES", "NONE");
    let accessors = g.json["accessors"].as_array_mut().unwrap();
    accessors.push(json!({"bufferView": pv, "componentType": 5126, "type": "VEC3", "count": 4, "min": [-1, -1, 0], "max": [1, 1, 0]}));
    accessors.push(json!({"bufferView": nv, "componentType": 5120, "normalized": true, "type": "VEC3", "count": 4}));
    accessors.push(json!({"bufferView": iv, "componentType": 5125, "type": "SCALAR", "count": 6}));
    let n = accessors.len();
    let mesh = g.mesh(
        "m",
        vec![json!({"attributes": {"POSITION": n - 3, "NORMAL": n - 2}, "indices": n - 1})],
    );
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    g.json["extensionsUsed"] = json!(["EXT_meshopt_compression", "KHR_mesh_quantization"]);
    g.json["extensionsRequired"] = json!(["EXT_meshopt_compression", "KHR_mesh_quantization"]);
    let path = temp_dir("meshopt").join("meshopt.glb");
    g.write_glb(&path);
    // Add the fallback buffer (no data) after writing: patch the GLB's JSON.
    let bytes = std::fs::read(&path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    doc["buffers"].as_array_mut().unwrap().push(
        json!({"byteLength": 1024, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}),
    );
    let mut text = serde_json::to_vec(&doc).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let bin = &bytes[20 + json_len..];
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + text.len() + bin.len()) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&text);
    out.extend(bin);
    std::fs::write(&path, out).unwrap();

    let loaded = load_scene(&path).expect("meshopt file");
    let m = &loaded.scene.meshes[0];
    assert_eq!(m.positions, positions.map(Vec3::from).to_vec());
    assert_eq!(m.indices, indices.to_vec());
    for n in m.normals.as_ref().unwrap() {
        assert!((*n - Vec3::Z).length() < 0.01, "{n}");
    }
}
