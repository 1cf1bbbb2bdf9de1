//! Traversal strategies compared on small, large and thin triangles (coverage only: setup is
//! done once, the benchmark walks every tile the triangles touch and counts covered pixels), at
//! the scalar level and at the best instruction set of this CPU (named `strategy/isa`).
//!
//! `cargo bench -p kantele --bench traversal`

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec4;
use kantele::raster::bin::{TileBins, TileGrid};
use kantele::raster::{rasterize, Strategy};
use kantele::setup::{setup_triangle, CullMode, FrontFace, TriangleSetup, Viewport};
use kantele::simd::Isa;

const WIDTH: u32 = 1024;
const HEIGHT: u32 = 768;

/// `count` triangles of roughly `size × size · aspect` pixels scattered over the target.
fn triangles(count: usize, size: f32, aspect: f32) -> Vec<TriangleSetup> {
    let viewport = Viewport::new(WIDTH, HEIGHT);
    let mut seed = 7u64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 1_000_000) as f32 / 1_000_000.0
    };
    let to_ndc = |x: f32, y: f32| {
        Vec4::new(
            x / WIDTH as f32 * 2.0 - 1.0,
            1.0 - y / HEIGHT as f32 * 2.0,
            0.0,
            1.0,
        )
    };
    (0..count)
        .filter_map(|_| {
            let x = rand() * (WIDTH as f32 - size * aspect);
            let y = rand() * (HEIGHT as f32 - size);
            let (w, h) = (size * aspect, size);
            let a = to_ndc(x, y + h * rand());
            let b = to_ndc(x + w * rand(), y + h);
            let c = to_ndc(x + w, y + h * rand());
            setup_triangle(&viewport, [a, b, c], CullMode::None, FrontFace::Ccw).ok()
        })
        .collect()
}

fn bench_traversal(c: &mut Criterion) {
    let grid = TileGrid::new(WIDTH, HEIGHT);
    let cases = [
        ("small-8px", triangles(20_000, 8.0, 1.0)),
        ("medium-40px", triangles(2_000, 40.0, 1.0)),
        ("large-300px", triangles(100, 300.0, 1.0)),
        ("thin-200x6px", triangles(1_000, 6.0, 33.0)),
    ];
    for (name, tris) in cases {
        let mut bins = TileBins::default();
        bins.bin_triangles(&grid, &tris);
        let mut pixels = 0u64;
        for tile in 0..bins.tile_count() {
            for t in bins.tile(tile) {
                rasterize(
                    &tris[t.packed() as usize],
                    grid.tile_rect(tile),
                    Strategy::BoundingBox,
                    Isa::Scalar,
                    |_, _| pixels += 1,
                );
            }
        }
        let mut group = c.benchmark_group(format!("traversal/{name}"));
        group.throughput(Throughput::Elements(pixels));
        let mut levels = vec![Isa::Scalar];
        if Isa::best() != Isa::Scalar {
            levels.push(Isa::best());
        }
        let runs = Strategy::ALL
            .into_iter()
            .flat_map(|s| levels.iter().map(move |&isa| (s, isa)));
        for (strategy, isa) in runs {
            group.bench_with_input(
                BenchmarkId::from_parameter(format!("{strategy}/{isa}")),
                &strategy,
                |b, &strategy| {
                    b.iter(|| {
                        let mut covered = 0u64;
                        for tile in 0..bins.tile_count() {
                            let rect = grid.tile_rect(tile);
                            for t in bins.tile(tile) {
                                rasterize(
                                    &tris[t.packed() as usize],
                                    rect,
                                    strategy,
                                    isa,
                                    |x, _| covered += x as u64 & 1 | 1,
                                );
                            }
                        }
                        black_box(covered)
                    })
                },
            );
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = bench_traversal
}
criterion_main!(benches);
