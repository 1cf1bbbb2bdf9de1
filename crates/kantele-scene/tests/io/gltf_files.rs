//! glTF files written by the tests: the three storage forms give the same scene, and every rule
//! of the loader (hierarchy, camera, light, extras, materials, samplers, attributes).

use std::path::Path;

use crate::common::*;
use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::scene::{AlphaMode, Light, LightKind, Scene, Shading};
use kantele::shade::texture::{Filter, MinFilter, Wrap};
use kantele_scene::{load_scene, LoadedScene};
use serde_json::json;

fn load(path: &Path) -> LoadedScene {
    load_scene(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

fn assert_same_scene(a: &Scene, b: &Scene) {
    assert_eq!(a.meshes.len(), b.meshes.len());
    for (ma, mb) in a.meshes.iter().zip(&b.meshes) {
        assert_eq!(ma.positions, mb.positions);
        assert_eq!(ma.normals, mb.normals);
        assert_eq!(ma.texcoords, mb.texcoords);
        assert_eq!(ma.colors, mb.colors);
        assert_eq!(ma.indices, mb.indices);
        assert_eq!(ma.material, mb.material);
    }
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.textures.len(), b.textures.len());
    for (ta, tb) in a.textures.iter().zip(&b.textures) {
        assert_eq!(ta.levels().len(), tb.levels().len());
        assert_eq!(ta.level(0).map(|l| l.texels), tb.level(0).map(|l| l.texels));
    }
    assert_eq!(a.draws.len(), b.draws.len());
    for (da, db) in a.draws.iter().zip(&b.draws) {
        assert_eq!(da.mesh, db.mesh);
        assert_eq!(da.model, db.model);
        assert_eq!(da.node_name, db.node_name);
        assert_eq!(da.node_index, db.node_index);
    }
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.light, b.light);
    assert_eq!(a.resolution, b.resolution);
    assert_eq!(a.clear_color, b.clear_color);
    assert_eq!(a.ambient, b.ambient);
}

#[test]
fn glb_external_and_embedded_gltf_give_the_same_scene() {
    let dir = temp_dir("forms");
    let g = textured_quad();
    let glb = dir.join("quad.glb");
    let external = dir.join("quad-external.gltf");
    let embedded = dir.join("quad-embedded.gltf");
    g.write_glb(&glb);
    g.write_gltf_external(&external);
    g.write_gltf_embedded(&embedded);
    let a = load(&glb);
    let b = load(&external);
    let c = load(&embedded);
    assert_same_scene(&a.scene, &b.scene);
    assert_same_scene(&a.scene, &c.scene);
    assert_eq!(
        a.info.extensions_used,
        vec!["KHR_lights_punctual".to_string()]
    );
    assert!(a.info.warnings.is_empty(), "{:?}", a.info.warnings);
    assert_eq!(a.info.source, glb.display().to_string());
}

