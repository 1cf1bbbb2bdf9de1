//! The textured cube of the thesis (Listings 6 and 7).

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele_rules::camera;
use kantele_rules::scene::{Camera, Draw, Light, Material, Mesh, Scene, TextureBinding};

use super::CLEAR_COLOR;
use crate::texture_util::{checker, trilinear_repeat};
use crate::SceneInfo;

/// The cube's 24 vertices (four per face) with their texture coordinates, as Listing 7 gives
/// them: front (+z), right (+x), back (−z), left (−x), top (+y), bottom (−y).
const VERTICES: [([f32; 3], [f32; 2]); 24] = [
    ([-0.5, 0.5, 0.5], [0.0, 0.0]),
    ([-0.5, -0.5, 0.5], [0.0, 1.0]),
    ([0.5, -0.5, 0.5], [1.0, 1.0]),
    ([0.5, 0.5, 0.5], [1.0, 0.0]),
    ([0.5, 0.5, 0.5], [0.0, 0.0]),
    ([0.5, -0.5, 0.5], [0.0, 1.0]),
    ([0.5, -0.5, -0.5], [1.0, 1.0]),
    ([0.5, 0.5, -0.5], [1.0, 0.0]),
    ([0.5, 0.5, -0.5], [0.0, 0.0]),
    ([0.5, -0.5, -0.5], [0.0, 1.0]),
    ([-0.5, -0.5, -0.5], [1.0, 1.0]),
    ([-0.5, 0.5, -0.5], [1.0, 0.0]),
    ([-0.5, 0.5, -0.5], [0.0, 0.0]),
    ([-0.5, -0.5, -0.5], [0.0, 1.0]),
    ([-0.5, -0.5, 0.5], [1.0, 1.0]),
    ([-0.5, 0.5, 0.5], [1.0, 0.0]),
    ([-0.5, 0.5, -0.5], [0.0, 0.0]),
    ([-0.5, 0.5, 0.5], [0.0, 1.0]),
    ([0.5, 0.5, 0.5], [1.0, 1.0]),
    ([0.5, 0.5, -0.5], [1.0, 0.0]),
    ([-0.5, -0.5, 0.5], [0.0, 0.0]),
    ([-0.5, -0.5, -0.5], [0.0, 1.0]),
    ([0.5, -0.5, -0.5], [1.0, 1.0]),
    ([0.5, -0.5, 0.5], [1.0, 0.0]),
];

/// Where the thesis puts the cube: `translate(3, 0, 5)`.
const CUBE_POSITION: Vec3 = Vec3::new(3.0, 0.0, 5.0);

/// The unit cube (−0.5..0.5) with per-face normals, white vertex colours and the listing's
/// texture coordinates. Each face is two triangles `(0, 1, 2)`, `(0, 2, 3)` of its four
/// vertices — the listing repeats the bottom face's first triangle by mistake; this is the
/// intended set of 12. The listing's order is counter-clockwise seen from outside, as glTF wants.
pub fn cube_mesh(material: usize) -> Mesh {
    let positions: Vec<Vec3> = VERTICES.iter().map(|(p, _)| Vec3::from(*p)).collect();
    let texcoords = VERTICES.iter().map(|(_, t)| Vec2::from(*t)).collect();
    let mut indices = Vec::with_capacity(36);
    let mut normals = Vec::with_capacity(24);
    for face in 0..6u32 {
        let base = 4 * face;
        indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        let [a, b, c] = [0, 1, 2].map(|k| positions[(base + k) as usize]);
        normals.extend([(b - a).cross(c - a).normalize(); 4]);
    }
    Mesh {
        name: "cube".into(),
        positions,
        normals: Some(normals),
        texcoords: Some(texcoords),
        colors: Some(vec![Vec4::ONE; 24]),
        indices,
        material,
        topology: kantele_rules::scene::Topology::Triangles,
        texcoords1: None,
        tangents: None,
    }
}

