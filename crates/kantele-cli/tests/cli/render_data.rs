//! End-to-end tests of `kantele render` for dataset work: cameras in (`--camera`, `--views`,
//! `--orbit`), one-channel id files, BOP depth, standard output, and whole output sets
//! (inputs protected, Ctrl-C leaves nothing behind).

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::{kantele, ok, TempDir, BIN};

fn err_line(o: &Output) -> String {
    assert!(!o.status.success(), "expected a failure");
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
    e
}

/// Reads a little-endian `.npy` of `<f4` or `<u4` values: (shape, raw 4-byte words).
fn read_npy(path: &Path) -> (Vec<usize>, String, Vec<[u8; 4]>) {
    let data = std::fs::read(path).unwrap();
    assert_eq!(&data[..6], b"\x93NUMPY");
    let header_len = u16::from_le_bytes([data[8], data[9]]) as usize;
    let header = std::str::from_utf8(&data[10..10 + header_len]).unwrap();
    let descr = header.split("'descr': '").nth(1).unwrap()[..3].to_string();
    let shape_text = header.split("'shape': (").nth(1).unwrap();
    let shape: Vec<usize> = shape_text[..shape_text.find(')').unwrap()]
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let words = data[10 + header_len..]
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    (shape, descr, words)
}

/// An OBJ of `n` small triangles in a strip across the unit square (one object).
fn write_triangle_soup(path: &Path, n: usize) {
    use std::fmt::Write;
    let mut s = String::with_capacity(n * 60);
    let cols = (n as f64).sqrt().ceil() as usize;
    for i in 0..n {
        let (x, y) = ((i % cols) as f32, (i / cols) as f32);
        let k = 1.0 / cols as f32;
        let _ = writeln!(
            s,
            "v {} {} 0\nv {} {} 0\nv {} {} 0",
            x * k,
            y * k,
            (x + 1.0) * k,
            y * k,
            x * k,
            (y + 1.0) * k
        );
    }
    for i in 0..n {
        let _ = writeln!(s, "f {} {} {}", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn views_file_reproduces_the_sidecar_picture() {
    let dir = TempDir::new("views");
    for camera in [
        &["--camera", "look-at:2.5,1.5,3:0,0,0"][..],
        &["--camera", "auto"],
        &["--ortho"],
    ] {
        let a_png = dir.s("a.png");
        let mut args = vec![
            "render",
            "--builtin",
            "teapot",
            "--size",
            "90x60",
            "-o",
            &a_png,
        ];
        args.extend_from_slice(camera);
        let o = kantele(&args);
        ok(&o);
        let side: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path("a.png.json")).unwrap()).unwrap();
        let model = side["camera"]["model"].as_str();
        assert_eq!(
            model == Some("orthographic"),
            camera == ["--ortho"],
            "{camera:?}: {model:?}"
        );
        let o = kantele(&[
            "render",
            "--builtin",
            "teapot",
            "--views",
            &dir.s("a.png.json"),
            "-o",
            &dir.s("b.png"),
        ]);
        ok(&o);
        let a = std::fs::read(dir.path("a.png")).unwrap();
        let b = std::fs::read(dir.path("b.png")).unwrap();
        assert!(a == b, "{camera:?}: the views file gives another picture");
        let side: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path("b.png.json")).unwrap()).unwrap();
        assert_eq!(
            (side["width"].as_u64(), side["height"].as_u64()),
            (Some(90), Some(60))
        );
    }
}

#[test]
fn auto_camera_fills_the_picture_on_a_transparent_background() {
    let dir = TempDir::new("auto");
    let o = kantele(&[
        "render",
        "--builtin",
        "teapot",
        "--size",
        "120x80",
        "--camera",
        "auto",
        "--background",
        "transparent",
        "-o",
        &dir.s("t.png"),
    ]);
    ok(&o);
    let img = image::open(dir.path("t.png")).unwrap().to_rgba8();
    assert_eq!(img.get_pixel(0, 0).0[3], 0, "background is transparent");
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for (x, y, p) in img.enumerate_pixels() {
        if p.0[3] > 0 {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
    }
    // The box fills the tighter direction; the teapot inside it spans well over half the
    // picture (the scene camera leaves it at a third) and touches no border.
    assert!(y1 - y0 >= 45 && x1 - x0 >= 70, "{x0}..{x1} x {y0}..{y1}");
    assert!(
        x0 > 0 && y0 > 0 && x1 < 119 && y1 < 79,
        "{x0}..{x1} x {y0}..{y1}"
    );
    let bad = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--background",
        "sky",
        "-o",
        &dir.s("x.png"),
    ]);
    assert!(err_line(&bad).contains("colour"));
}

