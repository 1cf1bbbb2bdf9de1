//! Behaviour of the pipeline stages: clipping, perspective-correct interpolation, level of
//! detail, depth functions, blending, and bad input.

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::camera::{look_at, perspective};
use kantele::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions};
use kantele::rop::{BlendMode, DepthFunc};
use kantele::setup::CullMode;
use kantele::shade::texture::{Sampler, Texture};
use kantele::RenderError;

/// Vertex: world position + a 2-component attribute.
type Vtx = (Vec3, Vec2);

fn attribute_shader(mvp: Mat4) -> impl kantele::pipeline::Shader<Vertex = Vtx> {
    FnShader::new(
        2,
        move |v: &Vtx, out: &mut [f32]| {
            out.copy_from_slice(&v.1.to_array());
            mvp * v.0.extend(1.0)
        },
        |f: &Fragment<'_>| Some(Vec4::new(f.varying(0), f.varying(1), 0.0, 1.0)),
    )
}

/// Two triangles covering NDC [−1, 1]² at clip z = `z` (w = 1), attribute `(c, c)`.
fn quad(z: f32, c: f32) -> Vec<Vtx> {
    quad_with(z, Vec2::splat(c))
}

/// The same with attribute `a`.
fn quad_with(z: f32, a: Vec2) -> Vec<Vtx> {
    let v = |x: f32, y: f32| (Vec3::new(x, y, z), a);
    vec![
        v(-1.0, -1.0),
        v(1.0, -1.0),
        v(1.0, 1.0),
        v(-1.0, -1.0),
        v(1.0, 1.0),
        v(-1.0, 1.0),
    ]
}

fn no_cull() -> RenderState {
    RenderState {
        cull: CullMode::None,
        ..RenderState::default()
    }
}

fn render(
    size: (u32, u32),
    shader: &impl kantele::pipeline::Shader<Vertex = Vtx>,
    vertices: &[Vtx],
    state: RenderState,
) -> Renderer {
    let mut renderer = Renderer::new(size.0, size.1, RendererOptions::default()).expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(shader, vertices, Indices::None, state)
        .expect("draw");
    frame.end();
    renderer
}

/// World-space ray through the centre of pixel (x, y).
fn pixel_ray(view_proj: Mat4, x: u32, y: u32, w: u32, h: u32) -> (Vec3, Vec3) {
    let ndc = Vec2::new(
        (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
    );
    let inv = view_proj.inverse();
    let near = inv.project_point3(ndc.extend(-1.0));
    let far = inv.project_point3(ndc.extend(1.0));
    (near, (far - near).normalize())
}

/// Ground plane y = 0 from (−s, −s) to (s, s) with texcoords = (x, z) / s mapped to [0, 1].
fn ground(s: f32) -> Vec<Vtx> {
    let v = |x: f32, z: f32| {
        (
            Vec3::new(x, 0.0, z),
            Vec2::new((x / s + 1.0) * 0.5, (z / s + 1.0) * 0.5),
        )
    };
    vec![v(-s, -s), v(-s, s), v(s, s), v(-s, -s), v(s, s), v(s, -s)]
}

#[test]
fn perspective_correct_attributes_match_the_analytic_mapping() {
    let (w, h) = (160, 120);
    let view_proj = perspective(1.0, w as f32 / h as f32, 0.1, 100.0)
        * look_at(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.0, -2.0), Vec3::Y);
    let s = 4.0;
    let renderer = render((w, h), &attribute_shader(view_proj), &ground(s), no_cull());
    let fb = renderer.framebuffer();
    let mut checked = 0;
    for y in 0..h {
        for x in 0..w {
            if fb.depth_at(x, y).unwrap_or(1.0) >= 1.0 {
                continue;
            }
            let (origin, dir) = pixel_ray(view_proj, x, y, w, h);
            let t = -origin.y / dir.y;
            let hit = origin + dir * t;
            if hit.x.abs() > s * 0.98 || hit.z.abs() > s * 0.98 {
                continue; // edge pixels: the centre may lie just outside
            }
            let expected = Vec2::new((hit.x / s + 1.0) * 0.5, (hit.z / s + 1.0) * 0.5);
            let got = fb.pixel(x, y).expect("pixel");
            assert!(
                (got.x - expected.x).abs() < 2e-3 && (got.y - expected.y).abs() < 2e-3,
                "pixel ({x}, {y}): {got:?} vs {expected:?}"
            );
            checked += 1;
        }
    }
    assert!(checked > 4000, "{checked}");
}

