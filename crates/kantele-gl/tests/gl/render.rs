//! Renders small hand-built scenes with the GL backend and checks the pictures against the rules
//! of the reference scenes. Every test skips (prints "skipping: <reason>") when no headless GL
//! context can be created on this machine.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::scene::{AlphaMode, Draw, Material, Mesh, Scene, TextureBinding};
use kantele::shade::texture::{Filter, MinFilter, Sampler, Texture, Wrap};
use kantele::RenderError;
use kantele_gl::GlBackend;

const W: u32 = 64;
const H: u32 = 48;

fn backend() -> Option<GlBackend> {
    match GlBackend::new() {
        Ok(b) => Some(b),
        Err(e) => {
            kantele_testkit::skip("gl", format!("OpenGL unavailable: {e}"));
            None
        }
    }
}

/// Identity camera: positions are NDC directly (w = 1), window depth = (z + 1) / 2.
fn view(to_light: Vec3) -> FrameView {
    FrameView {
        width: W,
        height: H,
        view: Mat4::IDENTITY,
        projection: Mat4::IDENTITY,
        to_light: to_light.normalize(),
        light_color: Vec3::ONE,
        pass: Pass::Color,
    }
}

/// An axis-aligned rectangle in NDC at depth `z`, counter-clockwise, normal +Z, uv (0, 0) at the
/// top-left corner.
fn rect(x0: f32, y0: f32, x1: f32, y1: f32, z: f32, material: usize) -> Mesh {
    Mesh {
        name: "rect".into(),
        positions: vec![
            Vec3::new(x0, y0, z),
            Vec3::new(x1, y0, z),
            Vec3::new(x1, y1, z),
            Vec3::new(x0, y1, z),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        texcoords: Some(vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ]),
        colors: None,
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Mesh::default()
    }
}

fn full(z: f32, material: usize) -> Mesh {
    rect(-1.0, -1.0, 1.0, 1.0, z, material)
}

fn unlit(color: Vec4) -> Material {
    Material {
        base_color_factor: color,
        unlit: true,
        ..Material::default()
    }
}

fn scene(meshes: Vec<Mesh>, materials: Vec<Material>) -> Scene {
    let draws = (0..meshes.len())
        .map(|i| Draw {
            mesh: i,
            model: Mat4::IDENTITY,
            node_name: format!("node{i}"),
            node_index: i * 10,
        })
        .collect();
    Scene {
        meshes,
        materials,
        draws,
        clear_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        ambient: 0.1,
        resolution: (W, H),
        ..Scene::default()
    }
}

fn render(gl: &mut GlBackend, scene: Scene, view: &FrameView) -> FrameImage {
    gl.load(Arc::new(scene)).expect("load");
    gl.render(view).expect("render");
    gl.read_frame().expect("read_frame")
}

fn px(img: &FrameImage, x: u32, y: u32) -> Vec4 {
    Vec4::from_array(img.color[(y * img.width + x) as usize])
}

fn assert_close(actual: Vec4, expected: Vec4, tol: f32, what: &str) {
    assert!(
        (actual - expected).abs().max_element() <= tol,
        "{what}: got {actual}, expected {expected}"
    );
}

#[test]
fn full_screen_quad_covers_every_pixel_with_its_colour_and_depth() {
    let Some(mut gl) = backend() else { return };
    println!("renderer: {} ({})", gl.renderer(), gl.platform());
    let color = Vec4::new(0.2, 0.4, 0.6, 1.0);
    let img = render(
        &mut gl,
        scene(vec![full(0.5, 0)], vec![unlit(color)]),
        &view(Vec3::Z),
    );
    assert_eq!((img.width, img.height), (W, H));
    assert_eq!(img.color.len(), (W * H) as usize);
    for (i, c) in img.color.iter().enumerate() {
        assert_eq!(Vec4::from_array(*c), color, "pixel {i}");
    }
    for d in &img.depth {
        assert!((d - 0.75).abs() < 1e-6, "depth {d}");
    }
}

