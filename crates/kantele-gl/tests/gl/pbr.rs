//! PBR scenes (`Shading::Pbr`) drawn by the OpenGL backend against the rules of
//! `kantele_rules::shade::pbr` evaluated directly (scalar lanes) at each pixel centre's surface
//! point: punctual lights (directional, point with a range, spot) over dielectrics and metals of
//! several roughnesses under every tone map, the headlight, the built-in studio environment
//! (rotated, dimmed, with occlusion), metallic-roughness and normal textures (front and back
//! faces, and the normal pass), unlit materials, the specular, IOR, clear-coat and sheen
//! extensions; and a Lambert scene that the PBR data leaves unchanged. A large plane fills the picture, so every pixel is compared; the tolerance only
//! covers float rounding (GL's arithmetic differs from the CPU's in the last bits).
//!
//! Every test skips (prints "skipping: <reason>") where no headless GL context can be created.

use std::sync::Arc;

use glam::{DMat4, DVec3, DVec4, Mat4, Vec2, Vec3, Vec4};
use kantele_gl::GlBackend;
use kantele_lanes::{F32x8, Lanes, Scalar};
use kantele_rules::backend::{Backend, FrameImage, FrameView, Pass};
use kantele_rules::camera::{look_at, normal_matrix, perspective};
use kantele_rules::scene::{
    Draw, LightKind, Material, Mesh, PunctualLight, Scene, Shading, TextureBinding,
};
use kantele_rules::shade::environment::EnvironmentLight;
use kantele_rules::shade::pbr::{
    shade, tonemap, ClearcoatLayer, PbrLighting, Surface, Tonemap, DIELECTRIC_F0,
};
use kantele_rules::shade::sheen::SheenLayer;
use kantele_rules::shade::texture::{ColorSpace, Sampler, Texture};

use crate::common::gl_or_skip;

const W: u32 = 48;
const H: u32 = 36;

/// Half the side of the plane: it covers the whole picture from every camera used here.
const EXTENT: f32 = 6.0;

/// Largest difference allowed per channel: absolute plus relative to the expected value.
const ABSOLUTE: f32 = 1e-3;
const RELATIVE: f32 = 1e-3;

/// The plane's placement: tilted about x and y, lifted, so the model matrix matters.
fn model() -> Mat4 {
    Mat4::from_translation(Vec3::new(0.1, -0.2, -0.3))
        * Mat4::from_rotation_x(-0.35)
        * Mat4::from_rotation_y(0.2)
}

