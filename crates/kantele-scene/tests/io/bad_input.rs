//! Broken files give an error that names the file, never a panic.

use std::path::Path;

use crate::common::*;
use kantele_scene::{load_scene, load_scene_with, LoadError, LoadOptions};
use serde_json::json;

/// Loads `path`, expecting an error whose message names the file (and contains `expected`).
fn expect_error(path: &Path, expected: &str) -> String {
    let err = match load_scene(path) {
        Ok(_) => panic!("{} should not load", path.display()),
        Err(e) => e.to_string(),
    };
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(err.contains(name), "error does not name {name}: {err}");
    assert!(
        err.to_lowercase().contains(&expected.to_lowercase()),
        "error lacks '{expected}': {err}"
    );
    err
}

/// A texture that cannot be loaded: by default the scene loads with a warning naming
/// `expected` and the material drawn untextured; with `strict` it is an error naming the file.
fn expect_texture_problem(path: &Path, expected: &str) -> String {
    let loaded = load_scene(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()));
    assert!(
        loaded
            .info
            .warnings
            .iter()
            .any(|w| w.contains(expected) && w.contains("untextured")),
        "no warning naming {expected}: {:?}",
        loaded.info.warnings
    );
    assert!(
        loaded
            .scene
            .materials
            .iter()
            .all(|m| m.base_color_texture.is_none()),
        "the material keeps a texture"
    );
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    let err = load_scene_with(path, &strict)
        .err()
        .unwrap_or_else(|| panic!("{} should not load when strict", path.display()))
        .to_string();
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(err.contains(name), "error does not name {name}: {err}");
    assert!(err.contains(expected), "error lacks '{expected}': {err}");
    err
}

#[test]
fn missing_file() {
    let dir = temp_dir("missing");
    for name in ["nope.glb", "nope.gltf", "nope.obj"] {
        let path = dir.join(name);
        expect_error(&path, "");
        assert!(matches!(load_scene(&path), Err(LoadError::Io { .. })));
    }
}

#[test]
fn unknown_extension() {
    let dir = temp_dir("unknown");
    let path = dir.join("scene.txt");
    std::fs::write(&path, b"hello").unwrap();
    assert!(matches!(
        load_scene(&path),
        Err(LoadError::UnknownFormat { .. })
    ));
    expect_error(&path, "unknown scene format");
}

#[test]
fn empty_files() {
    let dir = temp_dir("empty");
    for name in ["empty.glb", "empty.gltf"] {
        let path = dir.join(name);
        std::fs::write(&path, b"").unwrap();
        expect_error(&path, "empty");
    }
    // An empty OBJ is a valid (empty) scene.
    let path = dir.join("empty.obj");
    std::fs::write(&path, b"").unwrap();
    let loaded = load_scene(&path).expect("an empty OBJ loads");
    assert_eq!(loaded.scene.triangle_count(), 0);
}

#[test]
fn garbage_bytes() {
    let dir = temp_dir("garbage");
    let mut state = 0x1234_5678u32;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as u8
        })
        .collect();
    for name in ["garbage.glb", "garbage.gltf", "garbage.obj"] {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).unwrap();
        if name.ends_with(".obj") {
            // tobj may read garbage as an empty model list or fail; either is fine, no panic.
            let _ = load_scene(&path);
        } else {
            expect_error(&path, "");
        }
    }
    // A GLB header followed by garbage, and JSON that is not glTF.
    let path = dir.join("header.glb");
    let mut glb = b"glTF\x02\0\0\0\xff\0\0\0".to_vec();
    glb.extend_from_slice(&bytes[..200]);
    std::fs::write(&path, &glb).unwrap();
    expect_error(&path, "");
    let path = dir.join("notgltf.gltf");
    std::fs::write(&path, br#"{"hello": [1, 2, 3]}"#).unwrap();
    expect_error(&path, "");
}