#[test]
fn row_zero_is_the_top_of_the_image() {
    let Some(mut gl) = backend() else { return };
    let clear = Vec4::new(0.0, 0.0, 0.0, 1.0);
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    // Top-left quadrant of NDC: x in [-1, 0], y in [0, 1].
    let img = render(
        &mut gl,
        scene(vec![rect(-1.0, 0.0, 0.0, 1.0, 0.0, 0)], vec![unlit(red)]),
        &view(Vec3::Z),
    );
    for y in 0..H {
        for x in 0..W {
            let inside = x < W / 2 && y < H / 2;
            let expected = if inside { red } else { clear };
            assert_eq!(px(&img, x, y), expected, "pixel ({x}, {y})");
            let depth = img.depth[(y * W + x) as usize];
            assert_eq!(depth, if inside { 0.5 } else { 1.0 }, "depth ({x}, {y})");
        }
    }
}

#[test]
fn top_left_rule_on_shared_pixel_centres() {
    let Some(mut gl) = backend() else { return };
    // A triangle whose edges pass exactly through pixel centres: the left edge x = 0.5 px
    // (covered: left edge) and the bottom edge y = H/2 + 0.5 in image rows (not covered: a
    // bottom edge), the top edge y = 0.5 (covered: a top edge), right edge x = W/2 + 0.5 (not).
    let px_x = |x: f32| x / W as f32 * 2.0 - 1.0;
    let px_y = |y: f32| 1.0 - y / H as f32 * 2.0;
    let (x0, x1, y0, y1) = (
        px_x(0.5),
        px_x(W as f32 / 2.0 + 0.5),
        px_y(0.5),
        px_y(H as f32 / 2.0 + 0.5),
    );
    let white = Vec4::ONE;
    let img = render(
        &mut gl,
        scene(vec![rect(x0, y1, x1, y0, 0.0, 0)], vec![unlit(white)]),
        &view(Vec3::Z),
    );
    for y in 0..H {
        for x in 0..W {
            let covered = x < W / 2 && y < H / 2;
            let got = px(&img, x, y) == white;
            assert_eq!(got, covered, "pixel ({x}, {y})");
        }
    }
}

#[test]
fn back_faces_are_culled_unless_double_sided() {
    let Some(mut gl) = backend() else { return };
    let green = Vec4::new(0.0, 1.0, 0.0, 1.0);
    let mut cw = full(0.0, 0);
    cw.indices = vec![0, 2, 1, 0, 3, 2];
    let img = render(
        &mut gl,
        scene(vec![cw.clone()], vec![unlit(green)]),
        &view(Vec3::Z),
    );
    assert!(
        img.color.iter().all(|c| c[1] == 0.0),
        "single-sided back face drawn"
    );
    let mut material = unlit(green);
    material.double_sided = true;
    let img = render(&mut gl, scene(vec![cw], vec![material]), &view(Vec3::Z));
    assert!(
        img.color.iter().all(|c| *c == green.to_array()),
        "double-sided back face missing"
    );
}

#[test]
fn lambert_with_known_normal_and_light() {
    let Some(mut gl) = backend() else { return };
    let base = Vec4::new(0.8, 0.6, 0.4, 1.0);
    let material = Material {
        base_color_factor: base,
        ..Material::default()
    };
    // N = +Z, L at 60° from it: N·L = 0.5; ambient 0.1 → 0.1 + 0.9 × 0.5 = 0.55.
    let to_light = Vec3::new(60f32.to_radians().sin(), 0.0, 0.5);
    let img = render(
        &mut gl,
        scene(vec![full(0.0, 0)], vec![material]),
        &view(to_light),
    );
    let expected = (base.truncate() * 0.55).extend(1.0);
    for y in 0..H {
        for x in 0..W {
            assert_close(px(&img, x, y), expected, 1e-3, "lambert");
        }
    }
    // Light behind the surface: ambient only.
    let material = Material {
        base_color_factor: base,
        ..Material::default()
    };
    let img = render(
        &mut gl,
        scene(vec![full(0.0, 0)], vec![material]),
        &view(-Vec3::Z),
    );
    assert_close(
        px(&img, 3, 3),
        (base.truncate() * 0.1).extend(1.0),
        1e-6,
        "unlit side",
    );
}

