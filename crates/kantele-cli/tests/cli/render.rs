//! `kantele render` with the real loaders and CPU renderer: built-in and shared scenes, every
//! pass and file type, orbits, several scenes at once.

use crate::common::{kantele, ok, stdout, TempDir};
use crate::{distinct_colors, read_pfm, shared_scenes};

fn scene_resolution(args: &[&str]) -> (u32, u32) {
    let mut a = vec!["info", "--json"];
    a.extend_from_slice(args);
    let o = kantele(&a);
    ok(&o);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    let r = &v["resolution"];
    (r[0].as_u64().unwrap() as u32, r[1].as_u64().unwrap() as u32)
}

#[test]
fn render_builtin_cube() {
    let dir = TempDir::new("cube");
    let (w, h) = scene_resolution(&["--builtin", "cube"]);
    let out = dir.s("cube.png");
    let o = kantele(&["render", "--builtin", "cube", "-o", &out, "--json"]);
    ok(&o);
    let img = image::open(&out).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (w, h));
    assert!(distinct_colors(&img) > 2, "picture is too flat");
    let line: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(line["scene"], "cube");
    assert_eq!(line["width"], w);
    assert!(line["ms"].as_f64().unwrap() >= 0.0);
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path("cube.png.json")).unwrap()).unwrap();
    for key in ["fx", "fy", "cx", "cy", "yfov", "znear"] {
        assert!(
            side["camera"][key].is_number(),
            "sidecar camera.{key}: {side}"
        );
    }
    assert_eq!(side["backend"], "cpu");
    assert_eq!(side["world_to_camera_opencv"].as_array().unwrap().len(), 4);
    // The id entry names only what exists: no `files` without id outputs, no `file: null`.
    let ids = side["ids"].as_object().unwrap();
    assert!(
        ids.contains_key("channels") && !ids.contains_key("file"),
        "{side}"
    );
    assert!(!ids.contains_key("files"), "{side}");
    assert_eq!(dir.files(), vec!["cube.png", "cube.png.json"]);
}

#[test]
fn render_all_passes() {
    let dir = TempDir::new("passes");
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--size",
        "96x64",
        "-o",
        &dir.s("c.png"),
        "--depth",
        &dir.s("d.pfm"),
        "--normals",
        &dir.s("n.png"),
        "--ids",
        &dir.s("i.png"),
    ]);
    ok(&o);
    let (w, h, depth) = read_pfm(&dir.path("d.pfm"));
    assert_eq!((w, h), (96, 64));
    assert!(depth.iter().any(|d| d.is_infinite()), "no background");
    assert!(
        depth.iter().any(|d| d.is_finite() && *d > 0.0),
        "no geometry"
    );
    let normals = image::open(dir.path("n.png")).unwrap().to_rgba8();
    assert_eq!(normals.dimensions(), (96, 64));
    let ids = image::open(dir.path("i.png")).unwrap();
    assert_eq!(ids.color(), image::ColorType::L16, "one 16-bit channel");
    let ids = ids.to_luma16();
    assert_eq!(ids.dimensions(), (96, 64));
    assert!(ids.pixels().any(|p| p.0[0] >= 1));
    assert!(ids.pixels().any(|p| p.0[0] == 0));
    // Background agrees between depth and ids.
    for (i, p) in ids.pixels().enumerate() {
        assert_eq!(p.0[0] == 0, depth[i].is_infinite(), "pixel {i}");
    }
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--size",
        "32x32",
        "-o",
        &dir.s("w.exr"),
        "--depth",
        &dir.s("w-depth.pfm"),
        "--depth-kind",
        "window",
    ]);
    ok(&o);
    let (_, _, d) = read_pfm(&dir.path("w-depth.pfm"));
    assert!(d.contains(&1.0));
    assert!(d.iter().all(|p| (0.0..=1.0).contains(p)));
}

#[test]
fn render_orbit() {
    let dir = TempDir::new("orbit");
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--size",
        "48x48",
        "--orbit",
        "3",
        "-o",
        &dir.s("{stem}-{frame}.png"),
    ]);
    ok(&o);
    let files = dir.files();
    assert_eq!(
        files,
        vec![
            "cube-0000.png",
            "cube-0000.png.json",
            "cube-0001.png",
            "cube-0001.png.json",
            "cube-0002.png",
            "cube-0002.png.json",
        ]
    );
    let a = image::open(dir.path("cube-0000.png")).unwrap().to_rgba8();
    let b = image::open(dir.path("cube-0001.png")).unwrap().to_rgba8();
    assert!(distinct_colors(&a) > 2);
    assert_ne!(a, b, "orbit views should differ");
}

#[test]
fn render_several_scenes() {
    let dir = TempDir::new("several");
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--builtin",
        "teapot",
        "--size",
        "40x30",
        "-o",
        &dir.s("{index}-{stem}.png"),
    ]);
    ok(&o);
    assert!(dir.path("0000-cube.png").exists() && dir.path("0001-teapot.png").exists());
}

#[test]
fn render_shared_scene_at_its_resolution() {
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let dir = TempDir::new("shared");
    let o = kantele(&[
        "render",
        scenes.join("blog-teapot.glb").to_str().unwrap(),
        "-o",
        &dir.s("t.png"),
    ]);
    ok(&o);
    let img = image::open(dir.path("t.png")).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (192, 192));
    assert!(distinct_colors(&img) > 2);
}
