//! The vertex layouts every backend draws scene meshes with: one definition, so the CPU,
//! OpenGL and CUDA backends see identical vertex data. [`StandardVertex`] serves every
//! shading; [`PbrVertex`] adds what only PBR shading reads (the second texture coordinate set
//! and the tangent).

use std::borrow::Cow;

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
        let mesh = with_normals(mesh);
        let vertices = (0..mesh.positions.len())
            .map(|i| StandardVertex::of(&mesh, i))
            .collect();
        (vertices, mesh.indices.clone())
    }

    /// Vertex `i` of `mesh` (which has normals), with the defaults of absent attributes.
    fn of(mesh: &Mesh, i: usize) -> StandardVertex {
        StandardVertex {
            position: mesh.positions[i],
            normal: mesh.normals.as_ref().map_or(Vec3::Z, |n| n[i]),
            texcoord: mesh.texcoords.as_ref().map_or(Vec2::ZERO, |t| t[i]),
            color: mesh.colors.as_ref().map_or(Vec4::ONE, |c| c[i]),
        }
    }
}

/// The vertex layout of scene meshes drawn with PBR shading: [`StandardVertex`] and the
/// attributes only that shading reads.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PbrVertex {
    /// Position, normal, first texture coordinate set and colour.
    pub standard: StandardVertex,
    /// The second texture coordinate set ([`Mesh::texcoords1`]).
    pub texcoord1: Vec2,
    /// Object-space tangent and bitangent sign ([`Mesh::tangents`]).
    pub tangent: Vec4,
}

impl PbrVertex {
    /// The mesh's vertices and triangle list in this layout, as [`StandardVertex::from_mesh`]
    /// makes them, with the defaults texcoord1 (0, 0) and tangent 0 (no tangent) for absent
    /// attributes.
    pub fn from_mesh(mesh: &Mesh) -> (Vec<PbrVertex>, Vec<u32>) {
        let mesh = with_normals(mesh);
        let vertices = (0..mesh.positions.len())
            .map(|i| PbrVertex {
                standard: StandardVertex::of(&mesh, i),
                texcoord1: mesh.texcoords1.as_ref().map_or(Vec2::ZERO, |t| t[i]),
                tangent: mesh.tangents.as_ref().map_or(Vec4::ZERO, |t| t[i]),
            })
            .collect();
        (vertices, mesh.indices.clone())
    }
}

/// `mesh`, [flat-shaded](Mesh::flat_shaded) when it has no normals.
fn with_normals(mesh: &Mesh) -> Cow<'_, Mesh> {
    if mesh.normals.is_none() {
        Cow::Owned(mesh.flat_shaded())
    } else {
        Cow::Borrowed(mesh)
    }
}