#[test]
fn the_quad_scene_follows_the_rules() {
    let dir = temp_dir("rules");
    let path = dir.join("quad.glb");
    textured_quad().write_glb(&path);
    let LoadedScene { scene, info, .. } = load(&path);

    assert_eq!(info.node_count, 4);
    assert_eq!(info.cameras, vec!["cam".to_string()]);
    assert_eq!(info.lights, vec!["sun".to_string()]);
    assert!(info.camera_from_file);

    // Extras.
    assert_eq!(scene.resolution, (320, 240));
    assert_eq!(scene.clear_color, Vec4::new(0.1, 0.2, 0.3, 1.0));
    assert_eq!(scene.ambient, 0.25);

    // Camera: view = inverse of the node's world matrix; no aspect ratio and no zfar.
    assert!(scene
        .camera
        .view
        .abs_diff_eq(Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0)), 1e-6));
    assert_eq!(scene.camera.yfov, 0.8);
    assert_eq!(scene.camera.znear, 0.1);
    assert_eq!(scene.camera.aspect_ratio, None);
    assert_eq!(scene.camera.zfar, None);

    // Light: the node's +z axis, colour × intensity.
    match scene.light {
        Light::Directional { to_light, color } => {
            assert!(to_light.abs_diff_eq(Vec3::Y, 1e-6), "{to_light}");
            assert!(color.abs_diff_eq(Vec3::new(2.0, 1.0, 1.0), 1e-6));
        }
        other => panic!("expected a directional light, got {other:?}"),
    }

    // One draw: the child's world matrix = parent × child.
    assert_eq!(scene.draws.len(), 1);
    let draw = &scene.draws[0];
    assert_eq!(draw.node_name, "quad");
    assert_eq!(draw.node_index, 2);
    let parent =
        Mat4::from_translation(Vec3::new(0.5, 0.0, 0.0)) * Mat4::from_scale(Vec3::splat(2.0));
    let child = Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0));
    assert!(draw.model.abs_diff_eq(parent * child, 1e-6));

    // Mesh.
    let mesh = &scene.meshes[draw.mesh];
    assert_eq!(mesh.name, "quad");
    assert_eq!(mesh.triangle_count(), 2);
    assert_eq!(mesh.texcoords.as_ref().unwrap()[0], Vec2::new(0.0, 1.0));
    assert_eq!(mesh.normals.as_ref().unwrap()[0], Vec3::Z);
    assert!(mesh.colors.is_none());

    // Material, texture and sampler.
    let material = &scene.materials[mesh.material];
    assert_eq!(material.name, "quad-material");
    assert_eq!(material.base_color_factor, Vec4::new(1.0, 0.5, 0.25, 1.0));
    assert!(material.double_sided);
    assert!(!material.unlit);
    assert_eq!(material.alpha_mode, AlphaMode::Mask { cutoff: 0.25 });
    let binding = material.base_color_texture.expect("texture");
    assert_eq!(binding.sampler.mag_filter, Filter::Nearest);
    assert_eq!(binding.sampler.min_filter, MinFilter::NearestMipmapLinear);
    assert_eq!(binding.sampler.wrap_s, Wrap::ClampToEdge);
    assert_eq!(binding.sampler.wrap_t, Wrap::MirroredRepeat);
    let texture = &scene.textures[binding.texture];
    assert_eq!((texture.width(), texture.height()), (2, 2));
    let level = texture.level(0).expect("level 0");
    // sRGB decoded: pure colours stay pure.
    assert_eq!(level.texel(0, 0), Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(level.texel(0, 1), Vec4::new(0.0, 0.0, 1.0, 1.0));
}

