//! What a load chooses and lists besides the default: a glTF file's scene
//! (`LoadOptions::scene`), its material variant (`LoadOptions::variant`, `KHR_materials_variants`),
//! the lists of scenes, animations and variants in `SceneInfo`, and the face-culling override
//! (`LoadOptions::cull`) for every format, down to the faces the CPU backend draws.

use std::path::{Path, PathBuf};

use glam::Vec4;
use kantele::backend::{Backend, FrameView};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele_rules::state::CullMode;
use kantele_scene::{
    builtin_scene_with, load_scene_with, FileScene, LoadOptions, LoadedScene, SceneChoice,
};
use serde_json::json;

use crate::common::{temp_dir, Gltf, FLOAT};

fn load_with(path: &Path, options: LoadOptions) -> Result<LoadedScene, String> {
    load_scene_with(path, &options).map_err(|e| e.to_string())
}

fn scene(choice: &str) -> LoadOptions {
    LoadOptions {
        scene: Some(choice.parse().unwrap()),
        ..LoadOptions::default()
    }
}

fn variant(name: &str) -> LoadOptions {
    LoadOptions {
        variant: Some(name.to_string()),
        ..LoadOptions::default()
    }
}

fn cull(mode: CullMode) -> LoadOptions {
    LoadOptions {
        cull: Some(mode),
        ..LoadOptions::default()
    }
}

/// `realworld/MultipleScenes`, when the samples are present.
fn multiple_scenes() -> Option<PathBuf> {
    let dir = kantele_testkit::shared_dir("realworld")?;
    Some(dir.join("MultipleScenes/glTF/MultipleScenes.gltf"))
}

