//! Set-up shared by the coverage and multisampling tests: a shader and state that count
//! coverage in the red channel, a jittered shared-edge mesh, and a busy frame of overlapping
//! opaque and blended triangles.
#![allow(dead_code)]

use glam::{Vec2, Vec4};
use kantele::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions};
use kantele::rop::{BlendMode, DepthFunc};
use kantele::setup::CullMode;

/// A xorshift generator of values in `[0, 1)` (in steps of 1e-6), reproducible from `seed`.
pub fn xorshift(seed: u64) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % 1_000_000) as f32 / 1_000_000.0
    }
}

/// A shader that adds 1 to the red channel per fragment: the result counts coverage.
pub fn counting_shader() -> impl kantele::pipeline::Shader<Vertex = Vec2> {
    FnShader::new(
        0,
        |p: &Vec2, _: &mut [f32]| Vec4::new(p.x, p.y, 0.0, 1.0),
        |_: &Fragment<'_>| Some(Vec4::new(1.0, 0.0, 0.0, 0.0)),
    )
}

/// No culling, no depth, additive blending: every fragment adds to what is there.
pub fn counting_state() -> RenderState {
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

/// Red channel of `vertices` (NDC positions) drawn with the counting shader: per-pixel
/// coverage counts (at 4× or 8×, the resolved share of covered samples).
pub fn red_channel(
    size: (u32, u32),
    vertices: &[Vec2],
    indices: &[u32],
    options: RendererOptions,
) -> Vec<f32> {
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
        .map(|c| c[0])
        .collect()
}

/// A jittered grid of `n × n` cells over the square [lo, hi]², split along random diagonals.
pub fn jittered_grid(n: usize, lo: f32, hi: f32, seed: u64) -> (Vec<Vec2>, Vec<u32>) {
    let mut rand = xorshift(seed | 1);
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

/// 300 opaque, depth-tested triangles, then 300 alpha-blended ones without depth writes, with
/// random positions, depths and colours, at `size`: the frame's colour and depth.
pub fn busy_frame(size: (u32, u32), options: RendererOptions) -> (Vec<[f32; 4]>, Vec<f32>) {
    let mut rand = xorshift(99);
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
    let mut renderer = Renderer::new(size.0, size.1, options).expect("renderer");
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
}
