//! Skins and animation: a glTF written here (a two-joint skin, node, morph-weight and
//! cubic-spline channels) posed at known times against analytic values, the real-world
//! skinned and animated samples at several times, and malformed skins and animations.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use kantele_scene::{load_scene_with, AnimationChoice, LoadOptions, LoadedScene, PoseError};
use serde_json::{json, Value};

use crate::common::{base64, temp_dir};

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;

/// A glTF document whose buffer is written as a data URI.
struct Doc {
    json: Value,
    bin: Vec<u8>,
}

impl Doc {
    /// Appends an accessor over new bytes; returns its index.
    fn accessor(&mut self, bytes: &[u8], component: u32, ty: &str, count: usize) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        let view = views.len() - 1;
        self.bin.extend_from_slice(bytes);
        let accessors = self.json["accessors"].as_array_mut().unwrap();
        accessors.push(
            json!({"bufferView": view, "componentType": component, "type": ty, "count": count}),
        );
        accessors.len() - 1
    }

    /// Float accessor of `ty` (`SCALAR`, `VEC3`, ...) with `per` components per element.
    fn floats(&mut self, values: &[f32], ty: &str, per: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let index = self.accessor(&bytes, FLOAT, ty, values.len() / per);
        if ty == "VEC3" {
            // POSITION accessors carry min and max.
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in values.chunks_exact(3) {
                for c in 0..3 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                }
            }
            self.json["accessors"][index]["min"] = json!(lo);
            self.json["accessors"][index]["max"] = json!(hi);
        }
        index
    }

    fn shorts(&mut self, values: &[u16], ty: &str, per: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.accessor(&bytes, UNSIGNED_SHORT, ty, values.len() / per)
    }

    /// The `.gltf` text, the buffer as a data URI.
    fn text(&self) -> Vec<u8> {
        let mut json = self.json.clone();
        json["buffers"] = json!([{
            "byteLength": self.bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin)),
        }]);
        serde_json::to_vec(&json).unwrap()
    }

    /// Writes `name.gltf` in a fresh folder.
    fn write(&self, name: &str) -> PathBuf {
        let path = temp_dir(name).join(format!("{name}.gltf"));
        std::fs::write(&path, self.text()).unwrap();
        path
    }
}

fn quat(q: Quat) -> [f32; 4] {
    q.to_array()
}

/// Bind-pose vertices of the skinned quad: joint 0 only, joint 1 only, half and half, joint 1.
const SKIN_POSITIONS: [Vec3; 4] = [
    Vec3::new(0.5, 0.0, 0.0),
    Vec3::new(1.5, 0.0, 0.0),
    Vec3::new(1.5, 0.5, 0.0),
    Vec3::new(2.0, 0.5, 0.0),
];
const SKIN_NORMALS: [Vec3; 4] = [Vec3::Z, Vec3::X, Vec3::Z, Vec3::Y];
/// Joint 1's rest rotation about Z (the file's static pose), in degrees.
const REST_DEGREES: f32 = 30.0;

