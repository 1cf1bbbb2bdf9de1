//! Hostile files: resource bombs are refused by arithmetic before anything is
//! allocated, and a scene reads only regular files inside its own folder unless allowed more.
//! Big inputs are generated here and run in a child process under `ulimit -v`, so an
//! allocation that slipped past the budget would abort the child and fail the test.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::*;
use kantele_scene::{load_scene, load_scene_with, LoadOptions};
use serde_json::json;

/// A triangle whose POSITION accessor is sparse with `count` elements and no buffer view.
fn sparse_bomb(count: u64) -> Gltf {
    let mut g = Gltf::new();
    let indices = g.accessor(&[0, 0, 0, 0], 5125, "SCALAR", 1, false);
    let values = g.accessor(&[0; 12], 5126, "VEC3", 1, false);
    let positions = json!({
        "componentType": 5126, "type": "VEC3", "count": count,
        "sparse": {"count": 1,
            "indices": {"bufferView": g.json["accessors"][indices]["bufferView"], "componentType": 5125},
            "values": {"bufferView": g.json["accessors"][values]["bufferView"]}}
    });
    g.json["accessors"].as_array_mut().unwrap().push(positions);
    let p = g.json["accessors"].as_array().unwrap().len() - 1;
    let mesh = g.mesh("bomb", vec![json!({"attributes": {"POSITION": p}})]);
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    g
}

