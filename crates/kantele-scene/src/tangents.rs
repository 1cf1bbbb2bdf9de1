//! Tangents for normal textures, generated with MikkTSpace (`bevy_mikktspace`) as glTF requires
//! for meshes whose file gives none.
//!
//! MikkTSpace gives each triangle corner a tangent and a handedness. Where the corners that
//! share a vertex disagree (a mirrored seam of the texture coordinates, a hard edge of the
//! tangent field), the vertex is split: one copy per distinct tangent, with the same other
//! attributes. A vertex no triangle uses, and a corner MikkTSpace cannot orient (a degenerate
//! triangle without oriented neighbours), get the zero tangent, which the shading reads as "keep
//! the interpolated normal".
//!
//! Texture coordinates enter as `(u, 1 − v)`: glTF's `v` runs down the image and its normal
//! textures' green channel up, so the bitangent MikkTSpace derives along increasing `1 − v` is
//! the one the texture's green channel points along — the tangents Blender and the other tools
//! that follow the glTF convention export.

use std::collections::HashMap;

use glam::{Vec2, Vec3, Vec4};
use kantele_rules::scene::{Mesh, Topology};

use crate::budget::Budget;

/// Bytes per triangle corner MikkTSpace's own tables take while it runs (a generous bound of
/// its per-corner and per-triangle records).
const SCRATCH_PER_CORNER: u64 = 160;

/// Bytes of one vertex with every attribute a split vertex copies: position, normal, two
/// texture coordinate sets, colour, tangent.
const BYTES_PER_VERTEX: u64 = 12 + 12 + 8 + 8 + 16 + 16;

/// Gives `mesh` MikkTSpace tangents for the texture coordinates `texcoord_set` (0:
/// [`Mesh::texcoords`], 1: [`Mesh::texcoords1`]), splitting vertices where corners disagree.
/// Leaves the mesh unchanged when it is not a triangle list with normals and those
/// coordinates (the shading then derives tangents from screen-space derivatives). The scratch
/// space and the largest result are charged to `budget` first; an error is the budget's.
pub(crate) fn generate(
    mesh: &mut Mesh,
    texcoord_set: usize,
    budget: &mut Budget,
    what: &str,
) -> Result<(), String> {
    let n = mesh.positions.len();
    let texcoords = match texcoord_set {
        0 => mesh.texcoords.as_ref(),
        _ => mesh.texcoords1.as_ref(),
    };
    let (Some(normals), Some(texcoords)) = (mesh.normals.as_ref(), texcoords) else {
        return Ok(());
    };
    if mesh.topology != Topology::Triangles
        || normals.len() != n
        || texcoords.len() != n
        || !mesh.indices.len().is_multiple_of(3)
        || mesh.indices.iter().any(|&i| i as usize >= n)
    {
        return Ok(());
    }
    let corners = mesh.indices.len() as u64;
    let label = format!("{what}: tangents");
    budget.charge(corners, SCRATCH_PER_CORNER + BYTES_PER_VERTEX, &label)?;
    let mut geometry = Corners {
        positions: &mesh.positions,
        normals,
        texcoords,
        indices: &mesh.indices,
        tangents: vec![Vec4::ZERO; mesh.indices.len()],
    };
    // The crate's only error type has no values; a panic on hostile data (NaN coordinates)
    // leaves the derivative frame rather than failing the load.
    let generated =
        crate::quiet_panic::catch(|| bevy_mikktspace::generate_tangents(&mut geometry).is_ok());
    if generated != Ok(true) {
        return Ok(());
    }
    let tangents = geometry.tangents;
    split_by_tangent(mesh, &tangents);
    Ok(())
}

/// The mesh as MikkTSpace reads it (faces of three corners), with the tangents it writes, one
/// per corner.
struct Corners<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    texcoords: &'a [Vec2],
    indices: &'a [u32],
    tangents: Vec<Vec4>,
}

impl Corners<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.indices[face * 3 + vert] as usize
    }
}

impl bevy_mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let t = self.texcoords[self.vertex(face, vert)];
        [t.x, 1.0 - t.y]
    }

    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        let tangent = tangent_space
            .map(|t| Vec4::from_array(t.tangent_encoded()))
            .filter(|t| t.is_finite())
            .unwrap_or(Vec4::ZERO);
        self.tangents[face * 3 + vert] = tangent;
    }
}

/// Sets `mesh.tangents` from one tangent per index (`corner_tangents`), giving each vertex one
/// copy per distinct tangent among its corners.
fn split_by_tangent(mesh: &mut Mesh, corner_tangents: &[Vec4]) {
    let n = mesh.positions.len();
    // Per vertex: its first corner's tangent, and whether a corner disagreed.
    let mut first: Vec<Option<Vec4>> = vec![None; n];
    let mut disagrees = false;
    for (&i, &t) in mesh.indices.iter().zip(corner_tangents) {
        match first[i as usize] {
            None => first[i as usize] = Some(t),
            Some(f) if f.to_array().map(f32::to_bits) != t.to_array().map(f32::to_bits) => {
                disagrees = true;
            }
            Some(_) => {}
        }
    }
    if !disagrees {
        mesh.tangents = Some(first.into_iter().map(|t| t.unwrap_or(Vec4::ZERO)).collect());
        return;
    }
    // (vertex, tangent bits) → the vertex's copy with that tangent; the first keeps its index.
    let mut copies: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    let mut tangents: Vec<Vec4> = first.iter().map(|t| t.unwrap_or(Vec4::ZERO)).collect();
    let mut sources: Vec<u32> = Vec::new();
    for (index, &t) in mesh.indices.iter_mut().zip(corner_tangents) {
        let vertex = *index;
        if tangents[vertex as usize].to_array().map(f32::to_bits) == t.to_array().map(f32::to_bits)
        {
            continue;
        }
        let key = (vertex, t.to_array().map(f32::to_bits));
        *index = *copies.entry(key).or_insert_with(|| {
            sources.push(vertex);
            tangents.push(t);
            (n + sources.len() - 1) as u32
        });
    }
    copy_vertices(&mut mesh.positions, &sources);
    if let Some(v) = mesh.normals.as_mut() {
        copy_vertices(v, &sources);
    }
    if let Some(v) = mesh.texcoords.as_mut() {
        copy_vertices(v, &sources);
    }
    if let Some(v) = mesh.texcoords1.as_mut() {
        copy_vertices(v, &sources);
    }
    if let Some(v) = mesh.colors.as_mut() {
        copy_vertices(v, &sources);
    }
    mesh.tangents = Some(tangents);
}

