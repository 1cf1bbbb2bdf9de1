//! Every reference scene of `$KANTELE_SHARED/scenes` loads with the counts of its INDEX.md.
// Quaternions are copied digit for digit from the files.
#![allow(clippy::excessive_precision)]

use glam::{Mat4, Quat, Vec3};
use kantele::scene::{AlphaMode, Light};
use kantele::shade::texture::{MinFilter, Wrap};
use kantele_scene::{load_scene, LoadedScene};

/// (file, resolution, triangles, draws) from INDEX.md.
const INDEX: &[(&str, (u32, u32), usize, usize)] = &[
    ("thesis-t1-b2f-1.glb", (1300, 700), 2, 1),
    ("thesis-t1-f2b-1.glb", (1300, 700), 2, 1),
    ("thesis-t1-b2f-10.glb", (1300, 700), 20, 10),
    ("thesis-t1-f2b-10.glb", (1300, 700), 20, 10),
    ("thesis-t1-b2f-100.glb", (1300, 700), 200, 100),
    ("thesis-t1-f2b-100.glb", (1300, 700), 200, 100),
    ("thesis-t2-cubes.glb", (1300, 700), 30000, 2500),
    ("thesis-cube-textured.glb", (1300, 700), 12, 1),
    ("paper-c1-lowpoly-far.glb", (1024, 768), 6320, 1),
    ("paper-c2-lowpoly-near.glb", (1024, 768), 6320, 1),
    ("paper-c3-head-far.glb", (1024, 768), 268686, 1),
    ("paper-c4-head-near.glb", (1024, 768), 268686, 1),
    ("paper-c5-statue.glb", (1024, 768), 99938, 1),
    ("blog-teapot.glb", (192, 192), 6320, 1),
    ("bunny.glb", (1024, 768), 69451, 1),
    ("spot-textured.glb", (1024, 768), 5856, 1),
    ("alpha-blend.glb", (800, 600), 8, 7),
    ("near-clip.glb", (1024, 768), 3, 2),
];

fn load(name: &str) -> Option<LoadedScene> {
    let dir = crate::common::reference_scenes()?;
    let path = dir.join(name);
    Some(load_scene(&path).unwrap_or_else(|e| panic!("{name}: {e}")))
}

#[test]
fn every_reference_scene_loads_with_its_index_counts() {
    let Some(dir) = crate::common::reference_scenes() else {
        return;
    };
    // Every .glb in the directory is in the table.
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .expect("read scenes")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".glb"))
        .collect();
    files.sort();
    for file in &files {
        assert!(
            INDEX.iter().any(|(n, ..)| n == file),
            "{file} is not in the test's table"
        );
    }
    for &(name, resolution, triangles, draws) in INDEX {
        let path = dir.join(name);
        if !path.exists() {
            eprintln!("{name} missing; skipped");
            continue;
        }
        let LoadedScene { scene, info, .. } =
            load_scene(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.resolution, resolution, "{name}");
        assert_eq!(scene.triangle_count(), triangles, "{name}");
        assert_eq!(scene.draws.len(), draws, "{name}");
        assert!(info.camera_from_file, "{name}");
        assert_eq!(info.cameras.len(), 1, "{name}");
        assert!(info.warnings.is_empty(), "{name}: {:?}", info.warnings);
        let aspect = resolution.0 as f32 / resolution.1 as f32;
        assert!(
            (scene.camera.aspect_ratio.expect("aspect ratio") - aspect).abs() < 1e-4,
            "{name}"
        );
        assert_eq!(info.source, path.display().to_string());
        // Every mesh has normals after loading; every scene validates.
        assert!(scene.meshes.iter().all(|m| m.normals.is_some()), "{name}");
        scene.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
        // Camera, light, then drawn nodes: node 0 is the camera, draws come after it.
        assert!(scene.draws.iter().all(|d| d.node_index > 0), "{name}");
    }
}

#[test]
fn shared_meshes_are_not_duplicated() {
    let Some(LoadedScene { scene, .. }) = load("thesis-t2-cubes.glb") else {
        return;
    };
    assert_eq!(scene.meshes.len(), 1);
    // The file's 24-vertex cube has no normals: flat normals de-index it to 36 vertices.
    assert_eq!(scene.meshes[0].positions.len(), 36);
    assert!(scene.draws.iter().all(|d| d.mesh == 0));
    // Draws are in node order.
    assert!(scene
        .draws
        .windows(2)
        .all(|w| w[0].node_index < w[1].node_index));
}

#[test]
fn lights() {
    let Some(bunny) = load("bunny.glb") else {
        return;
    };
    assert_eq!(bunny.scene.light, Light::Headlight);
    assert!(bunny.info.lights.is_empty());
    let Some(teapot) = load("paper-c1-lowpoly-far.glb") else {
        return;
    };
    assert_eq!(teapot.info.lights, vec!["sun".to_string()]);
    match teapot.scene.light {
        Light::Directional { to_light, color } => {
            assert_eq!(color, Vec3::ONE);
            // The sun node's rotation applied to +z.
            let q = Quat::from_xyzw(
                -0.4526244681792699,
                -0.280122578305433,
                -0.1522540364825911,
                0.8327551502714994,
            );
            assert!(to_light.abs_diff_eq(q * Vec3::Z, 1e-5), "{to_light}");
            assert!(to_light.y > 0.0, "the sun shines from above");
        }
        other => panic!("expected a directional light, got {other:?}"),
    }
}

