//! Multisampled pictures of Kantele against OpenGL's (4×, the count every GL 3.3 driver
//! offers): the built-in and reference scenes agree within stated tolerances, edges are
//! antialiased by both, and a count the driver lacks is refused with a clear error.
//! Skips (with a message) when EGL/OpenGL or the scenes are unavailable.

use std::sync::Arc;

use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::multisample::SampleCount;
use kantele::RenderError;
use kantele_testkit::compare::{compare, edge_mask, Comparison};

use crate::common::{
    gl_or_skip, interior_allowance, is_textured_scene, print_comparison, reference_scene_files,
    render, render_both_at, INTERIOR_BOUND,
};

/// Pixels with a value strictly between two others in 8-bit sRGB: partly covered edges.
fn partial_pixels(image: &FrameImage) -> usize {
    let clear = image.color[0];
    image
        .color
        .iter()
        .filter(|c| {
            let g = c[1];
            *c != &clear && g > 0.0 && g < 1.0 && g != clear[1]
        })
        .count()
}

/// Mean colour difference (8-bit, over every pixel) allowed at 4×.
const MEAN_BOUND: f64 = 1.0;

fn check(name: &str, cpu: &FrameImage, gl: &FrameImage, ids: &FrameImage, textured: bool) {
    let edges = edge_mask(ids);
    let c: Comparison = compare(cpu, gl, Some(&edges), INTERIOR_BOUND).expect("same size");
    print_comparison("4x ", name, &c);
    // Depth is per pixel in both (the 1× rule), so coverage agrees as at 1×.
    assert!(c.coverage_mismatch_fraction() <= 0.001, "{name}: coverage");
    assert!(
        c.mean_color_diff < MEAN_BOUND,
        "{name}: mean colour {}",
        c.mean_color_diff
    );
    let allowed = interior_allowance(c.pixels, textured);
    assert!(
        c.interior_over_bound <= allowed,
        "{name}: {} interior pixels over {INTERIOR_BOUND}",
        c.interior_over_bound
    );
    assert!(
        c.max_depth_diff <= 2e-3,
        "{name}: depth {}",
        c.max_depth_diff
    );
}

#[test]
fn builtin_scenes_agree_with_opengl_at_4x() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    for (name, _) in kantele_scene::builtin_scenes() {
        let scene = kantele_scene::builtin_scene(name).expect("builtin").scene;
        let (cpu, gl_image, ids) = render_both_at(scene, &mut gl, SampleCount::X4);
        // The cube, the ground, the normal-mapped floor of pbr-lights, the checker of
        // pbr-glass and the woven floor of pbr-sheen are textured (driver LOD choices differ,
        // as at 1×; GL's derivatives of the normal map's tangent frame are differences over
        // 2 × 2 pixels, the CPU's are exact).
        let textured = matches!(
            *name,
            "cube" | "ground" | "pbr-lights" | "pbr-glass" | "pbr-sheen"
        );
        check(name, &cpu, &gl_image, &ids, textured);
        // Both antialias: partly covered edge pixels exist in both, in similar numbers.
        let (a, b) = (partial_pixels(&cpu), partial_pixels(&gl_image));
        assert!(a > 0 && b > 0, "{name}: partial pixels cpu {a} gl {b}");
        let ratio = a as f64 / b as f64;
        assert!(
            (0.9..=1.1).contains(&ratio),
            "{name}: partial pixels cpu {a} gl {b}"
        );
        if *name == "pixel-edges" {
            // Flat colours and edges through pixel centres: the samples' coverage decides
            // alone, so the same positions and fill rule give the same picture.
            let c = compare(&cpu, &gl_image, None, 0).expect("same size");
            assert_eq!(
                c.max_color_diff, 0,
                "4x sample coverage differs from OpenGL's"
            );
        }
    }
}

#[test]
fn every_reference_scene_agrees_with_opengl_at_4x() {
    let Some(dir) = kantele_testkit::shared_dir("scenes") else {
        return;
    };
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    for (name, path) in &reference_scene_files(&dir) {
        let scene = kantele_scene::load_scene(path).expect("load").scene;
        let (cpu, gl_image, ids) = render_both_at(scene, &mut gl, SampleCount::X4);
        let textured = is_textured_scene(name);
        check(name, &cpu, &gl_image, &ids, textured);
    }
}

#[test]
fn gl_depth_ids_and_normals_at_4x_equal_its_1x_ones() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let scene = Arc::new(
        kantele_scene::builtin_scene("teapot")
            .expect("builtin")
            .scene,
    );
    gl.load(scene.clone()).expect("load");
    for pass in [Pass::Color, Pass::Ids, Pass::Normals] {
        let view = FrameView {
            pass,
            ..FrameView::of_scene(&scene)
        };
        gl.set_samples(SampleCount::X1).expect("1x");
        let one = render(&mut gl, &view);
        gl.set_samples(SampleCount::X4).expect("4x");
        let four = render(&mut gl, &view);
        assert_eq!(four.depth, one.depth, "{pass:?} depth");
        if pass == Pass::Color {
            assert!(four.color != one.color, "colour is antialiased");
        } else {
            assert_eq!(four.color, one.color, "{pass:?}");
        }
    }
}

#[test]
fn a_sample_count_the_driver_lacks_is_refused_clearly() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let max = gl.max_samples();
    eprintln!("GL_MAX_SAMPLES = {max} ({})", gl.gl_renderer());
    assert!(max >= 4, "GL 3.3 requires 4 samples");
    match gl.set_samples(SampleCount::X8) {
        Ok(()) => assert!(max >= 8),
        Err(RenderError::Unsupported { message, .. }) => {
            assert!(max < 8);
            assert!(message.contains("GL_MAX_SAMPLES"), "{message}");
            assert_eq!(gl.samples(), SampleCount::X1, "the count is unchanged");
        }
        Err(e) => panic!("unexpected error {e}"),
    }
}
