//! Reference images of the seed documents' scenes (see `kantele_testkit::demo`).
//!
//! A missing or different reference fails; `KANTELE_BLESS=1 cargo test -p kantele --test
//! reference` rewrites them. On failure the actual image and a difference image are written to
//! `target/test-output/`.

use std::path::{Path, PathBuf};

use kantele::pipeline::{Renderer, RendererOptions};
use kantele::stats::FrameStats;
use kantele::RenderError;

/// Largest allowed 8-bit difference in any channel. The pipeline is deterministic on one
/// machine; 1 level absorbs `powf` (sRGB encode) and libm differences between platforms.
const MAX_CHANNEL_DIFF: u8 = 1;

fn check(name: &str, render: fn(&mut Renderer) -> Result<FrameStats, RenderError>) {
    let mut renderer = Renderer::new(400, 300, RendererOptions::default()).expect("renderer");
    let stats = render(&mut renderer).expect("render");
    assert!(stats.fragments_shaded > 10_000, "{name}: {stats:?}");
    let fb = renderer.framebuffer();
    let actual = fb.read_rgba8(true);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference");
    let path = dir.join(format!("{name}.png"));
    if std::env::var_os("KANTELE_BLESS").is_some() {
        image::save_buffer(
            &path,
            &actual,
            fb.width(),
            fb.height(),
            image::ColorType::Rgba8,
        )
        .expect("bless");
        return;
    }
    let out_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    let fail = |why: String| -> ! {
        std::fs::create_dir_all(&out_dir).expect("output dir");
        let actual_path = out_dir.join(format!("{name}-actual.png"));
        image::save_buffer(
            &actual_path,
            &actual,
            fb.width(),
            fb.height(),
            image::ColorType::Rgba8,
        )
        .expect("write");
        panic!("{name}: {why}; actual image in {}", actual_path.display());
    };
    let reference = match image::open(&path) {
        Ok(img) => img.to_rgba8(),
        Err(e) => fail(format!(
            "reference {} missing or unreadable ({e}); run with KANTELE_BLESS=1",
            path.display()
        )),
    };
    if reference.dimensions() != (fb.width(), fb.height()) {
        fail(format!(
            "size {:?} differs from the reference",
            reference.dimensions()
        ));
    }
    let mut worst = 0u8;
    let mut differing = 0usize;
    let diff: Vec<u8> = reference
        .as_raw()
        .chunks_exact(4)
        .zip(actual.chunks_exact(4))
        .flat_map(|(r, a)| {
            let d = (0..4).map(|i| r[i].abs_diff(a[i])).max().unwrap_or(0);
            worst = worst.max(d);
            differing += (d > 0) as usize;
            let v = d.saturating_mul(32);
            [v, v, v, 255]
        })
        .collect();
    if worst > MAX_CHANNEL_DIFF {
        std::fs::create_dir_all(&out_dir).expect("output dir");
        let diff_path = out_dir.join(format!("{name}-difference.png"));
        image::save_buffer(
            &diff_path,
            &diff,
            fb.width(),
            fb.height(),
            image::ColorType::Rgba8,
        )
        .expect("write");
        fail(format!(
            "{differing} pixels differ, worst by {worst} (allowed {MAX_CHANNEL_DIFF}); difference in {}",
            diff_path.display()
        ));
    }
}

#[test]
fn thesis_textured_cube_matches_its_reference() {
    check("thesis-cube", kantele_testkit::demo::render_thesis_cube);
}

#[test]
fn exercise_blended_scene_matches_its_reference() {
    check("exercise", kantele_testkit::demo::render_exercise);
}
