//! Built-in PBR scenes, the reference scenes of the metallic-roughness model: a grid of spheres
//! over metallic × roughness in the studio environment, a normal-mapped floor under point
//! and spot lights with ranges, transmissive panes and volumes over a checker, and sheened
//! cloth.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele_rules::camera;
use kantele_rules::scene::{
    Camera, Draw, LightKind, Material, Mesh, PunctualLight, Scene, Shading, TextureBinding,
};
use kantele_rules::shade::environment::EnvironmentLight;
use kantele_rules::shade::texture::{ColorSpace, Texture};

use crate::texture_util::trilinear_repeat;
use crate::SceneInfo;

/// A UV sphere of radius 1: `rings` bands from pole to pole, `segments` around, `u` around
/// (+X towards −Z), `v` from the north pole down.
fn sphere(rings: u32, segments: u32, material: usize) -> Mesh {
    let mut positions = Vec::new();
    let mut texcoords = Vec::new();
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let phi = u * 2.0 * PI;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ));
            texcoords.push(Vec2::new(u, v));
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    Mesh {
        name: "sphere".into(),
        normals: Some(positions.clone()),
        positions,
        texcoords: Some(texcoords),
        indices,
        material,
        ..Mesh::default()
    }
}

/// A square of side 2 in the XZ plane facing +Y, its texture repeated `repeat` times.
fn floor(material: usize, repeat: f32) -> Mesh {
    Mesh {
        name: "floor".into(),
        positions: vec![
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(-1.0, 0.0, -1.0),
        ],
        normals: Some(vec![Vec3::Y; 4]),
        texcoords: Some(vec![
            Vec2::new(0.0, repeat),
            Vec2::new(repeat, repeat),
            Vec2::new(repeat, 0.0),
            Vec2::new(0.0, 0.0),
        ]),
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Mesh::default()
    }
}

/// What a built-in PBR scene reports: its camera (the scene's own) and one entry per light.
fn built_in_info(scene: &Scene) -> SceneInfo {
    SceneInfo {
        camera_from_file: true,
        lights: scene.lights.iter().map(|_| "light".to_string()).collect(),
        ..SceneInfo::default()
    }
}

fn draw(mesh: usize, model: Mat4, name: String, node_index: usize) -> Draw {
    Draw {
        mesh,
        model,
        node_name: name,
        node_index,
    }
}

fn perspective(eye: Vec3, target: Vec3, yfov_deg: f32) -> Camera {
    Camera {
        view: camera::look_at(eye, target, Vec3::Y),
        yfov: yfov_deg.to_radians(),
        ymag: None,
        aspect_ratio: None,
        znear: 0.1,
        zfar: Some(100.0),
    }
}

/// `pbr-spheres`: 5 × 5 spheres, metallic 0 → 1 upwards, roughness 0 → 1 rightwards, a warm
/// base colour, in the built-in studio with one directional key light.
pub fn spheres() -> (Scene, SceneInfo) {
    let mut materials = Vec::new();
    let mut meshes = Vec::new();
    let mut draws = Vec::new();
    for row in 0..5 {
        for column in 0..5 {
            let metallic = row as f32 / 4.0;
            let roughness = column as f32 / 4.0;
            materials.push(Material {
                name: format!("metallic {metallic} roughness {roughness}"),
                base_color_factor: Vec4::new(0.95, 0.64, 0.38, 1.0),
                metallic,
                roughness,
                ..Material::default()
            });
            let index = materials.len() - 1;
            meshes.push(sphere(32, 48, index));
            let at = Vec3::new((column as f32 - 2.0) * 2.3, (row as f32 - 2.0) * 2.3, 0.0);
            draws.push(draw(
                index,
                Mat4::from_translation(at),
                format!("sphere m{row} r{column}"),
                index,
            ));
        }
    }
    let scene = Scene {
        meshes,
        materials,
        draws,
        camera: perspective(Vec3::new(0.0, 0.0, 21.0), Vec3::ZERO, 35.0),
        shading: Shading::Pbr,
        lights: vec![PunctualLight {
            kind: LightKind::Directional,
            color: Vec3::splat(2.0),
            position: Vec3::ZERO,
            direction: Vec3::new(0.5, -0.6, -0.6).normalize(),
            range: None,
        }],
        environment: Some(EnvironmentLight::studio()),
        clear_color: crate::shading::PBR_BACKGROUND,
        resolution: (800, 800),
        ..Scene::default()
    };
    let info = built_in_info(&scene);
    (scene, info)
}

