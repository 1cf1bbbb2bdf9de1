//! Usage and input errors, which need no renderer: one clean line, nothing written.

use std::path::Path;

use crate::common::{kantele, kantele_with_env, ok, stderr, stdout, TempDir};
use crate::{assert_clean_failure, shared_scenes};

#[test]
fn version_and_help() {
    let o = kantele(&["--version"]);
    ok(&o);
    assert!(stdout(&o).starts_with("kantele "));
    for sub in ["render", "info", "bench", "compare", "view"] {
        let o = kantele(&[sub, "--help"]);
        ok(&o);
        assert!(stdout(&o).contains("Usage"), "{sub} --help: {}", stdout(&o));
    }
    assert!(stdout(&kantele(&["render", "--help"])).contains("{stem}"));
}

#[test]
fn missing_file() {
    let dir = TempDir::new("missing");
    let o = kantele(&["render", &dir.s("nope.glb"), "-o", &dir.s("out.png")]);
    assert_clean_failure(&o, "nope.glb", &dir, &[]);
    let o = kantele(&["info", &dir.s("nope.glb")]);
    assert_clean_failure(&o, "nope.glb", &dir, &[]);
    let o = kantele(&["bench", &dir.s("nope.glb"), "--frames", "2"]);
    assert_clean_failure(&o, "nope.glb", &dir, &[]);
}

#[test]
fn garbage_glb() {
    let dir = TempDir::new("garbage");
    std::fs::write(
        dir.path("broken.glb"),
        b"glTF\x02\x00\x00\x00garbage garbage",
    )
    .unwrap();
    let o = kantele(&["render", &dir.s("broken.glb"), "-o", &dir.s("out.png")]);
    assert_clean_failure(&o, "broken.glb", &dir, &["broken.glb"]);
    let o = kantele(&["info", &dir.s("broken.glb")]);
    assert_clean_failure(&o, "broken.glb", &dir, &["broken.glb"]);
}

#[test]
fn truncated_glb() {
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let dir = TempDir::new("truncated");
    let bytes = std::fs::read(scenes.join("bunny.glb")).unwrap();
    std::fs::write(dir.path("cut.glb"), &bytes[..bytes.len() / 2]).unwrap();
    let o = kantele(&["render", &dir.s("cut.glb"), "-o", &dir.s("out.png")]);
    assert_clean_failure(&o, "cut.glb", &dir, &["cut.glb"]);
}

#[test]
fn bad_sizes() {
    let dir = TempDir::new("sizes");
    for size in ["0x0", "100000x100000", "16385x2", "12", "axb"] {
        let o = kantele(&[
            "render",
            "--builtin",
            "cube",
            "-o",
            &dir.s("out.png"),
            "--size",
            size,
        ]);
        assert_clean_failure(&o, "size", &dir, &[]);
    }
}

/// A field of view outside [0.01°, 180°) is refused in one line: a narrower one frames the
/// scene from so far away that the picture came out empty, silently.
#[test]
fn bad_fields_of_view() {
    let dir = TempDir::new("fov");
    for fov in ["0", "1e-30", "0.009", "180", "nan", "inf"] {
        let o = kantele(&[
            "render",
            "--builtin",
            "cube",
            "-o",
            &dir.s("out.png"),
            "--fov",
            fov,
        ]);
        assert_clean_failure(&o, "field of view", &dir, &[]);
    }
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--size",
        "32x32",
        "-o",
        &dir.s("narrow.png"),
        "--fov",
        "0.01",
    ]);
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    let picture = image::open(dir.path("narrow.png")).unwrap().to_rgba8();
    assert!(
        picture.pixels().any(|p| p.0 != picture.get_pixel(0, 0).0),
        "the cube is drawn at the narrowest field of view"
    );
}

#[test]
fn unknown_strategy() {
    let dir = TempDir::new("strategy");
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "-o",
        &dir.s("out.png"),
        "--strategy",
        "zigzag",
    ]);
    assert_clean_failure(&o, "zigzag", &dir, &[]);
}

#[test]
fn unknown_builtin() {
    let dir = TempDir::new("builtin");
    let o = kantele(&[
        "render",
        "--builtin",
        "dodecahedron",
        "-o",
        &dir.s("out.png"),
    ]);
    assert_clean_failure(&o, "dodecahedron", &dir, &[]);
}