/// A triangle whose attributes are the same at its three vertices reads them as exactly that
/// value at every pixel, on every instruction set, although its perspective weights do not sum
/// to 1 exactly everywhere.
#[test]
fn constant_attributes_are_read_exactly() {
    let (w, h) = (160, 120);
    let view_proj = perspective(1.0, w as f32 / h as f32, 0.1, 100.0)
        * look_at(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.0, -2.0), Vec3::Y);
    let shader = attribute_shader(view_proj);
    let constant = Vec2::new(0.1, 0.7);
    // The ground's first triangle, receding, with the same attribute at its three vertices.
    let triangle: Vec<Vtx> = ground(4.0)[..3]
        .iter()
        .map(|&(position, _)| (position, constant))
        .collect();
    for isa in kantele::simd::Isa::supported() {
        let options = RendererOptions {
            isa: Some(isa),
            ..RendererOptions::default()
        };
        let mut renderer = Renderer::new(w, h, options).expect("renderer");
        let mut frame = renderer.begin_frame(Some(Vec4::ONE), Some(1.0));
        frame
            .draw(&shader, &triangle, Indices::None, no_cull())
            .expect("draw");
        frame.end();
        let fb = renderer.framebuffer();
        let mut covered = 0;
        for y in 0..h {
            for x in 0..w {
                let got = fb.pixel(x, y).expect("pixel");
                if got.z != 0.0 {
                    continue; // the clear colour
                }
                assert_eq!(got.truncate().truncate(), constant, "{isa} at ({x}, {y})");
                covered += 1;
            }
        }
        assert!(covered > w * h / 5, "{isa}: {covered} pixels covered");
    }
}

#[test]
fn a_triangle_reaching_behind_the_eye_renders_its_visible_part() {
    // The ground plane extends far behind the camera: the near clipper must cut it, and the
    // visible part must be exactly the pixels whose ray hits the plane in front of the camera.
    let (w, h) = (128, 96);
    let view_proj = perspective(1.2, w as f32 / h as f32, 0.1, 1000.0)
        * look_at(
            Vec3::new(0.0, 1.5, 0.0),
            Vec3::new(0.0, 1.5, -10.0),
            Vec3::Y,
        );
    let s = 500.0;
    let renderer = render((w, h), &attribute_shader(view_proj), &ground(s), no_cull());
    let fb = renderer.framebuffer();
    let mut mismatches = 0;
    let mut covered = 0;
    for y in 0..h {
        for x in 0..w {
            let (origin, dir) = pixel_ray(view_proj, x, y, w, h);
            // Hits the plane in front within the far plane (depth < 1).
            let t = -origin.y / dir.y;
            let expected = dir.y < 0.0
                && t * dir.dot(Vec3::NEG_Z) < 999.0
                && (origin + dir * t).abs().max_element() < s;
            let got = fb.depth_at(x, y).expect("depth") < 1.0;
            covered += got as u32;
            if expected != got {
                mismatches += 1;
            }
        }
    }
    // Only the horizon row may differ, where the plane meets the far plane.
    assert!(mismatches <= w, "{mismatches} mismatches");
    assert!(
        covered as f32 > 0.4 * (w * h) as f32,
        "the lower half must be ground ({covered})"
    );
}