#[test]
fn instance_mask_of_a_70000_triangle_mesh() {
    let dir = TempDir::new("bigmesh");
    let obj = dir.path("soup.obj");
    write_triangle_soup(&obj, 70_000);
    // Triangle ids do not fit a 16-bit PNG: refused before rendering, nothing written.
    let o = kantele(&[
        "render",
        &dir.s("soup.obj"),
        "--size",
        "64x64",
        "-o",
        &dir.s("c.png"),
        "--ids",
        &format!("triangle={}", dir.s("t.png")),
    ]);
    let e = err_line(&o);
    assert!(e.contains("t.png") && e.contains("16-bit"), "{e}");
    assert_eq!(dir.files(), vec!["soup.obj"]);
    // Instance ids alone fit; triangle ids go to a 32-bit .npy.
    let o = kantele(&[
        "render",
        &dir.s("soup.obj"),
        "--size",
        "64x64",
        "--camera",
        "look-at:0.5,0.5,1.5:0.5,0.5,0",
        "-o",
        &dir.s("c.png"),
        "--ids",
        &format!("instance={}", dir.s("i.png")),
        "--ids",
        &format!("triangle={}", dir.s("t.npy")),
    ]);
    ok(&o);
    let ids = image::open(dir.path("i.png")).unwrap();
    assert_eq!(ids.color(), image::ColorType::L16);
    let ids = ids.to_luma16();
    let values: std::collections::BTreeSet<u16> = ids.pixels().map(|p| p.0[0]).collect();
    assert!(
        values.contains(&1),
        "the mesh's instance id 1 is in the mask"
    );
    assert!(values.iter().all(|v| *v <= 1), "{values:?}");
    let (shape, descr, words) = read_npy(&dir.path("t.npy"));
    assert_eq!((shape, descr.as_str()), (vec![64, 64], "<u4"));
    let tri: Vec<u32> = words.iter().map(|w| u32::from_le_bytes(*w)).collect();
    assert!(tri.iter().any(|&t| t > 65_536), "high triangle ids present");
    for (p, t) in ids.pixels().zip(&tri) {
        assert_eq!(p.0[0] == 0, *t == 0, "masks agree on the background");
    }
}

#[test]
fn bop_depth_in_millimetres_matches_float_depth() {
    let dir = TempDir::new("bop");
    let render = |color: &str, kind: &str, depth: &str| {
        kantele(&[
            "render",
            "--builtin",
            "cube",
            "--size",
            "80x60",
            "-o",
            color,
            "--depth-kind",
            kind,
            "--depth",
            depth,
        ])
    };
    // One file as colour and depth: refused before rendering.
    let same = dir.s("same.png");
    assert!(err_line(&render(&same, "eye", &same)).contains("more than once"));
    for kind in ["eye", "ray"] {
        let (png, npy) = (dir.s(&format!("{kind}.png")), dir.s(&format!("{kind}.npy")));
        ok(&render(&dir.s("c1.png"), kind, &png));
        ok(&render(&dir.s("c2.png"), kind, &npy));
        let mm = image::open(&png).unwrap();
        assert_eq!(mm.color(), image::ColorType::L16);
        let mm = mm.to_luma16();
        let (shape, descr, words) = read_npy(Path::new(&npy));
        assert_eq!((shape, descr.as_str()), (vec![60, 80], "<f4"));
        let metres: Vec<f32> = words.iter().map(|w| f32::from_le_bytes(*w)).collect();
        let mut covered = 0;
        for (p, m) in mm.pixels().zip(&metres) {
            if m.is_finite() {
                covered += 1;
                assert_eq!(p.0[0], (m * 1000.0).round() as u16);
            } else {
                assert_eq!(p.0[0], 0, "background is 0");
            }
        }
        assert!(covered > 100);
    }
}

#[test]
fn png_to_standard_output() {
    let o = kantele(&["render", "--builtin", "cube", "--size", "20x10", "-o", "-"]);
    ok(&o);
    let img = image::load_from_memory(&o.stdout).unwrap();
    assert_eq!((img.width(), img.height()), (20, 10));
    let dir = TempDir::new("stdout");
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "-o",
        "-",
        "--depth",
        &dir.s("d.pfm"),
    ]);
    assert!(err_line(&o).contains("standard output"));
}

