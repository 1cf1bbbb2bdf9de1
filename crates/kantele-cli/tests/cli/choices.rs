//! What to draw of a file: `--scene`, `--animation` with `--time` and `--time-range`, `--cull`,
//! and `kantele info`'s lists of scenes and animations.

use crate::common::{kantele, ok, stdout, TempDir};
use crate::{assert_clean_failure, distinct_colors};

fn realworld(file: &str) -> Option<String> {
    let dir = kantele_testkit::shared_dir("realworld")?;
    Some(dir.join(file).display().to_string())
}

fn info_json(args: &[&str]) -> serde_json::Value {
    let mut a = vec!["info", "--json"];
    a.extend_from_slice(args);
    let o = kantele(&a);
    ok(&o);
    serde_json::from_str(stdout(&o).trim()).unwrap()
}

#[test]
fn info_lists_animations_and_scenes() {
    let Some(man) = realworld("skin-anim/CesiumMan.glb") else {
        return;
    };
    let v = info_json(&[&man]);
    let animations = v["animations"].as_array().unwrap();
    assert_eq!(animations.len(), 1, "{v}");
    let duration = animations[0]["duration_seconds"].as_f64().unwrap();
    assert!(
        duration > 1.0 && duration < 3.0,
        "CesiumMan's walk: {duration} s"
    );
    let Some(scenes) = realworld("MultipleScenes/glTF/MultipleScenes.gltf") else {
        return;
    };
    let v = info_json(&[&scenes]);
    let listed = v["scenes"].as_array().unwrap();
    assert!(listed.len() >= 2, "{v}");
    assert_eq!(listed.iter().filter(|s| s["drawn"] == true).count(), 1);
    let other = listed.iter().find(|s| s["drawn"] == false).unwrap()["index"]
        .as_u64()
        .unwrap()
        .to_string();
    let v = info_json(&[&scenes, "--scene", &other]);
    let drawn: Vec<_> = v["scenes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["drawn"] == true)
        .map(|s| s["index"].as_u64().unwrap().to_string())
        .collect();
    assert_eq!(drawn, vec![other]);
}

#[test]
fn an_unknown_scene_or_animation_is_one_line() {
    let Some(man) = realworld("skin-anim/CesiumMan.glb") else {
        return;
    };
    let dir = TempDir::new("choices-errors");
    let out = dir.s("x.png");
    let o = kantele(&["render", &man, "--animation", "no-such", "-o", &out]);
    assert_clean_failure(&o, "no-such", &dir, &[]);
    let o = kantele(&["render", &man, "--scene", "7", "-o", &out]);
    assert_clean_failure(&o, "7", &dir, &[]);
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--animation",
        "0",
        "-o",
        &out,
    ]);
    assert_clean_failure(&o, "animation", &dir, &[]);
}

/// A sequence's frames differ as the figure walks, and each frame's sidecar names its time:
/// rendering that one time again with `--time` gives the same picture, byte for byte.
#[test]
fn a_time_range_sequence_reproduces_frame_by_frame() {
    let Some(man) = realworld("skin-anim/CesiumMan.glb") else {
        return;
    };
    let dir = TempDir::new("sequence");
    let o = kantele(&[
        "render",
        &man,
        "--animation",
        "0",
        "--time-range",
        "0:1",
        "--fps",
        "2",
        "--size",
        "96x96",
        "-o",
        &dir.s("walk_{frame}.png"),
    ]);
    ok(&o);
    let frames: Vec<Vec<u8>> = (0..3)
        .map(|k| std::fs::read(dir.path(&format!("walk_{k:04}.png"))).unwrap())
        .collect();
    assert_ne!(frames[0], frames[1], "the figure moves");
    for (k, frame) in frames.iter().enumerate() {
        let side: serde_json::Value = serde_json::from_slice(
            &std::fs::read(dir.path(&format!("walk_{k:04}.png.json"))).unwrap(),
        )
        .unwrap();
        let time = side["animation"]["time"].as_f64().unwrap();
        assert_eq!(time, k as f64 * 0.5, "frame {k}");
        assert_eq!(side["animation"]["index"], 0);
        let again = dir.s(&format!("again_{k}.png"));
        // The cameras frame the sequence's first pose: the same camera, from the sidecar.
        let o = kantele(&[
            "render",
            &man,
            "--animation",
            "0",
            "--time",
            &time.to_string(),
            "--views",
            &dir.s(&format!("walk_{k:04}.png.json")),
            "-o",
            &again,
        ]);
        ok(&o);
        assert!(
            std::fs::read(&again).unwrap() == *frame,
            "frame {k} at {time} s differs when rendered alone"
        );
    }
}

/// A single quad whose front faces away from the camera: OBJ draws it (two-sided by default),
/// `--cull back` removes it, `--cull front` keeps it.
#[test]
fn cull_decides_whether_a_face_seen_from_behind_is_drawn() {
    let dir = TempDir::new("cull");
    // Counter-clockwise seen from -Z: its front faces -Z, away from a camera on +Z.
    std::fs::write(
        dir.path("quad.obj"),
        "v -1 -1 0\nv -1 1 0\nv 1 1 0\nv 1 -1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let render = |cull: Option<&str>| {
        let out = dir.s(&format!("q_{}.png", cull.unwrap_or("default")));
        let mut args = vec![
            "render",
            "--camera",
            "look-at:0,0,4:0,0,0",
            "--size",
            "64x64",
            "-o",
            &out,
        ];
        let quad = dir.s("quad.obj");
        args.insert(1, &quad);
        if let Some(c) = cull {
            args.extend(["--cull", c]);
        }
        let o = kantele(&args);
        ok(&o);
        distinct_colors(&image::open(&out).unwrap().to_rgba8())
    };
    assert!(render(None) > 1, "drawn two-sided by default");
    assert_eq!(render(Some("back")), 1, "culled with --cull back");
    assert!(render(Some("front")) > 1, "kept with --cull front");
    assert!(render(Some("none")) > 1, "drawn with --cull none");
}
