//! The whole pipeline on triangles of one size at a time: a sweep of triangle sizes × traversal
//! strategies × instruction sets. Throughput is in pixels (GPixels/s at large sizes); the
//! benchmark names carry the triangle count, so MTris/s = triangles / time (the small sizes are
//! triangle-bound).
//!
//! `cargo bench -p kantele --bench fill`

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::{Vec2, Vec4};
use kantele::pipeline::{
    Fragment, FragmentLanes, Indices, RenderState, Renderer, RendererOptions, ShadedLanes, Shader,
};
use kantele::raster::Strategy;
use kantele::setup::CullMode;
use kantele::simd::{Isa, Lanes};

const SIZE: u32 = 512;

/// Gouraud colour, lane-wide.
struct ColorShader;

impl Shader for ColorShader {
    type Vertex = (Vec2, Vec4);
    fn varying_count(&self) -> usize {
        4
    }
    fn vertex(&self, v: &(Vec2, Vec4), out: &mut [f32]) -> Vec4 {
        out.copy_from_slice(&v.1.to_array());
        Vec4::new(v.0.x, v.0.y, 0.5, 1.0)
    }
    fn fragment(&self, f: &Fragment<'_>) -> Option<Vec4> {
        let v = f.varyings();
        Some(Vec4::new(v[0], v[1], v[2], v[3]))
    }
    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        ShadedLanes {
            color: [f.varying(0), f.varying(1), f.varying(2), f.varying(3)],
            keep: f.lanes.mask_all(true),
        }
    }
}

/// `count` right triangles with legs of `legs` pixels spread over the target.
fn triangles(count: usize, legs: f32) -> Vec<(Vec2, Vec4)> {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 100_000) as f32 / 100_000.0
    };
    let to_ndc = |p: f32| p / SIZE as f32 * 2.0 - 1.0;
    let mut out = Vec::with_capacity(3 * count);
    for _ in 0..count {
        let x = rand() * (SIZE as f32 - legs);
        let y = rand() * (SIZE as f32 - legs);
        let c = Vec4::new(rand(), rand(), rand(), 1.0);
        out.push((Vec2::new(to_ndc(x), to_ndc(y)), c));
        out.push((Vec2::new(to_ndc(x + legs), to_ndc(y)), c));
        out.push((Vec2::new(to_ndc(x), to_ndc(y + legs)), c));
    }
    out
}

fn bench_fill(c: &mut Criterion) {
    let isas: Vec<Isa> = Isa::supported().collect();
    for (legs, count) in [(2.0, 40_000), (8.0, 20_000), (32.0, 4_000), (128.0, 400)] {
        let vertices = triangles(count, legs);
        let pixels = (count as f64 * legs as f64 * legs as f64 / 2.0) as u64;
        let mut group = c.benchmark_group(format!("fill/{legs}px-legs/{count}-triangles"));
        group.throughput(Throughput::Elements(pixels));
        for strategy in [Strategy::Incremental, Strategy::Block, Strategy::Bisector] {
            for &isa in &isas {
                let options = RendererOptions {
                    threads: Some(1),
                    strategy,
                    isa: Some(isa),
                    ..RendererOptions::default()
                };
                let mut renderer = Renderer::new(SIZE, SIZE, options).expect("renderer");
                let state = RenderState {
                    cull: CullMode::None,
                    depth_test: false,
                    ..RenderState::default()
                };
                group.bench_with_input(
                    BenchmarkId::new(strategy.name(), isa.name()),
                    &isa,
                    |b, _| {
                        b.iter(|| {
                            let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
                            frame
                                .draw(&ColorShader, &vertices, Indices::None, state)
                                .expect("draw");
                            black_box(frame.end().fragments_shaded)
                        })
                    },
                );
            }
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_millis(700)).warm_up_time(std::time::Duration::from_millis(200));
    targets = bench_fill
}
criterion_main!(benches);
