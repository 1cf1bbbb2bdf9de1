//! The corpus: small files written here, one per feature, and the real sample files of
//! `$KANTELE_SHARED/realworld`, each loaded and rendered with the CPU backend at a small size and
//! checked by a property the picture must show.
//!
//! The real files are read from the shared test data (never copied into the repository; see
//! `docs/rendering-rules.md`, "Reference scenes"). When they are absent the test says so and
//! skips them, unless `KANTELE_REQUIRE` contains `realworld`, where it fails.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::common::*;
use glam::Vec4;
use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::scene::{AlphaMode, Scene};
use kantele_scene::{load_scene, load_scene_with, LoadedScene};
use serde_json::json;

const SIZE: (u32, u32) = (160, 120);

/// Renders the scene's own view at [`SIZE`] in the given pass.
fn render(scene: &Scene, pass: Pass) -> FrameImage {
    let mut scene = scene.clone();
    scene.resolution = SIZE;
    let scene = Arc::new(scene);
    let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu backend");
    cpu.load(scene.clone())
        .expect("scene loads into the backend");
    let view = FrameView {
        pass,
        ..FrameView::of_scene(&scene)
    };
    cpu.render(&view).expect("render");
    cpu.read_frame().expect("read")
}

/// Pixels whose depth was written (drawn by an opaque or mask primitive).
fn coverage(image: &FrameImage) -> usize {
    image.depth.iter().filter(|d| **d < 1.0).count()
}

fn pixel(image: &FrameImage, x: u32, y: u32) -> Vec4 {
    Vec4::from_array(image.color[(y * image.width + x) as usize])
}

/// Loads with the Lambert rule: the features' pixels below are checked against it (no tone
/// map, no environment). PBR pictures are checked by the PBR tests; the real files below are
/// also loaded as a user gets them ([`load_as_chosen`]).
fn load(path: &Path) -> LoadedScene {
    let options = kantele_scene::LoadOptions {
        shading: Some(kantele::scene::Shading::Lambert),
        ..kantele_scene::LoadOptions::default()
    };
    load_scene_with(path, &options)
        .unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

/// Loads with the default options: the file's own shading model (PBR for these).
fn load_as_chosen(path: &Path) -> LoadedScene {
    load_scene(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

/// A unit quad in the z = 0 plane facing +z, seen by a camera at z = 3, with a material.
fn quad_scene(material: serde_json::Value) -> Gltf {
    let mut g = Gltf::new();
    let p = g.vec3(&[
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ]);
    let t = g.vec2(&[[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
    let i = g.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let m = g.material(material);
    let mesh = g.mesh(
        "quad",
        vec![json!({"attributes": {"POSITION": p, "TEXCOORD_0": t}, "indices": i, "material": m})],
    );
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    let cam = g.camera(json!({"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}}));
    let cam_node = g.node(json!({"camera": cam, "translation": [0.0, 0.0, 3.0]}));
    g.root(cam_node);
    g
}

fn write(g: &Gltf, name: &str) -> PathBuf {
    let path = temp_dir(&format!("corpus-{name}")).join(format!("{name}.glb"));
    g.write_glb(&path);
    path
}

#[test]
fn blend_drawn_after_opaque_back_to_front() {
    // A red BLEND panel in front, listed first; a grey opaque wall behind, listed later. In
    // file order the wall would overwrite the panel (the panel writes no depth).
    let mut g = quad_scene(
        json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.0, 0.0, 0.5]}, "alphaMode": "BLEND"}),
    );
    let wall = g.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]}, "extensions": {"KHR_materials_unlit": {}}}));
    let mesh = g.json["meshes"][0].clone();
    let mut wall_mesh = mesh.clone();
    wall_mesh["primitives"][0]["material"] = json!(wall);
    g.json["meshes"].as_array_mut().unwrap().push(wall_mesh);
    let wall_node =
        g.node(json!({"mesh": 1, "translation": [0.0, 0.0, -1.0], "scale": [3.0, 3.0, 1.0]}));
    g.root(wall_node);
    let loaded = load(&write(&g, "blend"));
    let image = render(&loaded.scene, Pass::Color);
    let centre = pixel(&image, SIZE.0 / 2, SIZE.1 / 2);
    assert!(
        centre.x > centre.y + 0.1,
        "the blend panel must tint the wall red: {centre}"
    );
}

