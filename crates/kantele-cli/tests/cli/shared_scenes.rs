//! Every reference scene of `$KANTELE_SHARED/scenes`, by property, and reference files patched
//! to be broken.

use crate::common::{kantele, ok, stderr, TempDir};
use crate::{assert_clean_failure, read_pfm, shared_scenes};

/// Linear luminance of an sRGB pixel.
fn luminance(p: &image::Rgba<u8>) -> f32 {
    let lin = |c: u8| kantele::color::srgb_to_linear(c as f32 / 255.0);
    0.2126 * lin(p.0[0]) + 0.7152 * lin(p.0[1]) + 0.0722 * lin(p.0[2])
}

/// Renders every `.glb` in `$KANTELE_SHARED/scenes` in one run of the binary and checks each
/// image's size against INDEX.md, then properties that a wrong renderer would break.
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

/// The box of a picture's non-transparent pixels: (left, top, right, bottom), exclusive ends.
fn opaque_box(img: &image::RgbaImage) -> Option<(u32, u32, u32, u32)> {
    let mut found: Option<(u32, u32, u32, u32)> = None;
    for (x, y, p) in img.enumerate_pixels() {
        if p.0[3] > 0 {
            found = Some(match found {
                None => (x, y, x + 1, y + 1),
                Some((l, t, r, b)) => (l.min(x), t.min(y), r.max(x + 1), b.max(y + 1)),
            });
        }
    }
    found
}

/// A thumbnail of every reference scene fills its picture with the model: the model spans at
/// least 85% of the picture along its tighter direction (the framing aims at 92%) and is
/// centred within 3 pixels both ways.
#[test]
fn thumbnails_fill_and_centre_every_reference_scene() {
    let Some(scenes) = shared_scenes() else {
        return;
    };
    let dir = TempDir::new("thumbs");
    let mut names: Vec<_> = std::fs::read_dir(&scenes)
        .expect("scenes folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    names.sort();
    assert!(names.len() >= 18, "{} scenes", names.len());
    let size = 256u32;
    for scene in &names {
        let stem = scene.file_stem().unwrap().to_string_lossy().into_owned();
        let out = dir.path(&format!("{stem}.png"));
        let o = kantele(&[
            "thumbnail",
            &scene.to_string_lossy(),
            &out.to_string_lossy(),
            "--size",
            &size.to_string(),
        ]);
        ok(&o);
        let img = image::open(&out).unwrap().to_rgba8();
        let (l, t, r, b) = opaque_box(&img).unwrap_or_else(|| panic!("{stem}: empty"));
        let span = (r - l).max(b - t) as f64 / size as f64;
        assert!(
            span >= 0.85,
            "{stem}: the model spans {span:.3} of the picture"
        );
        let centre = size as f64 / 2.0;
        let (cx, cy) = ((l + r) as f64 / 2.0, (t + b) as f64 / 2.0);
        assert!(
            (cx - centre).abs() <= 3.0 && (cy - centre).abs() <= 3.0,
            "{stem}: centred at ({cx}, {cy}), box {l},{t}..{r},{b}"
        );
    }
}