#[test]
fn double_sided_back_faces_flip_the_normal() {
    let Some(mut gl) = backend() else { return };
    let base = Vec4::new(0.5, 0.5, 0.5, 1.0);
    let material = Material {
        base_color_factor: base,
        double_sided: true,
        ..Material::default()
    };
    // Left half front-facing, right half back-facing (clockwise); both carry normal +Z and the
    // light comes from +Z: the front is fully lit, the back (normal flipped to −Z) gets ambient.
    let front = rect(-1.0, -1.0, 0.0, 1.0, 0.0, 0);
    let mut back = rect(0.0, -1.0, 1.0, 1.0, 0.0, 0);
    back.indices = vec![0, 2, 1, 0, 3, 2];
    let img = render(
        &mut gl,
        scene(vec![front, back], vec![material]),
        &view(Vec3::Z),
    );
    assert_close(px(&img, 5, 20), base, 1e-6, "front face");
    assert_close(
        px(&img, W - 5, 20),
        (base.truncate() * 0.1).extend(1.0),
        1e-6,
        "back face",
    );
}

#[test]
fn flat_normals_for_meshes_without_normals() {
    let Some(mut gl) = backend() else { return };
    let base = Vec4::new(0.3, 0.6, 0.9, 1.0);
    let mut mesh = full(0.0, 0);
    mesh.normals = None;
    let material = Material {
        base_color_factor: base,
        ..Material::default()
    };
    let img = render(&mut gl, scene(vec![mesh], vec![material]), &view(Vec3::Z));
    assert_close(px(&img, 10, 10), base, 1e-6, "flat normal +Z");
    assert_close(px(&img, W - 10, H - 10), base, 1e-6, "flat normal +Z");
}

#[test]
fn blend_half_transparent_red_over_blue() {
    let Some(mut gl) = backend() else { return };
    let blue = unlit(Vec4::new(0.0, 0.0, 1.0, 1.0));
    let mut red = unlit(Vec4::new(1.0, 0.0, 0.0, 0.5));
    red.alpha_mode = AlphaMode::Blend;
    let img = render(
        &mut gl,
        scene(vec![full(0.5, 0), full(0.0, 1)], vec![blue, red]),
        &view(Vec3::Z),
    );
    // dst.a = src.a + dst.a × (1 − src.a) = 1.
    assert_close(px(&img, 7, 7), Vec4::new(0.5, 0.0, 0.5, 1.0), 1e-3, "blend");
    // Blended geometry does not write depth.
    assert_eq!(img.depth[0], 0.75);
}

