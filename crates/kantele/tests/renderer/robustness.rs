//! No silent blanks at extreme scales: clipping that keeps its precision (tiny models, huge
//! ground planes, triangles reaching far past the guard band), and the frame-level guards
//! (NaN colours and samples, time budgets, empty-picture warning, streaming readback).

use glam::{Mat4, Vec3, Vec4};
use kantele::camera::{look_at, perspective};
use kantele::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions};
use kantele::setup::CullMode;

/// A shader whose vertices are clip-space positions already and which paints opaque white.
fn clip_space_shader() -> impl kantele::pipeline::Shader<Vertex = Vec4> {
    FnShader::new(
        0,
        |v: &Vec4, _out: &mut [f32]| *v,
        |_f: &Fragment<'_>| Some(Vec4::ONE),
    )
}

fn no_cull() -> RenderState {
    RenderState {
        cull: CullMode::None,
        ..RenderState::default()
    }
}

/// Renders clip-space triangles (white on transparent black); returns the renderer and stats.
fn render_clip(size: (u32, u32), vertices: &[Vec4]) -> (Renderer, kantele::stats::FrameStats) {
    let shader = clip_space_shader();
    let mut renderer = Renderer::new(size.0, size.1, RendererOptions::default()).expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, vertices, Indices::None, no_cull())
        .expect("draw");
    let stats = frame.end();
    (renderer, stats)
}

/// Which pixels were written (alpha > 0), row-major, row 0 at the top.
fn coverage(renderer: &Renderer) -> Vec<bool> {
    renderer
        .framebuffer()
        .read_color()
        .iter()
        .map(|c| c[3] > 0.0)
        .collect()
}

/// A few triangles of a model seen through `view_proj`: a box's faces.
fn box_triangles(view_proj: Mat4, half: f32) -> Vec<Vec4> {
    let corner = |i: u32| {
        Vec3::new(
            if i & 1 == 0 { -half } else { half },
            if i & 2 == 0 { -half } else { half },
            if i & 4 == 0 { -half } else { half },
        )
    };
    let faces = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    let mut out = Vec::new();
    for f in faces {
        for k in [0, 1, 2, 0, 2, 3] {
            out.push(view_proj * corner(f[k]).extend(1.0));
        }
    }
    out
}

#[test]
fn a_model_scaled_by_a_power_of_two_renders_bit_identically_down_to_1e_minus_9() {
    let view_proj =
        perspective(0.8, 1.0, 0.5, 50.0) * look_at(Vec3::new(1.3, 0.9, 2.0), Vec3::ZERO, Vec3::Y);
    let unit = box_triangles(view_proj, 1.0);
    let (reference, _) = render_clip((96, 96), &unit);
    let expected = coverage(&reference);
    assert!(expected.iter().filter(|&&c| c).count() > 500);
    // Scaling every clip coordinate by s is what scaling the model and the camera (eye, near
    // and far) by s does; with s a power of two, x/w, y/w and z/w keep their bits.
    for exponent in [-30, -60, -100] {
        let s = 2.0f32.powi(exponent);
        let scaled: Vec<Vec4> = unit.iter().map(|&p| p * s).collect();
        let (renderer, stats) = render_clip((96, 96), &scaled);
        assert_eq!(coverage(&renderer), expected, "scale 2^{exponent}");
        assert_eq!(stats.triangles_invalid, 0);
    }
}

#[test]
fn a_1e_minus_9_model_with_a_1e_minus_9_camera_renders_like_the_unit_model() {
    let picture = |s: f32| {
        let view_proj = perspective(0.8, 1.0, 0.5 * s, 50.0 * s)
            * look_at(Vec3::new(1.3, 0.9, 2.0) * s, Vec3::ZERO, Vec3::Y);
        let (renderer, _) = render_clip((96, 96), &box_triangles(view_proj, s));
        coverage(&renderer)
    };
    let unit = picture(1.0);
    let tiny = picture(1e-9);
    let covered = unit.iter().filter(|&&c| c).count();
    let differing = unit.iter().zip(&tiny).filter(|(a, b)| a != b).count();
    assert!(covered > 500);
    // f32 rounding of the matrices differs at the two scales: edge pixels may flip, no more.
    assert!(
        differing <= covered / 100,
        "{differing} of {covered} pixels differ"
    );
}

