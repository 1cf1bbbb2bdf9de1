//! Bodies of the `raster` and `clip` fuzz targets (`fuzz/` at the repository root), as plain
//! functions so that a stable test can replay the corpus without a nightly toolchain.
//!
//! Each function takes arbitrary bytes, builds its input from them deterministically, and
//! panics exactly when it finds a defect; every input is valid, so the fuzzer never wastes runs
//! on rejected data.

use std::cell::RefCell;

use glam::Vec4;

use crate::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions};
use crate::raster::{rasterize, Strategy};
use crate::rop::{BlendMode, DepthFunc};
use kantele_lanes::Isa;
use kantele_rules::fixed::{GUARD_BAND_PIXELS, SUBPIXEL_ONE};
use kantele_rules::geometry::clip::{
    classify, ClipPolygon, ClipTest, ClipVertex, GuardBand, W_MIN,
};
use kantele_rules::reference::reference_covers;
use kantele_rules::setup::{setup_triangle, CullMode, FrontFace, Viewport};
use kantele_rules::MAX_VARYINGS;

/// Reads the fuzzer's bytes as a stream of numbers; past the end it yields zeros.
struct ByteReader<'a> {
    data: &'a [u8],
}

impl ByteReader<'_> {
    fn u8(&mut self) -> u8 {
        match self.data.split_first() {
            Some((&b, rest)) => {
                self.data = rest;
                b
            }
            None => 0,
        }
    }

    fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    /// A number in `lo..=hi`.
    fn in_range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.u32() as u64 % (hi - lo + 1) as u64) as i64
    }
}

thread_local! {
    /// One renderer per thread, reused across inputs (starting a thread pool per input would
    /// dominate the fuzzer's time).
    static RENDERER: RefCell<Option<Renderer>> = const { RefCell::new(None) };
}

/// Runs `f` with a one-thread renderer resized to `width × height`.
fn with_renderer<T>(
    width: u32,
    height: u32,
    strategy: Strategy,
    f: impl FnOnce(&mut Renderer) -> T,
) -> T {
    RENDERER.with(|cell| {
        let mut slot = cell.borrow_mut();
        let renderer = slot.get_or_insert_with(|| {
            let options = RendererOptions {
                threads: Some(1),
                ..RendererOptions::default()
            };
            Renderer::new(width, height, options).expect("a small target can be allocated")
        });
        renderer
            .resize(width, height)
            .expect("a small target can be allocated");
        renderer.set_strategy(strategy);
        f(renderer)
    })
}

/// Draws one triangle list with a shader that adds 1 to red per fragment; returns the count
/// of fragments of each pixel.
fn count_fragments(renderer: &mut Renderer, vertices: &[Vec4], state: RenderState) -> Vec<u32> {
    let shader = FnShader::new(
        1,
        |p: &Vec4, out: &mut [f32]| {
            out[0] = p.z;
            *p
        },
        |_: &Fragment<'_>| Some(Vec4::new(1.0, 0.0, 0.0, 0.0)),
    );
    let indices: Vec<u32> = (0..vertices.len() as u32).collect();
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, vertices, Indices::U32(&indices), state)
        .expect("a draw of a few triangles is accepted");
    frame.end();
    renderer
        .framebuffer()
        .read_color()
        .iter()
        .map(|c| c[0] as u32)
        .collect()
}

/// Render state that counts coverage: no culling, no depth test, additive blending.
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