#[test]
fn mask_discards_below_the_cutoff_and_writes_alpha_one() {
    let Some(mut gl) = backend() else { return };
    let mut kept = unlit(Vec4::new(1.0, 0.0, 0.0, 0.6));
    kept.alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    let mut dropped = unlit(Vec4::new(0.0, 1.0, 0.0, 0.4));
    dropped.alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    let img = render(
        &mut gl,
        scene(
            vec![
                rect(-1.0, -1.0, 0.0, 1.0, 0.0, 0),
                rect(0.0, -1.0, 1.0, 1.0, 0.0, 1),
            ],
            vec![kept, dropped],
        ),
        &view(Vec3::Z),
    );
    assert_eq!(px(&img, 3, 3), Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(px(&img, W - 3, 3), Vec4::new(0.0, 0.0, 0.0, 1.0));
    assert_eq!(img.depth[(3 * W + W - 3) as usize], 1.0);
}

fn quadrant_texture(sampler: Sampler) -> (Scene, [Vec4; 4]) {
    let texels = [
        Vec4::new(1.0, 0.0, 0.0, 1.0), // row 0 (top), left
        Vec4::new(0.0, 1.0, 0.0, 1.0), // row 0 (top), right
        Vec4::new(0.0, 0.0, 1.0, 1.0), // row 1 (bottom), left
        Vec4::new(1.0, 1.0, 1.0, 1.0), // row 1 (bottom), right
    ];
    let texture = Texture::from_rgba_f32(2, 2, texels.to_vec()).expect("texture");
    let material = Material {
        base_color_texture: Some(TextureBinding {
            texture: 0,
            sampler,
            texcoord: 0,
        }),
        unlit: true,
        ..Material::default()
    };
    let mut scene = scene(vec![full(0.0, 0)], vec![material]);
    scene.textures = vec![Arc::new(texture)];
    (scene, texels)
}

#[test]
fn texture_rows_are_not_flipped() {
    let Some(mut gl) = backend() else { return };
    let sampler = Sampler {
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::ClampToEdge,
        mag_filter: Filter::Nearest,
        min_filter: MinFilter::Nearest,
    };
    let (scene, texels) = quadrant_texture(sampler);
    let img = render(&mut gl, scene, &view(Vec3::Z));
    for y in 0..H {
        for x in 0..W {
            let i = (x >= W / 2) as usize + 2 * (y >= H / 2) as usize;
            assert_eq!(px(&img, x, y), texels[i], "pixel ({x}, {y})");
        }
    }
}

#[test]
fn texture_matches_kantele_sampling_at_pixel_centres() {
    let Some(mut gl) = backend() else { return };
    // Bilinear magnification with REPEAT: compare with kantele's own sampler at each pixel centre
    // (level 0 only: magnified, λ < 0).
    let sampler = Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::MirroredRepeat,
        mag_filter: Filter::Linear,
        min_filter: MinFilter::LinearMipmapLinear,
    };
    let (scene, _) = quadrant_texture(sampler);
    let texture = scene.textures[0].clone();
    let img = render(&mut gl, scene, &view(Vec3::Z));
    for y in 0..H {
        for x in 0..W {
            let uv = Vec2::new((x as f32 + 0.5) / W as f32, (y as f32 + 0.5) / H as f32);
            let expected = texture.sample_lod(&sampler, uv, -1.0);
            // llvmpipe filters with 8-bit weights: allow 1/256 of the texel range.
            assert_close(
                px(&img, x, y),
                expected,
                1.0 / 256.0 + 1e-6,
                &format!("({x}, {y})"),
            );
        }
    }
}

#[test]
fn depth_test_less_keeps_the_nearer_surface() {
    let Some(mut gl) = backend() else { return };
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    let green = Vec4::new(0.0, 1.0, 0.0, 1.0);
    let img = render(
        &mut gl,
        scene(
            vec![full(-0.5, 0), full(0.5, 1)],
            vec![unlit(red), unlit(green)],
        ),
        &view(Vec3::Z),
    );
    assert!(img.color.iter().all(|c| *c == red.to_array()));
    assert!(img.depth.iter().all(|d| *d == 0.25));
    // Equal depth drawn second loses too (LESS, not LEQUAL).
    let img = render(
        &mut gl,
        scene(
            vec![full(0.0, 0), full(0.0, 1)],
            vec![unlit(red), unlit(green)],
        ),
        &view(Vec3::Z),
    );
    assert!(img.color.iter().all(|c| *c == red.to_array()));
}