/// A square of side `2 × EXTENT` in its local z = 0 plane, normal +Z, counter-clockwise seen
/// from +Z; `u` grows along +x and `v` along −y.
fn plane() -> Mesh {
    let e = EXTENT;
    Mesh {
        name: "plane".into(),
        positions: vec![
            Vec3::new(-e, -e, 0.0),
            Vec3::new(e, -e, 0.0),
            Vec3::new(e, e, 0.0),
            Vec3::new(-e, e, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        texcoords: Some(vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        material: 0,
        ..Mesh::default()
    }
}

/// A PBR scene of the plane with `material`, `textures` and `lights`.
fn scene(material: Material, textures: Vec<Arc<Texture>>, lights: Vec<PunctualLight>) -> Scene {
    Scene {
        meshes: vec![plane()],
        materials: vec![material],
        textures,
        draws: vec![Draw {
            mesh: 0,
            model: model(),
            node_name: "plane".into(),
            node_index: 0,
        }],
        clear_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        resolution: (W, H),
        shading: Shading::Pbr,
        lights,
        ..Scene::default()
    }
}

/// Three lights: a directional one, a point light with a range and a spot light, above the
/// plane and in front of it.
fn lights() -> Vec<PunctualLight> {
    vec![
        PunctualLight {
            kind: LightKind::Directional,
            color: Vec3::new(1.2, 1.1, 0.9),
            position: Vec3::ZERO,
            direction: Vec3::new(0.3, -0.5, -0.8),
            range: None,
        },
        PunctualLight {
            kind: LightKind::Point,
            color: Vec3::new(0.8, 1.0, 1.4),
            position: Vec3::new(0.6, 0.5, 0.8),
            direction: Vec3::ZERO,
            range: Some(3.0),
        },
        PunctualLight {
            kind: LightKind::Spot {
                inner_cone_angle: 0.2,
                outer_cone_angle: 0.5,
            },
            color: Vec3::new(3.0, 2.0, 1.0),
            position: Vec3::new(-0.8, -0.4, 1.2),
            direction: Vec3::new(0.3, 0.1, -1.0),
            range: None,
        },
    ]
}

/// The frame: a perspective camera at `eye` looking at the plane's centre.
fn frame(scene: &Scene, eye: Vec3, pass: Pass) -> FrameView {
    let view = look_at(eye, Vec3::new(0.1, -0.2, -0.3), Vec3::Y);
    let projection = perspective(50f32.to_radians(), W as f32 / H as f32, 0.1, 20.0);
    FrameView {
        pass,
        ..FrameView::with_matrices(scene, view, projection, W, H)
    }
}

fn render(gl: &mut GlBackend, scene: &Arc<Scene>, view: &FrameView) -> FrameImage {
    gl.load(scene.clone()).expect("load");
    gl.render(view).expect("render");
    gl.read_frame().expect("read_frame")
}

/// The plane's world normal as the shaders compute it (normal matrix × +Z, normalised).
fn plane_normal() -> Vec3 {
    (normal_matrix(&model()) * Vec3::Z).normalize()
}

/// Where the eye ray through the centre of pixel `(x, y)` (row 0 at the top) meets the plane,
/// in `f64`.
fn surface_point(view: &FrameView, x: u32, y: u32) -> Vec3 {
    let ndc_x = (x as f64 + 0.5) / view.width as f64 * 2.0 - 1.0;
    let ndc_y = 1.0 - (y as f64 + 0.5) / view.height as f64 * 2.0;
    let inverse = (view.projection.as_dmat4() * view.view.as_dmat4()).inverse();
    let unproject = |z: f64| {
        let p: DVec4 = inverse * DVec4::new(ndc_x, ndc_y, z, 1.0);
        p.truncate() / p.w
    };
    let (near, far) = (unproject(-1.0), unproject(1.0));
    let m: DMat4 = model().as_dmat4();
    let origin = m.transform_point3(DVec3::ZERO);
    let normal = plane_normal().as_dvec3();
    let t = (origin - near).dot(normal) / (far - near).dot(normal);
    (near + (far - near) * t).as_vec3()
}

fn splat3(v: Vec3) -> [<Scalar as Lanes>::F32; 3] {
    [
        Scalar.splat_f32(v.x),
        Scalar.splat_f32(v.y),
        Scalar.splat_f32(v.z),
    ]
}

fn lane0(v: [<Scalar as Lanes>::F32; 3]) -> Vec3 {
    Vec3::new(v[0].extract(0), v[1].extract(0), v[2].extract(0))
}

/// What a pixel's surface is made of (after its textures).
#[derive(Clone, Copy, Debug)]
struct Params {
    base: Vec3,
    metallic: f32,
    roughness: f32,
    occlusion: f32,
    emissive: Vec3,
    unlit: bool,
    /// Dielectric reflectance and specular weight (`KHR_materials_ior`, `_specular`).
    dielectric_f0: Vec3,
    specular_weight: f32,
    /// Clear coat factor and roughness (its normal is the plane's); 0: none.
    clearcoat: (f32, f32),
    /// Sheen colour and roughness, after their textures; `None`: no sheen.
    sheen: Option<(Vec3, f32)>,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            base: Vec3::ONE,
            metallic: 1.0,
            roughness: 1.0,
            occlusion: 1.0,
            emissive: Vec3::ZERO,
            unlit: false,
            dielectric_f0: Vec3::splat(DIELECTRIC_F0),
            specular_weight: 1.0,
            clearcoat: (0.0, 0.0),
            sheen: None,
        }
    }
}

/// The rules' colour of the surface point `p` with normal `n`: shading (or the unlit colour)
/// plus emission, exposure and the tone map.
fn expected(lighting: &PbrLighting, params: &Params, n: Vec3, p: Vec3) -> Vec3 {
    let rgb = if params.unlit {
        params.base + params.emissive
    } else {
        let (factor, roughness) = params.clearcoat;
        let surface = Surface::<Scalar> {
            base: splat3(params.base),
            metallic: Scalar.splat_f32(params.metallic),
            roughness: Scalar.splat_f32(params.roughness),
            occlusion: Scalar.splat_f32(params.occlusion),
            normal: splat3(n),
            position: splat3(p),
            dielectric_f0: splat3(params.dielectric_f0.min(Vec3::ONE)),
            specular_weight: Scalar.splat_f32(params.specular_weight.clamp(0.0, 1.0)),
            clearcoat: (factor > 0.0).then(|| ClearcoatLayer {
                factor: Scalar.splat_f32(factor),
                roughness: Scalar.splat_f32(roughness),
                normal: splat3(plane_normal()),
            }),
            sheen: params.sheen.map(|(color, roughness)| SheenLayer {
                color: splat3(color.clamp(Vec3::ZERO, Vec3::ONE)),
                roughness: Scalar.splat_f32(roughness.clamp(0.0, 1.0)),
            }),
            transmission: None,
        };
        lane0(shade(Scalar, lighting, &surface, &splat3(params.emissive)))
    };
    lane0(tonemap(
        Scalar,
        lighting.tonemap,
        lighting.exposure,
        splat3(rgb),
    ))
}

/// Compares every pixel of `image` with `want(p)` at its surface point `p`; returns the largest
/// difference. Panics (naming `what`) past the tolerance or where alpha is not 1.
fn check_every_pixel(
    image: &FrameImage,
    view: &FrameView,
    what: &str,
    want: impl Fn(Vec3) -> Vec3,
) -> f32 {
    let mut worst = 0.0f32;
    for y in 0..view.height {
        for x in 0..view.width {
            let p = surface_point(view, x, y);
            let want = want(p);
            let got = Vec4::from_array(image.color[(y * view.width + x) as usize]);
            assert_eq!(got.w, 1.0, "{what}: alpha at ({x}, {y})");
            let error = (got.truncate() - want).abs();
            let bound = Vec3::splat(ABSOLUTE) + want.abs() * RELATIVE;
            assert!(
                error.cmple(bound).all(),
                "{what}: pixel ({x}, {y}) at {p}: GL {} vs rules {want}",
                got.truncate()
            );
            worst = worst.max(error.max_element());
        }
    }
    worst
}

/// A linear 2 × 2 texture of one texel.
fn constant_texture(texel: [u8; 4]) -> Arc<Texture> {
    Arc::new(Texture::from_rgba8(2, 2, &texel.repeat(4), ColorSpace::Linear).expect("texture"))
}

fn binding(texture: usize) -> Option<TextureBinding> {
    Some(TextureBinding {
        texture,
        sampler: Sampler::default(),
        texcoord: 0,
    })
}

fn unorm(byte: u8) -> f32 {
    byte as f32 / 255.0
}

/// Renders `scene` from `eye` and compares it with the rules for a surface of `params` with the
/// plane's normal.
fn check_scene(gl: &mut GlBackend, scene: Scene, eye: Vec3, params: &Params, what: &str) -> f32 {
    let scene = Arc::new(scene);
    let view = frame(&scene, eye, Pass::Color);
    let image = render(gl, &scene, &view);
    let lighting = PbrLighting::for_frame(&scene, &view);
    let n = plane_normal();
    check_every_pixel(&image, &view, what, |p| expected(&lighting, params, n, p))
}

const EYE: Vec3 = Vec3::new(0.5, 0.8, 2.5);

/// Punctual lights over dielectrics, metals and a half metal, smooth to rough, under the three
/// tone maps and several exposures; the headlight where a scene has no light.
#[test]
fn punctual_lights_follow_the_rules() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let cases = [
        (0.0, 0.25, Tonemap::None, 0.0),
        (0.0, 0.6, Tonemap::PbrNeutral, 0.5),
        (1.0, 0.3, Tonemap::Aces, -0.5),
        (1.0, 1.0, Tonemap::None, 1.0),
        (0.5, 0.45, Tonemap::PbrNeutral, 0.0),
        (1.0, 0.2, Tonemap::PbrNeutral, 1.5),
    ];
    let base = Vec3::new(0.9, 0.55, 0.3);
    for (metallic, roughness, tonemap, exposure) in cases {
        for headlight in [false, true] {
            let material = Material {
                base_color_factor: base.extend(1.0),
                metallic,
                roughness,
                emissive: Vec3::new(0.02, 0.01, 0.0),
                ..Material::default()
            };
            let lights = if headlight { Vec::new() } else { lights() };
            let mut scene = scene(material, Vec::new(), lights);
            scene.tonemap = tonemap;
            scene.exposure = exposure;
            let params = Params {
                base,
                metallic,
                roughness,
                occlusion: 1.0,
                emissive: Vec3::new(0.02, 0.01, 0.0),
                unlit: false,
                ..Params::default()
            };
            let what = format!(
                "metallic {metallic} roughness {roughness} {tonemap:?} EV {exposure} headlight {headlight}"
            );
            let worst = check_scene(&mut gl, scene, EYE, &params, &what);
            eprintln!("{what}: largest difference {worst:.2e}");
        }
    }
}