#[test]
fn camera_view_is_the_inverse_of_the_camera_node() {
    let Some(LoadedScene { scene, .. }) = load("thesis-cube-textured.glb") else {
        return;
    };
    let node = Mat4::from_rotation_translation(
        Quat::from_xyzw(
            -0.19677872270423263,
            0.2581528946679582,
            0.05379422708243232,
            0.9443206014897951,
        ),
        Vec3::new(1.95, 1.55, 3.3),
    );
    assert!(scene.camera.view.abs_diff_eq(node.inverse(), 1e-5));
    assert_eq!(scene.camera.znear, 0.1);
    assert_eq!(scene.camera.zfar, Some(50.0));
    assert!((scene.camera.yfov - std::f32::consts::FRAC_PI_4).abs() < 1e-6);
    assert_eq!(scene.clear_color, glam::Vec4::new(0.3, 0.3, 0.3, 1.0));
    let material = &scene.materials[scene.meshes[0].material];
    assert!(material.unlit);
    let binding = material.base_color_texture.expect("texture");
    assert_eq!(binding.sampler.min_filter, MinFilter::LinearMipmapLinear);
    let texture = &scene.textures[binding.texture];
    assert_eq!((texture.width(), texture.height()), (256, 256));
}

#[test]
fn spot_is_textured_and_hangs_under_a_rotated_parent() {
    let Some(LoadedScene { scene, info, .. }) = load("spot-textured.glb") else {
        return;
    };
    assert_eq!(info.node_count, 4);
    assert_eq!(scene.textures.len(), 1);
    let texture = &scene.textures[0];
    assert_eq!((texture.width(), texture.height()), (1024, 1024));
    let material = &scene.materials[scene.meshes[0].material];
    let binding = material.base_color_texture.expect("spot is textured");
    assert_eq!(binding.sampler.min_filter, MinFilter::LinearMipmapLinear);
    assert_eq!(binding.sampler.wrap_s, Wrap::Repeat);
    assert_eq!(binding.sampler.wrap_t, Wrap::Repeat);
    assert!(!material.unlit);
    // The draw is node 2 ("spot", identity) under node 3 ("spot-root", rotated about y).
    let draw = &scene.draws[0];
    assert_eq!(draw.node_index, 2);
    assert_eq!(draw.node_name, "spot");
    let parent = Mat4::from_quat(Quat::from_xyzw(
        0.0,
        -0.25881904510252074,
        0.0,
        0.9659258262890683,
    ));
    let child = Mat4::IDENTITY;
    assert!(
        draw.model.abs_diff_eq(parent * child, 1e-6),
        "{:?}",
        draw.model
    );
    assert!(scene.meshes[0].texcoords.is_some());
}

#[test]
fn alpha_blend_draws_blended_triangles_after_the_opaque_quad() {
    let Some(LoadedScene { scene, .. }) = load("alpha-blend.glb") else {
        return;
    };
    let modes: Vec<AlphaMode> = scene
        .draws
        .iter()
        .map(|d| scene.materials[scene.meshes[d.mesh].material].alpha_mode)
        .collect();
    assert_eq!(modes[0], AlphaMode::Opaque);
    assert!(
        modes[1..].iter().all(|m| *m == AlphaMode::Blend),
        "{modes:?}"
    );
    // Alpha from baseColorFactor, and one primitive with per-vertex alpha in COLOR_0.
    assert_eq!(scene.materials[1].base_color_factor.w, 0.5);
    let per_vertex_alpha = scene
        .meshes
        .iter()
        .filter_map(|m| m.colors.as_ref())
        .any(|c| c.iter().any(|c| c.w < 1.0));
    assert!(per_vertex_alpha);
    // Blended triangles are unlit and single-sided.
    assert!(scene.materials.iter().all(|m| m.unlit && !m.double_sided));
}

#[test]
fn near_clip_ground_repeats_its_texture() {
    let Some(LoadedScene { scene, .. }) = load("near-clip.glb") else {
        return;
    };
    let ground = &scene.meshes[scene.draws[0].mesh];
    let max_uv = ground
        .texcoords
        .as_ref()
        .unwrap()
        .iter()
        .fold(0.0f32, |m, t| m.max(t.x).max(t.y));
    assert_eq!(max_uv, 200.0);
    assert_eq!(scene.camera.zfar, Some(1000.0));
    assert!(scene
        .camera
        .view
        .abs_diff_eq(Mat4::from_translation(Vec3::new(0.0, -1.5, 0.0)), 1e-6));
}