/// The PNG header of an image that declares `width` × `height` (the pixel data is tiny and
/// broken: a loader that trusted the header would allocate first and fail later).
fn png_header_claiming(width: u32, height: u32) -> Vec<u8> {
    let mut png = png(1, 1, &[255, 0, 0, 255]);
    // IHDR: length at 8, type at 12, data at 16..29 (width, height first), CRC at 29..33.
    png[16..20].copy_from_slice(&width.to_be_bytes());
    png[20..24].copy_from_slice(&height.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    png
}

/// CRC-32 (IEEE), as PNG chunks use it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// Runs this test binary's `child_load` test in a child process with virtual memory capped at
/// `limit_mib`, loading `path`; returns (exit success, stderr + stdout).
fn load_in_capped_child(path: &Path, limit_mib: u64) -> (bool, String) {
    let exe = std::env::current_exe().unwrap();
    let script = format!(
        "ulimit -v {} && exec \"$0\" hostile_files::child_load --exact --nocapture --test-threads=1",
        limit_mib * 1024
    );
    let out = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(exe)
        .env("KANTELE_CHILD_LOAD", path)
        .output()
        .expect("run the child");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

/// The child side of [`load_in_capped_child`]: loads the file named by `KANTELE_CHILD_LOAD`
/// and prints the outcome; passes trivially when run as an ordinary test.
#[test]
fn child_load() {
    let Ok(path) = std::env::var("KANTELE_CHILD_LOAD") else {
        return;
    };
    match load_scene(Path::new(&path)) {
        Ok(_) => println!("CHILD: loaded"),
        Err(e) => println!("CHILD: error: {e}"),
    }
}

#[test]
fn sparse_accessor_bomb_is_refused_before_allocating() {
    let dir = temp_dir("sparse-bomb");
    let path = dir.join("bomb.glb");
    sparse_bomb(1 << 31).write_glb(&path);
    let err = load_scene(&path).expect_err("must be refused").to_string();
    assert!(err.contains("memory budget"), "{err}");
    assert!(err.contains("bomb.glb"), "{err}");
    // Under a 1 GiB address-space cap the child must report the error, not abort.
    let (ok, text) = load_in_capped_child(&path, 1024);
    assert!(ok, "child failed: {text}");
    assert!(
        text.contains("CHILD: error:") && text.contains("memory budget"),
        "{text}"
    );
    // The same file with a count that fits loads, zero-filled with the sparse value on top.
    let path = dir.join("small.glb");
    sparse_bomb(3).write_glb(&path);
    let loaded = load_scene(&path).expect("small sparse accessor");
    assert_eq!(loaded.scene.meshes[0].positions.len(), 3);
}

#[test]
fn huge_declared_image_is_refused_from_its_header() {
    let dir = temp_dir("image-bomb");
    let mut g = textured_quad();
    g.images[0] = png_header_claiming(16000, 16000);
    let path = dir.join("bomb.glb");
    g.write_glb(&path);
    let small = LoadOptions {
        max_memory: 64 << 20,
        ..LoadOptions::default()
    };
    let err = load_scene_with(&path, &small)
        .expect_err("must be refused")
        .to_string();
    assert!(
        err.contains("16000x16000") && err.contains("memory budget"),
        "{err}"
    );
    let (ok, text) = load_in_capped_child(&path, 2048);
    assert!(ok, "child failed: {text}");
    assert!(text.contains("CHILD: "), "{text}");
}

#[test]
fn identical_images_are_decoded_once() {
    let dir = temp_dir("dedup");
    let mut g = textured_quad();
    let second = g.image(test_png());
    let texture = g.texture(json!({"source": second}));
    let material =
        g.material(json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": texture}}}));
    let p = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let mesh = g.mesh(
        "second",
        vec![json!({"attributes": {"POSITION": p}, "material": material})],
    );
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    let path = dir.join("dedup.glb");
    g.write_glb(&path);
    let loaded = load_scene(&path).unwrap();
    assert_eq!(
        loaded.scene.textures.len(),
        1,
        "two identical images, one texture"
    );
}

fn write_quad_referring_to(dir: &Path, uri: &str) -> PathBuf {
    let g = textured_quad();
    let path = dir.join("quad.gltf");
    g.write_gltf_external(&path);
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    json["buffers"][0]["uri"] = json!(uri);
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    path
}

#[test]
fn reads_are_confined_to_the_scene_folder() {
    let base = temp_dir("confined");
    let scene_dir = base.join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    // The buffer moved one folder up: refused unless that folder is allowed.
    let path = write_quad_referring_to(&scene_dir, "../quad.bin");
    std::fs::rename(scene_dir.join("quad.bin"), base.join("quad.bin")).unwrap();
    let err = load_scene(&path).expect_err("outside").to_string();
    assert!(err.contains("outside the scene's folder"), "{err}");
    let allowed = LoadOptions {
        allow_read: vec![base.clone()],
        ..LoadOptions::default()
    };
    load_scene_with(&path, &allowed).expect("allowed folder");
    // A symbolic link inside the folder that points outside is resolved and refused.
    std::os::unix::fs::symlink(base.join("quad.bin"), scene_dir.join("link.bin")).unwrap();
    let path = write_quad_referring_to(&scene_dir, "link.bin");
    let err = load_scene(&path).expect_err("symlink out").to_string();
    assert!(err.contains("outside the scene's folder"), "{err}");
    // Devices and absolute file URIs.
    let path = write_quad_referring_to(&scene_dir, "file:///dev/zero");
    let err = load_scene(&path).expect_err("device").to_string();
    assert!(err.contains("outside"), "{err}");
    let everything = LoadOptions {
        allow_read: vec![PathBuf::from("/dev")],
        ..LoadOptions::default()
    };
    let err = load_scene_with(&path, &everything)
        .expect_err("device")
        .to_string();
    assert!(err.contains("not a regular file"), "{err}");
    // A FIFO inside the folder is never opened (opening it would hang).
    let fifo = scene_dir.join("fifo.bin");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let path = write_quad_referring_to(&scene_dir, "fifo.bin");
        let err = load_scene(&path).expect_err("fifo").to_string();
        assert!(err.contains("not a regular file"), "{err}");
    }
    // A folder.
    std::fs::create_dir_all(scene_dir.join("folder.bin")).unwrap();
    let path = write_quad_referring_to(&scene_dir, "folder.bin");
    let err = load_scene(&path).expect_err("folder").to_string();
    assert!(err.contains("not a regular file"), "{err}");
}

#[test]
fn obj_texture_reads_are_confined_too() {
    let base = temp_dir("confined-obj");
    let scene_dir = base.join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    std::fs::write(base.join("private.png"), test_png()).unwrap();
    let path = scene_dir.join("tex.obj");
    std::fs::write(
        &path,
        "mtllib tex.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl m\nf 1/1 2/1 3/1\n",
    )
    .unwrap();
    std::fs::write(
        scene_dir.join("tex.mtl"),
        "newmtl m\nmap_Kd ../private.png\n",
    )
    .unwrap();
    let loaded = load_scene(&path).expect("loads untextured");
    assert!(loaded.scene.textures.is_empty());
    assert!(
        loaded
            .info
            .warnings
            .iter()
            .any(|w| w.contains("outside the scene's folder")),
        "{:?}",
        loaded.info.warnings
    );
    let allowed = LoadOptions {
        allow_read: vec![base.clone()],
        ..LoadOptions::default()
    };
    assert_eq!(
        load_scene_with(&path, &allowed)
            .unwrap()
            .scene
            .textures
            .len(),
        1
    );
}

#[test]
fn ply_and_stl_counts_beyond_the_file_are_refused_before_allocating() {
    let dir = temp_dir("ply-stl-counts");
    // 2^32 vertices of 12 bytes (48 GiB of data) declared, 12 bytes present.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4294967296\n\
        property float x\nproperty float y\nproperty float z\nend_header\n"
        .to_vec();
    ply.extend([0; 12]);
    let path = dir.join("vertices.ply");
    std::fs::write(&path, &ply).unwrap();
    let started = std::time::Instant::now();
    let err = load_scene(&path).expect_err("must be refused").to_string();
    assert!(
        err.contains("vertices.ply") && err.contains("4294967296 'vertex' elements"),
        "{err}"
    );
    assert!(started.elapsed().as_secs() < 2, "{:?}", started.elapsed());
    // Under a 1 GiB address-space cap the child must report the error, not abort.
    let (ok, text) = load_in_capped_child(&path, 1024);
    assert!(ok, "child failed: {text}");
    assert!(text.contains("CHILD: error:"), "{text}");
    // ASCII: 10^15 faces (and an element with no properties, which takes no bytes in binary
    // but a line each in ASCII).
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 1000000000000000\nproperty list uchar int vertex_indices\n\
        end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let path = dir.join("faces.ply");
    std::fs::write(&path, text).unwrap();
    let err = load_scene(&path).expect_err("must be refused").to_string();
    assert!(err.contains("1000000000000000 'face' elements"), "{err}");
    let empty_element = "ply\nformat binary_big_endian 1.0\nelement nothing 18446744073709551615\n\
        end_header\n";
    let path = dir.join("nothing.ply");
    std::fs::write(&path, empty_element).unwrap();
    let err = load_scene(&path).expect_err("must be refused").to_string();
    assert!(err.contains("'nothing' elements"), "{err}");
    // A face whose list declares 2^32 − 1 corners reads only what is there.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\n\
        end_header\n"
        .to_vec();
    ply.extend([0; 36]);
    ply.extend(u32::MAX.to_le_bytes());
    ply.extend([0; 12]);
    let path = dir.join("corners.ply");
    std::fs::write(&path, &ply).unwrap();
    let err = load_scene(&path).expect_err("must be refused").to_string();
    assert!(err.contains("truncated"), "{err}");
    let (ok, text) = load_in_capped_child(&path, 1024);
    assert!(ok && text.contains("CHILD: error:"), "{text}");
}

#[test]
fn ply_and_stl_arrays_are_charged_to_the_budget() {
    let dir = temp_dir("ply-stl-budget");
    let small = LoadOptions {
        max_memory: 1 << 20,
        ..LoadOptions::default()
    };
    // 100 000 vertices of three bytes each (300 KB): 1.2 MB of positions.
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 100000\n\
        property uchar x\nproperty uchar y\nproperty uchar z\nend_header\n"
        .to_vec();
    ply.extend((0..300_000).map(|i| (i % 251) as u8));
    let path = dir.join("cloud.ply");
    std::fs::write(&path, &ply).unwrap();
    let err = load_scene_with(&path, &small)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("the vertices") && err.contains("memory budget"),
        "{err}"
    );
    // The same file within a budget that fits: a point cloud of 100 000 points.
    let loaded = load_scene(&path).expect("loads");
    assert_eq!(loaded.scene.meshes[0].primitive_count(), 100_000);
    // 20 000 binary STL triangles (1 MB): 1.7 MB of mesh.
    let triangles = vec![[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 20_000];
    let stl = crate::common::ply_stl::stl_binary(&triangles, b"many", [0.0; 3]);
    let path = dir.join("many.stl");
    std::fs::write(&path, &stl).unwrap();
    let two = LoadOptions {
        max_memory: 2 << 20,
        ..LoadOptions::default()
    };
    let err = load_scene_with(&path, &two)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("the triangles") && err.contains("memory budget"),
        "{err}"
    );
    assert_eq!(
        load_scene(&path).expect("loads").scene.triangle_count(),
        20_000
    );
}

/// `\` continuation lines without end: a million of them, and one on the last line of the
/// file, in OBJ and MTL files, make one long line, read once.
#[test]
fn obj_continuation_lines_without_end() {
    let dir = temp_dir("obj-continued");
    let endless = b"\\\n".repeat(1_000_000);
    let mut mtl = b"newmtl m\nKd 1 0 0 \\\n".to_vec();
    mtl.extend_from_slice(&endless);
    mtl.push(b'\\');
    std::fs::write(dir.join("c.mtl"), mtl).unwrap();
    let mut obj = b"mtllib c.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3 \\\n".to_vec();
    obj.extend_from_slice(&endless);
    obj.push(b'\\');
    let path = dir.join("c.obj");
    std::fs::write(&path, obj).unwrap();
    let started = std::time::Instant::now();
    let loaded = load_scene(&path).expect("loads");
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
    assert_eq!(loaded.scene.triangle_count(), 1);
    assert_eq!(
        loaded.scene.materials[0].base_color_factor,
        glam::Vec4::new(1.0, 0.0, 0.0, 1.0)
    );
}

/// Huge UTF-16 OBJ and MTL files are charged to the budget as any text is (refused under a
/// small one), and load within the memory they are charged for.
#[test]
fn huge_utf16_obj_and_mtl_files() {
    let dir = temp_dir("obj-utf16-huge");
    let utf16 = |text: &str, repeat: usize, big_endian: bool| -> Vec<u8> {
        let units: Vec<u16> = text.encode_utf16().collect();
        let mut out = if big_endian {
            vec![0xfe, 0xff]
        } else {
            vec![0xff, 0xfe]
        };
        out.reserve(units.len() * 2 * repeat);
        for _ in 0..repeat {
            for u in &units {
                out.extend_from_slice(&if big_endian {
                    u.to_be_bytes()
                } else {
                    u.to_le_bytes()
                });
            }
        }
        out
    };
    // 16 MB of vertices: a point cloud of 800 000 points.
    let path = dir.join("huge16.obj");
    std::fs::write(&path, utf16("v 0.5 1 2\n", 800_000, false)).unwrap();
    let small = LoadOptions {
        max_memory: 64 << 20,
        ..LoadOptions::default()
    };
    let err = load_scene_with(&path, &small)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("memory budget") && err.contains("huge16.obj"),
        "{err}"
    );
    let (ok, text) = load_in_capped_child(&path, 1024);
    assert!(ok && text.contains("CHILD: loaded"), "{text}");
    // An 8 MB UTF-16 material library.
    std::fs::write(
        dir.join("big.mtl"),
        utf16("newmtl a\nKd 1 1 1\n", 200_000, true),
    )
    .unwrap();
    let path = dir.join("mtl16.obj");
    std::fs::write(
        &path,
        "mtllib big.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    )
    .unwrap();
    let tight = LoadOptions {
        max_memory: 32 << 20,
        ..LoadOptions::default()
    };
    let err = load_scene_with(&path, &tight)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("memory budget") && err.contains("mtl16.obj") && err.contains("big.mtl"),
        "{err}"
    );
    assert_eq!(load_scene(&path).expect("loads").scene.triangle_count(), 1);
}