#[test]
fn outputs_never_overwrite_inputs() {
    let dir = TempDir::new("inputs");
    std::fs::write(
        dir.path("m.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.path("m.mtl"), "newmtl a\nmap_Kd wood.png\n").unwrap();
    std::fs::write(dir.path("wood.png"), b"not really a png").unwrap();
    let o = kantele(&["render", &dir.s("m.obj"), "-o", &dir.s("wood.png")]);
    let e = err_line(&o);
    assert!(e.contains("overwrite the input"), "{e}");
    assert_eq!(
        std::fs::read(dir.path("wood.png")).unwrap(),
        b"not really a png"
    );
    // Output folders are made before rendering.
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--size",
        "16x16",
        "-o",
        &dir.s("new/deep/c.png"),
    ]);
    ok(&o);
    assert!(dir.path("new/deep/c.png.json").is_file());
}

/// A `.glb` of one triangle whose material's texture is the external image `uri`.
fn glb_with_image_uri(uri: &str) -> Vec<u8> {
    let positions: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}],
"textures":[{{"source":0}}],"images":[{{"uri":"{uri}"}}],
"buffers":[{{"byteLength":36}}],"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}]}}"#
    );
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + positions.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((positions.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&positions);
    glb
}

/// Files the scene reads through references the command cannot see before loading (a `.glb`'s
/// image URIs, `file://` URIs) are protected too: the output is refused after loading, before
/// anything is written, and the file keeps its bytes.
#[test]
fn outputs_never_overwrite_what_the_loader_read() {
    let dir = TempDir::new("loader-reads");
    std::fs::write(dir.path("tex.png"), b"not really a png").unwrap();
    std::fs::write(dir.path("t.glb"), glb_with_image_uri("tex.png")).unwrap();
    let absolute = std::fs::canonicalize(dir.path("tex.png")).unwrap();
    let file_uri = format!("file://{}", absolute.display());
    std::fs::write(dir.path("u.glb"), glb_with_image_uri(&file_uri)).unwrap();
    for (scene, command) in [
        ("t.glb", "render"),
        ("t.glb", "thumbnail"),
        ("u.glb", "render"),
    ] {
        let o = match command {
            "thumbnail" => kantele(&[command, &dir.s(scene), &dir.s("tex.png")]),
            _ => kantele(&[command, &dir.s(scene), "-o", &dir.s("tex.png")]),
        };
        let e = err_line(&o);
        assert!(
            e.contains("would overwrite") && e.contains("reads"),
            "{scene} {command}: {e}"
        );
        assert_eq!(
            std::fs::read(dir.path("tex.png")).unwrap(),
            b"not really a png",
            "{scene} {command}"
        );
        assert!(!dir.path("tex.png.json").exists());
    }
}

/// An `mtllib` naming a FIFO neither hangs the command's look at the inputs nor the load: the
/// library is not a regular file, so it is not read.
#[cfg(unix)]
#[test]
fn an_mtllib_fifo_does_not_hang() {
    let dir = TempDir::new("mtl-fifo");
    let status = Command::new("mkfifo")
        .arg(dir.path("fifo.mtl"))
        .status()
        .unwrap();
    assert!(status.success());
    std::fs::write(
        dir.path("f.obj"),
        "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let mut child = Command::new(BIN)
        .args([
            "render",
            &dir.s("f.obj"),
            "--size",
            "16x16",
            "-o",
            &dir.s("f.png"),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(30) {
            child.kill().unwrap();
            panic!("render hangs on an mtllib FIFO");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status}");
    assert!(dir.path("f.png").is_file());
}

/// A file camera whose near plane is too close for the depth buffer (`znear` 1e-7 before a
/// triangle 3 units ahead: every depth rounded to the far plane and the picture came out
/// empty, silently) has it raised, with a warning, and the triangle is drawn.
#[test]
fn a_near_plane_too_close_is_raised() {
    let dir = TempDir::new("znear");
    let positions: Vec<u8> = [-1.0f32, -1.0, -3.0, 1.0, -1.0, -3.0, 0.0, 1.0, -3.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    std::fs::write(dir.path("z.bin"), &positions).unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
"nodes":[{"mesh":0},{"camera":0}],
"cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":1e-7}}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"byteLength":36,"uri":"z.bin"}],
"bufferViews":[{"buffer":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[-1,-1,-3],"max":[1,1,-3]}]}"#;
    std::fs::write(dir.path("z.gltf"), gltf).unwrap();
    let o = kantele(&[
        "render",
        &dir.s("z.gltf"),
        "--size",
        "32x32",
        "-o",
        &dir.s("z.png"),
    ]);
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    assert!(
        crate::common::stderr(&o).contains("near plane"),
        "{}",
        crate::common::stderr(&o)
    );
    let picture = image::open(dir.path("z.png")).unwrap().to_rgba8();
    let background = picture.get_pixel(0, 0).0;
    assert_ne!(
        picture.get_pixel(16, 16).0,
        background,
        "the triangle is drawn"
    );
}