/// The built-in studio, rotated and dimmed, with one directional light: mirror-like to rough
/// (between two pre-filtered levels, on one, the last), dielectric and metal; occlusion
/// (strength 0.7) and a metallic-roughness texture on some.
#[test]
fn the_studio_environment_follows_the_rules() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    // Metallic-roughness texel: green 0.6 (roughness), blue 0.8 (metallic). Occlusion: red 0.5.
    let metallic_roughness = [0u8, 153, 204, 255];
    let occlusion = [128u8, 0, 0, 255];
    let cases = [
        (0.0, 0.0, false, false),
        (1.0, 0.0, false, false),
        (1.0, 0.3, true, false),
        (0.0, 0.4, false, true),
        (1.0, 0.7, true, true),
        (0.3, 1.0, false, false),
    ];
    let base = Vec3::new(0.95, 0.7, 0.45);
    for (metallic, roughness, occluded, textured) in cases {
        let mut material = Material {
            base_color_factor: base.extend(1.0),
            metallic,
            roughness,
            ..Material::default()
        };
        let mut textures = Vec::new();
        let (mut m, mut r, mut o) = (metallic, roughness, 1.0);
        if textured {
            material.metallic_roughness_texture = binding(textures.len());
            textures.push(constant_texture(metallic_roughness));
            m = (metallic * unorm(metallic_roughness[2])).clamp(0.0, 1.0);
            r = (roughness * unorm(metallic_roughness[1])).clamp(0.0, 1.0);
        }
        if occluded {
            material.occlusion_texture = binding(textures.len());
            material.occlusion_strength = 0.7;
            textures.push(constant_texture(occlusion));
            o = 1.0 + 0.7 * (unorm(occlusion[0]) - 1.0);
        }
        let mut scene = scene(
            material,
            textures,
            vec![PunctualLight {
                kind: LightKind::Directional,
                color: Vec3::splat(0.5),
                position: Vec3::ZERO,
                // Grazing from the side: no mirror highlight in view, where at roughness 0
                // (0.045 for punctual lights) a 1e-7 shift of the normal moves the colour
                // by 1e-3.
                direction: Vec3::new(1.0, -0.4, -0.2),
                range: None,
            }],
        );
        scene.environment = Some(EnvironmentLight {
            intensity: 0.8,
            rotation: 0.7,
            ..EnvironmentLight::studio()
        });
        let params = Params {
            base,
            metallic: m,
            roughness: r,
            occlusion: o,
            emissive: Vec3::ZERO,
            unlit: false,
            ..Params::default()
        };
        let what = format!(
            "studio: metallic {metallic} roughness {roughness} occluded {occluded} textured {textured}"
        );
        let worst = check_scene(&mut gl, scene, EYE, &params, &what);
        eprintln!("{what}: largest difference {worst:.2e}");
    }
}