/// Renders the square `[−e, e]²` of the plane y = 0 seen from `eye` towards `target` and
/// checks every pixel against the exact ray–plane intersection (pixels whose ray is within
/// 1e-4 of grazing are skipped: that is where the finite plane ends).
fn check_ground_plane(size: (u32, u32), eye: Vec3, target: Vec3, e: f32) {
    let (w, h) = size;
    let view_proj = perspective(1.2, w as f32 / h as f32, 0.1, 1e7) * look_at(eye, target, Vec3::Y);
    let corners = [
        Vec3::new(-e, 0.0, -e),
        Vec3::new(e, 0.0, -e),
        Vec3::new(e, 0.0, e),
        Vec3::new(-e, 0.0, e),
    ];
    let clip: Vec<Vec4> = [0, 1, 2, 0, 2, 3]
        .iter()
        .map(|&i| view_proj * corners[i].extend(1.0))
        .collect();
    let (renderer, stats) = render_clip((w, h), &clip);
    assert!(stats.triangles_clipped > 0);
    let covered = coverage(&renderer);
    let inverse = view_proj.as_dmat4().inverse();
    let (mut wrong, mut checked) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let x_ndc = (x as f64 + 0.5) / w as f64 * 2.0 - 1.0;
            let y_ndc = 1.0 - (y as f64 + 0.5) / h as f64 * 2.0;
            let near = inverse.project_point3(glam::DVec3::new(x_ndc, y_ndc, -1.0));
            let far = inverse.project_point3(glam::DVec3::new(x_ndc, y_ndc, 0.0));
            let direction = (far - near).normalize();
            if direction.y.abs() < 1e-4 {
                continue;
            }
            let t = -near.y / direction.y;
            let hit = near + direction * t;
            let expected = t > 0.0 && hit.x.abs() < e as f64 && hit.z.abs() < e as f64;
            checked += 1;
            if covered[(y * w + x) as usize] != expected {
                wrong += 1;
            }
        }
    }
    assert!(checked > (w * h) as usize * 9 / 10);
    assert_eq!(wrong, 0, "{wrong} of {checked} pixels wrong");
}

