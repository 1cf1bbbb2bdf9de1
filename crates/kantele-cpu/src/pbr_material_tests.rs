//! Tests of the PBR material shader (`pbr_material.rs`).

use std::sync::Arc;

use glam::{Vec3, Vec4};

use super::*;
use crate::pipeline::{Indices, Renderer, RendererOptions};
use kantele_rules::scene::{Mesh, Topology};
use kantele_rules::setup::CullMode;
use kantele_rules::shade::environment::EnvironmentLight;
use kantele_rules::shade::pbr::{FrameLight, Tonemap};
use kantele_rules::shade::texture::{ColorSpace, Filter, MinFilter, Wrap};
use kantele_rules::shade::transmission::{Backdrop, TransmissionView};

/// The shader with one fragment at a time: the trait's default `fragment_lanes`, which calls
/// `fragment` per lane.
struct OneAtATime<'s, 'a>(&'s PbrShader<'a>);

impl Shader for OneAtATime<'_, '_> {
    type Vertex = PbrVertex;
    fn varying_count(&self) -> usize {
        Shader::varying_count(self.0)
    }
    fn vertex(&self, vertex: &PbrVertex, varyings: &mut [f32]) -> Vec4 {
        self.0.vertex(vertex, varyings)
    }
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        self.0.fragment(fragment)
    }
}

/// A quad in the XY plane facing +Z, `u` along +X and `v` along −Y (image rows down).
fn quad() -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        texcoords: Some(vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    }
}

fn linear_texture(size: u32, texel: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
    let rgba: Vec<u8> = (0..size * size)
        .flat_map(|i| texel(i % size, i / size))
        .collect();
    let texture = Texture::from_rgba8(size, size, &rgba, ColorSpace::Linear).expect("texture");
    texture.prepare_lane_sampling();
    texture
}

/// `texture` bound through [`sampler`], reading the first texture coordinate set.
fn bound(texture: &Texture) -> BoundTexture<'_> {
    Some(Bound {
        texture,
        sampler: sampler(),
        texcoord: 0,
    })
}

fn sampler() -> Sampler {
    Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        mag_filter: Filter::Linear,
        min_filter: MinFilter::LinearMipmapLinear,
    }
}

fn lighting(environment: bool) -> PbrLighting {
    PbrLighting {
        lights: vec![
            FrameLight::directional(Vec3::new(0.4, 0.5, 0.8).normalize(), Vec3::splat(2.0)),
            FrameLight::new(&kantele_rules::scene::PunctualLight {
                kind: kantele_rules::scene::LightKind::Point,
                color: Vec3::new(3.0, 2.0, 1.0),
                position: Vec3::new(-0.5, 0.3, 1.0),
                direction: Vec3::NEG_Z,
                range: Some(4.0),
            }),
        ],
        environment: environment.then(EnvironmentLight::studio),
        eye: Vec3::new(0.0, 0.0, 3.0),
        exposure: 1.0,
        tonemap: Tonemap::PbrNeutral,
        transmission: None,
    }
}

fn view_projection() -> Mat4 {
    Mat4::perspective_rh_gl(0.9, 1.5, 0.1, 20.0)
        * Mat4::look_at_rh(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y)
}

/// The colour of a 96 × 64 frame of `mesh` drawn with `shader`.
fn render<S: Shader<Vertex = PbrVertex>>(
    shader: &S,
    mesh: &Mesh,
    options: RendererOptions,
) -> Vec<[f32; 4]> {
    let (vertices, indices) = PbrVertex::from_mesh(mesh);
    let mut renderer = Renderer::new(96, 64, options).expect("renderer");
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame
        .draw_primitives(
            shader,
            &vertices,
            Indices::U32(&indices),
            Topology::Triangles,
            RenderState {
                cull: CullMode::None,
                ..RenderState::default()
            },
        )
        .expect("draw");
    frame.try_end().expect("frame");
    renderer.framebuffer().read_color()
}

/// Every instruction set shades a fully textured, normal-mapped, clear-coated, sheened,
/// environment-lit quad to the same bits, and one fragment at a time (the scalar texture sampler) agrees within
/// the samplers' rounding.
#[test]
fn lanes_agree_across_instruction_sets_and_with_one_fragment_at_a_time() {
    lanes_agree(false);
}