#[test]
fn the_default_scene_or_the_chosen_one_is_drawn_and_all_are_listed() {
    let Some(path) = multiple_scenes() else {
        return;
    };
    // Scene 0 holds a triangle, scene 1 (the file's `scene`) a square of two triangles.
    let default = load_with(&path, LoadOptions::default()).unwrap();
    assert_eq!(default.scene.triangle_count(), 2);
    let listed = |loaded: usize| {
        (0..2)
            .map(|index| FileScene {
                index,
                name: None,
                is_default: index == 1,
                loaded: index == loaded,
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(default.info.scenes, listed(1));

    let first = load_with(&path, scene("0")).unwrap();
    assert_eq!(first.scene.triangle_count(), 1);
    assert_eq!(first.scene.draws.len(), 1);
    assert_eq!(first.info.scenes, listed(0));
    let second = load_with(&path, scene("1")).unwrap();
    assert_eq!(second.scene.triangle_count(), 2);

    for (choice, shown) in [("2", "2"), ("square", "'square'")] {
        let err = load_with(&path, scene(choice)).unwrap_err();
        assert!(
            err.ends_with(&format!(
                "no scene {shown} in the file; its scenes: 0, 1 (default)"
            )),
            "{err}"
        );
        assert!(err.contains("MultipleScenes.gltf"), "{err}");
    }
}

#[test]
fn scenes_are_chosen_by_name() {
    let dir = temp_dir("scene-names");
    let mut g = Gltf::new();
    let positions = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let mesh = g.mesh(
        "triangle",
        vec![json!({"attributes": {"POSITION": positions}})],
    );
    let one = g.node(json!({"mesh": mesh}));
    let two = g.node(json!({"mesh": mesh, "translation": [2.0, 0.0, 0.0]}));
    g.json["scenes"] = json!([
        {"name": "one", "nodes": [one]},
        {"name": "two", "nodes": [one, two]},
        {"name": "7", "nodes": []},
    ]);
    g.json.as_object_mut().unwrap().remove("scene");
    let path = dir.join("named.gltf");
    g.write_gltf_embedded(&path);

    let default = load_with(&path, LoadOptions::default()).unwrap();
    assert_eq!(default.scene.draws.len(), 1, "no `scene`: scene 0");
    assert!(default.info.scenes[0].is_default && default.info.scenes[0].loaded);
    let two = load_with(&path, scene("two")).unwrap();
    assert_eq!(two.scene.draws.len(), 2);
    assert_eq!(two.info.scenes[1].name.as_deref(), Some("two"));
    assert!(two.info.scenes[1].loaded && !two.info.scenes[0].loaded);
    // All digits: an index, even where a scene has that name.
    let err = load_with(&path, scene("7")).unwrap_err();
    assert!(
        err.ends_with("no scene 7 in the file; its scenes: 0 'one' (default), 1 'two', 2 '7'"),
        "{err}"
    );
    assert_eq!(
        "7".parse::<SceneChoice>().unwrap(),
        SceneChoice::Index(7),
        "documented"
    );
}

/// A quad whose primitive's own material is red; variant `blue` maps it to a blue material,
/// variants `green` and `also green` to a green one, variant `unused` to nothing. It has two animations: one
/// whose input accessor declares `max` 1.5 and one whose inputs lack `max` (their data ends at
/// 2.25 and 0.5).
fn variants_quad() -> Gltf {
    let mut g = Gltf::new();
    let positions = g.vec3(&[
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ]);
    let indices = g.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let colour = |g: &mut Gltf, name: &str, rgba: [f32; 4]| {
        g.material(json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": rgba}}))
    };
    let red = colour(&mut g, "red", [1.0, 0.0, 0.0, 1.0]);
    let blue = colour(&mut g, "blue", [0.0, 0.0, 1.0, 1.0]);
    let green = colour(&mut g, "green", [0.0, 1.0, 0.0, 0.5]);
    let mesh = g.mesh(
        "quad",
        vec![json!({
            "attributes": {"POSITION": positions},
            "indices": indices,
            "material": red,
            "extensions": {"KHR_materials_variants": {"mappings": [
                {"material": blue, "variants": [0]},
                {"material": green, "variants": [3, 1]},
            ]}},
        })],
    );
    let node = g.node(json!({"name": "quad", "mesh": mesh}));
    g.root(node);
    g.json["extensionsUsed"] = json!(["KHR_materials_variants"]);
    g.json["extensions"] = json!({"KHR_materials_variants": {"variants": [
        {"name": "blue"}, {"name": "green"}, {"name": "unused"}, {"name": "also green"},
    ]}});
    let times = |g: &mut Gltf, values: &[f32]| {
        let bytes: Vec<u8> = values.iter().flat_map(|t| t.to_le_bytes()).collect();
        g.accessor(&bytes, FLOAT, "SCALAR", values.len(), false)
    };
    let declared = times(&mut g, &[0.0, 0.5, 1.5]);
    g.json["accessors"][declared]["min"] = json!([0.0]);
    g.json["accessors"][declared]["max"] = json!([1.5]);
    let long = times(&mut g, &[0.25, 2.25]);
    let short = times(&mut g, &[0.0, 0.5]);
    let three = g.vec3(&[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
    let two = g.vec3(&[[1.0; 3], [2.0; 3]]);
    let sampler = |input: usize, output: usize| json!({"input": input, "output": output});
    let channel =
        |s: usize, path: &str| json!({"sampler": s, "target": {"node": node, "path": path}});
    g.json["animations"] = json!([
        {"name": "slide", "samplers": [sampler(declared, three)], "channels": [channel(0, "translation")]},
        {"samplers": [sampler(short, two), sampler(long, two)],
         "channels": [channel(0, "translation"), channel(1, "scale")]},
    ]);
    g
}

/// The base colour the scene's one draw is drawn with.
fn drawn_color(loaded: &LoadedScene) -> Vec4 {
    let scene = &loaded.scene;
    assert_eq!(scene.draws.len(), 1);
    let mesh = &scene.meshes[scene.draws[0].mesh];
    scene.materials[mesh.material].base_color_factor
}

#[test]
fn a_chosen_material_variant_replaces_the_mapped_materials() {
    let dir = temp_dir("variants");
    let path = dir.join("variants.gltf");
    variants_quad().write_gltf_embedded(&path);

    let default = load_with(&path, LoadOptions::default()).unwrap();
    assert_eq!(drawn_color(&default), Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(
        default.info.variants,
        ["blue", "green", "unused", "also green"]
    );
    assert_eq!(default.info.variant_loaded, None);
    assert!(
        !default
            .info
            .warnings
            .iter()
            .any(|w| w.contains("KHR_materials_variants")),
        "a supported extension: {:?}",
        default.info.warnings
    );

    let blue = load_with(&path, variant("blue")).unwrap();
    assert_eq!(drawn_color(&blue), Vec4::new(0.0, 0.0, 1.0, 1.0));
    assert_eq!(blue.info.variant_loaded, Some(0));
    let green = load_with(&path, variant("green")).unwrap();
    assert_eq!(drawn_color(&green), Vec4::new(0.0, 1.0, 0.0, 0.5));
    assert_eq!(
        green.scene.materials[green.scene.meshes[0].material].alpha_mode,
        kantele_rules::scene::AlphaMode::Opaque
    );
    let also = load_with(&path, variant("also green")).unwrap();
    assert_eq!(drawn_color(&also), Vec4::new(0.0, 1.0, 0.0, 0.5));
    assert_eq!(also.info.variant_loaded, Some(3));
    let unused = load_with(&path, variant("unused")).unwrap();
    assert_eq!(
        drawn_color(&unused),
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        "not mapped: the primitive's own material"
    );

    let err = load_with(&path, variant("Blue")).unwrap_err();
    assert!(
        err.ends_with(
            "no material variant 'Blue' in the file; its variants: 'blue', 'green', 'unused', 'also green'"
        ),
        "{err}"
    );
    assert!(!err.contains('\n'));
}

#[test]
fn a_variant_mapped_to_a_missing_material_is_an_error_only_when_chosen() {
    let dir = temp_dir("variant-bad-material");
    let mut g = variants_quad();
    g.json["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][0]
        ["material"] = json!(9);
    let path = dir.join("bad.gltf");
    g.write_gltf_embedded(&path);
    assert_eq!(
        drawn_color(&load_with(&path, LoadOptions::default()).unwrap()),
        Vec4::new(1.0, 0.0, 0.0, 1.0)
    );
    assert_eq!(
        drawn_color(&load_with(&path, variant("green")).unwrap()),
        Vec4::new(0.0, 1.0, 0.0, 0.5)
    );
    let err = load_with(&path, variant("blue")).unwrap_err();
    assert!(
        err.ends_with(
            "mesh 'quad' primitive 0: KHR_materials_variants maps variant 'blue' to material 9, but the file has 3 materials"
        ),
        "{err}"
    );
}

#[test]
fn animations_are_listed_with_their_durations() {
    let dir = temp_dir("animation-list");
    let path = dir.join("animated.gltf");
    variants_quad().write_gltf_embedded(&path);
    let loaded = load_with(&path, LoadOptions::default()).unwrap();
    let listed: Vec<_> = loaded
        .info
        .animations
        .iter()
        .map(|a| (a.index, a.name.as_deref(), a.duration_seconds))
        .collect();
    assert_eq!(listed, [(0, Some("slide"), 1.5), (1, None, 2.25)]);

    // An input accessor that is not in the file: a warning, and the other samplers count.
    let mut g = variants_quad();
    g.json["animations"][1]["samplers"][1]["input"] = json!(99);
    g.write_gltf_embedded(&path);
    let loaded = load_with(&path, LoadOptions::default()).unwrap();
    assert_eq!(loaded.info.animations[1].duration_seconds, 0.5);
    assert!(
        loaded
            .info
            .warnings
            .iter()
            .any(|w| w.starts_with("animation 'animation 1': sampler input accessor 99")),
        "{:?}",
        loaded.info.warnings
    );
}

#[test]
fn realworld_animations_are_listed_with_their_durations() {
    let Some(dir) = kantele_testkit::shared_dir("realworld") else {
        return;
    };
    let loaded = load_with(
        &dir.join("skin-anim/InterpolationTest.glb"),
        LoadOptions::default(),
    )
    .unwrap();
    let names: Vec<_> = loaded
        .info
        .animations
        .iter()
        .map(|a| a.name.as_deref().unwrap_or(""))
        .collect();
    assert_eq!(
        names,
        [
            "Step Scale",
            "Linear Scale",
            "CubicSpline Scale",
            "Step Rotation",
            "CubicSpline Rotation",
            "Linear Rotation",
            "Step Translation",
            "CubicSpline Translation",
            "Linear Translation"
        ]
    );
    // The inputs' declared `max`: 40 / 24 s for the scales and two translations, 41 / 24 s for
    // the others.
    let durations: Vec<f32> = loaded
        .info
        .animations
        .iter()
        .map(|a| a.duration_seconds)
        .collect();
    let (short, long) = (40.0f64 / 24.0, 41.0f64 / 24.0);
    let expected = [short, short, short, long, long, long, long, short, short];
    for (d, e) in durations.iter().zip(expected) {
        assert_eq!(*d, e as f32, "{durations:?}");
    }
    let man = load_with(&dir.join("skin-anim/CesiumMan.glb"), LoadOptions::default()).unwrap();
    assert_eq!(man.info.animations.len(), 1);
    assert_eq!(man.info.animations[0].name, None);
    assert_eq!(man.info.animations[0].duration_seconds, 2.0);
}

/// A single-sided quad facing +Z (two counter-clockwise triangles), as glTF and as OBJ.
fn quad_files(dir: &Path) -> (PathBuf, PathBuf) {
    let mut g = Gltf::new();
    let positions = g.vec3(&[
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ]);
    let normals = g.vec3(&[[0.0, 0.0, 1.0]; 4]);
    let indices = g.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let material = g.material(json!({"doubleSided": false}));
    let mesh = g.mesh(
        "quad",
        vec![json!({
            "attributes": {"POSITION": positions, "NORMAL": normals},
            "indices": indices,
            "material": material,
        })],
    );
    let node = g.node(json!({"mesh": mesh}));
    g.root(node);
    let gltf = dir.join("quad.gltf");
    g.write_gltf_embedded(&gltf);
    let obj = dir.join("quad.obj");
    std::fs::write(
        &obj,
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .unwrap();
    (gltf, obj)
}

/// Whether every triangle of the scene's one mesh faces +Z (counter-clockwise seen from +Z),
/// and whether its material is double-sided; its normals must still face +Z.
fn faces_and_sides(loaded: &LoadedScene) -> (Vec<bool>, bool) {
    let scene = &loaded.scene;
    assert_eq!(scene.meshes.len(), 1);
    let mesh = &scene.meshes[0];
    assert!(mesh
        .normals
        .as_ref()
        .unwrap()
        .iter()
        .all(|n| *n == glam::Vec3::Z));
    let facing = mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize]);
            (b - a).cross(c - a).z > 0.0
        })
        .collect();
    (facing, scene.materials[mesh.material].double_sided)
}

#[test]
fn the_cull_override_sets_every_material_and_front_reverses_the_winding() {
    let dir = temp_dir("cull-override");
    let (gltf, obj) = quad_files(&dir);
    for (path, file_double_sided) in [(&gltf, false), (&obj, true)] {
        let what = path.display();
        let as_file = load_with(path, LoadOptions::default()).unwrap();
        assert_eq!(
            faces_and_sides(&as_file),
            (vec![true, true], file_double_sided),
            "{what}"
        );
        let none = load_with(path, cull(CullMode::None)).unwrap();
        assert_eq!(faces_and_sides(&none), (vec![true, true], true), "{what}");
        let back = load_with(path, cull(CullMode::Back)).unwrap();
        assert_eq!(faces_and_sides(&back), (vec![true, true], false), "{what}");
        let front = load_with(path, cull(CullMode::Front)).unwrap();
        assert_eq!(
            faces_and_sides(&front),
            (vec![false, false], false),
            "{what}"
        );
        // The same triangles, each with its second and third corners swapped.
        let reversed: Vec<u32> = back.scene.meshes[0]
            .indices
            .chunks_exact(3)
            .flat_map(|t| [t[0], t[2], t[1]])
            .collect();
        assert_eq!(front.scene.meshes[0].indices, reversed, "{what}");
        assert_eq!(
            front.scene.meshes[0].positions, back.scene.meshes[0].positions,
            "{what}"
        );
    }
    let indices = |options| {
        load_with(&gltf, options).unwrap().scene.meshes[0]
            .indices
            .clone()
    };
    assert_eq!(indices(cull(CullMode::Back)), [0, 1, 2, 0, 2, 3]);
    assert_eq!(indices(cull(CullMode::Front)), [0, 2, 1, 0, 3, 2]);
}

/// Pixels the CPU backend draws of the scene seen from `from` (towards the origin).
fn covered_from(loaded: &LoadedScene, from: glam::Vec3) -> usize {
    let mut scene = loaded.scene.clone();
    scene.resolution = (80, 60);
    scene.camera = kantele::scene::Camera::framing(glam::Vec3::ZERO, 1.5, from, 4.0 / 3.0);
    let scene = std::sync::Arc::new(scene);
    let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu backend");
    cpu.load(scene.clone())
        .expect("scene loads into the backend");
    cpu.render(&FrameView::of_scene(&scene)).expect("render");
    let image = cpu.read_frame().expect("read");
    image.depth.iter().filter(|d| **d < 1.0).count()
}

#[test]
fn the_backend_draws_the_faces_the_cull_override_keeps() {
    let dir = temp_dir("cull-render");
    let (gltf, _) = quad_files(&dir);
    // (choice, drawn seen from the front (+Z), drawn seen from behind)
    for (choice, front, behind) in [
        (None, true, false),
        (Some(CullMode::None), true, true),
        (Some(CullMode::Back), true, false),
        (Some(CullMode::Front), false, true),
    ] {
        let options = LoadOptions {
            cull: choice,
            ..LoadOptions::default()
        };
        let loaded = load_with(&gltf, options).unwrap();
        let seen_front = covered_from(&loaded, glam::Vec3::Z);
        let seen_behind = covered_from(&loaded, -glam::Vec3::Z);
        assert_eq!(
            (seen_front > 0, seen_behind > 0),
            (front, behind),
            "{choice:?}: {seen_front} and {seen_behind} pixels"
        );
        for seen in [seen_front, seen_behind] {
            assert!(seen == 0 || seen > 500, "{choice:?}: {seen} pixels");
        }
    }
}

#[test]
fn built_in_scenes_take_the_cull_override_and_refuse_scene_choices() {
    let options = cull(CullMode::None);
    let cube = builtin_scene_with("cube", &options).unwrap();
    assert!(cube.scene.materials.iter().all(|m| m.double_sided));
    let plain = kantele_scene::builtin_scene("cube").unwrap();
    let front = builtin_scene_with("cube", &cull(CullMode::Front)).unwrap();
    for (a, b) in plain.scene.meshes.iter().zip(&front.scene.meshes) {
        for (p, q) in a.indices.chunks_exact(3).zip(b.indices.chunks_exact(3)) {
            assert_eq!([p[0], p[2], p[1]], q);
        }
    }
    let err = builtin_scene_with("cube", &scene("1")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "builtin:cube: cannot draw scene 1: only glTF files have scenes to choose from (this has one)"
    );
    assert!(builtin_scene_with("nope", &options).is_err());
}

#[test]
fn other_formats_refuse_scene_and_variant_choices() {
    let dir = temp_dir("choices-obj");
    let (_, obj) = quad_files(&dir);
    let err = load_with(&obj, scene("0")).unwrap_err();
    assert!(
        err.ends_with(
            "cannot draw scene 0: only glTF files have scenes to choose from (this has one)"
        ),
        "{err}"
    );
    let err = load_with(&obj, variant("red")).unwrap_err();
    assert!(
        err.ends_with("cannot draw material variant 'red': only glTF files have material variants"),
        "{err}"
    );
    let loaded = load_with(&obj, LoadOptions::default()).unwrap();
    assert!(loaded.info.scenes.is_empty() && loaded.info.variants.is_empty());
}