/// The test rig:
/// - node 0 `joint0` (root) → node 1 `joint1` at (1, 0, 0), rotated 30° about Z at rest;
/// - node 2 `skinned`: the skinned quad (mesh 0), translated by (100, 0, 0), which skinning
///   ignores;
/// - node 3 `mover` (a triangle) with children node 4 `child` at (0, 1, 0) and node 6, a
///   camera at (0, 0, 10);
/// - node 5 `morph`: a triangle with one morph target (+1 in y on every vertex), weight 0;
/// - node 7 `spline`: a triangle;
/// - node 8 `skinned again`: the skinned quad again, with the same skin.
///
/// Animation 0 `bend`: joint 1 rotates from 0° (t = 0) to 90° (t = 2) about Z, LINEAR; `mover`
/// jumps from (0, 0, 0) to (5, 0, 0) at t = 1, STEP; `morph`'s weight goes 0 → 1 over [0, 1],
/// LINEAR; `spline` moves along x on a CUBICSPLINE over [0, 2] (value 0 → 1, out-tangent 1 at
/// the first key, zero tangents else).
fn rig() -> Doc {
    let mut d = Doc {
        json: json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0, 2, 3, 5, 7, 8]}],
            "bufferViews": [],
            "accessors": [],
        }),
        bin: Vec::new(),
    };
    let positions: Vec<f32> = SKIN_POSITIONS.iter().flat_map(|p| p.to_array()).collect();
    let normals: Vec<f32> = SKIN_NORMALS.iter().flat_map(|p| p.to_array()).collect();
    let pos = d.floats(&positions, "VEC3", 3);
    let nor = d.floats(&normals, "VEC3", 3);
    let joints = d.shorts(&[0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0], "VEC4", 4);
    let weights = d.floats(
        &[
            1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
        ],
        "VEC4",
        4,
    );
    let indices = d.shorts(&[0, 1, 2, 1, 3, 2], "SCALAR", 1);
    let ibm: Vec<f32> = [
        Mat4::IDENTITY,
        Mat4::from_translation(Vec3::new(-1.0, 0.0, 0.0)),
    ]
    .iter()
    .flat_map(|m| m.to_cols_array())
    .collect();
    let ibm = d.accessor(
        &ibm.iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<u8>>(),
        FLOAT,
        "MAT4",
        2,
    );
    let triangle = d.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3", 3);
    let morph_up = d.floats(&[0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0], "VEC3", 3);
    let t02 = d.floats(&[0.0, 2.0], "SCALAR", 1);
    let t01 = d.floats(&[0.0, 1.0], "SCALAR", 1);
    let rotations = [quat(Quat::IDENTITY), quat(Quat::from_rotation_z(PI / 2.0))].concat();
    let rotations = d.floats(&rotations, "VEC4", 4);
    let steps = d.floats(&[0.0, 0.0, 0.0, 5.0, 0.0, 0.0], "VEC3", 3);
    let morph_weights = d.floats(&[0.0, 1.0], "SCALAR", 1);
    #[rustfmt::skip]
    let spline = d.floats(&[
        0.0, 0.0, 0.0,  0.0, 0.0, 0.0,  1.0, 0.0, 0.0, // key 0: in, value, out
        0.0, 0.0, 0.0,  1.0, 0.0, 0.0,  0.0, 0.0, 0.0, // key 1: in, value, out
    ], "VEC3", 3);
    let rest = quat(Quat::from_rotation_z(REST_DEGREES.to_radians()));
    d.json["nodes"] = json!([
        {"name": "joint0", "children": [1]},
        {"name": "joint1", "translation": [1.0, 0.0, 0.0], "rotation": rest},
        {"name": "skinned", "mesh": 0, "skin": 0, "translation": [100.0, 0.0, 0.0]},
        {"name": "mover", "mesh": 1, "children": [4, 6]},
        {"name": "child", "mesh": 1, "translation": [0.0, 1.0, 0.0]},
        {"name": "morph", "mesh": 2},
        {"name": "camera", "camera": 0, "translation": [0.0, 0.0, 10.0]},
        {"name": "spline", "mesh": 1},
        {"name": "skinned again", "mesh": 0, "skin": 0, "translation": [-50.0, 0.0, 0.0]},
    ]);
    d.json["meshes"] = json!([
        {"name": "skinned", "primitives": [{"attributes": {
            "POSITION": pos, "NORMAL": nor, "JOINTS_0": joints, "WEIGHTS_0": weights},
            "indices": indices}]},
        {"name": "triangle", "primitives": [{"attributes": {"POSITION": triangle}}]},
        {"name": "morph", "weights": [0.0], "primitives": [{"attributes": {"POSITION": triangle},
            "targets": [{"POSITION": morph_up}]}]},
    ]);
    d.json["skins"] = json!([{"joints": [0, 1], "inverseBindMatrices": ibm}]);
    d.json["cameras"] =
        json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    d.json["animations"] = json!([{
        "name": "bend",
        "channels": [
            {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 3, "path": "translation"}},
            {"sampler": 2, "target": {"node": 5, "path": "weights"}},
            {"sampler": 3, "target": {"node": 7, "path": "translation"}},
        ],
        "samplers": [
            {"input": t02, "output": rotations, "interpolation": "LINEAR"},
            {"input": t01, "output": steps, "interpolation": "STEP"},
            {"input": t01, "output": morph_weights},
            {"input": t02, "output": spline, "interpolation": "CUBICSPLINE"},
        ],
    }]);
    d
}

