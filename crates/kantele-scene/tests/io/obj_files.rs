//! OBJ + MTL files written by the tests.

use crate::common::*;
use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::scene::{AlphaMode, Light, Topology};
use kantele::shade::texture::{ColorSpace, MinFilter, Wrap};
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
        .find(|m| m.topology == Topology::Lines)
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

/// Writes `files` (name, contents) into a fresh folder; returns the folder.
fn write_files(name: &str, files: &[(&str, &[u8])]) -> std::path::PathBuf {
    let dir = temp_dir(name);
    for (file, bytes) in files {
        std::fs::write(dir.join(file), bytes).unwrap();
    }
    dir
}

/// `text` as UTF-16 with a byte-order mark, little- or big-endian.
fn utf16(text: &str, big_endian: bool) -> Vec<u8> {
    std::iter::once(0xfeff)
        .chain(text.encode_utf16())
        .flat_map(|u: u16| {
            if big_endian {
                u.to_be_bytes()
            } else {
                u.to_le_bytes()
            }
        })
        .collect()
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";

/// OBJ states no winding: a single face must show from behind, so OBJ materials (and the
/// default one) are double-sided.
#[test]
fn obj_materials_are_double_sided() {
    let dir = write_files(
        "obj-two-sided",
        &[
            ("q.mtl", b"newmtl m\nKd 1 0 0\n"),
            (
                "q.obj",
                format!("mtllib q.mtl\n{QUAD}usemtl m\nf 1 2 3 4\nusemtl none\nf 1 3 4\n")
                    .as_bytes(),
            ),
        ],
    );
    let loaded = load_scene(&dir.join("q.obj")).expect("loads");
    assert_eq!(loaded.scene.materials.len(), 2);
    assert!(loaded.scene.materials.iter().all(|m| m.double_sided));
}

/// `mtllib` with several names, and several `mtllib` lines: each library is read; a missing
/// one is a warning, and an error under `strict`.
#[test]
fn several_material_libraries() {
    let dir = write_files(
        "obj-mtllibs",
        &[
            ("a.mtl", b"newmtl red\nKd 1 0 0\n"),
            ("b.mtl", b"newmtl green\nKd 0 1 0\n"),
            ("c d.mtl", b"newmtl blue\nKd 0 0 1\n"),
            (
                "m.obj",
                format!(
                    "mtllib a.mtl gone.mtl b.mtl\nmtllib\tc d.mtl\n{QUAD}\
                     usemtl red\nf 1 2 3\nusemtl green\nf 1 3 4\nusemtl blue\nf 2 3 4\n"
                )
                .as_bytes(),
            ),
        ],
    );
    let path = dir.join("m.obj");
    let loaded = load_scene(&path).expect("loads");
    let scene = &loaded.scene;
    let colour = |mesh: usize| scene.materials[scene.meshes[mesh].material].base_color_factor;
    assert_eq!(scene.meshes.len(), 3);
    assert_eq!(colour(0), Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(colour(1), Vec4::new(0.0, 1.0, 0.0, 1.0));
    assert_eq!(colour(2), Vec4::new(0.0, 0.0, 1.0, 1.0));
    let warnings = &loaded.info.warnings;
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("gone.mtl"), "{warnings:?}");
    let strict = kantele_scene::LoadOptions {
        strict: true,
        ..kantele_scene::LoadOptions::default()
    };
    let err = kantele_scene::load_scene_with(&path, &strict)
        .expect_err("a missing library is an error under strict")
        .to_string();
    assert!(err.contains("m.obj") && err.contains("gone.mtl"), "{err}");
    assert!(!err.contains('\n'), "{err}");
}

/// A line ending in `\` continues on the next one, in OBJ and MTL files.
#[test]
fn continued_lines() {
    let dir = write_files(
        "obj-continued",
        &[
            ("c.mtl", b"newmtl m\nKd 0.5 \\\n 0.25 0.125\n"),
            (
                "c.obj",
                b"mtllib c.mtl\nv 0 0 0\nv 1 0 \\\n0\nv 1 1 0\nv 0 1 0\nusemtl m\nf 1 2 \\\r\n 3 4\n",
            ),
        ],
    );
    let loaded = load_scene(&dir.join("c.obj")).expect("loads");
    let scene = &loaded.scene;
    assert!(
        loaded.info.warnings.is_empty(),
        "{:?}",
        loaded.info.warnings
    );
    assert_eq!(scene.triangle_count(), 2);
    assert_eq!(
        scene.materials[scene.meshes[0].material].base_color_factor,
        Vec4::new(0.5, 0.25, 0.125, 1.0)
    );
}

/// Colours on only some vertices: the others are white.
#[test]
fn vertex_colours_on_some_vertices() {
    let dir = write_files(
        "obj-some-colours",
        &[(
            "v.obj",
            b"v 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0 0 0 1\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n",
        )],
    );
    let loaded = load_scene(&dir.join("v.obj")).expect("loads");
    let mesh = &loaded.scene.meshes[0];
    let colors = mesh.colors.as_ref().expect("colours");
    let at = |p: Vec3| colors[mesh.positions.iter().position(|q| *q == p).unwrap()];
    assert_eq!(at(Vec3::ZERO), Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(at(Vec3::new(1.0, 0.0, 0.0)), Vec4::ONE);
    assert_eq!(at(Vec3::new(1.0, 1.0, 0.0)), Vec4::new(0.0, 0.0, 1.0, 1.0));
    assert_eq!(at(Vec3::new(0.0, 1.0, 0.0)), Vec4::ONE);
}

/// A file of vertices alone (a point cloud) is drawn as points, with its colours; one with
/// `p` statements draws those.
#[test]
fn vertices_alone_are_points() {
    let dir = write_files(
        "obj-points",
        &[
            (
                "cloud.obj",
                b"# scan\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0\n",
            ),
            ("p.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 3\n"),
        ],
    );
    let loaded = load_scene(&dir.join("cloud.obj")).expect("loads");
    assert!(
        loaded.info.warnings.is_empty(),
        "{:?}",
        loaded.info.warnings
    );
    let scene = &loaded.scene;
    assert_eq!(scene.meshes.len(), 1);
    let cloud = &scene.meshes[0];
    assert_eq!(cloud.topology, Topology::Points);
    assert_eq!(cloud.positions.len(), 3);
    assert_eq!(cloud.indices, vec![0, 1, 2]);
    assert_eq!(
        cloud.colors.as_deref(),
        Some(
            &[
                Vec4::new(1.0, 0.0, 0.0, 1.0),
                Vec4::new(0.0, 1.0, 0.0, 1.0),
                Vec4::ONE
            ][..]
        )
    );
    let points = load_scene(&dir.join("p.obj")).expect("loads").scene;
    assert_eq!(points.meshes.len(), 1);
    assert_eq!(points.meshes[0].topology, Topology::Points);
    assert_eq!(points.meshes[0].positions.len(), 2);
}

/// UTF-16 text with a byte-order mark, little- and big-endian, in OBJ and MTL files.
#[test]
fn utf16_files() {
    for big_endian in [false, true] {
        let obj = format!("mtllib u.mtl\no ünï\n{QUAD}usemtl grün\nf 1 2 3 4\n");
        let dir = write_files(
            "obj-utf16",
            &[
                ("u.mtl", &utf16("newmtl grün\nKd 0 1 0\n", big_endian)),
                ("u.obj", &utf16(&obj, big_endian)),
            ],
        );
        let loaded = load_scene(&dir.join("u.obj")).expect("loads");
        assert!(
            loaded.info.warnings.is_empty(),
            "{:?}",
            loaded.info.warnings
        );
        let scene = &loaded.scene;
        assert_eq!(scene.triangle_count(), 2);
        assert_eq!(scene.meshes[0].name, "ünï");
        let material = &scene.materials[scene.meshes[0].material];
        assert_eq!(material.name, "grün");
        assert_eq!(material.base_color_factor, Vec4::new(0.0, 1.0, 0.0, 1.0));
    }
}

/// Texture statements with options: the file name is what the options leave (spaces
/// included, options after it too); `-s` / `-o` move the texture coordinates of the faces
/// using the material, `-clamp on` clamps, `-bm` scales the normal map, `-colorspace` sets
/// the decoding; options that are not applied are named once.
#[test]
fn texture_options() {
    let dir = write_files(
        "obj-texture-options",
        &[
            ("my wood.png", &test_png()),
            ("bump.png", &test_png()),
            (
                "t.mtl",
                b"newmtl m\nmap_Kd -s 2 2 -o 0.5 0 -clamp on -blendu off my wood.png\n\
                  map_Bump -imfchan r bump.png -bm 0.5\n\
                  newmtl n\nmap_Kd -colorspace linear -cc on bump.png\n",
            ),
            (
                "t.obj",
                format!(
                    "mtllib t.mtl\n{QUAD}usemtl m\nf 1/1 2/2 3/3 4/4\nusemtl n\nf 1/1 2/2 3/3\n"
                )
                .as_bytes(),
            ),
        ],
    );
    let loaded = load_scene(&dir.join("t.obj")).expect("loads");
    let scene = &loaded.scene;
    let warnings = loaded.info.warnings.join("\n");
    assert!(!warnings.contains("cannot read"), "{warnings}");
    assert!(
        warnings.contains("-blendu") && warnings.contains("-cc"),
        "{warnings}"
    );
    let m = &scene.materials[scene.meshes[0].material];
    let base = m.base_color_texture.expect("map_Kd");
    assert_eq!(base.sampler.wrap_s, Wrap::ClampToEdge);
    assert_eq!(base.sampler.wrap_t, Wrap::ClampToEdge);
    assert_eq!(
        scene.textures[base.texture].source_color_space(),
        ColorSpace::Srgb
    );
    let normal = m.normal_texture.expect("map_Bump");
    assert_eq!(m.normal_scale, 0.5);
    assert_eq!(normal.sampler.wrap_s, Wrap::Repeat);
    assert_eq!(
        scene.textures[normal.texture].source_color_space(),
        ColorSpace::Linear
    );
    // uv × 2 + (0.5, 0), then v flipped: OBJ (1, 1) → (2.5, 2) → (2.5, −1).
    let quad = &scene.meshes[0];
    let uv = quad.texcoords.as_ref().unwrap();
    let at = |p: Vec3| uv[quad.positions.iter().position(|q| *q == p).unwrap()];
    assert_eq!(at(Vec3::new(1.0, 1.0, 0.0)), Vec2::new(2.5, -1.0));
    assert_eq!(at(Vec3::ZERO), Vec2::new(0.5, 1.0));
    // Material n: the same image as a linear colour texture (one scene texture per file and
    // colour space), and its faces' coordinates unmoved.
    let n = &scene.materials[scene.meshes[1].material];
    let linear = n.base_color_texture.expect("map_Kd").texture;
    assert_eq!(linear, normal.texture);
    let tri = &scene.meshes[1];
    assert!(tri
        .texcoords
        .as_ref()
        .unwrap()
        .contains(&Vec2::new(1.0, 0.0)));
    assert_eq!(scene.textures.len(), 2);
}

/// tinyobjloader's issue files, copied with an image for every texture they name: each
/// statement's options are read and its texture is found.
#[test]
fn tinyobjloader_texture_option_files() {
    let Some(realworld) = kantele_testkit::shared_dir("realworld") else {
        return;
    };
    let source = realworld.join("obj-mtl");
    for name in [
        "colorspace-issue-184",
        "mtllib-multiple-files-issue-112",
        "texture-options-issue-85",
    ] {
        let dir = temp_dir(name);
        for ext in ["obj", "mtl"] {
            let file = format!("{name}.{ext}");
            std::fs::copy(source.join(&file), dir.join(&file)).unwrap();
        }
        let mtl = std::fs::read_to_string(dir.join(format!("{name}.mtl"))).unwrap();
        let mut images = Vec::new();
        for word in mtl.split_whitespace() {
            if word.ends_with(".jpg") || word.ends_with(".png") {
                std::fs::write(dir.join(word), test_png()).unwrap();
                images.push(word.to_string());
            }
        }
        let strict = kantele_scene::LoadOptions {
            strict: true,
            ..kantele_scene::LoadOptions::default()
        };
        let path = dir.join(format!("{name}.obj"));
        let loaded = if name.starts_with("mtllib") {
            // Two of its three libraries do not exist: a warning each.
            let loaded = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
            let missing = loaded
                .info
                .warnings
                .iter()
                .filter(|w| w.contains("invalid-file"))
                .count();
            assert_eq!(missing, 2, "{:?}", loaded.info.warnings);
            loaded
        } else {
            kantele_scene::load_scene_with(&path, &strict).unwrap_or_else(|e| panic!("{e}"))
        };
        let scene = &loaded.scene;
        let material = &scene.materials[scene.meshes[0].material];
        assert_eq!(material.name, "default", "{name}");
        assert!(material.base_color_texture.is_some(), "{name}");
        match name {
            "colorspace-issue-184" => {
                let normal = material.normal_texture.expect("map_bump");
                assert_eq!(material.normal_scale, 3.0);
                assert_eq!(
                    scene.textures[normal.texture].source_color_space(),
                    ColorSpace::Linear
                );
                assert!(material.specular_color_texture.is_some());
            }
            "texture-options-issue-85" => {
                // Every material's map_Kd, map_Ks, map_Ns (roughness) and bump map.
                for m in &scene.materials {
                    assert!(m.base_color_texture.is_some(), "{}", m.name);
                    assert!(m.specular_color_texture.is_some(), "{}", m.name);
                    assert!(m.metallic_roughness_texture.is_some(), "{}", m.name);
                    assert!(m.normal_texture.is_some(), "{}", m.name);
                }
                let bm2 = scene.materials.iter().find(|m| m.name == "bm2").unwrap();
                assert_eq!(bm2.normal_scale, 1.5);
                // bm3's map_d makes its base colour blend.
                let bm3 = scene.materials.iter().find(|m| m.name == "bm3").unwrap();
                assert_eq!(bm3.alpha_mode, AlphaMode::Blend);
                let ignored = loaded.info.warnings.join("\n");
                for what in ["map_Ka", "disp", "-blendu", "-mm", "-t", "-type"] {
                    assert!(ignored.contains(what), "{what}: {ignored}");
                }
            }
            _ => {}
        }
        assert!(
            !loaded
                .info
                .warnings
                .iter()
                .any(|w| w.contains("texture") && w.contains("cannot read")),
            "{name}: {:?} (images {images:?})",
            loaded.info.warnings
        );
    }
}

/// Vertex colours are sRGB-encoded display colours, as PLY's: decoded to linear (0.5 →
/// 0.214), clamped to [0, 1] first; faces and point clouds alike.
#[test]
fn vertex_colours_are_decoded_from_srgb() {
    let dir = write_files(
        "obj-srgb-colours",
        &[
            (
                "t.obj",
                b"v 0 0 0 0.5 1.5 -1\nv 1 0 0 0.5 1.5 -1\nv 0 1 0 0.5 1.5 -1\nf 1 2 3\n",
            ),
            ("cloud.obj", b"v 0 0 0 0.5 0.5 0.5\nv 1 0 0 0.5 0.5 0.5\n"),
        ],
    );
    let half = kantele::color::srgb_to_linear(0.5);
    assert!((half - 0.214).abs() < 1e-3, "{half}");
    for (file, want) in [
        ("t.obj", Vec4::new(half, 1.0, 0.0, 1.0)),
        ("cloud.obj", Vec4::new(half, half, half, 1.0)),
    ] {
        let loaded = load_scene(&dir.join(file)).expect("loads");
        let colors = loaded.scene.meshes[0].colors.as_ref().expect("colours");
        assert!(colors.iter().all(|c| *c == want), "{file}: {colors:?}");
    }
}

/// A material with a normal map (`norm`) gives its meshes MikkTSpace tangents when the file is
/// drawn with PBR shading (OBJ's default, Lambert, reads none).
#[test]
fn normal_mapped_materials_get_tangents() {
    let dir = write_files(
        "obj-normal-map",
        &[
            (
                "n.obj",
                b"mtllib n.mtl\nusemtl bumpy\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n",
            ),
            ("n.mtl", b"newmtl bumpy\nnorm bumps.png\n"),
        ],
    );
    std::fs::write(dir.join("bumps.png"), test_png()).expect("write");
    let lambert = load_scene(&dir.join("n.obj")).expect("loads");
    assert!(lambert.scene.meshes[0].tangents.is_none());
    let pbr = kantele_scene::LoadOptions {
        shading: Some(kantele::scene::Shading::Pbr),
        ..Default::default()
    };
    let loaded = kantele_scene::load_scene_with(&dir.join("n.obj"), &pbr).expect("loads");
    let mesh = &loaded.scene.meshes[0];
    let tangents = mesh.tangents.as_ref().expect("tangents");
    assert_eq!(tangents.len(), mesh.positions.len());
    // u along +x; OBJ's v runs up the image, so the bitangent n × t = +y needs w = +1.
    for t in tangents {
        assert!(t.abs_diff_eq(Vec4::new(1.0, 0.0, 0.0, 1.0), 1e-5), "{t}");
    }
}
