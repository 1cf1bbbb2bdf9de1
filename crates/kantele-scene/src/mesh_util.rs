//! Mesh helpers shared by the loaders and the built-in scenes.

use glam::Vec3;
use kantele_rules::scene::{Camera, Mesh, Scene};

/// The direction (towards the eye) a made-up camera looks from: in front, slightly above and to
/// the right.
pub const FRAMING_DIRECTION: Vec3 = Vec3::new(0.4, 0.5, 1.0);

/// Gives a mesh flat face normals: the mesh is de-indexed (three vertices of its own per
/// triangle, attributes copied) and every vertex gets the normal of its triangle, the normalised
/// cross product of its edges (counter-clockwise is the front). Degenerate or non-finite triangles
/// get (0, 0, 1).
///
/// The mesh must have valid indices (a multiple of three, all in range); otherwise it is left
/// unchanged and [`Scene::validate`] reports the problem.
pub fn flat_normals(mesh: &mut Mesh) {
    let n = mesh.positions.len();
    if !mesh.indices.len().is_multiple_of(3) || mesh.indices.iter().any(|&i| i as usize >= n) {
        return;
    }
    let attribute_ok = |len: Option<usize>| len.is_none_or(|l| l == n);
    if !attribute_ok(mesh.texcoords.as_ref().map(Vec::len))
        || !attribute_ok(mesh.colors.as_ref().map(Vec::len))
    {
        return;
    }
    *mesh = mesh.flat_shaded();
}

/// Converts a triangle strip (`TRIANGLE_STRIP`) to a triangle list, as glTF defines it: triangle
/// `i` is `(v[i], v[i + 1 + i % 2], v[i + 2 - i % 2])`, so all share the first one's orientation.
pub fn strip_to_list(strip: &[u32]) -> Vec<u32> {
    let mut list = Vec::with_capacity(strip.len().saturating_sub(2) * 3);
    for (i, w) in strip.windows(3).enumerate() {
        if i % 2 == 0 {
            list.extend([w[0], w[1], w[2]]);
        } else {
            list.extend([w[0], w[2], w[1]]);
        }
    }
    list
}

/// Converts a triangle fan (`TRIANGLE_FAN`) to a triangle list.
pub fn fan_to_list(fan: &[u32]) -> Vec<u32> {
    let Some((&center, rest)) = fan.split_first() else {
        return Vec::new();
    };
    let mut list = Vec::with_capacity(rest.len().saturating_sub(1) * 3);
    for w in rest.windows(2) {
        list.extend([center, w[0], w[1]]);
    }
    list
}

/// Converts a line strip (`LINE_STRIP`) or, with `closed`, a line loop (`LINE_LOOP`) to a list
/// of segments: `(v[i], v[i + 1])`, plus `(v[last], v[0])` for a loop. Fewer than two vertices
/// make no segment.
pub fn line_strip_to_list(strip: &[u32], closed: bool) -> Vec<u32> {
    if strip.len() < 2 {
        return Vec::new();
    }
    let mut list = Vec::with_capacity(strip.len() * 2);
    for w in strip.windows(2) {
        list.extend([w[0], w[1]]);
    }
    if closed {
        list.extend([strip[strip.len() - 1], strip[0]]);
    }
    list
}

/// The first index that is out of range, as `(position, index)`.
pub fn first_index_out_of_range(indices: &[u32], vertex_count: usize) -> Option<(usize, u32)> {
    indices
        .iter()
        .enumerate()
        .find(|(_, &i)| i as usize >= vertex_count)
        .map(|(p, &i)| (p, i))
}

/// A camera framing everything the scene draws, from [`FRAMING_DIRECTION`], for the scene's
/// resolution.
pub fn framing_camera(scene: &Scene) -> Camera {
    let (center, radius) = scene.bounding_sphere().unwrap_or((Vec3::ZERO, 1.0));
    let (w, h) = scene.resolution;
    let aspect = w.max(1) as f32 / h.max(1) as f32;
    Camera::framing(center, radius, FRAMING_DIRECTION, aspect)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec4};

    fn quad() -> Mesh {
        Mesh {
            name: "quad".into(),
            positions: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            normals: None,
            texcoords: Some(vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ]),
            colors: Some(vec![Vec4::ONE, Vec4::X, Vec4::Y, Vec4::Z]),
            indices: vec![0, 1, 2, 0, 2, 3],
            material: 0,
            topology: kantele_rules::scene::Topology::Triangles,
            texcoords1: None,
            tangents: None,
        }
    }

    #[test]
    fn flat_normals_deindexes_and_points_out_of_the_front() {
        let mut mesh = quad();
        flat_normals(&mut mesh);
        assert_eq!(mesh.positions.len(), 6);
        assert_eq!(mesh.indices, vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(mesh.triangle_count(), 2);
        let normals = mesh.normals.as_ref().expect("normals set");
        assert!(normals.iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));
        // Attributes follow their vertices.
        assert_eq!(mesh.positions[4], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(mesh.texcoords.as_ref().unwrap()[5], Vec2::new(0.0, 0.0));
        assert_eq!(mesh.colors.as_ref().unwrap()[5], Vec4::Z);
    }

    #[test]
    fn flat_normals_of_clockwise_triangle_point_backwards() {
        let mut mesh = quad();
        mesh.indices = vec![0, 2, 1];
        flat_normals(&mut mesh);
        let normals = mesh.normals.unwrap();
        assert!(normals[0].abs_diff_eq(-Vec3::Z, 1e-6));
    }

    #[test]
    fn flat_normals_of_degenerate_triangles_are_defined() {
        let mut mesh = quad();
        mesh.positions[1] = mesh.positions[0];
        mesh.positions[3] = Vec3::new(f32::NAN, 0.0, 0.0);
        flat_normals(&mut mesh);
        let normals = mesh.normals.unwrap();
        assert!(normals.iter().all(|n| n.is_finite() && n.length() > 0.99));
        assert_eq!(normals[0], Vec3::Z);
        assert_eq!(normals[3], Vec3::Z);
    }

    #[test]
    fn flat_normals_leaves_invalid_meshes_alone() {
        let mut mesh = quad();
        mesh.indices = vec![0, 1, 9];
        flat_normals(&mut mesh);
        assert!(mesh.normals.is_none());
        assert_eq!(mesh.positions.len(), 4);
    }

    #[test]
    fn strips_and_fans_keep_the_winding() {
        // A strip and a fan over the same quad, both counter-clockwise.
        assert_eq!(strip_to_list(&[0, 1, 3, 2]), vec![0, 1, 3, 1, 2, 3]);
        assert_eq!(fan_to_list(&[0, 1, 2, 3]), vec![0, 1, 2, 0, 2, 3]);
        assert!(strip_to_list(&[0, 1]).is_empty());
        assert!(fan_to_list(&[]).is_empty());
    }

    #[test]
    fn line_strips_and_loops_become_segments() {
        assert_eq!(line_strip_to_list(&[4, 5, 6], false), vec![4, 5, 5, 6]);
        assert_eq!(line_strip_to_list(&[4, 5, 6], true), vec![4, 5, 5, 6, 6, 4]);
        assert!(line_strip_to_list(&[4], true).is_empty());
    }
}