/// The test rig as a `.gltf` file, a seed of the `gltf` fuzz target (skins, every sampler
/// kind, node, morph-weight and camera channels).
pub fn fuzz_seed() -> Vec<u8> {
    rig().text()
}

fn options(animation: Option<AnimationChoice>, time: f32) -> LoadOptions {
    LoadOptions {
        animation,
        time,
        ..LoadOptions::default()
    }
}

fn load_at(path: &Path, animation: Option<AnimationChoice>, time: f32) -> LoadedScene {
    load_scene_with(path, &options(animation, time))
        .unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

/// The skinned quad's vertices with joint 1 turned by `degrees` about its pivot (1, 0, 0).
fn expected_skin(degrees: f32) -> ([Vec3; 4], [Vec3; 4]) {
    let (s, c) = degrees.to_radians().sin_cos();
    let turn = |p: Vec3| {
        Vec3::new(
            1.0 + c * (p.x - 1.0) - s * p.y,
            s * (p.x - 1.0) + c * p.y,
            p.z,
        )
    };
    let [a, b, m, d] = SKIN_POSITIONS;
    let positions = [a, turn(b), 0.5 * m + 0.5 * turn(m), turn(d)];
    let normals = [
        Vec3::Z,
        Vec3::new(c, s, 0.0),
        Vec3::Z,
        Vec3::new(-s, c, 0.0),
    ];
    (positions, normals)
}

fn assert_close(actual: &[Vec3], expected: &[Vec3], what: &str) {
    assert_eq!(actual.len(), expected.len(), "{what}");
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert!(
            (*a - *e).abs().max_element() <= 1e-5,
            "{what} {i}: {a} != {e}"
        );
    }
}

fn draw<'a>(loaded: &'a LoadedScene, node: &str) -> &'a kantele_rules::scene::Draw {
    loaded
        .scene
        .draws
        .iter()
        .find(|d| d.node_name == node)
        .unwrap_or_else(|| panic!("a draw of {node}"))
}

fn skinned_mesh(loaded: &LoadedScene) -> (&[Vec3], &[Vec3]) {
    let d = draw(loaded, "skinned");
    assert_eq!(
        d.model,
        Mat4::IDENTITY,
        "skinned vertices are in world space"
    );
    let mesh = &loaded.scene.meshes[d.mesh];
    (&mesh.positions, mesh.normals.as_deref().expect("normals"))
}

#[test]
fn a_two_joint_skin_follows_its_joint_to_the_analytic_positions() {
    let path = rig().write("two-joint-skin");
    // Without an animation: the file's rest pose, joint 1 at 30° (not the bind pose), and the
    // skinned node's own translation is not applied.
    let rest = load_at(&path, None, 7.0);
    assert!(rest.animation.is_none());
    let names: Vec<_> = rest
        .info
        .animations
        .iter()
        .map(|a| a.name.as_deref())
        .collect();
    assert_eq!(names, vec![Some("bend")]);
    assert!(rest.info.warnings.is_empty(), "{:?}", rest.info.warnings);
    let (p, n) = skinned_mesh(&rest);
    let (ep, en) = expected_skin(REST_DEGREES);
    assert_close(p, &ep, "rest positions");
    assert_close(n, &en, "rest normals");
    // The second node with the skin: a mesh of its own, posed the same (its translation is
    // not applied either).
    let again = draw(&rest, "skinned again");
    assert_ne!(again.mesh, draw(&rest, "skinned").mesh);
    assert_eq!(rest.scene.meshes[again.mesh].positions, p);

    let bend = Some(AnimationChoice::Name("bend".into()));
    for (time, degrees) in [
        (-1.0, 0.0),
        (0.0, 0.0),
        (1.0, 45.0),
        (0.5, 22.5),
        (2.0, 90.0),
        (9.0, 90.0),
    ] {
        let loaded = load_at(&path, bend.clone(), time);
        let (p, n) = skinned_mesh(&loaded);
        let (ep, en) = expected_skin(degrees);
        assert_close(p, &ep, &format!("positions at t = {time}"));
        assert_close(n, &en, &format!("normals at t = {time}"));
    }
}

