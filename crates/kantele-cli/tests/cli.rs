//! End-to-end tests of the `kantele` binary.
//!
//! Tests that need the real renderer and loaders (built-in scenes, shared scenes) are written
//! against the expected behaviour. Tests reading `shared/scenes` skip with a message when the
//! directory is absent; the viewer test skips when `xvfb-run` is not on PATH.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;

use common::{kantele, ok, stderr, stdout, TempDir, BIN};

/// A failure: non-zero status, exactly one line `kantele: error: ...` mentioning `needle`, no
/// panic, nothing written to `dir`.
fn assert_clean_failure(o: &Output, needle: &str, dir: &TempDir, keep: &[&str]) {
    let err = stderr(o);
    assert!(
        !o.status.success(),
        "expected failure, got success; stderr: {err}"
    );
    assert!(!err.contains("panicked"), "panic: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line on stderr, got: {err}");
    assert!(lines[0].starts_with("kantele: error: "), "{err}");
    assert!(
        lines[0].contains(needle),
        "message should mention '{needle}': {err}"
    );
    let left: Vec<String> = dir
        .files()
        .into_iter()
        .filter(|f| !keep.contains(&f.as_str()))
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

fn shared_scenes() -> Option<PathBuf> {
    kantele_testkit::shared_dir("scenes")
}

fn distinct_colors(img: &image::RgbaImage) -> usize {
    img.pixels().map(|p| p.0).collect::<HashSet<_>>().len()
}

// ---------------------------------------------------------------- errors (work without a renderer)

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

// ------------------------------------------------------- need the real loaders and CPU renderer

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
    assert_eq!(dir.files(), vec!["cube.png", "cube.png.json"]);
}