#[test]
fn truncated_glb() {
    let dir = temp_dir("truncated");
    let full = dir.join("full.glb");
    textured_quad().write_glb(&full);
    let bytes = std::fs::read(&full).unwrap();
    assert!(load_scene(&full).is_ok());
    for cut in [
        4,
        11,
        12,
        19,
        20,
        bytes.len() / 2,
        bytes.len() - 40,
        bytes.len() - 1,
    ] {
        let path = dir.join(format!("cut{cut}.glb"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        expect_error(&path, "");
    }
    // A real reference scene, cut in the middle of its binary chunk.
    if let Some(scenes) = reference_scenes() {
        let bytes = std::fs::read(scenes.join("spot-textured.glb")).unwrap();
        let path = dir.join("spot-cut.glb");
        std::fs::write(&path, &bytes[..bytes.len() * 2 / 3]).unwrap();
        expect_error(&path, "");
    }
}

#[test]
fn index_out_of_range() {
    let mut g = Gltf::new();
    let p = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let i = g.indices_u16(&[0, 1, 2, 0, 2, 7]);
    let mesh = g.mesh(
        "bad",
        vec![json!({"attributes": {"POSITION": p}, "indices": i})],
    );
    let n = g.node(json!({"mesh": mesh}));
    g.root(n);
    let dir = temp_dir("range");
    let path = dir.join("range.glb");
    g.write_glb(&path);
    let err = expect_error(&path, "out of range");
    assert!(err.contains("index 7"), "{err}");
}

#[test]
fn accessor_outside_its_buffer() {
    let mut g = Gltf::new();
    let p = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.json["accessors"][p]["count"] = json!(300);
    let mesh = g.mesh("bad", vec![json!({"attributes": {"POSITION": p}})]);
    let n = g.node(json!({"mesh": mesh}));
    g.root(n);
    let dir = temp_dir("outside");
    let path = dir.join("outside.glb");
    g.write_glb(&path);
    expect_error(&path, "POSITION");
}

#[test]
fn wrong_attribute_types() {
    let mut g = Gltf::new();
    let p = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    // COLOR_0 as VEC2 is not allowed (the gltf crate's reader would hit `unreachable!`).
    let c = g.vec2(&[[0.0, 0.0]; 3]);
    let mesh = g.mesh(
        "bad",
        vec![json!({"attributes": {"POSITION": p, "COLOR_0": c}})],
    );
    let n = g.node(json!({"mesh": mesh}));
    g.root(n);
    let dir = temp_dir("types");
    let path = dir.join("types.glb");
    g.write_glb(&path);
    expect_error(&path, "COLOR_0");
}

#[test]
fn node_cycles_do_not_hang() {
    let mut g = Gltf::new();
    let a = g.node(json!({"children": [1]}));
    let _b = g.node(json!({"children": [0]}));
    g.root(a);
    let dir = temp_dir("cycle");
    let path = dir.join("cycle.gltf");
    g.write_gltf_embedded(&path);
    // Either rejected by validation or loaded with a warning; never a hang or a panic.
    match load_scene(&path) {
        Ok(loaded) => assert!(!loaded.info.warnings.is_empty()),
        Err(e) => assert!(e.to_string().contains("cycle.gltf")),
    }
}

#[test]
fn nan_positions_load() {
    let mut g = Gltf::new();
    let p = g.vec3(&[
        [0.0, 0.0, 0.0],
        [f32::NAN, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    let i = g.indices_u16(&[0, 1, 2, 0, 3, 2]);
    let mesh = g.mesh(
        "nan",
        vec![json!({"attributes": {"POSITION": p}, "indices": i})],
    );
    let n = g.node(json!({"mesh": mesh}));
    g.root(n);
    let dir = temp_dir("nan");
    let path = dir.join("nan.glb");
    g.write_glb(&path);
    let loaded = load_scene(&path).expect("NaN positions are the renderer's business");
    // JSON has no NaN: this file has no POSITION min / max, which only gives a warning.
    assert!(
        loaded.info.warnings.iter().any(|w| w.contains("min / max")),
        "{:?}",
        loaded.info.warnings
    );
    assert_eq!(loaded.scene.triangle_count(), 2);
    let normals = loaded.scene.meshes[0].normals.as_ref().unwrap();
    assert!(normals.iter().all(|n| n.is_finite()));
    assert!(loaded.scene.camera.view.is_finite());
}

#[test]
fn missing_external_files() {
    let dir = temp_dir("external");
    let g = textured_quad();
    let path = dir.join("quad.gltf");
    g.write_gltf_external(&path);
    // Missing texture.
    std::fs::remove_file(dir.join("quad-image0.png")).unwrap();
    let err = expect_texture_problem(&path, "quad-image0.png");
    assert!(err.contains("image 0"), "{err}");
    // Missing buffer.
    std::fs::remove_file(dir.join("quad.bin")).unwrap();
    expect_error(&path, "quad.bin");
}

#[test]
fn corrupt_textures() {
    let dir = temp_dir("corrupt");
    let mut g = textured_quad();
    let mut broken = test_png();
    broken.truncate(broken.len() / 2);
    g.images[0] = broken;
    let path = dir.join("corrupt.gltf");
    g.write_gltf_external(&path);
    let err = expect_texture_problem(&path, "corrupt-image0.png");
    assert!(err.contains("image 0"), "{err}");
    // Not an image at all, inside a GLB.
    g.images[0] = b"this is not a png".to_vec();
    let path = dir.join("corrupt.glb");
    g.write_glb(&path);
    expect_texture_problem(&path, "image 0");
    // And as a data URI.
    let path = dir.join("corrupt-embedded.gltf");
    g.write_gltf_embedded(&path);
    expect_texture_problem(&path, "image 0");
}

#[test]
fn bad_data_uri() {
    let dir = temp_dir("datauri");
    let g = textured_quad();
    let path = dir.join("baduri.gltf");
    g.write_gltf_embedded(&path);
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    json["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,!!!notbase64!!!");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    expect_error(&path, "base64");
    // A percent-encoded name that is not UTF-8, and an unsupported scheme.
    json["buffers"][0]["uri"] = json!("%ff%fe.bin");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    expect_error(&path, "buffer 0");
    json["buffers"][0]["uri"] = json!("https://example.invalid/x.bin");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    expect_error(&path, "unsupported URI");
}

#[test]
fn broken_obj_files() {
    let dir = temp_dir("badobj");
    let path = dir.join("range.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    expect_error(&path, "");
    // A missing texture named by the MTL.
    let path = dir.join("tex.obj");
    std::fs::write(
        &path,
        "mtllib tex.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("tex.mtl"),
        "newmtl m\nKd 1 1 1\nmap_Kd nothere.png\n",
    )
    .unwrap();
    let err = expect_texture_problem(&path, "nothere.png");
    assert!(err.contains("tex.obj"));
}

/// Loads `bytes` written as `name`, expecting a one-line error that names the file and
/// contains `expected`.
fn expect_one_line_error(dir: &Path, name: &str, bytes: &[u8], expected: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let err = expect_error(&path, expected);
    assert!(!err.contains('\n'), "not one line: {err}");
    err
}

#[test]
fn broken_ply_files() {
    use crate::common::ply_stl::{quad_and_pentagon, PlyFormat, PlyMesh};
    let dir = temp_dir("badply");
    expect_one_line_error(&dir, "empty.ply", b"", "not a valid PLY file");
    expect_one_line_error(
        &dir,
        "notply.ply",
        b"solid x\nendsolid x\n",
        "not a valid PLY file",
    );
    // Truncated binary files: inside the vertices (the header's counts no longer fit) and
    // one byte short in the last face.
    for format in [PlyFormat::BinaryLittleEndian, PlyFormat::BinaryBigEndian] {
        let whole = quad_and_pentagon().to_ply(format);
        let header = whole
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        let err =
            expect_one_line_error(&dir, "cut-vertices.ply", &whole[..header + 40], "truncated");
        assert!(err.contains("'vertex'"), "{err}");
        let err =
            expect_one_line_error(&dir, "cut-face.ply", &whole[..whole.len() - 1], "truncated");
        assert!(err.contains("face 1 of 2"), "{err}");
    }
    // Indices out of range and negative ones.
    let mut mesh = PlyMesh {
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        faces: Some(vec![vec![0, 1, 2], vec![0, 2, 9]]),
        ..PlyMesh::default()
    };
    for format in PlyFormat::ALL {
        let err = expect_one_line_error(&dir, "range.ply", &mesh.to_ply(format), "out of range");
        assert!(err.contains("face 1") && err.contains("index 9"), "{err}");
    }
    mesh.faces = Some(vec![vec![0, -1, 2]]);
    expect_one_line_error(
        &dir,
        "negative.ply",
        &mesh.to_ply(PlyFormat::Ascii),
        "negative",
    );
    // Text that is not UTF-8, in the data and in the header.
    let mut ascii = mesh.to_ply(PlyFormat::Ascii);
    let data = ascii
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    ascii[data] = 0xff;
    expect_one_line_error(&dir, "latin1-data.ply", &ascii, "vertex 0 of 3");
    let mut header = mesh.to_ply(PlyFormat::Ascii);
    header[25] = 0xe9;
    expect_one_line_error(&dir, "latin1-header.ply", &header, "not a valid PLY file");
    // Numbers that are not numbers, and a short ASCII line.
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                property float z\nend_header\n0 0 zero\n1 1\n";
    expect_one_line_error(&dir, "words.ply", text.as_bytes(), "vertex 0 of 2");
    // Vertices without a position; faces whose corners are not integers.
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                end_header\n0 0\n";
    expect_one_line_error(&dir, "no-z.ply", text.as_bytes(), "no x, y and z");
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar float vertex_indices\n\
                end_header\n0 0 0\n3 0 0 0\n";
    expect_one_line_error(&dir, "float-faces.ply", text.as_bytes(), "not integers");
}

#[test]
fn broken_stl_files() {
    use crate::common::ply_stl::{stl_ascii, stl_binary, tetrahedron};
    let dir = temp_dir("badstl");
    let triangles = tetrahedron();
    expect_one_line_error(&dir, "empty.stl", b"", "not an STL file");
    expect_one_line_error(&dir, "short.stl", b"hello", "not an STL file");
    // Binary: one byte short, and a header that declares 2^32 − 1 triangles.
    let binary = stl_binary(&triangles, b"cut", [0.0; 3]);
    let err = expect_one_line_error(&dir, "cut.stl", &binary[..binary.len() - 1], "truncated");
    assert!(err.contains("4 triangles"), "{err}");
    let mut huge = binary.clone();
    huge[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    expect_one_line_error(&dir, "huge.stl", &huge, "4294967295 triangles");
    // ASCII: no `endsolid`, a facet cut short, text outside the solid, a NaN corner.
    let ascii = stl_ascii(&triangles, "solid t", "\n");
    let text = String::from_utf8(ascii.clone()).unwrap();
    let no_end = text.replace("endsolid\n", "");
    expect_one_line_error(&dir, "no-end.stl", no_end.as_bytes(), "truncated");
    let cut = text.replacen("      vertex 1 0 0\n", "", 1);
    expect_one_line_error(&dir, "short-facet.stl", cut.as_bytes(), "triangle 0");
    let outside = format!("{text}trailing words\n");
    expect_one_line_error(&dir, "outside.stl", outside.as_bytes(), "outside 'solid");
    let nan = text.replacen("vertex 1 0 0", "vertex nan 0 0", 1);
    expect_one_line_error(&dir, "nan.stl", nan.as_bytes(), "triangle 0");
    let mut latin1 = ascii.clone();
    let at = latin1.windows(6).position(|w| w == b"vertex").unwrap();
    latin1[at] = 0xe9;
    expect_one_line_error(&dir, "latin1.stl", &latin1, "triangle 0");
}

#[test]
fn garbage_ply_and_stl() {
    let dir = temp_dir("garbage-ply-stl");
    let mut state = 0x9e37_79b9u32;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as u8
        })
        .collect();
    expect_one_line_error(&dir, "garbage.ply", &bytes, "");
    expect_one_line_error(&dir, "garbage.stl", &bytes, "");
    // A PLY header followed by garbage.
    let mut ply = b"ply\nformat binary_big_endian 1.0\nelement vertex 100\nproperty double x\n\
        property double y\nproperty double z\nelement face 50\n\
        property list uint uint vertex_indices\nend_header\n"
        .to_vec();
    ply.extend_from_slice(&bytes);
    expect_one_line_error(&dir, "header-garbage.ply", &ply, "");
}
