//! OBJ + MTL files written by the tests.

use crate::common::*;
use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::scene::{AlphaMode, Light};
use kantele::shade::texture::{MinFilter, Wrap};
use kantele_scene::load_scene;

const CUBE_OBJ_WITH_NORMALS: &str = "\
mtllib things.mtl
o quad
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl textured
f 1/1/1 2/2/1 3/3/1 4/4/1
o tri
v 0 0 1
v 1 0 1
v 0 1 1
usemtl glass
f 5 6 7
";

const MTL: &str = "\
newmtl textured
Kd 0.5 0.25 1.0
map_Kd checker.png

newmtl glass
Kd 0.2 0.4 0.6
d 0.25
";

#[test]
fn obj_with_mtl_texture_normals_and_without() {
    let dir = temp_dir("obj");
    std::fs::write(dir.join("things.obj"), CUBE_OBJ_WITH_NORMALS).unwrap();
    std::fs::write(dir.join("things.mtl"), MTL).unwrap();
    std::fs::write(dir.join("checker.png"), test_png()).unwrap();
    let path = dir.join("things.obj");
    let loaded = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let (scene, info) = (&loaded.scene, &loaded.info);
    assert!(info.warnings.is_empty(), "{:?}", info.warnings);
    assert!(!info.camera_from_file);
    assert_eq!(scene.light, Light::Headlight);
    assert_eq!(scene.resolution, (800, 600));
    assert_eq!(scene.draws.len(), 2);
    assert_eq!(scene.triangle_count(), 3);
    assert!(scene.draws.iter().all(|d| d.model == Mat4::IDENTITY));
    assert_eq!(scene.draws[0].node_name, "quad");
    assert_eq!(scene.draws[1].node_index, 1);

    // The quad: smooth normals from the file, v flipped.
    let quad = &scene.meshes[scene.draws[0].mesh];
    assert_eq!(quad.positions.len(), 4);
    assert_eq!(quad.triangle_count(), 2);
    assert!(quad.normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));
    let uv = quad.texcoords.as_ref().unwrap();
    let at = |p: Vec3| uv[quad.positions.iter().position(|q| *q == p).unwrap()];
    assert_eq!(at(Vec3::new(-1.0, -1.0, 0.0)), Vec2::new(0.0, 1.0));
    assert_eq!(at(Vec3::new(1.0, 1.0, 0.0)), Vec2::new(1.0, 0.0));
    let material = &scene.materials[quad.material];
    assert_eq!(material.name, "textured");
    assert_eq!(material.base_color_factor, Vec4::new(0.5, 0.25, 1.0, 1.0));
    assert_eq!(material.alpha_mode, AlphaMode::Opaque);
    let binding = material.base_color_texture.expect("map_Kd");
    assert_eq!(binding.sampler.wrap_s, Wrap::Repeat);
    assert_eq!(binding.sampler.min_filter, MinFilter::LinearMipmapLinear);
    assert_eq!(scene.textures[binding.texture].width(), 2);

    // The triangle: no normals in the file → flat, de-indexed; dissolve → blend.
    let tri = &scene.meshes[scene.draws[1].mesh];
    assert_eq!(tri.positions.len(), 3);
    assert!(tri.normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));
    assert!(tri.texcoords.is_none());
    let glass = &scene.materials[tri.material];
    assert_eq!(glass.alpha_mode, AlphaMode::Blend);
    assert_eq!(glass.base_color_factor, Vec4::new(0.2, 0.4, 0.6, 0.25));

    // The framing camera looks at the scene.
    let (center, _) = scene.bounding_sphere().unwrap();
    assert!(scene.camera.view.transform_point3(center).z < 0.0);
}

#[test]
fn obj_without_mtl_uses_the_default_material() {
    let dir = temp_dir("obj-nomtl");
    let path = dir.join("lonely.obj");
    std::fs::write(
        &path,
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl x\nf 1 2 3 4\n",
    )
    .unwrap();
    let loaded = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        loaded.info.warnings.iter().any(|w| w.contains("material")),
        "{:?}",
        loaded.info.warnings
    );
    let scene = &loaded.scene;
    // OBJ's default material: white, dielectric, double-sided (OBJ states no winding).
    assert_eq!(
        scene.materials,
        vec![kantele::scene::Material {
            double_sided: true,
            metallic: 0.0,
            ..kantele::scene::Material::default()
        }]
    );
    assert_eq!(scene.triangle_count(), 2);
    let mesh = &scene.meshes[0];
    // Flat normals: 6 vertices, all +z.
    assert_eq!(mesh.positions.len(), 6);
    assert!(mesh.normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));
}