#[test]
fn node_morph_and_spline_channels_move_draws_meshes_and_the_camera() {
    let path = rig().write("node-channels");
    let by_index = Some(AnimationChoice::Index(0));
    let at = |time: f32| load_at(&path, by_index.clone(), time);
    let translation = |l: &LoadedScene, node: &str| draw(l, node).model.w_axis.truncate();

    let before = at(0.5);
    assert_eq!(
        translation(&before, "mover"),
        Vec3::ZERO,
        "STEP holds the first key"
    );
    assert_eq!(translation(&before, "child"), Vec3::new(0.0, 1.0, 0.0));
    let after = at(1.0);
    assert_eq!(translation(&after, "mover"), Vec3::new(5.0, 0.0, 0.0));
    assert_eq!(translation(&after, "child"), Vec3::new(5.0, 1.0, 0.0));
    // The camera hangs under `mover`: its eye is at (5, 0, 10).
    let eye = after.scene.camera.world_from_eye().w_axis.truncate();
    assert!((eye - Vec3::new(5.0, 0.0, 10.0)).length() < 1e-5, "{eye}");
    assert_eq!(after.scene.camera, after.scene.file_cameras[0].camera);

    // Morph weight 0.5 at t = 0.5: every vertex half a unit up (flat-shaded: one per corner).
    let morph = &before.scene.meshes[draw(&before, "morph").mesh];
    let base = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let up: Vec<Vec3> = base.iter().map(|p| *p + Vec3::new(0.0, 0.5, 0.0)).collect();
    assert_close(&morph.positions, &up, "morphed positions");
    assert_eq!(morph.normals.as_deref(), Some(&[Vec3::Z; 3][..]));

    // The cubic spline at t = 1 (u = 0.5, interval 2): 0.125 · 2 · 1 + 0.5 · 1 = 0.75.
    let x = translation(&at(1.0), "spline").x;
    assert!((x - 0.75).abs() < 1e-6, "{x}");
    // At t = 0.5 (u = 0.25): 0.140625 · 2 + 0.15625 = 0.4375.
    let x = translation(&at(0.5), "spline").x;
    assert!((x - 0.4375).abs() < 1e-6, "{x}");
}

/// Every bit of what posing writes.
fn pose_bits(loaded: &LoadedScene) -> Vec<u32> {
    let s = &loaded.scene;
    let mut bits = Vec::new();
    for m in &s.meshes {
        bits.extend(
            m.positions
                .iter()
                .flat_map(|p| p.to_array())
                .map(f32::to_bits),
        );
        for n in m.normals.iter().flatten() {
            bits.extend(n.to_array().map(f32::to_bits));
        }
    }
    for d in &s.draws {
        bits.extend(d.model.to_cols_array().map(f32::to_bits));
    }
    for c in &s.file_cameras {
        bits.extend(c.camera.view.to_cols_array().map(f32::to_bits));
    }
    bits.extend(s.camera.view.to_cols_array().map(f32::to_bits));
    bits
}