/// The thesis' camera frustum: `left/right = ∓0.25·aspect`, `bottom/top = ∓0.25`, near 0.5,
/// far 100, i.e. a vertical field of view of `2·atan(0.25 / 0.5)`.
fn thesis_camera(view: Mat4) -> Camera {
    Camera {
        view,
        yfov: 2.0 * (0.25f32 / 0.5).atan(),
        ymag: None,
        aspect_ratio: None,
        znear: 0.5,
        zfar: Some(100.0),
    }
}

pub fn scene() -> (Scene, SceneInfo) {
    let texture = checker(256, 8, [235, 235, 235], [40, 60, 110]);
    let material = Material {
        name: "checker-unlit".into(),
        base_color_texture: Some(TextureBinding {
            texture: 0,
            sampler: trilinear_repeat(),
            texcoord: 0,
        }),
        unlit: true,
        ..Material::default()
    };
    // Above, in front and to the right of the cube, so that the top and right faces are seen at
    // grazing angles and the mip level changes across them.
    let eye = CUBE_POSITION + Vec3::new(1.6, 1.3, 2.7);
    let view = camera::look_at(eye, CUBE_POSITION, Vec3::Y);
    let scene = Scene {
        meshes: vec![cube_mesh(0)],
        materials: vec![material],
        textures: vec![Arc::new(texture)],
        draws: vec![Draw {
            mesh: 0,
            model: Mat4::from_translation(CUBE_POSITION),
            node_name: "cube".into(),
            node_index: 1,
        }],
        camera: thesis_camera(view),
        file_cameras: Vec::new(),
        light: Light::Headlight,
        ambient: 0.1,
        clear_color: CLEAR_COLOR,
        resolution: (1300, 700),
        ..Scene::default()
    };
    let info = SceneInfo {
        cameras: vec!["camera".into()],
        camera_from_file: true,
        ..SceneInfo::default()
    };
    (scene, info)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_faces_are_counter_clockwise_from_outside() {
        let mesh = cube_mesh(0);
        assert_eq!(mesh.positions.len(), 24);
        assert_eq!(mesh.triangle_count(), 12);
        let mut seen = Vec::new();
        for tri in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[tri[k] as usize]);
            let normal = (b - a).cross(c - a);
            let centroid = (a + b + c) / 3.0;
            // The cube is centred on the origin: outward is away from it.
            assert!(normal.dot(centroid) > 0.0, "triangle {tri:?} faces inwards");
            let mut key = tri.to_vec();
            key.sort();
            assert!(!seen.contains(&key), "triangle {tri:?} repeated");
            seen.push(key);
        }
        for (n, p) in mesh.normals.as_ref().unwrap().iter().zip(&mesh.positions) {
            assert!((n.length() - 1.0).abs() < 1e-6);
            assert!(n.dot(*p) > 0.0);
        }
    }

    #[test]
    fn cube_is_in_view_and_faces_the_camera_from_the_front() {
        let (scene, _) = scene();
        let aspect = scene.resolution.0 as f32 / scene.resolution.1 as f32;
        let clip_from_world = scene.camera.projection(aspect) * scene.camera.view;
        let model = scene.draws[0].model;
        let mesh = &scene.meshes[0];
        for p in &mesh.positions {
            let clip = clip_from_world * model.transform_point3(*p).extend(1.0);
            let ndc = clip.truncate() / clip.w;
            assert!(
                clip.w > 0.0 && ndc.abs().max_element() < 1.0,
                "{p} out of view"
            );
        }
        // Front, right and top faces are visible (counter-clockwise in NDC), the others culled.
        let mut front_facing = 0;
        for tri in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| {
                let clip = clip_from_world
                    * model
                        .transform_point3(mesh.positions[tri[k] as usize])
                        .extend(1.0);
                clip.truncate().truncate() / clip.w
            });
            if (b - a).perp_dot(c - a) > 0.0 {
                front_facing += 1;
            }
        }
        assert_eq!(front_facing, 6);
    }
}