/// A normal texture tilts the normal in the tangent frame of the texture coordinates
/// (`t = ∂p/∂u`, `b = ng × t`), scaled in x and y; the normal pass writes it, the colour
/// follows it; a double-sided plane seen from behind uses its negation.
#[test]
fn normal_textures_follow_the_rules() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let texel = [170u8, 90, 220, 255];
    let scale = 0.8;
    let base = Vec3::new(0.8, 0.8, 0.75);
    let material = Material {
        base_color_factor: base.extend(1.0),
        metallic: 0.0,
        roughness: 0.5,
        normal_texture: binding(0),
        normal_scale: scale,
        double_sided: true,
        ..Material::default()
    };
    // The tangent frame: ∂p/∂u along the model's +x, b = ng × t.
    let ng = plane_normal();
    let t = model().transform_vector3(Vec3::X).normalize();
    let t = (t - ng * ng.dot(t)).normalize();
    let b = ng.cross(t);
    let m = Vec3::new(
        (unorm(texel[0]) * 2.0 - 1.0) * scale,
        (unorm(texel[1]) * 2.0 - 1.0) * scale,
        unorm(texel[2]) * 2.0 - 1.0,
    );
    let mapped = (t * m.x + b * m.y + ng * m.z).normalize();
    let params = Params {
        base,
        metallic: 0.0,
        roughness: 0.5,
        occlusion: 1.0,
        emissive: Vec3::ZERO,
        unlit: false,
        ..Params::default()
    };
    // From the front, then from behind (the back face of a double-sided plane).
    let behind = Vec3::new(-0.4, -0.6, -2.5);
    for (eye, n, side) in [(EYE, mapped, "front"), (behind, -mapped, "back")] {
        let mut lights = lights();
        if side == "back" {
            // Light the back.
            for l in &mut lights {
                l.direction = -l.direction;
                l.position = -l.position;
            }
        }
        let mut scene = scene(material.clone(), vec![constant_texture(texel)], lights);
        scene.tonemap = Tonemap::None;
        let scene = Arc::new(scene);
        let normals_view = frame(&scene, eye, Pass::Normals);
        let image = render(&mut gl, &scene, &normals_view);
        let what = format!("normal texture, {side}: normal pass");
        let worst = check_every_pixel(&image, &normals_view, &what, |_| n);
        eprintln!("{what}: largest difference {worst:.2e}");

        let view = frame(&scene, eye, Pass::Color);
        let image = render(&mut gl, &scene, &view);
        let lighting = PbrLighting::for_frame(&scene, &view);
        let what = format!("normal texture, {side}: colour");
        let worst = check_every_pixel(&image, &view, &what, |p| expected(&lighting, &params, n, p));
        eprintln!("{what}: largest difference {worst:.2e}");
    }
}