#[test]
fn emissive_label_glows() {
    // Black base colour, lit from behind (no direct light): only emission makes it bright.
    let g = quad_scene(json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0]},
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 0.8}}
    }));
    let loaded = load(&write(&g, "emissive"));
    let c = pixel(&render(&loaded.scene, Pass::Color), SIZE.0 / 2, SIZE.1 / 2);
    assert!((c.x - 0.8).abs() < 1e-3 && (c.y - 0.4).abs() < 1e-3, "{c}");
}

/// A 2 × 2 texture: red, green / blue, white.
fn four_colour_png() -> Vec<u8> {
    png(
        2,
        2,
        &[
            255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255,
        ],
    )
}

fn textured_material(g: &mut Gltf, info: serde_json::Value) -> serde_json::Value {
    let image = g.image(four_colour_png());
    let sampler =
        g.sampler(json!({"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}));
    let texture = g.texture(json!({"source": image, "sampler": sampler}));
    let mut info = info;
    info["index"] = json!(texture);
    json!({"pbrMetallicRoughness": {"baseColorTexture": info}, "extensions": {"KHR_materials_unlit": {}}})
}

#[test]
fn texture_transform_and_second_texcoord_set() {
    // Offset (0.5, 0) with scale 0.5: the quad shows only the texture's right column's top
    // texel region: its top-left corner is green, not red.
    let mut g = quad_scene(json!({}));
    let m = textured_material(
        &mut g,
        json!({"extensions": {"KHR_texture_transform": {"offset": [0.5, 0.0], "scale": [0.5, 0.5]}}}),
    );
    g.json["materials"][0] = m;
    g.json["extensionsUsed"] = json!(["KHR_texture_transform", "KHR_materials_unlit"]);
    let loaded = load(&write(&g, "transform"));
    let image = render(&loaded.scene, Pass::Color);
    let c = pixel(&image, SIZE.0 / 2, SIZE.1 / 2);
    assert!(
        c.y > 0.9 && c.x < 0.1 && c.z < 0.1,
        "expected green everywhere: {c}"
    );
    assert!(!loaded
        .info
        .warnings
        .iter()
        .any(|w| w.contains("KHR_texture_transform")));

    // TEXCOORD_1 holds the real coordinates; TEXCOORD_0 is all zeros (red).
    let mut g = quad_scene(json!({}));
    let zeros = g.vec2(&[[0.0, 0.0]; 4]);
    let real = g.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"].clone();
    g.json["meshes"][0]["primitives"][0]["attributes"] = json!({
        "POSITION": g.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"], "TEXCOORD_0": zeros, "TEXCOORD_1": real
    });
    let m = textured_material(&mut g, json!({"texCoord": 1}));
    g.json["materials"][0] = m;
    let loaded = load(&write(&g, "texcoord1"));
    let image = render(&loaded.scene, Pass::Color);
    // Bottom-right quarter of the quad is white (texel (1, 1)).
    let c = pixel(&image, SIZE.0 / 2 + 20, SIZE.1 / 2 + 20);
    assert!(c.x > 0.9 && c.y > 0.9 && c.z > 0.9, "expected white: {c}");
}

#[test]
fn instancing_draws_every_instance() {
    let mut g = quad_scene(json!({}));
    // 125 small instances on a 5 × 5 × 5 grid (x, y spread, z stacked): coverage as 25 quads.
    let mut translations = Vec::new();
    for z in 0..5 {
        for y in 0..5 {
            for x in 0..5 {
                translations.push([
                    x as f32 * 0.4 - 0.8,
                    y as f32 * 0.4 - 0.8,
                    -(z as f32) * 0.1,
                ]);
            }
        }
    }
    let t = g.vec3(&translations);
    let s = g.vec3(&[[0.1, 0.1, 0.1]; 125]);
    g.json["nodes"][0]["extensions"] =
        json!({"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t, "SCALE": s}}});
    g.json["extensionsUsed"] = json!(["EXT_mesh_gpu_instancing"]);
    let instanced = load(&write(&g, "instanced"));
    assert_eq!(instanced.scene.draws.len(), 125);
    let covered = coverage(&render(&instanced.scene, Pass::Color));
    // One instance alone.
    let mut one = instanced.scene.clone();
    one.draws.truncate(1);
    let single = coverage(&render(&one, Pass::Color));
    assert!(single > 10, "one instance covers {single}");
    // At least the 25 front instances, each as large as the single (front) one; the stacked
    // ones behind peek out by perspective, but never more than 125 instances' worth.
    assert!(
        covered as f32 > 24.0 * single as f32 && covered < 125 * single,
        "{covered} vs {single}"
    );
}

#[test]
fn default_morph_weights_shape_the_rest_pose() {
    let mut g = quad_scene(json!({}));
    let shift = g.vec3(&[[1.0, 0.0, 0.0]; 4]);
    g.json["meshes"][0]["primitives"][0]["targets"] = json!([{"POSITION": shift}]);
    g.json["meshes"][0]["weights"] = json!([0.5]);
    let loaded = load(&write(&g, "morph"));
    let image = render(&loaded.scene, Pass::Color);
    // The quad moved right by half a unit: the left edge region is empty, the right filled.
    let row = SIZE.1 / 2;
    let first = (0..SIZE.0)
        .find(|&x| image.depth[(row * SIZE.0 + x) as usize] < 1.0)
        .unwrap();
    let last = (0..SIZE.0)
        .rev()
        .find(|&x| image.depth[(row * SIZE.0 + x) as usize] < 1.0)
        .unwrap();
    let centre = (first + last) as f32 / 2.0;
    assert!(
        centre > SIZE.0 as f32 / 2.0 + 5.0,
        "coverage centre {centre}"
    );
}

#[test]
fn quantized_positions_draw_like_floats() {
    let float = load(&write(&quad_scene(json!({})), "float"));
    let mut g = quad_scene(json!({}));
    let bytes: Vec<u8> = [
        [-1i16, -1, 0, 0],
        [1, -1, 0, 0],
        [1, 1, 0, 0],
        [-1, 1, 0, 0],
    ]
    .iter()
    .flatten()
    .flat_map(|v| (v * 32767).to_le_bytes())
    .collect();
    let view = g.view(&bytes);
    g.json["bufferViews"][view]["byteStride"] = json!(8);
    g.json["accessors"].as_array_mut().unwrap().push(json!({
        "bufferView": view, "componentType": 5122, "normalized": true, "type": "VEC3", "count": 4,
        "min": [-1, -1, 0], "max": [1, 1, 0]
    }));
    let index = g.json["accessors"].as_array().unwrap().len() - 1;
    g.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(index);
    g.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    g.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let quantized = load(&write(&g, "quantized"));
    let a = coverage(&render(&float.scene, Pass::Color));
    let b = coverage(&render(&quantized.scene, Pass::Color));
    assert!(a > 1000 && a == b, "{a} vs {b}");
}

#[test]
fn nan_positions_warn() {
    let mut g = Gltf::new();
    let p = g.vec3(&[
        [0.0, 0.0, 0.0],
        [f32::NAN, 0.0, 0.0],
        [0.0, f32::INFINITY, 0.0],
    ]);
    let mesh = g.mesh("nan", vec![json!({"attributes": {"POSITION": p}})]);
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    let loaded = load(&write(&g, "nan"));
    assert!(
        loaded
            .info
            .warnings
            .iter()
            .any(|w| w.contains("infinite or NaN")),
        "{:?}",
        loaded.info.warnings
    );
}

#[test]
fn missing_texture_renders_untextured() {
    let mut g = quad_scene(json!({}));
    let m = textured_material(&mut g, json!({}));
    g.json["materials"][0] = m;
    g.json["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] =
        json!([0.25, 0.5, 1.0, 1.0]);
    let dir = temp_dir("corpus-missing-texture");
    let path = dir.join("missing.gltf");
    g.write_gltf_external(&path);
    std::fs::remove_file(dir.join("missing-image0.png")).unwrap();
    let loaded = load(&path);
    let c = pixel(&render(&loaded.scene, Pass::Color), SIZE.0 / 2, SIZE.1 / 2);
    assert_eq!(c.truncate(), glam::Vec3::new(0.25, 0.5, 1.0));
}

#[test]
fn concave_obj_face_keeps_its_notch() {
    let dir = temp_dir("corpus-obj");
    let path = dir.join("l.obj");
    // An L: the top-right square (1..2, 1..2) is the notch. Starting at the corner (2, 1) a
    // fan would cover the notch.
    std::fs::write(
        &path,
        "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nf 1 2 3 4 5 6\n",
    )
    .unwrap();
    let mut scene = load(&path).scene;
    scene.camera = kantele::scene::Camera::framing(
        glam::Vec3::new(1.0, 1.0, 0.0),
        1.5,
        glam::Vec3::Z,
        4.0 / 3.0,
    );
    let image = render(&scene, Pass::Color);
    let covered = coverage(&image);
    // Compare with the full square: the L covers three quarters of it.
    let mut square = scene.clone();
    square.meshes[0].positions = vec![
        glam::Vec3::ZERO,
        glam::Vec3::new(2.0, 0.0, 0.0),
        glam::Vec3::new(2.0, 2.0, 0.0),
        glam::Vec3::new(0.0, 2.0, 0.0),
    ];
    square.meshes[0].normals = Some(vec![glam::Vec3::Z; 4]);
    square.meshes[0].indices = vec![0, 1, 2, 0, 2, 3];
    let full = coverage(&render(&square, Pass::Color));
    let ratio = covered as f32 / full as f32;
    assert!((ratio - 0.75).abs() < 0.02, "L / square = {ratio}");
}

/// OBJ states no winding: a single quad seen from behind is drawn (its material is
/// double-sided), where culling would leave the same view empty.
#[test]
fn single_obj_quad_seen_from_behind_draws() {
    let dir = temp_dir("corpus-obj-behind");
    let path = dir.join("quad.obj");
    // Counter-clockwise seen from +z: its front faces +z; the camera looks from −z.
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let mut scene = load(&path).scene;
    scene.camera = kantele::scene::Camera::framing(
        glam::Vec3::new(0.5, 0.5, 0.0),
        1.0,
        -glam::Vec3::Z,
        4.0 / 3.0,
    );
    assert!(scene.materials.iter().all(|m| m.double_sided));
    assert!(
        coverage(&render(&scene, Pass::Color)) > 0,
        "the quad shows from behind"
    );
    let mut culled = scene.clone();
    for m in &mut culled.materials {
        m.double_sided = false;
    }
    assert_eq!(
        coverage(&render(&culled, Pass::Color)),
        0,
        "single-sided, the camera sees its back"
    );
}

/// The real-world samples (`$KANTELE_SHARED/realworld`), or `None` (with a printed reason)
/// when they are absent; absent and required (`KANTELE_REQUIRE` contains `realworld`) fails.
fn realworld() -> Option<PathBuf> {
    kantele_testkit::shared_dir("realworld")
}

/// Share of pixels covered in the colour pass.
fn covered_share(scene: &Scene) -> f32 {
    coverage(&render(scene, Pass::Color)) as f32 / (SIZE.0 * SIZE.1) as f32
}

#[test]
fn realworld_files_render_with_their_properties() {
    let Some(dir) = realworld() else { return };
    // Every listed file loads and shows something.
    let files = [
        "AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb",
        "Avocado/glTF-Quantized/Avocado.gltf",
        "TextureTransformMultiTest/glTF-Binary/TextureTransformMultiTest.glb",
        "MorphPrimitivesTest/glTF-Binary/MorphPrimitivesTest.glb",
        "ClearCoatTest/glTF-Binary/ClearCoatTest.glb",
        "TextureCoordinateTest/glTF-Binary/TextureCoordinateTest.glb",
        "TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb",
        "OrientationTest/glTF-Binary/OrientationTest.glb",
        "NegativeScaleTest/glTF-Binary/NegativeScaleTest.glb",
        "VertexColorTest/glTF-Binary/VertexColorTest.glb",
        "MultipleScenes/glTF/MultipleScenes.gltf",
        "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf",
        "CesiumMilkTruck/glTF-Binary/CesiumMilkTruck.glb",
        "2CylinderEngine/2CylinderEngine.glb",
    ];
    for file in files {
        let path = dir.join(file);
        let loaded = load_as_chosen(&path);
        assert_eq!(loaded.scene.shading, kantele::scene::Shading::Pbr, "{file}");
        let share = covered_share(&loaded.scene);
        assert!(share > 0.01, "{file}: only {share} of the picture covered");
        let lambert = covered_share(&load(&path).scene);
        assert_eq!(
            share, lambert,
            "{file}: PBR and Lambert cover different pixels"
        );
        // Features this loader handles are never reported as ignored.
        for handled in [
            "KHR_mesh_quantization",
            "KHR_texture_transform",
            "KHR_materials_emissive_strength",
            "KHR_materials_clearcoat",
            "KHR_materials_ior",
            "KHR_materials_specular",
        ] {
            assert!(
                !loaded.info.ignored.iter().any(|i| i == handled),
                "{file}: {handled} reported as ignored"
            );
        }
    }

    // TextureTransformMultiTest: the transformed TEXCOORD_0 and TEXCOORD_1 of the test cells
    // land inside the atlas region of the untransformed sample cell (the same checkmark; a
    // wrong rotation direction lands elsewhere and draws a crossed shape).
    let loaded = load(&dir.join(files[2]));
    let uv_box = |name: &str| {
        let mesh = loaded
            .scene
            .meshes
            .iter()
            .find(|m| m.name == name)
            .expect(name);
        let uv = mesh.texcoords.as_ref().expect("texcoords");
        uv.iter()
            .fold((glam::Vec2::MAX, glam::Vec2::MIN), |(lo, hi), t| {
                (lo.min(*t), hi.max(*t))
            })
    };
    let sample = uv_box("BaseColorSample");
    for cell in ["BaseColorUV0", "BaseColorUV1"] {
        let (lo, hi) = uv_box(cell);
        let eps = 0.02; // the cells' margins differ slightly; a wrong rotation is ~0.3 away
        assert!(
            lo.cmpge(sample.0 - eps).all() && hi.cmple(sample.1 + eps).all(),
            "{cell}: uv box {lo}..{hi} outside the sample's {}..{}",
            sample.0,
            sample.1
        );
    }

    // Draco used without being required is decoded (draco_files.rs checks the box).
    assert_eq!(load(&dir.join("BoxDraco.gltf")).scene.meshes.len(), 1);

    // AlphaBlendModeTest: the BLEND primitives stay visible (drawn last, back to front): in the
    // id pass, which writes the draw id of the last fragment drawn, BLEND draws own pixels.
    let loaded = load(&dir.join(files[0]));
    let scene = &loaded.scene;
    let ids = render(scene, Pass::Ids);
    let blend_pixels = ids
        .color
        .iter()
        .filter(|c| {
            let draw = c[2] as usize;
            draw >= 1 && {
                let d = &scene.draws[draw - 1];
                scene.materials[scene.meshes[d.mesh].material].alpha_mode == AlphaMode::Blend
            }
        })
        .count();
    assert!(
        blend_pixels as f32 > 0.01 * (SIZE.0 * SIZE.1) as f32,
        "the Blend panel is hidden ({blend_pixels} pixels)"
    );

    // ClearCoatTest: the emissive labels glow: without emission the picture is darker.
    let loaded = load(&dir.join(files[4]));
    assert!(loaded
        .scene
        .materials
        .iter()
        .any(|m| m.emissive != glam::Vec3::ZERO));
    let lit = render(&loaded.scene, Pass::Color);
    let mut dark = loaded.scene.clone();
    for m in &mut dark.materials {
        m.emissive = glam::Vec3::ZERO;
    }
    let unlit = render(&dark, Pass::Color);
    let bright = |img: &FrameImage| {
        img.color
            .iter()
            .filter(|c| c[0] + c[1] + c[2] > 2.4)
            .count()
    };
    assert!(
        bright(&lit) > bright(&unlit) + 50,
        "labels do not glow: {} vs {}",
        bright(&lit),
        bright(&unlit)
    );

    // ClearCoatTest as chosen (PBR): its coats are read — factors, the coat and coat-roughness
    // textures and the coat normal texture — and they show: without them the picture differs
    // (by 194 pixels when this was written).
    let loaded = load_as_chosen(&dir.join(files[4]));
    let materials = &loaded.scene.materials;
    let coated = materials.iter().filter(|m| m.has_clearcoat()).count();
    assert!(coated >= 6, "{coated} coated materials");
    assert!(materials.iter().any(|m| m.clearcoat_texture.is_some()));
    assert!(materials
        .iter()
        .any(|m| m.clearcoat_roughness_texture.is_some()));
    assert!(materials
        .iter()
        .any(|m| m.clearcoat_normal_texture.is_some()));
    let coats = render(&loaded.scene, Pass::Color);
    let mut bare = loaded.scene.clone();
    for m in &mut bare.materials {
        m.clearcoat = 0.0;
    }
    let without = render(&bare, Pass::Color);
    let changed = coats
        .color
        .iter()
        .zip(&without.color)
        .filter(|(a, b)| {
            (Vec4::from_array(**a) - Vec4::from_array(**b))
                .abs()
                .max_element()
                > 0.02
        })
        .count();
    // At this size the six coated spheres cover about 1500 pixels; a coat over a lit sphere
    // changes its rim (Fresnel) and its highlight by more than 0.02, the rest by less.
    assert!(changed > 100, "the coats change only {changed} pixels");
}

#[test]
fn realworld_ply_and_stl_files_render() {
    let Some(dir) = realworld() else { return };
    // Scans and CAD exports (`ply-stl/`): drawn with the Lambert rule, light grey and
    // double-sided, framed by the made-up camera.
    let meshes = [
        "ply-stl/bunny.ply",
        "ply-stl/cube_blender_uv.ply",
        "ply-stl/20mm-xyz-cube.stl",
        "ply-stl/cylinder.stl",
        "ply-stl/featuretype.STL",
    ];
    for file in meshes {
        let loaded = load_as_chosen(&dir.join(file));
        assert_eq!(
            loaded.scene.shading,
            kantele::scene::Shading::Lambert,
            "{file}"
        );
        let image = render(&loaded.scene, Pass::Color);
        let share = coverage(&image) as f32 / (SIZE.0 * SIZE.1) as f32;
        assert!(share > 0.05, "{file}: only {share} of the picture covered");
        // Lit, not black: the headlight reaches what the camera sees, front or back.
        let brightest = image
            .color
            .iter()
            .zip(&image.depth)
            .filter(|(_, d)| **d < 1.0)
            .map(|(c, _)| c[0])
            .fold(0.0f32, f32::max);
        assert!(brightest > 0.3, "{file}: brightest {brightest}");
    }
    // The point cloud: its 8 points, one pixel each.
    let loaded = load_as_chosen(&dir.join("ply-stl/ply_points_bin.ply"));
    let drawn = coverage(&render(&loaded.scene, Pass::Color));
    assert!((1..=8).contains(&drawn), "{drawn} pixels");
}

/// Renders the scene as the CLI does (`kantele_output::pose`: pixels square, the image's aspect
/// wins) with its file camera at [`SIZE`].
fn render_posed(scene: &Scene) -> FrameImage {
    let pose = kantele_output::pose::CameraPose::from_scene_camera(&scene.camera, SIZE.0, SIZE.1)
        .expect("usable camera");
    let scene = Arc::new(scene.clone());
    let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu backend");
    cpu.load(scene.clone()).expect("load");
    cpu.render(&pose.frame_view(&scene, Pass::Color))
        .expect("render");
    cpu.read_frame().expect("read")
}

/// Drawn pixels as `(x, y)`.
fn drawn_pixels(image: &FrameImage) -> Vec<(u32, u32)> {
    (0..image.width * image.height)
        .filter(|&i| image.depth[i as usize] < 1.0)
        .map(|i| (i % image.width, i / image.width))
        .collect()
}

/// An orthographic camera at z = 5 looking down −z whose view volume maps one scene unit to one
/// pixel at [`SIZE`] (ymag = 60 for 120 rows; xmag follows the image's aspect), and one mesh of
/// the given primitives (no normals: drawn unlit, white).
fn pixel_grid_scene(primitive: serde_json::Value) -> Gltf {
    let mut g = Gltf::new();
    let mesh = g.mesh("wide", vec![primitive]);
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    let cam = g.camera(json!({"type": "orthographic", "orthographic": {"xmag": 80.0, "ymag": 60.0, "znear": 1.0, "zfar": 10.0}}));
    let cam_node = g.node(json!({"camera": cam, "translation": [0.0, 0.0, 5.0]}));
    g.root(cam_node);
    g
}

/// Scene position of the centre of pixel `(x, y)` on the [`pixel_grid_scene`] camera.
fn pixel_centre(x: u32, y: u32) -> [f32; 3] {
    let (w, h) = (SIZE.0 as f32, SIZE.1 as f32);
    [x as f32 + 0.5 - w / 2.0, h / 2.0 - (y as f32 + 0.5), 0.0]
}

#[test]
fn a_gltf_line_covers_one_pixel_per_column_and_a_point_one_pixel() {
    // LINES from the centre of pixel (10, 49) to that of (140, 29): the start pixel's diamond
    // is left (drawn), the end's only entered (not drawn): columns 10..140, one pixel each.
    let mut g = pixel_grid_scene(json!({"attributes": {"POSITION": 0}, "mode": 1}));
    g.vec3(&[pixel_centre(10, 49), pixel_centre(140, 29)]);
    let loaded = load(&write(&g, "gltf-line"));
    assert_eq!(
        loaded.scene.meshes[0].topology,
        kantele::scene::Topology::Lines
    );
    let image = render_posed(&loaded.scene);
    let pixels = drawn_pixels(&image);
    assert_eq!(pixels.len(), 130, "{pixels:?}");
    let columns: std::collections::BTreeSet<u32> = pixels.iter().map(|p| p.0).collect();
    assert_eq!(columns, (10..140).collect(), "one pixel per column");
    assert!(pixels.contains(&(10, 49)) && pixels.contains(&(139, 29)));
    // Unlit white (no normals), not the ambient-only grey a lit line would get.
    let c = pixel(&image, 10, 49);
    assert!(c.truncate().min_element() > 0.99, "{c}");

    // POINTS: a point a quarter pixel off the centre of pixel (80, 59) draws that pixel only.
    let mut g = pixel_grid_scene(json!({"attributes": {"POSITION": 0}, "mode": 0}));
    let [x, y, z] = pixel_centre(80, 59);
    g.vec3(&[[x + 0.25, y - 0.25, z], [x - 30.0, y + 20.0, z]]);
    let loaded = load(&write(&g, "gltf-points"));
    let pixels = drawn_pixels(&render_posed(&loaded.scene));
    assert_eq!(pixels, vec![(50, 39), (80, 59)]);
}

#[test]
fn every_primitive_mode_draws_something() {
    // A square outline / its corners in each of glTF's seven modes (as the sample models
    // `Mesh_PrimitiveMode_*` do): none may come out black.
    for mode in 0..=6u32 {
        let mut g = pixel_grid_scene(json!({"attributes": {"POSITION": 0}, "mode": mode}));
        // Corners on pixel centres (80 ± 30.5, 60 ± 30.5 in window pixels).
        let s = 30.5;
        let corners = [[-s, -s, 0.0], [s, -s, 0.0], [s, s, 0.0], [-s, s, 0.0]];
        let positions: Vec<[f32; 3]> = match mode {
            1 => vec![
                corners[0], corners[1], corners[1], corners[2], corners[2], corners[3], corners[3],
                corners[0],
            ],
            4 => vec![
                corners[0], corners[1], corners[2], corners[0], corners[2], corners[3],
            ],
            5 => vec![corners[0], corners[1], corners[3], corners[2]],
            _ => corners.to_vec(),
        };
        g.vec3(&positions);
        let loaded = load(&write(&g, &format!("mode-{mode}")));
        assert!(
            loaded.info.warnings.is_empty(),
            "mode {mode}: {:?}",
            loaded.info.warnings
        );
        let drawn = drawn_pixels(&render_posed(&loaded.scene)).len();
        let want = match mode {
            0 => 4,       // points
            1 | 2 => 244, // four sides of 61 pixels, each corner drawn once (by the side leaving it)
            3 => 183,     // an open strip: three sides, its last corner not drawn
            _ => 3721,    // a filled 61 × 61 square
        };
        assert_eq!(drawn, want, "mode {mode}");
    }
}

#[test]
fn an_orthographic_square_stays_square() {
    // A 2 × 2 quad seen by an orthographic camera whose own xmag / ymag is 2: the image's
    // aspect (4:3) wins and ymag is kept, so the quad is 60 × 60 pixels, not stretched.
    let mut g = quad_scene(json!({"extensions": {"KHR_materials_unlit": {}}}));
    g.json["cameras"][0] = json!({"type": "orthographic", "orthographic": {"xmag": 4.0, "ymag": 2.0, "znear": 0.1, "zfar": 10.0}});
    let loaded = load(&write(&g, "ortho-square"));
    assert_eq!(loaded.scene.camera.ymag, Some(2.0));
    let pixels = drawn_pixels(&render_posed(&loaded.scene));
    let span = |f: fn(&(u32, u32)) -> u32| {
        let lo = pixels.iter().map(f).min().unwrap_or(0);
        let hi = pixels.iter().map(f).max().unwrap_or(0);
        hi + 1 - lo
    };
    assert_eq!((span(|p| p.0), span(|p| p.1)), (60, 60));
    assert_eq!(pixels.len(), 3600);
}

#[test]
fn a_line_without_normals_is_base_colour_plus_emissive() {
    // glTF: points and lines without normals are drawn unlit as base colour + emissive. The
    // same emission on a KHR_materials_unlit material is only a fallback and is not added.
    for (unlit_extension, want) in [(false, [0.7, 0.2, 0.2]), (true, [0.2, 0.2, 0.2])] {
        let mut material = json!({
            "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.2, 0.2, 1.0]},
            "emissiveFactor": [0.5, 0.0, 0.0]
        });
        if unlit_extension {
            material["extensions"] = json!({"KHR_materials_unlit": {}});
        }
        let mut g =
            pixel_grid_scene(json!({"attributes": {"POSITION": 0}, "mode": 1, "material": 0}));
        g.material(material);
        g.vec3(&[pixel_centre(10, 49), pixel_centre(140, 29)]);
        let loaded = load(&write(&g, &format!("emissive-line-{unlit_extension}")));
        let image = render_posed(&loaded.scene);
        let c = pixel(&image, 10, 49);
        for k in 0..3 {
            assert!(
                (c[k] - want[k]).abs() < 1e-6,
                "unlit extension {unlit_extension}: {c}"
            );
        }
    }
}

/// `KHR_materials_sheen`: the colour and roughness factors (clamped to [0, 1]) and both
/// textures, the colour's decoded as sRGB and the roughness's as linear; no warning.
#[test]
fn sheen_is_read_with_its_textures() {
    let mut g = quad_scene(json!({}));
    let image = g.image(four_colour_png());
    let texture = g.texture(json!({ "source": image }));
    g.json["materials"][0] = json!({
        "pbrMetallicRoughness": {"metallicFactor": 0.0},
        "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.9, 1.5, -0.2],
            "sheenColorTexture": {"index": texture},
            "sheenRoughnessFactor": 0.4,
            "sheenRoughnessTexture": {"index": texture},
        }}
    });
    g.json["extensionsUsed"] = json!(["KHR_materials_sheen"]);
    let loaded = load(&write(&g, "sheen"));
    let scene = &loaded.scene;
    let m = &scene.materials[0];
    assert_eq!(m.sheen_color, glam::Vec3::new(0.9, 1.0, 0.0));
    assert_eq!(m.sheen_roughness, 0.4);
    assert!(m.has_sheen());
    let color = m.sheen_color_texture.expect("sheen colour texture");
    let roughness = m.sheen_roughness_texture.expect("sheen roughness texture");
    use kantele::shade::texture::ColorSpace;
    assert_eq!(
        scene.textures[color.texture].source_color_space(),
        ColorSpace::Srgb
    );
    assert_eq!(
        scene.textures[roughness.texture].source_color_space(),
        ColorSpace::Linear
    );
    assert!(
        loaded.info.warnings.is_empty(),
        "{:?}",
        loaded.info.warnings
    );
}