/// Real-world OBJ details: texture paths relative to the MTL's folder, one-value
/// colours, Latin-1 names, empty material names, concave faces, `l` lines (kept as line meshes), malformed MTL lines.
#[test]
fn real_world_obj_details() {
    let dir = temp_dir("obj-real");
    std::fs::create_dir_all(dir.join("mats/tex")).unwrap();
    std::fs::write(dir.join("mats/tex/wood.png"), test_png()).unwrap();
    std::fs::write(
        dir.join("mats/lib.mtl"),
        b"newmtl wood\nKd 0.8\nmap_Kd -s 1 1 1 tex/wood.png\nnewmtl broken\nKd 1 1\nd 0.5\nnewmtl\nKd 0.25 0.5 1\n".as_slice(),
    )
    .unwrap();
    let mut obj = b"mtllib mats/lib.mtl\no caf\xe9\n".to_vec();
    // An L-shaped (concave) face, starting at a corner where a fan would leave the shape.
    obj.extend_from_slice(
        b"v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nvt 0 0\nusemtl wood\nf 1/1 2/1 3/1 4/1 5/1 6/1\n",
    );
    obj.extend_from_slice(b"l 1 2 3\nusemtl broken\nf 1 5 6\nusemtl\nf 2 5 6\n");
    let path = dir.join("real.obj");
    std::fs::write(&path, &obj).unwrap();
    let loaded = load_scene(&path).expect("loads");
    let scene = &loaded.scene;
    let warnings = loaded.info.warnings.join("\n");
    // The texture next to the MTL (not next to the OBJ) was found, and Kd 0.8 widened.
    assert_eq!(scene.textures.len(), 1, "{warnings}");
    let wood = scene.materials.iter().find(|m| m.name == "wood").unwrap();
    assert_eq!(wood.base_color_factor.truncate(), glam::Vec3::splat(0.8));
    assert!(wood.base_color_texture.is_some());
    // The malformed `Kd 1 1` falls back to the default colour, with a warning.
    let broken = scene.materials.iter().find(|m| m.name == "broken").unwrap();
    assert_eq!(broken.base_color_factor.truncate(), glam::Vec3::ONE);
    assert!(warnings.contains("Kd 1 1"), "{warnings}");
    // The unnamed material exists and is used.
    assert!(scene
        .materials
        .iter()
        .any(|m| m.name.is_empty() && m.base_color_factor.x == 0.25));
    // The Latin-1 object name.
    assert!(
        scene.meshes.iter().any(|m| m.name == "café"),
        "{:?}",
        scene.meshes.iter().map(|m| &m.name).collect::<Vec<_>>()
    );
    // The L face: 4 triangles of total area 3 (a fan from its first corner would cover 3.5 or
    // leave the shape); the `l` line is not a face.
    let wood_mesh = scene
        .meshes
        .iter()
        .find(|m| scene.materials[m.material].name == "wood")
        .unwrap();
    assert_eq!(wood_mesh.triangle_count(), 4);
    let area: f32 = wood_mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            let p = |i: u32| wood_mesh.positions[i as usize];
            (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).z * 0.5
        })
        .sum();
    assert!((area - 3.0).abs() < 1e-5, "area {area}");
    assert_eq!(scene.triangle_count(), 6);
    // The `l 1 2 3` polyline: two segments under the material in force, with its positions.
    let line = scene
        .meshes
        .iter()
        .find(|m| m.topology == kantele::scene::Topology::Lines)
        .expect("a line mesh");
    assert_eq!(line.indices, vec![0, 1, 1, 2]);
    assert_eq!(line.positions[2], glam::Vec3::new(1.0, 2.0, 0.0));
    assert_eq!(scene.materials[line.material].name, "wood");
    assert!(line.normals.is_none(), "lines keep no made-up normals");
}

/// A huge polygon is refused by the budget before it is parsed.
#[test]
fn huge_obj_polygon_is_refused_by_the_budget() {
    let dir = temp_dir("obj-huge");
    let n = 2_000_000;
    let mut obj = String::with_capacity(n * 16);
    obj.push_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for i in 0..n {
        obj.push_str(&format!(" {}", i % 3 + 1));
    }
    obj.push('\n');
    let path = dir.join("huge.obj");
    std::fs::write(&path, obj).unwrap();
    let options = kantele_scene::LoadOptions {
        max_memory: 64 << 20,
        ..kantele_scene::LoadOptions::default()
    };
    let err = kantele_scene::load_scene_with(&path, &options)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("memory budget") && err.contains("huge.obj"),
        "{err}"
    );
}
