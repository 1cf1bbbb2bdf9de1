//! The user's face culling ([`crate::LoadOptions::cull`]), applied to a loaded scene through
//! what every backend already draws: a material's `double_sided` and the triangles' winding.
//! Backends cull the back faces of single-sided materials and draw double-sided ones from both
//! sides (back faces lit with their normal flipped).

use kantele_rules::scene::{Scene, Topology};
use kantele_rules::state::CullMode;

use crate::mesh_util::flat_normals;

/// Makes `scene` draw with face culling `cull`, whatever its materials said:
///
/// - [`CullMode::None`]: every material becomes double-sided (both faces drawn).
/// - [`CullMode::Back`]: every material becomes single-sided (back faces culled).
/// - [`CullMode::Front`]: every material becomes single-sided and every triangle of every mesh
///   is wound the other way (its second and third indices swapped), so the backends' back-face
///   cull removes the faces that were in front. Normals are kept as they were (as an OpenGL
///   front-face cull keeps them): the faces left are lit as back faces of single-sided
///   materials are, by their own normals. A triangle mesh without normals first gets the flat
///   normals of its original winding ([`flat_normals`]), so reversing it does not turn them.
///
/// Lines and points have no faces and are left as they are.
pub fn override_culling(scene: &mut Scene, cull: CullMode) {
    for material in &mut scene.materials {
        material.double_sided = cull == CullMode::None;
    }
    if cull != CullMode::Front {
        return;
    }
    for mesh in &mut scene.meshes {
        if mesh.topology != Topology::Triangles {
            continue;
        }
        if mesh.normals.is_none() {
            flat_normals(mesh);
        }
        for triangle in mesh.indices.chunks_exact_mut(3) {
            triangle.swap(1, 2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use kantele_rules::scene::{Material, Mesh};

    fn scene() -> Scene {
        let triangle = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![0, 1, 2],
            ..Mesh::default()
        };
        let lines = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X],
            indices: vec![0, 1],
            topology: Topology::Lines,
            material: 1,
            ..Mesh::default()
        };
        let two_sided = Material {
            double_sided: true,
            ..Material::default()
        };
        Scene {
            meshes: vec![triangle, lines],
            materials: vec![Material::default(), two_sided],
            ..Scene::default()
        }
    }

    #[test]
    fn each_mode_sets_every_material_and_front_reverses_triangles_only() {
        let mut none = scene();
        override_culling(&mut none, CullMode::None);
        assert!(none.materials.iter().all(|m| m.double_sided));
        assert_eq!(none.meshes[0].indices, [0, 1, 2]);

        let mut back = scene();
        override_culling(&mut back, CullMode::Back);
        assert!(back.materials.iter().all(|m| !m.double_sided));
        assert_eq!(back.meshes[0].indices, [0, 1, 2]);

        let mut front = scene();
        override_culling(&mut front, CullMode::Front);
        assert!(front.materials.iter().all(|m| !m.double_sided));
        // Flat normals were made from the original winding (de-indexed: corners 0, 1, 2), then
        // the winding was reversed; the normal still points along +Z.
        let mesh = &front.meshes[0];
        assert_eq!(mesh.indices, [0, 2, 1]);
        assert_eq!(mesh.normals.as_deref(), Some(&[Vec3::Z; 3][..]));
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[mesh.indices[k] as usize]);
        assert!((b - a).cross(c - a).z < 0.0, "now clockwise seen from +Z");
        assert_eq!(front.meshes[1].indices, [0, 1]);
    }
}
