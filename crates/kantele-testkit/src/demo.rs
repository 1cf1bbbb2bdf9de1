//! Two small scenes written directly against the programmable pipeline, as the seed documents
//! describe them: the thesis' textured cube (Listings 6 and 7) and the lecture exercise's
//! Lambert-shaded, alpha-blended scene. The examples render them to PNG and the reference-image
//! tests compare them; they double as a tour of the API.
//!
//! ```
//! use kantele::pipeline::{Renderer, RendererOptions};
//! let mut renderer = Renderer::new(320, 240, RendererOptions::default())?;
//! let stats = kantele_testkit::demo::render_thesis_cube(&mut renderer)?;
//! assert!(stats.fragments_shaded > 0);
//! let rgba8: Vec<u8> = renderer.framebuffer().read_rgba8(true); // sRGB-encoded
//! assert_eq!(rgba8.len(), 320 * 240 * 4);
//! # Ok::<(), kantele::RenderError>(())
//! ```

use glam::{Mat4, Vec2, Vec3, Vec4};

use kantele::camera::{frustum, look_at, normal_matrix, perspective};
use kantele::pipeline::{FnShader, Fragment, Indices, RenderState, Renderer};
use kantele::rop::BlendMode;
use kantele::setup::CullMode;
use kantele::shade::texture::{MinFilter, Sampler, Wrap};
use kantele::stats::FrameStats;
use kantele::RenderError;
use kantele_scene::texture_util::checker;

/// The thesis' vertex: position, colour and texture coordinate.
#[derive(Clone, Copy, Debug)]
pub struct CubeVertex {
    /// Object-space position.
    pub position: Vec3,
    /// Linear colour.
    pub color: Vec3,
    /// Texture coordinate.
    pub tex_coord: Vec2,
}

/// The cube of Listing 7: 24 vertices (4 per face), 12 triangles, counter-clockwise from
/// outside. (The listing repeats one triangle of the bottom face; the intended face is used.)
pub fn thesis_cube() -> (Vec<CubeVertex>, Vec<u16>) {
    let p = [
        [-0.5, 0.5, 0.5],
        [-0.5, -0.5, 0.5],
        [0.5, -0.5, 0.5],
        [0.5, 0.5, 0.5], // front
        [0.5, 0.5, 0.5],
        [0.5, -0.5, 0.5],
        [0.5, -0.5, -0.5],
        [0.5, 0.5, -0.5], // right
        [0.5, 0.5, -0.5],
        [0.5, -0.5, -0.5],
        [-0.5, -0.5, -0.5],
        [-0.5, 0.5, -0.5], // back
        [-0.5, 0.5, -0.5],
        [-0.5, -0.5, -0.5],
        [-0.5, -0.5, 0.5],
        [-0.5, 0.5, 0.5], // left
        [-0.5, 0.5, -0.5],
        [-0.5, 0.5, 0.5],
        [0.5, 0.5, 0.5],
        [0.5, 0.5, -0.5], // top
        [-0.5, -0.5, 0.5],
        [-0.5, -0.5, -0.5],
        [0.5, -0.5, -0.5],
        [0.5, -0.5, 0.5], // bottom
    ];
    let uv = [[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
    let vertices = p
        .iter()
        .enumerate()
        .map(|(i, p)| CubeVertex {
            position: Vec3::from_array(*p),
            color: Vec3::ONE,
            tex_coord: Vec2::from_array(uv[i % 4]),
        })
        .collect();
    let mut indices = Vec::with_capacity(36);
    for face in 0..6u16 {
        let b = face * 4;
        indices.extend_from_slice(&[b, b + 1, b + 2, b, b + 2, b + 3]);
    }
    (vertices, indices)
}

/// Renders the thesis' textured cube (Listing 6): the thesis' frustum (left/right ∓0.25·aspect,
/// bottom/top ∓0.25, near 0.5, far 100), the cube translated to (3, 0, 5) relative to a camera
/// that sees its top face at a grazing angle, a 256 × 256 checker with trilinear filtering, and
/// the thesis' pixel shader `colour × tex2D(texture, uv)`.
pub fn render_thesis_cube(renderer: &mut Renderer) -> Result<FrameStats, RenderError> {
    let fb = renderer.framebuffer();
    let aspect = fb.width() as f32 / fb.height() as f32;
    let projection = frustum(-0.25 * aspect, 0.25 * aspect, -0.25, 0.25, 0.5, 100.0);
    let view = look_at(Vec3::new(4.4, 0.8, 7.6), Vec3::new(3.0, 0.0, 5.0), Vec3::Y);
    let transform = projection * view * Mat4::from_translation(Vec3::new(3.0, 0.0, 5.0));
    let texture = checker(256, 8, [230, 230, 230], [40, 90, 160]);
    let sampler = Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        min_filter: MinFilter::LinearMipmapLinear,
        ..Sampler::default()
    };
    let shader = FnShader::new(
        5,
        |v: &CubeVertex, out: &mut [f32]| {
            out[..3].copy_from_slice(&v.color.to_array());
            out[3..5].copy_from_slice(&v.tex_coord.to_array());
            transform * v.position.extend(1.0)
        },
        |f: &Fragment<'_>| {
            let v = f.varyings();
            let (du_dx, du_dy) = f.derivatives(3);
            let (dv_dx, dv_dy) = f.derivatives(4);
            let texel = texture.sample_grad(
                &sampler,
                Vec2::new(v[3], v[4]),
                Vec2::new(du_dx, dv_dx),
                Vec2::new(du_dy, dv_dy),
            );
            Some((Vec3::new(v[0], v[1], v[2]) * texel.truncate()).extend(1.0))
        },
    );
    let (vertices, indices) = thesis_cube();
    let mut frame = renderer.begin_frame(Some(Vec4::new(0.02, 0.02, 0.05, 1.0)), Some(1.0));
    frame.draw(
        &shader,
        &vertices,
        Indices::U16(&indices),
        RenderState::default(),
    )?;
    Ok(frame.end())
}