/// A `size²` linear normal map of round bumps (`cells` per side), tangent space.
fn bump_map(size: u32, cells: u32) -> Texture {
    let rgba: Vec<u8> = (0..size * size)
        .flat_map(|i| {
            let (x, y) = (i % size, i / size);
            let cell = size as f32 / cells as f32;
            let p = Vec2::new(
                (x as f32 + 0.5) % cell / cell - 0.5,
                (y as f32 + 0.5) % cell / cell - 0.5,
            );
            // A spherical cap of radius 0.4: its slope tilts the normal outwards.
            let r2 = p.length_squared();
            let n = if r2 < 0.16 {
                let h = (0.16 - r2).sqrt();
                // ∂h/∂u = −u / h; v runs down the image, so +y of tangent space is −v.
                Vec3::new(p.x / h, -p.y / h, 1.0).normalize()
            } else {
                Vec3::Z
            };
            let encode = |c: f32| ((c * 0.5 + 0.5) * 255.0).round() as u8;
            [encode(n.x), encode(n.y), encode(n.z), 255]
        })
        .collect();
    Texture::from_rgba8(size, size, &rgba, ColorSpace::Linear)
        .expect("a generated bump map is a valid texture")
}

/// `pbr-lights`: a normal-mapped floor, a metal and a plastic sphere, lit by a point light and
/// a spot light with ranges only (no environment).
pub fn lights() -> (Scene, SceneInfo) {
    let materials = vec![
        Material {
            name: "bumpy floor".into(),
            base_color_factor: Vec4::new(0.8, 0.8, 0.78, 1.0),
            metallic: 0.0,
            roughness: 0.45,
            normal_texture: Some(TextureBinding {
                texture: 0,
                sampler: trilinear_repeat(),
                texcoord: 0,
            }),
            normal_scale: 1.0,
            ..Material::default()
        },
        Material {
            name: "gold".into(),
            base_color_factor: Vec4::new(1.0, 0.77, 0.34, 1.0),
            metallic: 1.0,
            roughness: 0.25,
            ..Material::default()
        },
        Material {
            name: "blue plastic".into(),
            base_color_factor: Vec4::new(0.05, 0.2, 0.7, 1.0),
            metallic: 0.0,
            roughness: 0.35,
            ..Material::default()
        },
    ];
    let meshes = vec![floor(0, 8.0), sphere(32, 48, 1), sphere(32, 48, 2)];
    let draws = vec![
        draw(0, Mat4::from_scale(Vec3::splat(6.0)), "floor".into(), 0),
        draw(
            1,
            Mat4::from_translation(Vec3::new(-1.4, 1.0, 0.0)),
            "gold sphere".into(),
            1,
        ),
        draw(
            2,
            Mat4::from_translation(Vec3::new(1.4, 1.0, 0.5)),
            "plastic sphere".into(),
            2,
        ),
    ];
    let scene = Scene {
        meshes,
        materials,
        textures: vec![Arc::new(bump_map(256, 8))],
        draws,
        camera: perspective(Vec3::new(0.0, 4.0, 8.0), Vec3::new(0.0, 0.6, 0.0), 40.0),
        shading: Shading::Pbr,
        lights: vec![
            PunctualLight {
                kind: LightKind::Point,
                color: Vec3::new(1.0, 0.85, 0.7) * 25.0,
                position: Vec3::new(-2.5, 3.0, 2.0),
                direction: Vec3::NEG_Z,
                range: Some(9.0),
            },
            PunctualLight {
                kind: LightKind::Spot {
                    inner_cone_angle: 0.25,
                    outer_cone_angle: 0.45,
                },
                color: Vec3::new(0.7, 0.8, 1.0) * 60.0,
                position: Vec3::new(2.5, 5.0, 1.0),
                direction: (Vec3::new(1.0, 0.0, 0.3) - Vec3::new(2.5, 5.0, 1.0)).normalize(),
                range: Some(12.0),
            },
        ],
        environment: None,
        clear_color: Vec4::new(0.02, 0.02, 0.025, 1.0),
        resolution: (960, 640),
        ..Scene::default()
    };
    let info = built_in_info(&scene);
    (scene, info)
}

/// A `size²` sRGB checker of `cells` squares per side, cream and slate.
fn checker(size: u32, cells: u32) -> Texture {
    let rgba: Vec<u8> = (0..size * size)
        .flat_map(|i| {
            let (x, y) = (i % size, i / size);
            let cell = (size / cells).max(1);
            if (x / cell + y / cell).is_multiple_of(2) {
                [232, 226, 210, 255]
            } else {
                [46, 58, 74, 255]
            }
        })
        .collect();
    Texture::from_rgba8(size, size, &rgba, ColorSpace::Srgb)
        .expect("a generated checker is a valid texture")
}