/// The mesh's tangents orient the normal texture (`t = model × xyz`, `b = w (ng × t)`), and
/// textures bound to the second texture coordinate set read it: the plane's first set points at
/// one texel of a nearest-filtered base colour texture, its second set at another, and its
/// tangent runs along +y with a negative sign.
#[test]
fn mesh_tangents_and_the_second_coordinate_set_follow_the_rules() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let texel = [200u8, 100, 210, 255];
    let nearest = Sampler {
        mag_filter: kantele_rules::shade::texture::Filter::Nearest,
        min_filter: kantele_rules::shade::texture::MinFilter::Nearest,
        ..Sampler::default()
    };
    let set1 = |texture| {
        Some(TextureBinding {
            texture,
            sampler: nearest,
            texcoord: 1,
        })
    };
    let material = Material {
        base_color_texture: set1(0),
        metallic: 0.0,
        roughness: 0.5,
        normal_texture: set1(1),
        ..Material::default()
    };
    // Texels (0, 0) red and (1, 1) a pale blue; (1, 0) and (0, 1) black.
    let colors: Vec<u8> = [
        [255u8, 0, 0, 255],
        [0, 0, 0, 255],
        [0, 0, 0, 255],
        [64, 128, 230, 255],
    ]
    .concat();
    let base_texture =
        Arc::new(Texture::from_rgba8(2, 2, &colors, ColorSpace::Linear).expect("texture"));
    let mut scene = scene(
        material,
        vec![base_texture, constant_texture(texel)],
        lights(),
    );
    scene.tonemap = Tonemap::None;
    let mesh = &mut scene.meshes[0];
    mesh.texcoords = Some(vec![Vec2::splat(0.25); 4]);
    mesh.texcoords1 = Some(vec![Vec2::splat(0.75); 4]);
    mesh.tangents = Some(vec![Vec4::new(0.0, 1.0, 0.0, -1.0); 4]);
    let ng = plane_normal();
    let t = model().transform_vector3(Vec3::Y).normalize();
    let t = (t - ng * ng.dot(t)).normalize();
    let b = -ng.cross(t);
    let m = Vec3::new(
        unorm(texel[0]) * 2.0 - 1.0,
        unorm(texel[1]) * 2.0 - 1.0,
        unorm(texel[2]) * 2.0 - 1.0,
    );
    let mapped = (t * m.x + b * m.y + ng * m.z).normalize();
    let params = Params {
        base: Vec3::new(unorm(64), unorm(128), unorm(230)),
        metallic: 0.0,
        roughness: 0.5,
        ..Params::default()
    };
    let scene = Arc::new(scene);
    let normals_view = frame(&scene, EYE, Pass::Normals);
    let image = render(&mut gl, &scene, &normals_view);
    let worst = check_every_pixel(&image, &normals_view, "tangents: normal pass", |_| mapped);
    eprintln!("tangents, normal pass: largest difference {worst:.2e}");
    let view = frame(&scene, EYE, Pass::Color);
    let image = render(&mut gl, &scene, &view);
    let lighting = PbrLighting::for_frame(&scene, &view);
    let worst = check_every_pixel(&image, &view, "tangents, second set: colour", |p| {
        expected(&lighting, &params, mapped, p)
    });
    eprintln!("tangents, second set, colour: largest difference {worst:.2e}");
}

