//! `KHR_draco_mesh_compression` on the real-world samples: the Draco Duck (the extension
//! required, textured) and BoxDraco (used without being required), against what their
//! accessors declare; broken Draco data gives one line.

use std::path::{Path, PathBuf};

use glam::Vec3;
use kantele::scene::Topology;
use kantele_scene::load_scene;
use serde_json::Value;

use crate::common::temp_dir;

/// The real-world samples, or `None` (with a printed reason) when they are absent.
fn realworld() -> Option<PathBuf> {
    kantele_testkit::shared_dir("realworld")
}

fn json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).expect("read the glTF")).expect("glTF JSON")
}

/// The `min` / `max` an accessor declares.
fn declared_bounds(gltf: &Value, accessor: usize) -> (Vec3, Vec3) {
    let v = |key: &str| {
        let a = gltf["accessors"][accessor][key]
            .as_array()
            .expect("min/max");
        Vec3::new(
            a[0].as_f64().unwrap() as f32,
            a[1].as_f64().unwrap() as f32,
            a[2].as_f64().unwrap() as f32,
        )
    };
    (v("min"), v("max"))
}

fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

#[test]
fn draco_duck_loads_with_its_declared_vertices_bounds_and_texture() {
    let Some(dir) = realworld() else { return };
    let path = dir.join("draco/Duck/Duck.gltf");
    let gltf = json(&path);
    let loaded = load_scene(&path).expect("the Draco Duck loads");
    let scene = &loaded.scene;
    assert_eq!(scene.meshes.len(), 1);
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.topology, Topology::Triangles);
    assert_eq!(mesh.positions.len(), 2399);
    assert_eq!(mesh.indices.len(), 12636, "4212 triangles");
    assert!(mesh.indices.iter().all(|&i| (i as usize) < 2399));

    // Positions: the accessor's bounds, within Draco's quantisation step. The Duck's positions
    // are quantised to 11 bits over their largest extent (what its Draco data says); its
    // declared bounds lie one step outside the decoded ones (a wrong decode is far off).
    let (lo, hi) = declared_bounds(&gltf, 2);
    let step = (hi - lo).max_element() / ((1u32 << 11) - 1) as f32;
    let (dlo, dhi) = bounds(&mesh.positions);
    assert!(
        (dlo - lo).abs().max_element() <= 1.01 * step
            && (dhi - hi).abs().max_element() <= 1.01 * step,
        "decoded bounds {dlo}..{dhi}, declared {lo}..{hi}, step {step}"
    );

    // Normals: unit length (octahedral quantisation), within the declared bounds.
    let normals = mesh.normals.as_ref().expect("normals");
    assert_eq!(normals.len(), 2399);
    assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 0.02));

    // Texture coordinates inside the declared box, and the base colour texture bound to the
    // 512 × 512 DuckCM.png.
    let uv = mesh.texcoords.as_ref().expect("texture coordinates");
    assert_eq!(uv.len(), 2399);
    let uv_min = &gltf["accessors"][3]["min"];
    let uv_max = &gltf["accessors"][3]["max"];
    for t in uv {
        for k in 0..2 {
            let (a, b) = (uv_min[k].as_f64().unwrap(), uv_max[k].as_f64().unwrap());
            let x = t[k] as f64;
            assert!(x >= a - 1e-3 && x <= b + 1e-3, "uv {t} outside {a}..{b}");
        }
    }
    let material = &scene.materials[mesh.material];
    let binding = material.base_color_texture.expect("a base colour texture");
    let texture = &scene.textures[binding.texture];
    assert_eq!((texture.width(), texture.height()), (512, 512));
    assert!(loaded
        .info
        .extensions_used
        .iter()
        .any(|e| e == "KHR_draco_mesh_compression"));
    assert!(
        !loaded.info.warnings.iter().any(|w| w.contains("draco")),
        "{:?}",
        loaded.info.warnings
    );
}