#[test]
fn level_of_detail_grows_along_a_receding_plane_as_the_analytic_footprint() {
    let (w, h) = (128, 128);
    let view_proj = perspective(1.0, 1.0, 0.1, 1000.0)
        * look_at(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, -6.0), Vec3::Y);
    let s = 200.0;
    // The texture repeats 64 times across the plane: about 41 texels per world unit.
    let repeats = 64.0;
    let plane: Vec<Vtx> = ground(s)
        .into_iter()
        .map(|(p, uv)| (p, uv * repeats))
        .collect();
    let texture = Texture::from_rgba_f32(256, 256, vec![Vec4::ONE; 256 * 256]).expect("texture");
    let lod_shader = FnShader::new(
        2,
        move |v: &Vtx, out: &mut [f32]| {
            out.copy_from_slice(&v.1.to_array());
            view_proj * v.0.extend(1.0)
        },
        |f: &Fragment<'_>| {
            let (du_dx, du_dy) = f.derivatives(0);
            let (dv_dx, dv_dy) = f.derivatives(1);
            let lod = texture.lod(Vec2::new(du_dx, dv_dx), Vec2::new(du_dy, dv_dy));
            Some(Vec4::new(lod, f.varying(0), f.varying(1), 1.0))
        },
    );
    let renderer = render((w, h), &lod_shader, &plane, no_cull());
    let fb = renderer.framebuffer();
    // Analytic footprint: map neighbouring pixel centres onto the plane.
    let uv_at = |x: f32, y: f32| {
        let ndc = Vec2::new(x / w as f32 * 2.0 - 1.0, 1.0 - y / h as f32 * 2.0);
        let inv = view_proj.inverse();
        let near = inv.project_point3(ndc.extend(-1.0));
        let far = inv.project_point3(ndc.extend(1.0));
        let dir = far - near;
        let hit = near + dir * (-near.y / dir.y);
        Vec2::new((hit.x / s + 1.0) * 0.5, (hit.z / s + 1.0) * 0.5) * repeats * 256.0
    };
    let x = w / 2;
    let mut previous = f32::NEG_INFINITY;
    let mut rows = 0;
    for y in (h / 2 + 4..h).rev() {
        let lod = fb.pixel(x, y).expect("pixel").x;
        let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
        let e = 1e-2;
        let dx = (uv_at(cx + e, cy) - uv_at(cx - e, cy)) / (2.0 * e);
        let dy = (uv_at(cx, cy + e) - uv_at(cx, cy - e)) / (2.0 * e);
        let expected = dx.length().max(dy.length()).log2();
        assert!(
            (lod - expected).abs() < 0.05,
            "row {y}: lod {lod} vs {expected}"
        );
        assert!(lod >= previous - 1e-3, "lod must grow towards the horizon");
        previous = lod;
        rows += 1;
    }
    assert!(rows > 20);
    assert!(
        previous > 2.0,
        "far rows are strongly minified ({previous})"
    );
}

#[test]
fn depth_functions_decide_which_of_two_quads_is_seen() {
    // A near quad (depth 0.25) then a far one (0.75), both full-screen; the second draw uses
    // the function under test.
    let shader = attribute_shader(Mat4::IDENTITY);
    let first = quad(-0.5, 0.2);
    let cases = [
        (DepthFunc::Never, 0.75, 0.2),
        (DepthFunc::Less, 0.75, 0.2),
        (DepthFunc::Less, 0.0, 0.8),
        (DepthFunc::Greater, 0.75, 0.8),
        (DepthFunc::Equal, 0.25, 0.8),
        (DepthFunc::NotEqual, 0.25, 0.2),
        (DepthFunc::LessEqual, 0.25, 0.8),
        (DepthFunc::GreaterEqual, 0.0, 0.2),
        (DepthFunc::Always, 0.75, 0.8),
    ];
    for (func, second_depth, expected) in cases {
        let second = quad(second_depth * 2.0 - 1.0, 0.8);
        let mut renderer = Renderer::new(16, 16, RendererOptions::default()).expect("renderer");
        let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
        frame
            .draw(&shader, &first, Indices::None, no_cull())
            .expect("draw");
        let state = RenderState {
            depth_func: func,
            ..no_cull()
        };
        frame
            .draw(&shader, &second, Indices::None, state)
            .expect("draw");
        frame.end();
        let got = renderer.framebuffer().pixel(5, 9).expect("pixel").x;
        // Interpolation weights sum to 1 within f32 rounding.
        assert!(
            (got - expected).abs() < 1e-5,
            "{func:?} with second depth {second_depth}: {got}"
        );
    }
}

#[test]
fn depth_test_off_and_write_off_behave_independently() {
    let shader = attribute_shader(Mat4::IDENTITY);
    let mut renderer = Renderer::new(8, 8, RendererOptions::default()).expect("renderer");
    let near = quad(-0.5, 0.3);
    let far = quad(0.5, 0.6);
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw(&shader, &near, Indices::None, no_cull())
        .expect("draw");
    let untested = RenderState {
        depth_test: false,
        depth_write: false,
        ..no_cull()
    };
    frame
        .draw(&shader, &far, Indices::None, untested)
        .expect("draw");
    frame.end();
    let fb = renderer.framebuffer();
    assert!(
        (fb.pixel(3, 3).expect("pixel").x - 0.6).abs() < 1e-5,
        "depth test off draws over"
    );
    assert_eq!(
        fb.depth_at(3, 3),
        Some(0.25),
        "depth write off keeps the depth"
    );
}

#[test]
fn fragments_outside_the_depth_range_are_discarded() {
    let v = |x: f32, y: f32| (Vec3::new(x, y, 1.5), Vec2::ONE);
    let beyond_far = vec![v(-1.0, -1.0), v(1.0, -1.0), v(1.0, 1.0)];
    let renderer = render(
        (8, 8),
        &attribute_shader(Mat4::IDENTITY),
        &beyond_far,
        no_cull(),
    );
    assert!(renderer
        .framebuffer()
        .read_depth()
        .iter()
        .all(|d| *d == 1.0));
}