#[test]
fn a_1e6_ground_plane_through_the_near_plane_covers_exactly_the_screen_below_the_horizon() {
    let e = 1e6;
    check_ground_plane(
        (128, 96),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, -1.0),
        e,
    );
    check_ground_plane(
        (160, 120),
        Vec3::new(0.3, 1.7, 0.2),
        Vec3::new(2.0, 0.0, -5.0),
        e,
    );
    check_ground_plane(
        (160, 120),
        Vec3::new(10.0, 3.0, -7.0),
        Vec3::new(-3.0, 2.0, 5.0),
        e,
    );
    check_ground_plane(
        (400, 300),
        Vec3::new(0.0, 1.7, 0.0),
        Vec3::new(0.0, 0.0, -3.0),
        e,
    );
    check_ground_plane(
        (400, 300),
        Vec3::new(5.0, 0.3, 9.0),
        Vec3::new(4.0, 0.0, 7.0),
        e,
    );
    // Eye far from the origin, and high above it. (Not: an eye so close to the ground that the
    // near plane cuts it on screen. Its f32 clip coordinates (z ≈ 1e6, ulp 0.06) place the
    // near plane only to within ±15 % of 0.1, so the exact world-space answer is not what
    // any f32 pipeline, OpenGL included, can draw.)
    for (eye, target) in [
        (Vec3::new(3e5, 2.0, 1e5), Vec3::new(3e5, 0.0, 1e5 - 4.0)),
        (Vec3::new(0.0, 30.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
    ] {
        check_ground_plane((400, 300), eye, target, e);
    }
}

/// A triangle whose edge from `(−r, −m·r)` to `(r, m·r)` (clip space, w = 1) crosses the
/// target through its centre, the rest of it far outside: it must cover exactly the pixel
/// centres above that line.
fn check_far_reaching_triangle(r: f32, m: f32) {
    let (w, h) = (160u32, 120u32);
    let y_far = m * r;
    let tri = [
        Vec4::new(-r, -y_far, 0.0, 1.0),
        Vec4::new(r, y_far, 0.0, 1.0),
        Vec4::new(-r, r, 0.0, 1.0),
    ];
    let (renderer, stats) = render_clip((w, h), &tri);
    assert_eq!(stats.triangles_clipped, 1);
    let covered = coverage(&renderer);
    // The exact line through the f32 vertices (symmetric, so through the origin).
    let slope = y_far as f64 / r as f64;
    let mut checked = 0;
    for y in 0..h {
        for x in 0..w {
            let x_ndc = (x as f64 + 0.5) / w as f64 * 2.0 - 1.0;
            let y_ndc = 1.0 - (y as f64 + 0.5) / h as f64 * 2.0;
            let above = y_ndc - slope * x_ndc;
            // Distance from the edge in pixels (vertical); skip near-ties within 1/16 pixel.
            if (above * h as f64 / 2.0).abs() < 1.0 / 16.0 {
                continue;
            }
            checked += 1;
            assert_eq!(
                covered[(y * w + x) as usize],
                above > 0.0,
                "r = {r:e}: pixel ({x}, {y})"
            );
        }
    }
    assert!(checked > (w * h) as usize * 9 / 10);
}

#[test]
fn triangles_reaching_1e9_and_1e12_past_the_target_cover_exactly_their_pixels() {
    for r in [1e6, 1e9, 1e12] {
        check_far_reaching_triangle(r, 0.37);
        check_far_reaching_triangle(r, -0.61);
    }
}

#[test]
fn clipping_never_hands_setup_a_vertex_with_w_at_or_below_zero() {
    use kantele::geometry::clip::{ClipPolygon, ClipVertex, GuardBand, W_MIN};
    let guard = GuardBand::new(200, 100);
    let vertex = |x: f32, y: f32, z: f32, w: f32| ClipVertex {
        pos_clip: Vec4::new(x, y, z, w),
        varyings: [0.0; kantele::MAX_VARYINGS],
    };
    // Triangles crossing w = 0 at every scale, some through the eye itself.
    for scale in [1e-30f32, 1e-9, 1.0, 1e6, 1e20] {
        for (a, b, c) in [
            (
                (0.0, 0.0, 0.0, 0.0),
                (1.0, 0.5, 2.0, 3.0),
                (-1.0, 0.5, 2.0, 3.0),
            ),
            (
                (3.0, 1.0, -5.0, -4.0),
                (1.0, 0.0, 1.0, 2.0),
                (0.0, 1.0, 1.0, 2.0),
            ),
            (
                (1e6, 0.0, 0.0, 1e-3),
                (-1e6, 3.0, 0.0, -1.0),
                (0.0, -1.0, 0.5, 1.0),
            ),
        ] {
            let v = |p: (f32, f32, f32, f32)| {
                vertex(p.0 * scale, p.1 * scale, p.2 * scale, p.3 * scale)
            };
            let mut poly = ClipPolygon::triangle(v(a), v(b), v(c));
            poly.clip(&guard, 0);
            for v in poly.vertices() {
                assert!(v.pos_clip.is_finite());
                assert!(
                    v.pos_clip.w >= W_MIN,
                    "scale {scale:e}: w = {}",
                    v.pos_clip.w
                );
                assert!(v.pos_clip.z >= -v.pos_clip.w * (1.0 + 1e-6));
            }
        }
    }
}

/// Two clip-space triangles covering the whole target at depth 0.
fn full_screen_quad() -> Vec<Vec4> {
    let v = |x: f32, y: f32| Vec4::new(x, y, 0.0, 1.0);
    vec![
        v(-1.0, -1.0),
        v(1.0, -1.0),
        v(1.0, 1.0),
        v(-1.0, -1.0),
        v(1.0, 1.0),
        v(-1.0, 1.0),
    ]
}

#[test]
fn nan_colour_channels_are_written_as_zero_and_counted() {
    let shader = FnShader::new(
        0,
        |v: &Vec4, _out: &mut [f32]| *v,
        |_f: &Fragment<'_>| Some(Vec4::new(f32::NAN, 0.5, -f32::NAN, 1.0)),
    );
    let quad = full_screen_quad();
    let mut renderer = Renderer::new(40, 24, RendererOptions::default()).expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::splat(0.25)), Some(1.0));
    frame
        .draw(&shader, &quad, Indices::None, no_cull())
        .expect("draw");
    let stats = frame.end();
    assert_eq!(stats.fragments_covered, 40 * 24);
    assert_eq!(stats.nan_color_channels, 2 * 40 * 24);
    for c in renderer.framebuffer().read_color() {
        assert_eq!(c, [0.0, 0.5, 0.0, 1.0]);
    }

    // Blending infinities makes NaN too (∞ · 0): also written as 0 and counted.
    let infinite = FnShader::new(
        0,
        |v: &Vec4, _out: &mut [f32]| *v,
        |_f: &Fragment<'_>| Some(Vec4::new(f32::INFINITY, 0.5, 0.5, 0.0)),
    );
    let mut frame = renderer.begin_frame(Some(Vec4::splat(0.25)), Some(1.0));
    let blend = RenderState {
        blend: kantele::rop::BlendMode::Alpha,
        ..no_cull()
    };
    frame
        .draw(&infinite, &quad, Indices::None, blend)
        .expect("draw");
    let stats = frame.end();
    assert_eq!(stats.nan_color_channels, 40 * 24);
    for c in renderer.framebuffer().read_color() {
        assert!(c.iter().all(|v| !v.is_nan()), "{c:?}");
        assert_eq!(c[0], 0.0);
    }
}

