//! A huge textured ground plane seen from just above it.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele_rules::camera;
use kantele_rules::scene::{Camera, Draw, Light, Material, Mesh, Scene, TextureBinding};

use super::cube::cube_mesh;
use super::CLEAR_COLOR;
use crate::texture_util::{checker, trilinear_repeat};
use crate::SceneInfo;

/// Half the side of the ground quad.
const EXTENT: f32 = 1000.0;
/// Checker repetitions across the quad.
const REPEATS: f32 = 400.0;

/// The ground: a quad at y = 0 reaching ±[`EXTENT`], facing up, texture repeated [`REPEATS`]
/// times.
fn ground_mesh(material: usize) -> Mesh {
    let corners = [(-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (1.0, -1.0)];
    Mesh {
        name: "ground".into(),
        positions: corners
            .iter()
            .map(|&(x, z)| Vec3::new(x * EXTENT, 0.0, z * EXTENT))
            .collect(),
        normals: Some(vec![Vec3::Y; 4]),
        texcoords: Some(
            corners
                .iter()
                .map(|&(x, z)| Vec2::new((x + 1.0) * 0.5 * REPEATS, (z + 1.0) * 0.5 * REPEATS))
                .collect(),
        ),
        colors: None,
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        topology: kantele_rules::scene::Topology::Triangles,
        texcoords1: None,
        tangents: None,
    }
}

/// An upright triangle with red, green and blue corners, counter-clockwise towards +z.
fn triangle_mesh(material: usize) -> Mesh {
    let positions = vec![
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.8, 0.0),
    ];
    Mesh {
        name: "triangle".into(),
        normals: Some(vec![Vec3::Z; 3]),
        texcoords: None,
        colors: Some(vec![
            Vec4::new(1.0, 0.1, 0.1, 1.0),
            Vec4::new(0.1, 1.0, 0.1, 1.0),
            Vec4::new(0.1, 0.2, 1.0, 1.0),
        ]),
        indices: vec![0, 1, 2],
        positions,
        material,
        topology: kantele_rules::scene::Topology::Triangles,
        texcoords1: None,
        tangents: None,
    }
}

pub fn scene() -> (Scene, SceneInfo) {
    let texture = checker(64, 2, [220, 220, 210], [70, 80, 70]);
    let materials = vec![
        Material {
            name: "ground-unlit".into(),
            base_color_texture: Some(TextureBinding {
                texture: 0,
                sampler: trilinear_repeat(),
                texcoord: 0,
            }),
            unlit: true,
            ..Material::default()
        },
        Material {
            name: "cube-lambert".into(),
            base_color_factor: Vec4::new(0.9, 0.45, 0.15, 1.0),
            ..Material::default()
        },
        Material {
            name: "triangle-unlit".into(),
            double_sided: true,
            unlit: true,
            ..Material::default()
        },
    ];
    let mut cube = cube_mesh(1);
    cube.texcoords = None;
    let draw = |mesh, model, name: &str, node_index| Draw {
        mesh,
        model,
        node_name: name.into(),
        node_index,
    };
    let eye = Vec3::new(0.0, 1.5, 0.0);
    let scene = Scene {
        file_cameras: Vec::new(),
        meshes: vec![ground_mesh(0), cube, triangle_mesh(2)],
        materials,
        textures: vec![Arc::new(texture)],
        draws: vec![
            draw(0, Mat4::IDENTITY, "ground", 2),
            draw(
                1,
                Mat4::from_translation(Vec3::new(-1.2, 0.5, -5.0)) * Mat4::from_rotation_y(0.6),
                "cube",
                3,
            ),
            draw(
                2,
                Mat4::from_translation(Vec3::new(2.0, 0.0, -9.0)) * Mat4::from_rotation_y(-0.3),
                "triangle",
                4,
            ),
        ],
        // Just above the ground, looking at the horizon (slightly down): the ground reaches
        // behind the eye, so it is clipped at the near plane; the far plane is at infinity.
        camera: Camera {
            view: camera::look_at(eye, Vec3::new(0.0, 1.0, -20.0), Vec3::Y),
            yfov: 60f32.to_radians(),
            ymag: None,
            aspect_ratio: None,
            znear: 0.1,
            zfar: None,
        },
        light: Light::Directional {
            to_light: Vec3::new(-0.4, 0.8, 0.45).normalize(),
            color: Vec3::ONE,
        },
        ambient: 0.15,
        clear_color: CLEAR_COLOR,
        resolution: (1024, 768),
        ..Scene::default()
    };
    let info = SceneInfo {
        cameras: vec!["camera".into()],
        camera_from_file: true,
        lights: vec!["sun".into()],
        ..SceneInfo::default()
    };
    (scene, info)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ground_faces_up_and_reaches_behind_the_eye() {
        let (scene, _) = scene();
        let ground = &scene.meshes[0];
        let [a, b, c] = [0, 1, 2].map(|k| ground.positions[ground.indices[k] as usize]);
        assert!((b - a).cross(c - a).y > 0.0);
        // Some of the ground is behind the camera (positive eye-space z).
        assert!(ground
            .positions
            .iter()
            .any(|p| scene.camera.view.transform_point3(*p).z > 0.0));
        assert_eq!(scene.triangle_count(), 2 + 12 + 1);
    }
}
