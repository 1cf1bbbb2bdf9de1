//! `kantele info` and `kantele bench`.

use crate::common::{kantele, ok, stdout};
use crate::shared_scenes;

#[test]
fn info_builtin() {
    let o = kantele(&["info", "--builtin", "cube"]);
    ok(&o);
    assert!(stdout(&o).contains("triangles"));
    let o = kantele(&["info", "--builtin", "teapot", "--json"]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert!(v["triangles"].as_u64().unwrap() > 100);
}

#[test]
fn info_bunny() {
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let path = scenes.join("bunny.glb");
    let o = kantele(&["info", path.to_str().unwrap(), "--json"]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(v["triangles"], 69451);
    assert_eq!(v["resolution"], serde_json::json!([1024, 768]));
    let o = kantele(&[
        "info",
        scenes.join("spot-textured.glb").to_str().unwrap(),
        "--json",
    ]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(v["textures"][0]["width"], 1024);
    assert_eq!(v["textures"][0]["levels"], 11);
}

#[test]
fn bench_two_frames() {
    let o = kantele(&[
        "bench",
        "--builtin",
        "cube",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--json",
    ]);
    ok(&o);
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 1, "{out}");
    let v: serde_json::Value = serde_json::from_str(lines[0]).unwrap();
    assert_eq!(v["backend"], "cpu");
    assert_eq!(v["frames"], 2);
    // The build the figures came from: the tests' profile, not profile-guided.
    let build = v["build"]
        .as_str()
        .unwrap_or_else(|| panic!("build in {out}"));
    assert!(
        build.starts_with("opt-level ") && !build.contains("profile-guided"),
        "{out}"
    );
    assert!(v["median_ms"].as_f64().unwrap() > 0.0);
    assert!(v["min_ms"].as_f64().unwrap() <= v["max_ms"].as_f64().unwrap());
    // The CPU backend times its stages: medians within the slowest frame, the raster's not 0
    // (the cube covers pixels).
    for stage in ["geometry_ms", "binning_ms", "raster_ms"] {
        let t = v[stage]
            .as_f64()
            .unwrap_or_else(|| panic!("{stage} in {out}"));
        assert!(
            t >= 0.0 && t <= v["max_ms"].as_f64().unwrap(),
            "{stage} {t} in {out}"
        );
    }
    assert!(v["raster_ms"].as_f64().unwrap() > 0.0, "{out}");
    // And counts what it drew: the cube's front faces (of its 12 triangles, culling leaves at
    // most 6), each in at least one tile; no pixel drawn twice (a convex solid, back faces
    // culled), so covered fragments fit the picture, and every covered one is shaded (nothing
    // lies in front of it).
    let count = |name: &str| {
        v[name]
            .as_u64()
            .unwrap_or_else(|| panic!("{name} in {out}"))
    };
    let binned = count("triangles_binned");
    assert!((1..=6).contains(&binned), "{out}");
    assert!(count("bin_entries") >= binned, "{out}");
    let (width, height) = (count("width"), count("height"));
    let covered = count("fragments_covered");
    assert!(covered > 0 && covered <= width * height, "{out}");
    assert_eq!(count("fragments_shaded"), covered, "{out}");
    let o = kantele(&[
        "bench",
        "--builtin",
        "cube",
        "--frames",
        "2",
        "--warmup",
        "0",
    ]);
    ok(&o);
    assert!(stdout(&o).contains("median"));
}

#[test]
fn version_names_the_build() {
    let o = kantele(&["--version"]);
    ok(&o);
    let out = stdout(&o);
    assert!(
        out.starts_with("kantele ") && out.contains("(opt-level "),
        "{out}"
    );
}