#[test]
fn posing_a_loaded_scene_equals_loading_at_that_time_bit_for_bit() {
    let path = rig().write("repose");
    let bend = Some(AnimationChoice::Index(0));
    let mut loaded = load_at(&path, bend.clone(), 0.0);
    let player = loaded.animation.take().expect("a player");
    assert_eq!(player.name(), "bend");
    assert_eq!(player.index(), 0);
    assert_eq!(player.time_range(), (0.0, 2.0));
    for time in [1.3, 0.25, 2.0, 1.3] {
        player.pose(&mut loaded.scene, time).expect("posed");
        let fresh = load_at(&path, bend.clone(), time);
        assert_eq!(pose_bits(&loaded), pose_bits(&fresh), "t = {time}");
    }
    assert!(matches!(
        player.pose(&mut loaded.scene, f32::NAN),
        Err(PoseError::Time(_))
    ));
    // Another scene: refused, not a panic.
    let other = load_at(&path, None, 0.0);
    let mut wrong = other.scene.clone();
    wrong.meshes.clear();
    assert!(matches!(
        player.pose(&mut wrong, 1.0),
        Err(PoseError::Mismatch(_))
    ));
}

#[test]
fn unknown_animations_and_bad_times_are_one_line_errors() {
    let path = rig().write("choices");
    let err = |animation: AnimationChoice, time: f32| {
        load_scene_with(&path, &options(Some(animation), time))
            .expect_err("an error")
            .to_string()
    };
    let e = err(AnimationChoice::Name("walk".into()), 0.0);
    assert!(
        e.contains("'walk' is not in the file") && e.contains("0 'bend'"),
        "{e}"
    );
    let e = err(AnimationChoice::Index(4), 0.0);
    assert!(e.contains("animation 4") && e.contains("0 'bend'"), "{e}");
    let e = err(AnimationChoice::Index(0), f32::NAN);
    assert!(e.contains("not a finite number"), "{e}");
    // Without an animation the time is not used.
    assert!(load_scene_with(&path, &options(None, f32::NAN)).is_ok());
}

/// Loads `doc` with animation 0 (and, with `also_without`, without one) and expects an error
/// mentioning `expected`, on one line.
fn expect_error(doc: &Doc, name: &str, expected: &str) {
    let path = doc.write(name);
    let result = std::panic::catch_unwind(|| {
        load_scene_with(&path, &options(Some(AnimationChoice::Index(0)), 1.0))
    });
    let e = result
        .unwrap_or_else(|_| panic!("{name}: the loader panicked"))
        .err()
        .unwrap_or_else(|| panic!("{name}: loaded"))
        .to_string();
    assert!(!e.contains('\n'), "{name}: {e}");
    assert!(e.contains(expected), "{name}: {e}");
}

