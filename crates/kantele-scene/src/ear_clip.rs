//! Triangulating polygons (OBJ and PLY faces with more than three corners) by ear clipping, so
//! that concave faces keep their shape (a fan would cover area outside them).
//!
//! The ears are found by `earcut` (Mapbox's earcut, maintained by georust): ear clipping with
//! a z-order index of the corners, so a polygon of thousands of corners (a hostile comb of
//! 4 094 took seconds with plain ear clipping, a file of them minutes) is cut in about
//! `n log n`. Self-intersecting polygons are cut as earcut cuts them.

use glam::{Vec2, Vec3};

use crate::budget::Budget;

/// Polygons with more corners than this are fan-split instead.
pub(crate) const MAX_EAR_CLIP_CORNERS: usize = 4096;

/// Triangles (as corner numbers `0..n`, with the polygon's winding) covering the polygon with
/// the given corner positions; `None` when it is too large or degenerate for ear clipping (the
/// caller falls back to a fan).
pub(crate) fn triangulate(corners: &[Vec3]) -> Option<Vec<[usize; 3]>> {
    let n = corners.len();
    if !(3..=MAX_EAR_CLIP_CORNERS).contains(&n) || corners.iter().any(|c| !c.is_finite()) {
        return None;
    }
    if n == 3 {
        return Some(vec![[0, 1, 2]]);
    }
    // Project onto the plane of the polygon's Newell normal.
    let mut normal = Vec3::ZERO;
    for i in 0..n {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        normal += Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let normal = normal.try_normalize()?;
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let p: Vec<Vec2> = corners
        .iter()
        .map(|c| Vec2::new(c.dot(u), c.dot(v)))
        .collect();
    // With this basis the polygon is counter-clockwise in (u, v): triangles turning the other
    // way are reversed, so each keeps the polygon's winding in space.
    let flat: Vec<[f64; 2]> = p.iter().map(|q| [q.x as f64, q.y as f64]).collect();
    let mut indices: Vec<u32> = Vec::with_capacity(3 * (n - 2));
    earcut::Earcut::new().earcut_slice(&flat, &[], &mut indices);
    if indices.is_empty() {
        return None;
    }
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    Some(
        indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
                if cross(p[a], p[b], p[c]) < 0.0 {
                    [a, c, b]
                } else {
                    [a, b, c]
                }
            })
            .collect(),
    )
}

/// Triangles of the faces (`arities` corners each; empty means all triangles): polygons by ear
/// clipping, so concave ones keep their shape; faces of one or two corners are dropped. The
/// indices must be in range for `positions`.
pub(crate) fn triangulate_faces(
    indices: &[u32],
    arities: &[u32],
    positions: &[Vec3],
    budget: &mut Budget,
) -> Result<Vec<u32>, String> {
    if arities.is_empty() {
        if !indices.len().is_multiple_of(3) {
            return Err("the faces do not make whole triangles".to_string());
        }
        return Ok(indices.to_vec());
    }
    let corners: u64 = arities.iter().map(|&a| a as u64).sum();
    if corners != indices.len() as u64 {
        return Err("the face sizes do not match the indices".to_string());
    }
    // A polygon of k corners makes k − 2 triangles: at most 3 indices per corner.
    budget.charge(corners, 12, "triangulating the faces")?;
    let mut out = crate::budget::vec_with_capacity(indices.len() * 3, "triangulating the faces")?;
    let mut start = 0;
    for &arity in arities {
        let face = &indices[start..start + arity as usize];
        start += arity as usize;
        if face.len() < 3 {
            continue;
        }
        let corners: Vec<Vec3> = face.iter().map(|&i| positions[i as usize]).collect();
        match triangulate(&corners) {
            Some(triangles) => {
                for t in triangles {
                    out.extend(t.iter().map(|&k| face[k]));
                }
            }
            None => {
                for k in 1..face.len() - 1 {
                    out.extend([face[0], face[k], face[k + 1]]);
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(corners: &[Vec3], tris: &[[usize; 3]]) -> f32 {
        tris.iter()
            .map(|t| {
                (corners[t[1]] - corners[t[0]])
                    .cross(corners[t[2]] - corners[t[0]])
                    .z
                    * 0.5
            })
            .sum()
    }

    #[test]
    fn concave_polygon_keeps_its_area_and_winding() {
        // An L shape (area 3), counter-clockwise, starting at the reflex-adjacent corner so that
        // a fan from corner 0 would cover area outside it.
        let l = [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let tris = triangulate(&l).unwrap();
        assert_eq!(tris.len(), 4);
        assert!((area(&l, &tris) - 3.0).abs() < 1e-5);
        // Every triangle is counter-clockwise (positive area).
        assert!(tris.iter().all(|t| area(&l, &[*t]) > 0.0));
    }

    #[test]
    fn clockwise_polygons_stay_clockwise() {
        let sq = [Vec3::ZERO, Vec3::Y, Vec3::new(1.0, 1.0, 0.0), Vec3::X];
        let tris = triangulate(&sq).unwrap();
        assert!((area(&sq, &tris) + 1.0).abs() < 1e-5);
    }

    /// A comb of 4 094 corners (1 023 teeth), the shape that made plain ear clipping cubic:
    /// cut into 4 092 triangles of the comb's area and winding.
    #[test]
    fn a_comb_keeps_its_area() {
        let teeth = 1023;
        let mut comb = Vec::new();
        for i in 0..teeth {
            let x = 2.0 * i as f32;
            comb.extend([
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 1.0, 0.0, 0.0),
                Vec3::new(x + 1.0, 10.0, 0.0),
                Vec3::new(x + 2.0, 10.0, 0.0),
            ]);
        }
        let end = 2.0 * teeth as f32;
        comb.extend([Vec3::new(end, -1.0, 0.0), Vec3::new(0.0, -1.0, 0.0)]);
        // Built clockwise; turned counter-clockwise.
        comb.reverse();
        assert_eq!(comb.len(), 4094);
        // Each tooth's area 10 (its 1 × 10 column), over a 1-high base; plus the last column
        // from x = end − 1 up to 10.
        let tris = triangulate(&comb).expect("triangulated");
        assert_eq!(tris.len(), comb.len() - 2);
        let want = end + 10.0 * teeth as f32;
        assert!(
            (area(&comb, &tris) - want).abs() < 1e-2 * want,
            "{}",
            area(&comb, &tris)
        );
        assert!(tris.iter().all(|t| area(&comb, &[*t]) >= 0.0));
    }

    #[test]
    fn degenerate_polygons_fall_back() {
        assert!(triangulate(&[Vec3::ZERO; 5]).is_none());
        assert!(triangulate(&[Vec3::ZERO, Vec3::X]).is_none());
    }
}