/// [`lanes_agree_across_instruction_sets_and_with_one_fragment_at_a_time`] for a transmissive
/// volume (textured transmission and thickness, attenuation) over a backdrop.
#[test]
fn transmissive_lanes_agree_across_instruction_sets() {
    lanes_agree(true);
}

fn lanes_agree(transmissive: bool) {
    let base = linear_texture(16, |x, y| [(x * 16) as u8, (y * 16) as u8, 128, 255]);
    let bumps = linear_texture(16, |x, y| {
        let tilt = ((x as f32 * 0.7).sin() * 60.0 + 128.0) as u8;
        [tilt, (y * 9 + 80) as u8, 230, 255]
    });
    let mr = linear_texture(8, |x, y| [0, (x * 32) as u8, (y * 32) as u8, 255]);
    let occlusion = linear_texture(8, |x, _| [(255 - x * 20) as u8, 0, 0, 255]);
    let material = Material {
        emissive: Vec3::new(0.05, 0.0, 0.02),
        metallic: 0.8,
        roughness: 0.9,
        normal_scale: 0.7,
        occlusion_strength: 0.5,
        dielectric_f0: Vec3::new(0.08, 0.05, 0.02),
        specular_weight: 0.8,
        clearcoat: 0.9,
        clearcoat_roughness: 0.6,
        clearcoat_normal_scale: 1.2,
        ior: 1.4,
        transmission: if transmissive { 0.8 } else { 0.0 },
        thickness: 0.6,
        attenuation_color: Vec3::new(0.8, 0.5, 0.3),
        attenuation_distance: 0.7,
        sheen_color: Vec3::new(0.8, 0.6, 0.9),
        sheen_roughness: 0.5,
        ..Material::default()
    };
    let textures = PbrTextures {
        base_color: bound(&base),
        emissive: bound(&base),
        metallic_roughness: bound(&mr),
        normal: bound(&bumps),
        occlusion: bound(&occlusion),
        specular: bound(&base),
        specular_color: bound(&occlusion),
        clearcoat: bound(&mr),
        clearcoat_roughness: bound(&occlusion),
        clearcoat_normal: bound(&bumps),
        transmission: bound(&mr),
        thickness: bound(&base),
        sheen_color: bound(&occlusion),
        sheen_roughness: bound(&base),
    };
    let mut lighting = lighting(true);
    if transmissive {
        let picture: Vec<[f32; 4]> = (0..40 * 30)
            .map(|i| [(i % 40) as f32 / 20.0, (i / 40) as f32 / 15.0, 0.3, 1.0])
            .collect();
        lighting.transmission = Some(TransmissionView {
            backdrop: Arc::new(Backdrop::new(40, 30, &picture).expect("backdrop")),
            view_projection: view_projection(),
        });
    }
    let model = Mat4::from_rotation_y(0.4) * Mat4::from_rotation_x(-0.3);
    let shader = PbrShader::new(
        model,
        view_projection(),
        &lighting,
        &material,
        textures,
        Pass::Color,
        (1, 1),
    )
    .with_mesh_attributes(false, false);
    let mesh = quad();
    let reference = render(&shader, &mesh, RendererOptions::default());
    let covered = reference.iter().filter(|c| c[3] > 0.0).count();
    assert!(covered > 1500, "{covered} pixels");
    for isa in crate::pipeline::compiled_supported() {
        let options = RendererOptions {
            isa: Some(isa),
            ..RendererOptions::default()
        };
        let image = render(&shader, &mesh, options);
        let same = image
            .iter()
            .zip(&reference)
            .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits));
        assert!(same, "{isa} differs from the default instruction set");
    }
    let single = render(&OneAtATime(&shader), &mesh, RendererOptions::default());
    let mut worst = 0.0f32;
    for (a, b) in single.iter().zip(&reference) {
        for c in 0..4 {
            worst = worst.max((a[c] - b[c]).abs());
        }
    }
    assert!(worst < 0.02, "one fragment at a time differs by {worst}");
}

