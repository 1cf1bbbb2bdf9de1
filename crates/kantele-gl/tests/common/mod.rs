//! Helpers shared by the tests that set Kantele against OpenGL.
#![allow(dead_code)]

use std::sync::Arc;

use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::scene::Scene;
use kantele_gl::GlBackend;

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
    let scene = Arc::new(scene);
    let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
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
