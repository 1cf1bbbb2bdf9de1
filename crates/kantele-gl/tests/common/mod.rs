//! Helpers shared by the tests that set Kantele against OpenGL.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::multisample::SampleCount;
use kantele::scene::Scene;
use kantele_gl::GlBackend;
use kantele_testkit::compare::Comparison;

/// Largest colour difference (8-bit) allowed away from triangle edges.
pub const INTERIOR_BOUND: u8 = 3;

/// One frame of `backend`.
pub fn render(backend: &mut dyn Backend, view: &FrameView) -> FrameImage {
    backend.render(view).expect("render");
    backend.read_frame().expect("read")
}

/// The OpenGL backend, or `None` (with a message) where EGL/OpenGL is unavailable — a failure
/// instead when `KANTELE_REQUIRE` names `gl`.
pub fn gl_or_skip() -> Option<GlBackend> {
    match GlBackend::new() {
        Ok(gl) => Some(gl),
        Err(e) => {
            kantele_testkit::skip("gl", format!("OpenGL unavailable: {e}"));
            None
        }
    }
}

/// Renders a scene with both backends; returns (cpu, gl, cpu ids).
pub fn render_both(scene: Scene, gl: &mut GlBackend) -> (FrameImage, FrameImage, FrameImage) {
    render_both_at(scene, gl, SampleCount::X1)
}

/// The scene at `samples` with both backends: (cpu, gl, cpu ids at 1×).
pub fn render_both_at(
    scene: Scene,
    gl: &mut GlBackend,
    samples: SampleCount,
) -> (FrameImage, FrameImage, FrameImage) {
    let scene = Arc::new(scene);
    let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
    cpu.set_samples(samples).expect("cpu samples");
    gl.set_samples(samples).expect("gl samples");
    cpu.load(scene.clone()).expect("cpu load");
    gl.load(scene.clone()).expect("gl load");
    let view = FrameView::of_scene(&scene);
    let a = render(&mut cpu, &view);
    let b = render(gl, &view);
    let ids = render(
        &mut cpu,
        &FrameView {
            pass: Pass::Ids,
            ..view
        },
    );
    (a, b, ids)
}

/// The reference scenes (`.glb`) in `dir`, sorted, with their names (file stems); at least one.
pub fn reference_scene_files(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("read scenes")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "glb"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty());
    paths
        .into_iter()
        .map(|path| {
            let name = path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            (name, path)
        })
        .collect()
}

/// Whether a reference scene is textured (driver LOD choices differ on its interior).
pub fn is_textured_scene(name: &str) -> bool {
    name.contains("textured") || name == "near-clip"
}

/// Interior pixels allowed over [`INTERIOR_BOUND`]: texture level-of-detail choices differ
/// between drivers (`docs/rendering-rules.md` gives up to 0.6% of pixels between llvmpipe and
/// NVIDIA); untextured scenes must agree everywhere but on edges.
pub fn interior_allowance(pixels: usize, textured: bool) -> usize {
    if textured {
        pixels / 100
    } else {
        pixels / 2000
    }
}

/// Prints one comparison line: `label` (e.g. `4x`, or empty), the scene and the measures.
pub fn print_comparison(label: &str, name: &str, c: &Comparison) {
    eprintln!(
        "{label}{name:28} coverage {:.4}%  mean {:.3}  max {:3}  interior>{INTERIOR_BOUND}: {:6} ({:.3}%)  depth max {:.2e}",
        100.0 * c.coverage_mismatch_fraction(),
        c.mean_color_diff,
        c.max_color_diff,
        c.interior_over_bound,
        100.0 * c.interior_over_bound as f64 / c.pixels as f64,
        c.max_depth_diff,
    );
}
