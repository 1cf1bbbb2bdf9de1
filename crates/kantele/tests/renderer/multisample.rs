//! Multisampling (4× and 8×): edges get intermediate values, every sample is covered exactly
//! once by a shared-edge mesh, the picture is identical for every instruction set, strategy and
//! thread count, and the per-pixel outputs (depth, ids, normals) equal those of a 1× render.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use kantele::backend::{Backend, FrameView, Pass};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::multisample::SampleCount;
use kantele::pipeline::{Renderer, RendererOptions};
use kantele::raster::Strategy;
use kantele::scene::{Camera, Draw, Material, Mesh, Scene};
use kantele::simd::Isa;
use kantele::RenderError;

use crate::common::{busy_frame, jittered_grid, red_channel};

/// The size of the busy frame.
const SIZE: (u32, u32) = (181, 133);

/// Red channel of `vertices` drawn with the counting shader at `samples` per pixel.
fn red(size: (u32, u32), vertices: &[Vec2], indices: &[u32], samples: SampleCount) -> Vec<f32> {
    let options = RendererOptions {
        samples,
        ..RendererOptions::default()
    };
    red_channel(size, vertices, indices, options)
}

#[test]
fn a_triangle_edge_gets_intermediate_values_only_when_multisampled() {
    let tri = [
        Vec2::new(-0.9, -0.8),
        Vec2::new(0.85, -0.3),
        Vec2::new(-0.2, 0.9),
    ];
    let one = red((64, 48), &tri, &[0, 1, 2], SampleCount::X1);
    assert!(one.iter().all(|&v| v == 0.0 || v == 1.0));
    for samples in [SampleCount::X4, SampleCount::X8] {
        let n = samples.count() as f32;
        let pixels = red((64, 48), &tri, &[0, 1, 2], samples);
        let partial: Vec<f32> = pixels
            .iter()
            .copied()
            .filter(|&v| v > 0.0 && v < 1.0)
            .collect();
        // Every slanted edge crosses dozens of pixels partly.
        assert!(partial.len() > 60, "{samples}x: {} partial", partial.len());
        // Each is a whole number of samples.
        assert!(partial.iter().all(|v| (v * n).fract() == 0.0), "{samples}x");
        // The interior is untouched, so the covered amount stays the same (within the edges).
        let area = |p: &[f32]| p.iter().sum::<f32>();
        assert!((area(&pixels) - area(&one)).abs() < 0.05 * area(&one));
    }
}

#[test]
fn shared_edges_cover_every_sample_exactly_once() {
    // The square's sides lie on pixel boundaries (NDC ±0.5 on 96 × 80 = pixels 24/72, 20/60),
    // so every sample of an inside pixel is inside: a resolved 1 inside, 0 outside, and any
    // sample drawn twice or missed would show as another value.
    let (w, h) = (96u32, 80u32);
    for samples in [SampleCount::X4, SampleCount::X8] {
        for seed in 1..4 {
            let (vertices, indices) = jittered_grid(6, -0.5, 0.5, seed);
            let pixels = red((w, h), &vertices, &indices, samples);
            for y in 0..h {
                for x in 0..w {
                    let inside = (24..72).contains(&x) && (20..60).contains(&y);
                    assert_eq!(
                        pixels[(y * w + x) as usize],
                        inside as u32 as f32,
                        "{samples}x seed {seed} pixel ({x}, {y})"
                    );
                }
            }
        }
    }
}

#[test]
fn multisampled_pictures_are_identical_for_every_isa_strategy_and_thread_count() {
    let options = |threads: usize, strategy: Strategy, isa: Isa| RendererOptions {
        threads: Some(threads),
        strategy,
        isa: Some(isa),
        samples: SampleCount::X4,
        ..RendererOptions::default()
    };
    let reference = busy_frame(SIZE, options(1, Strategy::BoundingBox, Isa::Scalar));
    let single = busy_frame(
        SIZE,
        RendererOptions {
            samples: SampleCount::X1,
            ..options(1, Strategy::BoundingBox, Isa::Scalar)
        },
    );
    assert!(reference.0 != single.0, "4x must change the picture");
    let isas: Vec<Isa> = Isa::supported().collect();
    for isa in isas {
        for threads in [1, 3] {
            for strategy in Strategy::ALL {
                let image = busy_frame(SIZE, options(threads, strategy, isa));
                assert!(
                    image == reference,
                    "4x: {strategy} with {threads} threads on {isa} differs"
                );
            }
        }
    }
    // 8× once per instruction set.
    let eight = |isa: Isa| {
        busy_frame(
            SIZE,
            RendererOptions {
                samples: SampleCount::X8,
                ..options(2, Strategy::Bisector, isa)
            },
        )
    };
    let eight_reference = eight(Isa::Scalar);
    for isa in Isa::ALL.into_iter().filter(|i| i.is_supported()) {
        assert!(eight(isa) == eight_reference, "8x on {isa} differs");
    }
}