/// `pbr-glass`: over a checkered floor and wall, in the studio with a key light: a clear
/// blue-tinted thin-walled pane, a frosted pane (roughness 0.45), a clear glass sphere refracting the
/// checker (a volume 2 thick, IOR 1.5), a green-tinted glass sphere (Beer's law over 0.8) and
/// an opaque red sphere beside them (`KHR_materials_transmission`, `KHR_materials_volume`).
pub fn glass() -> (Scene, SceneInfo) {
    let glass = |name: &str, roughness: f32| Material {
        name: name.into(),
        base_color_factor: Vec4::ONE,
        metallic: 0.0,
        roughness,
        transmission: 1.0,
        double_sided: true,
        ..Material::default()
    };
    let materials = vec![
        Material {
            name: "checker".into(),
            base_color_factor: Vec4::ONE,
            base_color_texture: Some(TextureBinding {
                texture: 0,
                sampler: trilinear_repeat(),
                texcoord: 0,
            }),
            metallic: 0.0,
            roughness: 0.7,
            ..Material::default()
        },
        Material {
            base_color_factor: Vec4::new(0.75, 0.9, 1.0, 1.0),
            ..glass("blue pane", 0.0)
        },
        glass("frosted pane", 0.45),
        Material {
            thickness: 2.0,
            ..glass("clear volume", 0.0)
        },
        Material {
            thickness: 2.0,
            attenuation_color: Vec3::new(0.3, 0.85, 0.45),
            attenuation_distance: 0.8,
            ..glass("green volume", 0.05)
        },
        Material {
            name: "red".into(),
            base_color_factor: Vec4::new(0.7, 0.06, 0.04, 1.0),
            metallic: 0.0,
            roughness: 0.3,
            ..Material::default()
        },
    ];
    let meshes = vec![
        floor(0, 6.0),
        floor(1, 1.0),
        floor(2, 1.0),
        sphere(32, 48, 3),
        sphere(32, 48, 4),
        sphere(32, 48, 5),
    ];
    // Panes stand upright facing the camera (+Z): the floor square turned about X.
    let upright = Mat4::from_rotation_x(PI / 2.0);
    let draws = vec![
        draw(0, Mat4::from_scale(Vec3::splat(6.0)), "floor".into(), 0),
        draw(
            0,
            Mat4::from_translation(Vec3::new(0.0, 3.0, -3.0))
                * upright
                * Mat4::from_scale(Vec3::new(6.0, 1.0, 3.0)),
            "wall".into(),
            1,
        ),
        draw(
            1,
            Mat4::from_translation(Vec3::new(-2.6, 1.1, 0.8))
                * upright
                * Mat4::from_scale(Vec3::new(0.9, 1.0, 1.1)),
            "blue pane".into(),
            2,
        ),
        draw(
            2,
            Mat4::from_translation(Vec3::new(2.6, 1.1, 0.8))
                * upright
                * Mat4::from_scale(Vec3::new(0.9, 1.0, 1.1)),
            "frosted pane".into(),
            3,
        ),
        draw(
            3,
            Mat4::from_translation(Vec3::new(-0.75, 0.9, 1.2)) * Mat4::from_scale(Vec3::splat(0.9)),
            "clear sphere".into(),
            4,
        ),
        draw(
            4,
            Mat4::from_translation(Vec3::new(0.95, 0.9, 1.0)) * Mat4::from_scale(Vec3::splat(0.9)),
            "green sphere".into(),
            5,
        ),
        draw(
            5,
            Mat4::from_translation(Vec3::new(0.1, 0.6, -1.4)) * Mat4::from_scale(Vec3::splat(0.6)),
            "red sphere".into(),
            6,
        ),
    ];
    let scene = Scene {
        meshes,
        materials,
        textures: vec![Arc::new(checker(256, 8))],
        draws,
        camera: perspective(Vec3::new(0.0, 2.6, 7.5), Vec3::new(0.0, 1.0, 0.0), 40.0),
        shading: Shading::Pbr,
        lights: vec![PunctualLight {
            kind: LightKind::Directional,
            color: Vec3::splat(2.0),
            position: Vec3::ZERO,
            direction: Vec3::new(0.4, -0.8, -0.5).normalize(),
            range: None,
        }],
        environment: Some(EnvironmentLight::studio()),
        clear_color: crate::shading::PBR_BACKGROUND,
        resolution: (960, 640),
        ..Scene::default()
    };
    let info = built_in_info(&scene);
    (scene, info)
}

