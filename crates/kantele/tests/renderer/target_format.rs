//! The 8-bit sRGB target against the `f32` one: the same 8-bit picture for frames that start
//! with a clear (every instruction set, thread count, 1× and multisampled), across frames that
//! keep the previous picture, partial clears, and a quarter of the colour memory.

use glam::{Vec3, Vec4};
use kantele::multisample::SampleCount;
use kantele::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions};
use kantele::rop::{target_bytes, BlendMode, TargetFormat};
use kantele::setup::CullMode;
use kantele::simd::Isa;

/// Vertex: position in clip space (w = 1) and a linear RGBA colour.
type Vtx = (Vec3, Vec4);

fn colour_shader() -> impl kantele::pipeline::Shader<Vertex = Vtx> {
    FnShader::new(
        4,
        |v: &Vtx, out: &mut [f32]| {
            out.copy_from_slice(&v.1.to_array());
            v.0.extend(1.0)
        },
        |f: &Fragment<'_>| {
            Some(Vec4::new(
                f.varying(0),
                f.varying(1),
                f.varying(2),
                f.varying(3),
            ))
        },
    )
}

/// Triangles overlapping each other at several depths. With `overbright`, colours vary
/// smoothly and red runs from −0.1 to 1.1, so clamping is exercised. Otherwise each triangle
/// has one colour in [0, 1], so that no value past [0, 1] reaches the target, not even at a
/// multisampled edge pixel, whose colour is extrapolated to the pixel centre outside the
/// triangle.
fn triangles(seed: u32, overbright: bool) -> Vec<Vtx> {
    let mut x = seed.wrapping_mul(2_654_435_761) | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        (x % 10_000) as f32 / 10_000.0
    };
    let mut color = Vec4::ZERO;
    (0..60)
        .map(|k| {
            let position = Vec3::new(next() * 2.4 - 1.2, next() * 2.4 - 1.2, next() * 1.8 - 0.9);
            if overbright || k % 3 == 0 {
                let red = match overbright {
                    true => next() * 1.2 - 0.1,
                    false => next(),
                };
                color = Vec4::new(red, next(), next() * next(), next());
            }
            (position, color)
        })
        .collect()
}

fn state(blend: BlendMode) -> RenderState {
    RenderState {
        cull: CullMode::None,
        blend,
        ..RenderState::default()
    }
}

/// Draws `frames` (each: whether it clears colour, the blend mode, the seed of its
/// triangles, whether they are overbright) into a `w × h` target and returns the 8-bit sRGB picture and the depth bits.
fn draw(
    target: TargetFormat,
    isa: Isa,
    threads: usize,
    samples: SampleCount,
    frames: &[(bool, BlendMode, u32, bool)],
) -> (Vec<u8>, Vec<u32>) {
    let (w, h) = (150, 90);
    let options = RendererOptions {
        threads: Some(threads),
        isa: Some(isa),
        samples,
        target,
        ..RendererOptions::default()
    };
    let mut renderer = Renderer::new(w, h, options).expect("renderer");
    assert_eq!(renderer.target_format(), target);
    let shader = colour_shader();
    for &(clear_color, blend, seed, overbright) in frames {
        let vertices = triangles(seed, overbright);
        let clear = clear_color.then_some(Vec4::new(0.2, 0.05, 0.6, 1.0));
        let mut frame = renderer.begin_frame(clear, Some(1.0));
        frame
            .draw(&shader, &vertices, Indices::None, state(blend))
            .expect("draw");
        frame.end();
    }
    let fb = renderer.framebuffer();
    let depth = fb.read_depth().iter().map(|d| d.to_bits()).collect();
    (fb.read_rgba8(true), depth)
}

/// One frame from a clear, opaque and then blended: the 8-bit target reads back the `f32`
/// target's 8-bit picture byte for byte, on every instruction set, at 1 and 3 threads. At 4×
/// the resolve averages 8-bit samples: within one step where colours lie in [0, 1] (an 8-bit
/// sample holds no value outside [0, 1], which the `f32` resolve averages in, as OpenGL's
/// 8-bit targets clamp each sample).
#[test]
fn srgb8_target_reads_back_the_f32_targets_picture() {
    for samples in [SampleCount::X1, SampleCount::X4] {
        for blend in [BlendMode::Replace, BlendMode::Alpha, BlendMode::Additive] {
            if samples.is_multisampled() && blend == BlendMode::Additive {
                continue; // sums past 1: clamped per sample in 8 bits, averaged in f32
            }
            let frames = [(true, blend, 7, !samples.is_multisampled())];
            let reference = draw(
                TargetFormat::LinearF32,
                Isa::selected(),
                2,
                samples,
                &frames,
            );
            assert!(
                reference.0.chunks_exact(4).any(|p| p != &reference.0[..4]),
                "the picture is not one colour"
            );
            for (k, isa) in Isa::supported().enumerate() {
                let threads = [1, 3][k % 2];
                let got = draw(TargetFormat::Srgb8, isa, threads, samples, &frames);
                if samples.is_multisampled() {
                    // Resolved from 8-bit samples: within one step of the f32 resolve.
                    assert_eq!(got.1, reference.1, "{isa} {blend:?} {samples}: depth");
                    let worst = got.0.iter().zip(&reference.0).map(|(a, b)| a.abs_diff(*b));
                    assert!(worst.max() <= Some(1), "{isa} {blend:?} {samples}");
                } else {
                    assert!(
                        got == reference,
                        "{isa} {blend:?} on {threads} threads differs"
                    );
                }
            }
        }
    }
}