/// Appends to `values` a copy of the value of each vertex in `sources`.
fn copy_vertices<T: Copy>(values: &mut Vec<T>, sources: &[u32]) {
    values.reserve(sources.len());
    for &s in sources {
        let v = values[s as usize];
        values.push(v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad facing +Z with glTF's coordinates: u along +X, v along −Y (image rows down).
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

    fn generated(mut mesh: Mesh, set: usize) -> Mesh {
        let mut budget = Budget::new(1 << 30);
        generate(&mut mesh, set, &mut budget, "test").expect("within budget");
        mesh
    }

    /// The quad's tangent is +X with w = +1: the bitangent n × t = +Y points up the image, as
    /// the texture's green channel does.
    #[test]
    fn a_quad_gets_the_gltf_tangent_frame() {
        let mesh = generated(quad(), 0);
        let tangents = mesh.tangents.expect("tangents");
        assert_eq!(tangents.len(), 4);
        for t in tangents {
            assert!(t.abs_diff_eq(Vec4::new(1.0, 0.0, 0.0, 1.0), 1e-6), "{t}");
        }
        assert_eq!(mesh.indices, vec![0, 1, 2, 0, 2, 3]);
    }

    /// The second coordinate set is used when asked for: rotated coordinates turn the tangent.
    #[test]
    fn the_chosen_coordinate_set_orients_the_tangents() {
        let mut mesh = quad();
        // u along +y and v along −x: the tangent is +y, and the bitangent (up the image, +x)
        // is −(n × t), so w = −1.
        mesh.texcoords1 = Some(vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
        ]);
        let mesh = generated(mesh, 1);
        for t in mesh.tangents.expect("tangents") {
            assert!(t.abs_diff_eq(Vec4::new(0.0, 1.0, 0.0, -1.0), 1e-6), "{t}");
        }
    }

    /// Two quads sharing an edge whose texture is mirrored across it: the shared vertices get
    /// one copy per side, with opposite handedness, and the other attributes copied.
    #[test]
    fn a_mirrored_seam_splits_the_shared_vertices() {
        let mut mesh = quad();
        // A second quad to the right, sharing vertices 1 and 2, with u running back.
        mesh.positions
            .extend([Vec3::new(3.0, -1.0, 0.0), Vec3::new(3.0, 1.0, 0.0)]);
        mesh.normals.as_mut().expect("normals").extend([Vec3::Z; 2]);
        mesh.texcoords
            .as_mut()
            .expect("texcoords")
            .extend([Vec2::new(0.0, 1.0), Vec2::new(0.0, 0.0)]);
        mesh.colors = Some((0..6).map(|i| Vec4::splat(i as f32)).collect());
        mesh.indices.extend([1, 4, 5, 1, 5, 2]);
        let mesh = generated(mesh, 0);
        let tangents = mesh.tangents.as_ref().expect("tangents");
        assert_eq!(mesh.positions.len(), 8, "vertices 1 and 2 are split");
        let colors = mesh.colors.as_ref().expect("colors");
        for tri in mesh.indices.chunks_exact(3) {
            let left = tri.iter().all(|&i| mesh.positions[i as usize].x <= 1.0);
            for &i in tri {
                let t = tangents[i as usize];
                let want = if left { Vec3::X } else { -Vec3::X };
                assert!(t.truncate().abs_diff_eq(want, 1e-5), "{t} left {left}");
            }
        }
        // The copies keep their source's attributes.
        for copy in 6..8 {
            let source = mesh.positions[..6]
                .iter()
                .position(|p| *p == mesh.positions[copy])
                .expect("a source");
            assert_eq!(colors[copy], colors[source]);
        }
    }

    /// Meshes MikkTSpace cannot orient are left as they are: no normals, no coordinates,
    /// points; a budget too small for the scratch space is the budget's error.
    #[test]
    fn unusable_meshes_are_left_alone_and_the_budget_holds() {
        let mut no_normals = quad();
        no_normals.normals = None;
        assert!(generated(no_normals, 0).tangents.is_none());
        assert!(generated(quad(), 1).tangents.is_none(), "no second set");
        let mut points = quad();
        points.topology = Topology::Points;
        points.indices = vec![0, 1, 2, 3];
        assert!(generated(points, 0).tangents.is_none());
        let mut budget = Budget::new(100);
        let err = generate(&mut quad(), 0, &mut budget, "tiny").expect_err("over budget");
        assert!(err.contains("tiny"), "{err}");
    }

    /// Non-finite positions do not panic; their corners get some tangent or none.
    #[test]
    fn nan_positions_do_not_fail_the_load() {
        let mut mesh = quad();
        mesh.positions[2] = Vec3::NAN;
        let mesh = generated(mesh, 0);
        assert!(mesh
            .tangents
            .is_none_or(|t| t.len() == mesh.positions.len()));
    }
}
