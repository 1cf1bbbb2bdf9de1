//! Coverage properties: shared edges are drawn exactly once, nothing outside a triangle is
//! drawn, and every strategy / thread count gives the same result.

use glam::Vec2;
use kantele::pipeline::RendererOptions;
use kantele::raster::Strategy;
use kantele::reference::reference_covers;
use kantele::simd::Isa;
use proptest::prelude::*;

use crate::common::{busy_frame, jittered_grid, red_channel};

/// Renders `triangles` (NDC positions) with the counting shader; returns per-pixel counts.
fn coverage_counts(
    size: (u32, u32),
    vertices: &[Vec2],
    indices: &[u32],
    options: RendererOptions,
) -> Vec<u32> {
    red_channel(size, vertices, indices, options)
        .iter()
        .map(|&c| c as u32)
        .collect()
}

/// Pixel (x, y) centre in NDC for a `w × h` target.
fn centre_ndc(x: u32, y: u32, w: u32, h: u32) -> Vec2 {
    Vec2::new(
        (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
    )
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
    let render = |threads: usize, strategy: Strategy, isa: Isa| {
        busy_frame(
            (301, 203),
            RendererOptions {
                threads: Some(threads),
                strategy,
                isa: Some(isa),
                ..RendererOptions::default()
            },
        )
    };
    let reference = render(1, Strategy::BoundingBox, Isa::Scalar);
    let covered = reference.1.iter().filter(|d| **d < 1.0).count();
    assert!(
        covered > 10_000,
        "scene should cover much of the target ({covered})"
    );
    let isas: Vec<Isa> = Isa::supported().collect();
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