#[test]
fn blending_and_back_to_front_sorting() {
    // Two overlapping half-transparent quads submitted front first; with sorting the back one
    // is drawn first, so the front colour dominates.
    let view_proj = perspective(1.5, 1.0, 0.1, 10.0);
    let mut vertices = quad_with(-1.0, Vec2::new(1.0, 0.5)); // front, red = 1, alpha 0.5
    vertices.extend(quad_with(-2.0, Vec2::new(0.0, 0.5))); // back, red = 0
    let shader = FnShader::new(
        2,
        move |v: &Vtx, out: &mut [f32]| {
            out.copy_from_slice(&v.1.to_array());
            view_proj * v.0.extend(1.0)
        },
        |f: &Fragment<'_>| Some(Vec4::new(f.varying(0), 0.0, 0.0, f.varying(1))),
    );
    let draw = |sort: bool| {
        let state = RenderState {
            blend: BlendMode::Alpha,
            depth_write: false,
            sort_back_to_front: sort,
            ..no_cull()
        };
        let renderer = render((8, 8), &shader, &vertices, state);
        renderer.framebuffer().pixel(4, 4).expect("pixel").x
    };
    let (sorted, unsorted) = (draw(true), draw(false));
    assert!(
        (sorted - 0.5).abs() < 1e-5,
        "back (0) then front (1): 0·0.5, then 1·0.5 + 0·0.5 = {sorted}"
    );
    assert!(
        (unsorted - 0.25).abs() < 1e-5,
        "front then back: 1·0.5, then 0·0.5 + 0.5·0.5 = {unsorted}"
    );
}

#[test]
fn bad_input_gives_errors_or_defined_results() {
    assert!(matches!(
        Renderer::new(0, 10, RendererOptions::default()),
        Err(RenderError::InvalidSize { .. })
    ));
    assert!(matches!(
        Renderer::new(100_000, 100_000, RendererOptions::default()),
        Err(RenderError::InvalidSize { .. })
    ));
    let mut renderer = Renderer::new(32, 32, RendererOptions::default()).expect("renderer");
    let shader = attribute_shader(Mat4::IDENTITY);
    let good = (Vec3::ZERO, Vec2::ZERO);
    let vertices = vec![
        good,
        (Vec3::new(1.0, 0.0, 0.0), Vec2::ZERO),
        (Vec3::new(0.0, 1.0, 0.0), Vec2::ZERO),
        (Vec3::new(f32::NAN, 0.0, 0.0), Vec2::ZERO),
        (Vec3::new(f32::INFINITY, 1.0, 0.0), Vec2::ZERO),
        (Vec3::new(1e30, -1e30, 0.0), Vec2::ZERO),
        (Vec3::new(-1e30, 3e38, 0.5), Vec2::ZERO),
    ];
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    let out_of_range = [0u32, 1, 7];
    assert!(matches!(
        frame.draw(&shader, &vertices, Indices::U32(&out_of_range), no_cull()),
        Err(RenderError::IndexOutOfRange {
            index: 7,
            position: 2,
            ..
        })
    ));
    assert!(matches!(
        frame.draw(&shader, &vertices, Indices::U16(&[0, 1]), no_cull()),
        Err(RenderError::IncompleteTriangle(2))
    ));
    // NaN, infinite, huge and degenerate triangles: drawn as far as defined, never a panic.
    let nasty: [u16; 18] = [0, 1, 3, 0, 4, 2, 0, 5, 2, 0, 6, 5, 0, 0, 1, 1, 5, 6];
    frame
        .draw(&shader, &vertices, Indices::U16(&nasty), no_cull())
        .expect("draw");
    let stats = frame.end();
    assert_eq!(stats.triangles_in, 6);
    assert_eq!(stats.triangles_invalid, 2, "{stats:?}");
    assert!(stats.triangles_degenerate >= 1, "{stats:?}");
    let too_many = FnShader::new(
        kantele::MAX_VARYINGS + 1,
        |_: &Vtx, _: &mut [f32]| Vec4::ZERO,
        |_: &Fragment<'_>| None,
    );
    let mut frame = renderer.begin_frame(None, None);
    assert!(matches!(
        frame.draw(&too_many, &vertices, Indices::None, no_cull()),
        Err(RenderError::TooManyVaryings(_))
    ));
    // Textures: empty, wrong size, huge.
    assert!(Texture::from_rgba8(0, 4, &[], kantele::shade::texture::ColorSpace::Srgb).is_err());
    assert!(
        Texture::from_rgba8(2, 2, &[0; 15], kantele::shade::texture::ColorSpace::Srgb).is_err()
    );
    assert!(
        Texture::from_rgba8(1 << 20, 1, &[], kantele::shade::texture::ColorSpace::Linear).is_err()
    );
    // Sampling with NaN coordinates or derivatives is defined.
    let t = Texture::from_rgba_f32(4, 4, vec![Vec4::ONE; 16]).expect("texture");
    let s = Sampler::default();
    assert_eq!(
        t.sample_grad(&s, Vec2::NAN, Vec2::ONE, Vec2::ONE),
        Vec4::ZERO
    );
    assert!(t
        .sample_grad(&s, Vec2::ONE, Vec2::NAN, Vec2::INFINITY)
        .is_finite());
    assert!(t
        .sample_grad(&s, Vec2::splat(1e30), Vec2::ZERO, Vec2::ZERO)
        .is_finite());
}

