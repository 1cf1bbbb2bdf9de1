//! The vertex layout every backend draws scene meshes with: one definition, so the CPU,
//! OpenGL and CUDA backends see identical vertex data.

use glam::{Vec2, Vec3, Vec4};

use crate::scene::Mesh;

/// The vertex layout of scene meshes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct StandardVertex {
    /// Object-space position.
    pub position: Vec3,
    /// Object-space normal.
    pub normal: Vec3,
    /// Texture coordinate, (0, 0) = top-left of the image.
    pub texcoord: Vec2,
    /// Linear RGBA vertex colour (white when the mesh has none).
    pub color: Vec4,
}

impl StandardVertex {
    /// The mesh's vertices and triangle list in this layout, with the defaults of absent
    /// attributes: normal +Z, texcoord (0, 0), colour white. A mesh without normals is
    /// [flat-shaded](Mesh::flat_shaded) first. Every backend prepares scene meshes
    /// through this one function, so they see identical vertex data.
    pub fn from_mesh(mesh: &Mesh) -> (Vec<StandardVertex>, Vec<u32>) {
        let flat;
        let mesh = if mesh.normals.is_none() {
            flat = mesh.flat_shaded();
            &flat
        } else {
            mesh
        };
        let vertices = (0..mesh.positions.len())
            .map(|i| StandardVertex {
                position: mesh.positions[i],
                normal: mesh.normals.as_ref().map_or(Vec3::Z, |n| n[i]),
                texcoord: mesh.texcoords.as_ref().map_or(Vec2::ZERO, |t| t[i]),
                color: mesh.colors.as_ref().map_or(Vec4::ONE, |c| c[i]),
            })
            .collect();
        (vertices, mesh.indices.clone())
    }
}