/// Unlit materials skip the lighting, but their colour (base + emission) is exposed and tone
/// mapped like every other.
#[test]
fn unlit_materials_are_tone_mapped() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let base = Vec3::new(0.9, 0.5, 0.2);
    let emissive = Vec3::new(0.6, 0.3, 0.1);
    for (tonemap, exposure) in [
        (Tonemap::None, -1.0),
        (Tonemap::PbrNeutral, 0.5),
        (Tonemap::Aces, 0.0),
    ] {
        let material = Material {
            base_color_factor: base.extend(1.0),
            emissive,
            unlit: true,
            ..Material::default()
        };
        let mut scene = scene(material, Vec::new(), lights());
        scene.tonemap = tonemap;
        scene.exposure = exposure;
        let params = Params {
            base,
            metallic: 1.0,
            roughness: 1.0,
            occlusion: 1.0,
            emissive,
            unlit: true,
            ..Params::default()
        };
        let what = format!("unlit {tonemap:?} EV {exposure}");
        let worst = check_scene(&mut gl, scene, EYE, &params, &what);
        eprintln!("{what}: largest difference {worst:.2e}");
    }
}

/// A Lambert scene is drawn by the Lambert program whatever PBR data it carries: the same
/// scene with lights, an environment, exposure, a tone map and PBR material properties and
/// textures renders bit for bit as without them.
#[test]
fn lambert_scenes_ignore_the_pbr_data() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let material = Material {
        base_color_factor: Vec4::new(0.9, 0.55, 0.3, 1.0),
        ..Material::default()
    };
    let mut plain = scene(material, Vec::new(), Vec::new());
    plain.shading = Shading::Lambert;
    let mut dressed = plain.clone();
    dressed.lights = lights();
    dressed.environment = Some(EnvironmentLight::studio());
    dressed.exposure = 1.5;
    dressed.tonemap = Tonemap::Aces;
    dressed.textures = vec![constant_texture([128, 128, 255, 255])];
    let m = &mut dressed.materials[0];
    m.metallic = 0.2;
    m.roughness = 0.3;
    m.metallic_roughness_texture = binding(0);
    m.normal_texture = binding(0);
    m.occlusion_texture = binding(0);
    for pass in [Pass::Color, Pass::Normals, Pass::Ids] {
        let plain = Arc::new(plain.clone());
        let dressed = Arc::new(dressed.clone());
        let view = frame(&plain, EYE, pass);
        let a = render(&mut gl, &plain, &view);
        let b = render(&mut gl, &dressed, &view);
        assert!(a.color == b.color, "{pass:?}: colour differs");
        assert!(a.depth == b.depth, "{pass:?}: depth differs");
        if pass == Pass::Color {
            // And it is lit: Lambert's ambient + diffuse, not black.
            assert!(a.color.iter().all(|c| c[0] > 0.0), "unlit pixels");
        }
    }
}