/// The `raster` target: a triangle with fixed-point window coordinates anywhere in the guard
/// band (degenerate ones included) on a target of 8–256 pixels a side. Every traversal
/// strategy, and the whole pipeline, must cover exactly the pixels
/// [`reference_covers`](kantele_rules::reference::reference_covers) does, each once.
///
/// Layout: width and height exponents, a coordinate mode (near the target / half-pixel lattice
/// / whole guard band / collinear), a strategy for the pipeline run, then six coordinates.
pub fn raster(data: &[u8]) {
    let mut input = ByteReader { data };
    // Powers of two keep the clip-space → window mapping exact in f32 (see `to_clip` below).
    let width = 8u32 << (input.u8() % 6);
    let height = 8u32 << (input.u8() % 6);
    let mode = input.u8() % 4;
    let strategy = Strategy::ALL[input.u8() as usize % Strategy::ALL.len()];
    let guard = (GUARD_BAND_PIXELS as i64) * SUBPIXEL_ONE;
    let (w_sub, h_sub) = (width as i64 * SUBPIXEL_ONE, height as i64 * SUBPIXEL_ONE);
    let mut v = [(0i64, 0i64); 3];
    for p in &mut v {
        *p = match mode {
            // Within a target's width of the target.
            0 | 3 => (
                input.in_range(-w_sub, 2 * w_sub),
                input.in_range(-h_sub, 2 * h_sub),
            ),
            // On the half-pixel lattice: edges through pixel centres, the fill rule decides.
            1 => (
                input.in_range(-2 * width as i64, 4 * width as i64) * (SUBPIXEL_ONE / 2),
                input.in_range(-2 * height as i64, 4 * height as i64) * (SUBPIXEL_ONE / 2),
            ),
            // Anywhere in the guard band.
            _ => (
                input.in_range(-guard, w_sub + guard),
                input.in_range(-guard, h_sub + guard),
            ),
        };
    }
    if mode == 3 {
        // Collinear (or coincident) third vertex: zero area, must cover nothing.
        let t = input.u8() as i64 % 5 - 2;
        v[2] = (
            (v[0].0 + t * (v[1].0 - v[0].0)).clamp(-guard, w_sub + guard),
            (v[0].1 + t * (v[1].1 - v[0].1)).clamp(-guard, h_sub + guard),
        );
    }
    // Clip-space positions whose window coordinates are exactly v / 256: with half-sizes that
    // are powers of two and |numerators| < 2^24 every f32 step below is exact.
    let to_clip = |(x, y): (i64, i64)| {
        let (hw, hh) = (w_sub / 2, h_sub / 2);
        Vec4::new(
            (x - hw) as f32 / hw as f32,
            (hh - y) as f32 / hh as f32,
            0.0,
            1.0,
        )
    };
    let clip = [to_clip(v[0]), to_clip(v[1]), to_clip(v[2])];
    let viewport = Viewport::new(width, height);
    let expected: Vec<bool> = (0..height as i64)
        .flat_map(|y| (0..width as i64).map(move |x| (x, y)))
        .map(|(x, y)| reference_covers(v, x, y))
        .collect();
    match setup_triangle(&viewport, clip, CullMode::None, FrontFace::Ccw) {
        Ok(tri) => {
            // Every strategy at the best level, and the lane-wide ones at the scalar level too.
            let runs = Strategy::ALL
                .into_iter()
                .map(|s| (s, Isa::best()))
                .chain([Strategy::Block, Strategy::Bisector].map(|s| (s, Isa::Scalar)));
            for (strategy, isa) in runs {
                let mut counts = vec![0u32; expected.len()];
                rasterize(&tri, viewport.rect(), strategy, isa, |x, y| {
                    assert!(
                        (0..width as i32).contains(&x) && (0..height as i32).contains(&y),
                        "{strategy}: pixel ({x}, {y}) outside the {width}×{height} target for {v:?}"
                    );
                    counts[(y as u32 * width + x as u32) as usize] += 1;
                });
                let name = format!("{strategy} at {isa}");
                compare_coverage(&counts, &expected, width, &v, &name);
            }
        }
        Err(_) => {
            if let Some(i) = expected.iter().position(|&c| c) {
                panic!(
                    "setup rejected {v:?} on {width}×{height} but the reference covers pixel ({}, {})",
                    i as u32 % width,
                    i as u32 / width
                );
            }
        }
    }
    // The whole pipeline (classification, binning into tiles, block masks, blending).
    let counts = with_renderer(width, height, strategy, |renderer| {
        count_fragments(renderer, &clip, counting_state())
    });
    compare_coverage(&counts, &expected, width, &v, "pipeline");
}