#[test]
fn malformed_skins_and_animations_are_refused_by_line() {
    let mesh = "/meshes/0/primitives/0/attributes";
    let set = |d: &mut Doc, pointer: &str, value: Value| {
        *d.json.pointer_mut(pointer).unwrap() = value;
    };

    let mut d = rig();
    let joints = d.shorts(&[0, 0, 0, 0, 5, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0], "VEC4", 4);
    set(&mut d, &format!("{mesh}/JOINTS_0"), json!(joints));
    expect_error(
        &d,
        "joint-out-of-range",
        "on joint 5, but the skin has 2 joints",
    );
    // The same without an animation: skins are always applied.
    assert!(load_scene_with(&d.write("joint-out-of-range-rest"), &options(None, 0.0)).is_err());

    let mut d = rig();
    let weights = d.floats(&[1.0; 12], "VEC4", 4);
    set(&mut d, &format!("{mesh}/WEIGHTS_0"), json!(weights));
    expect_error(
        &d,
        "weights-count",
        "WEIGHTS_0 has 3 elements but POSITION has 4",
    );

    let mut d = rig();
    d.json
        .pointer_mut(mesh)
        .unwrap()
        .as_object_mut()
        .unwrap()
        .remove("WEIGHTS_0");
    expect_error(
        &d,
        "joints-without-weights",
        "JOINTS_0 and WEIGHTS_0 must come together",
    );

    let mut d = rig();
    let joints = d.floats(&[0.0; 16], "VEC4", 4);
    set(&mut d, &format!("{mesh}/JOINTS_0"), json!(joints));
    expect_error(&d, "joints-as-floats", "has a type glTF does not allow");

    let mut d = rig();
    let times = d.floats(&[2.0, 0.0], "SCALAR", 1);
    set(&mut d, "/animations/0/samplers/0/input", json!(times));
    expect_error(&d, "decreasing-times", "key times decrease");
    // Animations that are not played are not read.
    assert!(load_scene_with(&d.write("decreasing-times-rest"), &options(None, 0.0)).is_ok());

    let mut d = rig();
    let times = d.floats(&[0.0, f32::NAN], "SCALAR", 1);
    set(&mut d, "/animations/0/samplers/0/input", json!(times));
    expect_error(&d, "nan-times", "not finite");

    let mut d = rig();
    let vec3 = d.floats(&[0.0; 6], "VEC3", 3);
    set(&mut d, "/animations/0/samplers/0/output", json!(vec3));
    expect_error(
        &d,
        "rotation-as-vec3",
        "which glTF does not allow for Rotation",
    );

    let mut d = rig();
    let times = d.floats(&[0.0, 1.0, 2.0, 3.0], "VEC2", 2);
    set(&mut d, "/animations/0/samplers/0/input", json!(times));
    expect_error(&d, "times-as-vec2", "not float SCALAR times");

    let mut d = rig();
    let times = d.floats(&[0.0, 1.0, 2.0], "SCALAR", 1);
    set(&mut d, "/animations/0/samplers/0/input", json!(times));
    expect_error(&d, "key-count", "output values for 3 keys");

    let mut d = rig();
    set(&mut d, "/animations/0/channels/0/target/node", json!(99));
    expect_error(&d, "channel-node", "target node 99");

    let mut d = rig();
    set(&mut d, "/animations/0/channels/0/sampler", json!(9));
    expect_error(&d, "channel-sampler", "sampler 9 is not one of");

    let mut d = rig();
    set(
        &mut d,
        "/animations/0/samplers/0/interpolation",
        json!("BOUNCY"),
    );
    expect_error(&d, "interpolation", "'BOUNCY' is not STEP");

    let mut d = rig();
    let ibm = d.floats(&[0.0; 16], "MAT4", 16);
    set(&mut d, "/skins/0/inverseBindMatrices", json!(ibm));
    expect_error(&d, "too-few-ibms", "1 inverse bind matrices for 2 joints");

    // All-zero weights: defined, the vertex stays where the skinned node puts it.
    let mut d = rig();
    let weights = d.floats(&[0.0; 16], "VEC4", 4);
    set(&mut d, &format!("{mesh}/WEIGHTS_0"), json!(weights));
    let loaded = load_at(
        &d.write("zero-weights"),
        Some(AnimationChoice::Index(0)),
        1.0,
    );
    let (p, _) = skinned_mesh(&loaded);
    let moved: Vec<Vec3> = SKIN_POSITIONS
        .iter()
        .map(|p| *p + Vec3::new(100.0, 0.0, 0.0))
        .collect();
    assert_close(p, &moved, "unweighted vertices");
}

/// The real-world samples (`$KANTELE_SHARED/realworld`), or `None` with a printed reason.
fn realworld() -> Option<PathBuf> {
    kantele_testkit::shared_dir("realworld")
}

