//! The lane types per instruction set: one small kernel (three edge functions, an inside test,
//! a perspective-correct attribute with a divide, a masked store) over 1024 × 1024 pixels,
//! eight at a time, run through `kantele::simd::dispatch` at every level this CPU supports.
//!
//! `cargo bench -p kantele --bench simd`

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kantele::simd::{dispatch, F32x8, I32x8, Isa, LaneKernel, Lanes, Mask8};

const SIZE: usize = 1024;

/// Edge function `a·x + b·y + c` and the value `w` (clip-space w) it weights.
#[derive(Clone, Copy)]
struct Edge {
    a: f32,
    b: f32,
    c: f32,
    w: f32,
    u: f32,
}

/// One triangle covering about half the target.
const EDGES: [Edge; 3] = [
    Edge {
        a: 1.0,
        b: 0.0,
        c: -10.0,
        w: 1.0,
        u: 0.0,
    },
    Edge {
        a: 0.0,
        b: 1.0,
        c: -20.0,
        w: 2.5,
        u: 1.0,
    },
    Edge {
        a: -1.0,
        b: -1.0,
        c: 1000.0,
        w: 4.0,
        u: 0.5,
    },
];

/// Evaluates the edges at every pixel centre, writes the perspective-correct attribute
/// `Σ eᵢ·uᵢ/wᵢ / Σ eᵢ/wᵢ` where all three edges are non-negative, and counts those pixels.
struct EdgeAndDivide<'a> {
    out: &'a mut [f32],
}

impl LaneKernel for EdgeAndDivide<'_> {
    type Output = u32;

    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> u32 {
        let zero = lanes.splat_f32(0.0);
        let step = lanes.lane_index().to_f32() + lanes.splat_f32(0.5);
        let mut covered = 0;
        for (y, row) in self.out.chunks_exact_mut(SIZE).enumerate() {
            let py = lanes.splat_f32(y as f32 + 0.5);
            for (block, pixels) in row.chunks_exact_mut(8).enumerate() {
                let px = lanes.splat_f32((block * 8) as f32) + step;
                // (Not `EDGES.map(..)`: a closure handed to a std function may be compiled
                // outside the AVX2 entry point, see the `kantele::simd` docs.)
                let edge = |k: usize| {
                    lanes.splat_f32(EDGES[k].a) * px
                        + lanes.splat_f32(EDGES[k].b) * py
                        + lanes.splat_f32(EDGES[k].c)
                };
                let e = [edge(0), edge(1), edge(2)];
                let inside = e[0]
                    .simd_ge(zero)
                    .and(e[1].simd_ge(zero))
                    .and(e[2].simd_ge(zero));
                if inside.none() {
                    continue;
                }
                let mut one_over_w = zero;
                let mut u_over_w = zero;
                for (value, edge) in e.iter().zip(EDGES) {
                    let weight = *value / lanes.splat_f32(edge.w);
                    one_over_w = one_over_w + weight;
                    u_over_w = u_over_w + weight * lanes.splat_f32(edge.u);
                }
                (u_over_w / one_over_w).store_masked(inside, pixels);
                covered += inside.count();
            }
        }
        covered
    }
}

fn bench_simd(c: &mut Criterion) {
    let mut group = c.benchmark_group("edge_and_divide_1M");
    group.throughput(Throughput::Elements((SIZE * SIZE) as u64));
    group.sample_size(20);
    let mut out = vec![0.0f32; SIZE * SIZE];
    let reference = dispatch(Isa::Scalar, EdgeAndDivide { out: &mut out });
    let reference_bits: Vec<u32> = out.iter().map(|v| v.to_bits()).collect();
    for isa in Isa::supported() {
        // Every level must compute the same pixels, bit for bit.
        out.fill(0.0);
        assert_eq!(dispatch(isa, EdgeAndDivide { out: &mut out }), reference);
        assert!(out
            .iter()
            .map(|v| v.to_bits())
            .eq(reference_bits.iter().copied()));
        group.bench_function(BenchmarkId::from_parameter(isa), |b| {
            b.iter(|| {
                black_box(dispatch(
                    isa,
                    EdgeAndDivide {
                        out: black_box(&mut out),
                    },
                ))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_simd);
criterion_main!(benches);