fn read_pfm(path: &Path) -> (u32, u32, Vec<f32>) {
    let data = std::fs::read(path).unwrap();
    let text_end = {
        let mut newlines = 0;
        data.iter()
            .position(|&b| {
                if b == b'\n' {
                    newlines += 1;
                }
                newlines == 3
            })
            .unwrap()
            + 1
    };
    let header = std::str::from_utf8(&data[..text_end]).unwrap();
    let mut it = header.split_whitespace();
    assert_eq!(it.next(), Some("Pf"));
    let w: u32 = it.next().unwrap().parse().unwrap();
    let h: u32 = it.next().unwrap().parse().unwrap();
    assert_eq!(it.next(), Some("-1.0"));
    let vals: Vec<f32> = data[text_end..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(vals.len(), (w * h) as usize);
    // PFM stores rows bottom to top; return them top to bottom like every other image here.
    let vals = vals
        .chunks_exact(w as usize)
        .rev()
        .flatten()
        .copied()
        .collect();
    (w, h, vals)
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
    assert!(v["median_ms"].as_f64().unwrap() > 0.0);
    assert!(v["min_ms"].as_f64().unwrap() <= v["max_ms"].as_f64().unwrap());
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

fn gl_available() -> bool {
    let o = kantele(&[
        "bench",
        "--builtin",
        "cube",
        "--backend",
        "gl",
        "--frames",
        "1",
        "--warmup",
        "0",
    ]);
    if !o.status.success() {
        kantele_testkit::skip(
            "gl",
            format!("the gl backend is unavailable here: {}", stderr(&o).trim()),
        );
    }
    o.status.success()
}

#[test]
fn compare_cpu_and_gl() {
    if !gl_available() {
        return;
    }
    let dir = TempDir::new("compare");
    let o = kantele(&[
        "compare",
        "--builtin",
        "cube",
        "--backends",
        "cpu,gl",
        "--out",
        &dir.s("cmp"),
        "--json",
    ]);
    ok(&o);
    let v: serde_json::Value = serde_json::from_str(stdout(&o).lines().next().unwrap()).unwrap();
    assert_eq!(v["passed"], true);
    for f in ["cube-cpu.png", "cube-gl.png", "cube-diff.png"] {
        assert!(dir.path("cmp").join(f).exists(), "{f} missing");
    }
    // A negative tolerance is a usage error (status 2), not a broken tolerance (status 1).
    let o = kantele(&["compare", "--builtin", "cube", "--max-mean-diff", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--max-mean-diff"));
}

/// `kantele compare` catches bugs planted in Kantele (built with the `fault-injection`
/// feature for tests): a flipped fill rule and a flipped texture V axis. The same comparison
/// passes without the fault.
#[test]
fn compare_catches_planted_bugs() {
    if !gl_available() {
        return;
    }
    let run = |fault: Option<&str>, scene: &str, extra: &[&str]| {
        let mut cmd = Command::new(BIN);
        cmd.args(["compare", "--builtin", scene, "--backends", "cpu,gl"])
            .args(extra);
        if let Some(f) = fault {
            cmd.env("KANTELE_FAULT", f);
        }
        cmd.output().expect("run kantele")
    };
    // Every edge of `pixel-edges` runs through pixel centres: with the right rule Kantele and
    // OpenGL agree exactly, with the wrong one about a tenth of the coverage differs.
    let exact = ["--max-coverage-diff", "0"];
    ok(&run(None, "pixel-edges", &exact));
    let o = run(Some("fill-rule"), "pixel-edges", &exact);
    assert_eq!(
        o.status.code(),
        Some(1),
        "fill-rule fault not caught: {}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("pixel-edges"), "{}", stderr(&o));
    // A mirrored texture V axis on the textured cube.
    ok(&run(None, "cube", &[]));
    let o = run(Some("flip-v"), "cube", &[]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "flip-v fault not caught: {}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("mean colour difference"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn compare_needs_two_backends() {
    let o = kantele(&["compare", "--builtin", "cube", "--backends", "cpu"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("kantele: error:"));
}

// ----------------------------------------------------------------------------------- viewer

#[cfg(feature = "viewer")]
fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
        .unwrap_or(false)
}

#[cfg(feature = "viewer")]
#[test]
fn viewer_under_xvfb() {
    if !on_path("xvfb-run") {
        kantele_testkit::skip(
            "display",
            "xvfb-run is not on PATH (apt-get install xvfb xauth)",
        );
        return;
    }
    let dir = TempDir::new("view");
    let shot = dir.s("shot.png");
    let o = Command::new("xvfb-run")
        .args([
            "-a",
            "-s",
            "-screen 0 1024x768x24",
            BIN,
            "view",
            "--builtin",
            "cube",
            "--size",
            "160x120",
        ])
        .args(["--frames", "5", "--screenshot", &shot])
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run xvfb-run");
    ok(&o);
    let img = image::open(&shot).unwrap().to_rgba8();
    assert!(img.width() > 0 && img.height() > 0);
    assert!(distinct_colors(&img) > 1, "screenshot is uniform");
}

// ------------------------------------------------------------ every reference scene, by property

/// Linear luminance of an sRGB pixel.
fn luminance(p: &image::Rgba<u8>) -> f32 {
    let lin = |c: u8| kantele::color::srgb_to_linear(c as f32 / 255.0);
    0.2126 * lin(p.0[0]) + 0.7152 * lin(p.0[1]) + 0.0722 * lin(p.0[2])
}

/// Renders every `.glb` in `../shared/scenes` in one run of the binary and checks each image's
/// size against INDEX.md, then properties that a wrong renderer would break.
#[test]
fn every_shared_scene_renders_and_looks_right() {
    let Some(scenes) = shared_scenes() else {
        return;
    };
    // Expected sizes from INDEX.md's table: | `name.glb` | WxH | ...
    let index = std::fs::read_to_string(scenes.join("INDEX.md")).expect("INDEX.md");
    let mut expected = Vec::new();
    for line in index.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() > 3 && cells[1].starts_with('`') && cells[1].ends_with(".glb`") {
            let name = cells[1]
                .trim_matches('`')
                .trim_end_matches(".glb")
                .to_string();
            let (w, h) = cells[2].split_once('x').expect("WxH");
            let covered: f64 = cells[5].trim_end_matches('%').parse().expect("covered %");
            expected.push((
                name,
                w.parse::<u32>().expect("w"),
                h.parse::<u32>().expect("h"),
                covered,
            ));
        }
    }
    assert!(
        expected.len() >= 18,
        "INDEX.md lists {} scenes",
        expected.len()
    );
    let dir = TempDir::new("all-scenes");
    let mut args = vec!["render".to_string()];
    for (name, _, _, _) in &expected {
        args.push(
            scenes
                .join(format!("{name}.glb"))
                .to_string_lossy()
                .into_owned(),
        );
    }
    args.extend([
        "-o".into(),
        dir.s("{stem}.png"),
        "--depth".into(),
        dir.s("{stem}.pfm"),
    ]);
    let arg_refs: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&kantele(&arg_refs));
    for (name, w, h, covered) in &expected {
        let img = image::open(dir.path(&format!("{name}.png")))
            .expect("png")
            .to_rgba8();
        assert_eq!(img.dimensions(), (*w, *h), "{name}");
        // INDEX.md gives the share of pixels the OpenGL anchor covers with opaque geometry;
        // blended geometry writes no depth, so opaque coverage is what the depth image shows.
        let (_, _, depth) = read_pfm(&dir.path(&format!("{name}.pfm")));
        let ours =
            100.0 * depth.iter().filter(|d| d.is_finite()).count() as f64 / depth.len() as f64;
        assert!(
            (ours - covered).abs() < 0.2,
            "{name}: {ours:.2}% covered, INDEX.md says {covered}%"
        );
    }

    // The bunny, lit by the headlight: visible surfaces face the camera, so most covered pixels
    // are far brighter than the darkest (grazing, nearly ambient-only) ones. Inside out — back faces drawn or
    // normals reversed — everything would sit at the ambient level.
    let img = image::open(dir.path("bunny.png")).expect("png").to_rgba8();
    let (_, _, depth) = read_pfm(&dir.path("bunny.pfm"));
    let mut lum: Vec<f32> = img
        .pixels()
        .zip(&depth)
        .filter(|(_, d)| d.is_finite())
        .map(|(p, _)| luminance(p))
        .collect();
    assert!(lum.len() > 100_000, "bunny covers {} pixels", lum.len());
    lum.sort_by(f32::total_cmp);
    let (dark, median) = (lum[lum.len() / 50], lum[lum.len() / 2]);
    // Measured: median / 2nd percentile ≈ 2.7; inside out it would be about 1.
    assert!(
        median > 2.0 * dark,
        "bunny looks unlit or inside out: median {median}, 2nd percentile {dark}"
    );

    // near-clip: the ground plane reaches from the bottom of the image up to the horizon. In the
    // left half (clear of the big triangle) every column is covered from near the middle row
    // down to the bottom, and nothing above it.
    let (w, h, depth) = read_pfm(&dir.path("near-clip.pfm"));
    let covered = |x: u32, y: u32| depth[(y * w + x) as usize].is_finite();
    for x in (0..w / 2).step_by(7) {
        let top = (0..h)
            .find(|&y| covered(x, y))
            .expect("column covered somewhere");
        assert!(
            (h / 2 - 24..h / 2 + 24).contains(&top),
            "column {x}: ground starts at row {top}, not at the horizon"
        );
        assert!(
            (top..h).all(|y| covered(x, y)),
            "column {x}: hole in the ground below row {top}"
        );
    }
}

// ------------------------------------------------------------------- patched reference files

/// Byte range of the first primitive's accessor `attribute` (or its indices when `None`) in a
/// .glb's binary chunk, with the accessor's component type.
fn glb_accessor(glb: &[u8], attribute: Option<&str>) -> (usize, usize, u64) {
    let u32_at =
        |o: usize| u32::from_le_bytes([glb[o], glb[o + 1], glb[o + 2], glb[o + 3]]) as usize;
    let json_len = u32_at(12);
    let json: serde_json::Value =
        serde_json::from_slice(&glb[20..20 + json_len]).expect("json chunk");
    let bin_start = 20 + json_len + 8;
    let primitive = &json["meshes"][0]["primitives"][0];
    let accessor_index = match attribute {
        Some(name) => &primitive["attributes"][name],
        None => &primitive["indices"],
    }
    .as_u64()
    .expect("accessor") as usize;
    let accessor = &json["accessors"][accessor_index];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().expect("view") as usize];
    let offset = bin_start
        + view["byteOffset"].as_u64().unwrap_or(0) as usize
        + accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
    let component = accessor["componentType"].as_u64().expect("component type");
    (
        offset,
        accessor["count"].as_u64().expect("count") as usize,
        component,
    )
}

/// A reference file with an index past the end of its vertices is refused with a clear message;
/// one with NaN positions renders (those triangles are dropped) and leaves no error.
#[test]
fn patched_reference_files_bad_indices_and_nan_positions() {
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let original = std::fs::read(scenes.join("blog-teapot.glb")).expect("read");
    let dir = TempDir::new("patched");

    let mut bad_index = original.clone();
    let (offset, _, component) = glb_accessor(&bad_index, None);
    match component {
        5123 => bad_index[offset..offset + 2].copy_from_slice(&u16::MAX.to_le_bytes()),
        5125 => bad_index[offset..offset + 4].copy_from_slice(&u32::MAX.to_le_bytes()),
        other => panic!("unexpected index type {other}"),
    }
    std::fs::write(dir.path("bad-index.glb"), &bad_index).expect("write");
    let o = kantele(&["render", &dir.s("bad-index.glb"), "-o", &dir.s("bad.png")]);
    assert_clean_failure(&o, "bad-index.glb", &dir, &["bad-index.glb"]);
    assert!(stderr(&o).contains("index"), "{}", stderr(&o));

    let mut nan = original.clone();
    let (offset, count, _) = glb_accessor(&nan, Some("POSITION"));
    // Every third vertex's x becomes NaN: many triangles are dropped, the rest still draw.
    for v in (0..count).step_by(3) {
        nan[offset + 12 * v..offset + 12 * v + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    }
    std::fs::write(dir.path("nan.glb"), &nan).expect("write");
    let o = kantele(&["render", &dir.s("nan.glb"), "-o", &dir.s("nan.png")]);
    ok(&o);
    assert!(!stderr(&o).contains("panicked"));
    let img = image::open(dir.path("nan.png")).expect("png").to_rgba8();
    assert_eq!(img.dimensions(), (192, 192));
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