/// World-space boxes of every draw, as bits.
fn draw_boxes(loaded: &LoadedScene) -> Vec<[u32; 6]> {
    let s = &loaded.scene;
    s.draws
        .iter()
        .map(|d| {
            let (lo, hi) = s.meshes[d.mesh].bounds().expect("bounds");
            let mut a = Vec3::MAX;
            let mut b = Vec3::MIN;
            for i in 0..8 {
                let corner =
                    Vec3::select(glam::BVec3::new(i & 1 == 0, i & 2 == 0, i & 4 == 0), lo, hi);
                let p = d.model.transform_point3(corner);
                a = a.min(p);
                b = b.max(p);
            }
            [a.x, a.y, a.z, b.x, b.y, b.z].map(f32::to_bits)
        })
        .collect()
}

#[test]
fn realworld_skins_and_animations_play_without_warnings() {
    let Some(dir) = realworld() else { return };
    for (file, animations) in [
        ("skin-anim/CesiumMan.glb", 1),
        ("skin-anim/BrainStem.glb", 1),
        ("skin-anim/InterpolationTest.glb", 9),
    ] {
        let path = dir.join(file);
        let rest = load_at(&path, None, 0.0);
        assert!(
            rest.info.warnings.is_empty(),
            "{file}: {:?}",
            rest.info.warnings
        );
        assert_eq!(rest.info.animations.len(), animations, "{file}");
        for index in 0..animations {
            let choice = Some(AnimationChoice::Index(index));
            let mut boxes = Vec::new();
            for time in [0.0, 0.4, 0.9, 1.6] {
                let loaded = load_at(&path, choice.clone(), time);
                assert!(
                    loaded.info.warnings.is_empty(),
                    "{file}: {:?}",
                    loaded.info.warnings
                );
                boxes.push(draw_boxes(&loaded));
            }
            assert!(
                boxes.windows(2).any(|w| w[0] != w[1]),
                "{file} animation {index}: nothing moved"
            );
        }
        // Posing after loading: deterministic, and as fast as a frame should be.
        let mut loaded = load_at(&path, Some(AnimationChoice::Index(0)), 0.0);
        let player = loaded.animation.take().expect("a player");
        let (start, end) = player.time_range();
        assert!(end > start, "{file}: {start}..{end}");
        let frames = 24;
        let clock = std::time::Instant::now();
        for f in 0..frames {
            let t = start + (end - start) * f as f32 / frames as f32;
            player.pose(&mut loaded.scene, t).expect("posed");
        }
        let per_frame = clock.elapsed() / frames;
        let vertices: usize = loaded.scene.meshes.iter().map(|m| m.positions.len()).sum();
        println!("{file}: {vertices} vertices, {per_frame:?} per pose");
        player.pose(&mut loaded.scene, 0.77).unwrap();
        let first = pose_bits(&loaded);
        player.pose(&mut loaded.scene, 0.1).unwrap();
        player.pose(&mut loaded.scene, 0.77).unwrap();
        assert_eq!(
            first,
            pose_bits(&loaded),
            "{file}: posing is not deterministic"
        );
    }
}

#[test]
fn cesium_man_at_rest_is_skinned_into_its_bind_pose() {
    let Some(dir) = realworld() else { return };
    // CesiumMan's rest pose is its bind pose: skinned, the man has the extent of the bind
    // mesh's POSITION accessor (min/max in the file: x 0.3120, y 1.1383, z 1.5065, Z-up),
    // turned upright by the `Z_UP` and `Armature` nodes: width from y, height from z, depth
    // from x. Wrong inverse bind matrices or joint order give a different or collapsed shape.
    let loaded = load_at(&dir.join("skin-anim/CesiumMan.glb"), None, 0.0);
    let (lo, hi) = loaded
        .scene
        .draws
        .iter()
        .map(|d| {
            let (a, b) = loaded.scene.meshes[d.mesh].bounds().unwrap();
            (d.model.transform_point3(a), d.model.transform_point3(b))
        })
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), (a, b)| {
            (lo.min(a).min(b), hi.max(a).max(b))
        });
    let size = hi - lo;
    let bind = Vec3::new(0.569_137 + 0.569_137, 1.506_55, 0.180_954 + 0.131);
    assert!((size - bind).abs().max_element() < 1e-3, "{size} != {bind}");
}