/// A plane whose normal map encodes a constant tilt shades as the plane tilted by it: the
/// tangent frame follows `u` (+X) and `v` (image down, so the bitangent is +Y).
#[test]
fn a_normal_mapped_plane_shades_as_the_tilted_plane() {
    let lighting = lighting(false);
    for (mx, my) in [(0.5f32, 0.0f32), (0.0, 0.5), (-0.4, 0.3)] {
        let mz = (1.0 - mx * mx - my * my).sqrt();
        let encode = |m: f32| ((m * 0.5 + 0.5) * 255.0).round() as u8;
        let map = linear_texture(4, |_, _| [encode(mx), encode(my), encode(mz), 255]);
        // What the texels decode to (8-bit), as the shader sees them.
        let decoded = |m: f32| encode(m) as f32 / 255.0 * 2.0 - 1.0;
        let tilted = Vec3::new(decoded(mx), decoded(my), decoded(mz)).normalize();
        let material = Material {
            metallic: 0.0,
            roughness: 0.5,
            ..Material::default()
        };
        let mapped = PbrShader::new(
            Mat4::IDENTITY,
            view_projection(),
            &lighting,
            &material,
            PbrTextures {
                normal: bound(&map),
                ..PbrTextures::default()
            },
            Pass::Color,
            (1, 1),
        )
        .with_mesh_attributes(false, false);
        let plain = PbrShader::new(
            Mat4::IDENTITY,
            view_projection(),
            &lighting,
            &material,
            PbrTextures::default(),
            Pass::Color,
            (1, 1),
        )
        .with_mesh_attributes(false, false);
        let mut tilted_quad = quad();
        tilted_quad.normals = Some(vec![tilted; 4]);
        let a = render(&mapped, &quad(), RendererOptions::default());
        let b = render(&plain, &tilted_quad, RendererOptions::default());
        let flat = render(&plain, &quad(), RendererOptions::default());
        let mut worst = 0.0f32;
        let mut moved = 0.0f32;
        for ((a, b), f) in a.iter().zip(&b).zip(&flat) {
            for c in 0..3 {
                worst = worst.max((a[c] - b[c]).abs());
                moved = moved.max((a[c] - f[c]).abs());
            }
        }
        assert!(worst < 2e-3, "tilt ({mx}, {my}): differs by {worst}");
        assert!(moved > 0.05, "tilt ({mx}, {my}) changed nothing ({moved})");
    }
}

/// The normals pass writes the bent normal; back faces of double-sided materials flip it.
#[test]
fn the_normals_pass_writes_the_shading_normal() {
    let lighting = lighting(false);
    let map = linear_texture(4, |_, _| [191, 128, 221, 255]);
    let material = Material {
        double_sided: true,
        ..Material::default()
    };
    let shader = |model: Mat4| {
        PbrShader::new(
            model,
            view_projection(),
            &lighting,
            &material,
            PbrTextures {
                normal: bound(&map),
                ..PbrTextures::default()
            },
            Pass::Normals,
            (1, 1),
        )
        .with_mesh_attributes(false, false)
    };
    let front = render(&shader(Mat4::IDENTITY), &quad(), RendererOptions::default());
    let n = front.iter().find(|c| c[3] > 0.0).expect("covered");
    let want = Vec3::new(
        191.0 / 255.0 * 2.0 - 1.0,
        128.0 / 255.0 * 2.0 - 1.0,
        221.0 / 255.0 * 2.0 - 1.0,
    )
    .normalize();
    assert!(
        (Vec3::new(n[0], n[1], n[2]) - want).length() < 1e-3,
        "{n:?} vs {want}"
    );
    // Turned around: the back face shows; its normal faces the camera again.
    let back = render(
        &shader(Mat4::from_rotation_y(std::f32::consts::PI)),
        &quad(),
        RendererOptions::default(),
    );
    let n = back.iter().find(|c| c[3] > 0.0).expect("covered");
    assert!(n[2] > 0.5, "{n:?}");
    let _ = Arc::new(());
}

