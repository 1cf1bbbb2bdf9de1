//! Transmission (`KHR_materials_transmission`, `KHR_materials_volume`) drawn by the OpenGL
//! backend against the rules of `kantele_rules::shade::transmission` and `shade::pbr`
//! evaluated directly (scalar lanes) at each pixel centre's point on a transmissive pane in
//! front of a checkered, unlit wall: a thin pane, rough and thick panes of three indices of
//! refraction with textures and a light behind them, a volume that attenuates, a multisampled
//! frame, a frame wider than the largest backdrop, the 8-bit target and the normal pass.
//!
//! The rules read the backdrop that the frame's definition names — the scene without its
//! transmissive and blended draws, no tone map, exposure 1, at `backdrop_size`, one sample —
//! drawn here by the OpenGL backend as a scene of its own and read back, so the pane's pixels
//! test the shader's refraction, projection, level of detail, filtering, attenuation and mix
//! against the rules on the same texels. Away from the pane the frame equals that backdrop.
//!
//! Every test skips (prints "skipping: <reason>") where no headless GL context can be created.

use std::sync::Arc;

use glam::{DVec3, DVec4, Mat4, Vec2, Vec3, Vec4};
use kantele_gl::GlBackend;
use kantele_lanes::{F32x8, Lanes, Scalar};
use kantele_rules::backend::{Backend, FrameImage, FrameView};
use kantele_rules::camera::{look_at, normal_matrix, perspective};
use kantele_rules::multisample::SampleCount;
use kantele_rules::scene::{
    Draw, LightKind, Material, Mesh, PunctualLight, Scene, Shading, TextureBinding,
};
use kantele_rules::shade::environment::EnvironmentLight;
use kantele_rules::shade::pbr::{shade, tonemap, PbrLighting, Surface, Tonemap, DIELECTRIC_F0};
use kantele_rules::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};
use kantele_rules::shade::transmission::{
    backdrop_size, Backdrop, TransmissionLayer, TransmissionView, Volume,
};

use crate::common::gl_or_skip;

const W: u32 = 48;
const H: u32 = 36;

/// Largest difference allowed per channel: absolute plus relative to the expected value (as
/// the PBR tests: float rounding only).
const ABSOLUTE: f32 = 1e-3;
const RELATIVE: f32 = 1e-3;

/// Half the side of the pane, in its local units.
const PANE: f32 = 0.8;
/// Pixels whose point lies this close to the pane's edge (local units) are not compared: GL
/// and the rules may disagree on which surface covers them.
const MARGIN: f32 = 0.04;

/// The eye and the point it looks at.
const EYE: Vec3 = Vec3::new(0.3, 0.4, 2.6);
const TARGET: Vec3 = Vec3::new(0.0, 0.0, -0.5);

