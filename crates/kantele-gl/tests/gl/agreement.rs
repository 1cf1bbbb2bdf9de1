//! Kantele against OpenGL on every reference scene in `$KANTELE_SHARED/scenes`: the yardstick.
//!
//! Both render the same `Scene` by the same rules (`docs/rendering-rules.md`) into float
//! targets; the pictures are compared as 8-bit sRGB. Skips (with a message) when EGL/OpenGL or
//! the scenes are unavailable.

use std::path::Path;

use kantele_testkit::compare::{compare, edge_mask, Comparison};

use crate::common::{
    gl_or_skip, interior_allowance, is_textured_scene, print_comparison, reference_scene_files,
    render_both, INTERIOR_BOUND,
};

#[test]
fn builtin_scenes_agree_with_opengl() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    for (name, _) in kantele_scene::builtin_scenes() {
        let scene = kantele_scene::builtin_scene(name).expect("builtin").scene;
        let (a, b, _) = render_both(scene, &mut gl);
        let c = compare(&a, &b, None, 0).expect("same size");
        eprintln!(
            "{name:12} coverage {} px, mean {:.3}, max {}",
            c.coverage_mismatches, c.mean_color_diff, c.max_color_diff
        );
        assert!(c.coverage_mismatch_fraction() <= 0.001, "{name}: coverage");
        assert!(
            c.mean_color_diff < 1.0,
            "{name}: mean colour {}",
            c.mean_color_diff
        );
        if *name == "pixel-edges" {
            // Every edge passes through pixel centres: both apply the same top-left rule.
            assert_eq!(c.coverage_mismatches, 0, "fill rule differs from OpenGL's");
            assert_eq!(c.max_color_diff, 0);
        }
    }
}

/// Draws mirrored by their model matrix (negative determinant) keep their front faces in both
/// backends: the teapot mirrored in x is drawn by both exactly as the unmirrored one's mirror.
#[test]
fn mirrored_draws_agree_with_opengl() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let mut scene = kantele_scene::builtin_scene("teapot")
        .expect("builtin")
        .scene;
    for draw in &mut scene.draws {
        draw.model = glam::Mat4::from_scale(glam::Vec3::new(-1.0, 1.0, 1.0)) * draw.model;
    }
    let (a, b, _) = render_both(scene, &mut gl);
    let c = compare(&a, &b, None, 0).expect("same size");
    assert!(
        a.depth.iter().filter(|d| **d < 1.0).count() > 10_000,
        "mirrored teapot not drawn"
    );
    assert!(
        c.coverage_mismatch_fraction() <= 0.001,
        "coverage {}",
        c.coverage_mismatches
    );
    assert!(c.mean_color_diff < 0.5, "mean colour {}", c.mean_color_diff);
}

#[test]
fn every_reference_scene_agrees_with_opengl() {
    let Some(dir) = kantele_testkit::shared_dir("scenes") else {
        return;
    };
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let mut failures = Vec::new();
    for (name, path) in &reference_scene_files(&dir) {
        let scene = kantele_scene::load_scene(path).expect("load").scene;
        let (cpu, gl_image, ids) = render_both(scene, &mut gl);
        let edges = edge_mask(&ids);
        let c: Comparison =
            compare(&cpu, &gl_image, Some(&edges), INTERIOR_BOUND).expect("same size");
        let textured = is_textured_scene(name);
        print_comparison("", name, &c);
        // Coverage: edges (almost) exactly through pixel centres are the only expected
        // differences. Investigated on thesis-t2-cubes (2 of 910 000 pixels): a vertex whose
        // window coordinate × 256 lies 0.005 from a rounding boundary, below one f32 ulp there;
        // exact f64 arithmetic snaps it as llvmpipe does, Kantele's f32 transform (model-view-
        // projection premultiplied) the other way. Float noise, not a rule difference: on
        // `pixel-edges`, where the fill rule decides, the two agree exactly.
        let mut problems = Vec::new();
        if c.coverage_mismatch_fraction() > 0.001 {
            problems.push("coverage");
        }
        if c.mean_color_diff >= 1.0 {
            problems.push("mean colour");
        }
        // Texture level-of-detail choices differ between drivers: see `interior_allowance`.
        let allowed = interior_allowance(c.pixels, textured);
        if c.interior_over_bound > allowed {
            problems.push("interior colour");
        }
        // Kantele interpolates depth from the snapped vertex positions (as hardware does);
        // llvmpipe sets up its planes from the unsnapped ones. On sub-pixel triangles (the
        // far head) a 1/512-pixel shift moves depth by up to ~1e-3; elsewhere it is ~1e-6.
        if c.max_depth_diff > 2e-3 || c.mean_depth_diff > 1e-5 {
            problems.push("depth");
        }
        if !problems.is_empty() {
            let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
            std::fs::create_dir_all(&out).expect("output dir");
            for (suffix, data) in [
                ("cpu", cpu.to_rgba8(true)),
                ("gl", gl_image.to_rgba8(true)),
                ("difference", c.difference_image.clone()),
            ] {
                let file = out.join(format!("{name}-{suffix}.png"));
                image::save_buffer(&file, &data, cpu.width, cpu.height, image::ColorType::Rgba8)
                    .expect("write");
            }
            failures.push(format!("{name}: {}", problems.join(", ")));
        }
    }
    assert!(
        failures.is_empty(),
        "disagreements (images in target/test-output): {failures:#?}"
    );
}