#[test]
fn several_inputs_need_a_template() {
    let dir = TempDir::new("template");
    std::fs::write(dir.path("a.glb"), b"x").unwrap();
    std::fs::write(dir.path("b.glb"), b"y").unwrap();
    let o = kantele(&[
        "render",
        &dir.s("a.glb"),
        &dir.s("b.glb"),
        "-o",
        &dir.s("out.png"),
    ]);
    assert_clean_failure(&o, "out.png", &dir, &["a.glb", "b.glb"]);
    let o = kantele(&[
        "render",
        &dir.s("a.glb"),
        "--orbit",
        "3",
        "-o",
        &dir.s("out.png"),
    ]);
    assert_clean_failure(&o, "out.png", &dir, &["a.glb", "b.glb"]);
    let o = kantele(&["render", &dir.s("a.glb"), "-o", &dir.s("{bogus}.png")]);
    assert_clean_failure(&o, "bogus", &dir, &["a.glb", "b.glb"]);
}

#[test]
fn unsupported_output_types() {
    let dir = TempDir::new("types");
    std::fs::write(dir.path("a.glb"), b"x").unwrap();
    let keep = ["a.glb"];
    let o = kantele(&["render", &dir.s("a.glb"), "-o", &dir.s("out.jpg")]);
    assert_clean_failure(&o, "out.jpg", &dir, &keep);
    let o = kantele(&[
        "render",
        &dir.s("a.glb"),
        "-o",
        &dir.s("out.png"),
        "--depth",
        &dir.s("d.tiff"),
    ]);
    assert_clean_failure(&o, "d.tiff", &dir, &keep);
    let o = kantele(&[
        "render",
        &dir.s("a.glb"),
        "-o",
        &dir.s("out.png"),
        "--ids",
        &dir.s("out.png"),
    ]);
    assert_clean_failure(&o, "out.png", &dir, &keep);
}

#[test]
fn no_scene_given() {
    let o = kantele(&["render", "-o", "x.png"]);
    assert!(!o.status.success());
    assert!(stderr(&o).starts_with("kantele: error: "));
    assert!(!Path::new("x.png").exists());
}

#[test]
fn a_frame_over_its_time_budget_fails_cleanly() {
    let dir = TempDir::new("timeout");
    let out = dir.s("teapot.png");
    // A budget far below one frame: the frame stops at its first check, nothing is written.
    let o = kantele(&[
        "render",
        "--builtin",
        "teapot",
        "-o",
        &out,
        "--size",
        "640x480",
        "--timeout",
        "0.000001",
    ]);
    assert_clean_failure(&o, "time budget", &dir, &[]);
    // A generous budget renders as usual.
    let o = kantele(&[
        "render",
        "--builtin",
        "teapot",
        "-o",
        &out,
        "--timeout",
        "60",
    ]);
    ok(&o);
    // A budget that is not a positive number is a usage error.
    let o = kantele(&[
        "render",
        "--builtin",
        "teapot",
        "-o",
        &out,
        "--timeout",
        "0",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("timeout"), "{}", stderr(&o));
}

#[test]
fn kantele_isa_is_checked() {
    let dir = TempDir::new("isa");
    let out = dir.s("cube.png");
    let args = ["render", "--builtin", "cube", "--size", "64x48", "-o", &out];
    // A value that names no level: one clean line, nothing written.
    let o = kantele_with_env(&args, &[("KANTELE_ISA", "mmx")]);
    assert_clean_failure(&o, "KANTELE_ISA: unknown instruction set `mmx`", &dir, &[]);
    // A level this CPU lacks: a warning, and the picture from the best level.
    let missing = if cfg!(target_arch = "aarch64") {
        "avx2"
    } else {
        "neon"
    };
    let o = kantele_with_env(&args, &[("KANTELE_ISA", missing)]);
    ok(&o);
    let warning = format!("kantele: warning: KANTELE_ISA={missing}: this CPU does not support it");
    assert!(stderr(&o).contains(&warning), "{}", stderr(&o));
    assert!(dir.path("cube.png").is_file());
    // A supported level, and an empty value (no override): no warning.
    for value in ["scalar", ""] {
        let o = kantele_with_env(&args, &[("KANTELE_ISA", value)]);
        ok(&o);
        assert!(!stderr(&o).contains("KANTELE_ISA"), "{}", stderr(&o));
    }
}