#[test]
fn perspective_camera_and_vertex_colours() {
    let Some(mut gl) = backend() else { return };
    // A unit quad at z = 0 seen from z = 2 through a 90° frustum; vertex colours interpolate.
    let mut mesh = rect(-1.0, -1.0, 1.0, 1.0, 0.0, 0);
    mesh.colors = Some(vec![Vec4::new(1.0, 1.0, 1.0, 1.0); 4]);
    let mut scene = scene(vec![mesh], vec![unlit(Vec4::new(0.25, 0.5, 1.0, 1.0))]);
    scene.draws[0].model = Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0));
    let mut v = view(Vec3::Z);
    v.projection = kantele::camera::perspective(90f32.to_radians(), W as f32 / H as f32, 1.0, 3.0);
    let img = render(&mut gl, scene, &v);
    // Eye distance 2 with near 1, far 3: z_ndc = (f+n)/(f−n) − 2fn/((f−n)·2) = 2 − 1.5 = 0.5.
    let centre = img.depth[((H / 2) * W + W / 2) as usize];
    assert!((centre - 0.75).abs() < 1e-5, "depth {centre}");
    assert_close(
        px(&img, W / 2, H / 2),
        Vec4::new(0.25, 0.5, 1.0, 1.0),
        0.0,
        "centre",
    );
    assert_eq!(px(&img, 0, 0), Vec4::new(0.0, 0.0, 0.0, 1.0));
}

#[test]
fn normals_and_ids_passes() {
    let Some(mut gl) = backend() else { return };
    let material = Material {
        double_sided: true,
        ..Material::default()
    };
    let mut back = rect(0.0, -1.0, 1.0, 1.0, 0.0, 0);
    back.indices = vec![0, 2, 1, 0, 3, 2];
    let s = scene(
        vec![rect(-1.0, -1.0, 0.0, 1.0, 0.0, 0), back],
        vec![material],
    );
    gl.load(Arc::new(s)).unwrap();
    let mut v = view(Vec3::Z);
    v.pass = Pass::Normals;
    gl.render(&v).unwrap();
    let img = gl.read_frame().unwrap();
    assert_eq!(px(&img, 3, 3), Vec4::new(0.0, 0.0, 1.0, 1.0));
    assert_eq!(px(&img, W - 3, 3), Vec4::new(0.0, 0.0, -1.0, 1.0));
    v.pass = Pass::Ids;
    gl.render(&v).unwrap();
    let img = gl.read_frame().unwrap();
    // Left rect: node 0, draw 0; triangle 0 covers the lower-right half of it, 1 the upper-left.
    assert_eq!(px(&img, W / 2 - 2, H - 2), Vec4::new(1.0, 1.0, 1.0, 1.0));
    assert_eq!(px(&img, 1, 1), Vec4::new(1.0, 2.0, 1.0, 1.0));
    // Right rect: node 10, draw 1.
    assert_eq!(px(&img, W - 2, 1).x, 11.0);
    assert_eq!(px(&img, W - 2, 1).z, 2.0);
}

#[test]
fn resizing_fast_target_and_errors() {
    let Some(mut gl) = backend() else { return };
    assert!(matches!(
        gl.render(&view(Vec3::Z)),
        Err(RenderError::Backend { .. })
    ));
    let color = Vec4::new(0.5, 0.25, 1.0, 1.0);
    gl.load(Arc::new(scene(vec![full(0.0, 0)], vec![unlit(color)])))
        .unwrap();
    let mut v = view(Vec3::Z);
    for (w, h) in [(17, 5), (1, 1), (W, H)] {
        v.width = w;
        v.height = h;
        let stats = gl.render(&v).unwrap();
        assert_eq!((stats.draws, stats.triangles_in), (1, 2));
        let img = gl.read_frame().unwrap();
        assert_eq!(img.color.len(), (w * h) as usize);
        assert!(img.color.iter().all(|c| *c == color.to_array()));
    }
    gl.set_fast_target(true);
    gl.render(&v).unwrap();
    let img = gl.read_frame().unwrap();
    // 8-bit unorm storage: 0.25 → 64/255.
    assert_close(px(&img, 0, 0), color, 0.5 / 255.0 + 1e-6, "fast target");
    v.pass = Pass::Ids;
    assert!(matches!(
        gl.render(&v),
        Err(RenderError::Unsupported { .. })
    ));
    v.width = 0;
    assert!(matches!(
        gl.render(&v),
        Err(RenderError::InvalidSize { .. })
    ));
    // An invalid scene is refused before anything is uploaded.
    let mut bad = scene(vec![full(0.0, 0)], vec![unlit(color)]);
    bad.draws[0].mesh = 7;
    assert!(matches!(
        gl.load(Arc::new(bad)),
        Err(RenderError::InvalidScene(_))
    ));
}