/// With the mesh's tangents the normal map bends in their frame: a plane whose map encodes a
/// tilt `m` shades as the plane tilted to `t m.x + b m.y + n m.z`, with `b = w (n × t)`, for a
/// tangent along +X (b = +Y: image up, the frame the derivatives give), a tangent along +Y
/// (the tilt turns by 90°) and a negative `w` (b flips), also under a mirroring model matrix
/// (which flips `w` back where it turns the plane's frame over).
#[test]
fn mesh_tangents_orient_the_normal_map() {
    let lighting = lighting(false);
    let (mx, my) = (0.45f32, -0.3f32);
    let mz = (1.0 - mx * mx - my * my).sqrt();
    let encode = |m: f32| ((m * 0.5 + 0.5) * 255.0).round() as u8;
    let map = linear_texture(4, |_, _| [encode(mx), encode(my), encode(mz), 255]);
    let decoded = |m: f32| encode(m) as f32 / 255.0 * 2.0 - 1.0;
    let m = Vec3::new(decoded(mx), decoded(my), decoded(mz));
    let material = Material {
        metallic: 0.0,
        roughness: 0.5,
        ..Material::default()
    };
    let cases = [
        (
            Mat4::IDENTITY,
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec3::X,
            Vec3::Y,
        ),
        (
            Mat4::IDENTITY,
            Vec4::new(0.0, 1.0, 0.0, 1.0),
            Vec3::Y,
            -Vec3::X,
        ),
        (
            Mat4::IDENTITY,
            Vec4::new(1.0, 0.0, 0.0, -1.0),
            Vec3::X,
            -Vec3::Y,
        ),
        // Mirrored in x: the world tangent is −X, the world normal stays +Z; the object's
        // bitangent +Y stays +Y.
        (
            Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            -Vec3::X,
            Vec3::Y,
        ),
    ];
    for (model, tangent, t, b) in cases {
        let mut with_tangents = quad();
        with_tangents.tangents = Some(vec![tangent; 4]);
        let mapped = PbrShader::new(
            model,
            view_projection(),
            &lighting,
            &material,
            PbrTextures {
                normal: bound(&map),
                ..PbrTextures::default()
            },
            Pass::Color,
            (1, 1),
        )
        .with_mesh_attributes(false, true);
        let plain = PbrShader::new(
            Mat4::IDENTITY,
            view_projection(),
            &lighting,
            &material,
            PbrTextures::default(),
            Pass::Color,
            (1, 1),
        )
        .with_mesh_attributes(false, false);
        let tilted = (t * m.x + b * m.y + Vec3::Z * m.z).normalize();
        // The plain plane drawn with the model's mirror folded into its positions (the same
        // pixels) and the expected normal.
        let mut expected = quad();
        for p in expected.positions.iter_mut() {
            *p = model.transform_point3(*p);
        }
        expected.normals = Some(vec![tilted; 4]);
        let a = render(&mapped, &with_tangents, RendererOptions::default());
        let e = render(&plain, &expected, RendererOptions::default());
        let mut worst = 0.0f32;
        let mut covered = 0;
        for (a, e) in a.iter().zip(&e) {
            covered += usize::from(a[3] > 0.0);
            for c in 0..3 {
                worst = worst.max((a[c] - e[c]).abs());
            }
        }
        assert!(covered > 1500, "{covered} pixels");
        assert!(
            worst < 2e-3,
            "tangent {tangent} under {model}: differs by {worst}"
        );
    }
}

/// A texture bound to the second texture coordinate set reads it: the quad with its real
/// coordinates in the second set and nonsense in the first draws as the quad textured through
/// the first; the draw interpolates only the sets its textures read.
#[test]
fn textures_read_the_coordinate_set_they_are_bound_to() {
    let lighting = lighting(true);
    let checker = linear_texture(8, |x, y| {
        if (x + y) % 2 == 0 {
            [230, 40, 40, 255]
        } else {
            [20, 90, 200, 255]
        }
    });
    let material = Material {
        metallic: 0.0,
        roughness: 0.6,
        ..Material::default()
    };
    let shader = |set: u32| {
        PbrShader::new(
            Mat4::from_rotation_y(0.3),
            view_projection(),
            &lighting,
            &material,
            PbrTextures {
                base_color: Some(Bound {
                    texture: &checker,
                    sampler: sampler(),
                    texcoord: set,
                }),
                ..PbrTextures::default()
            },
            Pass::Color,
            (1, 1),
        )
        .with_mesh_attributes(false, false)
    };
    assert_eq!(shader(0).varying_count(), at::OPTIONAL + 2);
    let mut second = quad();
    second.texcoords1 = second.texcoords.take();
    second.texcoords = Some(vec![Vec2::splat(0.37); 4]);
    let want = render(&shader(0), &quad(), RendererOptions::default());
    let got = render(&shader(1), &second, RendererOptions::default());
    let first_set = render(&shader(0), &second, RendererOptions::default());
    assert!(want.iter().filter(|c| c[3] > 0.0).count() > 1500);
    assert!(
        got == want,
        "the second set differs from the same coordinates in the first"
    );
    assert!(first_set != want, "the nonsense first set was read");
}