fn compare_coverage(counts: &[u32], expected: &[bool], width: u32, v: &[(i64, i64); 3], who: &str) {
    for (i, (&n, &e)) in counts.iter().zip(expected).enumerate() {
        assert_eq!(
            n,
            e as u32,
            "{who}: pixel ({}, {}) drawn {n} times, reference {e}, triangle {v:?} (sub-pixel units)",
            i as u32 % width,
            i as u32 / width
        );
    }
}

/// Values that a bit pattern rarely hits but clipping must survive.
const SPECIAL: [f32; 12] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    0.0,
    -0.0,
    f32::MAX,
    -f32::MAX,
    f32::MIN_POSITIVE,
    1e-40,
    1e-30,
    1e30,
    1.0,
];

/// A float from the input: a special value, a raw bit pattern (every exponent), or a tame
/// value ±(0..1000) scaled by a power of ten from 1e-30 to 1e30.
fn read_float(input: &mut ByteReader<'_>) -> f32 {
    let tag = input.u8();
    match tag % 4 {
        0 => SPECIAL[tag as usize / 4 % SPECIAL.len()],
        1 => f32::from_bits(input.u32()),
        _ => {
            let mantissa = (input.u32() as i32 % 1_000_000) as f32 / 1000.0;
            mantissa * 10f32.powi(tag as i32 / 4 % 61 - 30)
        }
    }
}

/// The `clip` target: a clip-space triangle with huge, tiny, zero, infinite or NaN
/// coordinates, given directly or as eye-space points through a perspective projection with
/// any near/far. Clipping must never emit a vertex with `w ≤ 0` or a non-finite coordinate,
/// and drawing it must not panic; a triangle inside the guard band must be drawn unclipped.
pub fn clip(data: &[u8]) {
    let mut input = ByteReader { data };
    let width = 1 + input.u8() as u32 % 64;
    let height = 1 + input.u8() as u32 % 64;
    let perspective = input.u8() % 2 == 1;
    let strategy = Strategy::ALL[input.u8() as usize % Strategy::ALL.len()];
    let mut p = [Vec4::ZERO; 3];
    if perspective {
        let near = read_float(&mut input).abs();
        let far = read_float(&mut input).abs();
        let fov = 0.1 + (input.u8() as f32 / 255.0) * 3.0;
        let projection =
            glam::Mat4::perspective_rh_gl(fov, width as f32 / height as f32, near, far);
        for v in &mut p {
            let eye = Vec4::new(
                read_float(&mut input),
                read_float(&mut input),
                read_float(&mut input),
                1.0,
            );
            *v = projection * eye;
        }
    } else {
        for v in &mut p {
            *v = Vec4::new(
                read_float(&mut input),
                read_float(&mut input),
                read_float(&mut input),
                read_float(&mut input),
            );
        }
    }
    let guard = GuardBand::new(width, height);
    let vertex = |pos_clip: Vec4| ClipVertex {
        pos_clip,
        varyings: [pos_clip.z; MAX_VARYINGS],
    };
    match classify(p, &guard) {
        ClipTest::Reject => {}
        ClipTest::Accept => {
            for v in p {
                assert!(v.w >= W_MIN, "accepted a vertex with w = {} in {p:?}", v.w);
            }
        }
        ClipTest::Clip => {
            let mut polygon = ClipPolygon::triangle(vertex(p[0]), vertex(p[1]), vertex(p[2]));
            polygon.clip(&guard, 1);
            for v in polygon.vertices() {
                assert!(
                    v.pos_clip.is_finite() && v.pos_clip.w >= W_MIN,
                    "clipping {p:?} emitted {:?}",
                    v.pos_clip
                );
            }
        }
    }
    let state = RenderState {
        cull: CullMode::None,
        ..RenderState::default()
    };
    with_renderer(width, height, strategy, |renderer| {
        count_fragments(renderer, &p, state);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_and_empty_inputs_are_valid() {
        raster(&[]);
        clip(&[]);
        raster(&[5, 5, 1, 0, 1, 2, 3]);
        clip(&[63, 63, 1, 2]);
    }
}