#[test]
fn texture_samples_at_nan_and_huge_coordinates_are_defined() {
    use kantele::shade::texture::{Filter, MinFilter, Sampler, Texture, Wrap};
    let texels: Vec<Vec4> = (0..16)
        .map(|i| Vec4::new(i as f32, 1.0, 2.0, 1.0))
        .collect();
    let texture = Texture::from_rgba_f32(4, 4, texels).expect("texture");
    let coordinates = [
        f32::NAN,
        f32::INFINITY,
        -f32::INFINITY,
        1e38,
        -1e38,
        3e9,
        0.5,
    ];
    for wrap in [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat] {
        for filter in [Filter::Nearest, Filter::Linear] {
            let sampler = Sampler {
                wrap_s: wrap,
                wrap_t: wrap,
                mag_filter: filter,
                min_filter: MinFilter::Linear,
            };
            for &u in &coordinates {
                for &v in &coordinates {
                    let s = texture.sample_lod(&sampler, glam::Vec2::new(u, v), 0.0);
                    assert!(s.is_finite(), "{wrap:?} {filter:?} at ({u}, {v}): {s}");
                }
            }
        }
    }
}

#[test]
fn a_frame_of_a_million_full_screen_triangles_stops_at_its_time_budget() {
    use std::time::{Duration, Instant};
    let quad = full_screen_quad();
    let indices: Vec<u32> = (0..1_000_000u32).flat_map(|_| [0, 1, 2]).collect();
    let budget = Duration::from_millis(50);
    let shader = clip_space_shader();
    let mut renderer = Renderer::new(
        256,
        256,
        RendererOptions {
            timeout: Some(budget),
            ..RendererOptions::default()
        },
    )
    .expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    let state = RenderState {
        depth_test: false,
        ..no_cull()
    };
    frame
        .draw(&shader, &quad, Indices::U32(&indices), state)
        .expect("draw");
    let start = Instant::now();
    let result = frame.try_end();
    let elapsed = start.elapsed();
    assert_eq!(result, Err(kantele::RenderError::TimedOut { budget }));
    // About twice the budget on an idle machine; generous for a loaded CI runner.
    assert!(elapsed < budget * 5, "stopped after {elapsed:?}");
    eprintln!("a 50 ms budget stopped the frame after {elapsed:?}");

    // The stats say so too, and the error names the budget.
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, &quad, Indices::U32(&indices), state)
        .expect("draw");
    let stats = frame.end();
    assert_eq!(
        stats.stopped,
        Some(kantele::stats::FrameStop::TimedOut { budget })
    );
    assert!(!stats.empty_picture);
    assert_eq!(
        kantele::RenderError::TimedOut { budget }.to_string(),
        "frame stopped after its time budget of 50 ms"
    );
}

#[test]
fn a_raised_cancel_flag_stops_the_frame_and_a_lowered_one_lets_it_finish() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let quad = full_screen_quad();
    let shader = clip_space_shader();
    let mut renderer = Renderer::new(64, 64, RendererOptions::default()).expect("renderer");
    let flag = Arc::new(AtomicBool::new(true));
    renderer.set_cancel_flag(Some(flag.clone()));
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, &quad, Indices::None, no_cull())
        .expect("draw");
    assert_eq!(frame.try_end(), Err(kantele::RenderError::Cancelled));

    flag.store(false, Ordering::Relaxed);
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, &quad, Indices::None, no_cull())
        .expect("draw");
    let stats = frame.try_end().expect("not cancelled");
    assert_eq!(stats.fragments_covered, 64 * 64);
    assert_eq!(stats.stopped, None);
}