#[test]
fn multisampled_depth_equals_the_single_sample_depth() {
    let (_, depth_1x) = busy_frame(SIZE, RendererOptions::default());
    let covered = depth_1x.iter().filter(|d| **d < 1.0).count();
    assert!(covered > 5_000, "{covered}");
    for samples in [SampleCount::X4, SampleCount::X8] {
        let (_, depth) = busy_frame(
            SIZE,
            RendererOptions {
                samples,
                ..RendererOptions::default()
            },
        );
        let same = depth
            .iter()
            .zip(&depth_1x)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{samples}x depth differs from 1x");
    }
}

/// Two overlapping quads at different depths, one tilted, both double-sided.
fn two_quads() -> Arc<Scene> {
    let quad = |z: f32, tilt: f32| Mesh {
        positions: vec![
            Vec3::new(-0.6, -0.5, z),
            Vec3::new(0.5, -0.6 + tilt, z - tilt),
            Vec3::new(0.6, 0.5, z + tilt),
            Vec3::new(-0.5, 0.6, z),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    };
    let draw = |mesh: usize, model: Mat4| Draw {
        mesh,
        model,
        node_name: String::new(),
        node_index: mesh,
    };
    Arc::new(Scene {
        meshes: vec![quad(0.0, 0.0), quad(0.2, 0.3)],
        materials: vec![Material::default()],
        draws: vec![
            draw(0, Mat4::IDENTITY),
            draw(
                1,
                Mat4::from_rotation_z(0.4) * Mat4::from_scale(Vec3::splat(0.7)),
            ),
        ],
        camera: Camera::framing(Vec3::ZERO, 1.0, Vec3::Z, 1.0),
        resolution: (83, 67),
        ..Scene::default()
    })
}

#[test]
fn ids_normals_and_depth_of_a_4x_render_equal_the_1x_ones() {
    let scene = two_quads();
    let render = |samples: SampleCount, pass: Pass| {
        let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
        cpu.set_samples(samples).expect("samples");
        cpu.load(scene.clone()).expect("load");
        let view = FrameView {
            pass,
            ..FrameView::of_scene(&scene)
        };
        cpu.render(&view).expect("render");
        cpu.read_frame().expect("read")
    };
    for pass in [Pass::Color, Pass::Ids, Pass::Normals] {
        let one = render(SampleCount::X1, pass);
        let four = render(SampleCount::X4, pass);
        assert!(one.depth.iter().filter(|d| **d < 1.0).count() > 1000);
        assert_eq!(four.depth, one.depth, "{pass:?} depth");
        if pass == Pass::Color {
            assert!(four.color != one.color, "the colour pass is antialiased");
        } else {
            assert_eq!(four.color, one.color, "{pass:?} values");
        }
    }
}

#[test]
fn an_oversized_multisampled_target_is_refused_before_allocating() {
    let options = RendererOptions {
        samples: SampleCount::X8,
        ..RendererOptions::default()
    };
    match Renderer::new(16_384, 16_384, options) {
        Err(RenderError::Unsupported { message, .. }) => {
            assert!(message.contains("8 samples per pixel"), "{message}")
        }
        Err(e) => panic!("unexpected error {e}"),
        Ok(_) => panic!("an 8x 16384 x 16384 target must be refused"),
    }
    let mut renderer = Renderer::new(16, 16, RendererOptions::default()).expect("small");
    renderer.resize(1024, 1).expect("a strip is fine");
    assert!(renderer.set_samples(SampleCount::X8).is_ok());
    assert!(renderer.resize(16_384, 16_384).is_err());
}