#[test]
fn defaults_shared_meshes_flat_normals_and_normalized_attributes() {
    let mut g = Gltf::new();
    let positions = g.vec3(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]);
    // Normalized u16 texcoords and u8 RGBA colours.
    let texcoords = g.accessor(
        &[0u16, 0, 65535, 0, 0, 65535, 65535, 65535]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<_>>(),
        UNSIGNED_SHORT,
        "VEC2",
        4,
        true,
    );
    let colors = g.accessor(
        &[
            255u8, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 255, 255, 255, 255,
        ],
        UNSIGNED_BYTE,
        "VEC4",
        4,
        true,
    );
    let indices = g.indices_u32(&[0, 1, 2, 2, 1, 3]);
    let mesh = g.mesh(
        "no-normals",
        vec![json!({"attributes": {"POSITION": positions, "TEXCOORD_0": texcoords, "COLOR_0": colors}, "indices": indices})],
    );
    // A strip of the same four vertices (non-indexed) and a points primitive.
    let strip_mesh = g.mesh(
        "strip",
        vec![
            json!({"attributes": {"POSITION": positions}, "mode": 5}),
            json!({"attributes": {"POSITION": positions}, "mode": 0}),
        ],
    );
    for i in 0..3 {
        let n = g.node(json!({"name": format!("copy{i}"), "mesh": mesh, "translation": [i as f32 * 2.0, 0.0, 0.0]}));
        g.root(n);
    }
    let s = g.node(json!({"mesh": strip_mesh}));
    g.root(s);
    let dir = temp_dir("defaults");
    let path = dir.join("defaults.gltf");
    g.write_gltf_embedded(&path);
    let LoadedScene { scene, info, .. } = load(&path);

    // Defaults: no camera (framing one), headlight, 800 × 600, ambient 0.1; without
    // `ambient` in the extras the file is drawn with PBR: no lights, so the studio, and the
    // grey background.
    assert!(!info.camera_from_file);
    assert!(info.cameras.is_empty());
    assert_eq!(scene.light, Light::Headlight);
    assert_eq!(scene.resolution, (800, 600));
    assert_eq!(scene.shading, Shading::Pbr);
    assert!(scene.lights.is_empty());
    assert!(scene.environment.is_some());
    assert_eq!(scene.clear_color, Vec4::new(0.2, 0.2, 0.2, 1.0));
    assert_eq!(scene.ambient, 0.1);
    // Chosen Lambert: no environment, black.
    let options = kantele_scene::LoadOptions {
        shading: Some(Shading::Lambert),
        ..kantele_scene::LoadOptions::default()
    };
    let lambert = kantele_scene::load_scene_with(&path, &options)
        .expect("load")
        .scene;
    assert_eq!(lambert.shading, Shading::Lambert);
    assert!(lambert.environment.is_none());
    assert_eq!(lambert.clear_color, Vec4::new(0.0, 0.0, 0.0, 1.0));
    // The framing camera sees the scene's centre straight ahead.
    let (center, _) = scene.bounding_sphere().unwrap();
    let eye_center = scene.camera.view.transform_point3(center);
    assert!(eye_center.x.abs() < 1e-3 && eye_center.y.abs() < 1e-3 && eye_center.z < 0.0);

    // Three draws share one mesh; the strip is a second mesh, the points a third.
    assert_eq!(scene.draws.len(), 5);
    assert_eq!(scene.meshes.len(), 3);
    assert_eq!(scene.meshes[2].topology, kantele::scene::Topology::Points);
    assert_eq!(scene.meshes[2].indices, vec![0, 1, 2, 3]);
    assert!(scene.meshes[2].normals.is_none());
    assert!(scene.draws[..3].iter().all(|d| d.mesh == 0));
    assert_eq!(scene.draws[2].node_index, 2);
    assert!(scene.draws[2]
        .model
        .abs_diff_eq(Mat4::from_translation(Vec3::new(4.0, 0.0, 0.0)), 1e-6));
    assert!(
        !info.warnings.iter().any(|w| w.contains("Points")),
        "{:?}",
        info.warnings
    );

    // Default material appended once.
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[0], kantele::scene::Material::default());

    // Flat normals: de-indexed, facing +z (both triangles are counter-clockwise).
    let m = &scene.meshes[0];
    assert_eq!(m.positions.len(), 6);
    assert_eq!(m.triangle_count(), 2);
    assert!(m.normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));
    let t = m.texcoords.as_ref().unwrap();
    assert_eq!(t[1], Vec2::new(1.0, 0.0));
    assert_eq!(t[5], Vec2::new(1.0, 1.0));
    let c = m.colors.as_ref().unwrap();
    assert_eq!(c[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert!((c[1].w - 128.0 / 255.0).abs() < 1e-6);

    // The strip became two counter-clockwise triangles.
    let strip = &scene.meshes[1];
    assert_eq!(strip.triangle_count(), 2);
    assert!(strip
        .normals
        .as_ref()
        .unwrap()
        .iter()
        .all(|n| *n == Vec3::Z));
}

#[test]
fn camera_and_light_come_from_the_first_nodes_in_draw_order() {
    let mut g = Gltf::new();
    let cam0 = g.camera(json!({"name": "first", "type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.5, "zfar": 10.0}}));
    let cam1 = g.camera(json!({"name": "second", "type": "perspective", "perspective": {"yfov": 0.9, "znear": 1.0}}));
    let ortho = g.camera(json!({"name": "ortho", "type": "orthographic", "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0}}));
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_unlit"]);
    g.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1.0, 1.0, 1.0]},
        {"name": "a", "type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 1.0},
        {"name": "b", "type": "directional", "color": [0.0, 1.0, 0.0], "intensity": 3.0}
    ]}});
    // Depth first: root0 → child (first camera, point light), then root1 (second camera).
    let child = g.node(json!({"camera": cam0, "translation": [0.0, 0.0, 5.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    let o = g.node(json!({"camera": ortho}));
    let root0 = g.node(json!({"children": [child, o], "translation": [1.0, 0.0, 0.0]}));
    let root1 =
        g.node(json!({"camera": cam1, "extensions": {"KHR_lights_punctual": {"light": 2}}}));
    let root2 = g.node(json!({"extensions": {"KHR_lights_punctual": {"light": 1}}}));
    g.root(root0);
    g.root(root1);
    g.root(root2);
    // Something to draw, unlit.
    let p = g.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let mat = g.material(json!({"extensions": {"KHR_materials_unlit": {}}, "alphaMode": "BLEND"}));
    let mesh = g.mesh(
        "t",
        vec![json!({"attributes": {"POSITION": p}, "material": mat})],
    );
    let n = g.node(json!({"mesh": mesh}));
    g.root(n);
    let dir = temp_dir("camera");
    let path = dir.join("cameras.glb");
    g.write_glb(&path);
    let LoadedScene { scene, info, .. } = load(&path);
    assert!(info.camera_from_file);
    assert_eq!(info.cameras, vec!["first", "second", "ortho"]);
    assert_eq!(info.lights, vec!["light 0", "a", "b"]);
    assert_eq!(scene.camera.yfov, 0.5);
    assert_eq!(scene.camera.aspect_ratio, Some(2.0));
    assert_eq!(scene.camera.zfar, Some(10.0));
    assert!(scene
        .camera
        .view
        .abs_diff_eq(Mat4::from_translation(Vec3::new(-1.0, 0.0, -5.0)), 1e-6));
    assert_eq!(
        scene.light,
        Light::Directional {
            to_light: Vec3::Z,
            color: Vec3::new(0.0, 3.0, 0.0)
        }
    );
    // The orthographic camera is kept (after the first in draw order): ymag, xmag / ymag.
    assert!(!info.warnings.iter().any(|w| w.contains("orthographic")));
    let ortho = scene
        .file_cameras
        .iter()
        .find(|c| c.name == "ortho")
        .expect("orthographic camera kept");
    assert_eq!(ortho.camera.ymag, Some(1.0));
    assert_eq!(ortho.camera.aspect_ratio, Some(1.0));
    assert_eq!(ortho.camera.zfar, Some(10.0));
    // PBR (no `ambient` in the extras): every light is drawn, the point light where its
    // node puts it; no environment, since the file has lights.
    assert!(!info.warnings.iter().any(|w| w.contains("point and spot")));
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(scene.lights[0].kind, LightKind::Point);
    assert!(scene.lights[0]
        .position
        .abs_diff_eq(Vec3::new(1.0, 0.0, 5.0), 1e-6));
    assert!(scene.environment.is_none());
    // Lambert draws the first directional light and says the point light is left out.
    let options = kantele_scene::LoadOptions {
        shading: Some(Shading::Lambert),
        ..kantele_scene::LoadOptions::default()
    };
    let lambert = kantele_scene::load_scene_with(&path, &options).expect("load");
    assert!(lambert
        .info
        .warnings
        .iter()
        .any(|w| w.contains("point and spot")));
    assert!(scene.materials[0].unlit);
    assert_eq!(scene.materials[0].alpha_mode, AlphaMode::Blend);
    assert_eq!(scene.draws[0].node_index, n);
}

#[test]
fn unsupported_extensions_warn_and_unreadable_required_ones_fail() {
    let dir = temp_dir("extensions");
    let mut g = textured_quad();
    g.json["extensionsUsed"] = json!([
        "KHR_lights_punctual",
        "KHR_materials_anisotropy",
        "EXT_fancy"
    ]);
    g.json["extensionsRequired"] = json!(["EXT_fancy"]);
    let path = dir.join("fancy.glb");
    g.write_glb(&path);
    let loaded = load(&path);
    let w = &loaded.info.warnings;
    // Unsupported extensions are named in the one line of ignored features.
    let ignored: Vec<&String> = w.iter().filter(|w| w.starts_with("ignored")).collect();
    assert_eq!(ignored.len(), 1, "{w:?}");
    assert!(
        ignored[0].contains("KHR_materials_anisotropy") && ignored[0].contains("EXT_fancy"),
        "{w:?}"
    );
    assert!(
        w.iter()
            .any(|w| w.contains("requires unsupported extension EXT_fancy")),
        "{w:?}"
    );
    assert_eq!(w.iter().filter(|w| w.contains("EXT_fancy")).count(), 2);
    assert_eq!(loaded.info.extensions_used.len(), 3);

    // DDS images are decoded: requiring MSFT_texture_dds loads, with no warning naming it (the
    // quad's texture has no DDS image here and keeps its PNG).
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual", "MSFT_texture_dds"]);
    g.json["extensionsRequired"] = json!(["MSFT_texture_dds"]);
    let path = dir.join("dds.glb");
    g.write_glb(&path);
    let loaded = load(&path);
    let w = &loaded.info.warnings;
    assert!(w.iter().all(|w| !w.contains("MSFT_texture_dds")), "{w:?}");
    assert_eq!(loaded.scene.textures.len(), 1);

    // AVIF cannot be decoded: requiring it fails in one line naming the file and extension.
    g.json["extensionsUsed"] = json!(["EXT_texture_avif"]);
    g.json["extensionsRequired"] = json!(["EXT_texture_avif"]);
    let path = dir.join("avif.glb");
    g.write_glb(&path);
    let err = load_scene(&path)
        .expect_err("AVIF cannot be read")
        .to_string();
    assert!(
        err.contains("avif.glb") && err.contains("EXT_texture_avif"),
        "{err}"
    );
}

#[test]
fn reference_scene_round_trips_through_gltf_with_external_files() {
    // A real file re-packed as .gltf + .bin with the image moved out gives the same scene.
    let Some(dir) = reference_scenes() else {
        return;
    };
    let source = dir.join("thesis-cube-textured.glb");
    let bytes = std::fs::read(&source).expect("read");
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_start = 20 + json_len + 8;
    let bin = &bytes[bin_start..];
    let out = temp_dir("repack");
    std::fs::write(out.join("cube.bin"), bin).unwrap();
    json["buffers"][0]["uri"] = json!("cube.bin");
    let view = json["images"][0]["bufferView"].as_u64().unwrap() as usize;
    let v = &json["bufferViews"][view];
    let (offset, length) = (
        v["byteOffset"].as_u64().unwrap_or(0) as usize,
        v["byteLength"].as_u64().unwrap() as usize,
    );
    std::fs::write(out.join("checker image.png"), &bin[offset..offset + length]).unwrap();
    json["images"][0] = json!({"uri": "checker%20image.png"});
    let path = out.join("cube.gltf");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    let a = load(&source);
    let b = load(&path);
    assert_same_scene(&a.scene, &b.scene);
}

/// Textures are upright: the glTF convention puts texcoord (0, 0) at the image's first (top)
/// row. The quad's top-left vertex has uv (0, 0) and the 2 × 2 image is red, green / blue,
/// white, so the rendered quad must show red top-left, green top-right, blue bottom-left.
#[test]
fn textures_render_upright_and_unmirrored() {
    use kantele::backend::{Backend, FrameView};
    let dir = temp_dir("upright");
    let path = dir.join("quad.gltf");
    textured_quad().write_gltf_embedded(&path);
    let scene = std::sync::Arc::new(load(&path).scene);
    let mut cpu = kantele::cpu::CpuBackend::new(Default::default()).expect("cpu");
    cpu.load(scene.clone()).expect("load");
    let view = FrameView::of_scene(&scene);
    cpu.render(&view).expect("render");
    let frame = cpu.read_frame().expect("read");
    let at = |x: u32, y: u32| frame.color[(y * frame.width + x) as usize];
    let dominant = |c: [f32; 4]| (0..3).max_by(|&a, &b| c[a].total_cmp(&c[b])).unwrap_or(0);
    // Quadrant centres of the 320 × 240 image; the quad fills the view vertically and spans
    // the texel boundary u = 0.5 near the middle column.
    assert_eq!(
        dominant(at(80, 60)),
        0,
        "top-left should be red: {:?}",
        at(80, 60)
    );
    assert_eq!(
        dominant(at(240, 60)),
        1,
        "top-right should be green: {:?}",
        at(240, 60)
    );
    assert_eq!(
        dominant(at(80, 180)),
        2,
        "bottom-left should be blue: {:?}",
        at(80, 180)
    );
    let white = at(240, 180);
    assert!(
        white[0] > 0.0 && white[1] > 0.0 && white[2] > 0.0,
        "bottom-right should be white × factor: {white:?}"
    );
}
