//! The scene features the loaders added (BLEND draw order, emissive colour and texture) drawn by
//! Kantele and by OpenGL: the pictures must agree as on the reference scenes. Also the shared
//! real-world samples that exercise them, when present (`$KANTELE_SHARED/realworld`).
//! Skips (with a message) where EGL/OpenGL is unavailable.

use std::sync::Arc;

use glam::{Mat4, Vec3, Vec4};
use kantele::scene::{AlphaMode, Camera, Draw, Material, Mesh, Scene, TextureBinding};
use kantele::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};
use kantele_gl::GlBackend;
use kantele_testkit::compare::{compare, edge_mask};

use crate::common::{gl_or_skip, render_both};

/// Renders with both backends and checks agreement (the reference-scene tolerances).
fn assert_agree(name: &str, scene: Scene, gl: &mut GlBackend) {
    let (a, b, ids) = render_both(scene, gl);
    let c = compare(&a, &b, Some(&edge_mask(&ids)), 3).expect("same size");
    eprintln!(
        "{name:28} coverage {:.4}%  mean {:.3}  max {:3}  interior>3: {}",
        100.0 * c.coverage_mismatch_fraction(),
        c.mean_color_diff,
        c.max_color_diff,
        c.interior_over_bound
    );
    let drawn = a.depth.iter().filter(|d| **d < 1.0).count();
    assert!(drawn > c.pixels / 20, "{name}: only {drawn} pixels drawn");
    assert!(c.coverage_mismatch_fraction() <= 0.001, "{name}: coverage");
    assert!(c.mean_color_diff < 1.0, "{name}: mean colour");
    assert!(
        c.interior_over_bound <= c.pixels / 100,
        "{name}: interior colour"
    );
}

fn quad(material: usize) -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        texcoords: Some(vec![
            glam::Vec2::new(0.0, 1.0),
            glam::Vec2::new(1.0, 1.0),
            glam::Vec2::new(1.0, 0.0),
            glam::Vec2::new(0.0, 0.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Mesh::default()
    }
}

fn draw(mesh: usize, model: Mat4) -> Draw {
    Draw {
        mesh,
        model,
        node_name: String::new(),
        node_index: mesh,
    }
}

#[test]
fn blend_order_and_emission_agree_with_opengl() {
    let Some(mut gl) = gl_or_skip() else {
        return;
    };
    // A 4 × 4 checker as the emissive texture.
    let texels: Vec<u8> = (0..16)
        .flat_map(|i| {
            if (i % 4 + i / 4) % 2 == 0 {
                [255, 128, 0, 255]
            } else {
                [0, 64, 255, 255]
            }
        })
        .collect();
    let texture = Texture::from_rgba8(4, 4, &texels, ColorSpace::Srgb).expect("texture");
    let sampler = Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        mag_filter: Filter::Nearest,
        min_filter: MinFilter::Nearest,
    };
    let materials = vec![
        // 0: a half-transparent red panel (BLEND), listed first but in front.
        Material {
            base_color_factor: Vec4::new(1.0, 0.0, 0.0, 0.5),
            alpha_mode: AlphaMode::Blend,
            double_sided: true,
            ..Material::default()
        },
        // 1: a grey wall behind, glowing through an emissive texture.
        Material {
            base_color_factor: Vec4::new(0.3, 0.3, 0.3, 1.0),
            emissive: Vec3::new(0.5, 0.5, 0.5),
            emissive_texture: Some(TextureBinding {
                texture: 0,
                sampler,
                texcoord: 0,
            }),
            ..Material::default()
        },
        // 2: a second, farther BLEND panel listed last (must be drawn before panel 0).
        Material {
            base_color_factor: Vec4::new(0.0, 0.0, 1.0, 0.5),
            alpha_mode: AlphaMode::Blend,
            ..Material::default()
        },
    ];
    let scene = Scene {
        meshes: vec![quad(0), quad(1), quad(2)],
        materials,
        textures: vec![Arc::new(texture)],
        draws: vec![
            draw(0, Mat4::from_translation(Vec3::new(-0.3, 0.0, 0.5))),
            draw(1, Mat4::from_scale(Vec3::new(3.0, 3.0, 1.0))),
            draw(2, Mat4::from_translation(Vec3::new(0.3, 0.2, 0.25))),
        ],
        camera: Camera::framing(Vec3::ZERO, 2.0, Vec3::Z, 4.0 / 3.0),
        resolution: (200, 150),
        ..Scene::default()
    };
    assert_agree("blend-order+emissive", scene, &mut gl);

    // The real samples that exercise these features.
    let Some(dir) = kantele_testkit::shared_dir("realworld") else {
        return;
    };
    for file in [
        "AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb",
        "ClearCoatTest/glTF-Binary/ClearCoatTest.glb",
        "TextureTransformMultiTest/glTF-Binary/TextureTransformMultiTest.glb",
    ] {
        let mut scene = kantele_scene::load_scene(&dir.join(file))
            .expect("load")
            .scene;
        scene.resolution = (320, 240);
        assert_agree(file.split('/').next().unwrap_or(file), scene, &mut gl);
    }
}