/// A `size²` weave of `threads` threads per side, as a sheen's two textures: sRGB warp and weft
/// colours (gold and rose), and linear roughness in alpha (0.25 on the threads, 1 in the gaps
/// between them).
fn weave(size: u32, threads: u32) -> [Texture; 2] {
    let mut color = Vec::with_capacity((size * size * 4) as usize);
    let mut roughness = Vec::with_capacity((size * size * 4) as usize);
    let cell = (size / threads).max(1);
    for i in 0..size * size {
        let (x, y) = (i % size, i / size);
        let (cx, cy) = (x / cell, y / cell);
        let warp_on_top = (cx + cy).is_multiple_of(2);
        let (fx, fy) = (x % cell, y % cell);
        let gap = fx == 0 || fy == 0;
        color.extend_from_slice(if warp_on_top {
            &[240, 200, 110, 255]
        } else {
            &[230, 150, 170, 255]
        });
        roughness.extend_from_slice(&[0, 0, 0, if gap { 255 } else { 64 }]);
    }
    let texture = |rgba: &[u8], space| {
        Texture::from_rgba8(size, size, rgba, space).expect("a generated weave is a valid texture")
    };
    [
        texture(&color, ColorSpace::Srgb),
        texture(&roughness, ColorSpace::Linear),
    ]
}

/// `pbr-sheen`: cloth (`KHR_materials_sheen`) in the studio with a key light and a warm point
/// light: four columns of spheres — black velvet with a white sheen, dark red with a pink
/// one, navy with a gold one, and the navy base without a sheen — over sheen roughness 0.2,
/// 0.5 and 0.8 (rows, top to bottom), on a floor of woven cloth whose sheen colour and
/// roughness are textures.
pub fn sheen() -> (Scene, SceneInfo) {
    let cloth = |name: String, base: Vec3, sheen_color: Vec3, sheen_roughness: f32| Material {
        name,
        base_color_factor: base.extend(1.0),
        metallic: 0.0,
        roughness: 0.8,
        sheen_color,
        sheen_roughness,
        ..Material::default()
    };
    let columns = [
        ("black velvet", Vec3::splat(0.01), Vec3::ONE),
        (
            "red velvet",
            Vec3::new(0.25, 0.01, 0.02),
            Vec3::new(1.0, 0.6, 0.7),
        ),
        (
            "navy and gold",
            Vec3::new(0.02, 0.03, 0.12),
            Vec3::new(1.0, 0.8, 0.3),
        ),
        ("navy", Vec3::new(0.02, 0.03, 0.12), Vec3::ZERO),
    ];
    let sampler = || TextureBinding {
        texture: 0,
        sampler: trilinear_repeat(),
        texcoord: 0,
    };
    let mut materials = vec![Material {
        name: "woven floor".into(),
        base_color_factor: Vec4::new(0.08, 0.05, 0.06, 1.0),
        metallic: 0.0,
        roughness: 0.9,
        sheen_color: Vec3::ONE,
        sheen_color_texture: Some(sampler()),
        sheen_roughness: 1.0,
        sheen_roughness_texture: Some(TextureBinding {
            texture: 1,
            ..sampler()
        }),
        ..Material::default()
    }];
    let mut meshes = vec![floor(0, 8.0)];
    let mut draws = vec![draw(
        0,
        Mat4::from_scale(Vec3::splat(7.0)),
        "floor".into(),
        0,
    )];
    for (row, sheen_roughness) in [0.2f32, 0.5, 0.8].into_iter().enumerate() {
        for (column, (name, base, sheen_color)) in columns.iter().enumerate() {
            materials.push(cloth(
                format!("{name}, sheen roughness {sheen_roughness}"),
                *base,
                *sheen_color,
                sheen_roughness,
            ));
            let index = materials.len() - 1;
            meshes.push(sphere(32, 48, index));
            let at = Vec3::new(
                (column as f32 - 1.5) * 2.2,
                1.0 + (2 - row) as f32 * 2.2,
                0.0,
            );
            draws.push(draw(
                index,
                Mat4::from_translation(at),
                format!("sphere r{row} c{column}"),
                index,
            ));
        }
    }
    let scene = Scene {
        meshes,
        materials,
        textures: weave(128, 16).map(Arc::new).to_vec(),
        draws,
        camera: perspective(Vec3::new(0.0, 4.0, 15.0), Vec3::new(0.0, 3.0, 0.0), 38.0),
        shading: Shading::Pbr,
        lights: vec![
            PunctualLight {
                kind: LightKind::Directional,
                color: Vec3::splat(2.0),
                position: Vec3::ZERO,
                direction: Vec3::new(0.5, -0.5, -0.7).normalize(),
                range: None,
            },
            PunctualLight {
                kind: LightKind::Point,
                color: Vec3::new(40.0, 30.0, 20.0),
                position: Vec3::new(-4.0, 6.5, 4.0),
                direction: Vec3::NEG_Z,
                range: Some(20.0),
            },
        ],
        environment: Some(EnvironmentLight::studio()),
        clear_color: crate::shading::PBR_BACKGROUND,
        resolution: (960, 720),
        ..Scene::default()
    };
    let info = built_in_info(&scene);
    (scene, info)
}