/// `--views` reads only a regular file: a device or a FIFO is refused in one line, without
/// reading or waiting.
#[cfg(unix)]
#[test]
fn views_from_a_device_or_fifo_are_refused() {
    let dir = TempDir::new("views-special");
    let status = Command::new("mkfifo")
        .arg(dir.path("views.json"))
        .status()
        .unwrap();
    assert!(status.success());
    for views in ["/dev/zero".to_string(), dir.s("views.json")] {
        let start = Instant::now();
        let o = kantele(&[
            "render",
            "--builtin",
            "cube",
            "--views",
            &views,
            "-o",
            &dir.s("v.png"),
        ]);
        let e = err_line(&o);
        assert!(e.contains("not a regular file"), "{views}: {e}");
        assert!(start.elapsed() < Duration::from_secs(20), "{views}");
        assert!(!dir.path("v.png").exists());
    }
}

#[cfg(unix)]
#[test]
fn interrupt_during_an_orbit_leaves_whole_sets_only() {
    let dir = TempDir::new("sigint");
    let child = Command::new(BIN)
        .args([
            "render",
            "--builtin",
            "teapot",
            "--size",
            "400x300",
            "--orbit",
            "400",
            "-o",
            &dir.s("{frame}.png"),
            "--depth",
            &dir.s("{frame}.pfm"),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the first finished frame, so the interrupt lands in the middle of the work.
    let start = Instant::now();
    while !dir.path("0000.png.json").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let files = dir.files();
    assert!(
        !files.is_empty() && files.len() < 3 * 400,
        "{} files",
        files.len()
    );
    for f in &files {
        assert!(!f.starts_with('.'), "temporary left behind: {f}");
        if let Some(stem) = f.strip_suffix(".png.json") {
            for part in [format!("{stem}.png"), format!("{stem}.pfm")] {
                assert!(files.contains(&part), "{f} without {part}");
            }
        } else {
            let stem = f.split('.').next().unwrap();
            assert!(
                files.contains(&format!("{stem}.png.json")),
                "{f} without its sidecar"
            );
        }
    }
}

#[test]
fn compare_out_refuses_colliding_names_before_rendering() {
    let dir = TempDir::new("compare-out");
    for sub in ["a", "b"] {
        std::fs::create_dir_all(dir.path(sub)).unwrap();
        std::fs::write(dir.path(&format!("{sub}/x.glb")), b"not a scene").unwrap();
    }
    let o = kantele(&[
        "compare",
        &dir.s("a/x.glb"),
        &dir.s("b/x.glb"),
        "--out",
        &dir.s("diff"),
    ]);
    assert!(err_line(&o).contains("more than once"));
    assert!(!dir.path("diff").exists(), "nothing made before the check");
}

#[test]
fn folders_patterns_and_skip_existing() {
    let dir = TempDir::new("batch");
    std::fs::create_dir_all(dir.path("in")).unwrap();
    for name in ["a", "b"] {
        std::fs::write(
            dir.path(&format!("in/{name}.obj")),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
    }
    std::fs::write(dir.path("in/notes.txt"), "not a scene").unwrap();
    let out = dir.s("out/{stem}.png");
    let render = |input: &str, extra: &[&str]| {
        let mut a = vec!["render", input, "--size", "16x16", "-o", &out];
        a.extend_from_slice(extra);
        kantele(&a)
    };
    let first = render(&dir.s("in"), &[]);
    ok(&first);
    // One line per image written, naming its files.
    let said = crate::common::stderr(&first);
    let wrote: Vec<&str> = said
        .lines()
        .filter(|l| l.starts_with("kantele: wrote "))
        .collect();
    assert_eq!(wrote.len(), 2, "{said}");
    let (a_png, a_json) = (dir.s("out/a.png"), dir.s("out/a.png.json"));
    assert!(
        wrote[0] == format!("kantele: wrote {a_png}, {a_json} (16x16)"),
        "{said}"
    );
    let listing = |d: &TempDir| {
        let mut v: Vec<String> = std::fs::read_dir(d.path("out"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        listing(&dir),
        ["a.png", "a.png.json", "b.png", "b.png.json"]
    );
    // --skip-existing leaves finished images alone and makes the missing ones.
    std::fs::remove_file(dir.path("out/b.png.json")).unwrap();
    let before = std::fs::metadata(dir.path("out/a.png"))
        .unwrap()
        .modified()
        .unwrap();
    std::thread::sleep(Duration::from_millis(20));
    let resumed = render(&dir.s("in/*.obj"), &["--skip-existing"]);
    ok(&resumed);
    let said = crate::common::stderr(&resumed);
    assert!(
        said.contains("kantele: wrote ") && said.contains("b.png.json"),
        "{said}"
    );
    assert!(
        said.contains("kantele: skipped 1 image(s) whose files exist"),
        "{said}"
    );
    let quiet = render(&dir.s("in/*.obj"), &["--skip-existing", "--quiet"]);
    ok(&quiet);
    assert_eq!(crate::common::stderr(&quiet), "", "--quiet prints nothing");
    let after = std::fs::metadata(dir.path("out/a.png"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(before, after, "a finished image was rendered again");
    assert!(dir.path("out/b.png.json").is_file());
    let none = render(&dir.s("in/*.gltf"), &[]);
    assert!(err_line(&none).contains("no scene file"));
}

#[test]
fn orbit_straight_to_an_animation() {
    use image::AnimationDecoder;
    let dir = TempDir::new("turntable");
    let o = kantele(&[
        "render",
        "--builtin",
        "teapot",
        "--size",
        "40x30",
        "--orbit",
        "6",
        "--background",
        "transparent",
        "-o",
        &dir.s("spin.gif"),
    ]);
    ok(&o);
    let file = std::io::BufReader::new(std::fs::File::open(dir.path("spin.gif")).unwrap());
    let frames = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    assert_eq!(frames.len(), 6);
    assert_ne!(frames[0].buffer(), frames[1].buffer(), "the views turn");
    ok(&kantele(&[
        "render",
        "--builtin",
        "cube",
        "--size",
        "20x20",
        "--orbit",
        "3",
        "-o",
        &dir.s("spin.apng"),
    ]));
    let png = image::codecs::png::PngDecoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.path("spin.apng")).unwrap(),
    ))
    .unwrap();
    let frames = png.apng().unwrap().into_frames().collect_frames().unwrap();
    assert_eq!(frames.len(), 3);
    assert_eq!(
        dir.files(),
        ["spin.apng", "spin.apng.json", "spin.gif", "spin.gif.json"]
    );
}

#[test]
fn turntable_sidecar_reproduces_every_frame() {
    use image::AnimationDecoder;
    let dir = TempDir::new("turntable-sidecar");
    ok(&kantele(&[
        "render",
        "--builtin",
        "teapot",
        "--size",
        "48x36",
        "--orbit",
        "4",
        "--elevation",
        "35",
        "-o",
        &dir.s("spin.apng"),
    ]));
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path("spin.apng.json")).unwrap()).unwrap();
    assert_eq!(side["frames"].as_u64(), Some(4));
    assert_eq!(side["views"].as_array().map(Vec::len), Some(4));
    let png = image::codecs::png::PngDecoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.path("spin.apng")).unwrap(),
    ))
    .unwrap();
    let frames = png.apng().unwrap().into_frames().collect_frames().unwrap();
    // Every frame's pose read back renders that frame again, pixel for pixel.
    ok(&kantele(&[
        "render",
        "--builtin",
        "teapot",
        "--views",
        &dir.s("spin.apng.json"),
        "-o",
        &dir.s("view{frame}.png"),
    ]));
    for (k, frame) in frames.iter().enumerate() {
        let view = image::open(dir.path(&format!("view{k:04}.png")))
            .unwrap()
            .into_rgba8();
        assert!(
            view == *frame.buffer(),
            "frame {k} differs from its pose rendered again"
        );
    }
    assert_ne!(frames[0].buffer(), frames[1].buffer(), "the views turn");
}