/// `KHR_materials_ior`, `KHR_materials_specular` and `KHR_materials_clearcoat` — factors and
/// textures (specular weight in alpha, an sRGB specular colour, coat weight in red, coat
/// roughness in green) — under a punctual light and the studio, as the rules shade them.
#[test]
fn specular_ior_and_clear_coat_follow_the_rules() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    // Specular texel: alpha 0.6. Specular colour (sRGB): a warm tint. Coat: red 0.8; coat
    // roughness: green 0.5.
    let specular = [0u8, 0, 0, 153];
    let specular_color = [255u8, 200, 120, 255];
    let coat = [204u8, 0, 0, 255];
    let coat_roughness = [0u8, 128, 0, 255];
    let f0_of_ior = |ior: f64| (((ior - 1.0) / (ior + 1.0)).powi(2)) as f32;
    let base = Vec3::new(0.3, 0.5, 0.8);
    // (ior, specular colour factor, weight, coat factor, coat roughness, textured)
    let cases = [
        (1.5, Vec3::ONE, 1.0, 0.0, 0.0, false),
        (2.0, Vec3::new(1.0, 0.5, 0.2), 0.7, 0.0, 0.0, false),
        (1.33, Vec3::splat(2.0), 1.0, 0.0, 0.0, true),
        (1.5, Vec3::ONE, 1.0, 1.0, 0.0, false),
        (1.5, Vec3::ONE, 0.5, 0.7, 0.4, true),
        (1.8, Vec3::new(0.8, 1.0, 1.0), 1.0, 1.0, 1.0, false),
    ];
    for (ior, color, weight, coat_factor, coat_rough, textured) in cases {
        let mut material = Material {
            base_color_factor: base.extend(1.0),
            metallic: 0.2,
            roughness: 0.35,
            dielectric_f0: Vec3::splat(f0_of_ior(ior)) * color,
            specular_weight: weight,
            clearcoat: coat_factor,
            clearcoat_roughness: coat_rough,
            ..Material::default()
        };
        let mut params = Params {
            base,
            metallic: 0.2,
            roughness: 0.35,
            dielectric_f0: Vec3::splat(f0_of_ior(ior)) * color,
            specular_weight: weight,
            clearcoat: (coat_factor, coat_rough),
            ..Params::default()
        };
        let mut textures = Vec::new();
        if textured {
            material.specular_texture = binding(textures.len());
            textures.push(constant_texture(specular));
            material.specular_color_texture = binding(textures.len());
            let srgb = Texture::from_rgba8(2, 2, &specular_color.repeat(4), ColorSpace::Srgb)
                .expect("texture");
            let decoded = srgb.sample_lod(&Sampler::default(), Vec2::splat(0.5), 0.0);
            textures.push(Arc::new(srgb));
            params.specular_weight = weight * unorm(specular[3]);
            params.dielectric_f0 *= decoded.truncate();
            if coat_factor > 0.0 {
                material.clearcoat_texture = binding(textures.len());
                textures.push(constant_texture(coat));
                material.clearcoat_roughness_texture = binding(textures.len());
                textures.push(constant_texture(coat_roughness));
                params.clearcoat = (
                    (coat_factor * unorm(coat[0])).clamp(0.0, 1.0),
                    (coat_rough * unorm(coat_roughness[1])).clamp(0.0, 1.0),
                );
            }
        }
        let mut scene = scene(
            material,
            textures,
            vec![PunctualLight {
                kind: LightKind::Directional,
                color: Vec3::splat(0.8),
                position: Vec3::ZERO,
                direction: Vec3::new(1.0, -0.4, -0.2),
                range: None,
            }],
        );
        scene.environment = Some(EnvironmentLight::studio());
        let what = format!(
            "ior {ior} colour {color} weight {weight} coat {coat_factor}/{coat_rough} textured {textured}"
        );
        let worst = check_scene(&mut gl, scene, EYE, &params, &what);
        eprintln!("{what}: largest difference {worst:.2e}");
    }
}

/// An eye low over the plane: its views meet the plane at `NdotV` from 0.28 to 0.94, so the
/// sheen's `Λ(NdotV)` takes both branches of its fit.
const LOW_EYE: Vec3 = Vec3::new(0.45, -1.27, 1.93);

