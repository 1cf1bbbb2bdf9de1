//! Coverage properties: shared edges are drawn exactly once, nothing outside a triangle is
//! drawn, and every strategy / thread count gives the same result.

use glam::{Vec2, Vec4};
use kantele::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions};
use kantele::raster::Strategy;
use kantele::reference::reference_covers;
use kantele::rop::{BlendMode, DepthFunc};
use kantele::setup::CullMode;
use kantele::simd::Isa;
use proptest::prelude::*;

/// A shader that adds 1 to the red channel per fragment: the result counts coverage.
fn counting_shader() -> impl kantele::pipeline::Shader<Vertex = Vec2> {
    FnShader::new(
        0,
        |p: &Vec2, _: &mut [f32]| Vec4::new(p.x, p.y, 0.0, 1.0),
        |_: &Fragment<'_>| Some(Vec4::new(1.0, 0.0, 0.0, 0.0)),
    )
}

fn counting_state() -> RenderState {
    RenderState {
        cull: CullMode::None,
        depth_test: false,
        depth_write: false,
        depth_func: DepthFunc::Always,
        blend: BlendMode::Additive,
        sort_back_to_front: false,
        ..RenderState::default()
    }
}

/// Renders `triangles` (NDC positions) with the counting shader; returns per-pixel counts.
fn coverage_counts(
    size: (u32, u32),
    vertices: &[Vec2],
    indices: &[u32],
    options: RendererOptions,
) -> Vec<u32> {
    let mut renderer = Renderer::new(size.0, size.1, options).expect("renderer");
    let shader = counting_shader();
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, vertices, Indices::U32(indices), counting_state())
        .expect("draw");
    frame.end();
    renderer
        .framebuffer()
        .read_color()
        .iter()
        .map(|c| c[0] as u32)
        .collect()
}

/// Pixel (x, y) centre in NDC for a `w × h` target.
fn centre_ndc(x: u32, y: u32, w: u32, h: u32) -> Vec2 {
    Vec2::new(
        (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
    )
}

/// A jittered grid of `n × n` cells over the square [lo, hi]², split along random diagonals.
fn jittered_grid(n: usize, lo: f32, hi: f32, seed: u64) -> (Vec<Vec2>, Vec<u32>) {
    let mut state = seed | 1;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 1_000_000) as f32 / 1_000_000.0
    };
    let cell = (hi - lo) / n as f32;
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let mut p = Vec2::new(lo + i as f32 * cell, lo + j as f32 * cell);
            if i > 0 && i < n && j > 0 && j < n {
                // At most ±0.15 cell per vertex: every quad stays convex (a corner would have
                // to move ~0.7 cell to cross the opposite diagonal), so both splits are valid.
                p += (Vec2::new(rand(), rand()) - 0.5) * cell * 0.3;
            }
            vertices.push(p);
        }
    }
    let mut indices = Vec::new();
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if rand() < 0.5 {
                indices.extend([a, b, c, a, c, d]);
            } else {
                indices.extend([a, b, d, b, c, d]);
            }
        }
    }
    (vertices, indices)
}

#[test]
fn jittered_grids_cover_every_pixel_of_the_square_exactly_once() {
    // The square's sides are pixel-aligned between centres, so "inside" is unambiguous.
    let (w, h) = (96, 80);
    for seed in 1..6 {
        let (vertices, indices) = jittered_grid(7, -0.5, 0.5, seed);
        let counts = coverage_counts((w, h), &vertices, &indices, RendererOptions::default());
        for y in 0..h {
            for x in 0..w {
                let c = centre_ndc(x, y, w, h);
                let inside = c.x.abs() < 0.5 && c.y.abs() < 0.5;
                assert_eq!(
                    counts[(y * w + x) as usize],
                    inside as u32,
                    "seed {seed} pixel ({x}, {y})"
                );
            }
        }
    }
}

#[test]
fn a_fan_covers_its_polygon_exactly_once() {
    // A 40-gon fan around an off-centre point, both windings; its rim is far from pixel
    // centres' ambiguity only where it must be: we check exact-once inside, zero far outside.
    let (w, h) = (128, 128);
    let centre = Vec2::new(0.1, -0.05);
    let mut vertices = vec![centre];
    for k in 0..40 {
        let angle = k as f32 / 40.0 * std::f32::consts::TAU;
        vertices.push(Vec2::new(angle.cos(), angle.sin()) * 0.8);
    }
    let mut indices = Vec::new();
    for k in 0..40u32 {
        indices.extend([0, 1 + k, 1 + (k + 1) % 40]);
    }
    let counts = coverage_counts((w, h), &vertices, &indices, RendererOptions::default());
    let mut covered = 0;
    for y in 0..h {
        for x in 0..w {
            let r = centre_ndc(x, y, w, h).length();
            let n = counts[(y * w + x) as usize];
            assert!(n <= 1, "pixel ({x}, {y}) drawn {n} times");
            // The polygon's inscribed circle has radius 0.8·cos(π/40); pixels well inside must be
            // covered, pixels outside the circumscribed one must not.
            if r < 0.8 * (std::f32::consts::PI / 40.0).cos() - 0.02 {
                assert_eq!(n, 1, "pixel ({x}, {y}) inside the fan not covered");
            }
            if r > 0.81 {
                assert_eq!(n, 0, "pixel ({x}, {y}) outside the fan covered");
            }
            covered += n;
        }
    }
    assert!(covered > 0);
}