#[test]
fn an_empty_picture_with_geometry_in_view_is_flagged_and_an_empty_scene_is_not() {
    let quad = full_screen_quad();
    let shader = clip_space_shader();
    let mut renderer = Renderer::new(32, 32, RendererOptions::default()).expect("renderer");
    let frame_stats = |renderer: &mut Renderer, vertices: &[Vec4], state: RenderState| {
        let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
        frame
            .draw(&shader, vertices, Indices::None, state)
            .expect("draw");
        frame.end()
    };
    // Everything back-facing and culled: in view, but nothing drawn.
    let clockwise: Vec<Vec4> = quad.chunks(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
    let culled = frame_stats(&mut renderer, &clockwise, RenderState::default());
    assert!(culled.empty_picture);
    let warning = culled.empty_picture_warning().expect("warning");
    assert!(warning.contains("2 of 2 triangles"), "{warning}");
    assert!(warning.contains("2 culled"), "{warning}");
    // Drawn: no warning.
    let drawn = frame_stats(&mut renderer, &quad, no_cull());
    assert!(!drawn.empty_picture);
    assert_eq!(drawn.empty_picture_warning(), None);
    // Wholly outside the view volume, or no triangles at all: empty for an obvious reason.
    let behind: Vec<Vec4> = quad
        .iter()
        .map(|p| Vec4::new(p.x, p.y, -5.0, 1.0))
        .collect();
    assert!(!frame_stats(&mut renderer, &behind, no_cull()).empty_picture);
    assert!(!frame_stats(&mut renderer, &[], no_cull()).empty_picture);
}

#[test]
fn row_streaming_readback_gives_the_whole_frame_readback_row_by_row() {
    // An odd size: partial tiles on the right and at the bottom.
    let (w, h) = (130u32, 70u32);
    let shader = FnShader::new(
        0,
        |v: &Vec4, _out: &mut [f32]| *v,
        |f: &Fragment<'_>| Some(Vec4::new(f.x as f32 / 130.0, f.y as f32 / 70.0, 0.25, 1.0)),
    );
    let tri = [
        Vec4::new(-0.9, -0.8, 0.3, 1.0),
        Vec4::new(0.95, -0.2, -0.4, 1.0),
        Vec4::new(-0.1, 0.9, 0.1, 1.0),
    ];
    let mut renderer = Renderer::new(w, h, RendererOptions::default()).expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::new(0.1, 0.2, 0.3, 0.4)), Some(1.0));
    frame
        .draw(&shader, &tri, Indices::None, no_cull())
        .expect("draw");
    frame.end();
    let fb = renderer.framebuffer();

    let rgba8 = fb.read_rgba8(true);
    assert_eq!(rgba8.len(), (w * h * 4) as usize);
    assert_eq!(rgba8.capacity(), rgba8.len(), "one exact allocation");
    let mut next = 0;
    fb.read_rgba8_rows(true, |y, row| {
        assert_eq!(y, next);
        assert_eq!(row.len(), (w * 4) as usize);
        assert_eq!(
            row,
            &rgba8[(y * w * 4) as usize..((y + 1) * w * 4) as usize]
        );
        next += 1;
    });
    assert_eq!(next, h);

    let color = fb.read_color();
    let depth = fb.read_depth();
    let (mut color_rows, mut depth_rows) = (Vec::new(), Vec::new());
    fb.read_color_rows(|_, row| color_rows.extend_from_slice(row));
    fb.read_depth_rows(|_, row| depth_rows.extend_from_slice(row));
    assert_eq!(color_rows, color);
    assert_eq!(depth_rows, depth);
    assert_eq!(fb.try_read_depth().expect("depth"), depth);
    assert!(depth.iter().any(|&d| d < 1.0) && depth.contains(&1.0));
}

#[test]
fn a_16384_squared_readback_streams_in_one_row_of_extra_memory() {
    use kantele::rop::{framebuffer_bytes, readback_bytes};
    let side = kantele::MAX_TARGET_SIZE;
    assert_eq!(side, 16384);
    // The target itself: 16 bytes of colour and 4 of depth per pixel.
    let target = framebuffer_bytes(side, side);
    assert_eq!(target, 16384 * 16384 * 20);
    // Streaming an 8-bit PNG adds one row; a whole-frame 8-bit copy adds 1 GiB, a linear
    // colour copy 4 GiB (what `Backend::read_frame` returns, for callers that need it).
    assert_eq!(readback_bytes(side, 1, 4), 64 * 1024);
    assert_eq!(readback_bytes(side, side, 4), 1 << 30);
    assert_eq!(readback_bytes(side, side, 16), 1 << 32);
    // Saturating, never wrapping, for sizes no target has.
    assert_eq!(readback_bytes(u32::MAX, u32::MAX, usize::MAX), usize::MAX);
}