/// A vertex with position and normal, as in the lecture exercise.
#[derive(Clone, Copy, Debug)]
pub struct LitVertex {
    /// Object-space position.
    pub pos: Vec3,
    /// Object-space normal.
    pub normal: Vec3,
}

/// A UV sphere of radius 1 (counter-clockwise from outside).
pub fn uv_sphere(rings: u32, segments: u32) -> (Vec<LitVertex>, Vec<u32>) {
    let mut vertices = Vec::new();
    for r in 0..=rings {
        let theta = r as f32 / rings as f32 * std::f32::consts::PI;
        for s in 0..=segments {
            let phi = s as f32 / segments as f32 * std::f32::consts::TAU;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            vertices.push(LitVertex { pos: n, normal: n });
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + row;
            indices.extend_from_slice(&[a, b, b + 1, a, b + 1, a + 1]);
        }
    }
    (vertices, indices)
}

/// Renders the lecture exercise's scene: an opaque Lambert-lit ground, then two overlapping
/// translucent spheres drawn with two-sided Lambert shading (back faces lit with the flipped
/// normal), premultiplied "over" blending, no culling, depth test on without depth writes, and
/// their triangles sorted back to front.
pub fn render_exercise(renderer: &mut Renderer) -> Result<FrameStats, RenderError> {
    let fb = renderer.framebuffer();
    let aspect = fb.width() as f32 / fb.height() as f32;
    let view = look_at(Vec3::new(0.0, 1.6, 4.2), Vec3::new(0.0, 0.4, 0.0), Vec3::Y);
    let proj = perspective(50f32.to_radians(), aspect, 0.1, 50.0);
    let light = Vec3::new(0.4, 1.0, 0.6).normalize();

    // The exercise's shader: view/projection as uniforms, Lambert with the diffuse colour `diff`
    // and the light vector `L`, two-sided; output premultiplied by `alpha`.
    let make_shader = |model: Mat4, diff: Vec3, alpha: f32| {
        let mvp = proj * view * model;
        let nm = normal_matrix(&model);
        FnShader::new(
            3,
            move |v: &LitVertex, out: &mut [f32]| {
                out.copy_from_slice(&(nm * v.normal).to_array());
                mvp * v.pos.extend(1.0)
            },
            move |f: &Fragment<'_>| {
                let v = f.varyings();
                let mut n = Vec3::new(v[0], v[1], v[2]).normalize_or_zero();
                if !f.front_facing {
                    n = -n;
                }
                let lambert = 0.15 + 0.85 * n.dot(light).max(0.0);
                Some((diff * lambert * alpha).extend(alpha))
            },
        )
    };
    let ground_vertices: Vec<LitVertex> = [[-3.0, -3.0], [-3.0, 3.0], [3.0, 3.0], [3.0, -3.0]]
        .iter()
        .map(|[x, z]| LitVertex {
            pos: Vec3::new(*x, 0.0, *z),
            normal: Vec3::Y,
        })
        .collect();
    let ground_indices = [0u32, 1, 2, 0, 2, 3];
    let (sphere_vertices, sphere_indices) = uv_sphere(24, 48);
    let ground = make_shader(Mat4::IDENTITY, Vec3::new(0.8, 0.8, 0.75), 1.0);
    let left = make_shader(
        Mat4::from_translation(Vec3::new(-0.45, 0.8, 0.0)) * Mat4::from_scale(Vec3::splat(0.75)),
        Vec3::new(0.9, 0.2, 0.15),
        0.5,
    );
    let right = make_shader(
        Mat4::from_translation(Vec3::new(0.45, 0.8, -0.4)) * Mat4::from_scale(Vec3::splat(0.75)),
        Vec3::new(0.15, 0.4, 0.95),
        0.5,
    );
    let transparent = RenderState {
        cull: CullMode::None,
        depth_write: false,
        blend: BlendMode::PremultipliedOver,
        sort_back_to_front: true,
        ..RenderState::default()
    };
    let mut frame = renderer.begin_frame(Some(Vec4::new(0.05, 0.05, 0.08, 1.0)), Some(1.0));
    frame.draw(
        &ground,
        &ground_vertices,
        Indices::U32(&ground_indices),
        RenderState::default(),
    )?;
    // The farther sphere first, as the exercise sorts back to front.
    frame.draw(
        &right,
        &sphere_vertices,
        Indices::U32(&sphere_indices),
        transparent,
    )?;
    frame.draw(
        &left,
        &sphere_vertices,
        Indices::U32(&sphere_indices),
        transparent,
    )?;
    Ok(frame.end())
}
