//! The exact coverage reference that the coverage tests and the `raster` fuzz target compare
//! every traversal strategy with: snapped vertices, `i128` arithmetic, and the top-left rule
//! written as explicit cases rather than as a bias. Independent of [`crate::setup`] on purpose.

/// Whether the centre of pixel `(x, y)` lies inside the triangle with snapped window vertices
/// `v` (sub-pixel units, 8 bits: pixel centres at `x·256 + 128`), by the top-left fill rule.
/// A triangle of zero area covers nothing; either winding is accepted.
pub fn reference_covers(v: [(i64, i64); 3], x: i64, y: i64) -> bool {
    let (px, py) = (x * 256 + 128, y * 256 + 128);
    let area = (v[1].0 - v[0].0) as i128 * (v[2].1 - v[0].1) as i128
        - (v[2].0 - v[0].0) as i128 * (v[1].1 - v[0].1) as i128;
    if area == 0 {
        return false;
    }
    let v = if area > 0 { v } else { [v[0], v[2], v[1]] };
    (0..3).all(|i| {
        let (p, q) = (v[i], v[(i + 1) % 3]);
        let e = (q.0 - p.0) as i128 * (py - p.1) as i128 - (q.1 - p.1) as i128 * (px - p.0) as i128;
        if e != 0 {
            return e > 0;
        }
        let is_top = q.1 == p.1 && q.0 > p.0;
        let is_left = q.1 < p.1;
        is_top || is_left
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_applies_the_top_left_rule_on_shared_edges() {
        // Pixel (0, 0)'s centre (128, 128) lies on the diagonal shared by two triangles of the
        // square [0, 256]²: exactly one of them may own it, whatever the winding.
        let a = [(0, 0), (256, 0), (0, 256)];
        let b = [(256, 0), (256, 256), (0, 256)];
        assert_ne!(reference_covers(a, 0, 0), reference_covers(b, 0, 0));
        let a_reversed = [a[0], a[2], a[1]];
        assert_eq!(
            reference_covers(a, 0, 0),
            reference_covers(a_reversed, 0, 0)
        );
        // Zero area covers nothing; a pixel outside is never covered.
        assert!(!reference_covers([(0, 0), (512, 512), (1024, 1024)], 1, 1));
        assert!(!reference_covers(a, 3, 3));
    }
}