/// A square of side `2 × half` in its local z = 0 plane, normal +Z, counter-clockwise seen
/// from +Z, `u` along +x and `v` along −y (from 0 to `repeat`), on material `material`.
fn square(half: f32, repeat: f32, material: usize) -> Mesh {
    let (e, r) = (half, repeat);
    Mesh {
        name: "square".into(),
        positions: vec![
            Vec3::new(-e, -e, 0.0),
            Vec3::new(e, -e, 0.0),
            Vec3::new(e, e, 0.0),
            Vec3::new(-e, e, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        texcoords: Some(vec![
            Vec2::new(0.0, r),
            Vec2::new(r, r),
            Vec2::new(r, 0.0),
            Vec2::new(0.0, 0.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Mesh::default()
    }
}

/// The wall behind the pane: unlit, a 4 × 4 checker of saturated colours (sharp texels,
/// repeated: cells of 0.375 units), so the backdrop has edges for the refraction to move.
fn wall_material() -> (Material, Arc<Texture>) {
    let colors: [[u8; 4]; 4] = [
        [230, 40, 30, 255],
        [20, 200, 60, 255],
        [30, 60, 240, 255],
        [250, 230, 40, 255],
    ];
    let texels: Vec<u8> = (0..16).flat_map(|i| colors[(i % 4 + i / 4) % 4]).collect();
    let texture = Texture::from_rgba8(4, 4, &texels, ColorSpace::Srgb).expect("texture");
    let material = Material {
        unlit: true,
        base_color_texture: Some(TextureBinding {
            texture: 0,
            sampler: Sampler {
                wrap_s: Wrap::Repeat,
                wrap_t: Wrap::Repeat,
                mag_filter: Filter::Nearest,
                min_filter: MinFilter::Nearest,
            },
            texcoord: 0,
        }),
        ..Material::default()
    };
    (material, Arc::new(texture))
}

/// The pane's placement: turned about y and x, lifted towards the eye, scaled by `scale`.
fn pane_model(scale: Vec3) -> Mat4 {
    Mat4::from_translation(Vec3::new(0.05, 0.0, 0.2))
        * Mat4::from_rotation_y(0.3)
        * Mat4::from_rotation_x(-0.2)
        * Mat4::from_scale(scale)
}

/// What a test varies: the pane's material (its textures are the scene's textures 1 and 2
/// where it names them), its scale, the lights and the tone map.
struct Setup {
    pane: Material,
    /// Linear 2 × 2 textures of one texel each (transmission, thickness), textures 1, 2.
    textures: Vec<[u8; 4]>,
    scale: Vec3,
    lights: Vec<PunctualLight>,
    environment: bool,
    tonemap: Tonemap,
    exposure: f32,
}

fn scene(setup: &Setup, (width, height): (u32, u32)) -> Scene {
    let (wall, checker) = wall_material();
    let mut textures = vec![checker];
    for texel in &setup.textures {
        textures.push(Arc::new(
            Texture::from_rgba8(2, 2, &texel.repeat(4), ColorSpace::Linear).expect("texture"),
        ));
    }
    Scene {
        meshes: vec![square(6.0, 8.0, 0), square(PANE, 1.0, 1)],
        materials: vec![wall, setup.pane.clone()],
        textures,
        draws: vec![
            Draw {
                mesh: 0,
                model: Mat4::from_translation(Vec3::new(0.0, 0.0, -1.5)),
                node_name: "wall".into(),
                node_index: 0,
            },
            Draw {
                mesh: 1,
                model: pane_model(setup.scale),
                node_name: "pane".into(),
                node_index: 1,
            },
        ],
        clear_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        resolution: (width, height),
        shading: Shading::Pbr,
        lights: setup.lights.clone(),
        environment: setup.environment.then(|| EnvironmentLight {
            intensity: 0.7,
            rotation: 0.4,
            ..EnvironmentLight::studio()
        }),
        tonemap: setup.tonemap,
        exposure: setup.exposure,
        ..Scene::default()
    }
}

fn frame(scene: &Scene, (width, height): (u32, u32)) -> FrameView {
    let view = look_at(EYE, TARGET, Vec3::Y);
    let projection = perspective(55f32.to_radians(), width as f32 / height as f32, 0.1, 20.0);
    FrameView::with_matrices(scene, view, projection, width, height)
}

fn render(gl: &mut GlBackend, scene: &Arc<Scene>, view: &FrameView) -> FrameImage {
    gl.load(scene.clone()).expect("load");
    gl.render(view).expect("render");
    gl.read_frame().expect("read_frame")
}

/// The backdrop of `scene` seen as `view`, by its definition: the scene without transmissive
/// and blended draws, linear (no tone map, exposure 0 EV), drawn at `backdrop_size` with the
/// same camera by the OpenGL backend at 1×, read back into the rules' chain; and that picture.
fn backdrop(gl: &mut GlBackend, scene: &Scene, view: &FrameView) -> (Backdrop, FrameImage) {
    let mut opaque = scene.clone();
    opaque.draws.retain(|d| {
        let material = &scene.materials[scene.meshes[d.mesh].material];
        !material.has_transmission()
            && material.alpha_mode != kantele_rules::scene::AlphaMode::Blend
    });
    opaque.tonemap = Tonemap::None;
    opaque.exposure = 0.0;
    let (width, height) = backdrop_size(view.width, view.height);
    let opaque = Arc::new(opaque);
    let backdrop_view = FrameView {
        width,
        height,
        ..*view
    };
    let samples = gl.samples();
    gl.set_samples(SampleCount::X1).expect("1x");
    let image = render(gl, &opaque, &backdrop_view);
    gl.set_samples(samples).expect("samples");
    let chain = Backdrop::new(width, height, &image.color).expect("backdrop");
    (chain, image)
}

/// Where the eye ray through the centre of pixel `(x, y)` (row 0 at the top) meets the plane
/// through `origin` with normal `normal`, in `f64`.
fn ray_hit(view: &FrameView, x: u32, y: u32, origin: Vec3, normal: Vec3) -> Vec3 {
    let ndc_x = (x as f64 + 0.5) / view.width as f64 * 2.0 - 1.0;
    let ndc_y = 1.0 - (y as f64 + 0.5) / view.height as f64 * 2.0;
    let inverse = (view.projection.as_dmat4() * view.view.as_dmat4()).inverse();
    let unproject = |z: f64| {
        let p: DVec4 = inverse * DVec4::new(ndc_x, ndc_y, z, 1.0);
        p.truncate() / p.w
    };
    let (near, far) = (unproject(-1.0), unproject(1.0));
    let (origin, normal): (DVec3, DVec3) = (origin.as_dvec3(), normal.as_dvec3());
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

fn unorm(byte: u8) -> f32 {
    byte as f32 / 255.0
}

/// The pane as the rules see it after its textures: transmission factor and thickness.
fn pane_layer(setup: &Setup) -> (f32, f32) {
    let m = &setup.pane;
    let texel = |binding: Option<TextureBinding>, channel: usize| {
        binding.map_or(1.0, |b| unorm(setup.textures[b.texture - 1][channel]))
    };
    let factor = (m.transmission * texel(m.transmission_texture, 0)).clamp(0.0, 1.0);
    let thickness = (m.thickness * texel(m.thickness_texture, 1)).max(0.0);
    (factor, thickness)
}

/// The rules' colour of the pane at `p` (normal `n`), with transmission `factor` (0: as if
/// opaque, for the sensitivity checks).
fn expected(
    lighting: &PbrLighting,
    setup: &Setup,
    volume: Volume,
    (factor, thickness): (f32, f32),
    n: Vec3,
    p: Vec3,
) -> Vec3 {
    let m = &setup.pane;
    let base = m.base_color_factor.truncate();
    let surface = Surface::<Scalar> {
        base: splat3(base),
        metallic: Scalar.splat_f32(m.metallic),
        roughness: Scalar.splat_f32(m.roughness),
        occlusion: Scalar.splat_f32(1.0),
        normal: splat3(n),
        position: splat3(p),
        dielectric_f0: splat3(Vec3::splat(DIELECTRIC_F0)),
        specular_weight: Scalar.splat_f32(1.0),
        clearcoat: None,
        sheen: None,
        transmission: Some(TransmissionLayer {
            factor: Scalar.splat_f32(factor),
            thickness: Scalar.splat_f32(thickness),
            volume,
        }),
    };
    let rgb = lane0(shade(Scalar, lighting, &surface, &splat3(m.emissive)));
    lane0(tonemap(
        Scalar,
        lighting.tonemap,
        lighting.exposure,
        splat3(rgb),
    ))
}

/// What [`check`] found.
struct Checked {
    /// The frame.
    image: FrameImage,
    /// Pane pixels compared.
    pane_pixels: usize,
    /// Largest difference GL − rules on the pane.
    worst: f32,
    /// Largest change the transmission makes to the rules' colour on the pane (against the
    /// same pane with factor 0): what the comparison is sensitive to.
    transmission_effect: f32,
}

/// Renders the scene of `setup` at `size` and `samples` and compares every pixel well inside
/// the pane with the rules; with `tonemap` none and exposure 0, every pixel off the pane with
/// the backdrop. Panics (naming `what`) past the tolerance.
fn check(
    gl: &mut GlBackend,
    setup: &Setup,
    size: (u32, u32),
    samples: SampleCount,
    what: &str,
) -> Checked {
    let scene = scene(setup, size);
    let view = frame(&scene, size);
    let (chain, backdrop_image) = backdrop(gl, &scene, &view);
    let chain = Arc::new(chain);
    gl.set_samples(samples).expect("samples");
    let scene = Arc::new(scene);
    let image = render(gl, &scene, &view);
    gl.set_samples(SampleCount::X1).expect("1x");

    let model = pane_model(setup.scale);
    let mut lighting = PbrLighting::for_frame(&scene, &view);
    lighting.transmission = Some(TransmissionView {
        backdrop: chain.clone(),
        view_projection: view.projection * view.view,
    });
    let m = &setup.pane;
    let volume = Volume::new(
        m.ior,
        m.attenuation_color,
        m.attenuation_distance,
        &model,
        &chain,
    );
    let layer = pane_layer(setup);
    let n = (normal_matrix(&model) * Vec3::Z).normalize();
    let origin = model.transform_point3(Vec3::ZERO);
    let to_local = model.inverse();
    let same_size = backdrop_size(size.0, size.1) == size;
    let linear = setup.tonemap == Tonemap::None && setup.exposure == 0.0;
    let mut checked = Checked {
        image,
        pane_pixels: 0,
        worst: 0.0,
        transmission_effect: 0.0,
    };
    for y in 0..view.height {
        for x in 0..view.width {
            let i = (y * view.width + x) as usize;
            let got = Vec4::from_array(checked.image.color[i]);
            assert_eq!(got.w, 1.0, "{what}: alpha at ({x}, {y})");
            let p = ray_hit(&view, x, y, origin, n);
            let local = to_local.transform_point3(p);
            let inside = local.x.abs().max(local.y.abs());
            if inside > PANE + MARGIN && same_size && linear && samples == SampleCount::X1 {
                // Off the pane: the wall as the backdrop shows it.
                let want = Vec4::from_array(backdrop_image.color[i]).truncate();
                assert!(
                    (got.truncate() - want).abs().max_element() <= 1e-6,
                    "{what}: pixel ({x}, {y}) off the pane: frame {} vs backdrop {want}",
                    got.truncate()
                );
            }
            if inside > PANE - MARGIN {
                continue;
            }
            let want = expected(&lighting, setup, volume, layer, n, p);
            let error = (got.truncate() - want).abs();
            let bound = Vec3::splat(ABSOLUTE) + want.abs() * RELATIVE;
            assert!(
                error.cmple(bound).all(),
                "{what}: pixel ({x}, {y}) at {p}: GL {} vs rules {want}",
                got.truncate()
            );
            let opaque = expected(&lighting, setup, volume, (0.0, layer.1), n, p);
            checked.pane_pixels += 1;
            checked.worst = checked.worst.max(error.max_element());
            checked.transmission_effect = checked
                .transmission_effect
                .max((want - opaque).abs().max_element());
        }
    }
    eprintln!(
        "{what}: {} pane pixels, largest difference {:.2e}, transmission changes up to {:.3}",
        checked.pane_pixels, checked.worst, checked.transmission_effect
    );
    assert!(
        checked.pane_pixels >= 100,
        "{what}: only {} pane pixels",
        checked.pane_pixels
    );
    assert!(
        checked.transmission_effect > 0.05,
        "{what}: the transmission hardly shows"
    );
    checked
}

/// A light behind the pane (between it and the wall), which only transmission lets through,
/// and a directional light from the front.
fn lights() -> Vec<PunctualLight> {
    vec![
        PunctualLight {
            kind: LightKind::Point,
            color: Vec3::new(1.5, 1.2, 0.9),
            position: Vec3::new(-0.1, 0.1, -0.6),
            direction: Vec3::ZERO,
            range: Some(4.0),
        },
        PunctualLight {
            kind: LightKind::Directional,
            color: Vec3::new(0.6, 0.6, 0.7),
            position: Vec3::ZERO,
            direction: Vec3::new(0.5, -0.3, -0.8),
            range: None,
        },
    ]
}

fn glass(roughness: f32) -> Material {
    Material {
        base_color_factor: Vec4::new(0.9, 0.95, 1.0, 1.0),
        metallic: 0.0,
        roughness,
        transmission: 1.0,
        ..Material::default()
    }
}

/// A thin (thickness 0), smooth pane of IOR 1.5 under the studio: the backdrop read under
/// each pixel, level 0; off the pane the frame is the backdrop itself.
#[test]
fn a_thin_pane_shows_the_backdrop() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let setup = Setup {
        pane: glass(0.0),
        textures: Vec::new(),
        scale: Vec3::ONE,
        lights: Vec::new(),
        environment: true,
        tonemap: Tonemap::None,
        exposure: 0.0,
    };
    check(&mut gl, &setup, (W, H), SampleCount::X1, "thin pane");
}

/// Rough panes with a volume (thickness from its texture's green channel, transmission from
/// its texture's red one): the refracted exit point, the blurred levels read trilinearly, the
/// transmitted lobe of a light behind the pane; IOR 1.5 and 1.25 (half the blur and lobe
/// widening), and IOR 1 (no blur: level 0 at any roughness).
#[test]
fn rough_thick_panes_refract_and_blur() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    for (ior, roughness, tonemap) in [
        (1.5, 0.45, Tonemap::PbrNeutral),
        (1.25, 0.3, Tonemap::None),
        (1.0, 0.6, Tonemap::Aces),
    ] {
        let pane = Material {
            ior,
            transmission: 0.9,
            transmission_texture: Some(TextureBinding {
                texture: 1,
                sampler: Sampler::default(),
                texcoord: 0,
            }),
            thickness: 0.8,
            thickness_texture: Some(TextureBinding {
                texture: 2,
                sampler: Sampler::default(),
                texcoord: 0,
            }),
            ..glass(roughness)
        };
        let setup = Setup {
            pane,
            textures: vec![[204, 0, 0, 255], [0, 128, 0, 255]],
            scale: Vec3::ONE,
            lights: lights(),
            environment: true,
            tonemap,
            exposure: 0.3,
        };
        let what = format!("thick pane: IOR {ior} roughness {roughness} {tonemap:?}");
        check(&mut gl, &setup, (W, H), SampleCount::X1, &what);
    }
}

/// A volume that attenuates (attenuation colour and distance, Beer's law along the refracted
/// path), its thickness stretched by the model's scale along z; without an environment (the
/// split-sum table is still read) and with the lights.
#[test]
fn a_volume_attenuates_along_its_path() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let pane = Material {
        thickness: 0.3,
        attenuation_color: Vec3::new(0.8, 0.4, 0.1),
        attenuation_distance: 0.5,
        ..glass(0.2)
    };
    let setup = Setup {
        pane,
        textures: Vec::new(),
        scale: Vec3::new(1.0, 1.2, 2.0),
        lights: lights(),
        environment: false,
        tonemap: Tonemap::None,
        exposure: 0.0,
    };
    let attenuated = check(&mut gl, &setup, (W, H), SampleCount::X1, "volume");
    // The same pane without attenuation: the attenuation shows in the picture.
    let clear = Setup {
        pane: Material {
            attenuation_distance: f32::INFINITY,
            ..setup.pane.clone()
        },
        ..setup
    };
    let unattenuated = check(&mut gl, &clear, (W, H), SampleCount::X1, "clear volume");
    let largest = attenuated
        .image
        .color
        .iter()
        .zip(&unattenuated.image.color)
        .map(|(a, b)| (b[2] - a[2]).abs())
        .fold(0.0f32, f32::max);
    assert!(
        largest > 0.05,
        "attenuation changes blue by {largest} at most"
    );
}

/// A 4× frame reads the same one-sample backdrop: its pane pixels follow the rules too.
#[test]
fn a_multisampled_frame_reads_a_one_sample_backdrop() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    if gl.max_samples() < 4 {
        eprintln!("skipping: the driver offers {} samples", gl.max_samples());
        return;
    }
    let setup = Setup {
        pane: Material {
            thickness: 0.4,
            ..glass(0.35)
        },
        textures: Vec::new(),
        scale: Vec3::ONE,
        lights: lights(),
        environment: true,
        tonemap: Tonemap::PbrNeutral,
        exposure: 0.0,
    };
    check(&mut gl, &setup, (W, H), SampleCount::X4, "4x");
}

/// A frame wider than the largest backdrop: the backdrop is drawn scaled down to fit
/// (`backdrop_size`), and the pane reads it at the rules' coordinates.
#[test]
fn a_wide_frame_reads_a_smaller_backdrop() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let size = (2400, 40);
    assert_ne!(backdrop_size(size.0, size.1), size);
    let setup = Setup {
        pane: Material {
            thickness: 0.5,
            ..glass(0.25)
        },
        textures: Vec::new(),
        scale: Vec3::ONE,
        lights: Vec::new(),
        environment: true,
        tonemap: Tonemap::None,
        exposure: 0.0,
    };
    check(&mut gl, &setup, size, SampleCount::X1, "wide frame");
}

/// The 8-bit target draws the same frame (its backdrop stays float), to within its
/// quantisation; the normal pass draws no backdrop and writes the pane's normal.
#[test]
fn the_fast_target_and_the_normal_pass_draw_transmissive_scenes() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    let setup = Setup {
        pane: Material {
            thickness: 0.4,
            ..glass(0.3)
        },
        textures: Vec::new(),
        scale: Vec3::ONE,
        lights: Vec::new(),
        environment: true,
        tonemap: Tonemap::PbrNeutral,
        exposure: 0.0,
    };
    let reference = check(&mut gl, &setup, (W, H), SampleCount::X1, "float target");
    let scene = Arc::new(scene(&setup, (W, H)));
    let view = frame(&scene, (W, H));
    gl.set_fast_target(true);
    let fast = render(&mut gl, &scene, &view);
    gl.set_fast_target(false);
    for (i, (a, b)) in fast.color.iter().zip(&reference.image.color).enumerate() {
        for c in 0..3 {
            let want = b[c].clamp(0.0, 1.0);
            assert!(
                (a[c] - want).abs() <= 0.5 / 255.0 + 1e-3,
                "pixel {i}: 8-bit {a:?} vs float {b:?}"
            );
        }
    }
    let normals = render(
        &mut gl,
        &scene,
        &FrameView {
            pass: kantele_rules::backend::Pass::Normals,
            ..view
        },
    );
    let model = pane_model(Vec3::ONE);
    let n = (normal_matrix(&model) * Vec3::Z).normalize();
    let centre = normals.color[(H / 2 * W + W / 2) as usize];
    assert!(
        (Vec3::new(centre[0], centre[1], centre[2]) - n)
            .abs()
            .max_element()
            < 1e-5,
        "normal pass at the centre: {centre:?}, pane normal {n}"
    );
}