#[test]
fn box_draco_loads_as_the_unit_box() {
    let Some(dir) = realworld() else { return };
    let loaded = load_scene(&dir.join("BoxDraco.gltf")).expect("BoxDraco loads");
    let meshes = &loaded.scene.meshes;
    assert_eq!(meshes.len(), 1);
    let mesh = &meshes[0];
    assert_eq!(mesh.positions.len(), 24);
    assert_eq!(mesh.indices.len(), 36, "12 triangles");
    // Every corner at ±0.5 on each axis (the quantisation grid's ends are exact).
    for p in &mesh.positions {
        assert!(
            (p.abs() - Vec3::splat(0.5)).abs().max_element() < 1e-6,
            "{p}"
        );
    }
    // Each face's normal is an axis, pointing away from the centre, the same for its corners.
    let normals = mesh.normals.as_ref().expect("normals");
    for tri in mesh.indices.chunks_exact(3) {
        let n = normals[tri[0] as usize];
        assert!((n.abs().max_element() - 1.0).abs() < 1e-3, "{n}");
        for &i in tri {
            assert!((normals[i as usize] - n).length() < 1e-3);
            assert!(mesh.positions[i as usize].dot(n) > 0.49);
        }
        // Wound counter-clockwise seen from outside.
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| mesh.positions[i as usize]);
        assert!((b - a).cross(c - a).dot(n) > 0.0);
    }
}

/// The Draco Duck copied into a fresh folder, its JSON and binary given to `edit`.
fn broken_duck(name: &str, edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> Option<PathBuf> {
    let source = realworld()?.join("draco/Duck");
    let dir = temp_dir(name);
    let mut gltf = json(&source.join("Duck.gltf"));
    let mut bin = std::fs::read(source.join("Duck.bin")).expect("read Duck.bin");
    std::fs::copy(source.join("DuckCM.png"), dir.join("DuckCM.png")).expect("copy the texture");
    edit(&mut gltf, &mut bin);
    std::fs::write(dir.join("Duck.bin"), bin).expect("write");
    let path = dir.join("Duck.gltf");
    std::fs::write(&path, serde_json::to_vec(&gltf).unwrap()).expect("write");
    Some(path)
}

fn one_line_error(path: &Path, expected: &str) {
    let err = load_scene(path).expect_err("refused").to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("Duck.gltf") && err.contains("KHR_draco_mesh_compression"),
        "{err}"
    );
    assert!(err.contains(expected), "expected '{expected}' in: {err}");
}

#[test]
fn broken_draco_data_gives_one_line() {
    // The stream cut short (its view ends after 2000 of its 10366 bytes).
    let Some(cut) = broken_duck("draco-cut", |g, _| {
        g["bufferViews"][0]["byteLength"] = 2000.into()
    }) else {
        return;
    };
    one_line_error(&cut, "malformed");
    // Not a Draco stream at all.
    let path = broken_duck("draco-magic", |_, bin| bin[..5].copy_from_slice(b"DRACX")).unwrap();
    one_line_error(&path, "not a Draco stream");
    // An older bitstream than the extension's.
    let path = broken_duck("draco-version", |_, bin| bin[6] = 1).unwrap();
    one_line_error(&path, "bitstream 2.1");
    // Accessors that disagree with the stream.
    let path = broken_duck("draco-count", |g, _| {
        g["accessors"][0]["count"] = 300.into()
    })
    .unwrap();
    one_line_error(&path, "4212 triangles");
    // The stream's bytes scrambled past its header: an error or a load, never a panic.
    for seed in 0..64u64 {
        let path = broken_duck("draco-scrambled", |_, bin| {
            let mut x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
            for _ in 0..8 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let at = 11 + (x % 10_000) as usize;
                bin[at] ^= (x >> 32) as u8 | 1;
            }
        })
        .unwrap();
        if let Err(e) = load_scene(&path) {
            assert_eq!(e.to_string().lines().count(), 1, "{e}");
        }
    }
}