/// A `mtllib` line with 200 000 names and 100 000 lines naming the same library: at most
/// `MAX_LIBRARIES` (64) libraries are tried, each once, with a bounded number of warnings.
#[test]
fn many_material_library_names() {
    let dir = temp_dir("obj-mtllibs");
    std::fs::write(dir.join("a.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let mut obj = String::from("mtllib a.mtl\nmtllib");
    for i in 0..200_000 {
        obj.push_str(&format!(" missing{i}.mtl"));
    }
    obj.push('\n');
    obj.push_str(&"mtllib a.mtl\n".repeat(100_000));
    obj.push_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n");
    let path = dir.join("many.obj");
    std::fs::write(&path, obj).unwrap();
    let started = std::time::Instant::now();
    let loaded = load_scene(&path).expect("loads");
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
    let scene = &loaded.scene;
    assert_eq!(scene.materials.len(), 1, "a.mtl is read once");
    assert_eq!(
        scene.materials[0].base_color_factor,
        glam::Vec4::new(1.0, 0.0, 0.0, 1.0)
    );
    let warnings = &loaded.info.warnings;
    assert!(warnings.len() <= 70, "{} warnings", warnings.len());
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("more than 64 material libraries")),
        "{warnings:?}"
    );
}

/// A triangle strip or fan of `count` zero indices (an accessor without a buffer view: a few
/// hundred bytes of file), unrolled by the loader into three indices per triangle.
fn strip_bomb(mode: u32, count: u64) -> Gltf {
    let mut g = Gltf::new();
    let positions = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    g.json["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"componentType": 5125, "type": "SCALAR", "count": count}));
    let indices = g.json["accessors"].as_array().unwrap().len() - 1;
    let mesh = g.mesh(
        "strip",
        vec![json!({"attributes": {"POSITION": positions}, "indices": indices, "mode": mode})],
    );
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    g
}

/// Strips and fans are charged as the lists they become: 2 M indices (8 MB) unroll to 24 MB,
/// refused under a 20 MB budget that the indices alone fit; a small strip loads.
#[test]
fn unrolled_strips_and_fans_are_charged() {
    let dir = temp_dir("strip-bomb");
    let options = LoadOptions {
        max_memory: 20 << 20,
        ..LoadOptions::default()
    };
    for (mode, name) in [(5, "strip"), (6, "fan")] {
        let path = dir.join(format!("{name}.glb"));
        strip_bomb(mode, 2_000_000).write_glb(&path);
        let err = load_scene_with(&path, &options)
            .expect_err("must be refused")
            .to_string();
        assert!(err.contains("memory budget"), "{name}: {err}");
        let small = dir.join(format!("small-{name}.glb"));
        strip_bomb(mode, 300).write_glb(&small);
        let loaded = load_scene_with(&small, &options).expect("a small strip loads");
        assert_eq!(loaded.scene.meshes[0].indices.len(), 298 * 3, "{name}");
    }
}

/// Names from the file are kept to 256 characters (an ellipsis marks the cut): a draw, a
/// material and a mesh copy their names per draw, warning and sidecar entry, so a 100 000-
/// character name must not multiply.
#[test]
fn long_names_are_cut() {
    let dir = temp_dir("long-names");
    let long = "é".repeat(100_000);
    let mut g = textured_quad();
    g.json["nodes"][2]["name"] = json!(long);
    g.json["materials"][0]["name"] = json!(long);
    g.json["meshes"][0]["name"] = json!(long);
    let path = dir.join("names.glb");
    g.write_glb(&path);
    let loaded = load_scene(&path).expect("loads");
    let scene = &loaded.scene;
    let draw = scene
        .draws
        .iter()
        .find(|d| d.node_name.starts_with('é'))
        .expect("the quad");
    for name in [
        &draw.node_name,
        &scene.materials[0].name,
        &scene.meshes[0].name,
    ] {
        assert_eq!(name.chars().count(), 257, "{}", name.len());
        assert!(name.ends_with('…'));
    }
}