fn snap_ndc(p: Vec2, w: u32, h: u32) -> (i64, i64) {
    let half_w = w as f32 * 0.5;
    let half_h = h as f32 * 0.5;
    let x = p.x * half_w + half_w;
    let y = -p.y * half_h + half_h;
    (
        (x * 256.0).round_ties_even() as i64,
        (y * 256.0).round_ties_even() as i64,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    #[test]
    fn coverage_equals_the_exact_reference(
        lattice in prop::array::uniform6(-40i32..170),
        fine in prop::array::uniform6(-1.4f32..1.4),
        on_lattice in any::<bool>(),
        strategy in prop::sample::select(Strategy::ALL.to_vec()),
    ) {
        // Half the cases put vertices on a half-pixel lattice, so edges run exactly through
        // pixel centres and the fill rule decides; the rest are arbitrary.
        let (w, h) = (64u32, 64u32);
        let c: [f32; 6] = if on_lattice {
            lattice.map(|k| k as f32 / 64.0 - 1.0) // k half-pixels → NDC, exact in f32
        } else {
            fine
        };
        let vertices = vec![Vec2::new(c[0], c[1]), Vec2::new(c[2], c[3]), Vec2::new(c[4], c[5])];
        let options = RendererOptions { threads: Some(1), strategy, ..RendererOptions::default() };
        let counts = coverage_counts((w, h), &vertices, &[0, 1, 2], options);
        let snapped = [snap_ndc(vertices[0], w, h), snap_ndc(vertices[1], w, h), snap_ndc(vertices[2], w, h)];
        for y in 0..h {
            for x in 0..w {
                let expected = reference_covers(snapped, x as i64, y as i64) as u32;
                prop_assert_eq!(counts[(y * w + x) as usize], expected, "pixel ({}, {})", x, y);
            }
        }
    }

    #[test]
    fn random_triangulations_share_edges_exactly(seed in 1u64..u64::MAX, n in 1usize..9) {
        let (w, h) = (64u32, 64u32);
        // Square [-0.75, 0.75]² has edges at NDC ±0.75 = pixel 8 and 56: between centres.
        let (vertices, indices) = jittered_grid(n, -0.75, 0.75, seed);
        let counts = coverage_counts((w, h), &vertices, &indices, RendererOptions::default());
        for y in 0..h {
            for x in 0..w {
                let inside = (8..56).contains(&x) && (8..56).contains(&y);
                prop_assert_eq!(counts[(y * w + x) as usize], inside as u32);
            }
        }
    }
}

#[test]
fn every_strategy_and_thread_count_renders_the_same_image() {
    // Many overlapping, depth-tested, blended triangles with varying colours.
    let mut seed = 99u64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 1_000_000) as f32 / 1_000_000.0
    };
    let vertices: Vec<[f32; 7]> = (0..600)
        .map(|_| {
            [
                rand() * 3.0 - 1.5,
                rand() * 3.0 - 1.5,
                rand() * 2.0 - 1.0,
                rand(),
                rand(),
                rand(),
                rand(),
            ]
        })
        .collect();
    let indices: Vec<u32> = (0..600).collect();
    let shader = FnShader::new(
        4,
        |v: &[f32; 7], out: &mut [f32]| {
            out.copy_from_slice(&v[3..7]);
            Vec4::new(v[0], v[1], v[2], 1.0 + v[2] * 0.3)
        },
        |f: &Fragment<'_>| {
            let v = f.varyings();
            Some(Vec4::new(v[0], v[1], v[2], v[3]))
        },
    );
    let render = |threads: usize, strategy: Strategy, isa: Isa| {
        let mut renderer = Renderer::new(
            301,
            203,
            RendererOptions {
                threads: Some(threads),
                strategy,
                isa: Some(isa),
                ..RendererOptions::default()
            },
        )
        .expect("renderer");
        let mut frame = renderer.begin_frame(Some(Vec4::new(0.1, 0.2, 0.3, 1.0)), Some(1.0));
        let opaque = RenderState {
            cull: CullMode::None,
            ..RenderState::default()
        };
        let blended = RenderState {
            blend: BlendMode::Alpha,
            depth_write: false,
            ..opaque
        };
        frame
            .draw(&shader, &vertices, Indices::U32(&indices[..300]), opaque)
            .expect("draw");
        frame
            .draw(&shader, &vertices, Indices::U32(&indices[300..]), blended)
            .expect("draw");
        frame.end();
        (
            renderer.framebuffer().read_color(),
            renderer.framebuffer().read_depth(),
        )
    };
    let reference = render(1, Strategy::BoundingBox, Isa::Scalar);
    let covered = reference.1.iter().filter(|d| **d < 1.0).count();
    assert!(
        covered > 10_000,
        "scene should cover much of the target ({covered})"
    );
    let isas: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.is_supported()).collect();
    assert!(
        isas.len() > 1 || cfg!(not(target_arch = "x86_64")),
        "{isas:?}"
    );
    for isa in isas {
        for threads in [1, 2, 3, 8] {
            for strategy in Strategy::ALL {
                let image = render(threads, strategy, isa);
                assert!(
                    image == reference,
                    "{strategy} with {threads} threads on {isa} differs"
                );
            }
        }
    }
}