/// `KHR_materials_sheen` — factors at several roughnesses (the smallest under the punctual
/// lights' floor, a colour above 1 that is clamped), textures (an sRGB colour texture, the
/// roughness in a linear texture's alpha), under a clear coat, over a metal — under three
/// punctual lights and the studio, seen from above and from low over the plane, as the rules
/// shade it. A sheen of colour black is no sheen: its roughness and textures leave the
/// picture bit for bit as without them.
#[test]
fn sheen_follows_the_rules() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    // Sheen colour (sRGB): a pale rose. Roughness: alpha 0.6, the other channels different so
    // that a wrong channel shows. llvmpipe decodes sRGB texels with an approximation (0.45591
    // for 180, where the rules and the formula give 0.45641): most of the textured cases'
    // difference, about 6e-4 of the colour texture alone.
    let sheen_color = [255u8, 180, 200, 255];
    let sheen_roughness = [30u8, 220, 90, 153];
    let color_texture =
        Texture::from_rgba8(2, 2, &sheen_color.repeat(4), ColorSpace::Srgb).expect("texture");
    let decoded = color_texture
        .sample_lod(&Sampler::default(), Vec2::splat(0.5), 0.0)
        .truncate();
    let color_texture = Arc::new(color_texture);
    let base = Vec3::new(0.25, 0.05, 0.1);
    // (sheen colour, sheen roughness, metallic, coat factor, coat roughness, textured)
    let cases = [
        (Vec3::new(1.0, 0.6, 0.7), 0.0, 0.0, 0.0, 0.0, false),
        (Vec3::new(1.0, 0.6, 0.7), 0.3, 0.0, 0.0, 0.0, false),
        (Vec3::new(0.9, 0.8, 0.3), 0.6, 0.0, 0.0, 0.0, false),
        (Vec3::new(1.5, 1.0, 0.5), 1.0, 0.0, 0.0, 0.0, false),
        (Vec3::ONE, 0.8, 0.0, 0.0, 0.0, true),
        (Vec3::new(1.0, 0.6, 0.7), 0.5, 0.0, 0.8, 0.2, false),
        (Vec3::new(0.8, 0.9, 1.0), 0.4, 1.0, 1.0, 0.5, true),
    ];
    for (color, roughness, metallic, coat_factor, coat_rough, textured) in cases {
        let mut material = Material {
            base_color_factor: base.extend(1.0),
            metallic,
            roughness: 0.7,
            clearcoat: coat_factor,
            clearcoat_roughness: coat_rough,
            sheen_color: color,
            sheen_roughness: roughness,
            ..Material::default()
        };
        let mut params = Params {
            base,
            metallic,
            roughness: 0.7,
            clearcoat: (coat_factor, coat_rough),
            sheen: Some((color, roughness)),
            ..Params::default()
        };
        let mut textures = Vec::new();
        if textured {
            material.sheen_color_texture = binding(textures.len());
            textures.push(color_texture.clone());
            material.sheen_roughness_texture = binding(textures.len());
            textures.push(constant_texture(sheen_roughness));
            params.sheen = Some((color * decoded, roughness * unorm(sheen_roughness[3])));
        }
        let mut scene = scene(material, textures, lights());
        scene.environment = Some(EnvironmentLight {
            intensity: 0.9,
            rotation: 0.4,
            ..EnvironmentLight::studio()
        });
        for (eye, seen) in [(EYE, "above"), (LOW_EYE, "low")] {
            let what = format!(
                "sheen {color} roughness {roughness} metallic {metallic} coat \
                 {coat_factor}/{coat_rough} textured {textured}, seen from {seen}"
            );
            let worst = check_scene(&mut gl, scene.clone(), eye, &params, &what);
            eprintln!("{what}: largest difference {worst:.2e}");
        }
    }

    // Black sheen: no sheen, whatever its roughness and textures.
    let material = Material {
        base_color_factor: base.extend(1.0),
        metallic: 0.0,
        roughness: 0.7,
        ..Material::default()
    };
    let plain = Arc::new(scene(material.clone(), vec![color_texture], lights()));
    let mut black = (*plain).clone();
    black.textures.push(constant_texture(sheen_roughness));
    black.materials[0] = Material {
        sheen_roughness: 0.5,
        sheen_color_texture: binding(0),
        sheen_roughness_texture: binding(1),
        ..material
    };
    let black = Arc::new(black);
    let view = frame(&plain, LOW_EYE, Pass::Color);
    let a = render(&mut gl, &plain, &view);
    let b = render(&mut gl, &black, &view);
    assert!(a.color == b.color, "a black sheen changes the picture");
    let lighting = PbrLighting::for_frame(&black, &view);
    let params = Params {
        base,
        metallic: 0.0,
        roughness: 0.7,
        ..Params::default()
    };
    let worst = check_every_pixel(&b, &view, "black sheen", |p| {
        expected(&lighting, &params, plane_normal(), p)
    });
    eprintln!("black sheen: largest difference {worst:.2e}");
}