/// Frames that keep the previous picture start from its 8-bit values: drawing opaquely over
/// it gives the `f32` target's bytes exactly (decoding and encoding an 8-bit value gives it
/// back); blending over it stays within one step where colours lie in [0, 1].
#[test]
fn srgb8_target_keeps_its_picture_between_frames() {
    let opaque = [
        (true, BlendMode::Replace, 1, true),
        (false, BlendMode::Replace, 2, true),
    ];
    let blended = [
        (true, BlendMode::Replace, 1, false),
        (false, BlendMode::Alpha, 3, false),
    ];
    for isa in [Isa::Scalar, Isa::selected()] {
        let f32_target = draw(TargetFormat::LinearF32, isa, 2, SampleCount::X1, &opaque);
        let srgb8 = draw(TargetFormat::Srgb8, isa, 2, SampleCount::X1, &opaque);
        assert!(srgb8 == f32_target, "{isa}: opaque second frame");
        let f32_target = draw(TargetFormat::LinearF32, isa, 2, SampleCount::X1, &blended);
        let srgb8 = draw(TargetFormat::Srgb8, isa, 2, SampleCount::X1, &blended);
        assert_eq!(srgb8.1, f32_target.1, "{isa}: depth");
        let steps: Vec<u8> = srgb8
            .0
            .iter()
            .zip(&f32_target.0)
            .map(|(a, b)| a.abs_diff(*b))
            .collect();
        assert!(steps.iter().all(|&d| d <= 1), "{isa}: blended second frame");
    }
}

/// Clearing only colour or only depth on an 8-bit target keeps the other, as on `f32`.
#[test]
fn srgb8_target_partial_clears_match_the_f32_target() {
    let picture = |target: TargetFormat| {
        let options = RendererOptions {
            target,
            threads: Some(2),
            ..RendererOptions::default()
        };
        let mut renderer = Renderer::new(100, 70, options).expect("renderer");
        let shader = colour_shader();
        let vertices = triangles(5, true);
        let mut frame = renderer.begin_frame(Some(Vec4::ONE), Some(0.5));
        frame
            .draw(&shader, &vertices, Indices::None, state(BlendMode::Replace))
            .expect("draw");
        frame.end();
        let mut reads = Vec::new();
        for (color, depth) in [
            (Some(Vec4::new(0.0, 0.5, 0.25, 1.0)), None),
            (None, Some(0.75)),
        ] {
            renderer.begin_frame(color, depth).end();
            let fb = renderer.framebuffer();
            let depth: Vec<u32> = fb.read_depth().iter().map(|d| d.to_bits()).collect();
            reads.push((fb.read_rgba8(true), depth));
        }
        reads
    };
    assert!(picture(TargetFormat::Srgb8) == picture(TargetFormat::LinearF32));
}

/// The 8-bit target's tiles take 8 bytes a pixel against the `f32` target's 20; a worker's
/// `f32` tile is added per thread.
#[test]
fn srgb8_target_takes_a_fraction_of_the_memory() {
    let f32_bytes = target_bytes(4096, 4096, SampleCount::X1, TargetFormat::LinearF32, 16);
    let srgb8_bytes = target_bytes(4096, 4096, SampleCount::X1, TargetFormat::Srgb8, 16);
    assert_eq!(f32_bytes, 4096 * 4096 * 20);
    assert_eq!(srgb8_bytes, 4096 * 4096 * 8 + 16 * 64 * 64 * 20);
    let f32_4x = target_bytes(4096, 4096, SampleCount::X4, TargetFormat::LinearF32, 16);
    let srgb8_4x = target_bytes(4096, 4096, SampleCount::X4, TargetFormat::Srgb8, 16);
    assert!(srgb8_4x * 2 < f32_4x, "{srgb8_4x} against {f32_4x}");
    assert_eq!("srgb8".parse::<TargetFormat>(), Ok(TargetFormat::Srgb8));
    assert!("rgb8".parse::<TargetFormat>().is_err());
}