#[test]
fn two_backends_on_one_thread_and_on_two_threads() {
    let Some(mut a) = backend() else { return };
    let Some(mut b) = backend() else { return };
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    let blue = Vec4::new(0.0, 0.0, 1.0, 1.0);
    a.load(Arc::new(scene(vec![full(0.0, 0)], vec![unlit(red)])))
        .unwrap();
    b.load(Arc::new(scene(vec![full(0.0, 0)], vec![unlit(blue)])))
        .unwrap();
    a.render(&view(Vec3::Z)).unwrap();
    b.render(&view(Vec3::Z)).unwrap();
    assert_eq!(px(&a.read_frame().unwrap(), 0, 0), red);
    assert_eq!(px(&b.read_frame().unwrap(), 0, 0), blue);
    drop(b);
    a.render(&view(Vec3::Z)).unwrap();
    assert_eq!(px(&a.read_frame().unwrap(), 0, 0), red);
    let handle = std::thread::spawn(move || {
        let mut c = GlBackend::new().expect("a second thread gets a context too");
        c.load(Arc::new(scene(vec![full(0.0, 0)], vec![unlit(blue)])))
            .unwrap();
        c.render(&view(Vec3::Z)).unwrap();
        px(&c.read_frame().unwrap(), 0, 0)
    });
    assert_eq!(handle.join().unwrap(), blue);
    a.render(&view(Vec3::Z)).unwrap();
    assert_eq!(px(&a.read_frame().unwrap(), 0, 0), red);
}

#[test]
fn minification_reads_the_uploaded_mip_levels() {
    let Some(mut gl) = backend() else { return };
    // A 256 × 256 texture on a 64 × 64 image: one pixel spans 4 texels, λ = 2, so
    // NEAREST_MIPMAP_NEAREST reads level 2 (64 × 64) and pixel (x, y) lands on its texel (x, y).
    let size = 256u32;
    let texels = (0..size * size)
        .map(|i| {
            let (x, y) = (i % size, i / size);
            let h = (x.wrapping_mul(2_654_435_761) ^ y.wrapping_mul(40_503)) % 1000;
            Vec4::new(
                x as f32 / size as f32,
                y as f32 / size as f32,
                h as f32 / 1000.0,
                1.0,
            )
        })
        .collect();
    let texture = Arc::new(Texture::from_rgba_f32(size, size, texels).expect("texture"));
    let sampler = Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        mag_filter: Filter::Nearest,
        min_filter: MinFilter::NearestMipmapNearest,
    };
    let material = Material {
        base_color_texture: Some(TextureBinding {
            texture: 0,
            sampler,
            texcoord: 0,
        }),
        unlit: true,
        ..Material::default()
    };
    let mut s = scene(vec![full(0.0, 0)], vec![material]);
    s.textures = vec![texture.clone()];
    let mut v = view(Vec3::Z);
    v.width = 64;
    v.height = 64;
    let img = render(&mut gl, s, &v);
    let level = texture.level(2).expect("level 2");
    assert_eq!((level.width, level.height), (64, 64));
    for y in 0..64 {
        for x in 0..64 {
            let expected = level.texel(x, y);
            assert_close(px(&img, x, y), expected, 1e-6, &format!("({x}, {y})"));
        }
    }
}