#[test]
fn triangles_behind_a_tile_are_skipped_without_changing_the_picture() {
    // 130 × 70 pixels = 3 × 2 tiles. A near quad, then a far one: with LESS the far quad is
    // rejected tile by tile; with GREATER it must not be, and it is then drawn.
    let shader = attribute_shader(Mat4::IDENTITY);
    let near = quad(-0.5, 0.25);
    let far = quad(0.5, 0.75);
    for (func, rejected, expected) in [(DepthFunc::Less, 6, 0.25), (DepthFunc::Greater, 0, 0.75)] {
        let mut renderer = Renderer::new(130, 70, RendererOptions::default()).expect("renderer");
        let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
        frame
            .draw(&shader, &near, Indices::None, no_cull())
            .expect("draw");
        let state = RenderState {
            depth_func: func,
            ..no_cull()
        };
        frame
            .draw(&shader, &far, Indices::None, state)
            .expect("draw");
        let stats = frame.end();
        // Two triangles per quad, each touching all 6 tiles.
        assert_eq!(stats.tiles_depth_rejected, 2 * rejected, "{func:?}");
        let fb = renderer.framebuffer();
        for (x, y) in [(0, 0), (129, 69), (64, 35)] {
            let got = fb.pixel(x, y).expect("pixel").x;
            assert!(
                (got - expected).abs() < 1e-5,
                "{func:?} at ({x}, {y}): {got}"
            );
        }
    }
}

#[test]
fn blocks_behind_stored_depth_are_skipped_without_changing_the_picture() {
    // One 64 × 64 tile. A near quad over the left half (x < 32), then a far full-screen quad:
    // the tile as a whole still has cleared pixels (no tile rejection), but the 32 blocks of the
    // left half hold only near depths and are skipped; the right half is drawn.
    let shader = attribute_shader(Mat4::IDENTITY);
    let v = |x: f32, y: f32, z: f32, c: f32| (Vec3::new(x, y, z), Vec2::splat(c));
    let near = vec![
        v(-1.0, -1.0, -0.5, 0.25),
        v(0.0, -1.0, -0.5, 0.25),
        v(0.0, 1.0, -0.5, 0.25),
        v(-1.0, -1.0, -0.5, 0.25),
        v(0.0, 1.0, -0.5, 0.25),
        v(-1.0, 1.0, -0.5, 0.25),
    ];
    let far = quad(0.5, 0.75);
    for isa in kantele::simd::Isa::ALL
        .into_iter()
        .filter(|i| i.is_supported())
    {
        let options = RendererOptions {
            isa: Some(isa),
            ..RendererOptions::default()
        };
        let mut renderer = Renderer::new(64, 64, options).expect("renderer");
        let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
        frame
            .draw(&shader, &near, Indices::None, no_cull())
            .expect("draw");
        frame
            .draw(&shader, &far, Indices::None, no_cull())
            .expect("draw");
        let stats = frame.end();
        assert_eq!(stats.tiles_depth_rejected, 0, "{isa}");
        // The far quad's two triangles each cover the 32 left blocks only partly along the
        // diagonal; every left block covered by a far triangle is rejected.
        assert!(stats.blocks_depth_rejected >= 32, "{isa}: {stats:?}");
        let fb = renderer.framebuffer();
        for (x, y, expected) in [(0, 0, 0.25), (31, 63, 0.25), (32, 0, 0.75), (63, 63, 0.75)] {
            let got = fb.pixel(x, y).expect("pixel").x;
            assert!((got - expected).abs() < 1e-5, "{isa} at ({x}, {y}): {got}");
        }
    }
}
